//! The scene as a graph of Unity objects, with every prefab instance expanded.
//!
//! A scene or prefab file is loaded into one arena of objects (GameObjects, Transforms
//! and the components the converter uses), each keeping its parsed body. A prefab
//! instance loads its source again (a `.prefab` file, recursively, or a model whose
//! hierarchy is synthesised from the OBJ and its `.meta`), applies `m_Modifications` to
//! the bodies by target fileID, and maps `stripped` placeholders onto the instance's
//! objects, so that added objects and children parented under stripped Transforms link
//! up like any others. Intra-file links (`m_GameObject`, `m_Father`) are resolved to arena
//! indices when a file is loaded, before outer files modify anything.

use crate::docs::{self, Doc};
use crate::meta::hash_id;
use crate::project::{ext, Project};
use crate::yaml::{self, Node};
use std::collections::HashMap;
use std::path::{Path, PathBuf};

pub struct Obj {
    pub class: u32,
    pub body: Node,
    pub file_id: i64,
    /// Index into `Graph::files`: where local (guid-less) references in the body point.
    pub ctx: usize,
    /// Owning GameObject (components and transforms).
    pub go: Option<usize>,
    /// Parent Transform (transforms).
    pub father: Option<usize>,
    pub removed: bool,
}

pub struct FileCtx {
    pub path: PathBuf,
    pub text: String,
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
    #[error("{path}: {source}")]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("{0}: the file is empty (0 bytes)")]
    Empty(PathBuf),
    #[error("{0}: is a binary Unity file, not text YAML; in Unity set Edit > Project Settings > Editor > Asset Serialization > Mode to \"Force Text\" and save the scene again")]
    Binary(PathBuf),
}

