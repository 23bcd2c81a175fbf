//! Skies from images: Skybox/Panoramic, Skybox/Cubemap and Skybox/6 Sided materials read
//! with their textures, tint, exposure and rotation.

use crate::support::{assert_warned, convert, project, Scene, Tf};
use formats::{Panorama, Sky, SkyLayout, TexturedSky};
use glam::Vec3;
use std::path::Path;

const MAT_GUID: &str = "5ca1ab1e5ca1ab1e5ca1ab1e5ca1ab1e";

/// A Skybox camera's scene whose RenderSettings name the project's `Assets/Sky.mat`.
fn scene() -> String {
    let mut sc = Scene::default();
    sc.camera(&Tf::at(0.0, 0.0, 0.0));
    sc.raw(&format!(
        "--- !u!104 &2\nRenderSettings:\n  m_SkyboxMaterial: {{fileID: 2100000, guid: {MAT_GUID}, type: 2}}\n"
    ));
    sc.text
        .replace("  m_ClearFlags: 2\n", "  m_ClearFlags: 1\n")
}

/// A material on built-in skybox shader `shader` with `textures` (property, guid) and
/// extra property lines.
fn material(shader: i64, textures: &[(&str, &str)], floats: &str, colours: &str) -> String {
    let envs: String = textures
        .iter()
        .map(|(p, g)| {
            format!("    - {p}:\n        m_Texture: {{fileID: 2800000, guid: {g}, type: 3}}\n")
        })
        .collect();
    format!(
        "--- !u!21 &2100000\nMaterial:\n  m_Shader: {{fileID: {shader}, guid: 0000000000000000f000000000000000, type: 0}}\n  m_SavedProperties:\n    m_TexEnvs:\n{envs}    m_Floats:\n{floats}    m_Colors:\n{colours}"
    )
}

fn meta(guid: &str, importer: &str) -> String {
    format!("fileFormatVersion: 2\nguid: {guid}\n{importer}")
}

/// Convert a project of `Assets/s.unity`, `Assets/Sky.mat` and `files`, after `images`
/// writes its binary files under the root.
fn convert_with(mat: &str, files: &[(&str, &str)], images: impl FnOnce(&Path)) -> formats::Soup {
    let scene = scene();
    let mat_meta = meta(MAT_GUID, "");
    let mut all = vec![
        ("Assets/s.unity", scene.as_str()),
        ("Assets/Sky.mat", mat),
        ("Assets/Sky.mat.meta", mat_meta.as_str()),
    ];
    all.extend_from_slice(files);
    let (_d, root) = project(&all);
    images(&root);
    convert(&root.join("Assets/s.unity"))
}

fn textured(soup: &formats::Soup) -> &TexturedSky {
    match &soup.environment.sky {
        Some(Sky::Textured(t)) => t,
        other => panic!("not an image sky: {other:?} {:?}", soup.warnings),
    }
}

/// An HDR panorama keeps values far above 1; tint, [Gamma] exposure, rotation and the
/// 180° mirrored image type reach the soup.
#[test]
fn a_panoramic_skybox_keeps_its_hdr_image() {
    // 8×4 texels: texel (x, row) = (x + 1) / 2 in red and 0.25 in green, but the top
    // row's first texel, a sun of 1000 in green.
    let mut img = image::Rgb32FImage::new(8, 4);
    for (x, _, p) in img.enumerate_pixels_mut() {
        *p = image::Rgb([(x + 1) as f32 * 0.5, 0.25, 0.0]);
    }
    img.put_pixel(0, 0, image::Rgb([0.0, 1000.0, 0.0]));
    let mat = material(
        108,
        &[("_MainTex", "aaaa0000aaaa0000aaaa0000aaaa0000")],
        "    - _Exposure: 2\n    - _Rotation: 90\n    - _ImageType: 1\n    - _MirrorOnBack: 1\n",
        "    - _Tint: {r: 0.5, g: 0.5, b: 0.5, a: 0.5}\n",
    );
    let tex_meta = meta(
        "aaaa0000aaaa0000aaaa0000aaaa0000",
        "TextureImporter:\n  nPOTScale: 0\n",
    );
    let soup = convert_with(&mat, &[("Assets/Sky.hdr.meta", &tex_meta)], |root| {
        img.save(root.join("Assets/Sky.hdr")).unwrap();
    });
    let sky = textured(&soup);
    let tint = unity::material::srgb_to_linear(0.5) * 4.594_794;
    assert_eq!(sky.scale, Vec3::splat(tint * 2f32.powf(2.2)));
    assert_eq!(sky.rotation, 90.0);
    let SkyLayout::LatLong { image, panorama } = &sky.layout else {
        panic!("{:?}", sky.layout);
    };
    assert_eq!(*panorama, Panorama::HalfMirrored);
    assert_eq!(
        (image.width, image.height, image.source.as_str()),
        (8, 4, "Assets/Sky.hdr")
    );
    // Bottom row first: the file's top row is the soup's row 3.
    assert_eq!(image.texel(0, 3), Vec3::new(0.0, 1000.0, 0.0));
    assert_eq!(image.texel(1, 3), Vec3::new(1.0, 0.25, 0.0));
    assert_eq!(image.texel(7, 0), Vec3::new(4.0, 0.25, 0.0));
    assert!(soup.warnings.is_empty(), "{:?}", soup.warnings);
}

