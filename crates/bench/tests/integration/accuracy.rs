//! The accuracy report generator on a tiny scene: the reference against itself has zero
//! error, and the error against the reference shrinks as spp grows.

use bench::accuracy::{compare, scenes, sweep, Config};
use formats::BuildParams;
use kdtree::Accel;
use render::RenderOptions;

fn tiny_config() -> Config {
    Config {
        width: 32,
        height: 24,
        runs: 1,
        reference_spp: 256,
        threads: Some(1),
        ..Config::default()
    }
}

#[test]
fn reference_against_itself_has_zero_error() {
    let scene = scenes::tiny();
    scene.soup.validate().expect("the tiny soup is valid");
    let cfg = Config {
        reference_spp: 16,
        ..tiny_config()
    };
    let accel = Accel::build(&scene.soup.triangle_positions(), &BuildParams::default());
    let (a, rays, _) = sweep::reference(&scene, &accel, &cfg).unwrap();
    assert_eq!(rays.camera, 32 * 24 * 16);
    // Rendered twice: the renderer is deterministic per seed, so the images are equal.
    let (b, _, _) = sweep::reference(&scene, &accel, &cfg).unwrap();
    let e = compare(&a, &b, 32, 24);
    assert_eq!(e.rmse, 0.0);
    assert_eq!(e.rel_mse, 0.0);
    assert!((e.ssim - 1.0).abs() < 1e-12, "ssim {}", e.ssim);
    // The scene is not black: the comparison is over real pixel values.
    assert!(
        a.iter().any(|c| c.x > 0.05),
        "the tiny scene rendered black"
    );
}

#[test]
fn error_shrinks_as_spp_grows() {
    let scene = scenes::tiny();
    let cfg = tiny_config();
    let accel = Accel::build(&scene.soup.triangle_positions(), &BuildParams::default());
    let (reference, _, _) = sweep::reference(&scene, &accel, &cfg).unwrap();
    let base = sweep::defaults(&cfg);
    let errors: Vec<_> = [1, 4, 16, 64]
        .iter()
        .map(|&spp| {
            let o = RenderOptions {
                spp,
                ..base.clone()
            };
            let (img, rays, _) = sweep::render_once(&scene, &accel, &o).unwrap();
            assert_eq!(rays.camera, 32 * 24 * spp as u64);
            compare(&img, &reference, 32, 24)
        })
        .collect();
    for w in errors.windows(2) {
        assert!(
            w[1].rmse < w[0].rmse,
            "rmse did not shrink: {:?}",
            errors.iter().map(|e| e.rmse).collect::<Vec<_>>()
        );
        assert!(w[1].rel_mse < w[0].rel_mse);
        assert!(w[1].ssim >= w[0].ssim - 1e-9);
    }
    assert!(errors[0].rmse > 0.0);
}

#[test]
fn bias_is_measured_against_the_sweeps_most_accurate_setting() {
    let scene = scenes::tiny();
    let cfg = Config {
        reference_spp: 16,
        spp: vec![1],
        depth: vec![0, 1, 8],
        cutoff: vec![0.5, 0.0],
        soft: vec![1, 64],
        ..tiny_config()
    };
    let r = sweep::measure(&scene, &cfg, &|_| {}).unwrap();
    let bias = |knob: &str, value: &str| {
        r.points
            .iter()
            .find(|p| p.knob == knob && p.value == value)
            .and_then(|p| p.bias)
            .unwrap_or_else(|| panic!("no bias for {knob} = {value}"))
    };
    // The most accurate setting of each sweep is its own anchor: same options, same seed.
    assert_eq!(bias("depth", "8"), 0.0);
    assert_eq!(bias("cutoff", "0"), 0.0);
    assert_eq!(bias("soft", "64"), 0.0);
    assert_eq!(bias("probe", "off"), 0.0);
    // The floor is a mirror: without reflections it shows no reflection of the wall; one
    // soft-shadow sample is noisier than 64.
    assert!(bias("depth", "0") > bias("depth", "1"), "{:?}", r.points);
    assert!(bias("depth", "0") > 0.01);
    assert!(bias("soft", "1") > 0.0);
    assert!(r
        .points
        .iter()
        .filter(|p| p.knob == "spp")
        .all(|p| p.bias.is_none()));
    let md = bench::accuracy::report::markdown(&[r], &cfg, "test", &[]);
    assert!(md.contains("## Recommended defaults"), "{md}");
    assert!(md.contains("- mirror depth: "), "{md}");
}

#[test]
fn the_texture_filter_is_swept_on_textured_scenes_only() {
    let cfg = Config {
        reference_spp: 64,
        spp: vec![1],
        depth: vec![4],
        cutoff: vec![0.004],
        soft: vec![16],
        ..tiny_config()
    };
    let scene = scenes::checkerboard();
    scene
        .soup
        .validate()
        .expect("the checkerboard soup is valid");
    let r = sweep::measure(&scene, &cfg, &|_| {}).unwrap();
    let tex: Vec<_> = r.points.iter().filter(|p| p.knob == "texture").collect();
    let values: Vec<_> = tex.iter().map(|p| p.value.as_str()).collect();
    assert_eq!(values, ["point", "bilinear", "cone"]);
    assert!(tex.iter().all(|p| p.rays.texture_lookups > 0));
    // Minified, unfiltered lookups alias; the cone's mip level does not.
    let rmse = |v: &str| tex.iter().find(|p| p.value == v).unwrap().errors.rmse;
    assert!(rmse("cone") < rmse("point"), "{tex:?}");
    let md = bench::accuracy::report::markdown(&[r], &cfg, "test", &[]);
    assert!(md.contains("- texture filter: "), "{md}");
    let tiny = sweep::measure(&scenes::tiny(), &cfg, &|_| {}).unwrap();
    assert!(tiny.points.iter().all(|p| p.knob != "texture"));
}
