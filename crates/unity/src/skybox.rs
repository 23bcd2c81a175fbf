//! RenderSettings' skybox material, when it is Unity's procedural sky (the built-in
//! Default-Skybox, or a project material on the Skybox/Procedural shader), and the sun
//! it shows.

use crate::emit::Emitter;
use crate::material::{keyword_on, linear_rgb, prop, props};
use crate::project::Project;
use crate::reference::fref;
use crate::yaml::Node;
use formats::{Light, LightKind, ProceduralSky, SunDisk};
use glam::{Vec3, Vec4};

/// Unity's built-in extra resources, where Default-Skybox and the skybox shaders live.
const BUILTIN_EXTRA: &str = "0000000000000000f000000000000000";
const DEFAULT_SKYBOX: i64 = 10304;
const PROCEDURAL_SHADER: i64 = 106;

/// The Skybox/Procedural shader's property defaults, which Default-Skybox keeps.
fn default_sky() -> ProceduralSky {
    ProceduralSky {
        sun_disk: SunDisk::HighQuality,
        sun_size: 0.04,
        sun_size_convergence: 5.0,
        atmosphere_thickness: 1.0,
        exposure: 1.3,
        sky_tint: linear_rgb(Vec4::new(0.5, 0.5, 0.5, 1.0)),
        ground: linear_rgb(Vec4::new(0.369, 0.349, 0.341, 1.0)),
        sun_direction: Vec3::Z,
        sun_colour: Vec3::ZERO,
    }
}

/// The procedural sky RenderSettings names (its sun still unset), `Ok(None)` without a
/// skybox material, `Err` with the reason a skybox cannot be drawn.
pub fn procedural(rs: &Node, project: &Project) -> Result<Option<ProceduralSky>, String> {
    let r = fref(rs.get("m_SkyboxMaterial"));
    let (id, guid) = (r.0, r.1.unwrap_or_default());
    if id == 0 {
        return Ok(None);
    }
    if project.hdrp {
        return Err("HDRP ignores RenderSettings' skybox (its sky is a Volume override)".into());
    }
    if guid == BUILTIN_EXTRA && id == DEFAULT_SKYBOX {
        return Ok(Some(default_sky()));
    }
    let Some(path) = project.resolve(&guid) else {
        return Err(format!("skybox material GUID {guid} is not in the project"));
    };
    let body = match project.mat(path).as_ref() {
        Ok(Some(body)) => body.clone(),
        Ok(None) => return Err(format!("{} holds no Material", project.rel(path))),
        Err(e) => return Err(format!("{}: {e}", project.rel(path))),
    };
    let shader = fref(body.get("m_Shader"));
    if shader.0 != PROCEDURAL_SHADER || shader.1.as_deref() != Some(BUILTIN_EXTRA) {
        return Err(format!(
            "skybox {} is not a Skybox/Procedural material (shader fileID {})",
            project.rel(path),
            shader.0
        ));
    }
    Ok(Some(read_material(&body)))
}

/// A Skybox/Procedural material's properties over the shader's defaults.
fn read_material(body: &Node) -> ProceduralSky {
    let mut sky = default_sky();
    let saved = body.get("m_SavedProperties");
    let floats = saved.map(|s| props(s, "m_Floats")).unwrap_or_default();
    let colours = saved.map(|s| props(s, "m_Colors")).unwrap_or_default();
    // A number Unity cannot have written (NaN, infinite) leaves the shader's default, so
    // the soup stays one every reader takes.
    let float = |k: &str| {
        prop(&floats, k)
            .and_then(Node::as_f32)
            .filter(|x| x.is_finite())
    };
    let colour = |k: &str| {
        prop(&colours, k)
            .and_then(Node::color)
            .map(linear_rgb)
            .filter(|c| c.is_finite())
    };
    sky.sun_size = float("_SunSize").unwrap_or(sky.sun_size);
    sky.sun_size_convergence = float("_SunSizeConvergence").unwrap_or(sky.sun_size_convergence);
    sky.atmosphere_thickness = float("_AtmosphereThickness").unwrap_or(sky.atmosphere_thickness);
    sky.exposure = float("_Exposure").unwrap_or(sky.exposure);
    sky.sky_tint = colour("_SkyTint").unwrap_or(sky.sky_tint);
    sky.ground = colour("_GroundColor").unwrap_or(sky.ground);
    // The keyword picks the shader variant; without one the float mirrors it.
    let on = |k: &str| keyword_on(body, k) == Some(true);
    sky.sun_disk = if on("_SUNDISK_NONE") {
        SunDisk::None
    } else if on("_SUNDISK_SIMPLE") {
        SunDisk::Simple
    } else if on("_SUNDISK_HIGH_QUALITY") {
        SunDisk::HighQuality
    } else {
        match float("_SunDisk").map(|f| f as i64) {
            Some(0) => SunDisk::None,
            Some(1) => SunDisk::Simple,
            _ => SunDisk::HighQuality,
        }
    };
    sky
}

