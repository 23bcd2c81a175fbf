//! Whitted ray tracing, driven by the effects plan:
//!
//! ```text
//! L = emission + ambient(n)·diffuse colour
//!   + Σ_lights visible · falloff · intensity·colour · (max(0, n·l) · diffuse colour · shape
//!     + highlight)
//!   + max(0, environment(n·v) − reflectance) · probe(r, smoothness)
//!   + reflectance · L(mirror ray)        while bounce < depth and weight ≥ cutoff
//! ```
//!
//! n is the interpolated shading normal turned to face the incoming ray; the geometric
//! normal decides which side a secondary ray leaves from (see [`crate::offset`]).
//!
//! For a physically based material the diffuse colour is the albedo times the share its
//! shader lights as diffuse, the shape 1 (URP) or the built-in pipeline's Disney term, and
//! the highlight the specular term of the pipeline's shader for a punctual light (see
//! [`crate::brdf`]); otherwise the diffuse colour is the albedo, the shape 1 and there is
//! no highlight. Where the scene reflects its skybox, a physically based surface also takes
//! it from Unity's default reflection probe ([`crate::probe`]) along r, the view mirrored
//! about n, by its pipeline's environment term, less what its traced mirror ray brings.
//!
//! Albedo is colour·texel·(1 − metallic) where the material has a map and the plan turns
//! textures on: the texel is looked up at the hit's interpolated UV through the material's
//! tiling, filtered over the footprint of the pixel's ray cone (see [`crate::cone`]). Alpha
//! (see [`crate::alpha`]): cut-out holes are refused inside the traversals; a blended
//! surface mixes α of its own light with 1 − α of what lies behind it.
//!
//! Unity's draw rules: camera and reflection rays pass through faces their material culls
//! and shadows-only objects; shadow rays pass through objects that cast no shadow and
//! faces the material culls seen from the light (unless the object casts two-sided); a
//! surface that receives no shadows is lit unoccluded; a light lights only the layers in
//! its mask. Passing through is the same ray again with `tmin` just above the hit's t:
//! the same ray parameters give the same t for that triangle, so it is never found again.
//!
//! This file holds the recursion: camera samples, shading by the lights, mirrors and blended
//! layers. What a hit's surface is lives in `surface`, what camera and mirror rays see in
//! `visibility`, and how much of a light reaches a point in `shadows`.

use crate::alpha::{alpha_use, AlphaUse};
use crate::brdf::{Brdf, Diffuse, Gloss};
use crate::cone::RayCone;
use crate::counters::RayCounts;
use crate::environment;
use crate::fog::FogModel;
use crate::lights::{incident, Incident};
use crate::normal_map;
use crate::offset::{
    hit_point, intersector_margin, offset_origin, SHADOW_TMAX_FRACTION, SPAWN_TMIN,
};
use crate::plan::{colour_mapped, Plan, ShadowMode};
use crate::probe::Probe;
use crate::sampling::{DiscSpiral, Rng};
use crate::sky::{SkyAmbient, Skybox};
use crate::soft::{probe_asked, probe_fits, SoftCone};
use crate::tangents::Tangents;
use crate::texture::{cone_footprint, Sampler};
use crate::RenderOptions;
use crate::TextureFilter;
use formats::{AmbientMode, Attenuation, CastShadows, ClearFlags, Hit, Light, Soup, Tiling};
use glam::{Vec2, Vec3, Vec4};
use kdtree::triangle::RayPre;
use kdtree::{Accel, Ray, LANES};
use rayon::prelude::*;

mod shadows;
mod surface;
mod visibility;

pub(crate) use shadows::shadow_ray;

/// What the first hit of a camera ray tells the AOVs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Primary {
    pub depth: f32,
    pub normal: Vec3,
    pub albedo: Vec3,
    pub object: f32,
}

impl Primary {
    pub const MISS: Primary = Primary {
        depth: f32::MAX,
        normal: Vec3::ZERO,
        albedo: Vec3::ZERO,
        object: -1.0,
    };
}

struct ActiveLight<'a> {
    light: &'a Light,
    shadows: ShadowMode,
}

impl ActiveLight<'_> {
    /// The share of the light that reaches a point whose shadow rays let `visible` of it
    /// through: a shadow of strength s takes s of what it blocks away, as in Unity.
    #[inline(always)]
    fn unshadowed(&self, visible: f32) -> f32 {
        let s = self.light.shadow_strength;
        if s >= 1.0 {
            visible
        } else {
            1.0 - s * (1.0 - visible)
        }
    }
}

/// A shaded point and what it takes to leave it robustly (see [`crate::offset`]).
struct Surface {
    p: Vec3,
    err: Vec3,
    margin: f32,
    /// Unit geometric normal.
    ng: Vec3,
}

