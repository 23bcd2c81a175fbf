//! The triangle soup: world-space geometry plus everything the renderer needs from the
//! scene. Triangles index shared vertices, as the meshes they come from do: a closed mesh
//! has about half as many vertices as triangles, so this is a third of the bytes of three
//! corners per triangle to write, hash, read and keep in memory. Right-handed, Y up, metres: Unity's left-handed positions with X negated, so an
//! OBJ placed at the identity in Unity keeps its file's coordinates. Colours are linear RGB.

use crate::camera::Camera;
use crate::sky::Sky;
use crate::texture::{Texture, TextureRef};
use crate::{envelope, Digest, FormatError};
use glam::{Vec2, Vec3};
use serde::{Deserialize, Serialize};
use std::path::Path;

pub const MAGIC: &[u8; 8] = b"UTSOUP\0\0";
pub const VERSION: u32 = 14;

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Soup {
    /// World-space vertex positions.
    pub positions: Vec<Vec3>,
    /// Unit shading normal of each vertex, parallel to `positions`.
    pub normals: Vec<Vec3>,
    /// Texture coordinates of each vertex (the mesh's first UV channel, Unity's convention:
    /// (0, 0) is the image's bottom-left), parallel to `positions` when any material has a
    /// texture, empty otherwise; (0, 0) where a mesh has none.
    pub uvs: Vec<Vec2>,
    /// Three indices into `positions` per triangle, counter-clockwise seen from the front.
    pub triangles: Vec<[u32; 3]>,
    /// Index into `materials`, one per triangle.
    pub tri_material: Vec<u32>,
    /// Index into `objects`, one per triangle.
    pub tri_object: Vec<u32>,
    pub objects: Vec<Object>,
    pub materials: Vec<Material>,
    /// Every distinct texture image the materials use, once, at the size Unity imports it.
    pub textures: Vec<Texture>,
    pub lights: Vec<Light>,
    pub camera: Camera,
    pub environment: Environment,
    /// Everything the converter approximated, skipped or guessed, one line each.
    pub warnings: Vec<String>,
    /// Degenerate triangles (zero area, repeated or collinear vertices) dropped.
    pub dropped_degenerate: u64,
    /// BLAKE3 of the positions and triangles (see [`indexed_geometry_hash`]).
    pub geometry_hash: Digest,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Object {
    /// GameObject name (hierarchy path segments joined by '/').
    pub name: String,
    /// Where its mesh came from: an asset path relative to the project, or `builtin:Cube` …
    pub source: String,
    /// The GameObject's `m_Layer`, 0–31: lights light only the layers in their mask.
    pub layer: u8,
    /// The renderer's `m_CastShadows`.
    pub cast_shadows: CastShadows,
    /// The renderer's `m_ReceiveShadows`: false means lit as if nothing were in the way.
    pub receive_shadows: bool,
}

impl Object {
    /// An object on the Default layer that casts (culled like its material) and receives
    /// shadows: what Unity gives a new MeshRenderer.
    pub fn new(name: impl Into<String>, source: impl Into<String>) -> Self {
        Object {
            name: name.into(),
            source: source.into(),
            layer: 0,
            cast_shadows: CastShadows::On,
            receive_shadows: true,
        }
    }

    /// Whether camera and reflection rays see the object.
    pub fn visible(&self) -> bool {
        self.cast_shadows != CastShadows::ShadowsOnly
    }
}

/// `MeshRenderer.m_CastShadows`, in Unity's order (0–3).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum CastShadows {
    Off,
    /// Casts with the faces its material draws.
    On,
    /// Casts from both faces whatever the material culls.
    TwoSided,
    /// Casts like `On` but camera and reflection rays pass through it.
    ShadowsOnly,
}

/// Which faces a material does not draw: the shader's `_Cull`, in Unity's order (0–2).
/// The front face is the one the soup's winding shows counter-clockwise.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Cull {
    /// Two-sided.
    None,
    Front,
    Back,
}

