//! The scene as a graph of Unity objects, with every prefab instance expanded.
//!
//! A scene or prefab file is loaded into one arena of objects (GameObjects, Transforms
//! and the components the converter uses), each keeping its parsed body. A prefab
//! instance loads its source again (a `.prefab` file, recursively, or a model whose
//! hierarchy is built from the imported [`crate::model::Model`]), applies
//! `m_Modifications` by target fileID, and maps `stripped` placeholders onto the
//! instance's objects, so that added objects and children parented under stripped
//! Transforms link up like any others. Intra-file links (`m_GameObject`, `m_Father`) are
//! resolved to arena indices when a file is loaded, before outer files modify anything.

use crate::docs::{self, Doc};
use crate::project::Project;
use crate::reference::Ref;
use crate::yaml::{self, Node};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

pub use crate::reference::fref;

pub struct Obj {
    pub class: u32,
    pub body: Node,
    pub file_id: i64,
    /// Index into `Graph::files` of the file the object was written in.
    pub file: usize,
    /// Owning GameObject (components and transforms).
    pub go: Option<usize>,
    /// Parent Transform (transforms).
    pub father: Option<usize>,
    /// The root Transform of a tree painted on a terrain: it follows its parent's (the
    /// terrain's) position alone, as the terrain itself does.
    pub on_terrain: bool,
    pub removed: bool,
    /// A MeshFilter's `m_Mesh`.
    pub mesh: Ref,
    /// A renderer's `m_Materials`, one per sub-mesh slot.
    pub materials: Vec<Ref>,
    /// A SkinnedMeshRenderer's `m_Bones`, resolved to Transforms (`None`: a reference
    /// that names no Transform of its file).
    pub bones: Vec<Option<usize>>,
}

pub struct FileCtx {
    pub path: PathBuf,
    /// Shared by every instance of the same prefab (a forest of trees loads one prefab
    /// thousands of times).
    pub text: Arc<str>,
}

impl FileCtx {
    /// A document of this file by fileID, parsed (embedded materials and meshes).
    pub fn doc(&self, file_id: i64) -> Option<(u32, Node)> {
        docs::split(&self.text)
            .into_iter()
            .find(|d| d.file_id == file_id && !d.stripped)
            .map(|d| (d.class, d.parse()))
    }
}

#[derive(Debug, thiserror::Error)]
pub enum LoadError {
    // The I/O error is part of the message, not a `source`: printed with its causes, the
    // reason would appear twice.
    #[error("{path}: {error}")]
    Io {
        path: PathBuf,
        error: std::io::Error,
    },
    #[error("{0}: is a folder, not a scene file")]
    Folder(PathBuf),
    #[error("{0}: the file is empty (0 bytes)")]
    Empty(PathBuf),
    #[error("{0}: is a binary Unity file, not text YAML; in Unity set Edit > Project Settings > Editor > Asset Serialization > Mode to \"Force Text\" and save the scene again")]
    Binary(PathBuf),
    #[error("{0}: is not a Unity scene or prefab (text ones begin with `%YAML` or `--- !u!`)")]
    NotUnity(PathBuf),
    #[error("{0}: holds no Unity objects (no `--- !u!` document header); not a Unity scene")]
    NoDocuments(PathBuf),
}

/// The text of a scene or prefab, refusing empty and binary files.
pub fn read_text(project: &Project, path: &Path) -> Result<String, LoadError> {
    let bytes = project.file(path);
    let bytes = match bytes.as_ref() {
        Ok(b) => b,
        Err(e) => {
            return Err(LoadError::Io {
                path: path.to_path_buf(),
                error: std::io::Error::new(e.kind(), e.to_string()),
            })
        }
    };
    if bytes.is_empty() {
        return Err(LoadError::Empty(path.to_path_buf()));
    }
    if !docs::is_text_yaml(bytes) {
        // Unity's binary serialized files open with big-endian header words whose high
        // bytes are zero; a text file of another kind (UTF-16 too, by its byte order
        // mark) is not a binary scene to re-save as text.
        let head = &bytes[..bytes.len().min(64)];
        let utf16 = head.starts_with(&[0xFF, 0xFE]) || head.starts_with(&[0xFE, 0xFF]);
        return Err(if head.contains(&0) && !utf16 {
            LoadError::Binary(path.to_path_buf())
        } else {
            LoadError::NotUnity(path.to_path_buf())
        });
    }
    let text = String::from_utf8_lossy(bytes).into_owned();
    if !docs::has_document(&text) {
        return Err(LoadError::NoDocuments(path.to_path_buf()));
    }
    Ok(text)
}

