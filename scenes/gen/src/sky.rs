//! The `skybox` effect project: a sky from an HDR image. A latitude-longitude Radiance file
//! drawn here (a blue gradient over a ridge of hills, a sun of 400 where the scene's
//! directional light comes from) on Unity's Skybox/Panoramic shader, a Skybox camera, and
//! Skybox ambient, so the mirror sphere, the background and the shaded sides all show it.

use crate::effects::Builder;
use crate::material::MatDesc;
use crate::meta::TextureImport;
use crate::project::Project;
use crate::unity::{self, Ambient, CameraDesc, LightDesc, LightType, Xform};
use glam::Vec3;
use image::{ImageFormat, Rgb, Rgb32FImage};
use std::f32::consts::PI;
use std::io::Cursor;

const WIDTH: u32 = 1024;
const HEIGHT: u32 = 512;
/// The directional light's Euler angles (degrees); the sun sits opposite its direction.
const LIGHT_EULER: (f32, f32) = (35.0, -40.0);
const SUN_RADIANCE: f32 = 400.0;
/// The sun's angular radius, degrees.
const SUN_RADIUS: f32 = 1.5;

/// Unit vector towards the sun, in Unity's axes: a light turned by `LIGHT_EULER` (X then
/// Y) shines along its local +Z.
fn sun_direction() -> Vec3 {
    let (x, y) = (LIGHT_EULER.0.to_radians(), LIGHT_EULER.1.to_radians());
    -Vec3::new(y.sin() * x.cos(), -x.sin(), y.cos() * x.cos())
}

/// The panorama's radiance along Unity direction `d` (unit).
fn radiance(d: Vec3) -> Vec3 {
    if d.dot(sun_direction()) > SUN_RADIUS.to_radians().cos() {
        return Vec3::new(1.0, 0.95, 0.85) * SUN_RADIANCE;
    }
    let azimuth = d.z.atan2(d.x);
    let elevation = d.y.clamp(-1.0, 1.0).asin();
    // A ridge of hills 2–5° high around the horizon, its edge blended over half a degree
    // (about a texel and a half) so that it does not step from row to row.
    let ridge =
        (3.5 + 1.0 * (3.0 * azimuth).sin() + 0.5 * (7.0 * azimuth + 1.0).sin()).to_radians();
    let shade = if elevation < 0.0 { 0.6 } else { 1.0 };
    let hills = Vec3::new(0.16, 0.2, 0.12) * shade;
    let t = (elevation / (PI / 2.0)).clamp(0.0, 1.0).sqrt();
    let sky = Vec3::new(0.85, 0.9, 1.0).lerp(Vec3::new(0.12, 0.28, 0.75), t) * 1.2;
    let edge = ((elevation - ridge) / 0.5f32.to_radians() + 0.5).clamp(0.0, 1.0);
    hills.lerp(sky, edge)
}

/// The Radiance HDR file, top row first, each texel the radiance at its centre through
/// the panoramic shader's mapping (u = 0.5 − atan2(z, x)/2π, v = 1 − acos(y)/π).
pub fn panorama() -> Vec<u8> {
    let img = Rgb32FImage::from_fn(WIDTH, HEIGHT, |x, y| {
        let u = (x as f32 + 0.5) / WIDTH as f32;
        let v = 1.0 - (y as f32 + 0.5) / HEIGHT as f32;
        let (polar, azimuth) = (PI * (1.0 - v), (0.5 - u) * 2.0 * PI);
        let d = Vec3::new(
            polar.sin() * azimuth.cos(),
            polar.cos(),
            polar.sin() * azimuth.sin(),
        );
        Rgb(radiance(d).to_array())
    });
    let mut out = Cursor::new(Vec::new());
    img.write_to(&mut out, ImageFormat::Hdr)
        .expect("an HDR image in memory");
    out.into_inner()
}

/// A Skybox/Panoramic material (built-in shader 108) showing texture `guid` at the default
/// tint and exposure.
fn panoramic_material(guid: &str) -> String {
    format!(
        "%YAML 1.1
%TAG !u! tag:unity3d.com,2011:
--- !u!21 &2100000
Material:
  serializedVersion: 8
  m_Name: Sky
  m_Shader: {{fileID: 108, guid: 0000000000000000f000000000000000, type: 0}}
  m_ValidKeywords: []
  m_InvalidKeywords:
  - _MAPPING_LATITUDE_LONGITUDE_LAYOUT
  m_SavedProperties:
    serializedVersion: 3
    m_TexEnvs:
    - _MainTex:
        m_Texture: {{fileID: 2800000, guid: {guid}, type: 3}}
        m_Scale: {{x: 1, y: 1}}
        m_Offset: {{x: 0, y: 0}}
    m_Ints: []
    m_Floats:
    - _Exposure: 1
    - _ImageType: 0
    - _Layout: 0
    - _Mapping: 1
    - _MirrorOnBack: 0
    - _Rotation: 0
    m_Colors:
    - _Tint: {{r: 0.5, g: 0.5, b: 0.5, a: 0.5}}
"
    )
}

/// A grey stage with a mirror sphere and a red cube under the panorama's sky.
pub fn project() -> Project {
    let looks = [
        MatDesc::matte("Grey", [0.7, 0.7, 0.7]),
        MatDesc::matte("Red", [0.85, 0.15, 0.1]),
        MatDesc::mirror("Mirror"),
    ];
    let mut b = Builder::new("skybox", &looks);
    let guid = b.texture(
        "Assets/Textures/Sky.hdr",
        panorama(),
        &TextureImport {
            filter: 1,
            mipmaps: false,
            srgb: false,
            wrap: 0,
            alpha_is_transparency: false,
            normal_map: false,
        },
    );
    b.skybox("Assets/Materials/Sky.mat", panoramic_material(&guid))
        .camera(
            Xform::at(0.0, 1.2, -5.0).euler(-4.0, 0.0, 0.0),
            CameraDesc {
                skybox: true,
                ..CameraDesc::default()
            },
        )
        .mesh("Ground", unity::PLANE, "Grey", Xform::at(0.0, 0.0, 0.0))
        .mesh(
            "Sphere",
            unity::SPHERE,
            "Mirror",
            Xform::at(0.6, 1.0, 0.5).scale(2.0, 2.0, 2.0),
        )
        .mesh(
            "Cube",
            unity::CUBE,
            "Red",
            Xform::at(-1.6, 0.5, -0.5).euler(0.0, 25.0, 0.0),
        )
        .light(
            "Directional Light",
            Xform::at(0.0, 3.0, 0.0).euler(LIGHT_EULER.0, LIGHT_EULER.1, 0.0),
            LightDesc {
                kind: LightType::Directional,
                shadows: 1,
                ..LightDesc::point([1.0, 0.96, 0.88], 1.0, 10.0)
            },
        );
    b.finish("Skybox", Ambient::Skybox(1.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_sun_is_where_the_light_comes_from_and_above_the_hills() {
        let sun = sun_direction();
        assert!(sun.y > 0.5 && (sun.length() - 1.0).abs() < 1e-6, "{sun}");
        assert_eq!(radiance(sun).x, SUN_RADIANCE);
        assert!(radiance(Vec3::Y).z > radiance(Vec3::Y).x, "a blue zenith");
        assert!(radiance(-Vec3::Y).max_element() < 0.2, "dark ground");
        let hdr = panorama();
        assert!(hdr.starts_with(b"#?RADIANCE"));
    }
}