/// A cubemap imported from a horizontal cross: each face from its cell, 8-bit sRGB
/// decoded to linear.
#[test]
fn a_cubemap_skybox_splits_its_cross_into_faces() {
    // 4×3 cells of 2×2 texels; each face's cell a code of its own.
    let cells = [(2, 1), (0, 1), (1, 2), (1, 0), (1, 1), (3, 1)];
    let mut img = image::RgbImage::new(8, 6);
    for (f, (c, r)) in cells.iter().enumerate() {
        for dy in 0..2 {
            for dx in 0..2 {
                // Rows counted from the bottom; the file lists the top row first.
                let y = 5 - (r * 2 + dy);
                img.put_pixel(c * 2 + dx, y, image::Rgb([40 * (f as u8 + 1), 0, 255]));
            }
        }
    }
    let mat = material(103, &[("_Tex", "bbbb0000bbbb0000bbbb0000bbbb0000")], "", "");
    let tex_meta = meta(
        "bbbb0000bbbb0000bbbb0000bbbb0000",
        "TextureImporter:\n  textureShape: 2\n  generateCubemap: 6\n",
    );
    let soup = convert_with(&mat, &[("Assets/Cross.png.meta", &tex_meta)], |root| {
        img.save(root.join("Assets/Cross.png")).unwrap();
    });
    let sky = textured(&soup);
    assert_eq!(
        sky.scale,
        Vec3::splat(unity::material::srgb_to_linear(0.5) * 4.594_794)
    );
    let SkyLayout::Cube { faces } = &sky.layout else {
        panic!("{:?}", sky.layout);
    };
    assert_eq!(faces.len(), 6);
    for (f, face) in faces.iter().enumerate() {
        assert_eq!((face.width, face.height), (2, 2));
        let want = formats::texture::decode_u8(40 * (f as u8 + 1), true);
        let got = face.texel(1, 1);
        // RGBE keeps every channel to within 1/256 of the texel's brightest (blue, 1).
        assert!(
            (got.x - want).abs() <= 1.0 / 256.0,
            "face {f}: {got} against {want}"
        );
        assert_eq!(got.y, 0.0);
        assert_eq!(got.z, 1.0);
    }
}