/// Documents whose bodies the converter reads: its classes, and of the MonoBehaviours only
/// URP's camera settings (a scene holds many scripts it does not read).
fn wanted(d: &Doc) -> bool {
    if d.class == docs::MONO_BEHAVIOUR {
        return d.body.contains(crate::camera::URP_CAMERA_DATA);
    }
    matches!(
        d.class,
        docs::GAME_OBJECT
            | docs::TRANSFORM
            | docs::RECT_TRANSFORM
            | docs::CAMERA
            | docs::MESH_RENDERER
            | docs::MESH_FILTER
            | docs::LIGHT
            | docs::SKINNED_MESH_RENDERER
            | docs::TERRAIN
            | docs::LOD_GROUP
            | docs::SPRITE_RENDERER
            | docs::TEXT_MESH
            | docs::LINE_RENDERER
            | docs::PARTICLE_SYSTEM_RENDERER
            | docs::TILEMAP_RENDERER
    )
}

pub fn is_transform(class: u32) -> bool {
    class == docs::TRANSFORM || class == docs::RECT_TRANSFORM
}

pub struct Graph<'p> {
    pub project: &'p Project,
    pub objs: Vec<Obj>,
    pub files: Vec<FileCtx>,
    pub warnings: Vec<String>,
    /// The top scene's RenderSettings.
    pub render_settings: Option<Node>,
    /// Prefabs being loaded, outermost first (a prefab that nests itself is refused).
    pub(crate) stack: Vec<PathBuf>,
    /// The text of every prefab loaded so far.
    pub(crate) prefab_texts: HashMap<PathBuf, Arc<str>>,
}

/// A file's objects: source fileID → arena index.
pub type IdMap = HashMap<i64, usize>;

/// What loading one file gathers before its links are resolved.
#[derive(Default)]
struct FileLoad {
    file: usize,
    rel: String,
    /// fileID in this file → arena index (including instances' objects under Unity's
    /// combined ids).
    map: IdMap,
    /// Per prefab instance (by its fileID): its objects by fileID in its source.
    instances: HashMap<i64, IdMap>,
    /// Root Transforms to hang under a Transform of this file (by fileID).
    pending_parents: Vec<(Vec<usize>, i64)>,
    /// Instances whose source is missing: their modifications and parent.
    skipped: HashMap<i64, (Vec<Node>, i64)>,
    /// The file's own objects, in file order.
    own: Vec<usize>,
}

impl<'p> Graph<'p> {
    pub fn new(project: &'p Project) -> Self {
        Graph {
            project,
            objs: Vec::new(),
            files: Vec::new(),
            warnings: Vec::new(),
            render_settings: None,
            stack: Vec::new(),
            prefab_texts: HashMap::new(),
        }
    }

    pub(crate) fn push(&mut self, class: u32, body: Node, file_id: i64, file: usize) -> usize {
        self.objs.push(Obj {
            mesh: Ref::read(body.get("m_Mesh"), file),
            materials: Ref::read_all(body.get("m_Materials"), file),
            class,
            body,
            file_id,
            file,
            go: None,
            father: None,
            on_terrain: false,
            removed: false,
            bones: Vec::new(),
        });
        self.objs.len() - 1
    }

    /// Load the top-level scene, whose `text` the caller has read with [`read_text`].
    pub fn load_scene(&mut self, path: &Path, text: String) {
        self.load_file(path, text.into(), true);
        self.break_parent_cycles();
        self.plant_trees();
    }

    /// A Transform whose `m_Father` chain loops back on itself has no place in the
    /// world. Each loop is cut where it is found (that Transform goes to the root) with
    /// a warning naming every object in the loop, so the objects still convert.
    fn break_parent_cycles(&mut self) {
        // 0 unvisited, 1 on the chain being walked, 2 done.
        let mut state = vec![0u8; self.objs.len()];
        for start in 0..self.objs.len() {
            if state[start] != 0 || !is_transform(self.objs[start].class) {
                continue;
            }
            let mut chain = Vec::new();
            let mut cur = Some(start);
            while let Some(i) = cur {
                if state[i] != 0 {
                    break;
                }
                state[i] = 1;
                chain.push(i);
                cur = self.objs[i].father;
            }
            if let Some(i) = cur.filter(|&i| state[i] == 1) {
                // `i` is on this chain: the loop is chain[pos(i)..], closed by the last.
                let at = chain.iter().position(|&c| c == i).unwrap_or(0);
                let names: Vec<String> = chain[at..]
                    .iter()
                    .map(|&t| format!("'{}'", self.go_name(t)))
                    .collect();
                let last = *chain.last().unwrap_or(&i);
                let file = self
                    .files
                    .get(self.objs[last].file)
                    .map(|f| self.project.rel(&f.path))
                    .unwrap_or_default();
                self.warnings.push(format!(
                    "{file}: object {} (fileID {}): parent cycle ({} -> {}); placed at the root",
                    names.last().cloned().unwrap_or_default(),
                    self.objs[last].file_id,
                    names.join(" -> "),
                    names[0],
                ));
                self.objs[last].father = None;
            }
            for c in chain {
                state[c] = 2;
            }
        }
    }

