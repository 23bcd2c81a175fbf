//! `.meta` files: the project's GUID → asset index, and the ModelImporter settings that
//! decide which fileID names which object inside a model.

use crate::docs;
use crate::yaml::{self, Node};
use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};
use xxhash_rust::xxh64::xxh64;

/// GUID → asset path, from every `*.meta` under `Assets/`.
#[derive(Default, Debug)]
pub struct GuidIndex {
    pub map: HashMap<String, PathBuf>,
    pub warnings: Vec<String>,
}

impl GuidIndex {
    /// Symbolic links are followed only when they lead to a file or folder inside
    /// `assets` (never outside the project), and each real folder is walked once, so a
    /// link loop cannot hang the walk.
    pub fn build(assets: &Path) -> GuidIndex {
        let mut idx = GuidIndex::default();
        let Ok(inside) = assets.canonicalize() else {
            return idx;
        };
        // Warnings name files from the project root, as every other warning does.
        let root = assets.parent().unwrap_or(Path::new(""));
        let rel = |p: &Path| p.strip_prefix(root).unwrap_or(p).display().to_string();
        let mut seen: HashSet<PathBuf> = [inside.clone()].into_iter().collect();
        let mut stack = vec![assets.to_path_buf()];
        while let Some(dir) = stack.pop() {
            let Some(entries) = sorted_entries(&dir) else {
                continue;
            };
            for (p, ty) in entries {
                let is_dir = if ty.is_symlink() {
                    match p.canonicalize() {
                        Ok(real) if real.starts_with(&inside) => {
                            if real.is_dir() && !seen.insert(real) {
                                continue; // a folder already walked (link loop)
                            }
                            p.is_dir()
                        }
                        // Other linked files are only read through their .meta,
                        // which reports them (below).
                        Ok(real) if real.is_file() && p.extension().is_none_or(|e| e != "meta") => {
                            continue;
                        }
                        Ok(real) => {
                            idx.warnings.push(format!(
                                "{}: symbolic link to {}, outside the project; not read",
                                rel(&p),
                                real.display()
                            ));
                            continue;
                        }
                        Err(_) => continue, // dangling link
                    }
                } else {
                    if ty.is_dir() {
                        if let Ok(real) = p.canonicalize() {
                            seen.insert(real);
                        }
                    }
                    ty.is_dir()
                };
                if is_dir {
                    stack.push(p);
                } else if p.extension().is_some_and(|e| e == "meta") {
                    if let Some(guid) = read_guid(&p) {
                        let asset = p.with_extension("");
                        // The asset itself may be a link out of the project.
                        if let Some(real) = asset
                            .canonicalize()
                            .ok()
                            .filter(|r| !r.starts_with(&inside))
                        {
                            idx.warnings.push(format!(
                                "{}: symbolic link to {}, outside the project; not read",
                                rel(&asset),
                                real.display()
                            ));
                            continue;
                        }
                        if let Some(prev) = idx.map.get(&guid) {
                            idx.warnings.push(format!(
                                "duplicate GUID {guid} in {} and {}; using the first",
                                rel(prev),
                                rel(&asset)
                            ));
                        } else {
                            idx.map.insert(guid, asset);
                        }
                    }
                }
            }
        }
        idx
    }

    pub fn get(&self, guid: &str) -> Option<&PathBuf> {
        self.map.get(guid)
    }
}

/// A folder's entries with their types (a link's own, not its target's), sorted by path so
/// that walks are the same on every file system; None when it cannot be listed.
pub(crate) fn sorted_entries(dir: &Path) -> Option<Vec<(PathBuf, std::fs::FileType)>> {
    let mut entries: Vec<_> = std::fs::read_dir(dir)
        .ok()?
        .filter_map(Result::ok)
        .filter_map(|e| Some((e.path(), e.file_type().ok()?)))
        .collect();
    entries.sort_by(|a, b| a.0.cmp(&b.0));
    Some(entries)
}

/// The `guid:` line of a `.meta` file (read as a string, never as a number).
fn read_guid(meta: &Path) -> Option<String> {
    guid_of(&std::fs::read_to_string(meta).ok()?)
}

/// The GUID a `.meta` file's text declares, if any.
pub fn guid_of(text: &str) -> Option<String> {
    text.lines()
        .find_map(|l| l.strip_prefix("guid:"))
        .map(|g| g.trim().to_string())
        .filter(|g| !g.is_empty())
}

pub fn class_name(class: u32) -> &'static str {
    match class {
        docs::GAME_OBJECT => "GameObject",
        docs::TRANSFORM => "Transform",
        docs::MATERIAL => "Material",
        docs::MESH_RENDERER => "MeshRenderer",
        docs::MESH_FILTER => "MeshFilter",
        docs::SKINNED_MESH_RENDERER => "SkinnedMeshRenderer",
        docs::MESH => "Mesh",
        _ => "Object",
    }
}

