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

use glam::{Vec3, Vec4};

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
    /// The ray meets the triangle's front: its vertices run counter-clockwise as the ray
    /// sees them. Taken from the determinant's sign, so it is the side the hit itself was
    /// found on, never a separate (and differently rounded) normal test.
    pub front: bool,
}

/// The bound to test candidates against when the best t so far is `t`: a few ulps more,
/// so the scaled early out (T ≤ tmax·|det| before dividing) never refuses a triangle
/// whose divided t rounds to exactly `t`. The caller then compares the divided t with `t`
/// exactly, so a tie goes by index whatever order the triangles are tested in.
#[inline(always)]
pub fn widen(t: f32) -> f32 {
    t + t.abs() * PAD
}

/// A few ulps, relative: `widen`'s margin, and the traversal's padding of cell intervals.
pub const PAD: f32 = 4.0 * f32::EPSILON;

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
    let xy = [max3(ax, bx, cx), max3(ay, by, cy)];
    finish([u, v, w], [a[2], b[2], c[2]], xy, r.sz, tmin, tmax)
}

/// Whether a hit with determinant `det` is on the triangle's front. The determinant is minus
/// the sheared triangle's signed area in the plane of the other two axes: negative when
/// the vertices run counter-clockwise seen from the dominant axis's positive side, which is
/// the side a ray travelling down that axis (`sz` < 0) comes from.
#[inline(always)]
fn faces_front(det: f32, sz: f32) -> bool {
    (det < 0.0) == (sz < 0.0)
}

/// The largest magnitude of three values.
#[inline(always)]
fn max3(a: f32, b: f32, c: f32) -> f32 {
    a.abs().max(b.abs()).max(c.abs())
}

/// [`max3`] on four lanes, with `f32::max`'s answer where a lane is NaN (the other value),
/// which a plain vector maximum does not give.
#[inline(always)]
fn max3_4(a: Vec4, b: Vec4, c: Vec4) -> Vec4 {
    let max = |x: Vec4, y: Vec4| {
        Vec4::select(
            x.is_nan_mask(),
            y,
            Vec4::select(y.is_nan_mask(), x, x.max(y)),
        )
    };
    max(max(a.abs(), b.abs()), c.abs())
}

/// γₙ = n·u / (1 − n·u), u = 2⁻²⁴: Higham's bound on n roundings.
const fn gamma(n: i32) -> f32 {
    let u = f32::EPSILON * 0.5;
    (n as f32 * u) / (1.0 - n as f32 * u)
}

/// Below this, a positive tmin is taken as 0 in the scaled early-out `tt ≥ tmin·|det|`.
/// A spawned ray's tmin is `f32::MIN_POSITIVE`, which excludes t = 0 and subnormal t, and
/// its product with a determinant below 1 is subnormal: Intel cores take a microcode assist
/// of about a hundred cycles for each such result, at every triangle test. The final
/// `t ≥ tmin` still holds each hit to the real bound; the early-out with 0 lets through
/// only hits within an ulp of a tmin this small, which the near-hit bound in `finish`
/// refuses unless the triangle lies within about 1e-16 of the origin.
const TINY_TMIN: f32 = 1.0 / 18_446_744_073_709_551_616.0; // 2⁻⁶⁴

/// The lower bound for the scaled early-out: `tmin`, or 0 for a positive tmin below
/// [`TINY_TMIN`].
#[inline(always)]
fn scaled_tmin(tmin: f32) -> f32 {
    if tmin > 0.0 && tmin < TINY_TMIN {
        0.0
    } else {
        tmin
    }
}

/// [`scaled_tmin`] on four lanes.
#[inline(always)]
fn scaled_tmin4(tmin: Vec4) -> Vec4 {
    let tiny = tmin.cmpgt(Vec4::ZERO) & tmin.cmplt(Vec4::splat(TINY_TMIN));
    Vec4::select(tiny, Vec4::ZERO, tmin)
}