impl Surface {
    fn spawn(&self, dir: Vec3) -> Vec3 {
        offset_origin(self.p, self.err, self.margin, self.ng, dir)
    }
}

/// A surface point being shaded: what its lights and mirror ray need, and the light
/// gathered so far.
struct Lit {
    l: Vec3,
    /// The surface's α.
    a: f32,
    /// The colour its diffuse term lights: the albedo, times the diffuse share of a
    /// physically based material.
    albedo: Vec3,
    /// The shape of its diffuse term.
    diffuse: Diffuse,
    /// Unit direction towards the eye.
    view: Vec3,
    /// The glossy side of the surface, where it reflects the lights' highlights.
    gloss: Option<Gloss>,
    /// The albedo or the gloss is not black, so lights can show.
    lit: bool,
    surf: Surface,
    /// Unit shading normal, facing the ray.
    ns: Vec3,
    layer: u8,
    /// The object receives shadows.
    receives: bool,
    /// How far its shadows have faded out with distance from the camera: 0 where they are
    /// whole, 1 where none is drawn ([`ShadowFade`]).
    fade: f32,
    reflectance: Vec3,
}

impl Lit {
    /// Adds a light's share arriving from `inc` at cosine `cos`, `visible` of it unshadowed
    /// before the shadow's fade with distance.
    #[inline(always)]
    fn add(&mut self, inc: &Incident, cos: f32, visible: f32) {
        let visible = if self.fade > 0.0 {
            visible + (1.0 - visible) * self.fade
        } else {
            visible
        };
        if visible > 0.0 {
            let lv = inc.dir.dot(self.view);
            let mut reflected = self.albedo * (cos * self.diffuse.scale(lv, cos));
            if let Some(g) = &self.gloss {
                reflected += g.highlight(self.ns, self.view, inc.dir, cos);
            }
            self.l += inc.radiance * visible * reflected;
        }
    }
}

/// URP's shadow fade with distance from the camera: a shadow's light becomes
/// lerp(shadowed, lit, fade), the fade clamp(d²·scale + bias, 0, 1) at squared distance d²,
/// as URP's `GetMainLightShadowFade` computes it (see [`formats::ShadowDistance`]).
#[derive(Clone, Copy, Debug)]
struct ShadowFade {
    camera: Vec3,
    scale: f32,
    bias: f32,
}

impl ShadowFade {
    /// The fade of `soup`'s shadows, where its pipeline limits their distance and some
    /// light traces shadows: they end at the shadow distance or the camera's far plane,
    /// whichever is nearer.
    fn of(soup: &Soup, lights: &[ActiveLight]) -> Option<ShadowFade> {
        let d = soup.environment.shadow_distance?;
        if lights.iter().all(|l| l.shadows == ShadowMode::None) {
            return None;
        }
        let (scale, bias) = d.scale_bias(d.far(&soup.camera));
        Some(ShadowFade {
            camera: soup.camera.position,
            scale,
            bias,
        })
    }

    /// The fade at point `p`: 0 where shadows are whole, 1 where none is drawn.
    fn at(&self, p: Vec3) -> f32 {
        let f = (p - self.camera).length_squared() * self.scale + self.bias;
        // Written so that a NaN (a far plane at the camera) keeps the shadow whole.
        if f >= 1.0 {
            1.0
        } else if f > 0.0 {
            f
        } else {
            0.0
        }
    }
}

/// A shaded point's mirror ray, its cone, the weight it carries to the eye and the
/// reflectance its light is scaled by.
#[derive(Clone, Copy)]
struct Mirror {
    ray: Ray,
    cone: RayCone,
    weight: Vec3,
    reflectance: Vec3,
}

/// What a material needs from its texture, resolved once per render.
struct Surfacing {
    /// The sampler (index into `Integrator::samplers`) and tiling of its map.
    map: Option<(usize, Tiling)>,
    /// The albedo is multiplied by the map's colour.
    colour: bool,
    /// The normal map's sampler, tiling and scale, where the plan reads it.
    normal: Option<(usize, Tiling, f32)>,
    /// The emission map's sampler and tiling, where the plan reads it for a glowing material.
    emission: Option<(usize, Tiling)>,
    /// The occlusion map's sampler, tiling and strength, where the plan reads it.
    occlusion: Option<(usize, Tiling, f32)>,
    /// The metallic map's sampler, tiling and smoothness scale, where the plan reads it.
    metallic: Option<(usize, Tiling, f32)>,
    alpha: AlphaUse,
    opacity: f32,
}

/// What a camera or mirror ray has gathered from the blended layers it passed: their light,
/// and the share of what lies behind them that still reaches the eye.
#[derive(Clone, Copy)]
struct Layers {
    acc: Vec3,
    through: f32,
}

