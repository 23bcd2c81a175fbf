//! Brute force: every ray against every triangle. Two references with different jobs:
//!
//! * [`intersect`] uses the tree's own watertight test and tie rule, so a correct tree
//!   gives exactly its answer (same triangle, same t, bit for bit): the equivalence
//!   tests compare with it. [`Runs`] gives the same answers for a million rays in
//!   seconds instead of minutes.
//! * [`intersect_f64`] and [`occluded_f64`] are plain Möller–Trumbore in f64 and share no
//!   code with the tree: an independent referee for benchmarks that compare the tree
//!   with other tracers, and the floor that shows what an acceleration structure buys.

use crate::traverse::keep_closer;
use crate::triangle::{self, RayPre};
use crate::Ray;
use formats::Hit;
use glam::{DVec3, Vec3};

/// Closest hit in [tmin, tmax] with the tree's watertight test; ties in t go to the lower
/// triangle index, as in the tree.
pub fn intersect(triangles: &[[Vec3; 3]], ray: &Ray) -> Option<Hit> {
    intersect_filtered(triangles, ray, |_, _| true)
}

/// [`intersect`] over the hits `accept` takes, asked as the tree asks it.
pub fn intersect_filtered(
    triangles: &[[Vec3; 3]],
    ray: &Ray,
    mut accept: impl FnMut(&Hit, bool) -> bool,
) -> Option<Hit> {
    let pre = ray_pre(ray)?;
    let mut best = Hit::MISS;
    let mut best_t = ray.tmax;
    test_run(&pre, ray, triangles, 0, &mut best, &mut best_t, &mut accept);
    (!best.is_miss()).then_some(best)
}

/// The per-ray constants, or None for a ray that can hit nothing (an empty interval, bad
/// numbers).
fn ray_pre(ray: &Ray) -> Option<RayPre> {
    if !(ray.tmin <= ray.tmax) || ray.tmax == f32::NEG_INFINITY || ray.tmin == f32::INFINITY {
        return None;
    }
    RayPre::new(ray.origin, ray.dir)
}

/// Tests `run`, whose first triangle has index `first`, keeping the closer hits `accept`
/// takes, with the tree's test and tie rule.
fn test_run(
    pre: &RayPre,
    ray: &Ray,
    run: &[[Vec3; 3]],
    first: usize,
    best: &mut Hit,
    best_t: &mut f32,
    accept: &mut impl FnMut(&Hit, bool) -> bool,
) {
    for (i, t) in run.iter().enumerate() {
        let tri = [t[0].to_array(), t[1].to_array(), t[2].to_array()];
        if let Some(h) = triangle::intersect(pre, &tri, ray.tmin, triangle::widen(*best_t)) {
            keep_closer(best, best_t, (first + i) as u32, h, accept);
        }
    }
}

/// [`intersect`], answer for answer, with most of the work skipped where it provably
/// cannot change the answer. The triangles are cut into runs of consecutive indices
/// (meshes are contiguous in a soup, so a run is a patch of a mesh) and each run sits in its
/// bounding box, grown for each ray by 10⁻⁴ of the scene's diagonal plus the largest
/// coordinate of the scene and of the ray's origin: the triangle test works on vertices
/// less the origin in f32, so its hits are off the exact line by a few ulps of those, and the
/// margin is hundreds of times that. A ray that misses a run's box cannot hit a triangle in
/// it, and a run whose box the ray enters beyond the best hit so far cannot hold a closer
/// one; since ties go to the lower index whatever the order of the tests, visiting the boxes
/// nearest first and stopping there leaves the answer unchanged. The boxes are a flat list in f64, not
/// a hierarchy, and share no code with the tree's build or traversal.
pub struct Runs<'a> {
    triangles: &'a [[Vec3; 3]],
    run: usize,
    boxes: Vec<[DVec3; 2]>,
    /// The scene's diagonal plus its largest coordinate (see the margin above).
    scale: f64,
}

