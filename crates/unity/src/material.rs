//! Unity materials (class 21) → soup materials, and where a renderer's material slot
//! comes from: a `.mat` file, a Material embedded in the scene or prefab, Unity's
//! built-in materials, or a model's own material.

use crate::docs;
use crate::emit::Emitter;
use crate::model::Model;
use crate::project::ModelError;
use crate::reference::Ref;
use crate::settings::Pipeline;
use crate::yaml::Node;
pub use formats::srgb::{gamma_to_linear, linear_to_srgb, srgb_to_linear};
use formats::{Alpha, ColorSpace, Cull, Material};
use glam::{Vec3, Vec4};
use std::borrow::Cow;
use std::path::Path;

/// The GUID of Unity's built-in extra resources (Default-Material and its kin).
const BUILTIN_EXTRA_GUID: &str = "0000000000000000f000000000000000";

/// Default-Material's fileID among the built-in extra resources.
const DEFAULT_MATERIAL_ID: i64 = 10303;

/// The default materials the scriptable pipelines give every object made in their editors:
/// (GUID, the pipeline whose package holds it, its path there, its Lit base colour's grey
/// in sRGB, its smoothness). They live in the package cache, outside the project's folders,
/// so they never resolve there. Both are opaque, back-face culled, not metallic, without
/// emission or maps, and have kept these values since their packages' first releases.
const PACKAGE_MATERIALS: [(&str, Pipeline, &str, f32, f32); 2] = [
    (
        "31321ba15b8f8eb4c954353edc038b1d",
        Pipeline::Universal,
        "com.unity.render-pipelines.universal/Runtime/Materials/Lit.mat",
        0.5,
        0.5,
    ),
    (
        "73c176f402d2c2f4d929aa5da7585d17",
        Pipeline::HighDefinition,
        "com.unity.render-pipelines.high-definition/Runtime/RenderPipelineResources/Material/DefaultHDMaterial.mat",
        0.72794116,
        0.7,
    ),
];

/// A stored colour as a project in colour space `space` shades it: decoded to linear in a
/// linear project, as stored in a gamma one.
pub fn shaded_rgb(c: Vec4, space: ColorSpace) -> Vec3 {
    match space {
        ColorSpace::Linear => linear_rgb(c),
        ColorSpace::Gamma => c.truncate(),
    }
}

pub fn linear_rgb(c: Vec4) -> Vec3 {
    Vec3::new(
        srgb_to_linear(c.x),
        srgb_to_linear(c.y),
        srgb_to_linear(c.z),
    )
}

/// The named float and colour properties of `m_SavedProperties`, in either layout: the
/// modern `- _Name: value` list, or Unity ≤ 5.5's repeated `data: {first: {name}, second}`.
pub(crate) fn props<'a>(saved: &'a Node, section: &str) -> Vec<(&'a str, &'a Node)> {
    let Some(sec) = saved.get(section) else {
        return vec![];
    };
    let mut out = Vec::new();
    for item in sec.as_seq() {
        for (k, v) in item.as_map() {
            out.push((k.as_str(), v));
        }
    }
    for d in sec.get_all("data") {
        if let (Some(name), Some(v)) = (
            d.path(&["first", "name"]).and_then(Node::as_str),
            d.get("second"),
        ) {
            out.push((name, v));
        }
    }
    out
}

/// The property `name` among [`props`] of one section.
pub(crate) fn prop<'a>(props: &[(&str, &'a Node)], name: &str) -> Option<&'a Node> {
    props.iter().find(|(k, _)| *k == name).map(|(_, v)| *v)
}

/// Whether the material's shader keywords (`m_ShaderKeywords`, or 2021's
/// `m_ValidKeywords`) include `keyword`; None when the file lists no keywords at all.
pub(crate) fn keyword_on(body: &Node, keyword: &str) -> Option<bool> {
    let lists: Vec<&Node> = ["m_ShaderKeywords", "m_ValidKeywords"]
        .iter()
        .filter_map(|k| body.get(k))
        .collect();
    if lists.is_empty() {
        return None;
    }
    Some(lists.iter().any(|n| match n {
        Node::Scalar(s) => s.split_whitespace().any(|k| k == keyword),
        Node::Seq(v) => v.iter().any(|k| k.as_str() == Some(keyword)),
        _ => false,
    }))
}

/// Convert a parsed Material body. Returns the material and notes worth a warning.
pub fn convert(body: &Node, source: &str) -> (Material, Vec<String>) {
    let mut notes = Vec::new();
    let mut m = Material::unity_default();
    m.name = body.str_at("m_Name").unwrap_or("").to_string();
    m.source = source.to_string();
    let empty = Node::Map(vec![]);
    let saved = body.get("m_SavedProperties").unwrap_or(&empty);
    let floats = props(saved, "m_Floats");
    let colors = props(saved, "m_Colors");
    let float = |n: &str| prop(&floats, n).and_then(Node::as_f32);
    let color = |n: &str| prop(&colors, n).and_then(Node::color);

    let unlit = unlit_shader(body);
    // An unlit shader reads only its own colour property, and some read none (white).
    let tint = match unlit {
        Some(u) => u.tint.map(|p| (color(p), p)),
        None => Some((
            color("_BaseColor").or_else(|| color("_Color")),
            "_Color or _BaseColor",
        )),
    };
    match tint {
        Some((Some(c), _)) => {
            m.color = linear_rgb(c);
            // Alpha is stored linear, never sRGB-encoded.
            if c.w.is_finite() {
                m.opacity = c.w.clamp(0.0, 1.0);
            }
        }
        Some((None, names)) => notes.push(format!("no {names}; white")),
        None => {}
    }
    if let Some(x) = float("_Metallic") {
        m.metallic = x.clamp(0.0, 1.0);
    }
    if let Some(x) = float("_Smoothness").or_else(|| float("_Glossiness")) {
        m.smoothness = x.clamp(0.0, 1.0);
    }
    if let Some(scale) = smoothness_in_alpha(body, &float) {
        m.smoothness = scale.clamp(0.0, 1.0);
        m.smoothness_in_alpha = true;
    }
    // Unity's Standard and Lit shaders cull back faces unless `_Cull` says otherwise.
    match float("_Cull").map(|c| c.round() as i64) {
        Some(0) => m.cull = Cull::None,
        Some(1) => m.cull = Cull::Front,
        _ => {}
    }
    m.alpha = alpha_mode(body, &float);
    m.pbs = pbs(body, &float);
    m.highlights = m.pbs && highlights_on(body, &float);
    m.reflections = m.pbs && reflections_on(body, &float);
    if let Some(x) = float("_Reflectivity") {
        m.reflectivity = Some(x.clamp(0.0, 1.0));
    }
    if let Some(e) = color("_EmissionColor") {
        let e = linear_rgb(e);
        // Unity's Standard and URP shaders glow only with the _EMISSION keyword; files
        // without any keyword list (custom shaders) glow when the colour is not black.
        if keyword_on(body, "_EMISSION").unwrap_or(e != Vec3::ZERO) {
            m.emission = e;
        }
    }
    if let Some(u) = unlit {
        // Unlit shaders show colour·texture as it is: no metal, mirror or glow.
        m.unlit = true;
        m.metallic = 0.0;
        m.smoothness = 0.0;
        m.pbs = false;
        m.highlights = false;
        m.reflections = false;
        m.reflectivity = None;
        m.emission = Vec3::ZERO;
        if u.two_sided {
            m.cull = Cull::None;
        }
    }
    if !(m.color.is_finite()
        && m.emission.is_finite()
        && m.metallic.is_finite()
        && m.smoothness.is_finite())
    {
        notes.push("non-finite property; Unity's default used".to_string());
        let (name, source) = (m.name.clone(), m.source.clone());
        m = Material::unity_default();
        m.name = name;
        m.source = source;
    }
    (m, notes)
}