/// What a model's `.meta` says about fileIDs and import scale.
#[derive(Clone, Debug, Default)]
pub struct ModelMeta {
    /// `fileIDToRecycleName` (legacy): fileID → name.
    pub recycle: Vec<(i64, String)>,
    /// `internalIDToNameTable`: (class, fileID, name).
    pub internal: Vec<(u32, i64, String)>,
    /// `fileIdsGeneration: 2` (path-string hashes).
    pub generation2: bool,
    /// `globalScale` (ModelImporter scale factor).
    pub global_scale: f32,
    /// `useFileScale` ("Convert Units"); `None` in Unity 5.x metas, which fold the file's
    /// unit into `globalScale` instead.
    pub use_file_scale: Option<bool>,
    /// `bakeAxisConversion: 1`: the file's axis conversion is baked into the geometry
    /// rather than kept as a rotation on the root GameObject.
    pub bake_axis_conversion: bool,
    /// `materials.materialLocation`: 0 extracted `.mat` files found by name, 1 sub-assets
    /// of the model; `None` when the meta does not say.
    pub material_location: Option<i64>,
    /// `materials.materialName`: how an extracted `.mat` is named: 0 after the diffuse
    /// texture's file (the material's name when it has none; Unity's default), 1 after
    /// the material, 2 `<model>-<material>`, 3 the texture's, else `<model>-<material>`.
    pub material_name: i64,
    /// `materials.materialSearch`: where an extracted `.mat` is looked for: 0 the
    /// `Materials/` folder next to the model, 1 (Unity's default) that and each parent
    /// folder's `Materials/` up to `Assets`, 2 also anywhere in the project.
    pub material_search: i64,
    /// `externalObjects` remaps: (type, name, guid), e.g.
    /// (`UnityEngine:Material`, FBX material name, `.mat` guid).
    pub external_objects: Vec<(String, String, String)>,
    /// `tangentSpace.normalImportMode`: 0 import, 1 calculate, 2 none.
    pub normal_import_mode: i64,
    /// `tangentSpace.normalSmoothAngle` in degrees (Unity's default 60).
    pub normal_smoothing_angle: f32,
}

impl ModelMeta {
    pub fn read(model: &Path) -> ModelMeta {
        let mut meta_path = model.as_os_str().to_owned();
        meta_path.push(".meta");
        let text = std::fs::read_to_string(PathBuf::from(meta_path)).unwrap_or_default();
        Self::parse(&text)
    }

    pub fn parse(text: &str) -> ModelMeta {
        let root = yaml::parse(text);
        let imp = root
            .get("ModelImporter")
            .cloned()
            .unwrap_or(Node::Map(vec![]));
        let mut m = ModelMeta {
            global_scale: 1.0,
            normal_smoothing_angle: 60.0,
            ..Default::default()
        };
        for (k, v) in imp
            .get("fileIDToRecycleName")
            .map(Node::as_map)
            .unwrap_or(&[])
        {
            if let (Ok(id), Some(name)) = (k.trim().parse::<i64>(), v.as_str()) {
                m.recycle.push((id, name.to_string()));
            }
        }
        for e in imp
            .get("internalIDToNameTable")
            .map(Node::as_seq)
            .unwrap_or(&[])
        {
            let name = e.str_at("second").unwrap_or("").to_string();
            if let Some((k, v)) = e.get("first").and_then(|f| f.as_map().first()) {
                if let (Ok(class), Some(id)) = (k.trim().parse::<u32>(), v.as_i64()) {
                    m.internal.push((class, id, name));
                }
            }
        }
        if let Some(meshes) = imp.get("meshes") {
            if let Some(s) = meshes.f32_at("globalScale") {
                if s.is_finite() && s > 0.0 {
                    m.global_scale = s;
                }
            }
        }
        m.use_file_scale = imp
            .path(&["meshes", "useFileScale"])
            .and_then(Node::as_i64)
            .map(|v| v != 0);
        m.bake_axis_conversion = imp
            .path(&["meshes", "bakeAxisConversion"])
            .and_then(Node::as_i64)
            == Some(1);
        m.material_location = imp
            .path(&["materials", "materialLocation"])
            .and_then(Node::as_i64);
        m.material_name = imp
            .path(&["materials", "materialName"])
            .and_then(Node::as_i64)
            .unwrap_or(0);
        m.material_search = imp
            .path(&["materials", "materialSearch"])
            .and_then(Node::as_i64)
            .unwrap_or(1);
        for e in imp.get("externalObjects").map(Node::as_seq).unwrap_or(&[]) {
            let (Some(first), Some(guid)) = (e.get("first"), e.path(&["second", "guid"])) else {
                continue;
            };
            let field = |k: &str| first.str_at(k).unwrap_or("").to_string();
            if let Some(guid) = guid.as_str() {
                m.external_objects
                    .push((field("type"), field("name"), guid.to_string()));
            }
        }
        if let Some(ts) = imp.get("tangentSpace") {
            if let Some(v) = ts.i64_at("normalImportMode") {
                m.normal_import_mode = v;
            }
            if let Some(a) = ts.f32_at("normalSmoothAngle").filter(|a| a.is_finite()) {
                m.normal_smoothing_angle = a;
            }
        }
        m.generation2 = imp
            .path(&["meshes", "fileIdsGeneration"])
            .or_else(|| imp.get("fileIdsGeneration"))
            .and_then(Node::as_i64)
            == Some(2);
        m
    }

