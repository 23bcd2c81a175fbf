//! The real `kd2exr` binary, end to end: artifacts written by the libraries into a
//! temporary folder, then rendered, merged and refused.

use crate::common::*;
use formats::Shadows;
use glam::Vec3;
use render::ExrImage;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn kd2exr(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_kd2exr"))
        .args(args)
        .output()
        .expect("run kd2exr")
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

/// A lit floor with a box on it, written as scene.soup + scene.kd.
fn write_scene(dir: &Path) -> (PathBuf, PathBuf, formats::Soup) {
    write_scene_lit(dir, Shadows::Hard, 0.0)
}

/// [`write_scene`] with its light's shadows and shadow radius.
fn write_scene_lit(
    dir: &Path,
    shadows: Shadows,
    shadow_radius: f32,
) -> (PathBuf, PathBuf, formats::Soup) {
    let mut s = SceneBuilder::new();
    let floor = s.diffuse(Vec3::new(0.8, 0.6, 0.4));
    s.floor(0.0, 0.0, 0.0, 20.0, floor);
    let white = s.diffuse(Vec3::ONE);
    s.cube(
        "box",
        Vec3::new(-1.0, 0.0, -1.0),
        Vec3::new(1.0, 1.0, 1.0),
        white,
    );
    let mut light = point_light(Vec3::new(2.0, 4.0, 0.0), 1.5, 12.0, shadows);
    light.shadow_radius = shadow_radius;
    s.light(light);
    s.camera(top_down_camera(Vec3::new(0.0, 10.0, 0.0), 5.0));
    let (soup, kd) = s.build();
    let (sp, kp) = (dir.join("scene.soup"), dir.join("scene.kd"));
    soup.write(&sp).unwrap();
    kd.write(&kp).unwrap();
    (sp, kp, soup)
}

/// The rim probe answers the wholly lit and wholly shadowed points of a soft shadow with
/// four rays; `--soft-all` traces every sample; the two frames differ only at points the
/// probe misjudged, and the box's edges are wider than the light, so none is.
#[test]
fn soft_shadows_are_probed_unless_every_sample_is_asked_for() {
    let dir = tempfile::tempdir().unwrap();
    // A 0.1 m disc at least 4 m away: under 2° in radius, so the probe is asked.
    let (sp, kp, _) = write_scene_lit(dir.path(), Shadows::Soft, 0.1);
    let (s, k) = (sp.to_str().unwrap(), kp.to_str().unwrap());
    let render = |name: &str, extra: &[&str]| {
        let exr = dir.path().join(name);
        let mut args = vec![s, k, "-o", exr.to_str().unwrap(), "--json"];
        args.extend(["--width", "40", "--height", "30", "--soft-samples", "16"]);
        args.extend(extra);
        let out = kd2exr(&args);
        assert!(out.status.success(), "{}", text(&out.stderr));
        let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        let rays = |k: &str| json["rays"][k].as_u64().unwrap();
        (
            ExrImage::read(&exr).unwrap(),
            rays("soft_shadow"),
            rays("soft_decided"),
        )
    };
    let (probed, probed_rays, decided) = render("probed.exr", &[]);
    let (all, all_rays, none) = render("all.exr", &["--soft-all"]);
    // Every camera ray meets the floor or the box, and each point asks the one light.
    assert_eq!((all_rays, none), (1200 * 16, 0));
    assert!(decided > 600 && decided < 1200, "{decided} of 1200 decided");
    assert_eq!(probed_rays, 1200 * 4 + (1200 - decided) * 16);
    assert_eq!(probed.attributes["unitrace.softProbe"], "true");
    assert_eq!(all.attributes["unitrace.softProbe"], "false");
    let (p, a) = (probed.color().unwrap(), all.color().unwrap());
    let differ: Vec<f32> = p
        .iter()
        .zip(&a)
        .map(|(p, a)| (*p - *a).abs().max_element())
        .filter(|&d| d > 0.0)
        .collect();
    // Measured: 1,198 points decided, none of them wrongly.
    assert!(differ.is_empty(), "{differ:?}");
}

#[test]
fn renders_merges_and_reports() {
    let dir = tempfile::tempdir().unwrap();
    let (sp, kp, soup) = write_scene(dir.path());
    let (s, k) = (sp.to_str().unwrap(), kp.to_str().unwrap());
    let exr = dir.path().join("out.exr");
    let png = dir.path().join("out.png");
    let out = kd2exr(&[
        s,
        k,
        "-o",
        exr.to_str().unwrap(),
        "--preview",
        png.to_str().unwrap(),
        "--width",
        "40",
        "--height",
        "30",
        "--json",
        "--aov",
        "depth,object",
        "--threads",
        "2",
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let json: serde_json::Value =
        serde_json::from_slice(&out.stdout).expect("one JSON object on stdout");
    assert_eq!(json["width"], 40);
    assert_eq!(json["height"], 30);
    assert_eq!(json["spp"], 1);
    assert_eq!(
        json["depth"], 4,
        "the default mirror depth (reports/accuracy.md)"
    );
    assert!(json["seconds"].as_f64().unwrap() >= 0.0);
    assert_eq!(json["rays"]["camera"], 1200);
    assert_eq!(json["rays"]["reflection"], 0);
    assert_eq!(json["rays"]["soft_shadow"], 0);
    let shadow = json["rays"]["shadow"].as_u64().unwrap();
    assert!(shadow > 0 && shadow <= 1200);
    assert_eq!(json["plan"]["reflections"]["enabled"], false);
    assert_eq!(json["plan"]["lights"][0]["shadows"], "hard");
    let err = text(&out.stderr);
    assert!(err.contains("rays: camera 1200"), "{err}");

    // The EXR: RGBA + AOVs, header with the plan; the PNG decodes at the image size.
    let img = ExrImage::read(&exr).unwrap();
    assert_eq!(img.channel_names(), ["A", "B", "G", "R", "Z", "object"]);
    assert_eq!(
        img.attributes["unitrace.geometryHash"],
        formats::hex(&soup.geometry_hash)
    );
    let decoder = png::Decoder::new(std::fs::File::open(&png).unwrap());
    let reader = decoder.read_info().unwrap();
    assert_eq!((reader.info().width, reader.info().height), (40, 30));

    // Crops through the CLI, merged by the subcommand, equal the one-shot render.
    let mut crops = Vec::new();
    for (i, c) in ["0,0,40,13", "0,13,40,30"].iter().enumerate() {
        let p = dir.path().join(format!("crop{i}.exr"));
        let out = kd2exr(&[
            s,
            k,
            "-o",
            p.to_str().unwrap(),
            "--width",
            "40",
            "--height",
            "30",
            "--aov",
            "depth,object",
            "--crop",
            c,
        ]);
        assert!(out.status.success(), "{}", text(&out.stderr));
        crops.push(p);
    }
    let merged = dir.path().join("merged.exr");
    let out = kd2exr(&[
        "merge",
        crops[1].to_str().unwrap(),
        crops[0].to_str().unwrap(),
        "-o",
        merged.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let m = ExrImage::read(&merged).unwrap();
    assert_eq!(
        m.channels, img.channels,
        "merged crops equal the full render"
    );
}

#[test]
fn bad_input_is_one_clear_line_and_exit_1() {
    let dir = tempfile::tempdir().unwrap();
    let (sp, kp, _) = write_scene(dir.path());
    let (s, k) = (sp.to_str().unwrap(), kp.to_str().unwrap());
    let o = dir.path().join("x.exr");
    let o = o.to_str().unwrap();
    let folder = dir.path().to_str().unwrap();
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (vec![s, k, "-o", o, "--width", "0"], "--width 0"),
        (vec![s, k, "-o", o, "--spp", "0"], "--spp 0"),
        (
            vec![
                s,
                k,
                "-o",
                o,
                "--width",
                "40",
                "--height",
                "30",
                "--crop",
                "30,0,50,10",
            ],
            "--crop 30,0,50,10",
        ),
        (vec![s, k, "-o", o, "--crop", "5,5,5,9"], "non-empty window"),
        (vec![s, k, "-o", o, "--aov", "depth,motion"], "motion"),
        (
            vec![s, "/nonexistent/scene.kd", "-o", o],
            "/nonexistent/scene.kd",
        ),
        (vec![k, k, "-o", o], "scene.kd"),
        (
            vec![s, k, "-o", "/nonexistent/dir/x.exr"],
            "the folder /nonexistent/dir does not exist",
        ),
        // Refused before rendering: the EXR of a run whose preview fails is never written.
        (vec![s, k, "-o", o, "--preview", folder], "it is a folder"),
    ];
    for (args, needle) in cases {
        let out = kd2exr(&args);
        let err = text(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: {err}");
        assert_eq!(err.trim().lines().count(), 1, "one line: {err}");
    }
    assert!(!Path::new(o).exists(), "no output after an error");

    // A tree built from other geometry is refused.
    let mut s2 = SceneBuilder::new();
    let m = s2.diffuse(Vec3::ONE);
    s2.floor(1.0, 0.0, 0.0, 3.0, m);
    let (_, other_kd) = s2.build();
    let okp = dir.path().join("other.kd");
    other_kd.write(&okp).unwrap();
    let out = kd2exr(&[s, okp.to_str().unwrap(), "-o", o]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        text(&out.stderr).contains("soup2kd"),
        "{}",
        text(&out.stderr)
    );

    // Bad usage (a missing argument) is clap's exit code 2.
    assert_eq!(kd2exr(&[s, k]).status.code(), Some(2));
    // A merge with a gap names it.
    let part = dir.path().join("part.exr");
    let out = kd2exr(&[
        s,
        k,
        "-o",
        part.to_str().unwrap(),
        "--width",
        "8",
        "--height",
        "8",
        "--crop",
        "0,0,4,8",
    ]);
    assert!(out.status.success());
    let out = kd2exr(&["merge", part.to_str().unwrap(), "-o", o]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        text(&out.stderr).contains("32 pixels are in no input"),
        "{}",
        text(&out.stderr)
    );
}

#[test]
fn a_16k_render_with_aovs_is_refused_before_work_starts_when_it_cannot_fit() {
    let opts = render::RenderOptions {
        width: 16384,
        height: 16384,
        aovs: render::AovSet::all(),
        ..Default::default()
    };
    let need = render::memory::estimate_bytes(&opts);
    let Some(avail) = render::memory::available_bytes() else {
        println!("SKIPPED: a_16k_render…: this system does not report its available memory");
        return;
    };
    if need <= avail {
        println!("SKIPPED: a_16k_render…: {avail} bytes available, the render needs {need}: it would fit here");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let (sp, kp, _) = write_scene(dir.path());
    let o = dir.path().join("huge.exr");
    // Nonexistent inputs prove the refusal comes before any loading.
    let _ = (sp, kp);
    let out = kd2exr(&[
        "/nonexistent.soup",
        "/nonexistent.kd",
        "-o",
        o.to_str().unwrap(),
        "--width",
        "16384",
        "--height",
        "16384",
        "--aov",
        "depth,normal,albedo,object",
    ]);
    let err = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("GiB") && err.contains("--crop"), "{err}");
    assert!(!o.exists());
}

#[test]
fn the_texture_filter_is_an_option_and_lookups_are_reported() {
    use formats::texture::{TextureRef, Tiling, Wrap};
    let dir = tempfile::tempdir().unwrap();
    let mut s = SceneBuilder::new();
    let t = s.texture(texture(
        2,
        2,
        &[
            [255, 0, 0, 255],
            [0, 255, 0, 255],
            [0, 0, 255, 255],
            [255; 4],
        ],
        Wrap::Repeat,
    ));
    let m = s.material(formats::Material {
        normal_map: None,
        emission_map: None,
        occlusion_map: None,
        metallic_map: None,
        unlit: false,
        albedo_map: Some(TextureRef {
            texture: t,
            tiling: Tiling::default(),
        }),
        ..diffuse(Vec3::ONE)
    });
    s.floor(0.0, 0.0, 0.0, 20.0, m);
    s.light(point_light(
        Vec3::new(0.0, 4.0, 0.0),
        1.5,
        12.0,
        Shadows::Hard,
    ));
    s.camera(top_down_camera(Vec3::new(0.0, 10.0, 0.0), 5.0));
    let (soup, kd) = s.build();
    let (sp, kp) = (dir.path().join("t.soup"), dir.path().join("t.kd"));
    soup.write(&sp).unwrap();
    kd.write(&kp).unwrap();
    let (sp, kp) = (sp.to_str().unwrap(), kp.to_str().unwrap());
    let o = dir.path().join("t.exr");
    let o = o.to_str().unwrap();
    let size = ["--width", "8", "--height", "6"];
    let out = kd2exr(
        &[
            &[sp, kp, "-o", o, "--json", "--texture-filter", "point"][..],
            &size,
        ]
        .concat(),
    );
    assert!(out.status.success(), "{}", text(&out.stderr));
    let j: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(j["texture_filter"], "point");
    assert_eq!(j["plan"]["textures"]["enabled"], true);
    assert_eq!(j["plan"]["textures"]["filter"], "point");
    assert_eq!(j["rays"]["texture_lookups"], 48, "{j}");
    assert!(text(&out.stderr).contains("texture lookups 48"));
    let exr = ExrImage::read(Path::new(o)).unwrap();
    assert_eq!(
        exr.attributes
            .get("unitrace.textureFilter")
            .map(String::as_str),
        Some("point")
    );
    // A filter that does not exist is bad usage, naming the choices.
    let out = kd2exr(&[sp, kp, "-o", o, "--texture-filter", "nearest"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        text(&out.stderr).contains("point, bilinear, cone"),
        "{}",
        text(&out.stderr)
    );
}
