//! Watertight ray/triangle intersection (Woop, Benthin & Wald 2013, JCGT 2(1)).
//!
//! The ray is translated to the origin, its axes permuted so that the dominant direction
//! component becomes z, and the triangle sheared so that the ray runs along +z. The hit
//! test is then three 2-D edge functions whose values for an edge shared by two triangles
//! are exact negations of each other, so no ray can slip between them. When an edge
//! function is exactly zero it is recomputed in f64 (products of two f32 are exact there),
//! so the sign on an edge is never decided by rounding. There is no absolute epsilon on
//! the determinant and no division before the hit is known to be closer than the current
//! best (the t test multiplies by the determinant instead).

use glam::Vec3;

/// Per-ray constants of the watertight test, computed once per ray.
#[derive(Clone, Copy, Debug)]
pub struct RayPre {
    pub origin: [f32; 3],
    /// The dominant axis of the direction; x and y of the sheared frame are the next
    /// two axes in cyclic order.
    pub kz: usize,
    pub sx: f32,
    pub sy: f32,
    pub sz: f32,
}

impl RayPre {
    /// None when the direction is zero or not finite (such a ray hits nothing).
    #[inline]
    pub fn new(origin: Vec3, dir: Vec3) -> Option<RayPre> {
        if !origin.is_finite() || !dir.is_finite() {
            return None;
        }
        let a = dir.abs();
        let kz = if a.x >= a.y && a.x >= a.z {
            0
        } else if a.y >= a.z {
            1
        } else {
            2
        };
        let d = dir.to_array();
        if d[kz] == 0.0 {
            return None;
        }
        // Woop et al. swap x and y for a negative direction to keep the winding's sign;
        // the test here is two-sided, and the swap would only negate all three edge
        // functions, the determinant and the t numerator, which cancel.
        let (kx, ky) = ((kz + 1) % 3, (kz + 2) % 3);
        Some(RayPre {
            origin: origin.to_array(),
            kz,
            sx: d[kx] / d[kz],
            sy: d[ky] / d[kz],
            sz: 1.0 / d[kz],
        })
    }
}

/// A hit's unnormalised quantities; `t()` etc. divide only once the hit is accepted.
#[derive(Clone, Copy, Debug)]
pub struct RawHit {
    pub t: f32,
    pub u: f32,
    pub v: f32,
}

/// Watertight, two-sided test of one triangle against a ray in [tmin, tmax]
/// (tmax may be +inf). Returns t and the barycentrics (u weights v1, v weights v2).
#[inline(always)]
pub fn intersect(r: &RayPre, tri: &[[f32; 3]; 3], tmin: f32, tmax: f32) -> Option<RawHit> {
    match r.kz {
        0 => intersect_along::<0>(r, tri, tmin, tmax),
        1 => intersect_along::<1>(r, tri, tmin, tmax),
        _ => intersect_along::<2>(r, tri, tmin, tmax),
    }
}

/// [`intersect`] for a ray whose dominant axis is `KZ` (`r.kz == KZ`). The permutation is
/// a constant here, so the vertices are read straight from memory; the traversal is
/// instantiated once per dominant axis to call this.
///
#[inline(always)]
pub fn intersect_along<const KZ: usize>(
    r: &RayPre,
    tri: &[[f32; 3]; 3],
    tmin: f32,
    tmax: f32,
) -> Option<RawHit> {
    debug_assert_eq!(r.kz, KZ);
    let kx = (KZ + 1) % 3;
    let ky = (KZ + 2) % 3;
    let (sx, sy) = (r.sx, r.sy);
    let o = r.origin;
    let rel = |p: &[f32; 3]| [p[kx] - o[kx], p[ky] - o[ky], p[KZ] - o[KZ]];
    let a = rel(&tri[0]);
    let b = rel(&tri[1]);
    let c = rel(&tri[2]);
    let ax = a[0] - sx * a[2];
    let ay = a[1] - sy * a[2];
    let bx = b[0] - sx * b[2];
    let by = b[1] - sy * b[2];
    let cx = c[0] - sx * c[2];
    let cy = c[1] - sy * c[2];
    let mut u = cx * by - cy * bx;
    let mut v = ax * cy - ay * cx;
    let mut w = bx * ay - by * ax;
    if u == 0.0 || v == 0.0 || w == 0.0 {
        // Exactly on an edge in f32: decide in f64, where these products are exact.
        let (ax, ay, bx, by, cx, cy) = (
            ax as f64, ay as f64, bx as f64, by as f64, cx as f64, cy as f64,
        );
        u = (cx * by - cy * bx) as f32;
        v = (ax * cy - ay * cx) as f32;
        w = (bx * ay - by * ax) as f32;
    }
    if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
        return None;
    }
    let det = u + v + w;
    if det == 0.0 || det.is_nan() {
        return None;
    }
    let az = r.sz * a[2];
    let bz = r.sz * b[2];
    let cz = r.sz * c[2];
    let tt = u * az + v * bz + w * cz;
    // Two-sided: compare against |det|-scaled bounds instead of dividing.
    let (tt, adet) = if det < 0.0 { (-tt, -det) } else { (tt, det) };
    if !(tt >= tmin * adet && tt <= tmax * adet) {
        return None;
    }
    let inv = 1.0 / det;
    let t = tt / adet;
    if !(t >= tmin && t <= tmax) {
        // Overflow of tmax·det or rounding of the final division: stay inside the interval.
        return None;
    }
    Some(RawHit {
        t,
        u: v * inv,
        v: w * inv,
    })
}