/// Built-in shaders (under [`BUILTIN_EXTRA_GUID`]) by fileID.
pub(crate) const STANDARD: i64 = 46;
const STANDARD_SPECULAR: i64 = 45;
const UNLIT_TRANSPARENT: i64 = 10750;
const UNLIT_TRANSPARENT_CUTOUT: i64 = 10751;
const SPRITES_DEFAULT: i64 = 10753;
const UNLIT_TEXTURE: i64 = 10752;
const UNLIT_COLOR: i64 = 10755;
/// The two leaf shaders of Unity's Tree Creator (its Leaves Optimized and Leaves Fast
/// Optimized: the shader of every "Optimized Leaf Material" it writes into a tree
/// prefab), both alpha-tested at `_Cutoff`.
const TREE_LEAVES: i64 = 10601;
const TREE_LEAVES_FAST: i64 = 10605;

/// Scriptable pipelines' Lit shaders.
const URP_LIT: &str = "933532a4fcc9baf4fa0491de14d08ed7";
const HDRP_LIT: &str = "6e4ae4064600d784cac1e41a9e6f2e59";
/// URP's Unlit shader.
pub(crate) const URP_UNLIT: &str = "650dd9526735d5b46b79224bc6e94025";

/// The material's shader as `m_Shader` names it: its guid and fileID.
pub(crate) fn shader_of(body: &Node) -> (Option<&str>, Option<i64>) {
    let shader = body.get("m_Shader");
    (
        shader.and_then(|s| s.str_at("guid")),
        shader.and_then(|s| s.i64_at("fileID")),
    )
}

/// What one of Unity's unlit shaders shows: the colour property it multiplies in (none:
/// white), whether it samples its albedo texture, and whether it draws both faces.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Unlit {
    pub tint: Option<&'static str>,
    pub textured: bool,
    pub two_sided: bool,
}

/// The material's shader when it is one of Unity's unlit ones: the built-in Unlit/Texture,
/// Unlit/Color, Unlit/Transparent and Unlit/Transparent Cutout, Sprites/Default, and URP's
/// Unlit. None of them is lit, and none has a shadow-caster pass.
pub(crate) fn unlit_shader(body: &Node) -> Option<Unlit> {
    let (tint, textured, two_sided) = match shader_of(body) {
        (
            Some(BUILTIN_EXTRA_GUID),
            Some(UNLIT_TEXTURE | UNLIT_TRANSPARENT | UNLIT_TRANSPARENT_CUTOUT),
        ) => (None, true, false),
        (Some(BUILTIN_EXTRA_GUID), Some(UNLIT_COLOR)) => (Some("_Color"), false, false),
        // Sprites/Default is `Cull Off`.
        (Some(BUILTIN_EXTRA_GUID), Some(SPRITES_DEFAULT)) => (Some("_Color"), true, true),
        (Some(URP_UNLIT), _) => (Some("_BaseColor"), true, false),
        _ => return None,
    };
    Some(Unlit {
        tint,
        textured,
        two_sided,
    })
}

/// Whether the material's shader is physically based: it has the Standard or Lit shaders'
/// smoothness (`_Glossiness`, `_Smoothness`) and is not one of the other built-in shaders
/// (legacy, mobile, Tree Creator: Lambert diffuse, and Blinn-Phong highlights that are not
/// modelled).
fn pbs(body: &Node, float: &dyn Fn(&str) -> Option<f32>) -> bool {
    if float("_Glossiness").is_none() && float("_Smoothness").is_none() {
        return false;
    }
    match shader_of(body) {
        (Some(BUILTIN_EXTRA_GUID), Some(id)) => id == STANDARD || id == STANDARD_SPECULAR,
        _ => true,
    }
}

/// Whether a physically based shader's Specular Highlights switch is on: the
/// `_SPECULARHIGHLIGHTS_OFF` keyword, which the shaders compile by, or `_SpecularHighlights`
/// in a file without keywords.
fn highlights_on(body: &Node, float: &dyn Fn(&str) -> Option<f32>) -> bool {
    match keyword_on(body, "_SPECULARHIGHLIGHTS_OFF") {
        Some(off) => !off,
        None => float("_SpecularHighlights") != Some(0.0),
    }
}

/// Whether a physically based shader's Reflections switch is on: Standard's
/// `_GLOSSYREFLECTIONS_OFF` and URP Lit's `_ENVIRONMENTREFLECTIONS_OFF` keywords, or their
/// floats `_GlossyReflections` and `_EnvironmentReflections` in a file without keywords.
fn reflections_on(body: &Node, float: &dyn Fn(&str) -> Option<f32>) -> bool {
    let keyword = keyword_on(body, "_GLOSSYREFLECTIONS_OFF")
        .zip(keyword_on(body, "_ENVIRONMENTREFLECTIONS_OFF"))
        .map(|(a, b)| a || b);
    match keyword {
        Some(off) => !off,
        None => {
            float("_GlossyReflections") != Some(0.0)
                && float("_EnvironmentReflections") != Some(0.0)
        }
    }
}

