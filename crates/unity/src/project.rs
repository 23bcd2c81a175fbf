//! A Unity project on disk: its root, the GUID index, and every read of an asset a scene
//! uses. Each file is read once however many objects use it (scenes and prefabs as bytes,
//! `.mat` files as their parsed Material, models as a [`Model`]); the models a scene can
//! reach are loaded in parallel before the scene is walked.

use crate::docs;
use crate::fbx;
use crate::light::{LightUnits, UniversalAsset};
use crate::meta::{GuidIndex, ModelMeta};
use crate::model::Model;
use crate::obj;
use crate::quality::ShadowQuality;
use crate::yaml::Node;
use formats::ColorSpace;
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

/// The render pipeline a project draws with. Its lights, sky and fog follow that
/// pipeline's rules, so a scene renders as its own editor shows it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Pipeline {
    BuiltIn,
    /// The Universal Render Pipeline, or the Lightweight one it grew from.
    Universal,
    /// The High Definition Render Pipeline: lights in physical units, sky and fog in
    /// Volumes.
    HighDefinition,
}

impl Pipeline {
    /// The pipeline's name in messages.
    pub fn name(self) -> &'static str {
        match self {
            Pipeline::BuiltIn => "the built-in render pipeline",
            Pipeline::Universal => "URP",
            Pipeline::HighDefinition => "HDRP",
        }
    }

    /// The pipeline whose package a `Packages/manifest.json` lists (an installed pipeline
    /// package is, in practice, the one the project's graphics settings use).
    pub fn of_manifest(text: &str) -> Pipeline {
        let lists = |package: &str| text.contains(&format!("\"{package}\""));
        if lists("com.unity.render-pipelines.high-definition") {
            Pipeline::HighDefinition
        } else if lists("com.unity.render-pipelines.universal")
            || lists("com.unity.render-pipelines.lightweight")
        {
            Pipeline::Universal
        } else {
            Pipeline::BuiltIn
        }
    }
}

/// Settings files are a few kilobytes; a larger one (a GUID that names some other
/// asset, a damaged file) is not read whole, and its settings count as unknown.
const SETTINGS_BYTES: u64 = 16 << 20;

/// A settings file's text (invalid UTF-8 replaced), or `None` when it is missing,
/// unreadable or larger than [`SETTINGS_BYTES`].
fn settings_text(path: &Path) -> Option<String> {
    use std::io::Read;
    let mut bytes = Vec::new();
    std::fs::File::open(path)
        .ok()?
        .take(SETTINGS_BYTES + 1)
        .read_to_end(&mut bytes)
        .ok()?;
    (bytes.len() as u64 <= SETTINGS_BYTES).then(|| String::from_utf8_lossy(&bytes).into_owned())
}

/// The render pipeline asset a project's settings assign.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum PipelineAsset {
    /// The graphics settings are absent or do not say: only the manifest tells.
    Unknown,
    /// Neither the current quality level nor `GraphicsSettings.asset` assigns one: a
    /// pipeline package alone leaves Unity drawing with the built-in pipeline.
    Unassigned,
    /// The current quality level's asset, else `GraphicsSettings.asset`'s default
    /// (`m_CustomRenderPipeline`), by GUID.
    Assigned(Option<String>),
}

impl PipelineAsset {
    pub fn of(graphics: Option<&str>, quality: Option<&str>) -> PipelineAsset {
        if let Some((id, guid)) = quality.and_then(crate::quality::render_pipeline_asset) {
            if id != 0 {
                return PipelineAsset::Assigned(guid);
            }
        }
        let default = graphics.and_then(|text| {
            let body = docs::split(text)
                .into_iter()
                .find(|d| d.class == docs::GRAPHICS_SETTINGS)?
                .parse();
            Some(crate::reference::fref(Some(
                body.get("m_CustomRenderPipeline")?,
            )))
        });
        match default {
            None => PipelineAsset::Unknown,
            Some((0, _)) => PipelineAsset::Unassigned,
            Some((_, guid)) => PipelineAsset::Assigned(guid),
        }
    }
}

/// The colour space a `ProjectSettings.asset` text sets (`m_ActiveColorSpace` 0 Gamma, 1
/// Linear); Linear where it does not say.
pub fn color_space(text: &str) -> ColorSpace {
    let gamma = docs::split(text)
        .into_iter()
        .find(|d| d.class == docs::PLAYER_SETTINGS)
        .is_some_and(|d| d.parse().i64_at("m_ActiveColorSpace") == Some(0));
    if gamma {
        ColorSpace::Gamma
    } else {
        ColorSpace::Linear
    }
}

