//! Light (class 108) → soup light: kind, colour, intensity, range, shadows, placed by
//! the GameObject's world transform.

use crate::docs;
use crate::emit::{enabled, flip, EmitError, Emitter};
use crate::material::{gamma_to_linear, srgb_to_linear};
use crate::project::{Pipeline, Project};
use crate::quality::ShadowQuality;
use crate::yaml::Node;
use formats::{Attenuation, Light, LightKind, Shadows};
use glam::{Mat4, Vec3, Vec4Swizzles};

/// Unity's `m_Type` of a directional light (its shadow softness is an angle).
const DIRECTIONAL: i64 = 1;

/// How a project turns a light's colour, intensity and colour temperature into the light
/// it casts: GraphicsSettings' `lightsUseLinearIntensity` and `lightsUseColorTemperature`.
/// Both are off in a built-in project unless its settings turn them on; URP and HDRP
/// switch both on whenever they render (URP's intensity follows the colour space, which
/// is linear here).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LightUnits {
    /// Intensity multiplies the linear colour; off, it multiplies the gamma-encoded colour
    /// and the product is decoded, so an intensity of 2 lights 2^2.2 ≈ 4.6 times as much.
    pub linear_intensity: bool,
    /// A light's `m_UseColorTemperature` tints it by its `m_ColorTemperature` (only
    /// with linear intensity, as Unity applies it).
    pub color_temperature: bool,
}

impl LightUnits {
    /// The units of a project drawn by `pipeline` whose
    /// `ProjectSettings/GraphicsSettings.asset` holds `graphics_settings` (`None` when the
    /// file is absent: Unity's defaults).
    pub fn of(pipeline: Pipeline, graphics_settings: Option<&str>) -> LightUnits {
        if pipeline != Pipeline::BuiltIn {
            return LightUnits {
                linear_intensity: true,
                color_temperature: true,
            };
        }
        let body = graphics_settings.and_then(|text| {
            docs::split(text)
                .into_iter()
                .find(|d| d.class == docs::GRAPHICS_SETTINGS)
                .map(|d| d.parse())
        });
        let on = |key: &str| body.as_ref().and_then(|b| b.i64_at(key)) == Some(1);
        LightUnits {
            linear_intensity: on("m_LightsUseLinearIntensity"),
            color_temperature: on("m_LightsUseColorTemperature"),
        }
    }

    /// The linear colour and intensity of a light whose inspector shows `gamma` (the
    /// stored colour), `intensity` and, where it uses one, a colour `temperature` in
    /// kelvin. The soup keeps the intensity of a white light and the colour as each
    /// channel's share of it, so the product is Unity's final light colour.
    pub fn light(self, gamma: Vec3, intensity: f32, temperature: Option<f32>) -> (Vec3, f32) {
        if !self.linear_intensity {
            let white = gamma_to_linear(intensity);
            if !(white.is_normal() && white > 0.0) {
                return (gamma.map(srgb_to_linear), intensity);
            }
            return ((gamma * intensity).map(gamma_to_linear) / white, white);
        }
        let tint = match temperature {
            Some(kelvin) if self.color_temperature => temperature_rgb(kelvin),
            _ => Vec3::ONE,
        };
        (gamma.map(srgb_to_linear) * tint, intensity)
    }
}

