//! A Unity project on disk: its root, the GUID index, and caches of the assets a scene
//! uses (each OBJ is read once however many objects use it; OBJ files are loaded in
//! parallel before the scene is walked).

use crate::meta::{GuidIndex, ModelMeta};
use crate::obj::{self, ObjModel};
use rayon::prelude::*;
use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

pub struct ModelAsset {
    pub obj: ObjModel,
    pub meta: ModelMeta,
}

pub type ModelResult = Arc<Result<ModelAsset, String>>;

pub struct Project {
    pub root: PathBuf,
    pub assets: PathBuf,
    pub guids: GuidIndex,
    /// `Packages/manifest.json` names the High Definition Render Pipeline, whose lights
    /// are in physical units.
    pub hdrp: bool,
    models: Mutex<HashMap<PathBuf, ModelResult>>,
}

/// The folder holding `Assets/`, walking up from `start`.
pub fn find_root(start: &Path) -> Option<PathBuf> {
    let start = start.canonicalize().ok()?;
    start
        .ancestors()
        .find(|d| d.join("Assets").is_dir())
        .map(Path::to_path_buf)
}

impl Project {
    /// `dir` may be the project root (holding `Assets/`) or the `Assets` folder itself.
    pub fn open(dir: &Path) -> Project {
        let (root, assets) = if dir.join("Assets").is_dir() {
            (dir.to_path_buf(), dir.join("Assets"))
        } else {
            (
                dir.parent()
                    .map(Path::to_path_buf)
                    .unwrap_or_else(|| dir.to_path_buf()),
                dir.to_path_buf(),
            )
        };
        let guids = GuidIndex::build(&assets);
        let hdrp = std::fs::read_to_string(root.join("Packages").join("manifest.json"))
            .is_ok_and(|m| m.contains("com.unity.render-pipelines.high-definition"));
        Project {
            root,
            assets,
            guids,
            hdrp,
            models: Mutex::new(HashMap::new()),
        }
    }

    /// A path relative to the project root, with forward slashes (for names and
    /// messages).
    pub fn rel(&self, p: &Path) -> String {
        let canon = p.canonicalize().unwrap_or_else(|_| p.to_path_buf());
        let root = self
            .root
            .canonicalize()
            .unwrap_or_else(|_| self.root.clone());
        canon
            .strip_prefix(&root)
            .unwrap_or(p)
            .to_string_lossy()
            .replace('\\', "/")
    }

    pub fn resolve(&self, guid: &str) -> Option<&PathBuf> {
        self.guids.get(guid)
    }

    /// Load an OBJ model (once).
    pub fn model(&self, path: &Path) -> ModelResult {
        if let Some(m) = self
            .models
            .lock()
            .map(|m| m.get(path).cloned())
            .ok()
            .flatten()
        {
            return m;
        }
        let loaded = Arc::new(self.load_model(path));
        if let Ok(mut m) = self.models.lock() {
            m.insert(path.to_path_buf(), loaded.clone());
        }
        loaded
    }

    /// Load, in parallel, every OBJ referenced by GUID from `scene_text` and from the
    /// prefab files it reaches.
    pub fn preload_models(&self, scene_text: &str) {
        let mut seen = HashSet::new();
        let mut objs: Vec<PathBuf> = Vec::new();
        let mut texts = vec![scene_text.to_string()];
        while let Some(t) = texts.pop() {
            for guid in guids_in(&t) {
                if !seen.insert(guid.to_string()) {
                    continue;
                }
                let Some(p) = self.resolve(guid) else {
                    continue;
                };
                match ext(p).as_str() {
                    "obj" => objs.push(p.clone()),
                    "prefab" => {
                        if let Ok(t) = std::fs::read_to_string(p) {
                            texts.push(t);
                        }
                    }
                    _ => {}
                }
            }
        }
        let loaded: Vec<(PathBuf, ModelResult)> = objs
            .into_par_iter()
            .map(|p| {
                let m = Arc::new(self.load_model(&p));
                (p, m)
            })
            .collect();
        if let Ok(mut m) = self.models.lock() {
            m.extend(loaded);
        }
    }
}

impl Project {
    fn load_model(&self, path: &Path) -> Result<ModelAsset, String> {
        let obj = obj::load_in(path, &self.root).map_err(|e| {
            // Name the file relative to the project, as every other message does.
            e.to_string()
                .replace(&path.display().to_string(), &self.rel(path))
        })?;
        Ok(ModelAsset {
            obj,
            meta: ModelMeta::read(path),
        })
    }
}

/// Lower-case extension.
pub fn ext(p: &Path) -> String {
    p.extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default()
}

fn guids_in(text: &str) -> impl Iterator<Item = &str> {
    text.match_indices("guid: ").filter_map(|(i, _)| {
        let rest = &text[i + 6..];
        let end = rest
            .find(|c: char| !c.is_ascii_hexdigit())
            .unwrap_or(rest.len());
        (end == 32).then(|| &rest[..end])
    })
}
