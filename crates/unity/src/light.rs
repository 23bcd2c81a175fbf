//! Light (class 108) → soup light: kind, colour, intensity, range, shadows, placed by
//! the GameObject's world transform.

use crate::emit::{enabled, flip, EmitError, Emitter};
use crate::material::linear_rgb;
use crate::project::Pipeline;
use crate::yaml::Node;
use formats::{Attenuation, Light, LightKind, Shadows};
use glam::{Mat4, Vec3, Vec4Swizzles};

/// Unity's `m_Type` of a directional light (its shadow softness is an angle).
const DIRECTIONAL: i64 = 1;

/// The kind of light a body describes; `Err` with the `m_Type` of an area light, which
/// is not converted.
pub fn kind(b: &Node) -> Result<LightKind, i64> {
    let ty = b.i64_at("m_Type").unwrap_or(2);
    let angle = b.f32_at("m_SpotAngle").unwrap_or(30.0);
    match ty {
        0 => Ok(LightKind::Spot {
            angle,
            inner_angle: b.f32_at("m_InnerSpotAngle").unwrap_or(angle).min(angle),
        }),
        DIRECTIONAL => Ok(LightKind::Directional),
        2 => Ok(LightKind::Point),
        _ => Err(ty),
    }
}

/// The soup light of a body with that kind and world transform, and a note when the
/// intensity was mapped from HDRP's physical units; `None` when a value is NaN,
/// infinite or degenerate.
pub fn convert(
    b: &Node,
    kind: LightKind,
    world: Mat4,
    pipeline: Pipeline,
    name: String,
) -> Option<(Light, Option<String>)> {
    let directional = b.i64_at("m_Type").unwrap_or(2) == DIRECTIONAL;
    let angle = b.f32_at("m_SpotAngle").unwrap_or(30.0);
    let color = b
        .get("m_Color")
        .and_then(Node::color)
        .map(linear_rgb)
        .unwrap_or(Vec3::ONE);
    let mut intensity = b.f32_at("m_Intensity").unwrap_or(1.0);
    let range = b.f32_at("m_Range").unwrap_or(10.0);
    let shadows = match b
        .path(&["m_Shadows", "m_Type"])
        .and_then(Node::as_i64)
        .unwrap_or(0)
    {
        1 => Shadows::Hard,
        2 => Shadows::Soft,
        _ => Shadows::None,
    };
    // Unity's inspector keeps the strength within 0–1.
    let shadow_strength = b
        .path(&["m_Shadows", "m_Strength"])
        .and_then(Node::as_f32)
        .unwrap_or(1.0);
    let shadow_radius = if directional {
        b.f32_at("m_ShadowAngle")
            .filter(|&a| a > 0.0)
            .unwrap_or(1.0)
    } else {
        b.f32_at("m_ShadowRadius")
            .filter(|&r| r > 0.0)
            .unwrap_or(0.1)
    };
    // HDRP stores physical units (lux for the sun, lumen for lamps); the renderer's
    // built-in lighting model wants about 1 for a typical light.
    let mut note = None;
    if pipeline == Pipeline::HighDefinition {
        let div = if directional { 100_000.0 } else { 1_000.0 };
        let mapped = intensity / div;
        note = Some(format!(
            "HDRP project: intensity {intensity} (physical units) mapped to {mapped} (÷{div})"
        ));
        intensity = mapped;
    }
    let position = flip(world.w_axis.xyz());
    let direction = flip(world.transform_vector3(Vec3::Z)).normalize_or_zero();
    let all = [
        color.x,
        color.y,
        color.z,
        intensity,
        range,
        angle,
        shadow_radius,
        shadow_strength,
    ];
    if all.iter().any(|v| !v.is_finite()) || direction == Vec3::ZERO {
        return None;
    }
    let light = Light {
        name,
        kind,
        position,
        direction,
        color,
        intensity,
        range,
        attenuation: match pipeline {
            Pipeline::Universal => Attenuation::Universal,
            Pipeline::BuiltIn | Pipeline::HighDefinition => Attenuation::BuiltIn,
        },
        shadows,
        shadow_radius,
        shadow_strength: shadow_strength.clamp(0.0, 1.0),
        culling_mask: crate::layer::culling_mask(b),
    };
    Some((light, note))
}

impl Emitter<'_, '_> {
    /// Light component `c` of GameObject `go`.
    pub(crate) fn light(&mut self, go: usize, c: usize) -> Result<(), EmitError> {
        let g = self.g;
        let o = &g.objs[c];
        if !enabled(o) {
            return Ok(());
        }
        let what = self.describe(go);
        let kind = match kind(&o.body) {
            Ok(k) => k,
            Err(ty) => {
                self.soup.warnings.push(format!(
                    "{what}: area light (m_Type {ty}) is not converted; skipped"
                ));
                return Ok(());
            }
        };
        let world = self.checked_world(go)?;
        let Some((light, note)) = convert(&o.body, kind, world, g.project.pipeline, self.path(go))
        else {
            let detail = "light has a NaN, infinite or degenerate value".into();
            return Err(self.non_finite(go, detail));
        };
        self.soup
            .warnings
            .extend(note.map(|n| format!("{what}: {n}")));
        self.soup.lights.push(light);
        self.light_ids.push((o.file, o.file_id));
        Ok(())
    }
}
