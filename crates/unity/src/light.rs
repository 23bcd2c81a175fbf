//! Light (class 108) → soup light: kind, colour, intensity, range, shadows, placed by
//! the GameObject's world transform.

use crate::docs;
use crate::emit::{enabled, flip, EmitError, Emitter};
use crate::material::{gamma_to_linear, srgb_to_linear};
use crate::project::Project;
use crate::quality::ShadowQuality;
use crate::reference::fref;
use crate::settings::Pipeline;
use crate::yaml::Node;
use formats::{Attenuation, ColorSpace, Light, LightKind, ShadowDistance, Shadows};
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
    /// A gamma-space project's shaders take the stored colour times the intensity as it
    /// is.
    pub gamma_space: bool,
}

impl LightUnits {
    /// The units of a project drawn by `pipeline` whose
    /// `ProjectSettings/GraphicsSettings.asset` holds `graphics_settings` (`None` when the
    /// file is absent: Unity's defaults).
    pub fn of(
        pipeline: Pipeline,
        graphics_settings: Option<&str>,
        space: ColorSpace,
    ) -> LightUnits {
        let gamma_space = space == ColorSpace::Gamma;
        if pipeline != Pipeline::BuiltIn {
            return LightUnits {
                linear_intensity: true,
                color_temperature: true,
                gamma_space,
            };
        }
        let body = graphics_settings.and_then(|text| docs::first(text, docs::GRAPHICS_SETTINGS));
        let on = |key: &str| body.as_ref().and_then(|b| b.i64_at(key)) == Some(1);
        LightUnits {
            linear_intensity: on("m_LightsUseLinearIntensity"),
            color_temperature: on("m_LightsUseColorTemperature"),
            gamma_space,
        }
    }

