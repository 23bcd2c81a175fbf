//! The skybox reflected by physically based surfaces, as Unity's default reflection probe
//! lends it: a floor seen by an orthographic camera from 75° off its normal, so that every
//! pixel has one n·v, under skies whose probe is known in closed form.

use crate::common::*;
use crate::highlights::{glossy, COLOUR};
use formats::{
    Attenuation, ClearFlags, Material, Panorama, Projection, Shadows, Sky, SkyImage, SkyLayout,
    TexturedSky,
};
use glam::Vec3;
use render::{Plan, Rendered};

/// cos 75°: the cosine between the floor's normal and the direction towards the eye.
const NV: f32 = 0.258_819;
const SKY: Vec3 = Vec3::new(0.5, 1.0, 2.0);

/// A sky of one colour everywhere (a cube of 8×8 faces).
fn uniform_sky() -> Sky {
    Sky::Textured(TexturedSky {
        scale: Vec3::ONE,
        rotation: 0.0,
        layout: SkyLayout::Cube {
            faces: vec![SkyImage::from_linear("f", 8, 8, &[SKY; 64]); 6],
        },
    })
}

/// A latitude-longitude sky of `SKY` above the horizon and black below it.
fn half_sky() -> Sky {
    let rgb: Vec<Vec3> = (0..64)
        .map(|i| if i >= 32 { SKY } else { Vec3::ZERO })
        .collect();
    Sky::Textured(TexturedSky {
        scale: Vec3::ONE,
        rotation: 0.0,
        layout: SkyLayout::LatLong {
            image: SkyImage::from_linear("half", 8, 8, &rgb),
            panorama: Panorama::Full,
        },
    })
}

/// Floor `material` (facing +Y, or −Y as a ceiling) under `sky` reflected at `intensity`,
/// no lights unless the pipeline is URP (then one that reaches nothing, which says so),
/// black ambient and background unless `clear` is Skybox; 8×8 pixels, seen from 75° off
/// the normal.
fn scene(
    material: Material,
    sky: Sky,
    intensity: f32,
    pipeline: Attenuation,
    ceiling: bool,
    clear: ClearFlags,
) -> (Rendered, Plan) {
    let mut s = SceneBuilder::new();
    s.soup.environment.sky = Some(sky);
    s.soup.environment.reflection = intensity;
    s.soup.environment.clear = clear;
    let m = s.material(material);
    let (normal, sin) = (if ceiling { -1.0 } else { 1.0 }, (1.0 - NV * NV).sqrt());
    let (a, b) = (Vec3::new(-50.0, 0.0, -50.0), Vec3::new(100.0, 0.0, 0.0));
    let c = Vec3::new(0.0, 0.0, 100.0);
    if ceiling {
        s.quad("ceiling", a, b, c, m);
    } else {
        s.quad("floor", a, c, b, m);
    }
    let forward = Vec3::new(0.0, -NV * normal, sin);
    s.camera(formats::Camera {
        name: "oblique".into(),
        position: -forward * 10.0,
        forward,
        up: Vec3::new(0.0, sin * normal, NV),
        projection: Projection::Orthographic { half_height: 1.0 },
        near: 0.0,
        far: f32::INFINITY,
    });
    if pipeline == Attenuation::Universal {
        s.light(formats::Light {
            attenuation: pipeline,
            ..point_light(Vec3::new(0.0, -40.0, 0.0), 1.0, 0.01, Shadows::None)
        });
    }
    let (soup, kd) = s.build();
    render(&soup, &kd, &opts(8, 8))
}

/// [`scene`] under [`half_sky`] at intensity 1, built-in pipeline, black background.
fn under_half_sky(material: Material, ceiling: bool) -> (Rendered, Plan) {
    scene(
        material,
        half_sky(),
        1.0,
        Attenuation::BuiltIn,
        ceiling,
        ClearFlags::SolidColor,
    )
}

fn reflecting(metallic: f32, smoothness: f32) -> Material {
    Material {
        reflections: true,
        ..glossy(metallic, smoothness)
    }
}

/// Unity's environment reflectance written out again: `BRDF1_Unity_PBS` (fifth power) and
/// URP's `EnvironmentBRDFSpecular` (fourth), linear colour space.
fn unity_environment(f0: Vec3, metallic: f32, smoothness: f32, nv: f32, urp: bool) -> Vec3 {
    let p = 1.0 - smoothness;
    let r = if urp {
        (p * p).max(0.007_812_5)
    } else {
        (p * p).max(0.002)
    };
    let grazing = (smoothness + 1.0 - 0.96 * (1.0 - metallic)).min(1.0);
    let fresnel = (1.0 - nv).powi(if urp { 4 } else { 5 });
    (f0 + (Vec3::splat(grazing) - f0) * fresnel) / (r * r + 1.0)
}

