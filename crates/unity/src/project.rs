//! A Unity project on disk: its root, the GUID index, and every read of an asset a scene
//! uses. Each file is read once however many objects use it (scenes and prefabs as bytes,
//! `.mat` files as their parsed Material, models as a [`Model`]); the models a scene can
//! reach are loaded in parallel before the scene is walked.

use crate::docs;
use crate::fbx;
use crate::meta::{GuidIndex, ModelMeta};
use crate::model::Model;
use crate::obj;
use crate::settings::Settings;
use crate::yaml::Node;
use rayon::prelude::*;
use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, OnceLock};

/// An imported model with the `.meta` settings that name its objects.
pub struct ModelAsset {
    pub model: Model,
    pub meta: ModelMeta,
}

/// Why a model asset gives no [`Model`].
#[derive(Clone, Debug, thiserror::Error)]
pub enum ModelError {
    /// A model format this converter has no reader for (the lower-case extension).
    #[error("a .{0} model, which is not converted (only OBJ and FBX models are)")]
    Unsupported(String),
    /// An authoring tool's own file, which Unity imports by running that tool: the
    /// lower-case extension and the tool.
    #[error("a .{0} file; Unity imports it through {1}; export it as FBX")]
    Authoring(String, &'static str),
    /// The reader refused the file (the message names it relative to the project).
    #[error("{0}")]
    Read(String),
}

pub type ModelResult = Arc<Result<ModelAsset, ModelError>>;

/// A file's bytes, or why it could not be read.
pub type FileResult = Arc<std::io::Result<Vec<u8>>>;

/// The Material body of a `.mat` file: `Ok(None)` when it holds none, `Err` with the
/// read error's message.
pub type MatResult = Arc<Result<Option<Node>, String>>;

/// A TerrainData asset as read, or why it could not be (without the file's name).
pub type TerrainResult = Arc<Result<crate::terrain::TerrainData, String>>;

pub struct Project {
    pub root: PathBuf,
    pub assets: PathBuf,
    pub guids: GuidIndex,
    /// What the project's settings say of how it draws.
    pub settings: Settings,
    /// `root` canonicalised once: `rel` runs for every object and message.
    canonical_root: PathBuf,
    files: Mutex<HashMap<PathBuf, FileResult>>,
    models: Mutex<HashMap<PathBuf, ModelResult>>,
    mats: Mutex<HashMap<PathBuf, MatResult>>,
    terrains: Mutex<HashMap<PathBuf, TerrainResult>>,
    by_name: OnceLock<HashMap<String, PathBuf>>,
}

/// The folder holding `Assets/`, walking up from `start`.
pub fn find_root(start: &Path) -> Option<PathBuf> {
    let start = start.canonicalize().ok()?;
    start
        .ancestors()
        .find(|d| d.join("Assets").is_dir())
        .map(Path::to_path_buf)
}

/// A cached value of `cache` under `key`, computed by `make` on first use.
fn cached<V: Clone>(cache: &Mutex<HashMap<PathBuf, V>>, key: &Path, make: impl FnOnce() -> V) -> V {
    if let Some(v) = cache.lock().ok().and_then(|m| m.get(key).cloned()) {
        return v;
    }
    let v = make();
    if let Ok(mut m) = cache.lock() {
        m.insert(key.to_path_buf(), v.clone());
    }
    v
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
        let settings = Settings::read(&root, &guids);
        let canonical_root = root.canonicalize().unwrap_or_else(|_| root.clone());
        Project {
            canonical_root,
            root,
            assets,
            guids,
            settings,
            files: Mutex::default(),
            models: Mutex::default(),
            mats: Mutex::default(),
            terrains: Mutex::default(),
            by_name: OnceLock::new(),
        }
    }

    /// What the converter read of the project's settings, in one line (for `--list`).
    pub fn describe_settings(&self) -> String {
        self.settings.describe(|p| self.rel(p))
    }

    /// A path relative to the project root, with forward slashes (for names and
    /// messages).
    pub fn rel(&self, p: &Path) -> String {
        // Asset paths are built under `root`, so the file system is asked only about a path
        // from elsewhere (through a symlink, or a scene named by a path outside the root).
        let rel = match p
            .strip_prefix(&self.root)
            .or_else(|_| p.strip_prefix(&self.canonical_root))
        {
            Ok(r) => r.to_path_buf(),
            Err(_) => {
                let canon = p.canonicalize().unwrap_or_else(|_| p.to_path_buf());
                match canon.strip_prefix(&self.canonical_root) {
                    Ok(r) => r.to_path_buf(),
                    Err(_) => p.to_path_buf(),
                }
            }
        };
        rel.to_string_lossy().replace('\\', "/")
    }

    pub fn resolve(&self, guid: &str) -> Option<&PathBuf> {
        self.guids.get(guid)
    }

    /// A scene or prefab file's bytes (read once).
    pub fn file(&self, path: &Path) -> FileResult {
        cached(&self.files, path, || Arc::new(std::fs::read(path)))
    }

    /// The Material of a `.mat` file (read and parsed once).
    pub fn mat(&self, path: &Path) -> MatResult {
        cached(&self.mats, path, || {
            Arc::new(match std::fs::read_to_string(path) {
                Ok(text) => Ok(docs::first(&text, docs::MATERIAL)),
                Err(e) => Err(e.to_string()),
            })
        })
    }