impl Layers {
    const NONE: Layers = Layers {
        acc: Vec3::ZERO,
        through: 1.0,
    };
}

/// Where a ray goes on behind a blended hit: past the surface point, and past the triangle
/// sharing the edge it may lie on.
fn past(hit: &Hit) -> f32 {
    (hit.t + hit.t * SAME_SURFACE).max(hit.t.next_up())
}

/// Two hits of one object closer than this fraction of their distance are one surface
/// point: the any-hit query reports a triangle once per leaf it spans, and a ray through an
/// edge meets both triangles that share it (at t a few ulps apart). Distinct layers this
/// close would z-fight in Unity's depth buffer, which is far coarser.
const SAME_SURFACE: f32 = 1e-5;

fn same_surface(t0: f32, t1: f32) -> bool {
    (t0 - t1).abs() <= SAME_SURFACE * t0.max(t1)
}

/// Blended surface points a shadow ray has already been attenuated by, as (object, t).
/// Eight fit inline; deeper stacks spill.
struct Seen {
    inline: [(u32, f32); 8],
    len: usize,
    spill: Vec<(u32, f32)>,
}

impl Seen {
    fn new() -> Self {
        Seen {
            inline: [(0, 0.0); 8],
            len: 0,
            spill: Vec::new(),
        }
    }

    /// True the first time a point of `object` at `t` is offered.
    fn first(&mut self, object: u32, t: f32) -> bool {
        let seen = |&(o, s): &(u32, f32)| o == object && same_surface(s, t);
        if self.inline[..self.len].iter().any(seen) || self.spill.iter().any(seen) {
            return false;
        }
        if self.len < self.inline.len() {
            self.inline[self.len] = (object, t);
            self.len += 1;
        } else {
            self.spill.push((object, t));
        }
        true
    }
}

pub struct Integrator<'a> {
    soup: &'a Soup,
    accel: &'a Accel,
    lights: Vec<ActiveLight<'a>>,
    ambient: bool,
    emission: bool,
    max_depth: u32,
    cutoff: f32,
    soft_samples: u32,
    /// The render probes soft shadows at their rim (`soft::probe_asked`).
    soft_probe: bool,
    /// Camera and reflection rays check their hits against the culling rules.
    culling: bool,
    /// Shadow rays ask each hit whether it casts (non-casting surfaces, culled faces).
    shadow_filter: bool,
    /// Cut-out and blended materials are honoured (the plan's alpha effect).
    alpha: bool,
    filter: TextureFilter,
    /// One per soup texture, built when textures or alpha are on (else empty).
    samplers: Vec<Option<Sampler<'a>>>,
    /// One per material (empty when textures and alpha are off).
    surfacing: Vec<Surfacing>,
    /// Some material is blended: shadow rays through cut-out and blended casters meet
    /// them front to back, so that the light left, a product, rounds in the order the
    /// layers lie. Without blending every hit is judged on its own and the walk takes the
    /// far child first, which finds a blocker sooner.
    blend: bool,
    /// Per triangle, the sides it is drawn and casts from ([`DRAWN_FRONT`] …): what the
    /// traversals' filters ask, one byte instead of the object's and the material's records
    /// (empty when no face is culled and every object casts).
    sides: Vec<u8>,
    /// The scene's fog, when the plan turns it on.
    fog: Option<FogModel>,
    /// The skybox a Skybox camera shows, when the scene has one.
    sky: Option<Skybox<'a>>,
    /// The ambient light of the skybox, where the ambient mode is Skybox. Boxed: inline, the
    /// compiler worked out the harmonics' constant term ahead of the branch on it, from the
    /// bytes an absent value leaves, and where those read as subnormal numbers Intel cores
    /// took a microcode assist at every block of pixels (the baseline traced 6–9 % slower).
    sky_ambient: Option<Box<SkyAmbient>>,
    /// The MikkTSpace tangents of the objects whose normal map the plan reads, each
    /// object's computed when a ray first reads its map.
    tangents: Option<Tangents<'a>>,
    /// How shadows fade out with distance from the camera, where the pipeline limits it.
    shadow_fade: Option<ShadowFade>,
    /// The pipeline's formulas for physically based materials.
    brdf: Brdf,
    /// The skybox as Unity's default reflection probe holds it, where the plan has
    /// physically based surfaces reflect it.
    probe: Option<Box<Probe>>,
}

/// [`Integrator::sides`] bits: camera and reflection rays that meet the triangle's front
/// (back) stop there; shadow rays that meet its front (back) are blocked.
const DRAWN_FRONT: u8 = 1;
const DRAWN_BACK: u8 = 2;
const CASTS_FRONT: u8 = 4;
const CASTS_BACK: u8 = 8;