    /// Every fileID this meta may use for the object of `class` that Unity names
    /// `name` in its legacy table and in the 2019.1–2019.2 hash, and `path` in the
    /// `fileIdsGeneration: 2` hash. All schemes are registered at once: they cannot
    /// collide in practice, and old projects keep legacy ids after an upgrade.
    pub fn ids(&self, class: u32, name: &str, path: &str) -> Vec<i64> {
        self.ids_nth(class, name, path, (0, 0))
    }

    /// [`Self::ids`] of an object that is the `n.0`-th (from 0) of its class with that
    /// name and the `n.1`-th with that path: Unity's hashes end in that count, so objects
    /// sharing a name get distinct ids.
    pub fn ids_nth(&self, class: u32, name: &str, path: &str, n: (usize, usize)) -> Vec<i64> {
        let mut out = Vec::new();
        for (id, entry) in &self.recycle {
            // Legacy ids are classID·100000 + 2k.
            if entry == name && (*id / 100000) as u32 == class {
                out.push(*id);
            }
        }
        for (c, id, entry) in &self.internal {
            if *c == class && entry == name {
                out.push(*id);
            }
        }
        let cls = class_name(class);
        out.push(hash_id(&format!("Type:{cls}->{name}{}", n.0)));
        out.push(hash_id(&format!("Type:{cls}->{path}{}", n.1)));
        out
    }
}

/// Counts the objects of each class and name (and path) a model has given ids so far,
/// for [`ModelMeta::ids_nth`].
#[derive(Default)]
pub struct IdCounter {
    names: HashMap<(u32, String), usize>,
    paths: HashMap<(u32, String), usize>,
}

impl IdCounter {
    /// Every fileID of the next object of `class` named `name` (hashed by `path` under
    /// `fileIdsGeneration: 2`).
    pub fn ids(&mut self, meta: &ModelMeta, class: u32, name: &str, path: &str) -> Vec<i64> {
        let n = (
            next(&mut self.names, class, name),
            next(&mut self.paths, class, path),
        );
        meta.ids_nth(class, name, path, n)
    }
}

/// The count so far of `key` in `seen`, counting this one.
fn next(seen: &mut HashMap<(u32, String), usize>, class: u32, key: &str) -> usize {
    let n = seen.entry((class, key.to_string())).or_default();
    *n += 1;
    *n - 1
}

