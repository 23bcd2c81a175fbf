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
//! Unity's draw rules: camera and reflection rays pass through faces their material culls
//! and shadows-only objects; shadow rays pass through objects that cast no shadow and
//! faces the material culls seen from the light (unless the object casts two-sided); a
//! surface that receives no shadows is lit unoccluded; a light lights only the layers in
//! its mask. Passing through is the same ray again with `tmin` just above the hit's t:
//! the same ray parameters give the same t for that triangle, so it is never found again.

use crate::counters::RayCounts;
use crate::environment;
use crate::lights::{basis, incident, Incident};
use crate::offset::{
    hit_point, intersector_margin, offset_origin, SHADOW_TMAX_FRACTION, SPAWN_TMIN,
};
use crate::plan::{Plan, ShadowMode};
use crate::sampling::{disc_sample, Rng};
use formats::{CastShadows, Cull, Hit, Light, LightKind, Soup};
use glam::Vec3;
use kdtree::{Accel, Ray};

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
    /// Shadow rays loop closest hits past non-casting surfaces instead of any-hit.
    shadow_filter: bool,
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
    pub fn new(soup: &'a Soup, accel: &'a Accel, plan: &Plan, soft_samples: u32) -> Self {
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
            shadow_filter: plan.shadow_casting.enabled,
        }
    }

    /// Radiance along a camera ray (counted), with what its first hit tells the AOVs.
    /// The result is always finite (non-finite channels are zeroed and counted).
    pub fn camera_sample(
        &self,
        ray: &Ray,
        rng: &mut Rng,
        counts: &mut RayCounts,
    ) -> (Vec3, Primary) {
        counts.camera += 1;
        let mut primary = Primary::MISS;
        let mut l = self.radiance(ray, 0, Vec3::ONE, rng, counts, Some(&mut primary));
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

    fn radiance(
        &self,
        ray: &Ray,
        bounce: u32,
        weight: Vec3,
        rng: &mut Rng,
        counts: &mut RayCounts,
        primary: Option<&mut Primary>,
    ) -> Vec3 {
        let Some(hit) = self.first_visible(ray, counts) else {
            return environment::background(&self.soup.environment, ray.dir);
        };
        let prim = hit.prim as usize;
        let tri = &self.soup.triangles[prim];
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
        let ns_tri = &self.soup.normals[prim];
        let b0 = 1.0 - hit.u - hit.v;
        let mut ns = (ns_tri[0] * b0 + ns_tri[1] * hit.u + ns_tri[2] * hit.v).normalize_or_zero();
        if ns == Vec3::ZERO || !ns.is_finite() {
            ns = ng;
        }
        if ns.dot(ray.dir) > 0.0 {
            ns = -ns;
        }

        let mat = &self.soup.materials[self.soup.tri_material[prim] as usize];
        let obj = &self.soup.objects[self.soup.tri_object[prim] as usize];
        let albedo = mat.albedo();
        if let Some(pr) = primary {
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
                        if self.blocked(&surf, inc.dir, inc.dist, counts) {
                            0.0
                        } else {
                            1.0
                        }
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
            let w = weight * refl;
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
                    l += refl * self.radiance(&next, bounce + 1, w, rng, counts, None);
                }
            }
        }
        l
    }

    /// The closest hit camera and reflection rays see, passing through culled faces and
    /// shadows-only objects inside one traversal (each pass-through counted).
    fn first_visible(&self, ray: &Ray, counts: &mut RayCounts) -> Option<Hit> {
        if !self.culling {
            return self.accel.intersect(ray);
        }
        self.accel.intersect_filtered(ray, |hit| {
            let prim = hit.prim as usize;
            let obj = &self.soup.objects[self.soup.tri_object[prim] as usize];
            let cull = self.soup.materials[self.soup.tri_material[prim] as usize].cull;
            let through = !obj.visible()
                || (cull != Cull::None && cull.skips(winding(self.soup, prim), ray.dir));
            counts.pass_through += through as u64;
            !through
        })
    }

    /// Whether the hit triangle `prim` blocks a shadow ray travelling along `dir` (towards
    /// the light): the shadow pass sees it from the light, looking along −`dir`.
    fn casts(&self, prim: usize, dir: Vec3) -> bool {
        let obj = &self.soup.objects[self.soup.tri_object[prim] as usize];
        match obj.cast_shadows {
            CastShadows::Off => false,
            CastShadows::TwoSided => true,
            CastShadows::On | CastShadows::ShadowsOnly => {
                let cull = self.soup.materials[self.soup.tri_material[prim] as usize].cull;
                cull == Cull::None || !cull.skips(winding(self.soup, prim), -dir)
            }
        }
    }

    /// Whether the way from the surface at `p` along unit `dir` to a light `dist` away is
    /// blocked (`dist` infinite: a directional light, the ray is unbounded).
    fn blocked(&self, surf: &Surface, dir: Vec3, dist: f32, counts: &mut RayCounts) -> bool {
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
            return self.accel.occluded(&ray);
        }
        self.accel.occluded_filtered(&ray, |hit| {
            let casts = self.casts(hit.prim as usize, ray.dir);
            counts.shadow_pass_through += !casts as u64;
            casts
        })
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
        let mut visible = 0u32;
        for i in 0..n {
            let (dx, dy) = disc_sample(i, n, rng.next_f32(), rotation);
            counts.soft_shadow += 1;
            let blocked = match light.kind {
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
                    self.blocked(surf, dir, f32::INFINITY, counts)
                }
                LightKind::Point | LightKind::Spot { .. } => {
                    let q = light.position + (t * dx + b * dy) * light.shadow_radius;
                    let to = q - surf.p;
                    let dist = to.length();
                    if dist <= 0.0 {
                        continue;
                    }
                    self.blocked(surf, to / dist, dist, counts)
                }
            };
            if !blocked {
                visible += 1;
            }
        }
        visible as f32 / n as f32
    }
}

/// Triangle `prim`'s winding normal (unnormalised): it points out of the front face.
fn winding(soup: &Soup, prim: usize) -> Vec3 {
    let t = &soup.triangles[prim];
    (t[1] - t[0]).cross(t[2] - t[0])
}
