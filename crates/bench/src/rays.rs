//! The ray sets every contender traces: primary rays from a camera, shadow rays from the
//! primary hits towards a light above the scene, random rays inside the bounds, and rays
//! spawned from random surface points as the renderer spawns secondary rays.
//! All are generated once per scene, so every contender sees exactly the same rays.

use glam::Vec3;
use kdtree::testkit::Rng;
use kdtree::Ray;

/// A pinhole camera (square image).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct View {
    pub eye: Vec3,
    /// Unit view direction.
    pub forward: Vec3,
    /// Unit up vector, orthogonal to `forward`.
    pub up: Vec3,
    /// Vertical field of view in degrees.
    pub fov_y: f32,
}

/// A 45° camera looking down at the bounds' centre from above and to the side, at 0.75
/// of the distance where the bounding sphere would just fit: most primary rays hit
/// something, as in a rendered view, while the scene still fills the frame.
pub fn framing(bounds: [Vec3; 2]) -> View {
    let centre = (bounds[0] + bounds[1]) * 0.5;
    let radius = ((bounds[1] - bounds[0]).length() * 0.5).max(1e-3);
    let fov_y = 45.0f32;
    let dist = 0.75 * radius / (fov_y.to_radians() * 0.5).sin();
    let from = Vec3::new(0.5, 0.8, -1.0).normalize();
    let forward = -from;
    let up = forward.cross(Vec3::Y).cross(forward).normalize();
    View {
        eye: centre + from * dist,
        forward,
        up,
        fov_y,
    }
}

/// One ray through the centre of each pixel of a `size` × `size` image, row by row from
/// the top left. Directions are unit length; the interval is [0, ∞).
pub fn primary(view: &View, size: u32) -> Vec<Ray> {
    let right = view.forward.cross(view.up).normalize();
    let up = right.cross(view.forward);
    let half = (view.fov_y.to_radians() * 0.5).tan();
    let mut out = Vec::with_capacity((size * size) as usize);
    for y in 0..size {
        for x in 0..size {
            let sx = ((x as f32 + 0.5) / size as f32 * 2.0 - 1.0) * half;
            let sy = (1.0 - (y as f32 + 0.5) / size as f32 * 2.0) * half;
            let dir = (view.forward + right * sx + up * sy).normalize();
            out.push(Ray::new(view.eye, dir, 0.0, f32::INFINITY));
        }
    }
    out
}

/// `primary`'s rays (a `size` × `size` image, row by row) reordered into packets of
/// `packet` neighbouring pixels, as a renderer would form them: 2×2 blocks for 4, 4×2 for
/// 8, 4×4 for 16, each made of 2×2 blocks in a row (so that a four-wide tracer sees the same
/// 2×2 packets inside every wider one). Pixels outside the whole blocks (the last rows or
/// columns) stay in row order at the end.
///
/// # Panics
/// When `packet` is not 4, 8 or 16.
pub fn in_blocks(primary: &[Ray], size: u32, packet: usize) -> Vec<Ray> {
    let (bw, bh) = match packet {
        4 => (2, 2),
        8 => (4, 2),
        16 => (4, 4),
        _ => panic!("packets are 4, 8 or 16 rays, not {packet}"),
    };
    let n = size as usize;
    let (ew, eh) = (n / bw * bw, n / bh * bh);
    let mut out = Vec::with_capacity(primary.len());
    for by in (0..eh).step_by(bh) {
        for bx in (0..ew).step_by(bw) {
            for sy in (0..bh).step_by(2) {
                for sx in (0..bw).step_by(2) {
                    for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                        out.push(primary[(by + sy + dy) * n + bx + sx + dx]);
                    }
                }
            }
        }
    }
    for y in 0..n {
        for x in 0..n {
            if y >= eh || x >= ew {
                out.push(primary[y * n + x]);
            }
        }
    }
    out
}