/// Point the sky at its sun: the light RenderSettings names (`m_Sun`, `named`) when it
/// is a converted directional light, else the brightest directional light. Without one
/// the direction stays Unity's +Z and the colour black (no sun disk), as URP leaves its
/// main light.
pub fn aim(sky: &mut ProceduralSky, lights: &[Light], named: Option<usize>) {
    let directional = |l: &&Light| matches!(l.kind, LightKind::Directional);
    let brightness = |l: &Light| (l.color * l.intensity).element_sum();
    let sun = named
        .and_then(|i| lights.get(i))
        .filter(directional)
        .or_else(|| {
            lights
                .iter()
                .filter(directional)
                .max_by(|a, b| brightness(a).total_cmp(&brightness(b)))
        });
    if let Some(sun) = sun {
        sky.sun_direction = -sun.direction;
        sky.sun_colour = sun.color * sun.intensity;
    }
}

impl Emitter<'_, '_> {
    /// The procedural sky RenderSettings `rs` names, aimed at the scene's sun (the top
    /// scene's file is the graph's first).
    pub(crate) fn sky(&mut self, rs: &Node) {
        match procedural(rs, self.g.project) {
            Ok(Some(mut sky)) => {
                let sun = fref(rs.get("m_Sun")).0;
                let named = self
                    .light_ids
                    .iter()
                    .position(|&(file, id)| sun != 0 && file == 0 && id == sun);
                aim(&mut sky, &self.soup.lights, named);
                self.soup.environment.sky = Some(sky);
            }
            Ok(None) => {}
            Err(why) => self.soup.warnings.push(format!(
                "{}: RenderSettings: {why}; a sky gradient stands in",
                self.scene_rel
            )),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::yaml::parse;

    #[test]
    fn a_procedural_material_overrides_the_defaults_it_names() {
        let m = parse(
            "Material:\n  m_Shader: {fileID: 106, guid: 0000000000000000f000000000000000, type: 0}\n  m_ShaderKeywords: _SUNDISK_SIMPLE\n  m_SavedProperties:\n    m_Floats:\n    - _AtmosphereThickness: 0.53\n    - _Exposure: 1.25\n    m_Colors:\n    - _SkyTint: {r: 1, g: 1, b: 1, a: 1}\n",
        );
        let sky = read_material(m.get("Material").unwrap());
        assert_eq!(sky.atmosphere_thickness, 0.53);
        assert_eq!(sky.exposure, 1.25);
        assert_eq!(sky.sky_tint, Vec3::ONE);
        assert_eq!(sky.sun_disk, SunDisk::Simple);
        assert_eq!(sky.sun_size, 0.04, "the shader's default");
        assert_eq!(sky.ground, default_sky().ground);
    }

    #[test]
    fn a_property_that_is_not_a_finite_number_keeps_the_default() {
        let m = parse(
            "Material:\n  m_SavedProperties:\n    m_Floats:\n    - _Exposure: NaN\n    - _SunSize: Infinity\n    m_Colors:\n    - _SkyTint: {r: NaN, g: 1, b: 1, a: 1}\n",
        );
        let sky = read_material(m.get("Material").unwrap());
        let default = default_sky();
        assert_eq!(
            (sky.exposure, sky.sun_size, sky.sky_tint),
            (default.exposure, default.sun_size, default.sky_tint)
        );
    }

    #[test]
    fn the_sun_is_the_named_light_or_the_brightest_directional_one() {
        let light = |kind, intensity: f32, direction: Vec3| Light {
            name: "l".into(),
            kind,
            position: Vec3::ZERO,
            direction,
            color: Vec3::ONE,
            intensity,
            range: 10.0,
            shadows: formats::Shadows::None,
            shadow_radius: 0.0,
            shadow_strength: 1.0,
            culling_mask: u32::MAX,
        };
        let lights = [
            light(LightKind::Point, 9.0, Vec3::Y),
            light(LightKind::Directional, 1.0, -Vec3::Y),
            light(LightKind::Directional, 2.0, -Vec3::X),
        ];
        let mut sky = default_sky();
        aim(&mut sky, &lights, Some(1));
        assert_eq!((sky.sun_direction, sky.sun_colour), (Vec3::Y, Vec3::ONE));
        // A point light named as the sun does not count; the brightest directional does.
        aim(&mut sky, &lights, Some(0));
        assert_eq!(
            (sky.sun_direction, sky.sun_colour),
            (Vec3::X, Vec3::splat(2.0))
        );
        let mut dark = default_sky();
        aim(&mut dark, &lights[..1], None);
        assert_eq!((dark.sun_direction, dark.sun_colour), (Vec3::Z, Vec3::ZERO));
    }
}