    /// The colour and intensity the project's shaders take (linear, or as stored in a
    /// gamma-space project) from a light whose inspector shows `gamma` (the stored
    /// colour), `intensity` and, where it uses one, a colour `temperature` in kelvin. The
    /// soup keeps the intensity of a white light and the colour as each channel's share
    /// of it, so the product is Unity's final light colour.
    pub fn light(self, gamma: Vec3, intensity: f32, temperature: Option<f32>) -> (Vec3, f32) {
        if self.gamma_space {
            return (gamma, intensity);
        }
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

/// What a URP pipeline asset lets lights do (`UniversalRenderPipelineAsset`'s fields;
/// where a field is missing, the default the asset's class gives it).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UniversalAsset {
    /// `m_MainLightRenderingMode` not Disabled (default Per Pixel): there is a main light.
    pub main_light: bool,
    /// `m_AdditionalLightsRenderingMode` not Disabled (default Per Pixel): lights other
    /// than the main one light anything (per vertex is drawn per pixel here).
    pub additional_lights: bool,
    /// `m_MainLightShadowsSupported` (default on).
    pub main_shadows: bool,
    /// `m_AdditionalLightShadowsSupported`: point and spot lights (default off).
    pub additional_shadows: bool,
    /// `m_SoftShadowsSupported` (default off: soft shadows are drawn hard).
    pub soft_shadows: bool,
    /// `m_ShadowDistance` (default 50 m) and `m_CascadeBorder` (default 0.2): how far from
    /// the camera shadows reach, and the share of that over which they fade out.
    pub shadow_distance: ShadowDistance,
}

impl UniversalAsset {
    /// The settings of a pipeline asset's text; `None` when it holds no URP asset.
    pub fn of_asset(text: &str) -> Option<UniversalAsset> {
        let body = docs::split(text)
            .into_iter()
            .filter(|d| d.class == docs::MONO_BEHAVIOUR)
            .map(|d| d.parse())
            .find(|b| b.get("m_MainLightShadowsSupported").is_some())?;
        let flag = |key: &str, default: bool| body.i64_at(key).map_or(default, |v| v != 0);
        Some(UniversalAsset {
            main_light: flag("m_MainLightRenderingMode", true),
            additional_lights: flag("m_AdditionalLightsRenderingMode", true),
            main_shadows: flag("m_MainLightShadowsSupported", true),
            additional_shadows: flag("m_AdditionalLightShadowsSupported", false),
            soft_shadows: flag("m_SoftShadowsSupported", false),
            shadow_distance: ShadowDistance {
                distance: body
                    .f32_at("m_ShadowDistance")
                    .filter(|d| d.is_finite() && *d >= 0.0)
                    .unwrap_or(50.0),
                border: body
                    .f32_at("m_CascadeBorder")
                    .filter(|b| b.is_finite())
                    .map_or(0.2, |b| b.clamp(0.0, 1.0)),
            },
        })
    }
}

/// What URP's rules left of a scene's lights.
#[derive(Debug, PartialEq, Eq)]
pub struct UniversalLights {
    /// How many lights' shadows the rules changed.
    pub shadows_changed: usize,
    /// Per light, whether URP draws it at all.
    pub drawn: Vec<bool>,
}

/// Applies URP's rules to a URP scene's `lights`. Its main light is the light
/// RenderSettings names (`sun`) when that is directional, else the first of the
/// brightest directional lights by intensity, and of the directional lights only it casts
/// shadows. Where the pipeline asset is known (`asset`): without main-light rendering
/// there is no main light, and every light is an additional one; without additional
/// lights only the main light is drawn; its switches for main-light, additional-light
/// (point, spot) and soft shadows apply.
pub fn universal_rules(
    lights: &mut [Light],
    sun: Option<usize>,
    asset: Option<UniversalAsset>,
) -> UniversalLights {
    let directional = |l: &Light| matches!(l.kind, LightKind::Directional);
    let main = sun
        .filter(|&i| lights.get(i).is_some_and(directional))
        .or_else(|| {
            let mut best: Option<(usize, f32)> = None;
            for (i, l) in lights.iter().enumerate().filter(|(_, l)| directional(l)) {
                if l.intensity > best.map_or(0.0, |b| b.1) {
                    best = Some((i, l.intensity));
                }
            }
            best.map(|b| b.0)
        })
        .filter(|_| asset.is_none_or(|a| a.main_light));
    let mut shadows_changed = 0;
    let mut drawn = Vec::with_capacity(lights.len());
    for (i, l) in lights.iter_mut().enumerate() {
        let is_main = Some(i) == main;
        drawn.push(is_main || asset.is_none_or(|a| a.additional_lights));
        let casts = match (directional(l), asset) {
            (true, _) if !is_main => false,
            (true, Some(a)) => a.main_shadows,
            (false, Some(a)) => a.additional_shadows,
            (_, None) => true,
        };
        let shadows = match l.shadows {
            _ if !casts => Shadows::None,
            Shadows::Soft if asset.is_some_and(|a| !a.soft_shadows) => Shadows::Hard,
            asked => asked,
        };
        if shadows != l.shadows {
            l.shadows = shadows;
            shadows_changed += 1;
        }
    }
    UniversalLights {
        shadows_changed,
        drawn,
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
    let pipeline = project.settings.pipeline;
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
    let shadows = match (project.settings.shadow_quality, shadows) {
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
    let (color, intensity) = project
        .settings
        .light_units
        .light(gamma, intensity, temperature);
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
    /// The index among the soup's lights of the light RenderSettings `rs` names as the
    /// sun (`m_Sun`, a light of the top scene's file).
    pub(crate) fn sun(&self, rs: &Node) -> Option<usize> {
        let sun = fref(rs.get("m_Sun")).0;
        self.light_ids
            .iter()
            .position(|&(file, id)| sun != 0 && file == 0 && id == sun)
    }

    /// URP's rules on the converted lights, said once where they change any.
    pub(crate) fn universal_rules(&mut self) {
        let g = self.g;
        if g.project.settings.pipeline != Pipeline::Universal {
            return;
        }
        let sun = g.render_settings.as_ref().and_then(|rs| self.sun(rs));
        let asset = g.project.settings.universal_asset;
        let out = universal_rules(&mut self.soup.lights, sun, asset);
        let changed = out.shadows_changed;
        if changed > 0 {
            let rules = if asset.is_some() {
                "its main light alone among directional lights, and as its pipeline asset \
                 supports main-light, additional-light and soft shadows"
            } else {
                "its main light alone among directional lights"
            };
            self.soup.warnings.push(format!(
                "{}: URP draws shadows for {rules}: {changed} light(s) traced so",
                self.scene_rel
            ));
        }
        let dropped = out.drawn.iter().filter(|&&d| !d).count();
        if dropped > 0 {
            self.soup.warnings.push(format!(
                "{}: the URP pipeline asset renders no additional lights (or no main light): \
                 {dropped} light(s) not drawn, as in Unity",
                self.scene_rel
            ));
            let mut keep = out.drawn.iter().copied();
            self.soup.lights.retain(|_| keep.next().unwrap_or(true));
            let mut keep = out.drawn.iter().copied();
            self.light_ids.retain(|_| keep.next().unwrap_or(true));
        }
        if !self.camera_shadows {
            self.no_shadows("the camera's Render Shadows is off (URP)".into());
        }
        if let Some(u) = asset {
            self.shadow_distance(u.shadow_distance);
        }
    }

    /// URP's shadow distance, capped by the camera's far plane: none at all where that is
    /// nearer than the near plane (URP then turns shadows off), else the fade the renderer
    /// draws them with.
    fn shadow_distance(&mut self, d: ShadowDistance) {
        if self.soup.lights.iter().all(|l| l.shadows == Shadows::None) {
            return;
        }
        let cam = &self.soup.camera;
        let far = d.far(cam);
        if far > 0.0 && far >= cam.near {
            self.soup.environment.shadow_distance = Some(d);
            return;
        }
        let why = format!(
            "the URP pipeline asset's shadow distance ({} m) is nearer than the camera's \
             near plane ({} m)",
            d.distance, cam.near
        );
        self.no_shadows(why);
    }

    /// No light casts a shadow, because `why`; said where some light would have.
    fn no_shadows(&mut self, why: String) {
        if self.soup.lights.iter().all(|l| l.shadows == Shadows::None) {
            return;
        }
        for l in &mut self.soup.lights {
            l.shadows = Shadows::None;
        }
        self.soup.warnings.push(format!(
            "{}: {why}: no shadows, as in Unity",
            self.scene_rel
        ));
    }

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
        gamma_space: false,
    };
    const LINEAR: LightUnits = LightUnits {
        linear_intensity: true,
        color_temperature: true,
        gamma_space: false,
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
        // A gamma-space project's shaders take the stored colour times the intensity.
        let raw = LightUnits {
            gamma_space: true,
            ..LINEAR
        };
        assert_eq!(raw.light(orange, 1.5, Some(2000.0)), (orange, 1.5));
        // Temperature tints only linear intensities.
        assert_eq!(GAMMA.light(Vec3::ONE, 1.0, Some(2000.0)).0, Vec3::ONE);
        let (c, _) = LINEAR.light(Vec3::ONE, 1.0, Some(2000.0));
        assert_eq!(c, temperature_rgb(2000.0));
    }

    fn light(kind: LightKind, intensity: f32, shadows: Shadows) -> Light {
        Light {
            name: String::new(),
            kind,
            position: Vec3::ZERO,
            direction: Vec3::NEG_Y,
            color: Vec3::ONE,
            intensity,
            range: 10.0,
            attenuation: Attenuation::Universal,
            shadows,
            shadow_radius: 0.1,
            shadow_strength: 1.0,
            culling_mask: u32::MAX,
        }
    }

    /// A URP asset with every light and shadow on, `change`d.
    fn urp_asset(change: impl FnOnce(&mut UniversalAsset)) -> Option<UniversalAsset> {
        let mut a = UniversalAsset {
            main_light: true,
            additional_lights: true,
            main_shadows: true,
            additional_shadows: true,
            soft_shadows: true,
            shadow_distance: ShadowDistance {
                distance: 50.0,
                border: 0.2,
            },
        };
        change(&mut a);
        Some(a)
    }

    #[test]
    fn urp_casts_directional_shadows_from_its_main_light_alone() {
        let sun = |i| light(LightKind::Directional, i, Shadows::Soft);
        let lamp = light(LightKind::Point, 1.0, Shadows::Soft);
        let shadows = |ls: &[Light]| ls.iter().map(|l| l.shadows).collect::<Vec<_>>();
        // The brightest directional light is the main one; the first of equals wins.
        let mut ls = vec![sun(1.0), sun(2.0), sun(2.0), lamp.clone()];
        let out = universal_rules(&mut ls, None, None);
        assert_eq!(out.shadows_changed, 2);
        assert_eq!(out.drawn, [true; 4]);
        let (s, n) = (Shadows::Soft, Shadows::None);
        assert_eq!(shadows(&ls), [n, s, n, s]);
        // RenderSettings' sun wins over brightness, unless it is not directional.
        let mut ls = vec![sun(1.0), sun(2.0), lamp.clone()];
        universal_rules(&mut ls, Some(0), None);
        assert_eq!(shadows(&ls), [s, n, s]);
        let mut ls = vec![sun(1.0), sun(2.0), lamp.clone()];
        universal_rules(&mut ls, Some(2), None);
        assert_eq!(shadows(&ls), [n, s, s]);
        // A directional light of intensity 0 is never the main light.
        let mut ls = vec![sun(0.0)];
        universal_rules(&mut ls, None, None);
        assert_eq!(shadows(&ls), [n]);
        // The asset's switches.
        let h = Shadows::Hard;
        let (t, f) = (true, false);
        for (a, want, drawn) in [
            (urp_asset(|_| {}), [s, n, s], [t, t, t]),
            (urp_asset(|a| a.soft_shadows = false), [h, n, h], [t, t, t]),
            (
                urp_asset(|a| (a.soft_shadows, a.additional_shadows) = (false, false)),
                [h, n, n],
                [t, t, t],
            ),
            (urp_asset(|a| a.main_shadows = false), [n, n, s], [t, t, t]),
            // Without additional lights only the main light is drawn.
            (
                urp_asset(|a| a.additional_lights = false),
                [s, n, s],
                [t, f, f],
            ),
            // Without a main light every light is an additional one: drawn, and no
            // directional light casts a shadow.
            (urp_asset(|a| a.main_light = false), [n, n, s], [t, t, t]),
            (
                urp_asset(|a| (a.main_light, a.additional_lights) = (false, false)),
                [n, n, s],
                [f, f, f],
            ),
        ] {
            let mut ls = vec![sun(2.0), sun(1.0), lamp.clone()];
            let out = universal_rules(&mut ls, None, a);
            assert_eq!(
                (shadows(&ls), out.drawn),
                (want.to_vec(), drawn.to_vec()),
                "{a:?}"
            );
        }
    }

    #[test]
    fn a_urp_asset_says_what_lights_and_shadows_it_renders() {
        let text = "%YAML 1.1\n--- !u!114 &11400000\nMonoBehaviour:\n  m_Name: UniversalRP-HighQuality\n  m_MainLightRenderingMode: 1\n  m_AdditionalLightsRenderingMode: 2\n  m_MainLightShadowsSupported: 1\n  m_AdditionalLightShadowsSupported: 1\n  m_SoftShadowsSupported: 0\n";
        let got = UniversalAsset::of_asset(text);
        assert_eq!(got, urp_asset(|a| a.soft_shadows = false));
        let off = text.replace("RenderingMode: 2", "RenderingMode: 0");
        let want = urp_asset(|a| (a.soft_shadows, a.additional_lights) = (false, false));
        assert_eq!(UniversalAsset::of_asset(&off), want);
        // Fields an older asset lacks take the class's defaults.
        let old = "--- !u!114 &1\nMonoBehaviour:\n  m_MainLightShadowsSupported: 0\n";
        let want = urp_asset(|a| {
            (a.main_shadows, a.additional_shadows, a.soft_shadows) = (false, false, false)
        });
        assert_eq!(UniversalAsset::of_asset(old), want);
        for other in [
            "",
            "--- !u!114 &1\nMonoBehaviour:\n  m_Name: x\n",
            "\0\u{fffd}",
        ] {
            assert_eq!(UniversalAsset::of_asset(other), None, "{other:?}");
        }
    }

    #[test]
    fn graphics_settings_are_read_for_the_built_in_pipeline_only() {
        let text = "%YAML 1.1\n--- !u!30 &1\nGraphicsSettings:\n  m_LightsUseLinearIntensity: 1\n  m_LightsUseColorTemperature: 0\n";
        let units = LightUnits::of(Pipeline::BuiltIn, Some(text), ColorSpace::Linear);
        assert!(units.linear_intensity && !units.color_temperature);
        assert_eq!(
            LightUnits::of(Pipeline::BuiltIn, None, ColorSpace::Linear),
            GAMMA
        );
        for junk in ["", "m_LightsUseLinearIntensity: 1", "--- !u!30 &1\n: : ["] {
            assert_eq!(
                LightUnits::of(Pipeline::BuiltIn, Some(junk), ColorSpace::Linear),
                GAMMA,
                "{junk}"
            );
        }
        let off = text.replace(": 1", ": 0");
        for p in [Pipeline::Universal, Pipeline::HighDefinition] {
            assert_eq!(LightUnits::of(p, Some(&off), ColorSpace::Linear), LINEAR);
        }
    }
}