/// The light for shadow rays: above the centre of the bounds, one diagonal higher than
/// the top, offset sideways so that shadows fall at an angle.
pub fn light_above(bounds: [Vec3; 2]) -> Vec3 {
    let centre = (bounds[0] + bounds[1]) * 0.5;
    let diag = (bounds[1] - bounds[0]).length().max(1e-3);
    Vec3::new(
        centre.x + 0.3 * diag,
        bounds[1].y + diag,
        centre.z + 0.2 * diag,
    )
}

/// One shadow ray per primary ray that hit: from the hit point (moved off the surface,
/// to the light's side of the triangle's plane, by 1e-4 of the scene diagonal) to the
/// light. Unit direction, interval [0, distance to the light].
///
/// `hits[i]` is the closest hit of `primary[i]` as (triangle, u, v); `None` is a miss.
pub fn shadow(
    triangles: &[[Vec3; 3]],
    hits: &[Option<(u32, f32, f32)>],
    light: Vec3,
    bounds: [Vec3; 2],
) -> Vec<Ray> {
    let offset = 1e-4 * (bounds[1] - bounds[0]).length().max(1e-3);
    hits.iter()
        .flatten()
        .filter_map(|&(prim, u, v)| {
            let t = triangles.get(prim as usize)?;
            let p = (1.0 - u - v) * t[0] + u * t[1] + v * t[2];
            let mut n = (t[1] - t[0]).cross(t[2] - t[0]).normalize_or_zero();
            if n.dot(light - p) < 0.0 {
                n = -n;
            }
            let o = p + n * offset;
            let to = light - o;
            let dist = to.length();
            (dist > 0.0 && dist.is_finite()).then(|| Ray::new(o, to / dist, 0.0, dist))
        })
        .collect()
}

/// Angular diameter of the sun's disc in [`soft`], in degrees: a directional light's soft
/// shadows in Unity default to a small cone, and the corpus scenes' lights are a degree or
/// two.
pub const SUN_DEGREES: f32 = 2.0;

/// A soft shadow's samples as the renderer traces them: from every `per_point`-th primary
/// hit (so the set has about as many rays as there are hits) whose surface, seen from the
/// camera, faces the sun, `per_point` rays spawned as the renderer spawns them, uniform over
/// a cone of [`SUN_DEGREES`] around unit `sun`, unbounded. A hit's samples are
/// consecutive, so packets of `per_point` rays are one point's samples, as the renderer's
/// are. `hits[i]` is the closest hit of `primary[i]`, as for [`shadow`].
pub fn soft(
    triangles: &[[Vec3; 3]],
    primary: &[Ray],
    hits: &[Option<(u32, f32, f32)>],
    sun: Vec3,
    per_point: usize,
    seed: u64,
) -> Vec<Ray> {
    use render::offset::{hit_point, intersector_margin, offset_origin, SPAWN_TMIN};
    let per_point = per_point.max(1);
    let mut rng = Rng(seed);
    let (a, b) = sun.any_orthonormal_pair();
    let cos_half = (SUN_DEGREES * 0.5).to_radians().cos();
    let mut out = Vec::new();
    let lit = primary.iter().zip(hits).filter_map(|(r, h)| {
        let (prim, u, v) = (*h)?;
        let t = triangles.get(prim as usize)?;
        let mut ng = (t[1] - t[0]).cross(t[2] - t[0]).normalize_or_zero();
        if ng.dot(r.dir) > 0.0 {
            ng = -ng;
        }
        (ng.dot(sun) > 0.0).then_some((t, u, v, ng))
    });
    for (t, u, v, ng) in lit.step_by(per_point) {
        let (p, err) = hit_point(t, u, v);
        let margin = intersector_margin(t);
        for _ in 0..per_point {
            let cos_t = 1.0 - rng.unit() * (1.0 - cos_half);
            let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
            let phi = rng.unit() * std::f32::consts::TAU;
            let dir = (a * (sin_t * phi.cos()) + b * (sin_t * phi.sin()) + sun * cos_t).normalize();
            let o = offset_origin(p, err, margin, ng, dir);
            out.push(Ray::new(o, dir, SPAWN_TMIN, f32::INFINITY));
        }
    }
    out
}