/// The part of the test after the edge functions `uvw` agree in sign: the determinant,
/// the distance from the vertices' `z` (relative to the origin, before the z shear) and
/// the interval. Shared by the one- and four-triangle tests so they give the same bits.
///
/// A hit no farther than the bound on t's own rounding error is refused: the sign of such
/// a t is not known. `xy` holds the largest |x| and |y| of the sheared
/// vertices. Without this, a ray spawned a hair below a large triangle's plane (a small
/// face lying flat on a big floor, the ray leaving downwards) could find that plane at a
/// tiny positive t: on a 24 m triangle t rounds at the ULPs of metres.
#[inline(always)]
fn finish(
    uvw: [f32; 3],
    z: [f32; 3],
    xy: [f32; 2],
    sz: f32,
    tmin: f32,
    tmax: f32,
) -> Option<RawHit> {
    let [u, v, w] = uvw;
    let det = u + v + w;
    if det == 0.0 || det.is_nan() {
        return None;
    }
    let tt = u * (sz * z[0]) + v * (sz * z[1]) + w * (sz * z[2]);
    // Two-sided: compare against |det|-scaled bounds instead of dividing.
    let (tt, adet) = if det < 0.0 { (-tt, -det) } else { (tt, det) };
    if !(tt >= scaled_tmin(tmin) * adet && tt <= tmax * adet) {
        return None;
    }
    let inv = 1.0 / det;
    let t = tt / adet;
    if !(t >= tmin && t <= tmax) {
        // Overflow of tmax·det or rounding of the final division: stay inside the interval.
        return None;
    }
    // The bound is a few ulps of the vertices' depth from the origin unless the triangle
    // is seen almost edge-on, so it is worked out only for a t below 2⁻¹⁰ of that depth.
    let max_z = max3(sz * z[0], sz * z[1], sz * z[2]);
    if t < max_z * (1.0 / 1024.0) && t <= t_error([u, v, w], max_z, xy, inv) {
        return None;
    }
    Some(RawHit {
        t,
        u: v * inv,
        v: w * inv,
        front: faces_front(det, sz),
    })
}

/// The answers of [`intersect4_along`], lane by lane: `hit[l]` says whether lane `l` hit,
/// and `t`, `u`, `v` hold its hit where it did (anything elsewhere).
#[derive(Clone, Copy, Debug)]
pub struct Hits4 {
    pub hit: [bool; 4],
    pub t: [f32; 4],
    pub u: [f32; 4],
    pub v: [f32; 4],
    pub front: [bool; 4],
}

impl Hits4 {
    /// The lanes that hit, in lane order. The loop runs once per hit (most groups have
    /// none): asking each of four lanes was four branches a predictor cannot guess.
    #[inline(always)]
    pub fn hit_lanes(&self) -> impl Iterator<Item = usize> {
        // One byte per lane, so lane l is bit 8·l of the little-endian word.
        let mut mask = u32::from_le_bytes(self.hit.map(u8::from));
        std::iter::from_fn(move || {
            (mask != 0).then(|| {
                let l = mask.trailing_zeros() as usize / 8;
                mask &= mask - 1;
                l
            })
        })
    }

    /// Lane `l`'s hit, for a lane that hit.
    #[inline(always)]
    pub fn raw(&self, l: usize) -> RawHit {
        RawHit {
            t: self.t[l],
            u: self.u[l],
            v: self.v[l],
            front: self.front[l],
        }
    }
}

/// The bound on the rounding error of a hit's t: `uvw` the edge functions, `max_z` the
/// largest |z| of the sheared vertices, `xy` their largest |x| and |y|, `inv` 1/det.
#[inline(always)]
fn t_error(uvw: [f32; 3], max_z: f32, xy: [f32; 2], inv: f32) -> f32 {
    let [max_x, max_y] = xy;
    let dz = gamma(3) * max_z;
    let dx = gamma(5) * (max_x + max_z);
    let dy = gamma(5) * (max_y + max_z);
    let de = 2.0 * (gamma(2) * max_x * max_y + dy * max_x + dx * max_y);
    let max_e = max3(uvw[0], uvw[1], uvw[2]);
    3.0 * (gamma(3) * max_e * max_z + de * max_z + dz * max_e) * inv.abs()
}

