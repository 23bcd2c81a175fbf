//! Textures and alpha through the three binaries, on the bundled `scenes/textures` project
//! (written by `scenegen`): each scene is a Quad whose every pixel follows from a texel.
//!
//! Every scene is lit by one white directional light of intensity 1 and has no ambient
//! light and no sky reflection (its intensity is 0), so a lit pixel is texel · tint times the Standard shader's diffuse term (smoothness
//! 0, Specular Highlights off). The Quads face the camera; image x grows to the right and y
//! downwards.

use glam::Vec3;
use std::path::Path;
use unitrace::{repo, run_ok, unity_diffuse, Rgba};

const SIDE: usize = 64;

/// The diffuse term of a Quad facing the camera (−Z in Unity) under the sun turned `deg`
/// about Y from shining straight at it: Unity's, with n·l = cos `deg`.
fn sun_at(deg: f32) -> f32 {
    let (s, c) = deg.to_radians().sin_cos();
    unity_diffuse(Vec3::NEG_Z, Vec3::new(-s, 0.0, -c), Vec3::NEG_Z, 0.0)
}

/// Unity's sRGB → linear decoding.
fn linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

struct Frame {
    img: Rgba,
    json: serde_json::Value,
}

impl Frame {
    fn rgb(&self, x: usize, y: usize) -> Vec3 {
        let p = self.img.at(x, y);
        Vec3::new(p[0], p[1], p[2])
    }
}

/// Convert, compile and render `scenes/textures/Assets/Scenes/NAME.unity` at SIDE².
fn render(dir: &Path, name: &str) -> Frame {
    let scene = repo().join(format!("scenes/textures/Assets/Scenes/{name}.unity"));
    let soup = dir.join(format!("{name}.soup"));
    let kd = dir.join(format!("{name}.kd"));
    let exr = dir.join(format!("{name}.exr"));
    run_ok(
        "unity2soup",
        [scene.as_os_str(), "-o".as_ref(), soup.as_os_str()],
    );
    run_ok("soup2kd", [soup.as_os_str(), "-o".as_ref(), kd.as_os_str()]);
    let side = SIDE.to_string();
    let json = run_ok(
        "kd2exr",
        [
            soup.to_str().unwrap(),
            kd.to_str().unwrap(),
            "-o",
            exr.to_str().unwrap(),
            "--width",
            &side,
            "--height",
            &side,
            "--json",
        ],
    )
    .json();
    let img = Rgba::read(&exr);
    img.assert_finite();
    Frame { img, json }
}

fn assert_close(got: Vec3, want: Vec3, what: &str) {
    assert!(
        (got - want).abs().max_element() < 1e-4,
        "{what}: got {got}, want {want}"
    );
}

#[test]
fn the_quadrant_texture_is_upright_and_not_mirrored() {
    let dir = tempfile::tempdir().unwrap();
    let f = render(dir.path(), "Quadrants");
    // The image file's top-left texel is red, top-right green, bottom-left blue,
    // bottom-right white: the render shows them in the same corners.
    // Head-on, the diffuse term is the 96 % a dielectric does not reflect.
    let lit = sun_at(0.0);
    assert!((lit - 0.96).abs() < 1e-6, "{lit}");
    assert_close(f.rgb(8, 8), Vec3::X * lit, "top left");
    assert_close(f.rgb(56, 8), Vec3::Y * lit, "top right");
    assert_close(f.rgb(8, 56), Vec3::Z * lit, "bottom left");
    assert_close(f.rgb(56, 56), Vec3::ONE * lit, "bottom right");
    assert_eq!(f.json["plan"]["textures"]["enabled"], true, "{}", f.json);
}

#[test]
fn a_mid_grey_srgb_texel_is_0_2158_linear() {
    let dir = tempfile::tempdir().unwrap();
    let f = render(dir.path(), "Grey");
    let texel = linear(128.0 / 255.0);
    assert!((texel - 0.2158).abs() < 1e-4);
    let want = Vec3::splat(texel * sun_at(0.0));
    for (x, y) in [(0, 0), (31, 31), (63, 0), (10, 50), (63, 63)] {
        assert_close(f.rgb(x, y), want, &format!("pixel ({x}, {y})"));
    }
}

#[test]
fn tiling_and_offset_land_where_unity_puts_them() {
    let dir = tempfile::tempdir().unwrap();
    let f = render(dir.path(), "Tiling");
    // uv' = (2u + 0.5, v), repeating: the four image columns show the texture's right,
    // left, right and left halves (top row green/red, bottom row white/blue).
    for (col, right_half) in [(8, true), (24, false), (40, true), (56, false)] {
        let (top, bottom) = if right_half {
            (Vec3::Y, Vec3::ONE)
        } else {
            (Vec3::X, Vec3::Z)
        };
        let (top, bottom) = (top * sun_at(0.0), bottom * sun_at(0.0));
        assert_close(f.rgb(col, 8), top, &format!("column {col}, top"));
        assert_close(f.rgb(col, 56), bottom, &format!("column {col}, bottom"));
    }
}

