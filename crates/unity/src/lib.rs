//! `unity2soup`'s library: reads a text-serialized Unity scene with its project (`.meta`
//! GUIDs, `.prefab`, `.mat`, OBJ and FBX models) and produces the world-space, right-handed
//! triangle soup the renderer reads.
//!
//! Stages: [`docs`] splits files into documents, [`yaml`] parses the bodies it needs,
//! [`graph`] builds the object graph with prefab instances expanded, [`emit`] walks it
//! into a [`formats::Soup`]. Every asset read goes through [`project::Project`].

pub mod albedo;
pub mod camera;
pub mod docs;
pub mod embedded;
pub mod emit;
pub mod environment;
pub mod fbx;
mod fbx_pool;
pub mod graph;
pub mod layer;
pub mod light;
pub mod lod;
pub mod material;
pub mod mesh;
pub mod mesh_source;
pub mod meta;
pub mod model;
pub mod model_instance;
pub mod modification;
pub mod obj;
pub mod objexport;
pub mod prefab;
pub mod primitives;
pub mod project;
pub mod quality;
pub mod reference;
pub mod renderer;
pub mod serialized;
pub mod settings;
pub mod skinned_renderer;
pub mod skybox;
pub mod terrain;
pub mod texture;
pub mod transform;
pub mod trees;
mod undrawn;
pub mod yaml;

use formats::Soup;
use std::path::{Path, PathBuf};

#[derive(Debug, thiserror::Error)]
pub enum ConvertError {
    #[error("{0}: no folder holding Assets/ above the scene; pass --assets PROJECT_DIR")]
    NoProject(PathBuf),
    #[error(transparent)]
    Load(#[from] graph::LoadError),
    #[error(transparent)]
    Emit(#[from] emit::EmitError),
    #[error("--strict: {count} warning(s); the first: {first}")]
    Strict { count: usize, first: String },
}

#[derive(Clone, Debug, Default)]
pub struct Options {
    /// Project root (the folder holding `Assets/`) or the `Assets` folder; default: walk
    /// up from the scene.
    pub project: Option<PathBuf>,
    /// Turn warnings into an error.
    pub strict: bool,
    /// The camera to render, by GameObject name or hierarchy path (`Parent/Child`), instead
    /// of the Game view's.
    pub camera: Option<String>,
}

/// A converted scene with the counts the soup does not hold.
pub struct Report {
    pub soup: Soup,
    /// Enabled cameras on active objects (the soup keeps one).
    pub cameras: usize,
    /// Per soup object: each soup material it uses and where the material came from.
    pub material_origins: Vec<Vec<(u32, String)>>,
    /// Renderers Unity does not draw by design (outside the camera's culling mask, in a
    /// LOD level the camera does not show), one line each.
    pub skipped: Vec<String>,
    /// What was read of the project's settings ([`project::Project::settings`]).
    pub settings: String,
}

/// Convert a scene into a sealed soup.
pub fn convert(scene: &Path, opts: &Options) -> Result<Soup, ConvertError> {
    convert_report(scene, opts).map(|r| r.soup)
}

/// [`convert`], also returning counts for diagnostics and tests.
pub fn convert_report(scene: &Path, opts: &Options) -> Result<Report, ConvertError> {
    // A scene that cannot be read is named as such, before the project is looked for.
    match std::fs::metadata(scene) {
        Err(error) => {
            let path = scene.to_path_buf();
            return Err(graph::LoadError::Io { path, error }.into());
        }
        Ok(m) if m.is_dir() => return Err(graph::LoadError::Folder(scene.to_path_buf()).into()),
        Ok(_) => {}
    }
    let root = match &opts.project {
        Some(p) => p.clone(),
        None => {
            let dir = scene.parent().unwrap_or(Path::new("."));
            project::find_root(dir).ok_or_else(|| ConvertError::NoProject(scene.to_path_buf()))?
        }
    };
    let project = project::Project::open(&root);
    // Refuse binary scenes before doing any work.
    let text = graph::read_text(&project, scene)?;
    project.preload_models(&text);
    let mut g = graph::Graph::new(&project);
    g.warnings.extend(project.guids.warnings.iter().cloned());
    g.load_scene(scene, text);
    let scene_rel = project.rel(scene);
    let emit::Emitted {
        mut soup,
        cameras,
        material_origins,
        skipped,
    } = emit::emit(&g, &scene_rel, opts.camera.as_deref())?;
    // Model-level warnings (missing .mtl …), once per model used.
    let mut model_warnings: Vec<String> = Vec::new();
    for f in soup
        .objects
        .iter()
        .map(|o| o.source.split('#').next().unwrap_or(""))
    {
        if let Ok(a) = project.model(&project.root.join(f)).as_ref() {
            for w in &a.model.warnings {
                let w = format!("{f}: {w}");
                if !model_warnings.contains(&w) {
                    model_warnings.push(w);
                }
            }
        }
    }
    soup.warnings.extend(model_warnings);
    if opts.strict && !soup.warnings.is_empty() {
        return Err(ConvertError::Strict {
            count: soup.warnings.len(),
            first: soup.warnings[0].clone(),
        });
    }
    Ok(Report {
        soup,
        cameras,
        material_origins,
        skipped,
        settings: project.describe_settings(),
    })
}
