//! From the object graph to the soup: walks the active GameObjects and hands each
//! component to the file of its Unity concept ([`crate::transform`],
//! [`crate::renderer`], [`crate::skinned_renderer`], [`crate::mesh_source`],
//! [`crate::material`], [`crate::light`],
//! [`crate::camera`], [`crate::environment`]). The soup is right-handed: Unity's x is
//! negated and every triangle's winding reversed.

use crate::docs;
use crate::graph::{is_transform, Graph, Obj};
use crate::material::linear_to_srgb;
use crate::mesh::Mesh;
use crate::settings::Pipeline;
use formats::{ColorSpace, Soup};
use glam::{Mat4, Vec3};
use std::collections::HashMap;
use std::sync::Arc;

#[derive(Debug, thiserror::Error)]
pub enum EmitError {
    #[error("{file}: object '{object}' (fileID {file_id}): {detail}")]
    NonFinite {
        file: String,
        object: String,
        file_id: i64,
        detail: String,
    },
    #[error("{file}: no enabled camera is named '{asked}'; the enabled cameras: {cameras}")]
    NoSuchCamera {
        file: String,
        asked: String,
        cameras: String,
    },
}

/// Unity space → soup space for points and directions.
pub(crate) fn flip(v: Vec3) -> Vec3 {
    Vec3::new(-v.x, v.y, v.z)
}

/// The soup being built and what is looked up more than once on the way.
pub(crate) struct Emitter<'g, 'p> {
    pub(crate) g: &'g Graph<'p>,
    pub(crate) scene_rel: &'g str,
    pub(crate) soup: Soup,
    /// GameObject → its Transform.
    pub(crate) go_tf: HashMap<usize, usize>,
    /// GameObject → its components (not removed ones), in file order.
    pub(crate) go_comps: HashMap<usize, Vec<usize>>,
    /// Transform → local-to-world.
    pub(crate) world: HashMap<usize, Mat4>,
    /// Mesh source key → mesh (`None`: a built-in id without a mesh).
    pub(crate) meshes: HashMap<String, Option<Arc<Mesh>>>,
    /// Material source key → soup material index.
    pub(crate) materials: HashMap<String, u32>,
    /// Texture file and import settings → index into `pending_textures`.
    pub(crate) textures: HashMap<String, u32>,
    /// The images materials use, in first-use order, decoded at the end.
    pub(crate) pending_textures: Vec<crate::albedo::PendingTexture>,
    /// (model, texture name as the model writes it) → the file found for it: the search
    /// walks folders, and every instance of a model asks again.
    pub(crate) model_textures: HashMap<(std::path::PathBuf, String), Option<std::path::PathBuf>>,
    /// Per soup object: each soup material it uses and where the slot's material came
    /// from.
    pub(crate) material_origins: Vec<Vec<(u32, String)>>,
    /// (model, material name) → the extracted `.mat` found for it, if any: the search
    /// walks folders, and every instance of a model asks again.
    pub(crate) extracted: HashMap<(std::path::PathBuf, String), Option<std::path::PathBuf>>,
    /// The chosen camera's culling mask (see [`crate::layer`]).
    pub(crate) camera_mask: u32,
    /// The chosen camera's Unity-space position and projection, which pick each
    /// LODGroup's level (see [`crate::lod`]); `None` when the scene has no camera.
    pub(crate) lod_camera: Option<(Vec3, formats::Projection)>,
    /// Renderers not drawn by Unity's own rules, one line each for `--list`.
    pub(crate) skipped: Vec<String>,
    /// The meshes drawn so far, placed into the soup at the end.
    pub(crate) placements: crate::renderer::Placements,
    /// Per soup light: the file and fileID of its Light component (RenderSettings names
    /// the sun so).
    pub(crate) light_ids: Vec<(usize, i64)>,
    /// The chosen camera renders shadows (a URP camera's Render Shadows can turn them off).
    pub(crate) camera_shadows: bool,
}

/// What [`emit`] produces.
pub struct Emitted {
    pub soup: Soup,
    /// Enabled cameras on active objects (the soup keeps one).
    pub cameras: usize,
    /// Per soup object: each soup material it uses and where it came from (a renderer
    /// override, a model importer remap, a `Materials/` folder, the model's own, or the
    /// default).
    pub material_origins: Vec<Vec<(u32, String)>>,
    /// Renderers Unity does not draw by design (outside the camera's culling mask, in a
    /// LOD level the camera does not show), one line each.
    pub skipped: Vec<String>,
}