/// Each triangle's [`Integrator::sides`] bits, from its object's and material's rules.
fn sides(soup: &Soup) -> Vec<u8> {
    soup.tri_object
        .par_iter()
        .zip(&soup.tri_material)
        .map(|(&o, &m)| {
            let obj = &soup.objects[o as usize];
            let cull = soup.materials[m as usize].cull;
            // The shadow pass sees a face from the light, so from the side the shadow ray
            // did not meet.
            let unlit = soup.materials[m as usize].unlit;
            let casts = |front: bool| match obj.cast_shadows {
                _ if unlit => false,
                CastShadows::Off => false,
                CastShadows::TwoSided => true,
                CastShadows::On | CastShadows::ShadowsOnly => !cull.skips(!front),
            };
            let drawn = |front: bool| obj.visible() && !cull.skips(front);
            [
                (drawn(true), DRAWN_FRONT),
                (drawn(false), DRAWN_BACK),
                (casts(true), CASTS_FRONT),
                (casts(false), CASTS_BACK),
            ]
            .iter()
            .fold(0, |b, &(on, bit)| if on { b | bit } else { b })
        })
        .collect()
}

/// The skybox's reflection probe, where the plan has surfaces reflect it.
fn probe(soup: &Soup, plan: &Plan) -> Option<Probe> {
    let env = &soup.environment;
    let sky = env.sky.as_ref().filter(|_| plan.sky_reflections.enabled)?;
    let sky = Skybox::new(sky, env.color_space);
    Some(Probe::new(
        |d, spread| sky.radiance(d, spread),
        env.reflection,
        plan.sky_reflections.levels,
    ))
}

/// The skybox's ambient light, where the plan lights surfaces with skybox ambient.
fn sky_ambient(soup: &Soup, plan: &Plan) -> Option<SkyAmbient> {
    let env = &soup.environment;
    let sky = env
        .sky
        .as_ref()
        .filter(|_| env.ambient.mode == AmbientMode::Skybox)?;
    plan.ambient
        .enabled
        .then(|| Skybox::new(sky, env.color_space).ambient(env.ambient.intensity))
}

/// Replace NaN and ±Inf channels by 0; true when something was replaced.
pub fn sanitize(v: &mut Vec3) -> bool {
    if v.is_finite() {
        return false;
    }
    *v = Vec3::from_array(v.to_array().map(|c| if c.is_finite() { c } else { 0.0 }));
    true
}

impl<'a> Integrator<'a> {
    /// Builds a sampler (the mip levels below the full-size image) for each texture the
    /// plan reads, so this is the render's texture setup step (`setup_seconds`).
    pub fn new(soup: &'a Soup, accel: &'a Accel, plan: &Plan, opts: &RenderOptions) -> Self {
        let lights: Vec<ActiveLight> = soup
            .lights
            .iter()
            .zip(&plan.lights)
            .filter(|(_, p)| p.enabled && plan.direct.enabled)
            .map(|(light, p)| ActiveLight {
                light,
                shadows: p.shadows,
            })
            .collect();
        let shadow_fade = ShadowFade::of(soup, &lights);
        // A scene's lights all follow its pipeline; one without lights is shaded as the
        // built-in pipeline would (only its ambient light's diffuse share depends on it).
        let pipeline = soup
            .lights
            .first()
            .map_or(Attenuation::BuiltIn, |l| l.attenuation);
        let brdf = Brdf::of(pipeline, soup.environment.color_space);
        let textures = plan.textures.enabled;
        let alpha = plan.alpha.enabled;
        let read = &plan.textures.read;
        let (samplers, surfacing) = if alpha || read.contains(&true) {
            let surfacing = soup
                .materials
                .iter()
                .map(|m| Surfacing {
                    map: m
                        .albedo_map
                        .map(|r| (r.texture as usize, r.tiling))
                        .filter(|_| textures || alpha),
                    colour: textures && colour_mapped(m),
                    normal: m
                        .normal_map
                        .filter(|n| plan.normal_maps.enabled && read[n.map.texture as usize])
                        .map(|n| (n.map.texture as usize, n.map.tiling, n.scale)),
                    emission: m
                        .emission_map
                        .filter(|r| {
                            plan.emission.enabled
                                && m.emission.max_element() > 0.0
                                && read[r.texture as usize]
                        })
                        .map(|r| (r.texture as usize, r.tiling)),
                    occlusion: m
                        .occlusion_map
                        .filter(|o| read[o.map.texture as usize])
                        .map(|o| (o.map.texture as usize, o.map.tiling, o.strength)),
                    metallic: m
                        .metallic_map
                        .filter(|g| read[g.map.texture as usize])
                        .map(|g| (g.map.texture as usize, g.map.tiling, g.smoothness)),
                    alpha: if alpha {
                        alpha_use(m, &plan.alpha.min_alpha)
                    } else {
                        AlphaUse::Opaque
                    },
                    opacity: m.opacity,
                })
                .collect();
            // Only the textures a used material reads get mip levels, each on a thread.
            let samplers = soup
                .textures
                .par_iter()
                .zip(&plan.textures.read)
                .map(|(t, &read)| read.then(|| Sampler::new(t)))
                .collect();
            (samplers, surfacing)
        } else {
            (Vec::new(), Vec::new())
        };
        let shadow_filter = plan.shadow_casting.enabled || alpha;
        let blend = surfacing.iter().any(|s| s.alpha == AlphaUse::Blend);
        let normal_mapped: Vec<bool> = surfacing.iter().map(|s| s.normal.is_some()).collect();
        let tangents = normal_mapped
            .contains(&true)
            .then(|| Tangents::new(soup, &normal_mapped));
        Integrator {
            soup,
            accel,
            lights,
            ambient: plan.ambient.enabled,
            emission: plan.emission.enabled,
            max_depth: if plan.reflections.enabled {
                plan.reflections.depth
            } else {
                0
            },
            cutoff: plan.reflections.cutoff,
            soft_samples: opts.soft_samples,
            soft_probe: probe_asked(opts),
            culling: plan.culling.enabled,
            shadow_filter,
            alpha,
            filter: opts.texture_filter,
            samplers,
            surfacing,
            blend,
            sides: if plan.culling.enabled || shadow_filter {
                sides(soup)
            } else {
                Vec::new()
            },
            fog: soup
                .environment
                .fog
                .filter(|_| plan.fog.enabled)
                .map(|f| FogModel::new(f, &soup.camera)),
            sky: soup
                .environment
                .sky
                .as_ref()
                .filter(|_| soup.environment.clear == ClearFlags::Skybox)
                .map(|sky| Skybox::new(sky, soup.environment.color_space)),
            sky_ambient: sky_ambient(soup, plan).map(Box::new),
            tangents,
            shadow_fade,
            brdf,
            probe: probe(soup, plan).map(Box::new),
        }
    }

