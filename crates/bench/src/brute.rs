//! Brute force: every ray against every triangle, Möller–Trumbore in f64. An
//! independent reference (it shares no code with the k-d tree) and the floor that shows
//! what an acceleration structure buys.

use glam::{DVec3, Vec3};
use kdtree::Ray;

/// Hit distance and barycentrics of `ray` on `tri`, in f64, without interval checks.
#[inline]
fn hit(o: DVec3, d: DVec3, tri: &[Vec3; 3]) -> Option<(f64, f64, f64)> {
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

/// Closest hit in [tmin, tmax] as (t, triangle); ties go to the lower index.
pub fn intersect(triangles: &[[Vec3; 3]], ray: &Ray) -> Option<(f32, u32)> {
    let o = ray.origin.as_dvec3();
    let d = ray.dir.as_dvec3();
    let (tmin, mut tmax) = (ray.tmin as f64, ray.tmax as f64);
    let mut best = None;
    for (i, tri) in triangles.iter().enumerate() {
        if let Some((t, _, _)) = hit(o, d, tri) {
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

/// Whether any triangle is hit in [tmin, tmax].
pub fn occluded(triangles: &[[Vec3; 3]], ray: &Ray) -> bool {
    let o = ray.origin.as_dvec3();
    let d = ray.dir.as_dvec3();
    let (tmin, tmax) = (ray.tmin as f64, ray.tmax as f64);
    triangles
        .iter()
        .any(|tri| matches!(hit(o, d, tri), Some((t, _, _)) if t >= tmin && t <= tmax))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rays::ray;

    #[test]
    fn finds_the_nearest_of_two_and_respects_the_interval() {
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
        let r = ray(Vec3::ZERO, Vec3::Z, 0.0, f32::INFINITY);
        assert_eq!(intersect(&tris, &r), Some((3.0, 1)));
        let r = ray(Vec3::ZERO, Vec3::Z, 4.0, f32::INFINITY);
        assert_eq!(intersect(&tris, &r), Some((5.0, 0)));
        let r = ray(Vec3::ZERO, Vec3::Z, 0.0, 2.0);
        assert_eq!(intersect(&tris, &r), None);
        assert!(!occluded(&tris, &r));
        assert!(occluded(&tris, &ray(Vec3::ZERO, Vec3::Z, 0.0, 3.0)));
    }
}
