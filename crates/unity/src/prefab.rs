//! Prefab instances: the objects of an instance's source (a `.prefab` file, loaded
//! recursively, or a model) and the instance's modifications applied to them.

use crate::docs::Doc;
use crate::graph::{is_transform, read_text, Graph, IdMap};
use crate::modification;
use crate::project::{ext, ModelError};
use crate::reference::fref;
use crate::yaml::Node;

/// How deep prefabs may nest.
const MAX_NESTING: usize = 32;

/// The most objects a conversion holds. Nesting alone is no bound: ten instances per level,
/// eight levels deep, is a hundred million objects from a 92 KB project. Real scenes hold
/// tens of thousands.
pub(crate) const MAX_OBJECTS: usize = 1_000_000;

impl Graph<'_> {
    /// Apply `m_Modifications` to the objects of one instance (`smap`: source fileID →
    /// arena index). References written without a GUID point into file `file`.
    pub(crate) fn apply_mods(&mut self, smap: &IdMap, mods: &[Node], file: usize) {
        for md in mods {
            if let Some(&idx) = smap.get(&modification::target(md)) {
                modification::apply(&mut self.objs[idx], md, file);
            }
        }
    }

    /// The objects of one instance of `d`'s source prefab or model, keyed by their
    /// fileID in the source, and the instance's root transforms.
    pub(crate) fn instantiate(&mut self, d: &Doc, body: &Node, rel: &str) -> (IdMap, Vec<usize>) {
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
        self.instance_of(&guid, &what)
    }

    /// The objects of one instance of the prefab or model with GUID `guid`, keyed by their
    /// fileID in it, and its root transforms; none, with a warning beginning `what`, when
    /// it cannot be loaded.
    pub(crate) fn instance_of(&mut self, guid: &str, what: &str) -> (IdMap, Vec<usize>) {
        let Some(path) = self.project.resolve(guid).cloned() else {
            self.warnings.push(format!("{what}: source GUID {guid} is not in the project (missing asset or package); skipped"));
            return Default::default();
        };
        let src = self.project.rel(&path);
        if self.objs.len() >= MAX_OBJECTS {
            self.warnings.push(format!(
                "{what}: the scene already holds {} objects, the most a conversion takes; {src} skipped",
                self.objs.len()
            ));
            return Default::default();
        }
        if ext(&path) != "prefab" {
            return self.model_instance(&path, guid, what);
        }
        if self.stack.contains(&path) || self.stack.len() > MAX_NESTING {
            self.warnings
                .push(format!("{what}: {src} nests itself; skipped"));
            return Default::default();
        }
        let text = match self.prefab_texts.get(&path) {
            Some(t) => t.clone(),
            None => match read_text(self.project, &path) {
                Ok(t) => {
                    let t: std::sync::Arc<str> = t.into();
                    self.prefab_texts.insert(path.clone(), t.clone());
                    t
                }
                Err(e) => {
                    self.warnings.push(format!("{what}: {e}; skipped"));
                    return Default::default();
                }
            },
        };
        self.stack.push(path.clone());
        let map = self.load_file(&path, text, false);
        self.stack.pop();
        let mut roots: Vec<usize> = map
            .values()
            .copied()
            .filter(|&i| is_transform(self.objs[i].class) && self.objs[i].father.is_none())
            .collect();
        roots.sort_unstable();
        roots.dedup();
        (map, roots)
    }

    /// The objects of an instance of the model at `path`, or a warning why there are
    /// none.
    fn model_instance(
        &mut self,
        path: &std::path::Path,
        guid: &str,
        what: &str,
    ) -> (IdMap, Vec<usize>) {
        let model = self.project.model(path);
        match model.as_ref() {
            Ok(asset) => {
                if asset.model.meshes.is_empty() {
                    self.warnings.push(format!(
                        "{what}: {} has no faces; nothing to convert",
                        self.project.rel(path)
                    ));
                }
                self.add_model(asset, guid)
            }
            Err(ModelError::Unsupported(ext)) if ext.is_empty() => {
                self.warnings.push(format!(
                    "{what}: source {} is a .unknown model, which is not converted (only OBJ and FBX models are); skipped",
                    self.project.rel(path)
                ));
                Default::default()
            }
            Err(e @ (ModelError::Unsupported(_) | ModelError::Authoring(..))) => {
                self.warnings.push(format!(
                    "{what}: source {} is {e}; skipped",
                    self.project.rel(path)
                ));
                Default::default()
            }
            Err(e) => {
                self.warnings.push(format!("{what}: {e}; skipped"));
                Default::default()
            }
        }
    }
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