/// Where a surface ray goes: to a point (a light; the interval ends just short of it, as
/// the renderer's shadow rays do) or in a direction (unbounded).
#[derive(Clone, Copy, Debug)]
pub enum Toward {
    Point(Vec3),
    Direction(Vec3),
}

/// `n` rays leaving random points of random triangles (each triangle equally likely,
/// visible or not; uniform over its area), spawned exactly as the renderer spawns
/// secondary rays (`render::offset`). `toward` picks each ray's target from the RNG and
/// the triangle's unit geometric normal. Degenerate triangles are skipped.
pub fn surface(
    triangles: &[[Vec3; 3]],
    n: usize,
    seed: u64,
    mut toward: impl FnMut(&mut Rng, Vec3) -> Toward,
) -> Vec<Ray> {
    use render::offset::{
        hit_point, intersector_margin, offset_origin, SHADOW_TMAX_FRACTION, SPAWN_TMIN,
    };
    let mut rng = Rng(seed);
    let mut out = Vec::with_capacity(n);
    if triangles.is_empty() {
        return out;
    }
    let mut tries = 0usize;
    while out.len() < n && tries < 4 * n + 16 {
        tries += 1;
        let t = &triangles
            [((rng.unit() as f64 * triangles.len() as f64) as usize).min(triangles.len() - 1)];
        let ng = (t[1] - t[0]).cross(t[2] - t[0]).normalize_or_zero();
        if ng == Vec3::ZERO || !ng.is_finite() {
            continue;
        }
        let (mut u, mut v) = (rng.unit(), rng.unit());
        if u + v > 1.0 {
            (u, v) = (1.0 - u, 1.0 - v);
        }
        let (p, err) = hit_point(t, u, v);
        let (dir, tmax) = match toward(&mut rng, ng) {
            Toward::Point(l) => {
                let to = l - p;
                let d = to.length();
                (to / d, d)
            }
            Toward::Direction(d) => (d, f32::INFINITY),
        };
        if !dir.is_finite() || dir == Vec3::ZERO {
            continue;
        }
        let o = offset_origin(p, err, intersector_margin(t), ng, dir);
        let (dir, tmax) = if tmax.is_finite() {
            // As the renderer does: re-aimed and re-measured from the spawned origin.
            let to = p + dir * tmax - o;
            let d = to.length();
            (to / d, d * SHADOW_TMAX_FRACTION)
        } else {
            (dir, tmax)
        };
        out.push(Ray::new(o, dir, SPAWN_TMIN, tmax));
    }
    out
}

/// A direction uniform on the hemisphere around unit normal `n`.
pub fn hemisphere(rng: &mut Rng, n: Vec3) -> Vec3 {
    let z = rng.unit();
    let phi = std::f32::consts::TAU * rng.unit();
    let r = (1.0 - z * z).max(0.0).sqrt();
    let (a, b) = n.any_orthonormal_pair();
    (a * (r * phi.cos()) + b * (r * phi.sin()) + n * z).normalize()
}

/// How far [`moved_along`] moves origins: 5 mm in the corpus meshes' metres.
pub const MOVED: f32 = 0.005;

/// `rays` with their origins moved `by` along the ray and their intervals shortened to
/// match: rays that start clear of the surface they leave, to compare with.
pub fn moved_along(rays: &[Ray], by: f32) -> Vec<Ray> {
    rays.iter()
        .map(|r| {
            let tmax = if r.tmax.is_finite() {
                (r.tmax - by).max(r.tmin)
            } else {
                r.tmax
            };
            Ray::new(r.origin + r.dir * by, r.dir, r.tmin, tmax)
        })
        .collect()
}

