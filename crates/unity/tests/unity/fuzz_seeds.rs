//! The seeds of the `soup` and `unity_texture` fuzz targets are made here, from the
//! generated `textures` and `fog` projects, so they follow the soup format and the decoder's
//! formats: stale seeds fail this test, and `UNITRACE_WRITE_FUZZ_SEEDS=1` rewrites them.

use image::{ImageFormat, RgbaImage};
use std::io::Cursor;
use std::path::{Path, PathBuf};

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The texture target's first byte picks the claimed extension (index into its list:
/// png, jpg, tga, tif, exr, psd, hdr, bmp, dds; then the size limit, by index ÷ 9).
fn texture_seed(extension_index: u8, file: &[u8]) -> Vec<u8> {
    let mut v = vec![extension_index];
    v.extend_from_slice(file);
    v
}

fn encoded(img: &RgbaImage, format: ImageFormat) -> Vec<u8> {
    let mut out = Cursor::new(Vec::new());
    img.write_to(&mut out, format).unwrap();
    out.into_inner()
}

/// A flattened 2×2 RGB PSD, raw planes.
fn psd() -> Vec<u8> {
    let mut b = b"8BPS".to_vec();
    b.extend(1u16.to_be_bytes());
    b.extend([0; 6]);
    b.extend(3u16.to_be_bytes());
    b.extend(2u32.to_be_bytes());
    b.extend(2u32.to_be_bytes());
    b.extend(8u16.to_be_bytes());
    b.extend(3u16.to_be_bytes());
    b.extend([0; 12]);
    b.extend(0u16.to_be_bytes());
    b.extend([255, 0, 0, 128, 0, 255, 0, 128, 0, 0, 255, 128]);
    b
}

fn seeds() -> Vec<(PathBuf, Vec<u8>)> {
    let textures = repo().join("scenes/textures/Assets");
    let png = std::fs::read(textures.join("Textures/HalfCut.png")).unwrap();
    let img = image::load_from_memory(&png).unwrap().to_rgba8();
    let soup = unity::convert(
        &textures.join("Scenes/Cutout.unity"),
        &unity::Options::default(),
    )
    .unwrap();
    assert_eq!(soup.triangles.len(), 4);
    assert!(!soup.uvs.is_empty() && soup.textures.len() == 1);
    let framed = soup.to_bytes(Path::new("seed-4tri.soup")).unwrap();
    let payload = framed[52..].to_vec();
    let bent = unity::convert(
        &textures.join("Scenes/NormalMap.unity"),
        &unity::Options::default(),
    )
    .unwrap();
    assert!(bent.materials[0].normal_map.is_some());
    let foggy = unity::convert(
        &repo().join("scenes/fog/Assets/Scenes/Fog.unity"),
        &unity::Options::default(),
    )
    .unwrap();
    assert!(foggy.environment.fog.is_some());
    // The fog scene under a small latitude-longitude sky.
    let mut sky = foggy.clone();
    let rgb: Vec<glam::Vec3> = (0..8).map(|i| glam::Vec3::splat(i as f32 * 0.5)).collect();
    sky.environment.sky = Some(formats::Sky::Textured(formats::TexturedSky {
        scale: glam::Vec3::splat(0.98),
        rotation: 45.0,
        layout: formats::SkyLayout::LatLong {
            image: formats::SkyImage::from_linear("Assets/Sky.hdr", 4, 2, &rgb),
            panorama: formats::Panorama::Full,
        },
    }));
    let hdr = {
        let mut out = Cursor::new(Vec::new());
        image::DynamicImage::ImageRgba8(img.clone())
            .into_rgb32f()
            .write_to(&mut out, ImageFormat::Hdr)
            .unwrap();
        out.into_inner()
    };
    let fuzz = repo().join("fuzz/corpus");
    vec![
        (fuzz.join("soup/seed-4tri.soup"), framed),
        (
            fuzz.join("soup/seed-normal-map.soup"),
            bent.to_bytes(Path::new("seed-normal-map.soup")).unwrap(),
        ),
        (
            fuzz.join("soup/seed-fog.soup"),
            foggy.to_bytes(Path::new("seed-fog.soup")).unwrap(),
        ),
        (
            fuzz.join("soup/seed-sky.soup"),
            sky.to_bytes(Path::new("seed-sky.soup")).unwrap(),
        ),
        (fuzz.join("soup/seed-4tri-payload.bin"), payload),
        (
            fuzz.join("unity_texture/seed-hdr.bin"),
            texture_seed(6, &hdr),
        ),
        (
            fuzz.join("unity_texture/seed-png.bin"),
            texture_seed(0, &png),
        ),
        (
            fuzz.join("unity_texture/seed-tga.bin"),
            texture_seed(2, &encoded(&img, ImageFormat::Tga)),
        ),
        (
            fuzz.join("unity_texture/seed-psd.bin"),
            texture_seed(5, &psd()),
        ),
        // Raw image data followed by more bytes (the psd crate once wrote them out of
        // bounds).
        (
            fuzz.join("unity_texture/seed-psd-trailing.bin"),
            texture_seed(5, &[psd(), vec![0; 20]].concat()),
        ),
        (
            fuzz.join("unity_texture/seed-bmp.bin"),
            texture_seed(7, &encoded(&img, ImageFormat::Bmp)),
        ),
        // The PNG with a size limit of 1 texel, so the downscale runs.
        (
            fuzz.join("unity_texture/seed-png-max1.bin"),
            texture_seed(27, &png),
        ),
    ]
}

#[test]
fn fuzz_seeds_are_current() {
    let write = std::env::var_os("UNITRACE_WRITE_FUZZ_SEEDS").is_some();
    for (path, bytes) in seeds() {
        if write {
            std::fs::create_dir_all(path.parent().unwrap()).unwrap();
            std::fs::write(&path, &bytes).unwrap();
        }
        let on_disk = std::fs::read(&path).unwrap_or_default();
        assert!(
            on_disk == bytes,
            "{} is stale: UNITRACE_WRITE_FUZZ_SEEDS=1 cargo test -p unity --test unity fuzz_seeds",
            path.display()
        );
    }
}
