//! Robust spawning of secondary rays (pbrt-v4 §6.8.6, "Robust Spawned Ray Origins").
//!
//! A hit point computed in f32 from barycentrics, p = b0·p0 + b1·p1 + b2·p2, is off the
//! true surface by at most γ₇·(|b0·p0| + |b1·p1| + |b2·p2|) per axis. A new ray leaves from
//! p pushed along the geometric normal just past that error box, then rounded one more
//! ULP away, so it can never re-hit the surface it left, whatever the scene's scale or
//! distance from the origin — no fixed epsilon anywhere.

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

/// Origin for a ray leaving point `p` (error bound `err`) in direction `w`, on the side
/// of the surface with geometric normal `ng` that `w` points to.
pub fn offset_origin(p: Vec3, err: Vec3, ng: Vec3, w: Vec3) -> Vec3 {
    let side = if w.dot(ng) < 0.0 { -ng } else { ng };
    let off = side * side.abs().dot(err);
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
            let o = offset_origin(p, err, Vec3::Y, Vec3::Y);
            assert!(
                o.y > 0.0,
                "origin must leave the plane y = 0 at scale {scale}"
            );
            // The push is of the order of the rounding error, not a fixed epsilon.
            assert!(o.y < scale.max(1.0) * 1e-5, "{} at {scale}", o.y);
            let below = offset_origin(p, err, Vec3::Y, -Vec3::Y);
            assert!(below.y < 0.0);
        }
    }
}
