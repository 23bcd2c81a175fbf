//! EXR output: AOV channels read back with the exr crate, f16 colour, header attributes,
//! and crops merged into an image bit-identical to a one-shot render.

use crate::common::*;
use exr::prelude::{FlatSamples, ReadChannels, ReadLayers};
use formats::Shadows;
use glam::Vec3;
use render::exrio::{merge, ATTR_PREFIX};
use render::{header_attributes, AovSet, ExrImage, Window};

const FLOOR: Vec3 = Vec3::new(0.8, 0.6, 0.4);

/// Floor (object 0) with a 1 m box (object 1) on it, a soft point light and a mirror
/// panel, seen from above: every effect is on, so merged crops test all of them.
fn scene() -> (formats::Soup, formats::KdFile) {
    let mut s = SceneBuilder::new();
    let floor = s.diffuse(FLOOR);
    s.floor(0.0, 0.0, 0.0, 20.0, floor);
    let white = s.diffuse(Vec3::ONE);
    s.cube(
        "box",
        Vec3::new(1.0, 0.0, 1.0),
        Vec3::new(2.0, 1.0, 2.0),
        white,
    );
    let m = s.material(mirror(0.7));
    s.quad(
        "mirror",
        Vec3::new(-4.0, 0.0, -3.0),
        Vec3::new(0.0, 2.0, 0.0),
        Vec3::new(0.0, 0.0, 6.0),
        m,
    );
    let mut l = point_light(Vec3::new(2.0, 4.0, -1.0), 2.0, 15.0, Shadows::Soft);
    l.shadow_radius = 0.4;
    s.light(l);
    s.soup.environment.background = Vec3::new(0.1, 0.2, 0.4);
    s.camera(top_down_camera(Vec3::new(0.0, 10.0, 0.0), 5.0));
    s.build()
}

fn options(w: u32, h: u32) -> render::RenderOptions {
    let mut o = opts(w, h);
    o.spp = 4;
    o.soft_samples = 8;
    o.aovs = AovSet::all();
    o
}

fn write(
    dir: &std::path::Path,
    name: &str,
    soup: &formats::Soup,
    kd: &formats::KdFile,
    o: &render::RenderOptions,
    half: bool,
) -> std::path::PathBuf {
    let (out, plan) = render(soup, kd, o);
    let attrs = header_attributes(&plan, o, out.seconds, &soup.geometry_hash);
    let path = dir.join(name);
    ExrImage::from_frame(&out.frame, half, attrs)
        .write(&path)
        .expect("write EXR");
    path
}

#[test]
fn aov_channels_read_back_with_their_names_and_values() {
    let dir = tempfile::tempdir().unwrap();
    let (soup, kd) = scene();
    let o = options(40, 40);
    let path = write(dir.path(), "aov.exr", &soup, &kd, &o, false);

    // Read with the exr crate directly, not through our reader.
    let image = exr::prelude::read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_file(&path)
        .expect("the exr crate reads the file");
    let names: Vec<String> = image
        .layer_data
        .channel_data
        .list
        .iter()
        .map(|c| c.name.to_string())
        .collect();
    assert_eq!(
        names,
        [
            "A", "B", "G", "N.x", "N.y", "N.z", "R", "Z", "albedo.B", "albedo.G", "albedo.R",
            "object"
        ]
    );
    let at = |name: &str, x: u32, y: u32| -> f32 {
        let c = image
            .layer_data
            .channel_data
            .list
            .iter()
            .find(|c| c.name.to_string() == name)
            .unwrap();
        match &c.sample_data {
            FlatSamples::F32(v) => v[(y * 40 + x) as usize],
            other => panic!("{name} is not f32: {other:?}"),
        }
    };
    // Pixel (20, 20) sees the floor near (0, 0, 0) from 10 m above.
    let p = ortho_point(&soup.camera, 40, 40, 20, 20, 0.0);
    assert!(p.x.abs() < 0.5 && p.z.abs() < 0.5);
    assert_eq!(at("Z", 20, 20), 10.0);
    assert_eq!(
        (at("N.x", 20, 20), at("N.y", 20, 20), at("N.z", 20, 20)),
        (0.0, 1.0, 0.0)
    );
    assert_eq!(
        (
            at("albedo.R", 20, 20),
            at("albedo.G", 20, 20),
            at("albedo.B", 20, 20)
        ),
        (0.8, 0.6, 0.4)
    );
    assert_eq!(at("object", 20, 20), 0.0);
    assert_eq!(at("A", 20, 20), 1.0);
    // The box top (x, z ∈ [1, 2], y = 1): image right is −X, image up is +Z, so it is in
    // the upper left quarter. Find it through the camera mapping.
    let (bx, by) = (0..40)
        .flat_map(|y| (0..40).map(move |x| (x, y)))
        .find(|&(x, y)| {
            let q = ortho_point(&soup.camera, 40, 40, x, y, 1.0);
            q.x > 1.2 && q.x < 1.8 && q.z > 1.2 && q.z < 1.8
        })
        .unwrap();
    assert_eq!(at("object", bx, by), 1.0);
    assert_eq!(at("Z", bx, by), 9.0);
    assert_eq!(at("albedo.R", bx, by), 1.0);
    // The same values through our reader, plus the header.
    let ours = ExrImage::read(&path).unwrap();
    assert_eq!(ours.value("Z", bx, by), Some(9.0));
    assert_eq!(ours.attributes[&format!("{ATTR_PREFIX}spp")], "4");
    assert_eq!(ours.attributes[&format!("{ATTR_PREFIX}depth")], "4");
    assert_eq!(
        ours.attributes[&format!("{ATTR_PREFIX}geometryHash")],
        formats::hex(&soup.geometry_hash)
    );
    let plan: serde_json::Value =
        serde_json::from_str(&ours.attributes[&format!("{ATTR_PREFIX}plan")]).unwrap();
    assert_eq!(plan["lights"][0]["shadows"], "soft");
    assert_eq!(plan["reflections"]["enabled"], true);
    for (name, samples) in &ours.channels {
        assert!(
            samples.values_as_f32().all(f32::is_finite),
            "{name} holds NaN or Inf"
        );
    }
}