/// Where Standard or URP Lit takes smoothness from the albedo map's alpha (Smoothness
/// Source: Albedo Alpha; the `_SMOOTHNESS_TEXTURE_ALBEDO_CHANNEL_A` keyword, or
/// `_SmoothnessTextureChannel` 1 in a file without keywords), the scale the shader
/// multiplies it by: Standard's `_GlossMapScale`, URP Lit's `_Smoothness` (1 where unset).
/// A material without an albedo map reads white, alpha 1: the scale itself.
fn smoothness_in_alpha(body: &Node, float: &dyn Fn(&str) -> Option<f32>) -> Option<f32> {
    let scale = match shader_of(body) {
        (Some(BUILTIN_EXTRA_GUID), Some(STANDARD | STANDARD_SPECULAR)) => "_GlossMapScale",
        (Some(URP_LIT), _) => "_Smoothness",
        _ => return None,
    };
    let on = keyword_on(body, "_SMOOTHNESS_TEXTURE_ALBEDO_CHANNEL_A")
        .unwrap_or_else(|| float("_SmoothnessTextureChannel") == Some(1.0));
    on.then(|| float(scale).filter(|x| x.is_finite()).unwrap_or(1.0))
}

/// How the material's shader uses alpha, from the properties its inspector writes:
/// Standard's `_Mode` (0 Opaque, 1 Cutout, 2 Fade, 3 Transparent), URP Lit's `_Surface`
/// (1 Transparent) and `_AlphaClip`, HDRP Lit's `_SurfaceType` and `_AlphaCutoffEnable`,
/// and the fixed modes of the built-in Unlit, Sprite and Tree Creator leaf shaders. Other
/// shaders are opaque: their properties mean what their author chose.
pub fn alpha_mode(body: &Node, float: &dyn Fn(&str) -> Option<f32>) -> Alpha {
    let on = |n: &str| float(n).is_some_and(|x| x.round() as i64 == 1);
    let cutout = |key: &str| {
        let c = float(key).filter(|c| c.is_finite()).unwrap_or(0.5);
        Alpha::Cutout {
            cutoff: c.clamp(0.0, 1.0),
        }
    };
    match shader_of(body) {
        (Some(BUILTIN_EXTRA_GUID), Some(STANDARD | STANDARD_SPECULAR)) => {
            match float("_Mode").map(|x| x.round() as i64) {
                Some(1) => cutout("_Cutoff"),
                Some(2 | 3) => Alpha::Blend,
                _ => Alpha::Opaque,
            }
        }
        (Some(BUILTIN_EXTRA_GUID), Some(UNLIT_TRANSPARENT | SPRITES_DEFAULT)) => Alpha::Blend,
        (Some(BUILTIN_EXTRA_GUID), Some(UNLIT_TRANSPARENT_CUTOUT)) => cutout("_Cutoff"),
        (Some(BUILTIN_EXTRA_GUID), Some(TREE_LEAVES | TREE_LEAVES_FAST)) => cutout("_Cutoff"),
        // A transparent surface that also clips is drawn as blended: below the cutoff its
        // alpha lets most light through anyway.
        (Some(URP_LIT | URP_UNLIT), _) if on("_Surface") => Alpha::Blend,
        (Some(URP_LIT | URP_UNLIT), _) if on("_AlphaClip") => cutout("_Cutoff"),
        (Some(HDRP_LIT), _) if on("_SurfaceType") => Alpha::Blend,
        (Some(HDRP_LIT), _) if on("_AlphaCutoffEnable") => cutout("_AlphaCutoff"),
        _ => Alpha::Opaque,
    }
}

impl Emitter<'_, '_> {
    pub(crate) fn default_material(&mut self) -> u32 {
        self.add_material("builtin:Default-Material".into(), Material::unity_default)
    }

    /// The soup index of the material under `key`, made on first use.
    pub(crate) fn add_material(&mut self, key: String, make: impl FnOnce() -> Material) -> u32 {
        if let Some(&i) = self.materials.get(&key) {
            return i;
        }
        let i = self.soup.materials.len() as u32;
        self.soup.materials.push(make());
        self.materials.insert(key, i);
        i
    }

    /// A pipeline's default material ([`PACKAGE_MATERIALS`]), where the project lists the
    /// package that holds it; with where it came from.
    fn package_material(&mut self, guid: &str) -> Option<(u32, String)> {
        let settings = &self.g.project.settings;
        let listed =
            |p: Pipeline| settings.pipeline == p || settings.unassigned_pipeline == Some(p);
        let &(_, _, path, grey, smoothness) = PACKAGE_MATERIALS
            .iter()
            .find(|&&(g, pipeline, ..)| g == guid && listed(pipeline))?;
        let source = format!("package:{path}");
        let name = path.rsplit('/').next().unwrap_or(path);
        let i = self.add_material(source.clone(), || Material {
            name: name.trim_end_matches(".mat").to_string(),
            source,
            color: Vec3::splat(srgb_to_linear(grey)),
            smoothness,
            ..Material::unity_default()
        });
        Some((i, format!("the pipeline's {name}")))
    }

    /// Unity's default material, with a warning about `what` saying why.
    fn warn_default(&mut self, what: &str, why: String) -> u32 {
        self.soup
            .warnings
            .push(format!("{what}: {why}; Unity's default material used"));
        self.default_material()
    }

    /// A material slot's soup material index (deduplicated by source) and where the
    /// slot's material came from; `what` names the object in messages.
    pub(crate) fn material(&mut self, r: &Ref, what: &str) -> (u32, String) {
        let id = r.file_id;
        let default = || "default".to_string();
        if id == 0 {
            return (
                self.warn_default(what, "material slot is empty".into()),
                default(),
            );
        }
        let Some(guid) = r.guid.as_deref() else {
            return self.embedded_material(id, r.file, what);
        };
        if guid == BUILTIN_EXTRA_GUID {
            if id != DEFAULT_MATERIAL_ID {
                self.soup.warnings.push(format!(
                    "{what}: built-in material {id} approximated by Default-Material"
                ));
            }
            return (self.default_material(), default());
        }
        let project = self.g.project;
        let Some(path) = project.resolve(guid).cloned() else {
            if let Some(found) = self.package_material(guid) {
                return found;
            }
            let why =
                format!("material GUID {guid} is not in the project (a package or deleted asset)");
            return (self.warn_default(what, why), default());
        };
        if crate::project::ext(&path) == "mat" {
            self.mat_file_origin(&path, what, "override")
        } else {
            self.model_material(id, &path, what)
        }
    }

