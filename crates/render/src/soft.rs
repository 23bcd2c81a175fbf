//! A soft shadow's sample rays: from one shaded point towards points of a light's extent, a
//! disc of radius `shadow_radius` facing the point (point and spot lights) or a cone of
//! directions `shadow_radius` degrees wide around the light's direction (directional), built
//! four at a time.
//!
//! Each sample's direction and length take two to three square roots and three to six
//! divisions in a dependent chain; built one sample at a time they were a fifth of a
//! soft-shadow frame. On vectors, four samples cost one chain. Every lane does the scalar
//! rule's operations in the scalar rule's order (IEEE square roots and divisions are
//! correctly rounded on vectors too, and nothing is fused), so each ray is the one-sample
//! rule's to the bit (tested against it below).

use crate::lights::basis;
use crate::offset::{SHADOW_TMAX_FRACTION, SPAWN_TMIN};
use crate::RenderOptions;
use formats::{Light, LightKind};
use glam::{Vec3, Vec4};
use kdtree::{Ray, LANES};

/// Four lanes' 3-vectors, one vector per axis.
type Lanes3 = [Vec4; 3];

fn splat(v: Vec3) -> Lanes3 {
    [Vec4::splat(v.x), Vec4::splat(v.y), Vec4::splat(v.z)]
}

/// Each lane's square root (four `sqrtss`, or one `sqrtps` where the compiler merges them;
/// correctly rounded either way).
fn sqrt(v: Vec4) -> Vec4 {
    Vec4::from_array(v.to_array().map(f32::sqrt))
}

/// `Vec3::dot`'s sum, (x·x + y·y) + z·z, lane by lane.
fn dot(a: &Lanes3, b: &Lanes3) -> Vec4 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// What the samples of one point towards one light share.
pub(crate) struct SoftCone<'a> {
    light: &'a Light,
    /// The shaded point.
    p: Vec3,
    /// Unit direction from the point towards the light's centre.
    towards: Vec3,
    /// An orthonormal basis perpendicular to `towards`.
    t: Vec3,
    b: Vec3,
    /// The cosine of the half angle of a directional light's cone.
    cos_half: f32,
    /// The surface's geometric normal, and the spawned origins of rays that leave by its
    /// side and by the other (an origin depends on the side a ray leaves by, not on its
    /// direction).
    ng: Vec3,
    above: Vec3,
    below: Vec3,
}

impl<'a> SoftCone<'a> {
    pub(crate) fn new(
        light: &'a Light,
        p: Vec3,
        towards: Vec3,
        ng: Vec3,
        above: Vec3,
        below: Vec3,
    ) -> Self {
        let (t, b) = basis(towards);
        SoftCone {
            light,
            p,
            towards,
            t,
            b,
            cos_half: cos_half(light),
            ng,
            above,
            below,
        }
    }

    /// The shadow rays of four samples, the points (dx, dy) of the unit disc, and which of
    /// them to trace: none where a sample's point of the light is the shaded point itself.
    pub(crate) fn rays4(
        &self,
        dx: [f32; LANES],
        dy: [f32; LANES],
    ) -> ([Ray; LANES], [bool; LANES]) {
        let (dx, dy) = (Vec4::from_array(dx), Vec4::from_array(dy));
        let (t, b) = (splat(self.t), splat(self.b));
        let (dir, dist, live) = match self.light.kind {
            LightKind::Directional => {
                // Uniform over the spherical cap, stratified by the disc's area strata.
                let r2 = dx * dx + dy * dy;
                let cos_t = Vec4::ONE - r2 * (1.0 - self.cos_half);
                let sin_t = sqrt((Vec4::ONE - cos_t * cos_t).max(Vec4::ZERO));
                let r = sqrt(r2);
                let round = r.cmpgt(Vec4::ZERO);
                let c = Vec4::select(round, dx / r, Vec4::ONE) * sin_t;
                let s = Vec4::select(round, dy / r, Vec4::ZERO) * sin_t;
                let w = splat(self.towards);
                let v: Lanes3 = std::array::from_fn(|a| t[a] * c + b[a] * s + w[a] * cos_t);
                let inv = sqrt(dot(&v, &v)).recip();
                (v.map(|v| v * inv), Vec4::INFINITY, [true; LANES])
            }
            LightKind::Point | LightKind::Spot { .. } => {
                let (q, p) = (splat(self.light.position), splat(self.p));
                let radius = self.light.shadow_radius;
                let to: Lanes3 =
                    std::array::from_fn(|a| q[a] + (t[a] * dx + b[a] * dy) * radius - p[a]);
                let dist = sqrt(dot(&to, &to));
                // A NaN distance is traced (and refused by the traversal), as every other
                // non-finite ray is.
                let live = !dist.cmple(Vec4::ZERO).bitmask();
                (
                    to.map(|c| c / dist),
                    dist,
                    std::array::from_fn(|l| live >> l & 1 != 0),
                )
            }
        };
        let n = splat(self.ng);
        let leaves_below = dot(&dir, &n).cmplt(Vec4::ZERO);
        let (above, below) = (splat(self.above), splat(self.below));
        let origin: Lanes3 =
            std::array::from_fn(|a| Vec4::select(leaves_below, below[a], above[a]));
        // Towards a light at a distance, re-aimed and re-measured from the spawned origin
        // and stopped short of the light (`integrator::shadow_ray`). An infinite distance (a
        // directional light, or a point light's that overflowed) leaves the ray unbounded
        // along the sample's direction, so a directional light skips the re-aim.
        let (aimed, tmax) = if self.light.kind == LightKind::Directional {
            (dir, Vec4::INFINITY)
        } else {
            let p = splat(self.p);
            let to: Lanes3 = std::array::from_fn(|a| p[a] + dir[a] * dist - origin[a]);
            let d = sqrt(dot(&to, &to));
            // `dist` is a square root: +∞ when infinite, never −∞.
            let far = dist.cmpeq(Vec4::INFINITY);
            (
                std::array::from_fn(|a| Vec4::select(far, dir[a], to[a] / d)),
                Vec4::select(far, Vec4::INFINITY, d * SHADOW_TMAX_FRACTION),
            )
        };
        let lane = |v: &Lanes3, l: usize| Vec3::new(v[0][l], v[1][l], v[2][l]);
        let rays = std::array::from_fn(|l| Ray {
            origin: lane(&origin, l),
            dir: lane(&aimed, l),
            tmin: SPAWN_TMIN,
            tmax: tmax[l],
        });
        (rays, live)
    }
}

