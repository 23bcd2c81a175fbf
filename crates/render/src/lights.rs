//! Light falloff and cones: what each light delivers at a point before visibility, by the
//! formulas of the light's render pipeline ([`Attenuation`]).

use formats::{Attenuation, Light, LightKind};
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

/// The Universal Render Pipeline's range attenuation for point and spot lights (its
/// shader library's `DistanceAttenuation`, with the constants its C# side passes):
///
/// ```text
/// falloff(d) = 1 / max(d², 2⁻¹⁴) · (1 − (d² / max(range², 10⁻⁴))²)²   for d < range
///            = 0                                                      for d ≥ range
/// ```
///
/// The inverse square law, smoothed to reach zero at `range` (the smoothing Unity's
/// lightmapper uses); 2⁻¹⁴ is the smallest normal half float, URP's bound on d² near the
/// light. A non-positive range lights nothing.
pub fn inverse_square_falloff(d: f32, range: f32) -> f32 {
    if range.is_nan() || range <= 0.0 || d.is_nan() || d >= range {
        return 0.0;
    }
    let d2 = d * d;
    let factor = d2 / (range * range).max(1e-4);
    let smooth = (1.0 - factor * factor).clamp(0.0, 1.0);
    smooth * smooth / d2.max(HALF_MIN)
}

/// The smallest normal half float: URP's lower bound on a squared distance.
const HALF_MIN: f32 = 6.103_515_6e-5;

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

/// The Universal Render Pipeline's spot cone (`AngleAttenuation`): the square of a
/// linear ramp on cos θ from cos(angle/2), where it is 0, to cos(inner_angle/2), where it
/// reaches 1; angles as in [`spot_cone`]. URP keeps the ramp at least 0.001 wide in cos θ,
/// so an inner angle equal to the cone's is all but a hard edge there too.
pub fn spot_cone_universal(cos_theta: f32, angle: f32, inner_angle: f32) -> f32 {
    if angle <= 0.0 {
        return 0.0;
    }
    let cos_outer = (angle.to_radians() * 0.5).cos();
    let cos_inner = (inner_angle.clamp(0.0, angle).to_radians() * 0.5).cos();
    let inv_range = 1.0 / (cos_inner - cos_outer).max(0.001);
    let t = ((cos_theta - cos_outer) * inv_range).clamp(0.0, 1.0);
    t * t
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
/// outside the cone, black or zero intensity): such points need no shadow ray. Inlined
/// into the shading of four points: left to the compiler, it stopped inlining it once the
/// shaded point's record grew by one field, and a six-light scene traced 20 % slower.
#[inline(always)]
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
            let mut k = match light.attenuation {
                Attenuation::BuiltIn => range_falloff(dist, light.range),
                Attenuation::Universal => inverse_square_falloff(dist, light.range),
            };
            if let LightKind::Spot { angle, inner_angle } = light.kind {
                let cos = (-dir).dot(light.direction.normalize_or_zero());
                k *= match light.attenuation {
                    Attenuation::BuiltIn => spot_cone(cos, angle, inner_angle),
                    Attenuation::Universal => spot_cone_universal(cos, angle, inner_angle),
                };
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
    fn universal_falloff_is_the_inverse_square_smoothed_to_the_range() {
        let smooth = |d: f32, r: f32| (1.0 - (d * d / (r * r)).powi(2)).powi(2);
        assert_eq!(inverse_square_falloff(1.0, 10.0), smooth(1.0, 10.0));
        for d in [0.5f32, 2.0, 5.0, 9.0] {
            let want = smooth(d, 10.0) / (d * d);
            let got = inverse_square_falloff(d, 10.0);
            assert!((got - want).abs() <= want * 1e-6, "{d}: {got} vs {want}");
        }
        // Twice as far, a quarter of the light, while the smoothing is still near 1.
        let ratio = inverse_square_falloff(0.2, 100.0) / inverse_square_falloff(0.1, 100.0);
        assert!((ratio - 0.25).abs() < 1e-5, "{ratio}");
        // Bounded at the light itself, zero from the range on, nothing without a range.
        assert_eq!(inverse_square_falloff(0.0, 10.0), 1.0 / HALF_MIN);
        assert_eq!(inverse_square_falloff(10.0, 10.0), 0.0);
        assert_eq!(inverse_square_falloff(11.0, 10.0), 0.0);
        assert_eq!(inverse_square_falloff(1.0, 0.0), 0.0);
        assert_eq!(inverse_square_falloff(f32::NAN, 10.0), 0.0);
    }

    #[test]
    fn universal_spot_cone_squares_a_linear_ramp() {
        let c = |deg: f32| deg.to_radians().cos();
        assert_eq!(spot_cone_universal(c(19.0), 60.0, 40.0), 1.0);
        assert_eq!(spot_cone_universal(c(31.0), 60.0, 40.0), 0.0);
        let t = (c(25.0) - c(30.0)) / (c(20.0) - c(30.0));
        assert!((spot_cone_universal(c(25.0), 60.0, 40.0) - t * t).abs() < 1e-6);
        // An inner angle equal to the cone's: a ramp 0.001 wide in cos θ (a tenth of a degree
        // here), all but a hard edge.
        assert_eq!(spot_cone_universal(c(29.0), 60.0, 60.0), 1.0);
        assert_eq!(spot_cone_universal(c(30.1), 60.0, 60.0), 0.0);
        assert_eq!(spot_cone_universal(1.0, 0.0, 0.0), 0.0);
    }

    #[test]
    fn each_light_takes_its_pipelines_formulas() {
        let light = |attenuation, kind| Light {
            name: "l".into(),
            kind,
            position: Vec3::new(0.0, 4.0, 0.0),
            direction: -Vec3::Y,
            color: Vec3::ONE,
            intensity: 2.0,
            range: 10.0,
            attenuation,
            shadows: formats::Shadows::None,
            shadow_radius: 0.0,
            shadow_strength: 1.0,
            culling_mask: u32::MAX,
        };
        let p = Vec3::new(3.0, 0.0, 0.0); // 5 m from the light, 36.87° off the spot's axis
        let cos = 0.8f32;
        let spot = LightKind::Spot {
            angle: 90.0,
            inner_angle: 60.0,
        };
        let at = |a, k| incident(&light(a, k), p).map_or(0.0, |i| i.radiance.x);
        assert_eq!(
            at(Attenuation::BuiltIn, LightKind::Point),
            2.0 * range_falloff(5.0, 10.0)
        );
        assert_eq!(
            at(Attenuation::Universal, LightKind::Point),
            2.0 * inverse_square_falloff(5.0, 10.0)
        );
        assert_eq!(
            at(Attenuation::BuiltIn, spot),
            2.0 * range_falloff(5.0, 10.0) * spot_cone(cos, 90.0, 60.0)
        );
        assert_eq!(
            at(Attenuation::Universal, spot),
            2.0 * inverse_square_falloff(5.0, 10.0) * spot_cone_universal(cos, 90.0, 60.0)
        );
        // The two cones differ between their edges: a smoothstep against a squared ramp.
        assert_ne!(
            spot_cone(cos, 90.0, 60.0),
            spot_cone_universal(cos, 90.0, 60.0)
        );
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