    /// Bytes of the mip levels this render built (the full-size images are the soup's).
    pub fn texture_bytes(&self) -> u64 {
        self.samplers.iter().flatten().map(Sampler::bytes).sum()
    }

    /// Radiance along a camera ray (counted), with what its first hit tells the AOVs.
    /// The result is always finite (non-finite channels are zeroed and counted).
    /// `cone` is the pixel's ray cone ([`crate::CameraModel::cone`]).
    pub fn camera_sample(
        &self,
        ray: &Ray,
        cone: RayCone,
        rng: &mut Rng,
        counts: &mut RayCounts,
    ) -> (Vec3, Primary) {
        let first = self.first_visible(ray, cone, counts);
        let mut primary = Primary::MISS;
        let l = self.radiance_from(
            ray,
            first,
            cone,
            0,
            Vec3::ONE,
            rng,
            counts,
            Some(&mut primary),
        );
        finish_camera(l, primary, counts)
    }

    /// [`Integrator::camera_sample`] for the rays of four neighbouring pixels, traced
    /// together: their first hits, each light's hard shadow rays and their mirror rays, one
    /// packet query each, level by level. The same four results and counts, bit for bit.
    pub fn camera_sample4(
        &self,
        rays: &[Ray; LANES],
        cone: RayCone,
        rngs: &mut [Rng; LANES],
        counts: &mut RayCounts,
    ) -> [(Vec3, Primary); LANES] {
        let mut primary = [Primary::MISS; LANES];
        let mut slots = primary.each_mut().map(Some);
        let l = self.radiance4(
            rays,
            [true; LANES],
            [cone; LANES],
            0,
            [Vec3::ONE; LANES],
            rngs,
            counts,
            &mut slots,
        );
        std::array::from_fn(|i| finish_camera(l[i], primary[i], counts))
    }

