//! Brute force: every ray against every triangle. Two references with different jobs:
//!
//! * [`intersect`] uses the tree's own watertight test and tie rule, so a correct tree
//!   gives exactly its answer (same triangle, same t, bit for bit): the equivalence
//!   tests compare with it.
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
    if !(ray.tmin <= ray.tmax) || ray.tmax == f32::NEG_INFINITY || ray.tmin == f32::INFINITY {
        return None;
    }
    let pre = RayPre::new(ray.origin, ray.dir)?;
    let mut best = Hit::MISS;
    let mut best_t = ray.tmax;
    for (i, t) in triangles.iter().enumerate() {
        let tri = [t[0].to_array(), t[1].to_array(), t[2].to_array()];
        if let Some(h) = triangle::intersect(&pre, &tri, ray.tmin, triangle::widen(best_t)) {
            keep_closer(&mut best, &mut best_t, i as u32, h, &mut accept);
        }
    }
    (!best.is_miss()).then_some(best)
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