    /// The GameObject name of a Transform (`?` when it has none).
    fn go_name(&self, t: usize) -> &str {
        self.objs[t]
            .go
            .and_then(|g| self.objs[g].body.str_at("m_Name"))
            .unwrap_or("?")
    }

    /// Load a scene or prefab file; returns fileID → arena index for its objects
    /// (including those of its prefab instances under Unity's combined ids).
    pub(crate) fn load_file(&mut self, path: &Path, text: Arc<str>, top: bool) -> IdMap {
        let file = self.files.len();
        self.files.push(FileCtx {
            path: path.to_path_buf(),
            text: text.clone(),
        });
        let mut f = FileLoad {
            file,
            rel: self.project.rel(path),
            ..FileLoad::default()
        };
        let docs = docs::split(&text);
        self.expand_instances(&docs, &mut f);
        self.place_stand_ins(&docs, &mut f);
        self.read_own_objects(&docs, &text, top, &mut f);
        self.link(&mut f);
        f.map
    }

    /// Every prefab instance of the file, loaded with its modifications applied.
    fn expand_instances(&mut self, docs: &[Doc], f: &mut FileLoad) {
        for d in docs
            .iter()
            .filter(|d| d.class == docs::PREFAB_INSTANCE && !d.stripped)
        {
            let body = d.parse();
            if body.i64_at("m_IsPrefabParent") == Some(1)
                || body.i64_at("m_IsPrefabAsset") == Some(1)
            {
                continue; // a legacy prefab asset's own root, not an instance
            }
            let (smap, roots) = self.instantiate(d, &body, &f.rel);
            let m = body.get("m_Modification");
            let mods = m
                .and_then(|m| m.get("m_Modifications"))
                .map(Node::as_seq)
                .unwrap_or(&[]);
            self.apply_mods(&smap, mods, f.file);
            for key in ["m_RemovedComponents", "m_RemovedGameObjects"] {
                for r in m.and_then(|m| m.get(key)).map(Node::as_seq).unwrap_or(&[]) {
                    if let Some(&idx) = smap.get(&fref(Some(r)).0) {
                        self.objs[idx].removed = true;
                    }
                }
            }
            let (parent, _) = fref(m.and_then(|m| m.get("m_TransformParent")));
            if smap.is_empty() {
                // The source is missing: keep what the scene says about the instance so
                // that stripped placeholders can stand in for its objects.
                f.skipped.insert(d.file_id, (mods.to_vec(), parent));
            }
            f.pending_parents.push((roots, parent));
            for (&id, &i) in &smap {
                f.map.insert((d.file_id ^ id) & i64::MAX, i);
            }
            f.instances.insert(d.file_id, smap);
        }
    }

    /// Stripped placeholders stand for objects of an instance; those of a skipped
    /// instance become stand-in objects of their own.
    fn place_stand_ins(&mut self, docs: &[Doc], f: &mut FileLoad) {
        let mut stand_ins: HashMap<i64, Vec<usize>> = HashMap::new();
        for d in docs.iter().filter(|d| d.stripped) {
            let body = d.parse();
            let corr = fref(
                body.get("m_CorrespondingSourceObject")
                    .or(body.get("m_PrefabParentObject")),
            )
            .0;
            let inst = fref(
                body.get("m_PrefabInstance")
                    .or(body.get("m_PrefabInternal")),
            )
            .0;
            if let Some(&i) = f.instances.get(&inst).and_then(|m| m.get(&corr)) {
                f.map.insert(d.file_id, i);
            } else if let Some((mods, parent)) = f.skipped.get(&inst) {
                // A stand-in for an object of a skipped instance (no geometry): its
                // transform and activity from the modifications, so scene objects
                // parented under it land where Unity puts them. The source's own
                // hierarchy is unknown: a Transform is treated as the instance's root.
                if !(is_transform(d.class) || d.class == docs::GAME_OBJECT) {
                    continue;
                }
                let body = if d.class == docs::GAME_OBJECT {
                    game_object_body("?")
                } else {
                    transform_body(glam::Vec3::ZERO, glam::Quat::IDENTITY, glam::Vec3::ONE)
                };
                let idx = self.push(d.class, body, d.file_id, f.file);
                let one: IdMap = [(corr, idx)].into_iter().collect();
                self.apply_mods(&one, mods, f.file);
                if is_transform(d.class) {
                    f.pending_parents.push((vec![idx], *parent));
                }
                stand_ins.entry(inst).or_default().push(idx);
                f.map.insert(d.file_id, idx);
            }
        }
        // Pair a skipped instance's stand-in Transform with its stand-in GameObject, so
        // an m_IsActive override on it still hides the scene objects under it.
        for objs in stand_ins.values() {
            let go = objs
                .iter()
                .copied()
                .find(|&i| self.objs[i].class == docs::GAME_OBJECT);
            for &i in objs {
                if is_transform(self.objs[i].class) {
                    self.objs[i].go = go;
                }
            }
        }
    }