impl Cull {
    /// Whether a viewer who sees the face's front (`front`) or its back skips it.
    pub fn skips(self, front: bool) -> bool {
        match self {
            Cull::None => false,
            Cull::Back => !front,
            Cull::Front => front,
        }
    }
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Material {
    pub name: String,
    /// `.mat` path relative to the project, or `builtin:Default-Material`, or the OBJ's `.mtl`.
    pub source: String,
    /// `_Color` / `_BaseColor`, linear RGB.
    pub color: Vec3,
    /// `_Metallic`, 0–1 (where `metallic_map` is set, its texel's red channel instead).
    pub metallic: f32,
    /// `_Glossiness` / `_Smoothness`, 0–1; where `smoothness_in_alpha`, the scale of the
    /// albedo map's alpha instead (`_GlossMapScale`, URP Lit's `_Smoothness`).
    pub smoothness: f32,
    /// Smoothness is the albedo map's alpha times `smoothness` at each point (Smoothness
    /// Source: Albedo Alpha, the `_SMOOTHNESS_TEXTURE_ALBEDO_CHANNEL_A` keyword).
    pub smoothness_in_alpha: bool,
    /// The surface is lit by Unity's physically based shading (the Standard and Lit
    /// shaders, and other shaders with their smoothness property): its diffuse light is
    /// (1 − the dielectric reflectance) of its albedo, and in the built-in pipeline
    /// Disney's. Else (the legacy, mobile and Tree Creator shaders) it is Lambert's.
    pub pbs: bool,
    /// The lights leave highlights on the surface: it is `pbs` and `_SpecularHighlights`
    /// is on.
    pub highlights: bool,
    /// The skybox's reflection shows on the surface (where the scene has one, see
    /// [`Environment::reflection`]): it is `pbs` and its shader's Reflections switch
    /// (`_GlossyReflections`, URP's `_EnvironmentReflections`) is on. With the switch off,
    /// Unity's shaders reflect one constant colour instead.
    pub reflections: bool,
    /// `_Reflectivity` when the material sets it: overrides metallic·smoothness.
    pub reflectivity: Option<f32>,
    /// `_EmissionColor` when emission is enabled, linear RGB (HDR, may exceed 1).
    pub emission: Vec3,
    /// `_Cull`: the faces camera, reflection and (for casters that are `On`) shadow rays
    /// pass through.
    pub cull: Cull,
    /// The albedo map (`_MainTex`, `_BaseMap`, `_BaseColorMap`, or the model's own
    /// texture), multiplied with `color`.
    pub albedo_map: Option<TextureRef>,
    /// The alpha of the tint colour (`_Color.a`, `_BaseColor.a`), multiplied with the
    /// map's alpha where the material uses alpha.
    pub opacity: f32,
    /// How the material's alpha is used.
    pub alpha: Alpha,
    /// The tangent-space normal map (`_BumpMap`, HDRP `_NormalMap`) where the shader's
    /// `_NORMALMAP` keyword turns it on.
    pub normal_map: Option<NormalMap>,
    /// The emission map (`_EmissionMap`), multiplied with `emission`, tiled as the albedo
    /// map.
    pub emission_map: Option<TextureRef>,
    /// The occlusion map (`_OcclusionMap`), darkening the ambient light and the mirror
    /// reflection, tiled as the albedo map.
    pub occlusion_map: Option<OcclusionMap>,
    /// The metallic map (`_MetallicGlossMap`), tiled as the albedo map: where set, metallic
    /// is its texel's red channel and smoothness its alpha times the map's scale (unless
    /// smoothness is in the albedo map's alpha), as the Standard and URP Lit shaders read it.
    pub metallic_map: Option<MetallicMap>,
    /// An unlit shader's material (the built-in Unlit and Sprites shaders, URP Unlit): its
    /// surface shows colour·map as it is, whatever the lights and ambient, mirrors nothing
    /// and casts no shadow (those shaders have no lighting and no shadow-caster pass).
    pub unlit: bool,
}

/// A material's occlusion map: the green channel g of its texel leaves 1 + (g − 1)·strength
/// of the light that does not come straight from a light (ambient and reflection), as
/// Unity's Standard and URP Lit shaders apply it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct OcclusionMap {
    pub map: TextureRef,
    /// `_OcclusionStrength`, 0–1.
    pub strength: f32,
}

impl OcclusionMap {
    /// The share of indirect light left where the map's green channel is `g`.
    pub fn left(&self, g: f32) -> f32 {
        1.0 + (g - 1.0) * self.strength
    }
}

/// A material's metallic map: metallic is the red channel r of its texel, smoothness its
/// alpha a times `smoothness` (the shaders' `_GlossMapScale`, URP Lit's `_Smoothness`).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct MetallicMap {
    pub map: TextureRef,
    /// The scale of the texel's alpha, 0–1; unused where smoothness is in the albedo map's
    /// alpha, whose scale is the material's `smoothness`.
    pub smoothness: f32,
}

/// A material's normal map: a linear texture whose red and green channels hold the
/// normal's tangent-space x (along increasing u) and y (along increasing v) as
/// `2·c − 1`; z follows from them, as Unity's shaders unpack it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct NormalMap {
    /// The texture, tiled as the albedo map (Unity's shaders apply the main texture's
    /// tiling to every map).
    pub map: TextureRef,
    /// `_BumpScale` (HDRP `_NormalScale`): x and y are multiplied by it.
    pub scale: f32,
}