impl<'a> Runs<'a> {
    /// Runs of `run` triangles (the last may be shorter). Some hundred suit a scene of
    /// tens of thousands: a box test costs about what a triangle test does.
    pub fn new(triangles: &'a [[Vec3; 3]], run: usize) -> Runs<'a> {
        let run = run.max(1);
        let bounds = |tris: &[[Vec3; 3]]| {
            let mut b = [DVec3::INFINITY, DVec3::NEG_INFINITY];
            for p in tris.iter().flatten() {
                b = [b[0].min(p.as_dvec3()), b[1].max(p.as_dvec3())];
            }
            b
        };
        let [lo, hi] = bounds(triangles);
        let scale = (hi - lo).length() + lo.abs().max(hi.abs()).max_element();
        let boxes = triangles.chunks(run).map(bounds).collect();
        Runs {
            triangles,
            run,
            boxes,
            scale: if scale.is_finite() { scale } else { 0.0 },
        }
    }

    /// The same answer as [`intersect`] on all the triangles.
    pub fn intersect(&self, ray: &Ray) -> Option<Hit> {
        let pre = ray_pre(ray)?;
        let (o, d) = (ray.origin.as_dvec3(), ray.dir.as_dvec3());
        let margin = DVec3::splat((1e-4 * (self.scale + o.abs().max_element())).max(1e-30));
        let (tmin, tmax) = (ray.tmin as f64, ray.tmax as f64);
        let mut entered: Vec<(f64, usize)> = self
            .boxes
            .iter()
            .enumerate()
            .filter_map(|(k, b)| {
                let grown = [b[0] - margin, b[1] + margin];
                Some((entry(o, d, &grown, tmin, tmax)?, k))
            })
            .collect();
        entered.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
        let mut best = Hit::MISS;
        let mut best_t = ray.tmax;
        for (t_in, k) in entered {
            if t_in > triangle::widen(best_t) as f64 {
                break;
            }
            let first = k * self.run;
            let run = &self.triangles[first..(first + self.run).min(self.triangles.len())];
            test_run(
                &pre,
                ray,
                run,
                first,
                &mut best,
                &mut best_t,
                &mut |_, _| true,
            );
        }
        (!best.is_miss()).then_some(best)
    }
}

/// Where the ray o + t·d, t in [tmin, tmax], enters the box `b`, or None if it misses it.
fn entry(o: DVec3, d: DVec3, b: &[DVec3; 2], tmin: f64, tmax: f64) -> Option<f64> {
    let (mut near, mut far) = (tmin, tmax);
    for a in 0..3 {
        if d[a] == 0.0 {
            if o[a] < b[0][a] || o[a] > b[1][a] {
                return None;
            }
            continue;
        }
        let (t0, t1) = ((b[0][a] - o[a]) / d[a], (b[1][a] - o[a]) / d[a]);
        near = near.max(t0.min(t1));
        far = far.min(t0.max(t1));
        if near > far {
            return None;
        }
    }
    Some(near)
}

/// Hit distance and barycentrics of a ray on `tri`, in f64, without interval checks.
#[inline]
fn hit_f64(o: DVec3, d: DVec3, tri: &[Vec3; 3]) -> Option<(f64, f64, f64)> {
    let v0 = tri[0].as_dvec3();
    let e1 = tri[1].as_dvec3() - v0;
    let e2 = tri[2].as_dvec3() - v0;
    let p = d.cross(e2);
    let det = e1.dot(p);
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let inv = 1.0 / det;
    let s = o - v0;
    let u = s.dot(p) * inv;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let q = s.cross(e1);
    let v = d.dot(q) * inv;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    Some((e2.dot(q) * inv, u, v))
}

/// Closest hit in [tmin, tmax] as (t, triangle) by Möller–Trumbore in f64; ties go to the
/// lower index.
pub fn intersect_f64(triangles: &[[Vec3; 3]], ray: &Ray) -> Option<(f32, u32)> {
    let o = ray.origin.as_dvec3();
    let d = ray.dir.as_dvec3();
    let (tmin, mut tmax) = (ray.tmin as f64, ray.tmax as f64);
    let mut best = None;
    for (i, tri) in triangles.iter().enumerate() {
        if let Some((t, _, _)) = hit_f64(o, d, tri) {
            // Strictly closer replaces (ties keep the lower index); t = tmax counts only
            // for the first hit, since the interval is closed.
            if t >= tmin && (t < tmax || (t == tmax && best.is_none())) {
                tmax = t;
                best = Some((t as f32, i as u32));
            }
        }
    }
    best
}

/// Whether any triangle is hit in [tmin, tmax], by Möller–Trumbore in f64.
pub fn occluded_f64(triangles: &[[Vec3; 3]], ray: &Ray) -> bool {
    let o = ray.origin.as_dvec3();
    let d = ray.dir.as_dvec3();
    let (tmin, tmax) = (ray.tmin as f64, ray.tmax as f64);
    triangles
        .iter()
        .any(|tri| matches!(hit_f64(o, d, tri), Some((t, _, _)) if t >= tmin && t <= tmax))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testkit::{grid, grid_box, sphere, Rng};

    /// `Runs` must agree with `intersect` exactly, including bounded intervals, rays that
    /// start inside the scene, coplanar duplicates (ties by index) and rays along a plane.
    #[test]
    fn runs_give_exactly_the_answers_of_testing_every_triangle() {
        // At the origin, and 10⁵ away, where coordinates keep about 3 fractional bits.
        for offset in [Vec3::ZERO, Vec3::new(1e5, 0.0, -1e5)] {
            let mut tris = sphere(Vec3::new(0.3, 0.2, -0.1), 1.0, 12, 24);
            tris.extend(grid_box(Vec3::new(2.5, 0.0, 0.0), 0.7, 6));
            // The grid twice, exactly: ties go to the lower index.
            tris.extend(grid(10, 8.0, -1.2));
            tris.extend(grid(10, 8.0, -1.2));
            let tris: Vec<[Vec3; 3]> = tris.iter().map(|t| t.map(|v| v + offset)).collect();
            // Runs of 8: many boxes for so few triangles, so the order and the early stop
            // matter.
            let runs = Runs::new(&tris, 8);
            let mut rng = Rng(7);
            let (mut hits, mut rays) = (0, 0);
            for i in 0..4000 {
                let mut origin = Vec3::new(
                    rng.range(-2.0, 7.0),
                    rng.range(-3.0, 2.0),
                    rng.range(-2.0, 7.0),
                );
                let mut dir = rng.dir();
                if i % 10 == 0 {
                    // In the grid's plane, which is also a face of its runs' boxes.
                    (origin.y, dir.y) = (-1.2, 0.0);
                }
                let (tmin, tmax) = match i % 3 {
                    0 => (0.0, f32::INFINITY),
                    1 => (rng.range(0.0, 2.0), rng.range(2.0, 6.0)),
                    _ => (0.0, rng.range(0.0, 3.0)),
                };
                let r = Ray::new(origin + offset, dir, tmin, tmax);
                let want = intersect(&tris, &r);
                assert_eq!(runs.intersect(&r), want, "{r:?}");
                hits += want.is_some() as usize;
                rays += 1;
            }
            assert!(hits > rays / 8 && hits < rays, "{hits} of {rays} rays hit");
        }
    }

    #[test]
    fn f64_reference_finds_the_nearest_of_two_and_respects_the_interval() {
        let tris = [
            [
                Vec3::new(-1.0, -1.0, 5.0),
                Vec3::new(1.0, -1.0, 5.0),
                Vec3::new(0.0, 1.0, 5.0),
            ],
            [
                Vec3::new(-1.0, -1.0, 3.0),
                Vec3::new(1.0, -1.0, 3.0),
                Vec3::new(0.0, 1.0, 3.0),
            ],
        ];
        let r = Ray::new(Vec3::ZERO, Vec3::Z, 0.0, f32::INFINITY);
        assert_eq!(intersect_f64(&tris, &r), Some((3.0, 1)));
        let r = Ray::new(Vec3::ZERO, Vec3::Z, 4.0, f32::INFINITY);
        assert_eq!(intersect_f64(&tris, &r), Some((5.0, 0)));
        let r = Ray::new(Vec3::ZERO, Vec3::Z, 0.0, 2.0);
        assert_eq!(intersect_f64(&tris, &r), None);
        assert!(!occluded_f64(&tris, &r));
        assert!(occluded_f64(
            &tris,
            &Ray::new(Vec3::ZERO, Vec3::Z, 0.0, 3.0)
        ));
    }
}