    /// The file's own (not stripped) objects of the classes the converter reads, and the
    /// top scene's RenderSettings.
    fn read_own_objects(&mut self, docs: &[Doc], text: &str, top: bool, f: &mut FileLoad) {
        for d in docs.iter().filter(|d| !d.stripped) {
            if d.class == docs::RENDER_SETTINGS && top {
                self.render_settings = Some(d.parse());
            }
            if !wanted(d) {
                continue;
            }
            if let Some((line, what)) = yaml::malformed(d.body) {
                // Line numbers count from the file's start: the header line is just
                // before the body.
                let offset = d.body.as_ptr() as usize - text.as_ptr() as usize;
                let first = text[..offset].matches('\n').count() + 1;
                self.warnings.push(format!(
                    "{}:{}: document fileID {} ({}): malformed YAML: {what}; read what could be read",
                    f.rel,
                    first + line - 1,
                    d.file_id,
                    d.body.lines().next().unwrap_or("").trim_end_matches(':'),
                ));
            }
            let idx = self.push(d.class, d.parse(), d.file_id, f.file);
            f.map.insert(d.file_id, idx);
            f.own.push(idx);
        }
    }

    /// Owners and parents of the file's own objects, resolved in its id space, and the
    /// instances' roots hung under their parents.
    fn link(&mut self, f: &mut FileLoad) {
        let mut orphans = Vec::new();
        for &idx in &f.own {
            let (go, _) = fref(self.objs[idx].body.get("m_GameObject"));
            self.objs[idx].go = f.map.get(&go).copied();
            if self.objs[idx].class == docs::SKINNED_MESH_RENDERER {
                let bones = self.objs[idx]
                    .body
                    .get("m_Bones")
                    .map(Node::as_seq)
                    .unwrap_or(&[])
                    .iter()
                    .map(|b| {
                        f.map
                            .get(&fref(Some(b)).0)
                            .copied()
                            .filter(|&t| is_transform(self.objs[t].class))
                    })
                    .collect();
                self.objs[idx].bones = bones;
            }
            if is_transform(self.objs[idx].class) {
                let (father, _) = fref(self.objs[idx].body.get("m_Father"));
                self.objs[idx].father = f.map.get(&father).copied();
                if father != 0 && self.objs[idx].father.is_none() {
                    // Typically a child of a prefab instance that was skipped.
                    orphans.push((idx, father));
                }
            }
        }
        for (idx, father) in orphans {
            let name = self.objs[idx]
                .go
                .and_then(|g| self.objs[g].body.str_at("m_Name"))
                .unwrap_or("?")
                .to_string();
            self.warnings.push(format!(
                "{}: object '{name}' (fileID {}): parent Transform {father} is not converted (its prefab instance was skipped); placed at the root",
                f.rel,
                self.objs[idx].file_id
            ));
        }
        for (roots, parent) in std::mem::take(&mut f.pending_parents) {
            if parent != 0 {
                if let Some(&p) = f.map.get(&parent) {
                    for r in roots {
                        self.objs[r].father = Some(p);
                    }
                }
            }
        }
    }
}

fn scalar(s: impl ToString) -> Node {
    Node::Scalar(s.to_string())
}

/// An active GameObject's body.
pub(crate) fn game_object_body(name: &str) -> Node {
    Node::Map(vec![
        ("m_Name".into(), scalar(name)),
        ("m_IsActive".into(), scalar(1)),
    ])
}

/// A Transform's body with that local position, rotation and scale.
pub(crate) fn transform_body(t: glam::Vec3, r: glam::Quat, s: glam::Vec3) -> Node {
    let xyz = |v: glam::Vec3| {
        Node::Map(vec![
            ("x".into(), scalar(v.x)),
            ("y".into(), scalar(v.y)),
            ("z".into(), scalar(v.z)),
        ])
    };
    Node::Map(vec![
        ("m_LocalPosition".into(), xyz(t)),
        (
            "m_LocalRotation".into(),
            Node::Map(vec![
                ("x".into(), scalar(r.x)),
                ("y".into(), scalar(r.y)),
                ("z".into(), scalar(r.z)),
                ("w".into(), scalar(r.w)),
            ]),
        ),
        ("m_LocalScale".into(), xyz(s)),
    ])
}