/// Classes whose bodies the converter reads.
fn wanted(class: u32) -> bool {
    matches!(
        class,
        docs::GAME_OBJECT
            | docs::TRANSFORM
            | docs::RECT_TRANSFORM
            | docs::CAMERA
            | docs::MESH_RENDERER
            | docs::MESH_FILTER
            | docs::LIGHT
            | docs::SKINNED_MESH_RENDERER
            | docs::TERRAIN
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
    stack: Vec<PathBuf>,
}

/// A `{fileID: …, guid: …}` reference.
pub fn fref(node: Option<&Node>) -> (i64, Option<String>) {
    match node {
        Some(n) => (
            n.i64_at("fileID").unwrap_or(0),
            n.str_at("guid")
                .filter(|g| !g.is_empty())
                .map(str::to_string),
        ),
        None => (0, None),
    }
}

fn ref_node(file_id: i64, guid: &str) -> Node {
    Node::Map(vec![
        ("fileID".into(), Node::Scalar(file_id.to_string())),
        ("guid".into(), Node::Scalar(guid.to_string())),
        ("type".into(), Node::Scalar("3".into())),
    ])
}

fn scalar(s: impl ToString) -> Node {
    Node::Scalar(s.to_string())
}

fn xyz(x: f32, y: f32, z: f32) -> Node {
    Node::Map(vec![
        ("x".into(), scalar(x)),
        ("y".into(), scalar(y)),
        ("z".into(), scalar(z)),
    ])
}

/// Set `propertyPath` (e.g. `m_LocalPosition.x`, `m_Materials.Array.data[2]`) in a body.
fn set_path(node: &mut Node, segs: &[&str], value: Node) {
    let Some((&first, rest)) = segs.split_first() else {
        *node = value;
        return;
    };
    if first == "Array" {
        if !matches!(node, Node::Seq(_)) {
            *node = Node::Seq(vec![]);
        }
        let Node::Seq(items) = node else { return };
        let Some(&what) = rest.first() else { return };
        if what == "size" {
            if let Some(n) = value.as_i64().filter(|n| (0..1 << 16).contains(n)) {
                items.resize(n as usize, ref_node(0, ""));
            }
        } else if let Some(i) = what
            .strip_prefix("data[")
            .and_then(|s| s.strip_suffix(']'))
            .and_then(|s| s.parse::<usize>().ok())
            .filter(|&i| i < 1 << 16)
        {
            if items.len() <= i {
                items.resize(i + 1, ref_node(0, ""));
            }
            set_path(&mut items[i], &rest[1..], value);
        }
        return;
    }
    if !matches!(node, Node::Map(_)) {
        *node = Node::Map(vec![]);
    }
    let Node::Map(kv) = node else { return };
    let i = match kv.iter().position(|(k, _)| k == first) {
        Some(i) => i,
        None => {
            kv.push((first.to_string(), Node::Scalar(String::new())));
            kv.len() - 1
        }
    };
    set_path(&mut kv[i].1, rest, value);
}

/// Tag a guid-less reference with the file it was written in.
fn tag_local(mut r: Node, ctx: usize) -> Node {
    let (id, guid) = fref(Some(&r));
    if id != 0 && guid.is_none() {
        if let Node::Map(kv) = &mut r {
            kv.push(("@ctx".into(), scalar(ctx)));
        }
    }
    r
}

/// The file a reference inside `obj`'s body points into.
pub fn ref_ctx(r: &Node, obj: &Obj) -> usize {
    r.str_at("@ctx")
        .and_then(|s| s.parse().ok())
        .unwrap_or(obj.ctx)
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
        }
    }

    fn push(&mut self, class: u32, body: Node, file_id: i64, ctx: usize) -> usize {
        self.objs.push(Obj {
            class,
            body,
            file_id,
            ctx,
            go: None,
            father: None,
            removed: false,
        });
        self.objs.len() - 1
    }

    /// Load the top-level scene.
    pub fn load_scene(&mut self, path: &Path) -> Result<(), LoadError> {
        self.load_file(path, true)?;
        self.break_parent_cycles();
        Ok(())
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
                    .get(self.objs[last].ctx)
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
    fn load_file(&mut self, path: &Path, top: bool) -> Result<HashMap<i64, usize>, LoadError> {
        let bytes = std::fs::read(path).map_err(|source| LoadError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        if bytes.is_empty() {
            return Err(LoadError::Empty(path.to_path_buf()));
        }
        if !docs::is_text_yaml(&bytes) {
            return Err(LoadError::Binary(path.to_path_buf()));
        }
        let text = String::from_utf8_lossy(&bytes).into_owned();
        let ctx = self.files.len();
        self.files.push(FileCtx {
            path: path.to_path_buf(),
            text: String::new(),
        });
        let rel = self.project.rel(path);
        let docs = docs::split(&text);
        let mut map: HashMap<i64, usize> = HashMap::new();
        let mut instances: HashMap<i64, HashMap<i64, usize>> = HashMap::new();
        let mut pending_parents: Vec<(Vec<usize>, i64)> = Vec::new();
        let mut skipped: HashMap<i64, (Vec<Node>, i64)> = HashMap::new();

        // 1. Prefab instances.
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
            let (smap, roots) = self.instantiate(d, &body, &rel);
            let m = body.get("m_Modification");
            let mods = m
                .and_then(|m| m.get("m_Modifications"))
                .map(Node::as_seq)
                .unwrap_or(&[]);
            self.apply_mods(&smap, mods, ctx);
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
                // that stripped placeholders can stand in for its objects (step 2).
                skipped.insert(d.file_id, (mods.to_vec(), parent));
            }
            pending_parents.push((roots, parent));
            for (&f, &i) in &smap {
                map.insert((d.file_id ^ f) & i64::MAX, i);
            }
            instances.insert(d.file_id, smap);
        }

        // 2. Stripped placeholders stand for objects of an instance.
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
            if let Some(&i) = instances.get(&inst).and_then(|m| m.get(&corr)) {
                map.insert(d.file_id, i);
            } else if let Some((mods, parent)) = skipped.get(&inst) {
                // A stand-in for an object of a skipped instance (no geometry): its
                // transform and activity from the modifications, so scene objects
                // parented under it land where Unity puts them. The source's own
                // hierarchy is unknown: a Transform is treated as the instance's root.
                if !(is_transform(d.class) || d.class == docs::GAME_OBJECT) {
                    continue;
                }
                let body = if d.class == docs::GAME_OBJECT {
                    Node::Map(vec![
                        ("m_Name".into(), scalar("?")),
                        ("m_IsActive".into(), scalar(1)),
                    ])
                } else {
                    identity_transform()
                };
                let idx = self.push(d.class, body, d.file_id, ctx);
                let one: HashMap<i64, usize> = [(corr, idx)].into_iter().collect();
                self.apply_mods(&one, mods, ctx);
                if is_transform(d.class) {
                    pending_parents.push((vec![idx], *parent));
                }
                stand_ins.entry(inst).or_default().push(idx);
                map.insert(d.file_id, idx);
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

        // 3. The file's own objects.
        let mut own = Vec::new();
        for d in docs.iter().filter(|d| !d.stripped) {
            if d.class == docs::RENDER_SETTINGS && top {
                self.render_settings = Some(d.parse());
            }
            if !wanted(d.class) {
                continue;
            }
            if let Some((line, what)) = yaml::malformed(d.body) {
                // Line numbers count from the file's start: the header line is just
                // before the body.
                let offset = d.body.as_ptr() as usize - text.as_ptr() as usize;
                let first = text[..offset].matches('\n').count() + 1;
                self.warnings.push(format!(
                    "{rel}:{}: document fileID {} ({}): malformed YAML: {what}; read what could be read",
                    first + line - 1,
                    d.file_id,
                    d.body.lines().next().unwrap_or("").trim_end_matches(':'),
                ));
            }
            let idx = self.push(d.class, d.parse(), d.file_id, ctx);
            map.insert(d.file_id, idx);
            own.push(idx);
        }

        // 4. Links, resolved in this file's id space.
        let mut orphans = Vec::new();
        for &idx in &own {
            let (go, _) = fref(self.objs[idx].body.get("m_GameObject"));
            self.objs[idx].go = map.get(&go).copied();
            if is_transform(self.objs[idx].class) {
                let (f, _) = fref(self.objs[idx].body.get("m_Father"));
                self.objs[idx].father = map.get(&f).copied();
                if f != 0 && self.objs[idx].father.is_none() {
                    // Typically a child of a prefab instance that was skipped.
                    orphans.push((idx, f));
                }
            }
        }
        for (idx, f) in orphans {
            let name = self.objs[idx]
                .go
                .and_then(|g| self.objs[g].body.str_at("m_Name"))
                .unwrap_or("?")
                .to_string();
            self.warnings.push(format!(
                "{rel}: object '{name}' (fileID {}): parent Transform {f} is not converted (its prefab instance was skipped); placed at the root",
                self.objs[idx].file_id
            ));
        }
        for (roots, parent) in pending_parents {
            if parent != 0 {
                if let Some(&p) = map.get(&parent) {
                    for r in roots {
                        self.objs[r].father = Some(p);
                    }
                }
            }
        }
        self.files[ctx].text = text;
        Ok(map)
    }

    /// Apply `m_Modifications` to the objects of one instance (`smap`: source fileID →
    /// arena index). References written without a GUID point into file `ctx`.
    fn apply_mods(&mut self, smap: &HashMap<i64, usize>, mods: &[Node], ctx: usize) {
        for md in mods {
            let (target, _) = fref(md.get("target"));
            let Some(&idx) = smap.get(&target) else {
                continue;
            };
            let Some(prop) = md.str_at("propertyPath") else {
                continue;
            };
            let value = md.str_at("value").unwrap_or("");
            let objref = md.get("objectReference");
            let (ref_id, _) = fref(objref);
            let new = if value.is_empty() && (ref_id != 0 || is_ref_path(prop)) {
                tag_local(objref.cloned().unwrap_or(ref_node(0, "")), ctx)
            } else {
                scalar(value)
            };
            let segs: Vec<&str> = prop.split('.').collect();
            set_path(&mut self.objs[idx].body, &segs, new);
        }
    }

    /// The objects of one instance of `d`'s source prefab or model, keyed by their
    /// fileID in the source, and the instance's root transforms.
    fn instantiate(
        &mut self,
        d: &Doc,
        body: &Node,
        rel: &str,
    ) -> (HashMap<i64, usize>, Vec<usize>) {
        let (_, guid) = fref(body.get("m_SourcePrefab").or(body.get("m_ParentPrefab")));
        let source_stem = guid
            .as_deref()
            .and_then(|g| self.project.resolve(g))
            .and_then(|p| p.file_stem())
            .map(|s| s.to_string_lossy().into_owned());
        let name = instance_name(body)
            .or(source_stem)
            .unwrap_or_else(|| "?".into());
        let what = format!("{rel}: prefab instance '{name}' (fileID {})", d.file_id);
        let Some(guid) = guid else {
            self.warnings
                .push(format!("{what}: has no source prefab; skipped"));
            return Default::default();
        };
        let Some(path) = self.project.resolve(&guid).cloned() else {
            self.warnings.push(format!("{what}: source GUID {guid} is not in the project (missing asset or package); skipped"));
            return Default::default();
        };
        let src = self.project.rel(&path);
        match ext(&path).as_str() {
            "prefab" => {
                if self.stack.contains(&path) || self.stack.len() > 32 {
                    self.warnings
                        .push(format!("{what}: {src} nests itself; skipped"));
                    return Default::default();
                }
                self.stack.push(path.clone());
                let r = self.load_file(&path, false);
                self.stack.pop();
                match r {
                    Ok(map) => {
                        let mut roots: Vec<usize> = map
                            .values()
                            .copied()
                            .filter(|&i| {
                                is_transform(self.objs[i].class) && self.objs[i].father.is_none()
                            })
                            .collect();
                        roots.sort_unstable();
                        roots.dedup();
                        (map, roots)
                    }
                    Err(e) => {
                        self.warnings.push(format!("{what}: {e}; skipped"));
                        Default::default()
                    }
                }
            }
            "obj" => self.model_instance(&path, &guid, &what),
            other => {
                let kind = if other.is_empty() { "unknown" } else { other };
                self.warnings.push(format!(
                    "{what}: source {src} is a .{kind} model, which is not converted (only OBJ models are); skipped"
                ));
                Default::default()
            }
        }
    }

    /// Synthesise the hierarchy Unity builds for an OBJ: a root node named after the file
    /// and one child per group with MeshFilter + MeshRenderer, each object registered
    /// under every fileID the model's `.meta` implies.
    fn model_instance(
        &mut self,
        path: &Path,
        guid: &str,
        what: &str,
    ) -> (HashMap<i64, usize>, Vec<usize>) {
        let model = self.project.model(path);
        let asset = match model.as_ref() {
            Ok(a) => a,
            Err(e) => {
                self.warnings.push(format!("{what}: {e}; skipped"));
                return Default::default();
            }
        };
        if asset.obj.groups.is_empty() {
            self.warnings.push(format!(
                "{what}: {} has no faces; nothing to convert",
                self.project.rel(path)
            ));
        }
        let ctx = usize::MAX; // synthesised objects hold no local references
        let meta = &asset.meta;
        let stem = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        let mut map = HashMap::new();
        let go_body = |name: &str| {
            Node::Map(vec![
                ("m_Name".into(), scalar(name)),
                ("m_IsActive".into(), scalar(1)),
            ])
        };
        let root_go = self.push(docs::GAME_OBJECT, go_body(&stem), 0, ctx);
        let root_tf = self.push(docs::TRANSFORM, identity_transform(), 0, ctx);
        self.objs[root_tf].go = Some(root_go);
        for id in meta.ids(1, "//RootNode", "//RootNode/root") {
            map.insert(id, root_go);
        }
        for id in meta.ids(4, "//RootNode", "//RootNode/root/Transform") {
            map.insert(id, root_tf);
        }
        for g in &asset.obj.groups {
            let n = &g.name;
            let p = format!("//RootNode/root/{n}");
            let go = self.push(docs::GAME_OBJECT, go_body(n), 0, ctx);
            let tf = self.push(docs::TRANSFORM, identity_transform(), 0, ctx);
            self.objs[tf].go = Some(go);
            self.objs[tf].father = Some(root_tf);
            let mesh_id = meta.ids(43, n, n)[0];
            let mf = self.push(
                docs::MESH_FILTER,
                Node::Map(vec![("m_Mesh".into(), ref_node(mesh_id, guid))]),
                0,
                ctx,
            );
            let mats = g
                .materials
                .iter()
                .map(|m| ref_node(meta.ids(21, &model_material_name(m), "")[0], guid))
                .collect();
            let mr = self.push(
                docs::MESH_RENDERER,
                Node::Map(vec![
                    ("m_Enabled".into(), scalar(1)),
                    ("m_Materials".into(), Node::Seq(mats)),
                ]),
                0,
                ctx,
            );
            self.objs[mf].go = Some(go);
            self.objs[mr].go = Some(go);
            for (class, idx, suffix) in [
                (1, go, ""),
                (4, tf, "/Transform"),
                (33, mf, "/MeshFilter"),
                (23, mr, "/MeshRenderer"),
            ] {
                for id in meta.ids(class, n, &format!("{p}{suffix}")) {
                    map.entry(id).or_insert(idx);
                }
            }
        }
        (map, vec![root_tf])
    }
}