#[test]
fn a_cut_out_shows_the_wall_and_casts_a_cut_out_shadow() {
    let dir = tempfile::tempdir().unwrap();
    let f = render(dir.path(), "Cutout");
    // The sun is turned 25° about Y, so every lit surface facing the camera gets n·l =
    // cos 25°.
    let cos = sun_at(25.0);
    // The wall's `_Color` is 0.75 grey; the cut-out's texels are sRGB (255, 200, 0).
    let wall = Vec3::splat(linear(0.75)) * cos;
    let quad = Vec3::new(1.0, linear(200.0 / 255.0), 0.0) * cos;
    let row = 32;
    let pixels: Vec<Vec3> = (0..SIDE).map(|x| f.rgb(x, row)).collect();
    let is = |p: &Vec3, want: Vec3| (*p - want).abs().max_element() < 1e-4;
    // The Quad covers columns 24–40: its left half is a hole onto the lit wall, its right
    // half is drawn; right of it the wall lies in the shadow of the drawn half only.
    assert!(is(&pixels[26], wall), "the hole shows the lit wall");
    assert!(is(&pixels[36], quad), "the opaque half: {}", pixels[36]);
    let drawn = pixels.iter().filter(|p| is(p, quad)).count();
    let shadow = pixels.iter().filter(|p| **p == Vec3::ZERO).count();
    let lit = pixels.iter().filter(|p| is(p, wall)).count();
    assert!((7..=10).contains(&drawn), "{drawn} drawn pixels");
    assert!((3..=6).contains(&shadow), "{shadow} shadow pixels");
    assert_eq!(
        drawn + shadow + lit,
        SIDE,
        "nothing but wall, quad and shadow"
    );
    // The shadow is that of the drawn half alone: it starts where the drawn half ends.
    let last_drawn = pixels.iter().rposition(|p| is(p, quad)).unwrap();
    assert_eq!(pixels[last_drawn + 1], Vec3::ZERO);
    assert!(is(&pixels[last_drawn + 1 + shadow], wall));
    assert_eq!(f.json["plan"]["alpha"]["enabled"], true, "{}", f.json);
}

#[test]
fn a_transparent_quad_blends_half_its_colour_and_half_a_shadow() {
    let dir = tempfile::tempdir().unwrap();
    let f = render(dir.path(), "Transparent");
    let wall = Vec3::splat(linear(0.75)) * sun_at(0.0);
    let red = Vec3::X * sun_at(0.0);
    // In the middle the camera sees the wall through the quad where the quad also stands
    // between the wall and the light: half the quad's colour, half the wall in half light.
    assert_close(f.rgb(32, 32), red * 0.5 + wall * 0.25, "centre");
    // Outside the quad the wall is fully lit.
    assert_close(f.rgb(4, 32), wall, "beside");
}

#[test]
fn the_normal_map_bends_the_normal_towards_increasing_u_as_in_unity() {
    let dir = tempfile::tempdir().unwrap();
    let f = render(dir.path(), "NormalMap");
    // The map's texel (204, 128) is tangent-space x = 2·204/255 − 1 = 0.6 along increasing
    // u (Unity +X, the image's right) and y = 1/255 along v; the Quad faces −Z and the sun
    // arrives from 30° to its right: cos = 0.5·x + cos 30°·√(1 − x² − y²).
    let (x, y) = (2.0 * 204.0 / 255.0 - 1.0, 2.0 * 128.0 / 255.0 - 1.0);
    let z = (1.0f32 - x * x - y * y).sqrt();
    let cos = 0.5 * x + 30f32.to_radians().cos() * z;
    assert!((cos - 0.9928).abs() < 1e-4, "{cos}");
    // In the Quad's frame (u, v, its normal towards the camera): the bent normal, the sun
    // and the eye. The eye sees the bent normal at n·v = z.
    let n = Vec3::new(x, y, z);
    let sun = Vec3::new(0.5, 0.0, 30f32.to_radians().cos());
    assert!((n.dot(sun) - cos).abs() < 1e-6);
    let lit = unity_diffuse(n, sun, Vec3::Z, 0.0);
    for (px, py) in [(0, 0), (8, 40), (32, 32), (63, 63)] {
        assert_close(f.rgb(px, py), Vec3::splat(lit), "bent");
    }
    // Unmapped, the Quad would take cos 30° = 0.866; mirrored, 0.393.
    assert_eq!(f.json["plan"]["normal_maps"]["enabled"], true, "{}", f.json);
    assert_eq!(f.json["rays"]["normal_lookups"], (SIDE * SIDE) as u64);
    assert_eq!(f.json["rays"]["texture_lookups"], 0);
}

#[test]
fn the_emission_map_glows_upright_without_light() {
    let dir = tempfile::tempdir().unwrap();
    let f = render(dir.path(), "EmissionMap");
    // No light and no ambient: the white glow times the quadrant texture, in the corners
    // the image file puts them.
    assert_close(f.rgb(8, 8), Vec3::X, "top left");
    assert_close(f.rgb(56, 8), Vec3::Y, "top right");
    assert_close(f.rgb(8, 56), Vec3::Z, "bottom left");
    assert_close(f.rgb(56, 56), Vec3::ONE, "bottom right");
    assert_eq!(f.json["rays"]["emission_lookups"], (SIDE * SIDE) as u64);
    assert_eq!(f.json["rays"]["shadow"], 0);
}