/// Unity's linear RGB of a black body at `kelvin` (clamped to 1,000–40,000 K), white near
/// 6,570 K: its rational curve fit to the Planckian locus, within 0.008.
pub fn temperature_rgb(kelvin: f32) -> Vec3 {
    let k = kelvin.clamp(1000.0, 40000.0) / 1000.0;
    let k2 = k * k;
    let unit = |x: f32| x.clamp(0.0, 1.0);
    // The fit's pieces meet at 6,570 K, where blue still takes the warm piece.
    let r = if k < 6.57 {
        1.0
    } else {
        unit((1.35651 + 0.216422 * k + 0.000633715 * k2) / (-3.24223 + 0.918711 * k))
    };
    let g = if k < 6.57 {
        unit((-399.809 + 414.271 * k + 111.543 * k2) / (2779.24 + 164.143 * k + 84.7356 * k2))
    } else {
        unit((1370.38 + 734.616 * k + 0.689955 * k2) / (-4625.69 + 1699.87 * k))
    };
    let b = if k > 6.57 {
        1.0
    } else {
        unit((348.963 - 523.53 * k + 183.62 * k2) / (2848.82 - 214.52 * k + 78.8614 * k2))
    };
    Vec3::new(r, g, b)
}

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
    project: &Project,
    name: String,
) -> Option<(Light, Option<String>)> {
    let pipeline = project.pipeline;
    let directional = b.i64_at("m_Type").unwrap_or(2) == DIRECTIONAL;
    let angle = b.f32_at("m_SpotAngle").unwrap_or(30.0);
    let gamma = b
        .get("m_Color")
        .and_then(Node::color)
        .map_or(Vec3::ONE, |c| c.xyz());
    let temperature = (b.i64_at("m_UseColorTemperature") == Some(1))
        .then(|| b.f32_at("m_ColorTemperature").unwrap_or(6570.0));
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
    let shadows = match (project.shadow_quality, shadows) {
        (ShadowQuality::Disable, _) => Shadows::None,
        (ShadowQuality::HardOnly, Shadows::Soft) => Shadows::Hard,
        (_, asked) => asked,
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
    let (color, intensity) = project.light_units.light(gamma, intensity, temperature);
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
        let Some((light, note)) = convert(&o.body, kind, world, g.project, self.path(go)) else {
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

#[cfg(test)]
mod tests {
    use super::*;

    const GAMMA: LightUnits = LightUnits {
        linear_intensity: false,
        color_temperature: false,
    };
    const LINEAR: LightUnits = LightUnits {
        linear_intensity: true,
        color_temperature: true,
    };

    #[test]
    fn temperature_is_warm_below_the_pivot_and_cool_above() {
        let candle = temperature_rgb(1800.0);
        assert_eq!(candle.x, 1.0);
        assert!(candle.y < 0.5 && candle.z < 0.1, "{candle}");
        let sky = temperature_rgb(12000.0);
        assert_eq!(sky.z, 1.0);
        assert!(sky.x < 0.8 && sky.y < 0.9, "{sky}");
        // The two pieces of the fit meet at 6,570 K within its error.
        let (below, above) = (temperature_rgb(6569.0), temperature_rgb(6571.0));
        assert!(
            (below - above).abs().max_element() < 0.008,
            "{below} {above}"
        );
        // Blue rises towards the pivot (from 1,100 K: the fit wobbles at its cold end),
        // red falls beyond it.
        let blues: Vec<f32> = (11..=65)
            .map(|h| temperature_rgb(h as f32 * 100.0).z)
            .collect();
        assert!(blues.windows(2).all(|w| w[0] <= w[1]), "{blues:?}");
        let reds: Vec<f32> = (66..=400)
            .map(|h| temperature_rgb(h as f32 * 100.0).x)
            .collect();
        assert!(reds.windows(2).all(|w| w[0] >= w[1]), "{reds:?}");
        // Outside 1,000–40,000 K the ends hold.
        assert_eq!(temperature_rgb(100.0), temperature_rgb(1000.0));
        assert_eq!(temperature_rgb(1e9), temperature_rgb(40000.0));
    }

    #[test]
    fn gamma_intensity_decodes_the_product() {
        let orange = Vec3::new(1.0, 0.5, 0.0);
        // At intensity 1 both conventions agree.
        let (c, i) = GAMMA.light(orange, 1.0, None);
        let (lc, li) = LINEAR.light(orange, 1.0, None);
        assert!((c * i - lc * li).abs().max_element() < 1e-6);
        // Half intensity darkens by the sRGB curve, not by half.
        let (c, i) = GAMMA.light(Vec3::ONE, 0.5, None);
        assert!((i - 0.21404114).abs() < 1e-6 && c == Vec3::ONE, "{c} {i}");
        // No light at all keeps a finite colour.
        let (c, i) = GAMMA.light(orange, 0.0, None);
        assert_eq!((c, i), (orange.map(srgb_to_linear), 0.0));
        // Temperature tints only linear intensities.
        assert_eq!(GAMMA.light(Vec3::ONE, 1.0, Some(2000.0)).0, Vec3::ONE);
        let (c, _) = LINEAR.light(Vec3::ONE, 1.0, Some(2000.0));
        assert_eq!(c, temperature_rgb(2000.0));
    }

    #[test]
    fn graphics_settings_are_read_for_the_built_in_pipeline_only() {
        let text = "%YAML 1.1\n--- !u!30 &1\nGraphicsSettings:\n  m_LightsUseLinearIntensity: 1\n  m_LightsUseColorTemperature: 0\n";
        let units = LightUnits::of(Pipeline::BuiltIn, Some(text));
        assert!(units.linear_intensity && !units.color_temperature);
        assert_eq!(LightUnits::of(Pipeline::BuiltIn, None), GAMMA);
        for junk in ["", "m_LightsUseLinearIntensity: 1", "--- !u!30 &1\n: : ["] {
            assert_eq!(
                LightUnits::of(Pipeline::BuiltIn, Some(junk)),
                GAMMA,
                "{junk}"
            );
        }
        let off = text.replace(": 1", ": 0");
        for p in [Pipeline::Universal, Pipeline::HighDefinition] {
            assert_eq!(LightUnits::of(p, Some(&off)), LINEAR);
        }
    }
}