/// Plain Möller–Trumbore (1997), kept only to measure what watertightness costs: it leaks
/// rays through shared edges and rejects hits with an absolute determinant epsilon.
#[inline(always)]
pub fn intersect_moller(
    origin: Vec3,
    dir: Vec3,
    tri: &[[f32; 3]; 3],
    tmin: f32,
    tmax: f32,
) -> Option<RawHit> {
    let v0 = Vec3::from(tri[0]);
    let e1 = Vec3::from(tri[1]) - v0;
    let e2 = Vec3::from(tri[2]) - v0;
    let p = dir.cross(e2);
    let det = e1.dot(p);
    if det.abs() < 1e-8 {
        return None;
    }
    let inv = 1.0 / det;
    let s = origin - v0;
    let u = s.dot(p) * inv;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let q = s.cross(e1);
    let v = dir.dot(q) * inv;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    let t = e2.dot(q) * inv;
    if t >= tmin && t <= tmax {
        Some(RawHit { t, u, v })
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri() -> [[f32; 3]; 3] {
        [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]
    }

    #[test]
    fn hits_front_and_back_with_barycentrics() {
        for dz in [1.0f32, -1.0] {
            let o = Vec3::new(0.25, 0.5, -2.0 * dz);
            let r = RayPre::new(o, Vec3::new(0.0, 0.0, dz)).unwrap();
            let h = intersect(&r, &tri(), 0.0, f32::INFINITY).unwrap();
            assert_eq!(h.t, 2.0);
            assert!(
                (h.u - 0.25).abs() < 1e-6 && (h.v - 0.5).abs() < 1e-6,
                "{h:?}"
            );
        }
    }

    #[test]
    fn respects_interval() {
        let r = RayPre::new(Vec3::new(0.2, 0.2, -1.0), Vec3::Z).unwrap();
        assert!(intersect(&r, &tri(), 0.0, 0.999).is_none());
        assert!(intersect(&r, &tri(), 1.001, 5.0).is_none());
        assert_eq!(intersect(&r, &tri(), 1.0, 1.0).unwrap().t, 1.0);
    }

    #[test]
    fn vertex_and_edge_hits_count() {
        // Exactly through a vertex and through an edge midpoint: both are hits.
        for p in [[0.0, 0.0], [1.0, 0.0], [0.5, 0.5], [0.0, 0.5]] {
            let r = RayPre::new(Vec3::new(p[0], p[1], -1.0), Vec3::Z).unwrap();
            assert!(intersect(&r, &tri(), 0.0, 10.0).is_some(), "{p:?}");
        }
    }

    #[test]
    fn degenerate_inputs_miss() {
        assert!(RayPre::new(Vec3::ZERO, Vec3::ZERO).is_none());
        assert!(RayPre::new(Vec3::ZERO, Vec3::new(f32::NAN, 0.0, 1.0)).is_none());
        assert!(RayPre::new(Vec3::splat(f32::INFINITY), Vec3::Z).is_none());
        let r = RayPre::new(Vec3::new(0.0, 0.0, -1.0), Vec3::Z).unwrap();
        let line = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]];
        assert!(intersect(&r, &line, 0.0, 10.0).is_none());
        let point = [[0.0, 0.0, 0.0]; 3];
        assert!(intersect(&r, &point, 0.0, 10.0).is_none());
    }
}