/// The widest angular radius of a light's extent, seen from the shaded point, that the
/// soft-shadow rim probe is asked about, in degrees. A caster, or a gap between casters,
/// can slip between the four probes only if it is narrower than the extent, so the probe
/// can miss only features under 4° across as seen from the point; from wider extents (a
/// large lamp close by) it would miss the shadows of whole objects, and every sample is
/// traced. The sun is 0.53° across; Unity's directional soft lights import as 1° cones
/// unless they set an angle.
pub(crate) const PROBE_MAX_DEGREES: f32 = 2.0;

/// tan(`PROBE_MAX_DEGREES`), for lights at a distance.
const PROBE_MAX_TAN: f32 = 0.034_920_77;

/// Whether a render probes at all: asked to, with more samples than the probe's one packet.
pub(crate) fn probe_asked(opts: &RenderOptions) -> bool {
    opts.soft_probe && opts.soft_samples > LANES as u32
}

/// Whether a light's extent seen from a point `dist` away (infinite: directional) is
/// narrow enough for the rim probe.
pub(crate) fn probe_fits(light: &Light, dist: f32) -> bool {
    match light.kind {
        LightKind::Directional => light.shadow_radius * 0.5 <= PROBE_MAX_DEGREES,
        LightKind::Point | LightKind::Spot { .. } => light.shadow_radius <= dist * PROBE_MAX_TAN,
    }
}

/// The distance from which a point or spot light's disc is narrow enough for the probe.
pub(crate) fn probe_distance(light: &Light) -> f32 {
    light.shadow_radius / PROBE_MAX_TAN
}

