//! RenderSettings (class 104): the ambient light and the fog of the scene.

use crate::material::shaded_rgb;
use crate::yaml::Node;
use formats::{Ambient, AmbientMode, ColorSpace, Fog, FogMode};
use glam::{Vec3, Vec4};

/// The ambient light a RenderSettings body sets; `None` when a colour is not finite
/// (the soup keeps its default).
pub fn ambient(rs: &Node, space: ColorSpace) -> Option<Ambient> {
    let intensity = rs.f32_at("m_AmbientIntensity").unwrap_or(1.0);
    let col = |k: &str| {
        rs.get(k)
            .and_then(Node::color)
            .map(|c| shaded_rgb(c, space))
            .unwrap_or(Vec3::ZERO)
            * intensity
    };
    let mode = match rs.i64_at("m_AmbientMode").unwrap_or(0) {
        1 => AmbientMode::Trilight,
        3 => AmbientMode::Flat,
        _ => AmbientMode::Skybox,
    };
    let amb = Ambient {
        mode,
        sky: col("m_AmbientSkyColor"),
        equator: col("m_AmbientEquatorColor"),
        ground: col("m_AmbientGroundColor"),
        intensity,
    };
    ([amb.sky, amb.equator, amb.ground]
        .iter()
        .all(|c| c.is_finite())
        && intensity.is_finite())
    .then_some(amb)
}

/// The Intensity Multiplier of the environment reflection a RenderSettings body sets, where
/// Unity's default reflection probe holds the skybox (`m_DefaultReflectionMode` 0, the
/// default); `Err` with the reason where it holds something the soup cannot (a custom
/// cubemap). HDRP has no such probe (its sky is a Volume override): 0.
pub fn reflection(rs: &Node, hdrp: bool) -> Result<f32, String> {
    if hdrp {
        return Ok(0.0);
    }
    let intensity = rs.f32_at("m_ReflectionIntensity").unwrap_or(1.0);
    match rs.i64_at("m_DefaultReflectionMode").unwrap_or(0) {
        0 if intensity.is_finite() => Ok(intensity.max(0.0)),
        0 => Err(format!(
            "environment reflection intensity {intensity} is not finite; drawn without \
             environment reflection"
        )),
        _ => Err(
            "the environment reflection is a custom cubemap, which is not read; drawn \
                  without environment reflection"
                .into(),
        ),
    }
}