    /// [`Integrator::radiance`] on four rays that travel side by side, lane by lane the
    /// same results, counts and draws from each lane's generator: their first hits are
    /// found together, then each light's hard shadow rays from those hits and their mirror
    /// rays are traced together, level by level ([`Integrator::shade4`]), and the lanes
    /// that see through a blended surface go on to the next layer together, with
    /// [`Integrator::radiance_from`]'s arithmetic. Lanes not `live` trace nothing and send
    /// back black.
    #[allow(clippy::too_many_arguments)]
    fn radiance4(
        &self,
        rays: &[Ray; LANES],
        live: [bool; LANES],
        cones: [RayCone; LANES],
        bounce: u32,
        weights: [Vec3; LANES],
        rngs: &mut [Rng; LANES],
        counts: &mut RayCounts,
        primary: &mut [Option<&mut Primary>; LANES],
    ) -> [Vec3; LANES] {
        let mut rays = std::array::from_fn(|i| if live[i] { rays[i] } else { no_ray() });
        let mut going = live;
        let mut layers = [Layers::NONE; LANES];
        let mut out = [Vec3::ZERO; LANES];
        loop {
            let first = self.first_visible4(&rays, &cones, counts);
            let through = layers.map(|f| f.through);
            let shaded = self.shade4(
                &rays, &first, &cones, bounce, weights, through, rngs, counts, primary,
            );
            let was = going;
            for i in (0..LANES).filter(|&i| was[i]) {
                going[i] = false;
                let (Some(hit), Some(shaded)) = (first[i], shaded[i]) else {
                    out[i] = self.beyond(&layers[i], rays[i].dir, cones[i].spread);
                    continue;
                };
                let shaded = self.fogged(shaded, &rays[i], &hit, bounce, counts);
                if let Some(done) = self.fold(&mut layers[i], weights[i], shaded) {
                    out[i] = done;
                    continue;
                }
                counts.blend_continuation += 1;
                rays[i].tmin = past(&hit);
                going[i] = true;
            }
            if going == [false; LANES] {
                return out;
            }
            for i in 0..LANES {
                if !going[i] {
                    rays[i] = no_ray();
                }
            }
        }
    }

    /// A layer's light `l` and α `a` folded into what a ray has gathered: its radiance when
    /// the layer ends it (opaque, or what passes too faint to matter by the reflection
    /// cut-off's rule), None when it goes on behind the layer. `weight` is the ray's.
    #[inline(always)]
    fn fold(&self, layers: &mut Layers, weight: Vec3, (l, a): (Vec3, f32)) -> Option<Vec3> {
        if !self.alpha || (a >= 1.0 && layers.through == 1.0) {
            return Some(l);
        }
        layers.acc += l * (a * layers.through);
        layers.through *= 1.0 - a;
        let faint = self.cutoff.max(f32::MIN_POSITIVE);
        (a >= 1.0 || (weight * layers.through).max_element() < faint).then_some(layers.acc)
    }

    /// A layer's light `l` and α `a` as seen through the fog from where `ray` began (the
    /// background is not fogged: it is not a surface).
    #[inline(always)]
    fn fogged(
        &self,
        (l, a): (Vec3, f32),
        ray: &Ray,
        hit: &Hit,
        bounce: u32,
        counts: &mut RayCounts,
    ) -> (Vec3, f32) {
        match &self.fog {
            Some(fog) => {
                counts.fogged += 1;
                (fog.apply(l, ray, hit.t, bounce), a)
            }
            None => (l, a),
        }
    }

    /// The radiance of a ray that leaves the scene along `dir` behind its blended layers,
    /// its cone `spread` radians wide.
    #[inline(always)]
    fn beyond(&self, layers: &Layers, dir: Vec3, spread: f32) -> Vec3 {
        let bg = environment::background(&self.soup.environment, self.sky.as_ref(), dir, spread);
        if layers.through == 1.0 {
            bg
        } else {
            layers.acc + bg * layers.through
        }
    }

    /// Radiance along `ray`: the first visible surface's, and where that surface is
    /// blended, mixed with what the same ray meets behind it (each layer a continuation).
    #[allow(clippy::too_many_arguments)]
    fn radiance(
        &self,
        ray: &Ray,
        cone: RayCone,
        bounce: u32,
        weight: Vec3,
        rng: &mut Rng,
        counts: &mut RayCounts,
        primary: Option<&mut Primary>,
    ) -> Vec3 {
        let first = self.first_visible(ray, cone, counts);
        self.radiance_from(ray, first, cone, bounce, weight, rng, counts, primary)
    }

    /// [`Integrator::radiance`] once the ray's first visible hit, `first`, is known: that
    /// surface's light and, where it is blended, what lies behind it, layer by layer.
    #[allow(clippy::too_many_arguments)]
    fn radiance_from(
        &self,
        ray: &Ray,
        first: Option<Hit>,
        cone: RayCone,
        bounce: u32,
        weight: Vec3,
        rng: &mut Rng,
        counts: &mut RayCounts,
        primary: Option<&mut Primary>,
    ) -> Vec3 {
        let mut primary = primary;
        let mut r = *ray;
        let mut next = first;
        let mut layers = Layers::NONE;
        loop {
            let Some(hit) = next else {
                return self.beyond(&layers, r.dir, cone.spread);
            };
            let shaded = self.shade(
                &r,
                &hit,
                cone,
                bounce,
                weight,
                layers.through,
                rng,
                counts,
                &mut primary,
            );
            let shaded = self.fogged(shaded, &r, &hit, bounce, counts);
            if let Some(done) = self.fold(&mut layers, weight, shaded) {
                return done;
            }
            counts.blend_continuation += 1;
            r.tmin = past(&hit);
            next = self.first_visible(&r, cone, counts);
        }
    }

