//! Whitted ray tracing, driven by the effects plan:
//!
//! ```text
//! L = emission + ambient(n)·albedo
//!   + Σ_lights visible · falloff · intensity·colour · max(0, n·l) · albedo
//!   + reflectance · L(mirror ray)        while bounce < depth and weight ≥ cutoff
//! ```
//!
//! n is the interpolated shading normal turned to face the incoming ray; the geometric
//! normal decides which side a secondary ray leaves from (see [`crate::offset`]).
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

use crate::alpha::{alpha_use, min_alphas, AlphaUse};
use crate::cone::RayCone;
use crate::counters::RayCounts;
use crate::environment;
use crate::lights::{basis, incident, Incident};
use crate::offset::{
    hit_point, intersector_margin, offset_origin, SHADOW_TMAX_FRACTION, SPAWN_TMIN,
};
use crate::plan::{colour_mapped, Plan, ShadowMode};
use crate::sampling::{disc_sample, Rng};
use crate::solid::Solids;
use crate::texture::{cone_footprint, Sampler};
use crate::TextureFilter;
use formats::{CastShadows, Hit, Light, LightKind, Soup, Tiling};
use glam::{Vec2, Vec3, Vec4};
use kdtree::{Accel, Ray, LANES};

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

/// What a material needs from its texture, resolved once per render.
struct Surfacing {
    /// The sampler (index into `Integrator::samplers`) and tiling of its map.
    map: Option<(usize, Tiling)>,
    /// The albedo is multiplied by the map's colour.
    colour: bool,
    alpha: AlphaUse,
    opacity: f32,
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
    /// Camera and reflection rays check their hits against the culling rules.
    culling: bool,
    /// Shadow rays ask each hit whether it casts (non-casting surfaces, culled faces).
    shadow_filter: bool,
    /// Cut-out and blended materials are honoured (the plan's alpha effect).
    alpha: bool,
    filter: TextureFilter,
    /// One per soup texture, built when textures or alpha are on (else empty).
    samplers: Vec<Sampler>,
    /// One per material (empty when textures and alpha are off).
    surfacing: Vec<Surfacing>,
    /// Closed pieces of objects, asked about by opaque shadow rays passing into them.
    solids: Solids<'a>,
    /// Per triangle, the sides it is drawn and casts from ([`DRAWN_FRONT`] …): what the
    /// traversals' filters ask, one byte instead of the object's and the material's records
    /// (empty when no face is culled and every object casts).
    sides: Vec<u8>,
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
        .iter()
        .zip(&soup.tri_material)
        .map(|(&o, &m)| {
            let obj = &soup.objects[o as usize];
            let cull = soup.materials[m as usize].cull;
            // The shadow pass sees a face from the light, so from the side the shadow ray
            // did not meet.
            let casts = |front: bool| match obj.cast_shadows {
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

/// Replace NaN and ±Inf channels by 0; true when something was replaced.
pub fn sanitize(v: &mut Vec3) -> bool {
    if v.is_finite() {
        return false;
    }
    *v = Vec3::from_array(v.to_array().map(|c| if c.is_finite() { c } else { 0.0 }));
    true
}

impl<'a> Integrator<'a> {
    /// Builds every texture's sampler (mip chain) when the plan reads textures, so this
    /// is the render's texture loading step.
    pub fn new(
        soup: &'a Soup,
        accel: &'a Accel,
        plan: &Plan,
        soft_samples: u32,
        filter: TextureFilter,
    ) -> Self {
        let lights = soup
            .lights
            .iter()
            .zip(&plan.lights)
            .filter(|(_, p)| p.enabled && plan.direct.enabled)
            .map(|(light, p)| ActiveLight {
                light,
                shadows: p.shadows,
            })
            .collect();
        let textures = plan.textures.enabled;
        let alpha = plan.alpha.enabled;
        let (samplers, surfacing) = if textures || alpha {
            let min_alpha = min_alphas(&soup.textures);
            let surfacing = soup
                .materials
                .iter()
                .map(|m| Surfacing {
                    map: m
                        .albedo_map
                        .map(|r| (r.texture as usize, r.tiling))
                        .filter(|_| textures || alpha),
                    colour: textures && colour_mapped(m),
                    alpha: if alpha {
                        alpha_use(m, &min_alpha)
                    } else {
                        AlphaUse::Opaque
                    },
                    opacity: m.opacity,
                })
                .collect();
            (soup.textures.iter().map(Sampler::new).collect(), surfacing)
        } else {
            (Vec::new(), Vec::new())
        };
        let shadow_filter = plan.shadow_casting.enabled || alpha;
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
            soft_samples,
            culling: plan.culling.enabled,
            shadow_filter,
            alpha,
            filter,
            samplers,
            surfacing,
            solids: if shadow_filter && !alpha {
                Solids::new(soup)
            } else {
                Solids::none(soup)
            },
            sides: if plan.culling.enabled || shadow_filter {
                sides(soup)
            } else {
                Vec::new()
            },
        }
    }

    /// Bytes of the texture samplers this render built (mip chains included).
    pub fn texture_bytes(&self) -> u64 {
        self.samplers.iter().map(Sampler::bytes).sum()
    }

    /// The interpolated UV of triangle `prim` at barycentrics (u, v): corner 0 weighs
    /// 1 − u − v, corner 1 u, corner 2 v, as for the normals.
    fn uv_at(&self, prim: usize, u: f32, v: f32) -> Vec2 {
        let t = self.soup.corner_uvs(prim);
        t[0] * (1.0 - u - v) + t[1] * u + t[2] * v
    }

    /// The map's RGBA at a hit of `prim` along `dir`, where the ray's cone is `width` wide
    /// (0: the full-size image, for shadow rays, which have no pixel footprint).
    fn texel(&self, map: &(usize, Tiling), prim: usize, hit: &Hit, dir: Vec3, width: f32) -> Vec4 {
        let uv = self.uv_at(prim, hit.u, hit.v);
        let w = if self.filter == TextureFilter::Cone && width > 0.0 {
            cone_footprint(
                width,
                dir,
                self.soup.corners(prim),
                self.soup.corner_uvs(prim),
            )
        } else {
            0.0
        };
        self.samplers[map.0].lookup(self.filter, &map.1, uv, w)
    }

    /// α of a cut-out or blended surface at a hit (its opacity without a map).
    fn alpha_at(
        &self,
        s: &Surfacing,
        prim: usize,
        hit: &Hit,
        dir: Vec3,
        width: f32,
        counts: &mut RayCounts,
    ) -> f32 {
        match &s.map {
            Some(map) => {
                counts.alpha_lookups += 1;
                s.opacity * self.texel(map, prim, hit, dir, width).w
            }
            None => s.opacity,
        }
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
        self.camera_sample_from(ray, first, cone, rng, counts)
    }

    /// [`Integrator::camera_sample`] for the rays of four neighbouring pixels, their first
    /// hits found together: the same four results and counts, bit for bit.
    pub fn camera_sample4(
        &self,
        rays: &[Ray; LANES],
        cone: RayCone,
        rngs: &mut [Rng; LANES],
        counts: &mut RayCounts,
    ) -> [(Vec3, Primary); LANES] {
        let first = self.first_visible4(rays, cone, counts);
        let mut lanes = rngs.iter_mut().zip(rays).zip(first);
        std::array::from_fn(|_| {
            let ((rng, ray), first) = lanes.next().expect("four lanes");
            self.camera_sample_from(ray, first, cone, rng, counts)
        })
    }

    /// [`Integrator::camera_sample`] once the ray's first visible hit is known.
    fn camera_sample_from(
        &self,
        ray: &Ray,
        first: Option<Hit>,
        cone: RayCone,
        rng: &mut Rng,
        counts: &mut RayCounts,
    ) -> (Vec3, Primary) {
        counts.camera += 1;
        let mut primary = Primary::MISS;
        let mut l = self.radiance_from(
            ray,
            first,
            cone,
            0,
            Vec3::ONE,
            rng,
            counts,
            Some(&mut primary),
        );
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

    /// [`Integrator::radiance`] once the ray's first visible hit, `first`, is known.
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
        if !self.alpha {
            let Some(hit) = first else {
                return environment::background(&self.soup.environment, ray.dir);
            };
            let p = &mut primary;
            return self
                .shade(ray, &hit, cone, bounce, weight, 1.0, rng, counts, p)
                .0;
        }
        let mut r = *ray;
        let mut next = first;
        // Light gathered from the blended layers so far, and the share of what lies behind
        // them that still reaches the eye.
        let mut acc = Vec3::ZERO;
        let mut through = 1.0f32;
        loop {
            let Some(hit) = next else {
                let bg = environment::background(&self.soup.environment, r.dir);
                return if through == 1.0 {
                    bg
                } else {
                    acc + bg * through
                };
            };
            let (l, a) = self.shade(
                &r,
                &hit,
                cone,
                bounce,
                weight,
                through,
                rng,
                counts,
                &mut primary,
            );
            if a >= 1.0 && through == 1.0 {
                return l;
            }
            acc += l * (a * through);
            through *= 1.0 - a;
            // A layer that stops all light, or a remainder too faint to matter (the
            // reflection cut-off's rule), ends the ray.
            if a >= 1.0 || (weight * through).max_element() < self.cutoff.max(f32::MIN_POSITIVE) {
                return acc;
            }
            counts.blend_continuation += 1;
            // Past this surface point, and past the triangle sharing the edge it may lie on.
            r.tmin = (hit.t + hit.t * SAME_SURFACE).max(hit.t.next_up());
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
        let prim = hit.prim as usize;
        let mat_index = self.soup.tri_material[prim] as usize;
        let mat = &self.soup.materials[mat_index];
        let mut albedo = mat.albedo();
        let mut a = 1.0f32;
        if let Some(s) = self.surfacing.get(mat_index) {
            let blend = s.alpha == AlphaUse::Blend;
            match &s.map {
                Some(map) if s.colour || blend => {
                    let texel = self.texel(map, prim, hit, ray.dir, cone.at(hit.t));
                    if s.colour {
                        counts.texture_lookups += 1;
                        albedo *= texel.truncate();
                    } else {
                        counts.alpha_lookups += 1;
                    }
                    if blend {
                        a = s.opacity * texel.w;
                    }
                }
                _ if blend => a = s.opacity,
                _ => {}
            }
            if a <= 0.0 {
                return (Vec3::ZERO, 0.0);
            }
        }

        let tri = &self.soup.corners(prim);
        let (p, err) = hit_point(tri, hit.u, hit.v);

        // Geometric normal, turned to face where the ray came from.
        let mut ng = (tri[1] - tri[0]).cross(tri[2] - tri[0]).normalize_or_zero();
        if ng.dot(ray.dir) > 0.0 {
            ng = -ng;
        }
        let surf = Surface {
            p,
            err,
            margin: intersector_margin(tri),
            ng,
        };
        let ns_tri = self.soup.corner_normals(prim);
        let b0 = 1.0 - hit.u - hit.v;
        let mut ns = (ns_tri[0] * b0 + ns_tri[1] * hit.u + ns_tri[2] * hit.v).normalize_or_zero();
        if ns == Vec3::ZERO || !ns.is_finite() {
            ns = ng;
        }
        if ns.dot(ray.dir) > 0.0 {
            ns = -ns;
        }

        let obj = &self.soup.objects[self.soup.tri_object[prim] as usize];
        if let Some(pr) = primary.take() {
            *pr = Primary {
                depth: hit.t,
                normal: ns,
                albedo,
                object: self.soup.tri_object[prim] as f32,
            };
        }

        let mut l = Vec3::ZERO;
        if self.emission {
            l += mat.emission;
        }
        // A black albedo cannot show any light: skip the lights and their shadow rays.
        if albedo.max_element() > 0.0 {
            if self.ambient {
                l += environment::ambient(&self.soup.environment, ns) * albedo;
            }
            for al in &self.lights {
                if !al.light.lights_layer(obj.layer) {
                    continue;
                }
                let Some(inc) = incident(al.light, p) else {
                    continue;
                };
                let cos = ns.dot(inc.dir);
                if cos <= 0.0 {
                    continue;
                }
                let shadows = if obj.receive_shadows {
                    al.shadows
                } else {
                    ShadowMode::None
                };
                let visible = match shadows {
                    ShadowMode::None => 1.0,
                    ShadowMode::Hard => {
                        counts.shadow += 1;
                        self.transmittance(&surf, inc.dir, inc.dist, counts)
                    }
                    ShadowMode::Soft => self.soft_visibility(&surf, al.light, &inc, rng, counts),
                };
                if visible > 0.0 {
                    l += inc.radiance * (cos * visible) * albedo;
                }
            }
        }

        if bounce < self.max_depth {
            let refl = mat.reflectance();
            let w = weight * (through * a) * refl;
            if w.max_element() >= self.cutoff && refl.max_element() > 0.0 {
                let d = ray.dir;
                let mut r = d - ns * (2.0 * d.dot(ns));
                // An interpolated normal can send the mirror ray into the surface: then
                // mirror about the true surface instead.
                if r.dot(ng) <= 0.0 {
                    r = d - ng * (2.0 * d.dot(ng));
                }
                let r = r.normalize_or_zero();
                if r != Vec3::ZERO {
                    counts.reflection += 1;
                    let next = Ray {
                        origin: surf.spawn(r),
                        dir: r,
                        tmin: SPAWN_TMIN,
                        tmax: f32::INFINITY,
                    };
                    let c = cone.reflected(hit.t);
                    l += refl * self.radiance(&next, c, bounce + 1, w, rng, counts, None);
                }
            }
        }
        (l, a)
    }

    /// The closest hit camera and reflection rays see, passing through culled faces,
    /// shadows-only objects and cut-out holes inside one traversal (each pass-through
    /// counted). Holes are tested at the cone's footprint, the lookup that shades the
    /// surface, so a cut-out's edge and its colour come from the same mip level, as in
    /// Unity's `clip()` on the sampled alpha.
    fn first_visible(&self, ray: &Ray, cone: RayCone, counts: &mut RayCounts) -> Option<Hit> {
        // Each combination gets its own closure, so a scene without cut-outs runs the
        // culling test alone, as it did before alpha existed.
        match (self.culling, self.alpha) {
            (false, false) => self.accel.intersect(ray),
            (true, false) => {
                // Most rays meet a drawn face first, and most culled faces a filter would
                // be asked about lie behind that face anyway: so a query that takes every
                // hit (keeping the side of the one it ends with), and the filtered one only
                // from a refused hit on (same answer, ties included).
                let mut front = true;
                let first = self.accel.intersect_filtered(ray, |_, f| {
                    front = f;
                    true
                })?;
                self.unless_culled(ray, first, front, counts)
            }
            (_, true) => self.first_visible_alpha(ray, cone, counts),
        }
    }

    /// [`Integrator::first_visible`] for four camera rays of neighbouring pixels (one
    /// packet query where the scene has no cut-outs), lane by lane the same answers and
    /// the same counts.
    fn first_visible4(
        &self,
        rays: &[Ray; LANES],
        cone: RayCone,
        counts: &mut RayCounts,
    ) -> [Option<Hit>; LANES] {
        match (self.culling, self.alpha) {
            (false, false) => self.accel.intersect4(rays),
            (true, false) => {
                let mut front = [true; LANES];
                let first = self.accel.intersect4_filtered(rays, |l, _, f| {
                    front[l] = f;
                    true
                });
                std::array::from_fn(|l| self.unless_culled(&rays[l], first[l]?, front[l], counts))
            }
            (_, true) => rays
                .each_ref()
                .map(|r| self.first_visible_alpha(r, cone, counts)),
        }
    }

    /// `first`, the ray's closest hit met on its front (`front`) or back, when its face is
    /// drawn; else the closest drawn face behind it (each pass-through counted).
    #[inline(always)]
    fn unless_culled(
        &self,
        ray: &Ray,
        first: Hit,
        front: bool,
        counts: &mut RayCounts,
    ) -> Option<Hit> {
        if !self.culled(first.prim as usize, front) {
            return Some(first);
        }
        counts.pass_through += 1;
        let rest = Ray {
            tmin: first.t,
            ..*ray
        };
        self.accel.intersect_filtered(&rest, |hit, front| {
            if hit.prim == first.prim {
                return false;
            }
            let through = self.culled(hit.prim as usize, front);
            counts.pass_through += through as u64;
            !through
        })
    }

    /// [`Integrator::first_visible`] with cut-out holes, out of line so that scenes
    /// without them keep the old query's code.
    #[inline(never)]
    fn first_visible_alpha(&self, ray: &Ray, cone: RayCone, counts: &mut RayCounts) -> Option<Hit> {
        let culling = self.culling;
        self.accel.intersect_filtered(ray, |hit, front| {
            let prim = hit.prim as usize;
            let s = &self.surfacing[self.soup.tri_material[prim] as usize];
            let through = (culling && self.culled(prim, front))
                || matches!(s.alpha, AlphaUse::Cutout { cutoff }
                    if self.alpha_at(s, prim, hit, ray.dir, cone.at(hit.t), counts) < cutoff);
            counts.pass_through += through as u64;
            !through
        })
    }

    /// Whether camera and reflection rays pass through triangle `prim`, met on its front
    /// (`front`) or back: a shadows-only object, or a face its material culls.
    #[inline(always)]
    fn culled(&self, prim: usize, front: bool) -> bool {
        self.sides[prim] & if front { DRAWN_FRONT } else { DRAWN_BACK } == 0
    }

    /// Whether the hit triangle `prim` blocks a shadow ray (travelling towards the light)
    /// that meets its front (`front`) or back.
    #[inline(always)]
    fn casts(&self, prim: usize, front: bool) -> bool {
        self.sides[prim] & if front { CASTS_FRONT } else { CASTS_BACK } != 0
    }

    /// The share of a light's light that reaches the surface at `p` along unit `dir` from
    /// `dist` away (`dist` infinite: a directional light, the ray is unbounded): 0 when an
    /// opaque caster is in the way, the product of (1 − α) over the blended casters met
    /// otherwise. Cut-out holes are tested at full resolution: a shadow ray has no pixel
    /// footprint, and the full-size image gives the hole's true shape.
    fn transmittance(&self, surf: &Surface, dir: Vec3, dist: f32, counts: &mut RayCounts) -> f32 {
        let origin = surf.spawn(dir);
        let p = surf.p;
        let ray = if dist.is_infinite() {
            Ray {
                origin,
                dir,
                tmin: SPAWN_TMIN,
                tmax: f32::INFINITY,
            }
        } else {
            // Re-measure from the spawned origin; stop short of the light by a relative margin.
            let target = p + dir * dist;
            let to = target - origin;
            let d = to.length();
            Ray {
                origin,
                dir: to / d,
                tmin: SPAWN_TMIN,
                tmax: d * SHADOW_TMAX_FRACTION,
            }
        };
        if !self.shadow_filter {
            return if self.accel.occluded(&ray) { 0.0 } else { 1.0 };
        }
        if !self.alpha {
            let blocked = self.accel.occluded_filtered(&ray, |hit, front| {
                let prim = hit.prim as usize;
                if self.casts(prim, front) {
                    return true;
                }
                counts.shadow_pass_through += 1;
                // Entering a closed piece: the face it leaves by casts (see `solid`).
                let solid = self.solids.blocks(prim, &ray);
                counts.shadow_solid += solid as u64;
                solid
            });
            return if blocked { 0.0 } else { 1.0 };
        }
        self.transmittance_alpha(&ray, counts)
    }

    /// [`Integrator::transmittance`] through cut-out holes and blended casters, out of
    /// line so that scenes without them keep the old query's code.
    #[inline(never)]
    fn transmittance_alpha(&self, ray: &Ray, counts: &mut RayCounts) -> f32 {
        let mut share = 1.0f32;
        let mut seen = Seen::new();
        let blocked = self.accel.occluded_filtered(ray, |hit, front| {
            let prim = hit.prim as usize;
            if !self.casts(prim, front) {
                counts.shadow_pass_through += 1;
                return false;
            }
            let s = &self.surfacing[self.soup.tri_material[prim] as usize];
            match s.alpha {
                AlphaUse::Opaque => true,
                AlphaUse::Cutout { cutoff } => {
                    let hole = self.alpha_at(s, prim, hit, ray.dir, 0.0, counts) < cutoff;
                    counts.shadow_pass_through += hole as u64;
                    !hole
                }
                AlphaUse::Blend => {
                    if !seen.first(self.soup.tri_object[prim], hit.t) {
                        return false;
                    }
                    counts.shadow_blend += 1;
                    share *= 1.0 - self.alpha_at(s, prim, hit, ray.dir, 0.0, counts);
                    share <= 0.0
                }
            }
        });
        if blocked {
            0.0
        } else {
            share
        }
    }

    /// Fraction of `soft_samples` stratified shadow rays that reach the light's extent: a
    /// disc of radius `shadow_radius` facing the point (point, spot) or a cone of angular
    /// diameter `shadow_radius` degrees around the light direction (directional).
    #[allow(clippy::too_many_arguments)]
    fn soft_visibility(
        &self,
        surf: &Surface,
        light: &Light,
        inc: &Incident,
        rng: &mut Rng,
        counts: &mut RayCounts,
    ) -> f32 {
        let n = self.soft_samples;
        let rotation = rng.next_f32() * std::f32::consts::TAU;
        let (t, b) = basis(inc.dir);
        let mut visible = 0.0f32;
        for i in 0..n {
            let (dx, dy) = disc_sample(i, n, rng.next_f32(), rotation);
            counts.soft_shadow += 1;
            visible += match light.kind {
                LightKind::Directional => {
                    // Uniform over the spherical cap, stratified by the disc's area strata.
                    let half = (light.shadow_radius * 0.5)
                        .to_radians()
                        .min(std::f32::consts::FRAC_PI_2);
                    let r2 = dx * dx + dy * dy;
                    let cos_t = 1.0 - r2 * (1.0 - half.cos());
                    let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
                    let r = r2.sqrt();
                    let (c, s) = if r > 0.0 {
                        (dx / r, dy / r)
                    } else {
                        (1.0, 0.0)
                    };
                    let dir = (t * (c * sin_t) + b * (s * sin_t) + inc.dir * cos_t).normalize();
                    self.transmittance(surf, dir, f32::INFINITY, counts)
                }
                LightKind::Point | LightKind::Spot { .. } => {
                    let q = light.position + (t * dx + b * dy) * light.shadow_radius;
                    let to = q - surf.p;
                    let dist = to.length();
                    if dist <= 0.0 {
                        continue;
                    }
                    self.transmittance(surf, to / dist, dist, counts)
                }
            };
        }
        visible / n as f32
    }
}