fn identity_transform() -> Node {
    Node::Map(vec![
        ("m_LocalPosition".into(), xyz(0.0, 0.0, 0.0)),
        (
            "m_LocalRotation".into(),
            Node::Map(vec![
                ("x".into(), scalar(0)),
                ("y".into(), scalar(0)),
                ("z".into(), scalar(0)),
                ("w".into(), scalar(1)),
            ]),
        ),
        ("m_LocalScale".into(), xyz(1.0, 1.0, 1.0)),
    ])
}

/// The name Unity gives a model's material for a `usemtl` name (none → `defaultMat`).
pub fn model_material_name(usemtl: &str) -> String {
    if usemtl.is_empty() {
        "defaultMat".into()
    } else {
        usemtl.to_string()
    }
}

/// The fileID a synthesised renderer uses for a model material when the meta has none.
pub fn model_material_hash(name: &str) -> i64 {
    hash_id(&format!("Type:Material->{name}0"))
}

fn is_ref_path(prop: &str) -> bool {
    prop == "m_Mesh" || prop.starts_with("m_Materials.Array.data[")
}

/// The instance's name: its `m_Name` override, else its source's name.
fn instance_name(body: &Node) -> Option<String> {
    body.path(&["m_Modification", "m_Modifications"])
        .map(Node::as_seq)
        .unwrap_or(&[])
        .iter()
        .find(|m| m.str_at("propertyPath") == Some("m_Name"))
        .and_then(|m| m.str_at("value"))
        .map(str::to_string)
}