pub struct Project {
    pub root: PathBuf,
    pub assets: PathBuf,
    pub guids: GuidIndex,
    /// The render pipeline `Packages/manifest.json` names, unless the graphics settings
    /// assign no pipeline asset (then the built-in one).
    pub pipeline: Pipeline,
    /// The pipeline the manifest lists where no asset assigns it, for a warning.
    pub unassigned_pipeline: Option<Pipeline>,
    /// The assigned render pipeline asset's file, where the project holds it.
    pub pipeline_asset: Option<PathBuf>,
    /// What a URP project's assigned pipeline asset lets lights do, where it is found.
    pub universal_asset: Option<UniversalAsset>,
    /// How lights' colours and intensities combine, from the pipeline and
    /// `ProjectSettings/GraphicsSettings.asset`.
    pub light_units: LightUnits,
    /// A built-in project without `ProjectSettings/GraphicsSettings.asset`, whose lights take
    /// Unity's default units.
    pub light_units_assumed: bool,
    /// The colour space `ProjectSettings/ProjectSettings.asset` sets (absent: linear).
    pub color_space: ColorSpace,
    /// The realtime shadows the current quality level allows a built-in project (`All` for
    /// URP and HDRP, whose pipeline assets decide, and where the file does not say).
    pub shadow_quality: ShadowQuality,
    /// `ProjectSettings/QualitySettings.asset`'s lodBias at its current quality level; 1
    /// when the file is absent or does not say (see [`crate::lod`]).
    pub lod_bias: f32,
    /// `root` canonicalised once: `rel` runs for every object and message.
    canonical_root: PathBuf,
    files: Mutex<HashMap<PathBuf, FileResult>>,
    models: Mutex<HashMap<PathBuf, ModelResult>>,
    mats: Mutex<HashMap<PathBuf, MatResult>>,
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
        let settings = |name: &str| settings_text(&root.join("ProjectSettings").join(name));
        let quality = settings("QualitySettings.asset");
        let graphics = settings("GraphicsSettings.asset");
        let listed = std::fs::read_to_string(root.join("Packages").join("manifest.json"))
            .map_or(Pipeline::BuiltIn, |m| Pipeline::of_manifest(&m));
        let asset = PipelineAsset::of(graphics.as_deref(), quality.as_deref());
        let pipeline = match asset {
            PipelineAsset::Unassigned => Pipeline::BuiltIn,
            _ => listed,
        };
        let pipeline_asset = match &asset {
            PipelineAsset::Assigned(Some(guid)) => guids.get(guid).cloned(),
            _ => None,
        };
        let universal_asset = pipeline_asset
            .as_deref()
            .filter(|_| pipeline == Pipeline::Universal)
            .and_then(settings_text)
            .and_then(|text| UniversalAsset::of_asset(&text));
        let unassigned_pipeline = (pipeline != listed).then_some(listed);
        let lod_bias = quality
            .as_deref()
            .and_then(crate::quality::lod_bias)
            .unwrap_or(1.0);
        let shadow_quality = quality
            .as_deref()
            .filter(|_| pipeline == Pipeline::BuiltIn)
            .and_then(crate::quality::shadows)
            .unwrap_or(ShadowQuality::All);
        let light_units_assumed = pipeline == Pipeline::BuiltIn && graphics.is_none();
        let color_space = settings("ProjectSettings.asset")
            .as_deref()
            .map_or(ColorSpace::Linear, color_space);
        let light_units = LightUnits::of(pipeline, graphics.as_deref(), color_space);
        let canonical_root = root.canonicalize().unwrap_or_else(|_| root.clone());
        Project {
            canonical_root,
            root,
            assets,
            guids,
            pipeline,
            unassigned_pipeline,
            pipeline_asset,
            universal_asset,
            light_units,
            light_units_assumed,
            color_space,
            shadow_quality,
            lod_bias,
            files: Mutex::default(),
            models: Mutex::default(),
            mats: Mutex::default(),
            by_name: OnceLock::new(),
        }
    }

    /// What the converter read of the project's settings, in one line (for `--list`).
    pub fn settings(&self) -> String {
        let on = |b: bool| if b { "on" } else { "off" };
        let mut pipeline = self.pipeline.name().to_string();
        if let Some(path) = &self.pipeline_asset {
            pipeline += &format!(" (asset {}", self.rel(path));
            if let Some(u) = self.universal_asset {
                pipeline += &format!(
                    ": main light {}, additional lights {}, main-light shadows {}, \
                     additional-light shadows {}, soft shadows {}",
                    on(u.main_light),
                    on(u.additional_lights),
                    on(u.main_shadows),
                    on(u.additional_shadows),
                    on(u.soft_shadows)
                );
            }
            pipeline += ")";
        }
        let units = self.light_units;
        let intensity = if units.gamma_space {
            "as stored (gamma space)"
        } else if units.linear_intensity {
            "linear"
        } else {
            "gamma"
        };
        let assumed = if self.light_units_assumed {
            ", no GraphicsSettings.asset: Unity's default"
        } else {
            ""
        };
        let space = match self.color_space {
            ColorSpace::Gamma => "Gamma",
            ColorSpace::Linear => "linear",
        };
        let shadows = match self.pipeline {
            Pipeline::BuiltIn => format!("; quality-level shadows {:?}", self.shadow_quality),
            _ => String::new(),
        };
        format!(
            "{pipeline}; light intensity {intensity}, colour temperature {}{assumed}; colour space {space}{shadows}; LOD bias {}",
            on(units.linear_intensity && units.color_temperature && !units.gamma_space),
            self.lod_bias
        )
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
                Ok(text) => Ok(docs::split(&text)
                    .into_iter()
                    .find(|d| d.class == docs::MATERIAL)
                    .map(|d| d.parse())),
                Err(e) => Err(e.to_string()),
            })
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn settings_files_are_read_up_to_a_bound() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("QualitySettings.asset");
        std::fs::write(&path, "m_CurrentQuality: 0\n").unwrap();
        assert_eq!(
            settings_text(&path).as_deref(),
            Some("m_CurrentQuality: 0\n")
        );
        let f = std::fs::File::create(&path).unwrap();
        f.set_len(SETTINGS_BYTES).unwrap();
        assert_eq!(
            settings_text(&path).map(|t| t.len()),
            Some(SETTINGS_BYTES as usize)
        );
        f.set_len(SETTINGS_BYTES + 1).unwrap();
        assert_eq!(settings_text(&path), None);
        assert_eq!(settings_text(&dir.path().join("absent")), None);
    }
}