#[test]
fn a_dielectric_reflects_the_sky_by_each_pipelines_fresnel() {
    for smoothness in [0.0, 0.3, 0.9] {
        for urp in [false, true] {
            let pipeline = if urp {
                Attenuation::Universal
            } else {
                Attenuation::BuiltIn
            };
            let (out, plan) = scene(
                reflecting(0.0, smoothness),
                uniform_sky(),
                0.5,
                pipeline,
                false,
                ClearFlags::SolidColor,
            );
            assert!(
                plan.sky_reflections.enabled,
                "{}",
                plan.sky_reflections.reason
            );
            let w = unity_environment(Vec3::splat(0.04), 0.0, smoothness, NV, urp);
            let what = format!("smoothness {smoothness}, URP {urp}");
            assert_close(out.frame.pixel(4, 4), w * SKY * 0.5, 2e-5, &what);
            assert_eq!(out.counts.probe_lookups, 64, "{what}");
        }
    }
}

#[test]
fn a_smooth_metal_mirrors_its_colour_and_the_probe_adds_the_fresnel_rest() {
    // The traced mirror ray reflects colour·metallic·smoothness of the sky itself; the
    // probe adds what Unity's formula gives beyond that: (1 − colour)·(1 − n·v)⁵.
    let (out, _) = scene(
        reflecting(1.0, 1.0),
        uniform_sky(),
        1.0,
        Attenuation::BuiltIn,
        false,
        ClearFlags::Skybox,
    );
    let fresnel = (1.0 - NV).powi(5);
    let want = COLOUR * SKY + (Vec3::ONE - COLOUR) * fresnel * SKY;
    assert_close(out.frame.pixel(4, 4), want, 1e-4, "a gold mirror");
    assert_eq!(out.counts.reflection, 64);
}

#[test]
fn surfaces_reflect_the_sky_above_and_the_dark_below() {
    // A mirror-smooth dielectric floor reflects the bright upper half (75° off the normal
    // the reflected ray rises 15° above the horizon; the lower half is black), a ceiling
    // the black lower half.
    let floor = under_half_sky(reflecting(0.0, 1.0), false).0;
    let w = unity_environment(Vec3::splat(0.04), 0.0, 1.0, NV, false);
    assert_close(floor.frame.pixel(4, 4), w * SKY, 1e-3, "floor");
    let ceiling = under_half_sky(reflecting(0.0, 1.0), true).0;
    assert_close(ceiling.frame.pixel(4, 4), Vec3::ZERO, 1e-3, "ceiling");
    // The roughest floor sees the two halves blurred together, still mostly the upper.
    let rough = under_half_sky(reflecting(0.0, 0.0), false).0;
    let full = unity_environment(Vec3::splat(0.04), 0.0, 0.0, NV, false) * SKY;
    let got = rough.frame.pixel(4, 4);
    assert!(
        got.x > 0.5 * full.x && got.x < full.x,
        "{got} against {full}"
    );
}

#[test]
fn reflections_off_take_the_skys_mean_without_a_lookup() {
    let off = Material {
        reflections: false,
        ..glossy(0.0, 1.0)
    };
    let (out, plan) = under_half_sky(off, false);
    assert!(
        plan.sky_reflections
            .reason
            .contains("1 with Reflections off"),
        "{}",
        plan.sky_reflections.reason
    );
    assert_eq!(out.counts.probe_lookups, 0);
    // Half the sphere is SKY, half black.
    let w = unity_environment(Vec3::splat(0.04), 0.0, 1.0, NV, false);
    assert_close(out.frame.pixel(4, 4), w * SKY * 0.5, 1e-4, "the mean");
}

#[test]
fn nothing_is_reflected_where_the_scene_or_the_material_says_so() {
    let black = |material: Material, intensity: f32, why: &str| {
        let (out, plan) = scene(
            material,
            uniform_sky(),
            intensity,
            Attenuation::BuiltIn,
            false,
            ClearFlags::SolidColor,
        );
        assert!(!plan.sky_reflections.enabled);
        assert_eq!(plan.sky_reflections.reason, why);
        assert_eq!(out.frame.pixel(4, 4), Vec3::ZERO);
        assert_eq!(out.counts.probe_lookups, 0);
    };
    black(
        reflecting(0.0, 0.5),
        0.0,
        "the environment reflection's intensity is 0",
    );
    // Lambert's materials (legacy shaders) reflect nothing.
    black(
        Material {
            pbs: false,
            highlights: false,
            ..reflecting(0.0, 0.5)
        },
        1.0,
        "no material is physically based",
    );
}
