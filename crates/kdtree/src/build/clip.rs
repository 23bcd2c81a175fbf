//! Perfect splits: the bounds of the part of a triangle inside a cell.
//!
//! The triangle is clipped to the cell in f64 (Sutherland–Hodgman against the six planes)
//! and the bounds of the clipped polygon are rounded outward to f32, then limited to the
//! cell. Rounding outward means the f32 box always contains the true clipped part, so a
//! triangle is never lost from a cell it enters; limiting to the cell keeps a flat cell's
//! triangles flat (a planar event) instead of giving them a sliver of thickness.

use crate::aabb::Aabb;
use glam::Vec3;

/// At most 3 + 6 vertices after clipping a triangle by six planes.
const MAX_POLY: usize = 9;

fn down(x: f64) -> f32 {
    let f = x as f32;
    if f as f64 > x {
        f.next_down()
    } else {
        f
    }
}

fn up(x: f64) -> f32 {
    let f = x as f32;
    if (f as f64) < x {
        f.next_up()
    } else {
        f
    }
}

/// A convex polygon in f64, cut down one plane at a time.
struct Poly {
    v: [[f64; 3]; MAX_POLY],
    n: usize,
}

impl Poly {
    /// Keep the part on one side of the plane `AXIS = plane` (at or above it when `ABOVE`):
    /// false when no vertex is on that side. The axis and side are constants so that each
    /// of the six calls compiles to its own straight comparisons.
    #[inline(always)]
    fn cut<const AXIS: usize, const ABOVE: bool>(&mut self, plane: f64) -> bool {
        let inside = |p: &[f64; 3]| {
            if ABOVE {
                p[AXIS] >= plane
            } else {
                p[AXIS] <= plane
            }
        };
        let n = self.n;
        let v = &self.v;
        // One bit per vertex; most planes cut nothing and are skipped (the polygon is
        // unchanged, same bits).
        let mut mask = 0u32;
        for (i, p) in v[..n].iter().enumerate() {
            mask |= (inside(p) as u32) << i;
        }
        if mask == (1 << n) - 1 {
            return true;
        }
        if mask == 0 {
            return false;
        }
        let mut out = [[0f64; 3]; MAX_POLY];
        let mut m = 0;
        for i in 0..n {
            let a = v[i];
            // The edge to the next vertex, the last closing on the first.
            let j = if i + 1 == n { 0 } else { i + 1 };
            let b = v[j];
            let (ia, ib) = (mask >> i & 1 != 0, mask >> j & 1 != 0);
            if ia {
                out[m] = a;
                m += 1;
            }
            if ia != ib && m < MAX_POLY {
                let s = (plane - a[AXIS]) / (b[AXIS] - a[AXIS]);
                let mut p = [0f64; 3];
                for k in 0..3 {
                    p[k] = a[k] + s * (b[k] - a[k]);
                }
                // The crossing point lies on the plane by construction.
                p[AXIS] = plane;
                out[m] = p;
                m += 1;
            }
        }
        self.v = out;
        self.n = m;
        true
    }
}

/// Bounds of `tri ∩ cell`, or None when the triangle does not reach into the cell.
pub fn clipped_bounds(tri: &[Vec3; 3], cell: &Aabb) -> Option<Aabb> {
    let mut poly = Poly {
        v: [[0f64; 3]; MAX_POLY],
        n: 3,
    };
    for (i, v) in tri.iter().enumerate() {
        poly.v[i] = [v.x as f64, v.y as f64, v.z as f64];
    }
    let (lo, hi) = (cell.lo.map(f64::from), cell.hi.map(f64::from));
    let inside = poly.cut::<0, true>(lo[0])
        && poly.cut::<0, false>(hi[0])
        && poly.cut::<1, true>(lo[1])
        && poly.cut::<1, false>(hi[1])
        && poly.cut::<2, true>(lo[2])
        && poly.cut::<2, false>(hi[2]);
    if !inside {
        return None;
    }
    bounds_in(&poly.v[..poly.n], cell)
}