/// The shader's blend mode as far as rays care (Standard `_Mode`, URP `_Surface` and
/// `_AlphaClip`).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum Alpha {
    /// Alpha is ignored.
    Opaque,
    /// Texels with alpha below `cutoff` (`_Cutoff`) are holes, for every ray.
    Cutout { cutoff: f32 },
    /// Transparent or Fade: alpha is the fraction of light the surface stops; the rest
    /// continues through it.
    Blend,
}

impl Material {
    /// Whether rays need the alpha at a hit to know if it is there at all.
    pub fn uses_alpha(&self) -> bool {
        self.alpha != Alpha::Opaque
    }

    /// Whether the material looks anything up by UV (an albedo, normal, emission,
    /// occlusion or metallic map).
    pub fn reads_uvs(&self) -> bool {
        self.albedo_map.is_some()
            || self.normal_map.is_some()
            || self.emission_map.is_some()
            || self.occlusion_map.is_some()
            || self.metallic_map.is_some()
    }

    /// The least and greatest smoothness anywhere on the surface: from 0 to its scale where
    /// the albedo map's alpha or a metallic map gives it, else its one value.
    pub fn smoothness_range(&self) -> (f32, f32) {
        match (&self.metallic_map, self.smoothness_in_alpha) {
            (_, true) => (0.0, self.smoothness),
            (Some(map), false) => (0.0, map.smoothness),
            (None, false) => (self.smoothness, self.smoothness),
        }
    }

    /// The smallest metallic value anywhere on the surface: a metallic map may hold 0.
    pub fn least_metallic(&self) -> f32 {
        if self.metallic_map.is_some() {
            0.0
        } else {
            self.metallic.clamp(0.0, 1.0)
        }
    }
}

impl Material {
    /// Unity's Default-Material: white, non-metallic, smoothness 0.5.
    pub fn unity_default() -> Self {
        Material {
            name: "Default-Material".into(),
            source: "builtin:Default-Material".into(),
            color: Vec3::ONE,
            metallic: 0.0,
            smoothness: 0.5,
            smoothness_in_alpha: false,
            pbs: true,
            highlights: true,
            reflections: true,
            reflectivity: None,
            emission: Vec3::ZERO,
            cull: Cull::Back,
            albedo_map: None,
            opacity: 1.0,
            alpha: Alpha::Opaque,
            normal_map: None,
            emission_map: None,
            occlusion_map: None,
            metallic_map: None,
            unlit: false,
        }
    }

    /// Lambert albedo: colour·(1 − metallic), because a metal's colour shows in its
    /// reflection, not in diffuse light; with a metallic map, its largest value. An unlit
    /// material's is its colour: what it shows.
    pub fn albedo(&self) -> Vec3 {
        self.albedo_at(self.least_metallic())
    }

    /// [`Material::albedo`] at a point whose metallic value is `metallic`.
    pub fn albedo_at(&self, metallic: f32) -> Vec3 {
        if self.unlit {
            return self.color;
        }
        self.color * (1.0 - metallic.clamp(0.0, 1.0))
    }

    /// Mirror reflectance, tinted by the colour: `_Reflectivity` if set, else
    /// metallic·smoothness, so only smooth metals mirror unless a material says otherwise.
    /// Where a map or the albedo map's alpha gives metallic or smoothness, this is its
    /// largest value.
    pub fn reflectance(&self) -> Vec3 {
        match &self.metallic_map {
            Some(map) if !self.smoothness_in_alpha => self.reflectance_at(1.0, map.smoothness),
            Some(_) => self.reflectance_at(1.0, self.smoothness),
            None => self.reflectance_at(self.metallic, self.smoothness),
        }
    }