    /// A `.mat` file's material with `origin`, or the default when it holds none.
    fn mat_file_origin(&mut self, path: &Path, what: &str, origin: &str) -> (u32, String) {
        let before = self.soup.warnings.len();
        let i = self.mat_file(path, what);
        let fell_back = self.soup.warnings[before..]
            .iter()
            .any(|w| w.ends_with("Unity's default material used"));
        let origin = if fell_back {
            "default".to_string()
        } else {
            format!("{origin} {}", self.g.project.rel(path))
        };
        (i, origin)
    }

    /// The texture maps of material `m`, converted from Material `body` (`what` names it
    /// in warnings).
    fn mat_maps(&mut self, m: &mut Material, body: &Node, what: &str) {
        m.albedo_map = self.mat_albedo(body, what);
        // Unlit shaders sample no normal, emission, occlusion or metallic map.
        if !m.unlit {
            m.normal_map = self.mat_normal(body, what);
            m.emission_map = self.mat_emission(body, m.emission, what);
            m.occlusion_map = self.mat_occlusion(body, what);
            m.metallic_map = self.mat_metallic(body, what);
        }
    }

    /// A Material document of file `file` (guid-less reference): one soup material for
    /// every instance of the prefab that holds it.
    fn embedded_material(&mut self, id: i64, file: usize, what: &str) -> (u32, String) {
        let project = self.g.project;
        let Some(f) = self.g.files.get(file) else {
            let why = format!("local material {id} not found");
            return (self.warn_default(what, why), "default".into());
        };
        let key = format!("local:{}:{id}", f.path.display());
        let src = format!("{}#{id}", project.rel(&f.path));
        if let Some(&i) = self.materials.get(&key) {
            return (i, format!("override {src}"));
        }
        match f.doc(id) {
            Some((docs::MATERIAL, body)) => {
                let body = self.inherit(&body, &src);
                let (mut m, _notes) = convert(&body, &src);
                self.mat_maps(&mut m, &body, &src);
                (self.add_material(key, || m), format!("override {src}"))
            }
            _ => {
                let why = format!("material fileID {id} is not in {}", project.rel(&f.path));
                (self.warn_default(what, why), "default".into())
            }
        }
    }

    /// The Material of a `.mat` file.
    fn mat_file(&mut self, path: &Path, what: &str) -> u32 {
        let rel = self.g.project.rel(path);
        let key = format!("mat:{rel}");
        if let Some(&i) = self.materials.get(&key) {
            return i;
        }
        let mat = self.g.project.mat(path);
        match mat.as_ref() {
            Ok(Some(b)) => {
                let b = self.inherit(b, &rel);
                let (mut m, notes) = convert(&b, &rel);
                for n in notes {
                    self.soup.warnings.push(format!("{rel}: {n}"));
                }
                self.mat_maps(&mut m, &b, &rel);
                self.add_material(key, || m)
            }
            Ok(None) => self.warn_default(what, format!("{rel} holds no Material")),
            Err(e) => self.warn_default(what, format!("{rel}: {e}")),
        }
    }

    /// The material Unity puts in a model's slot whose fileID is `id`, in the importer's
    /// precedence: an `externalObjects` remap, then (FBX models whose meta does not keep
    /// materials inside the model) an extracted `.mat` found by name in a `Materials/`
    /// folder, then the model's own material.
    fn model_material(&mut self, id: i64, path: &Path, what: &str) -> (u32, String) {
        let rel = self.g.project.rel(path);
        let loaded = self.g.project.model(path);
        let asset = match loaded.as_ref() {
            Ok(a) => a,
            Err(ModelError::Unsupported(ext) | ModelError::Authoring(ext, _)) => {
                let why = format!("{rel} is a .{ext}, not a material");
                return (self.warn_default(what, why), "default".into());
            }
            Err(ModelError::Read(_)) => {
                let why = format!("{rel} could not be read");
                return (self.warn_default(what, why), "default".into());
            }
        };
        let name = asset
            .material_names()
            .find(|n| asset.material_ids(n).contains(&id));
        let Some(name) = name else {
            let why = format!("material fileID {id} names no material of {rel}");
            return (self.warn_default(what, why), "default".into());
        };
        let fbx = crate::project::ext(path) == "fbx";
        if fbx {
            let remap = asset
                .meta
                .external_objects
                .iter()
                .find(|(ty, n, _)| ty == "UnityEngine:Material" && n == name);
            if let Some((_, _, guid)) = remap {
                let Some(mat) = self.g.project.resolve(guid).cloned() else {
                    if let Some(found) = self.package_material(guid) {
                        return found;
                    }
                    let why = format!(
                        "{rel}: material '{name}' is remapped to GUID {guid}, which is not in the project"
                    );
                    return (self.warn_default(what, why), "default".into());
                };
                return self.mat_file_origin(&mat, what, "remap");
            }
            if asset.meta.material_location != Some(1) {
                let key = (path.to_path_buf(), name.to_string());
                let found = match self.extracted.get(&key) {
                    Some(f) => f.clone(),
                    None => {
                        let own = asset.model.material(name);
                        let f = self.extracted_material(path, asset, name, own);
                        self.extracted.insert(key, f.clone());
                        f
                    }
                };
                if let Some(mat) = found {
                    return self.mat_file_origin(&mat, what, "Materials folder");
                }
            }
        }
        let key = format!("objmat:{rel}:{name}");
        let own = asset.model.material(name);
        let texture = own
            .and_then(|m| m.texture.as_deref())
            .map(|t| (t, self.model_texture(path, t)));
        let origin = match &texture {
            Some((_, Some(found))) => format!(
                "model's own {rel}#{name}, texture {}",
                self.g.project.rel(found)
            ),
            Some((t, None)) => format!("model's own {rel}#{name}, texture {t} not found"),
            None => format!("model's own {rel}#{name}"),
        };
        if let Some(&i) = self.materials.get(&key) {
            return (i, origin);
        }
        match own {
            Some(own) => {
                let mut m = Material::unity_default();
                m.name = name.to_string();
                m.source = format!("{rel}#{name}");
                m.color = own.color;
                let src = m.source.clone();
                m.albedo_map = match texture {
                    Some((_, Some(found))) => self.texture_ref(
                        &found,
                        crate::texture::Import::read(&found),
                        Default::default(),
                        &src,
                        crate::albedo::TINT_ALONE,
                    ),
                    Some((t, None)) => {
                        self.soup.warnings.push(format!(
                            "{src}: texture {t} is not next to the model, in a Textures folder or anywhere in Assets; drawn with its tint alone"
                        ));
                        None
                    }
                    None => None,
                };
                (self.add_material(key, || m), origin)
            }
            // A sub-mesh without a material name: Unity's importer gives it its default
            // material.
            None if name == Model::UNNAMED_MATERIAL
                || (fbx && name == Model::FBX_UNNAMED_MATERIAL) =>
            {
                (self.default_material(), "default".into())
            }
            None if fbx => {
                let why = format!("{rel}: material '{name}' is not defined in the file");
                (self.warn_default(what, why), "default".into())
            }
            None => {
                let why = format!("{rel}: material '{name}' has no Kd in a .mtl");
                (self.warn_default(what, why), "default".into())
            }
        }
    }

