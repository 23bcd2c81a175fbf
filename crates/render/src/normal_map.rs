//! Tangent-space normal maps, as Unity's Standard and Lit shaders apply them.
//!
//! A texel's red and green channels hold the bent normal's components along the surface's
//! tangent (the direction in which the mesh's u grows) and bitangent (v grows) as
//! `2·c − 1`, scaled by the material's bump scale; the component along the normal follows
//! from them, `√(1 − x² − y²)`, as Unity unpacks its compressed normal maps (the blue
//! channel is not read). The tangent comes from the mesh's MikkTSpace tangents, as Unity's
//! model importer makes them ([`crate::tangents`]), or, where those give none, from the
//! triangle's own `∂p/∂u` ([`triangle_tangent`]); either is made orthonormal to the
//! interpolated normal at the hit, and the bitangent is `sign · n × t`, as Unity's shaders
//! build it. Both are geometric directions, so the converter's mirroring of Unity's
//! left-handed space changes nothing here: a map that tilts the normal towards increasing u
//! does so in the soup as it does in Unity.

use glam::{Vec2, Vec3, Vec4};

/// A surface's tangent frame before it meets the shading normal `n`: `t` points where u
/// grows, and `sign · n × t` where v grows (±1: a mirrored UV layout turns it).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tangent {
    pub t: Vec3,
    pub sign: f32,
}

/// The frame of a triangle with corners `p` and mesh UVs `uv` alone, seen with normal `n`:
/// `∂p/∂u` and the sign that turns `n × ∂p/∂u` towards `∂p/∂v`. None where the UVs do not
/// span the triangle's plane (degenerate or all equal), so a map has no direction there.
pub fn triangle_tangent(n: Vec3, p: [Vec3; 3], uv: [Vec2; 3]) -> Option<Tangent> {
    let (dp1, dp2) = (p[1] - p[0], p[2] - p[0]);
    let (du1, du2) = (uv[1] - uv[0], uv[2] - uv[0]);
    let det = du1.x * du2.y - du2.x * du1.y;
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    // ∂p/∂u and ∂p/∂v scaled by det, whose sign keeps their directions.
    let s = det.signum();
    let dpdu = (dp1 * du2.y - dp2 * du1.y) * s;
    let dpdv = (dp2 * du1.x - dp1 * du2.x) * s;
    let side = n.cross(dpdu).dot(dpdv);
    (side != 0.0 && side.is_finite()).then_some(Tangent {
        t: dpdu,
        sign: side.signum(),
    })
}