/// The fog a RenderSettings body turns on (`m_Fog: 1`), with Unity's defaults for what it
/// does not say; `Err` with the reason when it cannot be drawn. HDRP draws its fog from a
/// Volume override and ignores these settings.
pub fn fog(rs: &Node, hdrp: bool, space: ColorSpace) -> Result<Option<Fog>, String> {
    if rs.i64_at("m_Fog") != Some(1) {
        return Ok(None);
    }
    if hdrp {
        return Err(
            "HDRP ignores RenderSettings fog (its fog is a Volume override); \
                    drawn without fog"
                .into(),
        );
    }
    let num = |k: &str, default: f32| rs.f32_at(k).unwrap_or(default);
    let density = num("m_FogDensity", 0.01);
    let mode = match rs.i64_at("m_FogMode").unwrap_or(3) {
        1 => FogMode::Linear {
            start: num("m_LinearFogStart", 0.0),
            end: num("m_LinearFogEnd", 300.0),
        },
        2 => FogMode::Exponential { density },
        3 => FogMode::ExponentialSquared { density },
        m => {
            return Err(format!(
                "fog mode {m} is not one of Unity's (1, 2, 3); drawn without fog"
            ))
        }
    };
    let colour = shaded_rgb(
        rs.get("m_FogColor")
            .and_then(Node::color)
            .unwrap_or(Vec4::new(0.5, 0.5, 0.5, 1.0)),
        space,
    );
    if !mode.is_finite() || !colour.is_finite() {
        return Err(format!(
            "fog {mode:?}, colour {colour} is not finite; drawn without fog"
        ));
    }
    Ok(Some(Fog {
        mode,
        colour: colour.max(Vec3::ZERO),
    }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::srgb_to_linear;
    use crate::yaml::parse;

    fn fog_of(fields: &str, hdrp: bool) -> Result<Option<Fog>, String> {
        let rs = parse(&format!("RenderSettings:\n  m_Fog: 1\n{fields}"));
        fog(rs.get("RenderSettings").unwrap(), hdrp, ColorSpace::Linear)
    }

    #[test]
    fn reflection_reads_the_skybox_modes_intensity() {
        let of = |fields: &str, hdrp: bool| {
            let rs = parse(&format!("RenderSettings:\n  m_Fog: 0\n{fields}"));
            reflection(rs.get("RenderSettings").unwrap(), hdrp)
        };
        assert_eq!(of("", false), Ok(1.0), "Unity's defaults: skybox, 1");
        let half = "  m_DefaultReflectionMode: 0\n  m_ReflectionIntensity: 0.5\n";
        assert_eq!(of(half, false), Ok(0.5));
        assert_eq!(
            of(half, true),
            Ok(0.0),
            "HDRP has no default reflection probe"
        );
        assert_eq!(of("  m_ReflectionIntensity: -2\n", false), Ok(0.0));
        let custom = of("  m_DefaultReflectionMode: 1\n", false).unwrap_err();
        assert!(custom.contains("custom cubemap"), "{custom}");
        let nan = of("  m_ReflectionIntensity: 1e99\n", false).unwrap_err();
        assert!(nan.contains("not finite"), "{nan}");
    }

    #[test]
    fn fog_reads_each_mode_and_decodes_its_colour() {
        let colour = "  m_FogColor: {r: 0.5, g: 0.25, b: 1, a: 1}\n";
        let lin = fog_of(
            &format!("{colour}  m_FogMode: 1\n  m_LinearFogStart: 2\n  m_LinearFogEnd: 40\n"),
            false,
        )
        .unwrap()
        .unwrap();
        assert_eq!(
            lin.mode,
            FogMode::Linear {
                start: 2.0,
                end: 40.0
            }
        );
        let want = Vec3::new(srgb_to_linear(0.5), srgb_to_linear(0.25), 1.0);
        assert_eq!(lin.colour, want);
        let exp = fog_of("  m_FogMode: 2\n  m_FogDensity: 0.05\n", false)
            .unwrap()
            .unwrap();
        assert_eq!(exp.mode, FogMode::Exponential { density: 0.05 });
        // Unity's defaults: exponential squared, density 0.01, grey.
        let default = fog_of("", false).unwrap().unwrap();
        assert_eq!(default.mode, FogMode::ExponentialSquared { density: 0.01 });
        assert_eq!(default.colour, Vec3::splat(srgb_to_linear(0.5)));
        // A gamma-space project's shaders take the stored colour.
        let rs = parse(&format!("RenderSettings:\n  m_Fog: 1\n{colour}"));
        let gamma = fog(rs.get("RenderSettings").unwrap(), false, ColorSpace::Gamma);
        assert_eq!(gamma.unwrap().unwrap().colour, Vec3::new(0.5, 0.25, 1.0));
    }

    #[test]
    fn fog_that_is_off_unknown_hdrp_or_not_finite_is_not_drawn() {
        let off = parse("RenderSettings:\n  m_Fog: 0\n  m_FogMode: 2\n");
        let off = off.get("RenderSettings").unwrap();
        assert_eq!(fog(off, false, ColorSpace::Linear), Ok(None));
        let hdrp = fog_of("  m_FogMode: 2\n", true).unwrap_err();
        assert!(hdrp.contains("HDRP ignores RenderSettings fog"), "{hdrp}");
        let mode = fog_of("  m_FogMode: 7\n", false).unwrap_err();
        assert!(mode.contains("fog mode 7"), "{mode}");
        let nan = fog_of("  m_FogMode: 3\n  m_FogDensity: NaN\n", false).unwrap_err();
        assert!(nan.contains("not finite"), "{nan}");
    }
}