    /// The `.mat` Unity's legacy import (materials extracted next to the model) gives
    /// the model's material `name`: named as the meta's `materialName` says and looked
    /// for in `Materials/` folders as its `materialSearch` says.
    fn extracted_material(
        &self,
        model_path: &Path,
        asset: &crate::project::ModelAsset,
        name: &str,
        own: Option<&crate::model::ModelMaterial>,
    ) -> Option<std::path::PathBuf> {
        let stem = model_path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        let texture = own
            .and_then(|m| m.texture.as_deref())
            .and_then(|t| t.rsplit(['/', '\\']).next())
            .and_then(|t| Path::new(t).file_stem())
            .map(|s| s.to_string_lossy().into_owned())
            .filter(|t| !t.is_empty());
        let by_model = format!("{stem}-{name}");
        let file = match asset.meta.material_name {
            0 => texture.unwrap_or_else(|| name.to_string()),
            1 => name.to_string(),
            3 => texture.unwrap_or(by_model),
            _ => by_model,
        };
        let file = format!("{}.mat", sanitize(&file));
        let assets = self.g.project.assets.canonicalize().ok()?;
        let mut dir = model_path.parent()?.canonicalize().ok()?;
        loop {
            if let Some(p) = file_in(&dir.join("Materials"), &file) {
                return Some(p);
            }
            if asset.meta.material_search == 0 || dir == assets || !dir.pop() {
                break;
            }
            if !dir.starts_with(&assets) {
                break;
            }
        }
        if asset.meta.material_search == 2 {
            return self.g.project.find_by_name(&file).cloned();
        }
        None
    }
}

/// How many `m_Parent` links a variant may follow (a cycle or a deep chain ends there).
const MAX_VARIANT_DEPTH: usize = 16;

/// The `m_SavedProperties` sections a variant inherits entry by entry.
const PROPERTY_SECTIONS: [&str; 4] = ["m_TexEnvs", "m_Ints", "m_Floats", "m_Colors"];

impl Emitter<'_, '_> {
    /// A Material body with what its parents set and it does not (a material variant,
    /// `m_Parent`, Unity 2022+, stores only its overrides); the body itself when it has no
    /// parent. `what` names the material in warnings.
    pub(crate) fn inherit<'b>(&mut self, body: &'b Node, what: &str) -> Cow<'b, Node> {
        let mut merged = Cow::Borrowed(body);
        let mut current = Cow::Borrowed(body);
        for _ in 0..MAX_VARIANT_DEPTH {
            let Some(guid) = current
                .get("m_Parent")
                .filter(|p| p.i64_at("fileID").unwrap_or(0) != 0)
                .and_then(|p| p.str_at("guid"))
            else {
                return merged;
            };
            let parent = self.g.project.resolve(guid).map(|p| self.g.project.mat(p));
            let Some(Ok(Some(parent))) = parent.as_deref() else {
                self.soup.warnings.push(format!(
                    "{what}: parent material {guid} is not a readable material of the project; only the variant's own properties used"
                ));
                return merged;
            };
            merged = Cow::Owned(with_parent(&merged, parent));
            current = Cow::Owned(parent.clone());
        }
        self.soup.warnings.push(format!(
            "{what}: more than {MAX_VARIANT_DEPTH} parent materials (a cycle?); the rest ignored"
        ));
        merged
    }
}

/// `child` with each saved property of `parent` that it does not set itself.
fn with_parent(child: &Node, parent: &Node) -> Node {
    let empty = Node::Map(vec![]);
    let parent_saved = parent.get("m_SavedProperties").unwrap_or(&empty);
    let mut out = child.clone();
    let Node::Map(top) = &mut out else {
        return out;
    };
    if !top.iter().any(|(k, _)| k == "m_SavedProperties") {
        top.push(("m_SavedProperties".into(), Node::Map(vec![])));
    }
    let Some((_, Node::Map(saved))) = top.iter_mut().find(|(k, _)| k == "m_SavedProperties") else {
        return out;
    };
    for section in PROPERTY_SECTIONS {
        let inherited: Vec<(String, Node)> = props(parent_saved, section)
            .into_iter()
            .map(|(k, v)| (k.to_string(), v.clone()))
            .collect();
        if inherited.is_empty() {
            continue;
        }
        // Rewritten in the modern list layout, which `props` reads like the legacy one.
        let wrapped = Node::Map(saved.clone());
        let mut entries: Vec<(String, Node)> = props(&wrapped, section)
            .into_iter()
            .map(|(k, v)| (k.to_string(), v.clone()))
            .collect();
        for (k, v) in inherited {
            if !entries.iter().any(|(own, _)| *own == k) {
                entries.push((k, v));
            }
        }
        let list = Node::Seq(entries.into_iter().map(|kv| Node::Map(vec![kv])).collect());
        match saved.iter_mut().find(|(k, _)| k == section) {
            Some((_, sec)) => *sec = list,
            None => saved.push((section.to_string(), list)),
        }
    }
    out
}