#[test]
fn half_output_stores_colour_as_f16_and_aovs_as_f32() {
    let dir = tempfile::tempdir().unwrap();
    let (soup, kd) = scene();
    let mut o = options(16, 16);
    o.aovs = AovSet::parse("depth,object").unwrap();
    let path = write(dir.path(), "half.exr", &soup, &kd, &o, true);
    let img = ExrImage::read(&path).unwrap();
    assert_eq!(img.channel_names(), ["A", "B", "G", "R", "Z", "object"]);
    assert!(matches!(img.channel("R"), Some(FlatSamples::F16(_))));
    assert!(matches!(img.channel("Z"), Some(FlatSamples::F32(_))));
    let (full, _) = render(&soup, &kd, &o);
    let want = full.frame.pixel(8, 8).x;
    let got = img.value("R", 8, 8).unwrap();
    assert!((got - want).abs() <= want * 1e-3, "{got} vs {want}");
}

#[test]
fn crops_merge_bit_identical_to_a_one_shot_render() {
    let dir = tempfile::tempdir().unwrap();
    let (soup, kd) = scene();
    let (w, h) = (50, 30);
    let full_path = write(dir.path(), "full.exr", &soup, &kd, &options(w, h), false);
    let crops = [
        Window {
            x0: 0,
            y0: 0,
            x1: 17,
            y1: 30,
        },
        Window {
            x0: 17,
            y0: 0,
            x1: 50,
            y1: 11,
        },
        Window {
            x0: 17,
            y0: 11,
            x1: 50,
            y1: 30,
        },
    ];
    let mut parts = Vec::new();
    for (i, c) in crops.iter().enumerate() {
        let mut o = options(w, h);
        o.crop = Some(*c);
        o.threads = Some(1 + i % 2);
        let p = write(dir.path(), &format!("crop{i}.exr"), &soup, &kd, &o, false);
        let img = ExrImage::read(&p).unwrap();
        assert_eq!(img.window, *c, "data window = crop");
        assert_eq!(
            (img.width, img.height),
            (w, h),
            "display window = full image"
        );
        parts.push(img);
    }
    // Any order.
    parts.reverse();
    let merged = merge(&parts).unwrap();
    let merged_path = dir.path().join("merged.exr");
    merged.write(&merged_path).unwrap();
    let merged = ExrImage::read(&merged_path).unwrap();
    let full = ExrImage::read(&full_path).unwrap();
    assert_eq!(merged.window, full.window);
    assert_eq!(merged.channel_names(), full.channel_names());
    for ((name, a), (_, b)) in merged.channels.iter().zip(&full.channels) {
        let (FlatSamples::F32(a), FlatSamples::F32(b)) = (a, b) else {
            panic!("{name} is not f32")
        };
        assert_eq!(a.len(), (w * h) as usize);
        let same = a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits());
        assert!(
            same,
            "channel {name} differs between merged crops and the full render"
        );
    }
    assert_eq!(merged.attributes[&format!("{ATTR_PREFIX}mergedFrom")], "3");
    // The scene is not trivial: several distinct colours, so equality means something.
    let r = full.channel("R").unwrap();
    let mut distinct: Vec<u32> = r.values_as_f32().map(f32::to_bits).collect();
    distinct.sort();
    distinct.dedup();
    assert!(distinct.len() > 100, "{} distinct values", distinct.len());
}

#[test]
fn merge_refuses_gaps_and_foreign_crops() {
    let (soup, kd) = scene();
    let make = |c: Window, spp: u32| {
        let mut o = options(20, 10);
        o.crop = Some(c);
        o.spp = spp;
        let (out, plan) = render(&soup, &kd, &o);
        ExrImage::from_frame(
            &out.frame,
            false,
            header_attributes(&plan, &o, 0.0, &soup.geometry_hash),
        )
    };
    let left = make(
        Window {
            x0: 0,
            y0: 0,
            x1: 10,
            y1: 10,
        },
        4,
    );
    let right = make(
        Window {
            x0: 10,
            y0: 0,
            x1: 20,
            y1: 10,
        },
        4,
    );
    let right_1spp = make(
        Window {
            x0: 10,
            y0: 0,
            x1: 20,
            y1: 10,
        },
        1,
    );
    let err = merge(std::slice::from_ref(&left)).unwrap_err().to_string();
    assert!(
        err.contains("100 pixels are in no input") && err.contains("(10, 0)"),
        "{err}"
    );
    let err = merge(&[left.clone(), right_1spp]).unwrap_err().to_string();
    assert!(err.contains("spp"), "{err}");
    assert!(merge(&[left.clone(), right.clone()]).is_ok());
    // Overlapping crops of one render agree and merge.
    let mid = make(
        Window {
            x0: 5,
            y0: 0,
            x1: 15,
            y1: 10,
        },
        4,
    );
    assert!(merge(&[left, mid, right]).is_ok());
}