/// The f32 box of the clipped polygon `poly`, rounded outward and held inside `cell`; None
/// when rounding leaves it empty.
fn bounds_in(poly: &[[f64; 3]], cell: &Aabb) -> Option<Aabb> {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    // Plain comparisons: every coordinate is a number (f64::min and max would also sort
    // out NaN), and which zero wins a tie of −0 and +0 changes no event (positions map
    // both to one key).
    for p in poly {
        for k in 0..3 {
            lo[k] = if p[k] < lo[k] { p[k] } else { lo[k] };
            hi[k] = if p[k] > hi[k] { p[k] } else { hi[k] };
        }
    }
    let mut b = Aabb::EMPTY;
    for k in 0..3 {
        b.lo[k] = down(lo[k]).max(cell.lo[k]);
        b.hi[k] = up(hi[k]).min(cell.hi[k]);
        if b.lo[k] > b.hi[k] {
            return None;
        }
    }
    Some(b)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testkit::Rng;

    fn cell(lo: [f32; 3], hi: [f32; 3]) -> Aabb {
        Aabb { lo, hi }
    }

    #[test]
    fn clipping_shrinks_to_the_part_inside() {
        let t = [
            Vec3::ZERO,
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(0.0, 2.0, 0.0),
        ];
        let b = clipped_bounds(&t, &cell([1.0, -1.0, -1.0], [3.0, 3.0, 1.0])).unwrap();
        assert_eq!(b.lo, [1.0, 0.0, 0.0]);
        assert_eq!(b.hi, [2.0, 1.0, 0.0]);
    }

    #[test]
    fn corner_cell_outside_the_hypotenuse_is_empty() {
        let t = [
            Vec3::ZERO,
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(0.0, 2.0, 0.0),
        ];
        assert!(clipped_bounds(&t, &cell([1.5, 1.5, -1.0], [3.0, 3.0, 1.0])).is_none());
    }

    #[test]
    fn flat_cell_keeps_its_planar_triangle() {
        let t = [
            Vec3::new(0.0, 0.5, 0.0),
            Vec3::new(1.0, 0.5, 0.0),
            Vec3::new(0.0, 0.5, 1.0),
        ];
        let b = clipped_bounds(&t, &cell([0.0, 0.5, 0.0], [0.25, 0.5, 1.0])).unwrap();
        assert_eq!(b.lo, [0.0, 0.5, 0.0]);
        assert_eq!(b.hi, [0.25, 0.5, 1.0]);
    }

    #[test]
    fn bounds_are_rounded_outward() {
        // The hypotenuse crosses x = 0.1 at y = 1.9 - something not representable in f32.
        let t = [
            Vec3::ZERO,
            Vec3::new(3.0, 0.0, 0.0),
            Vec3::new(0.0, 3.0, 0.0),
        ];
        let c = cell([0.1, 0.0, -1.0], [10.0, 10.0, 1.0]);
        let b = clipped_bounds(&t, &c).unwrap();
        let exact_y = 3.0 - 0.1f32 as f64;
        assert!(b.hi[1] as f64 >= exact_y);
        assert!((b.hi[1] as f64 - exact_y) < 1e-6);
    }

    /// The clipper's cuts as first written, one plane after another over a vertex list: the
    /// structure of [`clipped_bounds`] may change, its bits may not. (The box of the result
    /// is the same [`bounds_in`].)
    fn reference(tri: &[Vec3; 3], cell: &Aabb) -> Option<Aabb> {
        let mut poly = [[0f64; 3]; MAX_POLY];
        let mut n = 3;
        for (i, v) in tri.iter().enumerate() {
            poly[i] = [v.x as f64, v.y as f64, v.z as f64];
        }
        let mut next = [[0f64; 3]; MAX_POLY];
        for axis in 0..3 {
            for (plane, keep_above) in [(cell.lo[axis] as f64, true), (cell.hi[axis] as f64, false)]
            {
                let inside = |p: &[f64; 3]| {
                    if keep_above {
                        p[axis] >= plane
                    } else {
                        p[axis] <= plane
                    }
                };
                // Most planes cut nothing: skip them (the polygon is unchanged, same bits).
                let n_inside = poly[..n].iter().filter(|p| inside(p)).count();
                if n_inside == n {
                    continue;
                }
                if n_inside == 0 {
                    return None;
                }
                let mut m = 0;
                for i in 0..n {
                    let a = poly[i];
                    // The edge to the next vertex, the last closing on the first (no division
                    // by a variable `n`).
                    let b = poly[if i + 1 == n { 0 } else { i + 1 }];
                    let (ia, ib) = (inside(&a), inside(&b));
                    if ia {
                        next[m] = a;
                        m += 1;
                    }
                    if ia != ib && m < MAX_POLY {
                        let s = (plane - a[axis]) / (b[axis] - a[axis]);
                        let mut p = [0f64; 3];
                        for k in 0..3 {
                            p[k] = a[k] + s * (b[k] - a[k]);
                        }
                        // The crossing point lies on the plane by construction.
                        p[axis] = plane;
                        next[m] = p;
                        m += 1;
                    }
                }
                n = m;
                poly[..n].copy_from_slice(&next[..n]);
            }
        }
        bounds_in(&poly[..n], cell)
    }

    #[test]
    fn same_bounds_as_the_reference_clipper() {
        let mut rng = Rng(5);
        // Lattice coordinates put vertices on cell planes and make flat cells and
        // triangles; the scales cover rounding far from 1.
        let coord = |rng: &mut Rng, scale: f32| {
            if rng.unit() < 0.3 {
                (rng.range(-4.0, 4.0).round() * 0.5) * scale
            } else {
                rng.range(-2.0, 2.0) * scale
            }
        };
        for case in 0..200_000 {
            let scale = [1.0, 1e-3, 7.3e4, 3e-30][case % 4];
            let t: [Vec3; 3] = std::array::from_fn(|_| {
                Vec3::new(
                    coord(&mut rng, scale),
                    coord(&mut rng, scale),
                    coord(&mut rng, scale),
                )
            });
            let (mut lo, mut hi) = ([0f32; 3], [0f32; 3]);
            for k in 0..3 {
                let (a, b) = (coord(&mut rng, scale), coord(&mut rng, scale));
                (lo[k], hi[k]) = (a.min(b), a.max(b));
            }
            let c = cell(lo, hi);
            let (got, want) = (clipped_bounds(&t, &c), reference(&t, &c));
            let bits =
                |b: Option<Aabb>| b.map(|b| (b.lo.map(f32::to_bits), b.hi.map(f32::to_bits)));
            assert_eq!(bits(got), bits(want), "triangle {t:?}, cell {c:?}");
        }
    }
}