/// Unity's hashed fileID: xxHash64 (seed 0) of the identifier string, as i64.
pub fn hash_id(s: &str) -> i64 {
    xxh64(s.as_bytes(), 0) as i64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hashed_ids_match_the_corpus() {
        // fuqunaga/ComputeShaderBVHMeshHit bunny.obj (fileIdsGeneration: 2), and
        // Ayinzhang/Rigidbody-Fracture's PrefabInstance targets of its bunny.obj.
        assert_eq!(hash_id("Type:Mesh->default0"), -2432090755550338912);
        assert_eq!(
            hash_id("Type:GameObject->//RootNode/root0"),
            919132149155446097
        );
        assert_eq!(
            hash_id("Type:Transform->//RootNode/root/Transform0"),
            -8679921383154817045
        );
        assert_eq!(
            hash_id("Type:MeshFilter->//RootNode/root/default/MeshFilter0"),
            -6400281290468069383
        );
        // superdump (2019.2, name hashes): root GameObject, root and child Transforms.
        assert_eq!(hash_id("Type:GameObject->//RootNode0"), -927199367670048503);
        assert_eq!(hash_id("Type:Transform->//RootNode0"), -4216859302048453862);
        assert_eq!(hash_id("Type:Transform->default0"), -5975033157549033438);
    }

    #[test]
    fn links_out_of_assets_and_link_loops_are_not_followed() {
        let dir = tempfile::tempdir().unwrap();
        let assets = dir.path().join("Assets");
        let outside = dir.path().join("outside");
        std::fs::create_dir_all(assets.join("in")).unwrap();
        std::fs::create_dir_all(&outside).unwrap();
        std::fs::write(assets.join("in/a.obj.meta"), "guid: aaaa\n").unwrap();
        std::fs::write(outside.join("b.obj.meta"), "guid: bbbb\n").unwrap();
        std::fs::write(outside.join("c.obj"), "v 0 0 0\n").unwrap();
        std::os::unix::fs::symlink(&outside, assets.join("out")).unwrap();
        std::os::unix::fs::symlink(&assets, assets.join("in/loop")).unwrap();
        // An asset inside whose file is a link out of the project.
        std::os::unix::fs::symlink(outside.join("c.obj"), assets.join("c.obj")).unwrap();
        std::fs::write(assets.join("c.obj.meta"), "guid: cccc\n").unwrap();
        let idx = GuidIndex::build(&assets);
        assert_eq!(idx.map.len(), 1, "{:?}", idx.map);
        assert!(idx.get("aaaa").is_some());
        assert_eq!(idx.warnings.len(), 2, "{:?}", idx.warnings);
        assert!(idx
            .warnings
            .iter()
            .all(|w| w.contains("outside the project")));
    }

    #[test]
    fn objects_sharing_a_name_count_up_in_the_hashes() {
        let meta = ModelMeta::parse("ModelImporter:\n  meshes:\n    fileIdsGeneration: 2\n");
        let mut c = IdCounter::default();
        let first = c.ids(&meta, docs::MESH, "Wheel", "Wheel");
        let second = c.ids(&meta, docs::MESH, "Wheel", "Wheel");
        let other = c.ids(&meta, docs::GAME_OBJECT, "Wheel", "//RootNode/root/Wheel");
        assert_eq!(first, vec![hash_id("Type:Mesh->Wheel0"); 2]);
        assert_eq!(second, vec![hash_id("Type:Mesh->Wheel1"); 2]);
        assert_eq!(other[1], hash_id("Type:GameObject->//RootNode/root/Wheel0"));
    }

    #[test]
    fn legacy_table_and_settings() {
        let text = "fileFormatVersion: 2\nguid: 19cde6fd65027fb4c9c6814597f47199\nModelImporter:\n  serializedVersion: 23\n  fileIDToRecycleName:\n    100000: //RootNode\n    100002: Bunny\n    400000: //RootNode\n    400002: Bunny\n    4300000: default\n    4300002: Bunny\n  meshes:\n    globalScale: 0.007\n";
        let m = ModelMeta::parse(text);
        assert_eq!(m.global_scale, 0.007);
        assert!(!m.generation2);
        assert_eq!(m.ids(docs::MESH, "Bunny", "Bunny")[0], 4300002);
        assert_eq!(
            m.ids(docs::TRANSFORM, "//RootNode", "//RootNode/root/Transform")[0],
            400000
        );
        let g2 = ModelMeta::parse("ModelImporter:\n  internalIDToNameTable:\n  - first:\n      43: 777\n    second: Foo\n  meshes:\n    fileIdsGeneration: 2\n");
        assert!(g2.generation2);
        assert_eq!(g2.ids(docs::MESH, "Foo", "Foo")[0], 777);
        assert_eq!(g2.use_file_scale, None);
        assert_eq!(g2.normal_smoothing_angle, 60.0);
    }

    #[test]
    fn fbx_import_settings() {
        // The layout of GDSJam-Reflection's Animated_door.fbx.meta (2017.2), cut down.
        let text = "ModelImporter:\n  externalObjects:\n  - first:\n      type: UnityEngine:Material\n      assembly: UnityEngine.CoreModule\n      name: 'Material #25'\n    second: {fileID: 2100000, guid: 456775c7489e4bb4cb7e9f37e2ea3fb2, type: 2}\n  materials:\n    importMaterials: 1\n    materialLocation: 0\n  meshes:\n    globalScale: 1.5\n    useFileScale: 1\n    bakeAxisConversion: 1\n  tangentSpace:\n    normalSmoothAngle: 110\n    normalImportMode: 1\n";
        let m = ModelMeta::parse(text);
        assert_eq!(m.global_scale, 1.5);
        assert_eq!(m.use_file_scale, Some(true));
        assert!(m.bake_axis_conversion);
        assert_eq!(m.material_location, Some(0));
        assert_eq!(
            m.external_objects,
            [(
                "UnityEngine:Material".to_string(),
                "Material #25".to_string(),
                "456775c7489e4bb4cb7e9f37e2ea3fb2".to_string()
            )]
        );
        assert_eq!(m.normal_import_mode, 1);
        assert_eq!(m.normal_smoothing_angle, 110.0);
    }
}