/// `n` rays with origins uniform in the bounds and directions uniform on the sphere,
/// interval [0, ∞). Deterministic for a given seed.
pub fn random(bounds: [Vec3; 2], n: usize, seed: u64) -> Vec<Ray> {
    let mut rng = Rng(seed);
    let ext = bounds[1] - bounds[0];
    (0..n)
        .map(|_| {
            let o = bounds[0] + ext * Vec3::new(rng.unit(), rng.unit(), rng.unit());
            let z = 2.0 * rng.unit() - 1.0;
            let phi = std::f32::consts::TAU * rng.unit();
            let r = (1.0 - z * z).max(0.0).sqrt();
            let dir = Vec3::new(r * phi.cos(), r * phi.sin(), z);
            Ray::new(o, dir, 0.0, f32::INFINITY)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn primary_rays_centre_pixel_looks_forward() {
        let v = framing([Vec3::splat(-1.0), Vec3::splat(1.0)]);
        let rays = primary(&v, 3);
        assert_eq!(rays.len(), 9);
        // The centre pixel of a 3×3 image looks straight along `forward`, at the centre.
        let c = rays[4];
        assert!((c.dir - v.forward).length() < 1e-6);
        let to_centre = (-c.origin).normalize();
        assert!((to_centre - v.forward).length() < 1e-5);
        // Top-left pixel points up and left of the view.
        let right = v.forward.cross(v.up);
        assert!(rays[0].dir.dot(v.up) > 0.0 && rays[0].dir.dot(right) < 0.0);
    }

    #[test]
    fn blocks_hold_each_ray_once_in_2x2_order() {
        let v = framing([Vec3::splat(-1.0), Vec3::splat(1.0)]);
        // Pixel index of each reordered ray.
        let order = |size: u32, packet: usize| -> Vec<usize> {
            let rays = primary(&v, size);
            in_blocks(&rays, size, packet)
                .iter()
                .map(|b| rays.iter().position(|r| r.dir == b.dir).unwrap())
                .collect()
        };
        // The 2×2 block, then the odd column and row.
        assert_eq!(order(3, 4), [0, 1, 3, 4, 2, 5, 6, 7, 8]);
        // 5×5 in 4×2 blocks: two blocks of two 2×2 each, then column 4 and row 4.
        let wide = [
            0, 1, 5, 6, 2, 3, 7, 8, 10, 11, 15, 16, 12, 13, 17, 18, 4, 9, 14, 19, 20, 21, 22, 23,
            24,
        ];
        assert_eq!(order(5, 8), wide);
        // One 4×4 block holds the same four 2×2 blocks in the same order.
        assert_eq!(order(5, 16), wide);
        // 6×6 in 4×4 blocks: one block; columns 4–5 of rows 0–3 and rows 4–5 follow.
        let o = order(6, 16);
        assert_eq!(
            &o[..16],
            [0, 1, 6, 7, 2, 3, 8, 9, 12, 13, 18, 19, 14, 15, 20, 21]
        );
        assert_eq!(&o[16..20], [4, 5, 10, 11]);
        let mut all = o.clone();
        all.sort();
        assert_eq!(all, (0..36).collect::<Vec<_>>());
    }

    #[test]
    fn shadow_ray_starts_on_the_lights_side() {
        let tri = [[Vec3::ZERO, Vec3::X, Vec3::Z]]; // normal −Y, light above at +Y
        let b = [Vec3::ZERO, Vec3::new(1.0, 0.0, 1.0)];
        let rays = shadow(
            &tri,
            &[Some((0, 0.25, 0.25)), None],
            Vec3::new(0.0, 10.0, 0.0),
            b,
        );
        assert_eq!(rays.len(), 1);
        assert!(rays[0].origin.y > 0.0);
        assert!((rays[0].dir.length() - 1.0).abs() < 1e-6);
        let end = rays[0].origin + rays[0].dir * rays[0].tmax;
        assert!((end - Vec3::new(0.0, 10.0, 0.0)).length() < 1e-4);
    }

    #[test]
    fn surface_rays_leave_their_triangles_on_the_side_they_go() {
        let tris = [
            [Vec3::ZERO, Vec3::X, Vec3::Z],
            [
                Vec3::new(0.0, 1.0, 0.0),
                Vec3::new(1.0, 1.0, 0.0),
                Vec3::new(0.0, 1.0, 1.0),
            ],
        ];
        let light = Vec3::new(0.3, 10.0, 0.2);
        let to_light = surface(&tris, 500, 9, |_, _| Toward::Point(light));
        let hemi = surface(&tris, 500, 9, |rng, n| {
            Toward::Direction(hemisphere(rng, n))
        });
        assert_eq!((to_light.len(), hemi.len()), (500, 500));
        for r in &to_light {
            // Every origin is just above one of the two planes y = 0 and y = 1.
            let above = r.origin.y - r.origin.y.floor();
            assert!(above > 0.0 && above < 1e-5, "{r:?}");
            assert_eq!(r.tmin, render::offset::SPAWN_TMIN);
            let end = r.origin + r.dir * r.tmax;
            assert!(end.distance(light) < 1e-2 && r.tmax < r.origin.distance(light));
        }
        // Normals are −Y for both triangles (X × Z), so hemisphere rays go down.
        assert!(hemi
            .iter()
            .all(|r| r.dir.y < 0.0 && r.tmax == f32::INFINITY));
        let moved = moved_along(&to_light, MOVED);
        for (m, r) in moved.iter().zip(&to_light) {
            assert!((m.origin - (r.origin + r.dir * MOVED)).length() < 1e-6);
            assert!((m.tmax - (r.tmax - MOVED)).abs() < 1e-5);
        }
    }

    #[test]
    fn soft_rays_leave_every_nth_lit_hit_in_groups_within_the_cone() {
        // Normal −Y (X × Z); seen from above, so the lit side is +Y.
        let tris = [[Vec3::ZERO, Vec3::X, Vec3::Z]];
        let down = Ray::new(Vec3::new(0.2, 5.0, 0.2), -Vec3::Y, 0.0, f32::INFINITY);
        let up = Ray::new(Vec3::new(0.2, -5.0, 0.2), Vec3::Y, 0.0, f32::INFINITY);
        let sun = Vec3::new(0.3, 1.0, 0.1).normalize();
        let hit = Some((0, 0.25, 0.25));
        // Hits seen from below face away from the sun; misses make no rays.
        let primary = [down, up, down, down, up, down, down, down];
        let hits = [hit, hit, None, hit, hit, hit, hit, hit];
        let rays = soft(&tris, &primary, &hits, sun, 2, 5);
        // Five lit hits, every second one: three points, two samples each.
        assert_eq!(rays.len(), 6);
        let cos_half = (SUN_DEGREES * 0.5).to_radians().cos();
        for pair in rays.chunks(2) {
            assert_eq!(pair[0].origin, pair[1].origin);
            for r in pair {
                assert!(r.origin.y > 0.0 && r.origin.y < 1e-5, "{r:?}");
                assert!((r.dir.length() - 1.0).abs() < 1e-5);
                assert!(r.dir.dot(sun) >= cos_half - 1e-6, "{r:?}");
                assert_eq!(
                    (r.tmin, r.tmax),
                    (render::offset::SPAWN_TMIN, f32::INFINITY)
                );
            }
            assert_ne!(pair[0].dir, pair[1].dir);
        }
        assert_eq!(rays, soft(&tris, &primary, &hits, sun, 2, 5));
    }

    #[test]
    fn random_rays_are_inside_and_unit() {
        let b = [Vec3::new(-1.0, 0.0, 2.0), Vec3::new(3.0, 1.0, 4.0)];
        let rays = random(b, 1000, 7);
        assert_eq!(rays.len(), 1000);
        for r in &rays {
            assert!(r.origin.cmpge(b[0]).all() && r.origin.cmple(b[1]).all());
            assert!((r.dir.length() - 1.0).abs() < 1e-5);
        }
        assert_eq!(rays, random(b, 1000, 7));
    }
}
