//! Light falloff and cones: what each light delivers at a point before visibility.

use formats::{Light, LightKind};
use glam::Vec3;

/// Unity built-in pipeline range attenuation for point and spot lights.
///
/// With x = d / range:
///
/// ```text
/// falloff(d) = 1 / (1 + 25·x²) · fade(x)
/// fade(x)    = 1                  for x ≤ 0.8
///            = (1 − x) / 0.2      for 0.8 < x < 1
///            = 0                  for x ≥ 1
/// ```
///
/// The quadratic term is Unity's approximation of its attenuation texture; the linear
/// fade over the last fifth of the range makes the light reach exactly zero at `range`,
/// so a point beyond range needs no shadow ray. A non-positive range lights nothing.
pub fn range_falloff(d: f32, range: f32) -> f32 {
    if range.is_nan() || range <= 0.0 || d.is_nan() {
        return 0.0;
    }
    let x = d / range;
    if x >= 1.0 {
        return 0.0;
    }
    let fade = if x <= 0.8 { 1.0 } else { (1.0 - x) / 0.2 };
    fade / (1.0 + 25.0 * x * x)
}

/// Spot cone factor for a direction at angle θ from the spot's axis, given cos θ.
///
/// `angle` is the full cone angle and `inner_angle` the full angle of the fully lit
/// core, both in degrees. Outside angle/2: 0. Inside inner_angle/2: 1. Between: a
/// smoothstep on cos θ from cos(angle/2) to cos(inner_angle/2). `inner_angle ≥ angle`
/// means a hard edge exactly at angle/2.
pub fn spot_cone(cos_theta: f32, angle: f32, inner_angle: f32) -> f32 {
    let cos_outer = (angle.to_radians() * 0.5).cos();
    if cos_theta < cos_outer || angle <= 0.0 {
        return 0.0;
    }
    if inner_angle >= angle {
        return 1.0;
    }
    let cos_inner = (inner_angle.max(0.0).to_radians() * 0.5).cos();
    let t = ((cos_theta - cos_outer) / (cos_inner - cos_outer)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// What a light sends towards a point, before the cosine, albedo and visibility.
#[derive(Clone, Copy, Debug)]
pub struct Incident {
    /// Unit direction from the point towards the light.
    pub dir: Vec3,
    /// Distance to the light (infinite for directional lights).
    pub dist: f32,
    /// falloff · cone · intensity · colour.
    pub radiance: Vec3,
}

/// The light arriving at `p`, or None where the light delivers nothing (beyond range,
/// outside the cone, black or zero intensity): such points need no shadow ray.
pub fn incident(light: &Light, p: Vec3) -> Option<Incident> {
    let power = light.color * light.intensity;
    if power.max_element() <= 0.0 || !power.is_finite() {
        return None;
    }
    match light.kind {
        LightKind::Directional => {
            let dir = (-light.direction).normalize_or_zero();
            if dir == Vec3::ZERO {
                return None;
            }
            Some(Incident {
                dir,
                dist: f32::INFINITY,
                radiance: power,
            })
        }
        LightKind::Point | LightKind::Spot { .. } => {
            let to = light.position - p;
            let dist = to.length();
            if dist <= 0.0 || !dist.is_finite() {
                return None;
            }
            let dir = to / dist;
            let mut k = range_falloff(dist, light.range);
            if let LightKind::Spot { angle, inner_angle } = light.kind {
                let axis = light.direction.normalize_or_zero();
                k *= spot_cone((-dir).dot(axis), angle, inner_angle);
            }
            if k <= 0.0 {
                return None;
            }
            Some(Incident {
                dir,
                dist,
                radiance: power * k,
            })
        }
    }
}

/// An orthonormal basis (t, b) perpendicular to unit vector `n` (Duff et al. 2017).
pub fn basis(n: Vec3) -> (Vec3, Vec3) {
    let sign = 1.0f32.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (
        Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
        Vec3::new(b, sign + n.y * n.y * a, -n.y),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn falloff_matches_the_documented_formula() {
        assert_eq!(range_falloff(0.0, 10.0), 1.0);
        assert!((range_falloff(5.0, 10.0) - 1.0 / (1.0 + 25.0 * 0.25)).abs() < 1e-7);
        assert!((range_falloff(8.0, 10.0) - 1.0 / (1.0 + 25.0 * 0.64)).abs() < 1e-7);
        let x = 0.9f32;
        let want = (1.0 - x) / 0.2 / (1.0 + 25.0 * x * x);
        assert!((range_falloff(9.0, 10.0) - want).abs() < 1e-6);
        assert_eq!(range_falloff(10.0, 10.0), 0.0);
        assert_eq!(range_falloff(11.0, 10.0), 0.0);
        assert_eq!(range_falloff(1.0, 0.0), 0.0);
    }

    #[test]
    fn spot_cone_edges() {
        let c = |deg: f32| deg.to_radians().cos();
        assert_eq!(spot_cone(c(29.0), 60.0, 60.0), 1.0);
        assert_eq!(spot_cone(c(31.0), 60.0, 60.0), 0.0);
        assert_eq!(spot_cone(c(19.0), 60.0, 40.0), 1.0);
        let mid = spot_cone(c(25.0), 60.0, 40.0);
        assert!(mid > 0.0 && mid < 1.0);
    }

    #[test]
    fn basis_is_orthonormal() {
        for n in [
            Vec3::X,
            Vec3::Y,
            -Vec3::Z,
            Vec3::new(1.0, 2.0, -3.0).normalize(),
        ] {
            let (t, b) = basis(n);
            assert!(t.dot(n).abs() < 1e-6 && b.dot(n).abs() < 1e-6 && t.dot(b).abs() < 1e-6);
            assert!((t.length() - 1.0).abs() < 1e-6 && (b.length() - 1.0).abs() < 1e-6);
        }
    }
}