/// Four triangles' vertices by lane: `[a, b, c][axis]`, lane l from `tri[l]`.
///
/// On x86_64 each vertex comes in as one unaligned 16-byte load (floats 0–3, 3–6 and 5–8
/// of the triangle's nine, all inside it) and each vertex's four loads are transposed: 12
/// loads and 21 shuffles, where building the vectors element by element took 36 loads and
/// 27 inserts.
#[inline(always)]
fn gather4(tri: [&[[f32; 3]; 3]; 4]) -> [[Vec4; 3]; 3] {
    #[cfg(target_arch = "x86_64")]
    {
        use core::arch::x86_64::*;
        // SAFETY: SSE is part of x86_64. Each load reads 16 bytes from float 0, 3 or 5 of
        // a 36-byte triangle, so it stays inside the triangle the reference points at.
        unsafe {
            let transpose = |at: usize| -> [__m128; 4] {
                let [r0, r1, r2, r3] = tri.map(|t| _mm_loadu_ps(t.as_ptr().cast::<f32>().add(at)));
                let (t0, t1) = (_mm_unpacklo_ps(r0, r1), _mm_unpacklo_ps(r2, r3));
                let (t2, t3) = (_mm_unpackhi_ps(r0, r1), _mm_unpackhi_ps(r2, r3));
                [
                    _mm_movelh_ps(t0, t1),
                    _mm_movehl_ps(t1, t0),
                    _mm_movelh_ps(t2, t3),
                    _mm_movehl_ps(t3, t2),
                ]
            };
            let rows = |r: [__m128; 4], from: usize| -> [Vec4; 3] {
                [
                    Vec4::from(r[from]),
                    Vec4::from(r[from + 1]),
                    Vec4::from(r[from + 2]),
                ]
            };
            [
                rows(transpose(0), 0),
                rows(transpose(3), 0),
                rows(transpose(5), 1),
            ]
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        std::array::from_fn(|k| {
            std::array::from_fn(|axis| Vec4::from_array(tri.map(|t| t[k][axis])))
        })
    }
}

/// [`intersect_along`] for four triangles at once, on four-lane vectors (glam's `Vec4`, SSE
/// on x86_64) with masks instead of early returns; only the rare bound on a very near
/// hit's rounding is worked out lane by lane. Written lane by lane, the compiler left the
/// compares scalar (200 instructions a ray on the bunny's surface rays). Each lane's arithmetic is the
/// scalar test's, in the same order, so each lane's answer has the same bits as
/// `intersect_along` on that triangle (lanes that miss compute values nobody reads); a
/// group with an edge function exactly zero is handed to the scalar test whole, for its
/// f64 decision.
#[inline(always)]
pub fn intersect4_along<const KZ: usize>(
    r: &RayPre,
    tri: [&[[f32; 3]; 3]; 4],
    tmin: f32,
    tmax: f32,
) -> Hits4 {
    debug_assert_eq!(r.kz, KZ);
    let kx = (KZ + 1) % 3;
    let ky = (KZ + 2) % 3;
    let o = r.origin;
    // One vector per coordinate: vertex k's coordinate on `axis`, relative to the origin.
    let vertices = gather4(tri);
    let rel = |k: usize, axis: usize| vertices[k][axis] - Vec4::splat(o[axis]);
    let z = [rel(0, KZ), rel(1, KZ), rel(2, KZ)];
    let xy = [
        rel(0, kx),
        rel(0, ky),
        rel(1, kx),
        rel(1, ky),
        rel(2, kx),
        rel(2, ky),
    ];
    let shear = [Vec4::splat(r.sx), Vec4::splat(r.sy), Vec4::splat(r.sz)];
    let bounds = [
        Vec4::splat(scaled_tmin(tmin)),
        Vec4::splat(tmin),
        Vec4::splat(tmax),
    ];
    lanes4(xy, z, shear, bounds, |l| {
        intersect_along::<KZ>(r, tri[l], tmin, tmax)
    })
}

/// Four rays' constants of the watertight test, one lane per ray, for testing one triangle
/// against four rays with the same dominant axis ([`intersect_rays4_along`]).
#[derive(Clone, Copy, Debug)]
pub struct RayPre4 {
    pub rays: [RayPre; 4],
    origin: [Vec4; 3],
    shear: [Vec4; 3],
}

impl RayPre4 {
    /// Four rays with dominant axis `kz`, from their origins and their sx, sy and sz
    /// (`RayPre`'s fields) axis by axis, as vectors.
    #[inline(always)]
    pub fn from_lanes(kz: usize, origin: [Vec4; 3], shear: [Vec4; 3]) -> RayPre4 {
        let [o, s] = [origin, shear].map(|v| v.map(|x| x.to_array()));
        RayPre4 {
            rays: std::array::from_fn(|l| RayPre {
                origin: [o[0][l], o[1][l], o[2][l]],
                kz,
                sx: s[0][l],
                sy: s[1][l],
                sz: s[2][l],
            }),
            origin,
            shear,
        }
    }
}

/// [`intersect_along`] for one triangle against four rays, lane `l` the test of ray
/// `r.rays[l]` in [`tmin[l]`, `tmax[l]`], each with the same bits as the scalar test (a ray
/// with an edge function exactly zero goes to it, for its f64 decision). The triangle is
/// read once for four rays: a packet whose lanes reach the same leaf tests each of its
/// triangles once, not once per lane.
#[inline(always)]
pub fn intersect_rays4_along<const KZ: usize>(
    r: &RayPre4,
    tri: &[[f32; 3]; 3],
    tmin: [f32; 4],
    tmax: [f32; 4],
) -> Hits4 {
    debug_assert!(r.rays.iter().all(|r| r.kz == KZ));
    let kx = (KZ + 1) % 3;
    let ky = (KZ + 2) % 3;
    let rel = |k: usize, axis: usize| Vec4::splat(tri[k][axis]) - r.origin[axis];
    let z = [rel(0, KZ), rel(1, KZ), rel(2, KZ)];
    let xy = [
        rel(0, kx),
        rel(0, ky),
        rel(1, kx),
        rel(1, ky),
        rel(2, kx),
        rel(2, ky),
    ];
    let tmin4 = Vec4::from_array(tmin);
    let bounds = [scaled_tmin4(tmin4), tmin4, Vec4::from_array(tmax)];
    lanes4(xy, z, r.shear, bounds, |l| {
        intersect_along::<KZ>(&r.rays[l], tri, tmin[l], tmax[l])
    })
}

/// The four-lane test from the vertices relative to each lane's origin: `xy` holds
/// a, b and c's x and y (the axes after the dominant one), `z` their dominant-axis
/// coordinates, `shear` the rays' sx, sy and sz, `bounds` their [`scaled_tmin`], tmin and
/// tmax. When some lane's edge function is exactly zero every lane is answered by `exact`,
/// the scalar test.
#[inline(always)]
fn lanes4(
    xy: [Vec4; 6],
    z: [Vec4; 3],
    shear: [Vec4; 3],
    bounds: [Vec4; 3],
    exact: impl Fn(usize) -> Option<RawHit>,
) -> Hits4 {
    let [sxv, syv, sz] = shear;
    let [az, bz, cz] = z;
    let ax = xy[0] - sxv * az;
    let ay = xy[1] - syv * az;
    let bx = xy[2] - sxv * bz;
    let by = xy[3] - syv * bz;
    let cx = xy[4] - sxv * cz;
    let cy = xy[5] - syv * cz;
    let u = cx * by - cy * bx;
    let v = ax * cy - ay * cx;
    let w = bx * ay - by * ax;
    let z = Vec4::ZERO;
    let zero = u.cmpeq(z) | v.cmpeq(z) | w.cmpeq(z);
    let negative = u.cmplt(z) | v.cmplt(z) | w.cmplt(z);
    let positive = u.cmpgt(z) | v.cmpgt(z) | w.cmpgt(z);
    let mut out = Hits4 {
        hit: [false; 4],
        t: [0.0; 4],
        u: [0.0; 4],
        v: [0.0; 4],
        front: [false; 4],
    };
    if zero.any() {
        for l in 0..4 {
            if let Some(h) = exact(l) {
                (out.hit[l], out.t[l], out.u[l], out.v[l], out.front[l]) =
                    (true, h.t, h.u, h.v, h.front);
            }
        }
        return out;
    }
    // Outside: some edge function negative and some positive.
    let outside = (negative & positive).bitmask();
    if outside == 0b1111 {
        return out;
    }
    // `finish` on four lanes, its early returns as masks.
    let det = u + v + w;
    let (zu, zv, zw) = (sz * az, sz * bz, sz * cz);
    let tt = u * zu + v * zv + w * zw;
    let negative = det.cmplt(z);
    let tt = Vec4::select(negative, -tt, tt);
    let adet = Vec4::select(negative, -det, det);
    let t = tt / adet;
    let inv = Vec4::ONE / det;
    let max_z = max3_4(zu, zv, zw);
    let near = t.cmplt(max_z * (1.0 / 1024.0));
    let [scaled4, tmin4, tmax4] = bounds;
    let hit = det.cmpne(z)
        & !det.is_nan_mask()
        & tt.cmpge(scaled4 * adet)
        & tt.cmple(tmax4 * adet)
        & t.cmpge(tmin4)
        & t.cmple(tmax4);
    let mut hit = hit.bitmask() & !outside;
    // `faces_front`: the determinant's sign equal to the dominant axis's.
    let front = !(negative.bitmask() ^ sz.cmplt(z).bitmask());
    out.u = (v * inv).to_array();
    out.v = (w * inv).to_array();
    let (t, inv) = (t.to_array(), inv.to_array());
    let near_hits = hit & near.bitmask();
    if near_hits != 0 {
        let (max_z, uvw) = (max_z.to_array(), [u, v, w].map(|x| x.to_array()));
        let [ax, ay, bx, by, cx, cy] = [ax, ay, bx, by, cx, cy].map(|x| x.to_array());
        for l in (0..4).filter(|l| near_hits >> l & 1 != 0) {
            let xy = [max3(ax[l], bx[l], cx[l]), max3(ay[l], by[l], cy[l])];
            let e = [uvw[0][l], uvw[1][l], uvw[2][l]];
            if !(t[l] > t_error(e, max_z[l], xy, inv[l])) {
                hit &= !(1 << l);
            }
        }
    }
    out.hit = std::array::from_fn(|l| hit >> l & 1 != 0);
    out.front = std::array::from_fn(|l| front >> l & 1 != 0);
    out.t = t;
    out
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
            assert_eq!(h.front, dz < 0.0, "the front faces +z");
        }
    }

    /// `front` is the normal's side for every dominant axis, both directions along it,
    /// oblique rays and both windings: the determinant's sign folded with the axis's sign.
    #[test]
    fn front_is_the_side_the_winding_normal_faces() {
        let tri = [[0.3f32, -0.2, 0.1], [1.1, 0.4, -0.3], [-0.2, 0.9, 0.6]];
        let flipped = [tri[0], tri[2], tri[1]];
        let centre = Vec3::new(0.4, 0.366, 0.133);
        let mut checked = 0;
        for t in [tri, flipped] {
            let [a, b, c] = t.map(Vec3::from);
            let n = (b - a).cross(c - a);
            for dir in [
                Vec3::new(1.0, 0.2, -0.1),
                Vec3::new(-1.0, 0.3, 0.2),
                Vec3::new(0.1, 1.0, 0.3),
                Vec3::new(-0.2, -1.0, 0.1),
                Vec3::new(0.3, -0.1, 1.0),
                Vec3::new(0.2, 0.3, -1.0),
            ] {
                let r = RayPre::new(centre - 3.0 * dir, dir).unwrap();
                let h = intersect(&r, &t, 0.0, f32::INFINITY).expect("through the middle");
                assert_eq!(h.front, n.dot(dir) < 0.0, "dir {dir}, normal {n}");
                let lanes = [&t, &t, &t, &t];
                let four = match r.kz {
                    0 => intersect4_along::<0>(&r, lanes, 0.0, f32::INFINITY),
                    1 => intersect4_along::<1>(&r, lanes, 0.0, f32::INFINITY),
                    _ => intersect4_along::<2>(&r, lanes, 0.0, f32::INFINITY),
                };
                assert_eq!(four.front, [h.front; 4]);
                checked += 1;
            }
        }
        assert_eq!(checked, 12);
    }

    /// The four-lane maximum answers as `max3` in every lane, NaN and infinities included
    /// (a plain vector maximum would pass a NaN in its second operand through).
    #[test]
    fn four_lane_max3_is_max3_lane_by_lane() {
        let values = [
            0.0,
            -0.0,
            1.5,
            -2.0,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
            3e38,
        ];
        for &a in &values {
            for &b in &values {
                for &c in &values {
                    let four = max3_4(Vec4::splat(a), Vec4::new(b, c, a, b), Vec4::new(c, a, b, c));
                    let want = [max3(a, b, c), max3(a, c, a), max3(a, a, b), max3(a, b, c)];
                    let got = four.to_array();
                    for l in 0..4 {
                        assert!(
                            got[l].to_bits() == want[l].to_bits()
                                || (got[l].is_nan() && want[l].is_nan()),
                            "{a} {b} {c} lane {l}: {} against {}",
                            got[l],
                            want[l]
                        );
                    }
                }
            }
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

    /// Uniform in [-2, 2) (2·unit − 1 is exact on unit's 2⁻²⁴ grid), rounded to a whole
    /// number when `snap`, so that edge functions come out exactly zero (the f64 path).
    fn coord(rng: &mut crate::testkit::Rng, snap: bool) -> f32 {
        let v = 2.0 * (2.0 * rng.unit() - 1.0);
        if snap {
            v.round()
        } else {
            v
        }
    }

    /// Lanes held to the scalar test bit for bit, with how many of the scalar answers hit,
    /// and hit on an edge or vertex.
    #[derive(Default)]
    struct Tally {
        hits: u32,
        on_edges: u32,
    }

    impl Tally {
        fn lane(&mut self, got: Option<RawHit>, want: Option<RawHit>, what: std::fmt::Arguments) {
            let bits = |h: Option<RawHit>| {
                h.map(|h| (h.t.to_bits(), h.u.to_bits(), h.v.to_bits(), h.front))
            };
            assert_eq!(bits(got), bits(want), "{what}");
            if let Some(h) = want {
                self.hits += 1;
                self.on_edges += (h.u == 0.0 || h.v == 0.0 || h.u + h.v == 1.0) as u32;
            }
        }

        fn enough(&self) {
            assert!(self.hits > 5_000, "{} hits", self.hits);
            assert!(
                self.on_edges > 100,
                "{} hits on an edge or vertex",
                self.on_edges
            );
        }
    }

    /// Random groups of four triangles and rays, a third of them snapped to a coarse grid
    /// with axis-aligned rays so that edge functions are exactly zero (the f64 path):
    /// every lane answers with exactly the scalar test's bits.
    #[test]
    fn four_wide_matches_the_scalar_test_bit_for_bit() {
        let mut rng = crate::testkit::Rng(7);
        let mut tally = Tally::default();
        for i in 0..30_000 {
            let snap = i % 3 == 0;
            let mut p = || coord(&mut rng, snap);
            let tris: [[[f32; 3]; 3]; 4] =
                std::array::from_fn(|_| std::array::from_fn(|_| [p(), p(), p()]));
            let origin = Vec3::new(p(), p(), p() - 4.0);
            let mut unit = || 2.0 * rng.unit() - 1.0;
            let dir = if snap {
                [Vec3::X, Vec3::Y, Vec3::Z, -Vec3::Z][i % 4]
            } else {
                Vec3::new(unit(), unit(), unit() + 1.5)
            };
            let Some(r) = RayPre::new(origin, dir) else {
                continue;
            };
            let tmax = if i % 2 == 0 { f32::INFINITY } else { 5.0 };
            let group = [&tris[0], &tris[1], &tris[2], &tris[3]];
            let four = match r.kz {
                0 => intersect4_along::<0>(&r, group, 0.0, tmax),
                1 => intersect4_along::<1>(&r, group, 0.0, tmax),
                _ => intersect4_along::<2>(&r, group, 0.0, tmax),
            };
            let lanes: Vec<usize> = four.hit_lanes().collect();
            assert_eq!(lanes, (0..4).filter(|&l| four.hit[l]).collect::<Vec<_>>());
            for (l, tri) in tris.iter().enumerate() {
                let lane = four.hit[l].then(|| four.raw(l));
                let one = intersect(&r, tri, 0.0, tmax);
                tally.lane(lane, one, format_args!("group {i}, lane {l}"));
            }
        }
        tally.enough();
    }

    /// One random triangle against four random rays with the same dominant axis, each with
    /// its own interval, a third snapped to a coarse grid with axis-aligned rays (the f64
    /// path): every lane answers with exactly the scalar test's bits.
    #[test]
    fn one_triangle_four_rays_matches_the_scalar_test_bit_for_bit() {
        let mut rng = crate::testkit::Rng(9);
        let mut tally = Tally::default();
        for i in 0..30_000 {
            let snap = i % 3 == 0;
            let mut p = || coord(&mut rng, snap);
            let tri: [[f32; 3]; 3] = std::array::from_fn(|_| [p(), p(), p()]);
            let kz = i % 3;
            let rays: [RayPre; 4] = std::array::from_fn(|l| {
                let mut o = [p(), p(), p()];
                let mut d = if snap {
                    [0.0; 3]
                } else {
                    [p() * 0.35, p() * 0.35, 0.0]
                };
                d.rotate_right(kz);
                let along = if (i + l) % 2 == 0 { 1.0 } else { -1.0 };
                d[kz] = along;
                o[kz] -= 4.0 * along;
                RayPre::new(Vec3::from(o), Vec3::from(d)).expect("a usable ray")
            });
            assert!(rays.iter().all(|r| r.kz == kz));
            let tmin = std::array::from_fn(|l| [0.0, 3.5, 0.0, 1e-4][(i + l) % 4]);
            let tmax = std::array::from_fn(|l| [f32::INFINITY, 5.0, 4.2, 1e30][(i + 2 * l) % 4]);
            let lanes = |f: fn(&RayPre) -> f32| Vec4::from_array(rays.each_ref().map(f));
            let four = RayPre4::from_lanes(
                kz,
                [
                    lanes(|r| r.origin[0]),
                    lanes(|r| r.origin[1]),
                    lanes(|r| r.origin[2]),
                ],
                [lanes(|r| r.sx), lanes(|r| r.sy), lanes(|r| r.sz)],
            );
            let got = match kz {
                0 => intersect_rays4_along::<0>(&four, &tri, tmin, tmax),
                1 => intersect_rays4_along::<1>(&four, &tri, tmin, tmax),
                _ => intersect_rays4_along::<2>(&four, &tri, tmin, tmax),
            };
            for l in 0..4 {
                let lane = got.hit[l].then(|| got.raw(l));
                let one = intersect(&rays[l], &tri, tmin[l], tmax[l]);
                tally.lane(lane, one, format_args!("triangle {i}, lane {l}"));
            }
        }
        tally.enough();
    }

    /// Two overlapping coplanar triangles of the baseline scene (soup triangles 8880 and
    /// 12361, the floor under a pig's foot) hit at the same t by a random ray of
    /// tests/end_to_end/million_rays.rs. Tested against exactly the other's t, the scaled early out
    /// (T ≤ tmax·|det|, T rounded) refuses one of them, so a traversal that passed the best
    /// t as the bound kept whichever came first; against `widen(t)` each is accepted with
    /// its own t, and the caller's exact `t ≤ best` comparison decides the tie by index.
    #[test]
    fn a_tie_is_accepted_against_the_widened_bound() {
        let a = [
            [-3.5761795, 0.95, 1.0735804],
            [-3.4942644, 0.95, 1.0162227],
            [-3.628097, 0.95, 0.82509005],
        ];
        let b = [
            [-3.6585164, 0.95, 0.8812674],
            [-3.4806204, 0.95, 0.948536],
            [-3.5683844, 0.95, 1.0099889],
        ];
        let r = RayPre::new(
            Vec3::new(-3.7973728, 1.1198683, 1.1239977),
            Vec3::new(0.7221318, -0.5132683, -0.4637686),
        )
        .unwrap();
        let ta = intersect(&r, &a, 0.0, f32::INFINITY).unwrap().t;
        let tb = intersect(&r, &b, 0.0, f32::INFINITY).unwrap().t;
        assert_eq!(ta, tb);
        let refused = intersect(&r, &a, 0.0, tb).is_none() || intersect(&r, &b, 0.0, ta).is_none();
        assert!(
            refused,
            "the case no longer shows the scaled early out's rounding"
        );
        assert_eq!(intersect(&r, &a, 0.0, widen(tb)).map(|h| h.t), Some(ta));
        assert_eq!(intersect(&r, &b, 0.0, widen(ta)).map(|h| h.t), Some(tb));
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

    /// A ray that starts just below a large triangle's plane and leaves it downwards (a
    /// secondary ray from a small face lying flat on a big floor) must not find the floor:
    /// on a 24 m triangle t rounds at the ULPs of metres, far more than the 10⁻⁷ m the
    /// origin lies below the plane, so a hit closer than that rounding bound is refused.
    #[test]
    fn a_hit_closer_than_its_rounding_bound_is_refused() {
        let floor = [[-12.0, 0.0, -12.0], [12.0, 0.0, -12.0], [0.0, 0.0, 12.0]];
        let dir = Vec3::new(1.0, -0.3, 0.2).normalize();
        let mut refused = 0;
        for i in 0..200 {
            let o = Vec3::new(
                3.0 + i as f32 * 0.013,
                -9e-8 * (1 + i % 7) as f32,
                2.0 - i as f32 * 0.007,
            );
            let r = RayPre::new(o, dir).unwrap();
            // In exact arithmetic the plane y = 0 is behind every one of these origins.
            assert!(o.y < 0.0 && dir.y < 0.0);
            if intersect(&r, &floor, f32::MIN_POSITIVE, f32::INFINITY).is_none() {
                refused += 1;
            }
            let group = intersect4_along_any(&r, [&floor; 4]);
            assert_eq!(group.hit, [false; 4], "four-wide, origin {o}");
        }
        assert_eq!(refused, 200);
        // A real hit far beyond the rounding bound is kept.
        let r = RayPre::new(Vec3::new(0.0, 1.0, 0.0), dir).unwrap();
        let h = intersect(&r, &floor, f32::MIN_POSITIVE, f32::INFINITY).unwrap();
        assert!((h.t - 1.0 / -dir.y).abs() < 1e-5, "{}", h.t);
    }

    /// A tmin below `TINY_TMIN` skips the scaled early-out's product, which would be
    /// subnormal; the interval still holds, in the scalar test and in every lane.
    #[test]
    fn a_tiny_tmin_still_bounds_the_hits() {
        let floor = tri();
        let dir = Vec3::new(0.0, 0.0, 1.0);
        let rays4 = |o: Vec3, tmin: f32| {
            let r = RayPre::new(o, dir).unwrap();
            let lanes = RayPre4::from_lanes(
                r.kz,
                [o.x, o.y, o.z].map(Vec4::splat),
                [r.sx, r.sy, r.sz].map(Vec4::splat),
            );
            (
                intersect(&r, &floor, tmin, f32::INFINITY).map(|h| h.t),
                intersect4_along_any_in(&r, [&floor; 4], tmin).hit,
                intersect_rays4_along::<2>(&lanes, &floor, [tmin; 4], [f32::INFINITY; 4]).hit,
            )
        };
        // On the triangle: t = 0, outside [MIN_POSITIVE, ∞).
        let on = Vec3::new(0.25, 0.25, 0.0);
        assert_eq!(rays4(on, f32::MIN_POSITIVE), (None, [false; 4], [false; 4]));
        assert_eq!(rays4(on, 0.0).0, Some(0.0));
        // 1e-30 below it: t = 1e-30, inside [MIN_POSITIVE, ∞) and outside [2e-30, ∞).
        let below = Vec3::new(0.25, 0.25, -1e-30);
        assert_eq!(
            rays4(below, f32::MIN_POSITIVE),
            (Some(1e-30), [true; 4], [true; 4])
        );
        assert_eq!(rays4(below, 2e-30), (None, [false; 4], [false; 4]));
        assert_eq!(scaled_tmin(f32::MIN_POSITIVE), 0.0);
        assert_eq!(scaled_tmin(1e-10), 1e-10);
        assert_eq!(scaled_tmin(-1e-30), -1e-30);
    }

    fn intersect4_along_any_in(r: &RayPre, tri: [&[[f32; 3]; 3]; 4], tmin: f32) -> Hits4 {
        match r.kz {
            0 => intersect4_along::<0>(r, tri, tmin, f32::INFINITY),
            1 => intersect4_along::<1>(r, tri, tmin, f32::INFINITY),
            _ => intersect4_along::<2>(r, tri, tmin, f32::INFINITY),
        }
    }

    fn intersect4_along_any(r: &RayPre, tri: [&[[f32; 3]; 3]; 4]) -> Hits4 {
        match r.kz {
            0 => intersect4_along::<0>(r, tri, f32::MIN_POSITIVE, f32::INFINITY),
            1 => intersect4_along::<1>(r, tri, f32::MIN_POSITIVE, f32::INFINITY),
            _ => intersect4_along::<2>(r, tri, f32::MIN_POSITIVE, f32::INFINITY),
        }
    }
}