/// The cosine of the half angle of a directional light's soft-shadow cone (its
/// `shadow_radius` is the cone's angular diameter in degrees, at most a hemisphere).
fn cos_half(light: &Light) -> f32 {
    (light.shadow_radius * 0.5)
        .to_radians()
        .min(std::f32::consts::FRAC_PI_2)
        .cos()
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::integrator::shadow_ray;
    use crate::sampling::{DiscSpiral, Rng};
    use formats::Shadows;

    /// The rule one sample at a time, as the renderer ran it before samples were built
    /// four at a time: direction and distance of the sample (dx, dy) from `p`, or None
    /// when that point of the light is `p` itself.
    pub(crate) fn sample(c: &SoftCone, dx: f32, dy: f32) -> Option<(Vec3, f32)> {
        match c.light.kind {
            LightKind::Directional => {
                let r2 = dx * dx + dy * dy;
                let cos_t = 1.0 - r2 * (1.0 - c.cos_half);
                let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
                let r = r2.sqrt();
                let (u, v) = if r > 0.0 {
                    (dx / r, dy / r)
                } else {
                    (1.0, 0.0)
                };
                let dir = (c.t * (u * sin_t) + c.b * (v * sin_t) + c.towards * cos_t).normalize();
                Some((dir, f32::INFINITY))
            }
            LightKind::Point | LightKind::Spot { .. } => {
                let q = c.light.position + (c.t * dx + c.b * dy) * c.light.shadow_radius;
                let to = q - c.p;
                let dist = to.length();
                if dist <= 0.0 {
                    None
                } else {
                    Some((to / dist, dist))
                }
            }
        }
    }

    #[test]
    fn the_probe_asks_extents_up_to_two_degrees_in_radius() {
        let tan = (PROBE_MAX_DEGREES as f64).to_radians().tan();
        assert!((PROBE_MAX_TAN as f64 - tan).abs() < 1e-8);
        let point = light(LightKind::Point, Vec3::ZERO, 0.1);
        assert!(probe_fits(&point, 2.9) && !probe_fits(&point, 2.8));
        assert!((probe_distance(&point) - 2.8636).abs() < 1e-3);
        let mut sun = light(LightKind::Directional, Vec3::ZERO, 4.0);
        assert!(probe_fits(&sun, f32::INFINITY));
        sun.shadow_radius = 4.1;
        assert!(!probe_fits(&sun, f32::INFINITY));
    }

    fn light(kind: LightKind, position: Vec3, shadow_radius: f32) -> Light {
        Light {
            name: "l".into(),
            kind,
            position,
            direction: -Vec3::Y,
            color: Vec3::ONE,
            intensity: 1.0,
            range: 10.0,
            attenuation: formats::Attenuation::BuiltIn,
            shadows: Shadows::Soft,
            shadow_radius,
            shadow_strength: 1.0,
            culling_mask: u32::MAX,
        }
    }

    fn bits(r: &Ray) -> [u32; 8] {
        [
            r.origin.x, r.origin.y, r.origin.z, r.dir.x, r.dir.y, r.dir.z, r.tmin, r.tmax,
        ]
        .map(f32::to_bits)
    }

    /// Four samples at a time give each sample's one-at-a-time ray to the bit: every light
    /// kind, cones from a point to a hemisphere, points near, far, on the light's disc and
    /// beside it, samples at the disc's centre and rim, both sides of the surface.
    #[test]
    fn four_sample_rays_are_the_one_sample_rule_bit_for_bit() {
        let mut rng = Rng::new(17);
        let mut u = |lo: f32, hi: f32| lo + (hi - lo) * rng.next_f32();
        let mut checked = [0u32; 3];
        for case in 0..6000 {
            let kind = match case % 3 {
                0 => LightKind::Directional,
                1 => LightKind::Point,
                _ => LightKind::Spot {
                    angle: 60.0,
                    inner_angle: 40.0,
                },
            };
            let radius = match kind {
                LightKind::Directional => [0.0, 0.5, 3.0, 90.0, 180.0, 400.0][case % 6],
                _ => [0.0, 0.05, 0.5, 2.0][case % 4],
            };
            let position = Vec3::new(u(-5.0, 5.0), u(0.0, 8.0), u(-5.0, 5.0));
            let l = light(kind, position, radius);
            let p = if case % 97 == 0 {
                position
            } else {
                Vec3::new(u(-1e3, 1e3), u(-1.0, 1.0), u(-1e3, 1e3)) * [1.0, 1e-3, 1e-2][case % 3]
            };
            let towards = match kind {
                LightKind::Directional => Vec3::new(u(-1.0, 1.0), 1.0, u(-1.0, 1.0)).normalize(),
                _ => (position - p).normalize_or(Vec3::Y),
            };
            let ng = if case % 2 == 0 { Vec3::Y } else { -Vec3::Y };
            let (above, below) = (p + ng * 1e-4, p - ng * 1e-4);
            let cone = SoftCone::new(&l, p, towards, ng, above, below);
            let n = [1, 4, 16, 3][case / 3 % 4];
            let mut spiral = DiscSpiral::new(n, u(0.0, std::f32::consts::TAU));
            let draws: Vec<(f32, f32)> = (0..n)
                .map(|_| match case % 11 {
                    0 => (0.0, 0.0),
                    1 => (1.0, 0.0),
                    _ => spiral.next(u(0.0, 1.0)),
                })
                .collect();
            for group in draws.chunks(LANES) {
                let mut dx = [0.0; LANES];
                let mut dy = [0.0; LANES];
                for (l, &(x, y)) in group.iter().enumerate() {
                    (dx[l], dy[l]) = (x, y);
                }
                let (rays, live) = cone.rays4(dx, dy);
                for (l, &(x, y)) in group.iter().enumerate() {
                    let want = sample(&cone, x, y).map(|(dir, dist)| {
                        let origin = if dir.dot(ng) < 0.0 { below } else { above };
                        shadow_ray(origin, p, dir, dist)
                    });
                    assert_eq!(live[l], want.is_some(), "case {case}, lane {l}");
                    if let Some(want) = want {
                        assert_eq!(bits(&rays[l]), bits(&want), "case {case}, lane {l}");
                        checked[case % 3] += 1;
                    }
                }
            }
        }
        assert!(checked.iter().all(|&c| c > 5_000), "{checked:?}");
    }
}