/// The soup, how many enabled cameras on active objects the scene has, where the
/// objects' materials came from, and the renderers skipped by Unity's draw rules.
pub fn emit(g: &Graph, scene_rel: &str, camera: Option<&str>) -> Result<Emitted, EmitError> {
    let mut e = Emitter {
        g,
        scene_rel,
        soup: Soup::empty(),
        go_tf: HashMap::new(),
        go_comps: HashMap::new(),
        world: HashMap::new(),
        meshes: HashMap::new(),
        materials: HashMap::new(),
        textures: HashMap::new(),
        pending_textures: Vec::new(),
        model_textures: HashMap::new(),
        material_origins: Vec::new(),
        extracted: HashMap::new(),
        camera_mask: crate::layer::EVERYTHING,
        lod_camera: None,
        skipped: Vec::new(),
        placements: Default::default(),
        light_ids: Vec::new(),
        camera_shadows: true,
    };
    e.soup.warnings = g.warnings.clone();
    for (i, o) in g.objs.iter().enumerate() {
        let Some(go) = o.go else { continue };
        if is_transform(o.class) {
            e.go_tf.entry(go).or_insert(i);
        } else if !o.removed {
            e.go_comps.entry(go).or_default().push(i);
        }
    }
    // The camera comes first: its culling mask decides which renderers are converted.
    let mut cameras: Vec<(usize, usize)> = Vec::new(); // (go, camera component)
    for (gi, o) in g.objs.iter().enumerate() {
        if o.class != docs::GAME_OBJECT || !e.active(gi) {
            continue;
        }
        for &c in e.go_comps.get(&gi).into_iter().flatten() {
            if g.objs[c].class == docs::CAMERA && enabled(&g.objs[c]) {
                cameras.push((gi, c));
            }
        }
    }
    let before = e.soup.warnings.len();
    e.camera(&cameras, camera)?;
    // Keep the camera's warnings after the objects', where they have always been.
    let camera_warnings = e.soup.warnings.split_off(before);
    let lod_hidden = e.lod_hidden();
    let mut undrawn = crate::undrawn::Undrawn::default();
    for (gi, o) in g.objs.iter().enumerate() {
        if o.class != docs::GAME_OBJECT || !e.active(gi) {
            continue;
        }
        let comps = e.go_comps.get(&gi).cloned().unwrap_or_default();
        let class_of = |c: u32| comps.iter().copied().find(|&i| g.objs[i].class == c);
        let mesh = (class_of(docs::MESH_FILTER), class_of(docs::MESH_RENDERER));
        if let (Some(mf), Some(mr)) = mesh {
            if e.draws(gi, mr, &lod_hidden) {
                e.mesh_object(gi, mf, mr)?;
            }
        }
        if let Some(smr) = class_of(docs::SKINNED_MESH_RENDERER) {
            if e.draws(gi, smr, &lod_hidden) {
                e.skinned_object(gi, smr)?;
            }
        }
        if let Some(t) = class_of(docs::TERRAIN) {
            if e.draws(gi, t, &lod_hidden) {
                e.terrain(gi, t)?;
            }
        }
        e.note_undrawn(gi, &comps, &mut undrawn);
        for &c in comps.iter().filter(|&&i| g.objs[i].class == docs::LIGHT) {
            e.light(gi, c)?;
        }
    }
    e.warn_undrawn(undrawn);
    e.universal_rules();
    e.decode_textures();
    e.soup.warnings.extend(camera_warnings);
    let notes = g.project.settings.notes(&e.soup.lights);
    e.soup.warnings.extend(notes);
    if let Some(ambient) = g
        .render_settings
        .as_ref()
        .and_then(|rs| crate::environment::ambient(rs, g.project.settings.color_space))
    {
        e.soup.environment.ambient = ambient;
    }
    if let Some(rs) = &g.render_settings {
        let hdrp = g.project.settings.pipeline == Pipeline::HighDefinition;
        match crate::environment::fog(rs, hdrp, g.project.settings.color_space) {
            Ok(fog) => e.soup.environment.fog = fog,
            Err(why) => e
                .soup
                .warnings
                .push(format!("{scene_rel}: RenderSettings: {why}")),
        }
        let reflection = match crate::environment::reflection(rs, hdrp) {
            Ok(r) => r,
            Err(why) => {
                e.soup
                    .warnings
                    .push(format!("{scene_rel}: RenderSettings: {why}"));
                0.0
            }
        };
        // The skybox shows behind a Skybox camera, lights Skybox ambient and is what
        // surfaces reflect.
        let env = &e.soup.environment;
        let seen = env.clear == formats::ClearFlags::Skybox
            || env.ambient.mode == formats::AmbientMode::Skybox;
        if seen || reflection > 0.0 {
            e.sky(rs, seen, reflection > 0.0);
        }
        if e.soup.environment.sky.is_some() {
            e.soup.environment.reflection = reflection;
        }
    }
    let placements = std::mem::take(&mut e.placements);
    placements.fill(&mut e.soup, &mut e.material_origins);
    if g.project.settings.color_space == ColorSpace::Gamma {
        keep_gamma(&mut e.soup);
    }
    e.soup.seal();
    Ok(Emitted {
        soup: e.soup,
        cameras: cameras.len(),
        material_origins: e.material_origins,
        skipped: e.skipped,
    })
}

/// A component's `m_Enabled` (on unless it says 0).
pub(crate) fn enabled(o: &Obj) -> bool {
    o.body.i64_at("m_Enabled") != Some(0)
}

impl Emitter<'_, '_> {
    /// Whether Unity draws `renderer` on GameObject `go`: enabled, listed in no LOD level
    /// the camera leaves out (`lod_hidden`), on a layer the camera draws. An enabled
    /// renderer that is not drawn is named in `skipped` with the reason.
    fn draws(&mut self, go: usize, renderer: usize, lod_hidden: &HashMap<usize, String>) -> bool {
        if !enabled(&self.g.objs[renderer]) {
            return false;
        }
        if let Some(why) = lod_hidden.get(&renderer) {
            let line = format!("object {:?}: {why}; not converted", self.path(go));
            self.skipped.push(line);
            return false;
        }
        self.camera_draws(go)
    }
}

/// A gamma-space project's materials as its shaders take them. Materials are converted
/// (from `.mat` files, FBX and OBJ models alike) with their colours decoded as a linear
/// project decodes them; here those colours are encoded back to the values Unity stores,
/// and texels are read as stored (`srgb` off), which is what a gamma-space shader samples.
fn keep_gamma(soup: &mut Soup) {
    soup.environment.color_space = ColorSpace::Gamma;
    for m in &mut soup.materials {
        m.color = m.color.map(linear_to_srgb);
        m.emission = m.emission.map(linear_to_srgb);
    }
    for t in &mut soup.textures {
        t.srgb = false;
    }
}