    /// The light a surface hit sends back along the ray, and its α (1 unless the surface
    /// is blended). `through` is the share of this surface's light that reaches the eye
    /// past the blended layers in front of it (it scales the mirror ray's weight).
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn shade(
        &self,
        ray: &Ray,
        hit: &Hit,
        cone: RayCone,
        bounce: u32,
        weight: Vec3,
        through: f32,
        rng: &mut Rng,
        counts: &mut RayCounts,
        primary: &mut Option<&mut Primary>,
    ) -> (Vec3, f32) {
        let Some(mut lit) = self.surface(ray, hit, cone, counts, primary) else {
            return (Vec3::ZERO, 0.0);
        };
        for al in &self.lights {
            let Some((inc, cos, shadows)) = self.reaches(&lit, al) else {
                continue;
            };
            let visible = match shadows {
                ShadowMode::None => 1.0,
                ShadowMode::Hard => {
                    counts.shadow += 1;
                    self.transmittance(&lit.surf, inc.dir, inc.dist, counts)
                }
                ShadowMode::Soft => self.soft_visibility(&lit.surf, al.light, &inc, rng, counts),
            };
            lit.add(&inc, cos, al.unshadowed(visible));
        }
        self.reflect(lit, ray, hit, cone, bounce, weight, through, rng, counts)
    }

    /// [`Integrator::shade`] on the hits of four rays (`through` the share of each hit's
    /// light that passes the blended layers in front of it): each light's hard shadow rays
    /// from the four points are traced as one packet,
    /// as are their mirror rays ([`Integrator::radiance4`]). Each lane's light is added,
    /// and its generator drawn from, in the single path's order, so each lane's result and
    /// counts are [`Integrator::shade`]'s, bit for bit. None for a lane without a hit.
    #[allow(clippy::too_many_arguments)]
    fn shade4(
        &self,
        rays: &[Ray; LANES],
        first: &[Option<Hit>; LANES],
        cones: &[RayCone; LANES],
        bounce: u32,
        weights: [Vec3; LANES],
        through: [f32; LANES],
        rngs: &mut [Rng; LANES],
        counts: &mut RayCounts,
        primary: &mut [Option<&mut Primary>; LANES],
    ) -> [Option<(Vec3, f32)>; LANES] {
        // A loop, not `array::from_fn`: with the surface inlined into its closure, the
        // compiler kept `from_fn` as a call of its own.
        let mut lit: [Option<Lit>; LANES] = [None, None, None, None];
        for l in 0..LANES {
            if let Some(hit) = first[l] {
                lit[l] = self.surface(&rays[l], &hit, cones[l], counts, &mut primary[l]);
            }
        }
        for al in &self.lights {
            let mut shadow = [no_ray(); LANES];
            let mut hard = [None; LANES];
            for l in 0..LANES {
                let Some(lit) = lit[l].as_mut() else {
                    continue;
                };
                let Some((inc, cos, shadows)) = self.reaches(lit, al) else {
                    continue;
                };
                match shadows {
                    ShadowMode::None => lit.add(&inc, cos, 1.0),
                    ShadowMode::Hard => {
                        counts.shadow += 1;
                        let s = &lit.surf;
                        shadow[l] = shadow_ray(s.spawn(inc.dir), s.p, inc.dir, inc.dist);
                        hard[l] = Some((inc, cos));
                    }
                    ShadowMode::Soft => {
                        let v =
                            self.soft_visibility(&lit.surf, al.light, &inc, &mut rngs[l], counts);
                        lit.add(&inc, cos, al.unshadowed(v));
                    }
                }
            }
            if hard.iter().any(Option::is_some) {
                let live = hard.map(|h| h.is_some());
                let visible = self.transmittance4(&shadow, live, &mut None, counts);
                for l in 0..LANES {
                    if let (Some(lit), Some((inc, cos))) = (lit[l].as_mut(), hard[l]) {
                        lit.add(&inc, cos, al.unshadowed(visible[l]));
                    }
                }
            }
        }
        let mirrors: [Option<Mirror>; LANES] = std::array::from_fn(|l| {
            let (lit, hit) = (lit[l].as_ref()?, first[l]?);
            self.mirror(
                lit, &rays[l], &hit, cones[l], bounce, weights[l], through[l], counts,
            )
        });
        if mirrors.iter().any(Option::is_some) {
            let next = mirrors.map(|m| m.map_or(no_ray(), |m| m.ray));
            let reflected = self.radiance4(
                &next,
                mirrors.map(|m| m.is_some()),
                mirrors.map(|m| m.map_or(cones[0], |m| m.cone)),
                bounce + 1,
                mirrors.map(|m| m.map_or(Vec3::ZERO, |m| m.weight)),
                rngs,
                counts,
                &mut [None, None, None, None],
            );
            for l in 0..LANES {
                if let (Some(lit), Some(m)) = (lit[l].as_mut(), mirrors[l]) {
                    lit.l += m.reflectance * reflected[l];
                }
            }
        }
        std::array::from_fn(|l| {
            first[l]?;
            Some(
                lit[l]
                    .as_ref()
                    .map_or((Vec3::ZERO, 0.0), |lit| (lit.l, lit.a)),
            )
        })
    }

