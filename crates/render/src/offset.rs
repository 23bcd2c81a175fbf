//! Robust spawning of secondary rays (pbrt-v4 §6.8.6, "Robust Spawned Ray Origins").
//!
//! A hit point computed in f32 from barycentrics, p = b0·p0 + b1·p1 + b2·p2, is off the
//! true surface by at most γ₇·(|b0·p0| + |b1·p1| + |b2·p2|) per axis. A new ray leaves from
//! p pushed along the geometric normal just past that error box, then rounded one more
//! ULP away, so that its origin is provably on the intended side of the surface, whatever
//! the scene's scale or distance from the origin — no fixed epsilon anywhere.
//!
//! pbrt-v4 also relies on its intersector rejecting hits closer than a bound on the
//! rounding of t (its `deltaT`). Our intersector does not promise that, so the push also
//! covers it ([`intersector_margin`]): a watertight test translates and shears the
//! triangle relative to the ray origin, which perturbs the triangle's plane by a few ULPs
//! of the triangle's extent, and its barycentric rounding grows with the triangle's
//! aspect (longest edge² / area). That margin scales with the triangle, not the scene.
//! A spawned ray's interval starts at the smallest normal f32 ([`SPAWN_TMIN`]) so that
//! an underflowed t = 0 never counts.

use glam::Vec3;

/// γₙ = n·u / (1 − n·u) with u = 2⁻²⁴ (f32 unit roundoff), Higham's error bound factor.
pub const fn gamma(n: i32) -> f32 {
    let u = f32::EPSILON * 0.5;
    (n as f32 * u) / (1.0 - n as f32 * u)
}

/// The hit point on triangle `tri` at barycentrics (u, v) and its per-axis error bound.
pub fn hit_point(tri: &[Vec3; 3], u: f32, v: f32) -> (Vec3, Vec3) {
    let b0 = 1.0 - u - v;
    let (a, b, c) = (tri[0] * b0, tri[1] * u, tri[2] * v);
    let p = a + b + c;
    let err = (a.abs() + b.abs() + c.abs()) * gamma(7);
    (p, err)
}

/// Distance along the normal that covers the intersector's rounding for rays leaving
/// triangle `tri`: γ₁₂ · L · clamp(L² / 2A, 1, 10⁴), with L the longest edge and A the area.
pub fn intersector_margin(tri: &[Vec3; 3]) -> f32 {
    let e0 = tri[1] - tri[0];
    let e1 = tri[2] - tri[1];
    let e2 = tri[0] - tri[2];
    let l2 = e0
        .length_squared()
        .max(e1.length_squared())
        .max(e2.length_squared());
    let twice_area = e0.cross(-e2).length();
    let aspect = if twice_area > 0.0 {
        (l2 / twice_area).clamp(1.0, 1e4)
    } else {
        1e4
    };
    let m = gamma(12) * l2.sqrt() * aspect;
    if m.is_finite() {
        m
    } else {
        0.0
    }
}

/// Next representable f32 towards +∞ (`f32::next_up` needs Rust 1.86; we support 1.85).
pub fn next_up(x: f32) -> f32 {
    if x.is_infinite() && x > 0.0 || x.is_nan() {
        return x;
    }
    if x == 0.0 {
        return f32::from_bits(1);
    }
    let bits = x.to_bits();
    f32::from_bits(if x > 0.0 { bits + 1 } else { bits - 1 })
}

/// Next representable f32 towards −∞.
pub fn next_down(x: f32) -> f32 {
    -next_up(-x)
}

/// Origin for a ray leaving point `p` (error bound `err`, intersector margin `margin`)
/// in direction `w`, on the side of the surface with unit geometric normal `ng` that `w`
/// points to.
pub fn offset_origin(p: Vec3, err: Vec3, margin: f32, ng: Vec3, w: Vec3) -> Vec3 {
    let side = if w.dot(ng) < 0.0 { -ng } else { ng };
    let off = side * (side.abs().dot(err) + margin);
    let mut po = (p + off).to_array();
    // One more ULP away from the surface on every axis the normal has a component along,
    // also when the error bound is 0 (an exactly representable point on an axis-aligned
    // plane): a ray must never start exactly on the surface it leaves.
    // A coordinate stepped off an exact 0 would be a denormal, and products of denormals
    // underflow to 0 inside the intersector (a "hit" at t = 0): step to the smallest
    // normal float instead, still ~10⁻³⁸ from the surface.
    let side = side.to_array();
    for i in 0..3 {
        if side[i] > 0.0 {
            po[i] = next_up(po[i]);
            if po[i] > 0.0 && po[i] < f32::MIN_POSITIVE {
                po[i] = f32::MIN_POSITIVE;
            }
        } else if side[i] < 0.0 {
            po[i] = next_down(po[i]);
            if po[i] < 0.0 && po[i] > -f32::MIN_POSITIVE {
                po[i] = -f32::MIN_POSITIVE;
            }
        }
    }
    Vec3::from_array(po)
}

/// `tmin` of every spawned ray: the smallest normal f32. It only excludes t = 0 and
/// denormal distances, which a ray leaving an offset origin can reach only through
/// underflow inside the intersector (whose interval is closed at tmin); it is no
/// epsilon in the geometric sense — the offset above keeps real surfaces away.
pub const SPAWN_TMIN: f32 = f32::MIN_POSITIVE;

/// Fraction of the distance to a light that a shadow ray may travel: it stops short of
/// the light by a relative margin so that geometry at the light itself does not count.
pub const SHADOW_TMAX_FRACTION: f32 = 1.0 - 1e-4;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_margin_scales_with_the_triangle_and_its_aspect() {
        let t = |s: f32, h: f32| [Vec3::ZERO, Vec3::new(s, 0.0, 0.0), Vec3::new(0.0, 0.0, h)];
        let m1 = intersector_margin(&t(1.0, 1.0));
        assert!((intersector_margin(&t(1000.0, 1000.0)) / m1 - 1000.0).abs() < 1.0);
        // A needle (aspect 1000) needs a larger push than a well-shaped triangle.
        assert!(intersector_margin(&t(1.0, 1e-3)) > m1 * 100.0);
        assert!(m1 < 1e-5);
    }

    #[test]
    fn next_up_and_down_step_one_ulp() {
        assert_eq!(next_up(1.0), 1.0 + f32::EPSILON);
        assert_eq!(next_down(1.0), 1.0 - f32::EPSILON / 2.0);
        assert_eq!(next_up(0.0), f32::from_bits(1));
        assert_eq!(next_up(-0.0), f32::from_bits(1));
        assert_eq!(next_up(-1.0), -(1.0 - f32::EPSILON / 2.0));
    }

    #[test]
    fn offset_grows_with_distance_from_the_origin() {
        for scale in [1e-3f32, 1.0, 1e5] {
            let tri = [
                Vec3::new(scale, 0.0, 0.0),
                Vec3::new(scale + 1.0, 0.0, 0.0),
                Vec3::new(scale, 0.0, 1.0),
            ];
            let (p, err) = hit_point(&tri, 0.25, 0.25);
            let m = intersector_margin(&tri);
            let o = offset_origin(p, err, m, Vec3::Y, Vec3::Y);
            assert!(
                o.y > 0.0,
                "origin must leave the plane y = 0 at scale {scale}"
            );
            // The push is of the order of the rounding error, not a fixed epsilon.
            assert!(o.y < scale.max(1.0) * 1e-5, "{} at {scale}", o.y);
            let below = offset_origin(p, err, m, Vec3::Y, -Vec3::Y);
            assert!(below.y < 0.0);
        }
    }
}