    /// [`Material::reflectance`] at a point whose metallic value and smoothness are
    /// `metallic` and `smoothness`.
    pub fn reflectance_at(&self, metallic: f32, smoothness: f32) -> Vec3 {
        if self.unlit {
            return Vec3::ZERO;
        }
        let r = self
            .reflectivity
            .unwrap_or(metallic * smoothness)
            .clamp(0.0, 1.0);
        if self.reflectivity.is_some() {
            Vec3::splat(r)
        } else {
            self.color * r
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Shadows {
    None,
    Hard,
    Soft,
}

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum LightKind {
    /// Radiates in all directions from `position`, attenuated to zero at `range`.
    Point,
    /// A point light limited to a cone around `direction`; angles are full cone angles
    /// in degrees (`inner_angle` ≤ `angle`; equal means a hard edge).
    Spot { angle: f32, inner_angle: f32 },
    /// Parallel light travelling along `direction`; no falloff.
    Directional,
}

/// How a point or spot light weakens with distance and towards its cone's edge: Unity's
/// render pipelines each have their own formula (the renderer's `lights` module has both).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Attenuation {
    /// The built-in pipeline: 1/(1 + 25·x²) for x = distance/range, faded linearly to 0
    /// over the range's last fifth; a smoothstep across the spot's edge.
    BuiltIn,
    /// The Universal Render Pipeline (and the Lightweight one before it): the inverse
    /// square of the distance times (1 − x⁴)²; the square of a linear ramp across the
    /// spot's edge.
    Universal,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Light {
    pub name: String,
    pub kind: LightKind,
    pub position: Vec3,
    /// Unit vector the light shines along (Unity's local +Z, converted).
    pub direction: Vec3,
    /// Linear RGB; times `intensity`, the light's final colour as the project combines
    /// colour, intensity and colour temperature.
    pub color: Vec3,
    pub intensity: f32,
    /// Distance at which point and spot lights reach zero.
    pub range: f32,
    /// The pipeline's formula for distance and cone (directional lights have neither).
    pub attenuation: Attenuation,
    pub shadows: Shadows,
    /// Soft shadows: emitter radius in metres (point, spot) or angular diameter in degrees
    /// (directional).
    pub shadow_radius: f32,
    /// `m_Shadows.m_Strength`, 0–1: the share of the light a shadow takes away.
    pub shadow_strength: f32,
    /// `m_CullingMask.m_Bits`: bit `l` set means the light lights objects on layer `l`.
    pub culling_mask: u32,
}

impl Light {
    /// Whether the light lights an object on `layer`.
    pub fn lights_layer(&self, layer: u8) -> bool {
        layer < 32 && self.culling_mask >> layer & 1 == 1
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum ClearFlags {
    Skybox,
    SolidColor,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum AmbientMode {
    /// One colour (`sky`) everywhere.
    Flat,
    /// Sky above, equator at the horizon, ground below, by the normal's Y.
    Trilight,
    /// Unity's skybox ambient: the skybox's light on nine spherical harmonics, or the
    /// trilight of the colours under a skybox the soup does not hold.
    Skybox,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Ambient {
    pub mode: AmbientMode,
    /// Linear RGB, already multiplied by the ambient intensity.
    pub sky: Vec3,
    pub equator: Vec3,
    pub ground: Vec3,
    /// `m_AmbientIntensity`: it scales the skybox's light in Skybox mode.
    pub intensity: f32,
}

/// How fog thickens with the fog coordinate `c` (metres): the share of a surface's own
/// colour that is left is `(end − c) / (end − start)`, `e^(−density·c)` or
/// `e^(−(density·c)²)`, clamped to [0, 1], Unity's three fog modes.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum FogMode {
    Linear { start: f32, end: f32 },
    Exponential { density: f32 },
    ExponentialSquared { density: f32 },
}

impl FogMode {
    /// Whether its numbers are finite.
    pub fn is_finite(&self) -> bool {
        match *self {
            FogMode::Linear { start, end } => start.is_finite() && end.is_finite(),
            FogMode::Exponential { density } | FogMode::ExponentialSquared { density } => {
                density.is_finite()
            }
        }
    }
}

/// RenderSettings fog: each surface's colour is mixed toward `colour` by its distance.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Fog {
    pub mode: FogMode,
    /// Linear RGB.
    pub colour: Vec3,
}

impl Fog {
    /// The share of a surface's colour left at fog coordinate `c`, in [0, 1].
    pub fn keep(&self, c: f32) -> f32 {
        let f = match self.mode {
            FogMode::Linear { start, end } if end == start => (c < end) as u8 as f32,
            FogMode::Linear { start, end } => (end - c) / (end - start),
            FogMode::Exponential { density } => (-density * c).exp(),
            FogMode::ExponentialSquared { density } => (-(density * c) * (density * c)).exp(),
        };
        f.clamp(0.0, 1.0)
    }

    fn validate(&self) -> Result<(), String> {
        if !self.mode.is_finite() || !self.colour.is_finite() || self.colour.min_element() < 0.0 {
            return Err(format!("fog {:?} with colour {}", self.mode, self.colour));
        }
        Ok(())
    }
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Environment {
    pub clear: ClearFlags,
    /// The camera's solid background colour, linear RGB (used when `clear` is SolidColor).
    pub background: Vec3,
    pub ambient: Ambient,
    pub fog: Option<Fog>,
    /// RenderSettings' skybox, when it is one the renderer draws.
    pub sky: Option<Sky>,
    /// The colour space the project's shaders compute in.
    pub color_space: ColorSpace,
    /// How far from the camera realtime shadows reach, where the project's pipeline limits
    /// them (None: at any distance).
    pub shadow_distance: Option<ShadowDistance>,
    /// RenderSettings' Intensity Multiplier of the environment reflection, where the scene
    /// reflects its skybox (`m_DefaultReflectionMode` 0, built-in or URP, and `sky` set):
    /// physically based surfaces reflect the skybox as Unity's default reflection probe
    /// holds it, times this. 0: no environment reflection.
    pub reflection: f32,
}

/// URP's shadow distance: beyond `distance` from the camera no realtime shadow is drawn,
/// and the last stretch fades out over the `border` share of it (squared), as URP's
/// shaders fade a shadow toward the lit value.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ShadowDistance {
    /// The pipeline asset's Max Distance, metres.
    pub distance: f32,
    /// The last cascade's Border, 0–1 (a soup holding another value is refused); 0 cuts
    /// shadows off at `distance`.
    pub border: f32,
}

impl ShadowDistance {
    /// Where shadows end seen from `camera`: the shadow distance, or the camera's far
    /// plane where that is nearer (URP clamps one to the other).
    pub fn far(&self, camera: &Camera) -> f32 {
        if camera.far > camera.near {
            self.distance.min(camera.far)
        } else {
            self.distance
        }
    }

    /// The scale and bias URP's `GetScaleAndBiasForLinearDistanceFade` derives for a
    /// shadow that ends `far` from the camera (the smaller of `distance` and the camera's far
    /// plane): the fade at squared distance d² is clamp(d²·scale + bias, 0, 1), rising
    /// linearly in d² from (1 − border)²·far² to far². A border under 10⁻⁴ makes it a step.
    pub fn scale_bias(&self, far: f32) -> (f32, f32) {
        // A far plane so near that its square is zero ends shadows at the camera.
        let end = (far * far).max(f32::MIN_POSITIVE);
        if self.border < 1e-4 {
            let scale = 1000.0;
            return (scale, -end * scale);
        }
        let keep = (1.0 - self.border).powi(2);
        let start = keep * end;
        (1.0 / (end - start), -start / (end - start))
    }
}

/// The colour space a Unity project renders in (Player settings' Color Space).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum ColorSpace {
    /// Colours, textures and lights are decoded to linear values, shaded, and the frame is
    /// linear: every colour in the soup is linear RGB.
    #[default]
    Linear,
    /// Shaders compute on the stored, gamma-encoded values and the frame holds what the
    /// display shows: the soup's colours, light colours and texels are as Unity stores
    /// them (textures' `srgb` is false), the renderer shades them as they are and decodes
    /// each pixel from sRGB at the end; a procedural sky's light is the square root of its
    /// linear value, as Unity's gamma-space skybox shader outputs it.
    Gamma,
}

impl Default for Environment {
    fn default() -> Self {
        Environment {
            clear: ClearFlags::SolidColor,
            background: Vec3::ZERO,
            ambient: Ambient {
                mode: AmbientMode::Flat,
                sky: Vec3::ZERO,
                equator: Vec3::ZERO,
                ground: Vec3::ZERO,
                intensity: 1.0,
            },
            fog: None,
            sky: None,
            color_space: ColorSpace::Linear,
            shadow_distance: None,
            reflection: 0.0,
        }
    }
}

/// BLAKE3 of an indexed geometry: the positions, each coordinate as f32 little-endian, then
/// the triangles' indices as u32 little-endian. It names the soup's k-d tree in the cache.
pub fn indexed_geometry_hash(positions: &[Vec3], triangles: &[[u32; 3]]) -> Digest {
    let mut h = blake3::Hasher::new();
    hash_le(&mut h, positions);
    hash_le(&mut h, triangles);
    *h.finalize().as_bytes()
}

/// The geometry hash of bare triangles: that of a soup that gives each triangle three
/// vertices of its own, in order (what [`Soup::push_triangle`] builds).
pub fn geometry_hash(triangles: &[[Vec3; 3]]) -> Digest {
    let indices: Vec<[u32; 3]> = (0..triangles.len() as u32)
        .map(|t| [3 * t, 3 * t + 1, 3 * t + 2])
        .collect();
    indexed_geometry_hash(bytemuck::cast_slice(triangles), &indices)
}

/// On a little-endian machine the arrays in memory are the hashed bytes themselves, so a
/// soup's 50 MB of geometry (two million triangles) is hashed in place on all cores.
#[cfg(target_endian = "little")]
fn hash_le<T: bytemuck::Pod>(h: &mut blake3::Hasher, items: &[T]) {
    envelope::hash_into(h, bytemuck::cast_slice(items));
}

/// Elsewhere each 4-byte number (both arrays are made of them) is swapped first.
#[cfg(not(target_endian = "little"))]
fn hash_le<T: bytemuck::Pod>(h: &mut blake3::Hasher, items: &[T]) {
    let words: &[u32] = bytemuck::cast_slice(items);
    let mut buf = Vec::with_capacity(4 * 4096);
    for chunk in words.chunks(4096) {
        buf.clear();
        for w in chunk {
            buf.extend_from_slice(&w.to_le_bytes());
        }
        h.update(&buf);
    }
}

impl Soup {
    /// An empty soup with Unity's default camera and a black environment.
    pub fn empty() -> Self {
        Soup {
            positions: vec![],
            normals: vec![],
            uvs: vec![],
            triangles: vec![],
            tri_material: vec![],
            tri_object: vec![],
            objects: vec![],
            materials: vec![],
            textures: vec![],
            lights: vec![],
            camera: Camera::default(),
            environment: Environment::default(),
            warnings: vec![],
            dropped_degenerate: 0,
            geometry_hash: geometry_hash(&[]),
        }
    }

    /// Recompute `geometry_hash` from the geometry (call after changing it).
    pub fn seal(&mut self) {
        self.geometry_hash = indexed_geometry_hash(&self.positions, &self.triangles);
    }

    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// The positions of triangle `t`'s corners.
    #[inline]
    pub fn corners(&self, t: usize) -> [Vec3; 3] {
        self.triangles[t].map(|v| self.positions[v as usize])
    }

    /// The shading normals at triangle `t`'s corners.
    #[inline]
    pub fn corner_normals(&self, t: usize) -> [Vec3; 3] {
        self.triangles[t].map(|v| self.normals[v as usize])
    }

    /// The texture coordinates at triangle `t`'s corners; (0, 0) in a soup without UVs.
    #[inline]
    pub fn corner_uvs(&self, t: usize) -> [Vec2; 3] {
        if self.uvs.is_empty() {
            return [Vec2::ZERO; 3];
        }
        self.triangles[t].map(|v| self.uvs[v as usize])
    }

    /// Every triangle's corners, in soup order: what the k-d tree is built from.
    pub fn triangle_positions(&self) -> Vec<[Vec3; 3]> {
        corners(&self.positions, &self.triangles)
    }

    /// Append a triangle with three vertices of its own, and its UVs when the soup has
    /// them (`uvs` is ignored otherwise, and (0, 0) is stored when it is `None`). The
    /// caller appends its material and object.
    pub fn push_triangle(
        &mut self,
        corners: [Vec3; 3],
        normals: [Vec3; 3],
        uvs: Option<[Vec2; 3]>,
    ) {
        let first = self.positions.len() as u32;
        let with_uvs = uvs.is_some() || !self.uvs.is_empty();
        if with_uvs && self.uvs.len() < self.positions.len() {
            self.uvs.resize(self.positions.len(), Vec2::ZERO);
        }
        self.positions.extend(corners);
        self.normals.extend(normals);
        if with_uvs {
            self.uvs.extend(uvs.unwrap_or([Vec2::ZERO; 3]));
        }
        self.triangles.push([first, first + 1, first + 2]);
    }

    /// Check the cross-references a reader relies on, naming the first bad one.
    pub fn validate(&self) -> Result<(), String> {
        let n = self.triangles.len();
        let v = self.positions.len();
        if self.normals.len() != v {
            return Err(format!("{v} vertices but {} normals", self.normals.len()));
        }
        if self.tri_material.len() != n || self.tri_object.len() != n {
            return Err(format!(
                "{n} triangles but {} material indices, {} object indices",
                self.tri_material.len(),
                self.tri_object.len()
            ));
        }
        check_geometry(&self.positions, &self.triangles, &self.geometry_hash)?;
        if let Some(i) = crate::first_bad(&self.tri_material, |_, &m| {
            m as usize >= self.materials.len()
        }) {
            return Err(format!(
                "triangle {i} names material {} of {}",
                self.tri_material[i],
                self.materials.len()
            ));
        }
        if let Some(i) =
            crate::first_bad(&self.tri_object, |_, &o| o as usize >= self.objects.len())
        {
            return Err(format!(
                "triangle {i} names object {} of {}",
                self.tri_object[i],
                self.objects.len()
            ));
        }
        self.validate_textures()?;
        if let Some(fog) = &self.environment.fog {
            fog.validate()?;
        }
        if let Some(sky) = &self.environment.sky {
            sky.validate()?;
        }
        if let Some(d) = self.environment.shadow_distance {
            if !(d.distance > 0.0 && d.distance.is_finite() && (0.0..=1.0).contains(&d.border)) {
                return Err(format!(
                    "shadow distance {} with border {}",
                    d.distance, d.border
                ));
            }
        }
        let r = self.environment.reflection;
        if !(r.is_finite() && r >= 0.0) {
            return Err(format!("environment reflection intensity {r}"));
        }
        if !self.environment.ambient.intensity.is_finite() {
            return Err(format!(
                "ambient intensity {}",
                self.environment.ambient.intensity
            ));
        }
        if let Some(i) = self
            .lights
            .iter()
            .position(|l| !(0.0..=1.0).contains(&l.shadow_strength))
        {
            return Err(format!(
                "light {i} has shadow strength {}",
                self.lights[i].shadow_strength
            ));
        }
        if let Some(i) = self.objects.iter().position(|o| o.layer >= 32) {
            return Err(format!(
                "object {i} is on layer {}; Unity has 32",
                self.objects[i].layer
            ));
        }
        Ok(())
    }

    /// Textures, the materials' references to them, alpha settings and UVs: everything a
    /// texture lookup indexes or divides by.
    fn validate_textures(&self) -> Result<(), String> {
        for t in &self.textures {
            t.validate()?;
        }
        let n = self.positions.len();
        let textured = self.materials.iter().any(Material::reads_uvs);
        if !(self.uvs.is_empty() || self.uvs.len() == n) || (textured && self.uvs.len() != n) {
            return Err(format!(
                "{n} vertices but {} UVs{}",
                self.uvs.len(),
                if textured {
                    " (a material has a texture)"
                } else {
                    ""
                }
            ));
        }
        for (i, m) in self.materials.iter().enumerate() {
            if let Some(n) = &m.normal_map {
                if !n.scale.is_finite() {
                    return Err(format!("material {i} has normal map scale {}", n.scale));
                }
            }
            if let Some(g) = &m.metallic_map {
                if !(0.0..=1.0).contains(&g.smoothness) {
                    return Err(format!(
                        "material {i} has metallic map smoothness {}",
                        g.smoothness
                    ));
                }
            }
            if let Some(o) = &m.occlusion_map {
                if !(0.0..=1.0).contains(&o.strength) {
                    return Err(format!(
                        "material {i} has occlusion strength {}",
                        o.strength
                    ));
                }
            }
            let maps = [
                m.albedo_map.as_ref(),
                m.normal_map.as_ref().map(|n| &n.map),
                m.emission_map.as_ref(),
                m.occlusion_map.as_ref().map(|o| &o.map),
                m.metallic_map.as_ref().map(|g| &g.map),
            ];
            for r in maps.into_iter().flatten() {
                if r.texture as usize >= self.textures.len() {
                    return Err(format!(
                        "material {i} names texture {} of {}",
                        r.texture,
                        self.textures.len()
                    ));
                }
                if !r.tiling.is_finite() {
                    return Err(format!("material {i} has a non-finite texture tiling"));
                }
            }
            let cutoff_ok = match m.alpha {
                Alpha::Cutout { cutoff } => cutoff.is_finite(),
                Alpha::Opaque | Alpha::Blend => true,
            };
            if !(0.0..=1.0).contains(&m.opacity) || !cutoff_ok {
                return Err(format!(
                    "material {i} has opacity {} and alpha {:?}",
                    m.opacity, m.alpha
                ));
            }
        }
        if let Some(i) = crate::first_bad(&self.uvs, |_, uv| !uv.is_finite()) {
            return Err(format!("vertex {i} has a non-finite UV"));
        }
        Ok(())
    }

    pub fn to_bytes(&self, path: &Path) -> Result<Vec<u8>, FormatError> {
        envelope::encode(self, path)
    }

    pub fn from_bytes(bytes: &[u8], path: &Path) -> Result<Self, FormatError> {
        envelope::decode(bytes, path)
    }

    /// Write atomically (temp file + rename), the bytes of [`Soup::to_bytes`] streamed.
    pub fn write(&self, path: &Path) -> Result<(), FormatError> {
        envelope::write(self, path)
    }

    pub fn read(path: &Path) -> Result<Self, FormatError> {
        Self::from_bytes(&envelope::read_file(path)?, path)
    }
}

impl envelope::Checked<Soup> {
    /// The soup's [`SoupKey`]: the triangles' count and the last field, without decoding
    /// or checking the rest ([`Soup::read`] does; a renderer reading the soup refuses one
    /// whose geometry hash does not match its triangles).
    pub fn key(&self) -> Result<SoupKey, FormatError> {
        self.read(|r| {
            r.skip_array::<Vec3>("positions")?;
            r.skip_array::<Vec3>("normals")?;
            r.skip_array::<Vec2>("uvs")?;
            let triangles = r.skip_array::<[u32; 3]>("triangles")?;
            let geometry_hash = r.last::<32>("the geometry hash")?;
            Ok(SoupKey {
                triangles,
                geometry_hash,
            })
        })
    }

    /// The soup's [`SoupGeometry`]: positions and triangles decoded and checked as
    /// [`Soup::read`] checks them, the rest (normals, materials, textures …) neither
    /// decoded nor checked.
    pub fn geometry(&self) -> Result<SoupGeometry, FormatError> {
        self.read(|r| {
            let positions = r.array("positions")?;
            r.skip_array::<Vec3>("normals")?;
            r.skip_array::<Vec2>("uvs")?;
            let triangles = r.array("triangles")?;
            let geometry_hash = r.last::<32>("the geometry hash")?;
            check_geometry(&positions, &triangles, &geometry_hash)?;
            Ok(SoupGeometry {
                positions,
                triangles,
                geometry_hash,
            })
        })
    }
}

/// Three corners per triangle, gathered on all cores.
fn corners(positions: &[Vec3], triangles: &[[u32; 3]]) -> Vec<[Vec3; 3]> {
    use rayon::prelude::*;
    triangles
        .par_iter()
        .with_min_len(1 << 14)
        .map(|t| t.map(|v| positions[v as usize]))
        .collect()
}

/// Every triangle names existing vertices, every vertex is finite, and the geometry hash is
/// theirs.
fn check_geometry(positions: &[Vec3], triangles: &[[u32; 3]], hash: &Digest) -> Result<(), String> {
    let v = positions.len();
    if let Some(i) = crate::first_bad(triangles, |_, t| t.iter().any(|&i| i as usize >= v)) {
        return Err(format!(
            "triangle {i} names vertices {:?} of {v}",
            triangles[i]
        ));
    }
    if let Some(i) = crate::first_bad(positions, |_, p| !p.is_finite()) {
        return Err(format!("vertex {i} is not finite"));
    }
    if indexed_geometry_hash(positions, triangles) != *hash {
        return Err("geometry hash does not match the triangles".into());
    }
    Ok(())
}

/// What a tree is built from: a soup's positions and triangles and their hash
/// (`Checked::<Soup>::geometry`).
#[derive(Clone, Debug, PartialEq)]
pub struct SoupGeometry {
    pub positions: Vec<Vec3>,
    pub triangles: Vec<[u32; 3]>,
    pub geometry_hash: Digest,
}

impl SoupGeometry {
    /// The corners of each triangle.
    pub fn triangle_positions(&self) -> Vec<[Vec3; 3]> {
        corners(&self.positions, &self.triangles)
    }
}

/// What finding a soup's cached tree takes: its triangle count and geometry hash.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SoupKey {
    pub triangles: usize,
    pub geometry_hash: Digest,
}

/// The fields after the geometry arrays, in payload order.
type SoupRest = (
    Vec<Object>,
    Vec<Material>,
    Vec<Texture>,
    Vec<Light>,
    Camera,
    Environment,
    Vec<String>,
    u64,
    Digest,
);

/// The fields in the order of SOUP.md (the order of the struct, so the bytes are those of its
/// serde encoding), the geometry arrays as blocks.
impl envelope::Artifact for Soup {
    const MAGIC: &'static [u8; 8] = MAGIC;
    const VERSION: u32 = VERSION;
    const KIND: &'static str = "soup";

    fn write_payload<W: std::io::Write + Send>(
        &self,
        p: &mut envelope::PayloadWriter<W>,
    ) -> Result<(), FormatError> {
        p.array(&self.positions)?;
        p.array(&self.normals)?;
        p.array(&self.uvs)?;
        p.array(&self.triangles)?;
        p.array(&self.tri_material)?;
        p.array(&self.tri_object)?;
        p.value(&(
            &self.objects,
            &self.materials,
            &self.textures,
            &self.lights,
            &self.camera,
            &self.environment,
            &self.warnings,
            self.dropped_degenerate,
            &self.geometry_hash,
        ))
    }

    fn read_payload(r: &mut envelope::PayloadReader) -> Result<Self, String> {
        let positions = r.array("positions")?;
        let normals = r.array("normals")?;
        let uvs = r.array("uvs")?;
        let triangles = r.array("triangles")?;
        let tri_material = r.array("tri_material")?;
        let tri_object = r.array("tri_object")?;
        let (
            objects,
            materials,
            textures,
            lights,
            camera,
            environment,
            warnings,
            dropped_degenerate,
            geometry_hash,
        ): SoupRest = r.value("the fields after tri_object")?;
        Ok(Soup {
            positions,
            normals,
            uvs,
            triangles,
            tri_material,
            tri_object,
            objects,
            materials,
            textures,
            lights,
            camera,
            environment,
            warnings,
            dropped_degenerate,
            geometry_hash,
        })
    }

    fn validate(&self) -> Result<(), String> {
        Soup::validate(self)
    }
}