/// A material name as Unity writes it into a file name: characters no file system
/// allows become `_`.
fn sanitize(name: &str) -> String {
    name.chars()
        .map(|c| {
            if matches!(c, '/' | '\\' | ':' | '*' | '?' | '"' | '<' | '>' | '|') {
                '_'
            } else {
                c
            }
        })
        .collect()
}

/// The file `name` in `dir`, ASCII case ignored (projects made on Windows or macOS do
/// not keep case).
pub(crate) fn file_in(dir: &Path, name: &str) -> Option<std::path::PathBuf> {
    let exact = dir.join(name);
    if exact.is_file() {
        return Some(exact);
    }
    std::fs::read_dir(dir)
        .ok()?
        .filter_map(Result::ok)
        .map(|e| e.path())
        .find(|p| {
            p.is_file()
                && p.file_name()
                    .is_some_and(|f| f.to_string_lossy().eq_ignore_ascii_case(name))
        })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::yaml::parse;

    #[test]
    fn standard_urp_and_legacy_layouts() {
        let std_mat = parse("Material:\n  m_Name: Red\n  m_ShaderKeywords: _EMISSION\n  m_SavedProperties:\n    m_Floats:\n    - _Glossiness: 0.8\n    - _Metallic: 0.5\n    - _Reflectivity: 0.3\n    m_Colors:\n    - _Color: {r: 1, g: 0.5, b: 0, a: 1}\n    - _EmissionColor: {r: 2, g: 0, b: 0, a: 1}\n");
        let (m, _) = convert(std_mat.get("Material").unwrap(), "a.mat");
        assert_eq!(m.name, "Red");
        assert!(
            (m.color.y - 0.21404114).abs() < 1e-6,
            "sRGB 0.5 → linear {}",
            m.color.y
        );
        assert_eq!(
            (m.metallic, m.smoothness, m.reflectivity),
            (0.5, 0.8, Some(0.3))
        );
        assert!((m.emission.x - srgb_to_linear(2.0)).abs() < 1e-6 && m.emission.x > 4.0);

        let urp = parse("Material:\n  m_ValidKeywords: []\n  m_SavedProperties:\n    m_Floats:\n    - _Smoothness: 0.25\n    m_Colors:\n    - _BaseColor: {r: 0, g: 0, b: 1, a: 1}\n    - _Color: {r: 1, g: 1, b: 1, a: 1}\n    - _EmissionColor: {r: 1, g: 1, b: 1, a: 1}\n");
        let (m, _) = convert(urp.get("Material").unwrap(), "b.mat");
        assert_eq!(m.color, Vec3::new(0.0, 0.0, 1.0));
        assert_eq!(m.smoothness, 0.25);
        assert_eq!(m.emission, Vec3::ZERO, "no _EMISSION keyword");

        let legacy = parse("Material:\n  m_SavedProperties:\n    m_Floats:\n      data:\n        first:\n          name: _Metallic\n        second: 1\n    m_Colors:\n      data:\n        first:\n          name: _Color\n        second: {r: 0.2, g: 0.2, b: 0.2, a: 1}\n");
        let (m, _) = convert(legacy.get("Material").unwrap(), "c.mat");
        assert_eq!(m.metallic, 1.0);
        assert!((m.color.x - srgb_to_linear(0.2)).abs() < 1e-7);
    }

    #[test]
    fn smoothness_can_come_from_the_albedo_alpha() {
        let mat = |shader: &str, keywords: &str, floats: &str| {
            let text = format!("Material:\n  m_Shader: {shader}\n{keywords}  m_SavedProperties:\n    m_Floats:\n{floats}    m_Colors: []\n");
            let m = convert(parse(&text).get("Material").unwrap(), "a.mat").0;
            (m.smoothness_in_alpha, m.smoothness)
        };
        let standard = "{fileID: 46, guid: 0000000000000000f000000000000000, type: 0}";
        let floats =
            "    - _GlossMapScale: 0.5\n    - _Glossiness: 1\n    - _SmoothnessTextureChannel: 1\n";
        let keyword = "  m_ShaderKeywords: _SMOOTHNESS_TEXTURE_ALBEDO_CHANNEL_A\n";
        assert_eq!(mat(standard, keyword, floats), (true, 0.5));
        // Without keyword lists the float decides; a keyword list without it says no.
        assert_eq!(mat(standard, "", floats), (true, 0.5));
        assert_eq!(
            mat(standard, "  m_ShaderKeywords: _EMISSION\n", floats),
            (false, 1.0)
        );
        // URP Lit scales the alpha by its _Smoothness.
        let urp = "{fileID: 4800000, guid: 933532a4fcc9baf4fa0491de14d08ed7, type: 3}";
        let lit = "  m_ValidKeywords:\n  - _SMOOTHNESS_TEXTURE_ALBEDO_CHANNEL_A\n";
        assert_eq!(mat(urp, lit, "    - _Smoothness: 0.25\n"), (true, 0.25));
        // A custom shader's keyword means what its author chose.
        let custom = "{fileID: 4800000, guid: 0123456789abcdef0123456789abcdef, type: 3}";
        assert_eq!(mat(custom, keyword, floats), (false, 1.0));
    }

    #[test]
    fn highlights_follow_the_shader_and_its_switch() {
        let converted = |shader: i64, keywords: &str, floats: &str| {
            let text = format!("Material:\n  m_Shader: {{fileID: {shader}, guid: 0000000000000000f000000000000000, type: 0}}\n{keywords}  m_SavedProperties:\n    m_Floats:\n{floats}    m_Colors: []\n");
            convert(parse(&text).get("Material").unwrap(), "a.mat").0
        };
        let mat = |shader: i64, keywords: &str, floats: &str| {
            let m = converted(shader, keywords, floats);
            assert!(
                m.pbs || !m.highlights,
                "highlights only on physically based shaders"
            );
            m.highlights
        };
        let pbs = |shader: i64, floats: &str| converted(shader, "", floats).pbs;
        let glossy = "    - _Glossiness: 0.5\n";
        // Standard and Standard (Specular setup), with their switch on, off by keyword, and
        // off by the float where the file lists no keywords.
        assert!(mat(46, "  m_ShaderKeywords: \n", glossy));
        assert!(mat(45, "", glossy));
        assert!(!mat(
            46,
            "  m_ShaderKeywords: _SPECULARHIGHLIGHTS_OFF\n",
            glossy
        ));
        assert!(!mat(
            46,
            "  m_ValidKeywords:\n  - _SPECULARHIGHLIGHTS_OFF\n",
            glossy
        ));
        let off = "    - _Glossiness: 0.5\n    - _SpecularHighlights: 0\n";
        assert!(!mat(46, "", off));
        assert!(
            pbs(46, off),
            "the switch leaves the diffuse term physically based"
        );
        // The keyword list is what the shader compiles by: a stale float does not count.
        assert!(mat(46, "  m_ShaderKeywords: _EMISSION\n", off));
        // Legacy Diffuse keeps a stale smoothness from a Standard past; no smoothness at
        // all means a shader without the lobe.
        assert!(!mat(7, "", glossy));
        assert!(!pbs(7, glossy), "Legacy Diffuse is Lambert's");
        assert!(!mat(46, "", "    - _Metallic: 0\n"));
        // An unlit shader has no lights to reflect.
        assert!(!mat(10752, "", glossy));
        assert!(!pbs(10752, glossy));
        assert!(pbs(45, glossy));
        // URP Lit (a project shader, by GUID) with its smoothness.
        let urp = parse("Material:\n  m_Shader: {fileID: 4800000, guid: 933532a4fcc9baf4fa0491de14d08ed7, type: 3}\n  m_ValidKeywords: []\n  m_SavedProperties:\n    m_Floats:\n    - _Smoothness: 0.5\n    - _SpecularHighlights: 1\n");
        assert!(convert(urp.get("Material").unwrap(), "u.mat").0.highlights);
    }

    #[test]
    fn reflections_follow_each_pipelines_switch() {
        let on = |shader: &str, keywords: &str, floats: &str| {
            let text = format!("Material:\n  m_Shader: {shader}\n{keywords}  m_SavedProperties:\n    m_Floats:\n    - _Glossiness: 0.5\n    - _Smoothness: 0.5\n{floats}    m_Colors: []\n");
            convert(parse(&text).get("Material").unwrap(), "a.mat")
                .0
                .reflections
        };
        let standard = "{fileID: 46, guid: 0000000000000000f000000000000000, type: 0}";
        let urp = "{fileID: 4800000, guid: 933532a4fcc9baf4fa0491de14d08ed7, type: 3}";
        let legacy = "{fileID: 7, guid: 0000000000000000f000000000000000, type: 0}";
        let unlit = "{fileID: 10752, guid: 0000000000000000f000000000000000, type: 0}";
        assert!(on(standard, "  m_ShaderKeywords: \n", ""));
        assert!(!on(
            standard,
            "  m_ShaderKeywords: _GLOSSYREFLECTIONS_OFF\n",
            ""
        ));
        assert!(!on(standard, "", "    - _GlossyReflections: 0\n"));
        // The keyword list is what the shader compiles by.
        assert!(on(
            standard,
            "  m_ShaderKeywords: \n",
            "    - _GlossyReflections: 0\n"
        ));
        assert!(on(urp, "  m_ValidKeywords: []\n", ""));
        let urp_off = "  m_ValidKeywords:\n  - _ENVIRONMENTREFLECTIONS_OFF\n";
        assert!(!on(urp, urp_off, ""));
        assert!(!on(urp, "", "    - _EnvironmentReflections: 0\n"));
        // Lambert's shaders and unlit ones reflect nothing.
        assert!(!on(legacy, "", ""));
        assert!(!on(unlit, "", ""));
    }

    fn alpha_of(text: &str) -> (Alpha, f32) {
        let (m, _) = convert(parse(text).get("Material").unwrap(), "a.mat");
        (m.alpha, m.opacity)
    }

    #[test]
    fn alpha_modes_by_shader() {
        let standard = |mode: &str, rest: &str| {
            format!("Material:\n  m_Shader: {{fileID: 46, guid: 0000000000000000f000000000000000, type: 0}}\n  m_SavedProperties:\n    m_Floats:\n    - _Mode: {mode}\n{rest}    m_Colors:\n    - _Color: {{r: 1, g: 1, b: 1, a: 0.25}}\n")
        };
        assert_eq!(alpha_of(&standard("0", "")), (Alpha::Opaque, 0.25));
        assert_eq!(
            alpha_of(&standard("1", "    - _Cutoff: 0.3\n")).0,
            Alpha::Cutout { cutoff: 0.3 }
        );
        assert_eq!(
            alpha_of(&standard("1", "")).0,
            Alpha::Cutout { cutoff: 0.5 }
        );
        assert_eq!(alpha_of(&standard("2", "")).0, Alpha::Blend);
        assert_eq!(alpha_of(&standard("3", "")).0, Alpha::Blend);
        let urp = |floats: &str| {
            format!("Material:\n  m_Shader: {{fileID: 4800000, guid: 933532a4fcc9baf4fa0491de14d08ed7, type: 3}}\n  m_SavedProperties:\n    m_Floats:\n{floats}")
        };
        assert_eq!(
            alpha_of(&urp(
                "    - _Surface: 0\n    - _AlphaClip: 1\n    - _Cutoff: 0.7\n"
            ))
            .0,
            Alpha::Cutout { cutoff: 0.7 }
        );
        assert_eq!(
            alpha_of(&urp("    - _Surface: 1\n    - _AlphaClip: 0\n")).0,
            Alpha::Blend
        );
        assert_eq!(
            alpha_of(&urp("    - _Surface: 0\n    - _AlphaClip: 0\n")),
            (Alpha::Opaque, 1.0)
        );
        let hdrp = "Material:\n  m_Shader: {fileID: 4800000, guid: 6e4ae4064600d784cac1e41a9e6f2e59, type: 3}\n  m_SavedProperties:\n    m_Floats:\n    - _AlphaCutoffEnable: 1\n    - _AlphaCutoff: 0.25\n";
        assert_eq!(alpha_of(hdrp).0, Alpha::Cutout { cutoff: 0.25 });
        let unlit = |id: i64| {
            format!("Material:\n  m_Shader: {{fileID: {id}, guid: 0000000000000000f000000000000000, type: 0}}\n")
        };
        assert_eq!(alpha_of(&unlit(10750)).0, Alpha::Blend);
        assert_eq!(alpha_of(&unlit(10751)).0, Alpha::Cutout { cutoff: 0.5 });
        assert_eq!(alpha_of(&unlit(10752)).0, Alpha::Opaque);
        // Tree Creator's leaves are cut out, its bark is not.
        for (id, alpha) in [
            (10601, Alpha::Cutout { cutoff: 0.3 }),
            (10605, Alpha::Cutout { cutoff: 0.3 }),
            (10604, Alpha::Opaque),
        ] {
            let floats = "  m_SavedProperties:\n    m_Floats:\n    - _Cutoff: 0.3\n";
            assert_eq!(alpha_of(&(unlit(id) + floats)).0, alpha, "{id}");
        }
        // A custom shader's _Mode means what its author chose.
        let custom = "Material:\n  m_Shader: {fileID: 4800000, guid: 1234, type: 3}\n  m_SavedProperties:\n    m_Floats:\n    - _Mode: 1\n";
        assert_eq!(alpha_of(custom).0, Alpha::Opaque);
    }

    #[test]
    fn unlit_shaders_show_their_own_colour_and_texture_and_nothing_else() {
        // Every file keeps stale lit properties, as Unity leaves them on a shader change.
        let mat = |shader: &str| {
            format!("Material:\n  m_Shader: {shader}\n  m_ShaderKeywords: _EMISSION _NORMALMAP\n  m_SavedProperties:\n    m_TexEnvs:\n    - _BaseMap:\n        m_Texture: {{fileID: 2800000, guid: bbbb, type: 3}}\n        m_Scale: {{x: 1, y: 1}}\n        m_Offset: {{x: 0, y: 0}}\n    - _MainTex:\n        m_Texture: {{fileID: 2800000, guid: aaaa, type: 3}}\n        m_Scale: {{x: 2, y: 2}}\n        m_Offset: {{x: 0, y: 0}}\n    - _BumpMap:\n        m_Texture: {{fileID: 2800000, guid: cccc, type: 3}}\n        m_Scale: {{x: 1, y: 1}}\n        m_Offset: {{x: 0, y: 0}}\n    m_Floats:\n    - _Metallic: 1\n    - _Glossiness: 1\n    - _Smoothness: 1\n    - _Surface: 1\n    m_Colors:\n    - _Color: {{r: 0.2, g: 0.2, b: 0.2, a: 0.5}}\n    - _BaseColor: {{r: 1, g: 0.2, b: 0.2, a: 0.25}}\n    - _EmissionColor: {{r: 1, g: 1, b: 1, a: 1}}\n")
        };
        let builtin =
            |id: i64| format!("{{fileID: {id}, guid: 0000000000000000f000000000000000, type: 0}}");
        let urp = "{fileID: 4800000, guid: 650dd9526735d5b46b79224bc6e94025, type: 3}".to_string();
        let grey = srgb_to_linear(0.2);
        let red = Vec3::new(1.0, grey, grey);
        // shader, colour, opacity, albedo property, alpha, cull
        let cases = [
            (
                builtin(10752),
                Vec3::ONE,
                1.0,
                Some("_MainTex"),
                Alpha::Opaque,
                Cull::Back,
            ),
            (
                builtin(10750),
                Vec3::ONE,
                1.0,
                Some("_MainTex"),
                Alpha::Blend,
                Cull::Back,
            ),
            (
                builtin(10751),
                Vec3::ONE,
                1.0,
                Some("_MainTex"),
                Alpha::Cutout { cutoff: 0.5 },
                Cull::Back,
            ),
            (
                builtin(10755),
                Vec3::splat(grey),
                0.5,
                None,
                Alpha::Opaque,
                Cull::Back,
            ),
            (
                builtin(10753),
                Vec3::splat(grey),
                0.5,
                Some("_MainTex"),
                Alpha::Blend,
                Cull::None,
            ),
            (urp, red, 0.25, Some("_BaseMap"), Alpha::Blend, Cull::Back),
        ];
        for (shader, colour, opacity, albedo, alpha, cull) in cases {
            let text = mat(&shader);
            let body = parse(&text);
            let body = body.get("Material").unwrap();
            let (m, notes) = convert(body, "u.mat");
            assert!(m.unlit, "{shader}");
            assert!(
                (m.color - colour).abs().max_element() < 1e-6,
                "{shader}: {}",
                m.color
            );
            assert_eq!(
                (m.opacity, m.alpha, m.cull),
                (opacity, alpha, cull),
                "{shader}"
            );
            assert_eq!(
                (m.metallic, m.smoothness, m.emission),
                (0.0, 0.0, Vec3::ZERO),
                "{shader}"
            );
            assert_eq!(
                crate::texture::albedo_slot(body).map(|s| s.property),
                albedo.map(String::from),
                "{shader}"
            );
            assert!(notes.is_empty(), "{shader}: {notes:?}");
        }
        // The lit shaders stay lit.
        let (standard, _) = convert(parse(&mat(&builtin(46))).get("Material").unwrap(), "s.mat");
        assert!(!standard.unlit);
        assert_eq!(standard.metallic, 1.0);
    }

    #[test]
    fn a_variant_keeps_its_own_properties_and_inherits_the_rest() {
        let parent = parse("Material:\n  m_SavedProperties:\n    m_TexEnvs:\n    - _BaseMap:\n        m_Texture: {fileID: 2800000, guid: aaaa, type: 3}\n    m_Floats:\n    - _Smoothness: 0.9\n    - _Metallic: 0.5\n    m_Colors:\n    - _BaseColor: {r: 1, g: 0, b: 0, a: 1}\n");
        let child = parse("Material:\n  m_SavedProperties:\n    m_TexEnvs:\n    - _BaseMap:\n        m_Texture: {fileID: 2800000, guid: bbbb, type: 3}\n    m_Floats:\n    - _Metallic: 0.25\n    m_Colors: []\n");
        let merged = with_parent(
            child.get("Material").unwrap(),
            parent.get("Material").unwrap(),
        );
        let (m, _) = convert(&merged, "v.mat");
        assert_eq!((m.metallic, m.smoothness), (0.25, 0.9));
        assert_eq!(m.color, Vec3::new(1.0, 0.0, 0.0));
        let slot = crate::texture::albedo_slot(&merged).unwrap();
        assert_eq!(slot.guid, "bbbb");
    }
}