/// Six 2D textures; a face whose texture is missing is the shader's grey, with a warning.
#[test]
fn a_six_sided_skybox_reads_a_texture_per_face() {
    let names = ["_LeftTex", "_RightTex", "_UpTex", "_DownTex", "_FrontTex"];
    let guids: Vec<String> = (0..5).map(|i| format!("cccc{i:028}")).collect();
    let slots: Vec<(&str, &str)> = names
        .iter()
        .zip(&guids)
        .map(|(n, g)| (*n, g.as_str()))
        .collect();
    let mat = material(104, &slots, "", "");
    let metas: Vec<(String, String)> = guids
        .iter()
        .enumerate()
        .map(|(i, g)| (format!("Assets/F{i}.png.meta"), meta(g, "")))
        .collect();
    let files: Vec<(&str, &str)> = metas
        .iter()
        .map(|(p, t)| (p.as_str(), t.as_str()))
        .collect();
    let soup = convert_with(&mat, &files, |root| {
        for i in 0..5u8 {
            let img = image::RgbImage::from_pixel(4, 4, image::Rgb([0, 0, 50 * i]));
            img.save(root.join(format!("Assets/F{i}.png"))).unwrap();
        }
    });
    let SkyLayout::Cube { faces } = &textured(&soup).layout else {
        panic!("not a cube");
    };
    for (i, face) in faces.iter().take(5).enumerate() {
        let want = formats::texture::decode_u8(50 * i as u8, true);
        assert!(
            (face.texel(2, 2).z - want).abs() <= want / 256.0,
            "face {i}"
        );
        assert_eq!(face.source, format!("Assets/F{i}.png"));
    }
    assert_eq!(
        (faces[5].width, faces[5].texel(0, 0)),
        (1, Vec3::splat(0.5))
    );
    assert!(
        soup.warnings
            .iter()
            .any(|w| w
                .contains("skybox Assets/Sky.mat: _BackTex names no texture; that face is grey")),
        "{:?}",
        soup.warnings
    );
}

/// What cannot be drawn says why and leaves the gradient: a 2D texture on the cubemap
/// shader, an unknown image format.
#[test]
fn an_unreadable_image_skybox_is_a_warning() {
    let mat = material(103, &[("_Tex", "dddd0000dddd0000dddd0000dddd0000")], "", "");
    let tex_meta = meta(
        "dddd0000dddd0000dddd0000dddd0000",
        "TextureImporter:\n  textureShape: 1\n",
    );
    let soup = convert_with(&mat, &[("Assets/Flat.png.meta", &tex_meta)], |root| {
        image::RgbImage::new(2, 2)
            .save(root.join("Assets/Flat.png"))
            .unwrap();
    });
    assert!(soup.environment.sky.is_none());
    assert_warned(&soup, "skybox Assets/Sky.mat: _Tex is not imported as a cubemap (Texture Shape: Cube); a sky gradient stands in");
    let mat = material(
        108,
        &[("_MainTex", "eeee0000eeee0000eeee0000eeee0000")],
        "",
        "",
    );
    let soup = convert_with(
        &mat,
        &[
            ("Assets/Sky.dds", "DDS "),
            (
                "Assets/Sky.dds.meta",
                &meta("eeee0000eeee0000eeee0000eeee0000", ""),
            ),
        ],
        |_| {},
    );
    assert!(soup.environment.sky.is_none());
    assert_warned(&soup, "Assets/Sky.dds: .dds textures are not supported");
}

/// Numbers no inspector writes: an exposure beyond the shader's range 0–8 is kept within
/// it; a tint too bright for a float is a warning, never a soup its readers refuse.
#[test]
fn an_image_skybox_s_numbers_stay_drawable() {
    let hdr = |root: &Path| {
        image::Rgb32FImage::from_pixel(4, 2, image::Rgb([1.0, 1.0, 1.0]))
            .save(root.join("Assets/Sky.hdr"))
            .unwrap();
    };
    let tex_meta = meta("ffff0000ffff0000ffff0000ffff0000", "");
    let files = [("Assets/Sky.hdr.meta", tex_meta.as_str())];
    let slot = [("_MainTex", "ffff0000ffff0000ffff0000ffff0000")];
    let bright = material(108, &slot, "    - _Exposure: 1e30\n", "");
    let soup = convert_with(&bright, &files, hdr);
    let tint = unity::material::srgb_to_linear(0.5) * 4.594_794;
    assert_eq!(textured(&soup).scale, Vec3::splat(tint * 8f32.powf(2.2)));
    // Linear 1.1e36: finite, but not once times 4.59 and the exposure's 97.
    let blinding = material(
        108,
        &slot,
        "    - _Exposure: 8\n",
        "    - _Tint: {r: 1e15, g: 1, b: 1, a: 1}\n",
    );
    let soup = convert_with(&blinding, &files, hdr);
    assert!(soup.environment.sky.is_none());
    assert_warned(&soup, "is too bright to draw; a sky gradient stands in");
}