/// The unit shading normal `n` bent by normal-map texel `texel` (linear, 0–1) at scale
/// `scale` in the frame `tangent`; `n` itself where the tangent is parallel to `n`, so the
/// map has no direction there.
pub fn bend(n: Vec3, tangent: Tangent, texel: Vec4, scale: f32) -> Vec3 {
    let t = (tangent.t - n * n.dot(tangent.t)).normalize_or_zero();
    if t == Vec3::ZERO {
        return n;
    }
    let b = n.cross(t) * tangent.sign;
    let x = (texel.x * 2.0 - 1.0) * scale;
    let y = (texel.y * 2.0 - 1.0) * scale;
    let z = (1.0 - (x * x + y * y).min(1.0)).sqrt();
    let bent = (t * x + b * y + n * z).normalize_or_zero();
    if bent == Vec3::ZERO || !bent.is_finite() {
        n
    } else {
        bent
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit square in the xz plane facing +y, u along +x, v along −z.
    fn square() -> ([Vec3; 3], [Vec2; 3]) {
        (
            [Vec3::ZERO, Vec3::X, Vec3::NEG_Z],
            [Vec2::ZERO, Vec2::X, Vec2::Y],
        )
    }

    /// `n` bent in the triangle's own frame.
    fn bend_on(n: Vec3, p: [Vec3; 3], uv: [Vec2; 3], texel: Vec4, scale: f32) -> Vec3 {
        triangle_tangent(n, p, uv).map_or(n, |f| bend(n, f, texel, scale))
    }

    /// The texel that encodes tangent-space (x, y) with z from them.
    fn texel(x: f32, y: f32) -> Vec4 {
        Vec4::new(x * 0.5 + 0.5, y * 0.5 + 0.5, 1.0, 1.0)
    }

    #[test]
    fn the_flat_texel_keeps_the_normal() {
        let (p, uv) = square();
        assert_eq!(bend_on(Vec3::Y, p, uv, texel(0.0, 0.0), 1.0), Vec3::Y);
    }

    #[test]
    fn red_tilts_towards_u_and_green_towards_v() {
        let (p, uv) = square();
        let (s, c) = (0.6f32, 0.8f32);
        let u = bend_on(Vec3::Y, p, uv, texel(s, 0.0), 1.0);
        assert!((u - Vec3::new(s, c, 0.0)).length() < 1e-6, "{u}");
        let v = bend_on(Vec3::Y, p, uv, texel(0.0, s), 1.0);
        assert!((v - Vec3::new(0.0, c, -s)).length() < 1e-6, "{v}");
    }

    #[test]
    fn mirrored_uvs_and_either_winding_follow_the_uvs() {
        let (p, uv) = square();
        // The same triangle wound the other way round: the map still tilts along +u.
        let q = [p[0], p[2], p[1]];
        let w = [uv[0], uv[2], uv[1]];
        let a = bend_on(Vec3::Y, q, w, texel(0.6, 0.0), 1.0);
        assert!((a - Vec3::new(0.6, 0.8, 0.0)).length() < 1e-6, "{a}");
        // u running along −x: the tilt follows it.
        let m = [Vec2::ZERO, Vec2::NEG_X, Vec2::Y];
        let b = bend_on(Vec3::Y, p, m, texel(0.6, 0.0), 1.0);
        assert!((b - Vec3::new(-0.6, 0.8, 0.0)).length() < 1e-6, "{b}");
    }

    #[test]
    fn scale_multiplies_the_tilt_and_saturates() {
        let (p, uv) = square();
        let half = bend_on(Vec3::Y, p, uv, texel(0.6, 0.0), 0.5);
        let z = (1.0f32 - 0.09).sqrt();
        assert!((half - Vec3::new(0.3, z, 0.0)).length() < 1e-6, "{half}");
        // x² + y² past 1: z is 0 and the normal lies in the surface, still unit.
        let flat = bend_on(Vec3::Y, p, uv, texel(1.0, 1.0), 2.0);
        let d = std::f32::consts::FRAC_1_SQRT_2;
        assert!((flat - Vec3::new(d, 0.0, -d)).length() < 1e-6, "{flat}");
    }

    #[test]
    fn the_frame_is_made_orthonormal_to_the_shading_normal() {
        let (p, uv) = square();
        let n = Vec3::new(0.0, 1.0, 1.0).normalize();
        let b = bend_on(n, p, uv, texel(0.0, 0.0), 1.0);
        assert!((b - n).length() < 1e-6);
        let t = bend_on(n, p, uv, texel(0.6, 0.0), 1.0);
        assert!((t.length() - 1.0).abs() < 1e-6 && (t.dot(Vec3::X) - 0.6).abs() < 1e-6);
    }

    #[test]
    fn uvs_without_a_direction_keep_the_normal() {
        let (p, _) = square();
        for uv in [[Vec2::ONE; 3], [Vec2::ZERO, Vec2::X, Vec2::X * 2.0]] {
            assert_eq!(bend_on(Vec3::Y, p, uv, texel(0.6, 0.0), 1.0), Vec3::Y);
        }
        let nan = [Vec2::ZERO, Vec2::X, Vec2::new(f32::NAN, 1.0)];
        assert_eq!(bend_on(Vec3::Y, p, nan, texel(0.6, 0.0), 1.0), Vec3::Y);
    }
}