    /// TerrainData `id` of the asset at `path` (read once: its trees are planted with the
    /// scene's objects, its heightmap drawn later).
    pub fn terrain_data(&self, path: &Path, id: i64) -> TerrainResult {
        let key = PathBuf::from(format!("{}#{id}", path.display()));
        cached(&self.terrains, &key, || {
            let rel = self.rel(path);
            Arc::new(crate::terrain::load(path, &rel, id).map_err(|why| {
                why.strip_prefix(&format!("{rel}: "))
                    .unwrap_or(&why)
                    .to_string()
            }))
        })
    }

    /// A model (loaded once).
    pub fn model(&self, path: &Path) -> ModelResult {
        cached(&self.models, path, || Arc::new(self.load_model(path)))
    }

    /// The first file named `name` (ASCII case ignored) under the assets folder, in a
    /// depth-first walk of sorted folders; the folders are walked once for all names.
    pub fn find_by_name(&self, name: &str) -> Option<&PathBuf> {
        self.by_name
            .get_or_init(|| index_by_name(&self.assets))
            .get(&name.to_ascii_lowercase())
    }

    /// Load, in parallel, every model referenced by GUID from `scene_text` and from the
    /// prefab files it reaches.
    pub fn preload_models(&self, scene_text: &str) {
        let mut seen = HashSet::new();
        let mut models: Vec<PathBuf> = Vec::new();
        let mut texts = vec![scene_text.to_string()];
        while let Some(t) = texts.pop() {
            for guid in guids_in(&t) {
                if !seen.insert(guid.to_string()) {
                    continue;
                }
                let Some(p) = self.resolve(guid) else {
                    continue;
                };
                if ext(p) != "prefab" {
                    // Whatever is not a model is refused at once, without a read.
                    models.push(p.clone());
                } else if let Ok(bytes) = self.file(p).as_ref() {
                    if let Ok(t) = std::str::from_utf8(bytes) {
                        texts.push(t.to_string());
                    }
                }
            }
        }
        let loaded: Vec<(PathBuf, ModelResult)> = models
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

    /// The one place a model file's format picks its reader. Every model is scaled by
    /// its importer's `globalScale` (the FBX reader folds it into the file's unit scale).
    fn load_model(&self, path: &Path) -> Result<ModelAsset, ModelError> {
        let format = ext(path);
        if !matches!(format.as_str(), "obj" | "fbx") {
            return Err(match authoring_tool(&format) {
                Some(tool) => ModelError::Authoring(format, tool),
                None => ModelError::Unsupported(format),
            });
        }
        let meta = ModelMeta::read(path);
        let model = match format.as_str() {
            "obj" => {
                let mut m = obj::load_in(path, &self.root)
                    .map_err(|e| self.read_error(path, &e))?
                    .to_model();
                m.scale(meta.global_scale);
                m
            }
            _ => {
                let mut m = fbx::load(path, &meta).map_err(|e| self.read_error(path, &e))?;
                for name in m.meshes.iter_mut().flat_map(|x| &mut x.materials) {
                    if name.is_empty() {
                        *name = Model::FBX_UNNAMED_MATERIAL.to_string();
                    }
                }
                m
            }
        };
        Ok(ModelAsset { model, meta })
    }

    /// A reader's error, naming the file relative to the project as every other message
    /// does.
    fn read_error(&self, path: &Path, e: &dyn std::fmt::Display) -> ModelError {
        ModelError::Read(
            e.to_string()
                .replace(&path.display().to_string(), &self.rel(path)),
        )
    }
}

/// The application Unity runs to import an authoring tool's own scene file (it needs
/// that tool installed; the converter has no such route).
fn authoring_tool(ext: &str) -> Option<&'static str> {
    match ext {
        "blend" => Some("Blender"),
        "mb" | "ma" => Some("Maya"),
        "max" => Some("3ds Max"),
        _ => None,
    }
}

/// Lower-case extension.
pub fn ext(p: &Path) -> String {
    p.extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default()
}

/// Lower-case file name → first path in the walk order of [`Project::find_by_name`]. A
/// folder that cannot be listed ends the walk: a search by name never looked past it.
/// Symbolic links are followed as the GUID index follows them: only to what lies inside
/// `dir`, and each real folder once, so a link loop cannot multiply the walk.
fn index_by_name(dir: &Path) -> HashMap<String, PathBuf> {
    let mut index = HashMap::new();
    let Ok(inside) = dir.canonicalize() else {
        return index;
    };
    let mut seen: HashSet<PathBuf> = [inside.clone()].into_iter().collect();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        let Some(entries) = crate::meta::sorted_entries(&d) else {
            break;
        };
        for (p, ty) in entries {
            let is_dir = if ty.is_symlink() || ty.is_dir() {
                match p.canonicalize() {
                    Ok(real) if real.starts_with(&inside) => {
                        if real.is_dir() && !seen.insert(real) {
                            continue; // a folder already walked (a link loop)
                        }
                        p.is_dir()
                    }
                    _ => continue, // dangling, or out of the project
                }
            } else {
                false
            };
            if is_dir {
                stack.push(p);
            } else if let Some(f) = p.file_name() {
                let key = f.to_string_lossy().to_ascii_lowercase();
                index.entry(key).or_insert(p);
            }
        }
    }
    index
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