    /// What light `al` brings to the point: where it arrives from, the cosine with the
    /// shading normal and how its shadow is found. None where it brings nothing (a dark
    /// surface, a layer it does not light, out of its reach, or from behind).
    #[inline(always)]
    fn reaches(&self, lit: &Lit, al: &ActiveLight) -> Option<(Incident, f32, ShadowMode)> {
        if !lit.lit || !al.light.lights_layer(lit.layer) {
            return None;
        }
        let inc = incident(al.light, lit.surf.p)?;
        let cos = lit.ns.dot(inc.dir);
        if cos <= 0.0 {
            return None;
        }
        // Where the shadow has faded out entirely, no shadow ray can change the light.
        let shadows = if lit.receives && lit.fade < 1.0 {
            al.shadows
        } else {
            ShadowMode::None
        };
        Some((inc, cos, shadows))
    }

    /// The shaded point's light with its mirror reflection added, and its α.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn reflect(
        &self,
        lit: Lit,
        ray: &Ray,
        hit: &Hit,
        cone: RayCone,
        bounce: u32,
        weight: Vec3,
        through: f32,
        rng: &mut Rng,
        counts: &mut RayCounts,
    ) -> (Vec3, f32) {
        let mut l = lit.l;
        if let Some(m) = self.mirror(&lit, ray, hit, cone, bounce, weight, through, counts) {
            l += m.reflectance
                * self.radiance(&m.ray, m.cone, bounce + 1, m.weight, rng, counts, None);
        }
        (l, lit.a)
    }

    /// The shaded point's mirror ray (counted), where the bounce and the mirror ray's
    /// weight allow: the ray's `weight` times `through`, the share of this surface's light
    /// that reaches the eye past blended layers in front of it, times its α and
    /// reflectance.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn mirror(
        &self,
        lit: &Lit,
        ray: &Ray,
        hit: &Hit,
        cone: RayCone,
        bounce: u32,
        weight: Vec3,
        through: f32,
        counts: &mut RayCounts,
    ) -> Option<Mirror> {
        let Lit {
            a,
            surf,
            ns,
            reflectance: refl,
            ..
        } = lit;
        if bounce >= self.max_depth {
            return None;
        }
        let w = weight * (through * a) * *refl;
        if !(w.max_element() >= self.cutoff && refl.max_element() > 0.0) {
            return None;
        }
        let d = ray.dir;
        let mut r = d - *ns * (2.0 * d.dot(*ns));
        // An interpolated normal can send the mirror ray into the surface: then mirror
        // about the true surface instead.
        if r.dot(surf.ng) <= 0.0 {
            r = d - surf.ng * (2.0 * d.dot(surf.ng));
        }
        let r = r.normalize_or_zero();
        if r == Vec3::ZERO {
            return None;
        }
        counts.reflection += 1;
        Some(Mirror {
            ray: Ray {
                origin: surf.spawn(r),
                dir: r,
                tmin: SPAWN_TMIN,
                tmax: f32::INFINITY,
            },
            cone: cone.reflected(hit.t),
            weight: w,
            reflectance: *refl,
        })
    }
}

/// A lane of a packet that traces nothing: an empty interval, refused before any walk.
fn no_ray() -> Ray {
    Ray::new(Vec3::ZERO, Vec3::X, 1.0, 0.0)
}

/// A camera sample's radiance and AOVs, their non-finite channels zeroed (and counted).
fn finish_camera(l: Vec3, primary: Primary, counts: &mut RayCounts) -> (Vec3, Primary) {
    counts.camera += 1;
    let mut l = l;
    let mut primary = primary;
    if sanitize(&mut l) {
        counts.sanitized += 1;
    }
    let mut n = primary.normal;
    let mut a = primary.albedo;
    if sanitize(&mut n) | sanitize(&mut a) || !primary.depth.is_finite() {
        counts.sanitized += 1;
        primary.depth = if primary.depth.is_finite() {
            primary.depth
        } else {
            f32::MAX
        };
    }
    primary.normal = n;
    primary.albedo = a;
    (l, primary)
}
