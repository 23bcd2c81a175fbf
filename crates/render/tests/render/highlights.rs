//! Physically based shading: a glossy floor lit and seen from straight above, where each
//! pipeline's highlight reduces to a closed form (n·h = l·h = n·v = n·l = 1), the diffuse
//! term's share and the built-in pipeline's Disney shape, and what the plan makes of
//! materials that show only a highlight.

use crate::common::*;
use formats::{Attenuation, ColorSpace, Material, Shadows};
use glam::Vec3;
use render::Rendered;
use std::f32::consts::PI;

pub(crate) const COLOUR: Vec3 = Vec3::new(0.8, 0.6, 0.4);
/// The share of its albedo a physically based shader lights as diffuse in a linear project
/// (1 − 0.04), and in a built-in gamma one (1 − 0.2209). Head-on the built-in pipeline's
/// Disney term is 1.
pub(crate) const DIFFUSE: f32 = 0.96;
const DIFFUSE_GAMMA: f32 = 1.0 - 0.220_916_3;

/// The floor of `material` under a directional light of intensity 2 shining straight down,
/// seen by an orthographic camera straight down, in a project of `pipeline` and `space`:
/// the centre pixel.
fn overhead(material: Material, pipeline: Attenuation, space: ColorSpace) -> Vec3 {
    let mut s = SceneBuilder::new();
    s.soup.environment.color_space = space;
    let m = s.material(material);
    overhead_in(s, m, pipeline).frame.pixel(4, 4)
}

/// [`overhead`] for material `m` of `s` (which may hold its textures), rendered at 8×8.
pub(crate) fn overhead_in(mut s: SceneBuilder, m: u32, pipeline: Attenuation) -> Rendered {
    s.floor(0.0, 0.0, 0.0, 20.0, m);
    s.camera(top_down_camera(Vec3::new(0.0, 10.0, 0.0), 5.0));
    s.light(formats::Light {
        attenuation: pipeline,
        ..directional_light(-Vec3::Y, 2.0, Shadows::Hard)
    });
    let (soup, kd) = s.build();
    render(&soup, &kd, &opts(8, 8)).0
}

pub(crate) fn glossy(metallic: f32, smoothness: f32) -> Material {
    Material {
        metallic,
        smoothness,
        pbs: true,
        highlights: true,
        ..diffuse(COLOUR)
    }
}

/// The built-in pipeline's head-on peak: D·V·π with D = 1/(π a²) (a = (1 − s)², at least
/// 0.002) and V = 0.5/(2 + 1e-5), F = f0.
pub(crate) fn built_in_peak(smoothness: f32) -> f32 {
    let a = ((1.0 - smoothness) * (1.0 - smoothness)).max(0.002);
    let a2 = a * a;
    (0.5 / (2.0 + 1e-5)) * (a2 / (PI * (a2 * a2 + 1e-7))) * PI
}

/// URP's head-on peak: r²/(d²·(4r + 2)) with d = r² + 0.00001.
pub(crate) fn urp_peak(smoothness: f32) -> f32 {
    let r = (1.0 - smoothness) * (1.0 - smoothness);
    let r2 = r * r;
    let d = r2 + 0.00001;
    r2 / (d * d * (4.0 * r + 2.0))
}

#[test]
fn a_dielectric_shows_its_diffuse_light_and_a_four_percent_highlight() {
    for smoothness in [0.0, 0.5, 0.8] {
        let got = overhead(
            glossy(0.0, smoothness),
            Attenuation::BuiltIn,
            ColorSpace::Linear,
        );
        let want = 2.0 * (COLOUR * DIFFUSE + Vec3::splat(0.04 * built_in_peak(smoothness)));
        assert_close(
            got,
            want,
            2e-4,
            &format!("built-in, smoothness {smoothness}"),
        );
        let got = overhead(
            glossy(0.0, smoothness),
            Attenuation::Universal,
            ColorSpace::Linear,
        );
        let want = 2.0 * (COLOUR * DIFFUSE + Vec3::splat(0.04 * urp_peak(smoothness)));
        assert_close(got, want, 2e-3, &format!("URP, smoothness {smoothness}"));
    }
    // Smoothness 0.5 adds about a fifth (built-in) or a quarter (URP) of white's light.
    assert!((0.04 * built_in_peak(0.5) - 0.16).abs() < 1e-3);
    assert!((0.04 * urp_peak(0.5) - 0.2133).abs() < 1e-3);
}

#[test]
fn a_metal_shows_its_colour_in_the_highlight_alone() {
    // Before highlights a fully metallic surface took no light at all: black.
    let got = overhead(glossy(1.0, 0.5), Attenuation::BuiltIn, ColorSpace::Linear);
    assert_close(
        got,
        2.0 * COLOUR * built_in_peak(0.5),
        2e-4,
        "metal, built-in",
    );
    let half = overhead(glossy(0.5, 0.5), Attenuation::Universal, ColorSpace::Linear);
    let f0 = Vec3::splat(0.02) + COLOUR * 0.5;
    assert_close(
        half,
        2.0 * (COLOUR * 0.5 * DIFFUSE + f0 * urp_peak(0.5)),
        2e-3,
        "half metal, URP",
    );
}

#[test]
fn a_gamma_project_takes_the_square_root_of_the_specular_term() {
    // Built-in gamma shaders: f0 = 0.2209 (0.04 encoded), term √(D·V·π), all on stored
    // values; the pixel is decoded at the end.
    let got = overhead(glossy(0.0, 0.5), Attenuation::BuiltIn, ColorSpace::Gamma);
    let stored =
        2.0 * (COLOUR * DIFFUSE_GAMMA + Vec3::splat(0.220_916_3 * built_in_peak(0.5).sqrt()));
    let want = stored.map(formats::srgb::gamma_to_linear);
    assert_close(got, want, 2e-4, "gamma");
}

/// The built-in pipeline's Disney diffuse under a light 60° from the normal, seen head-on:
/// (1 + (f90 − 1)·(1 − n·l)⁵) with f90 = 0.5 + (1 + l·v)·(1 − smoothness), brighter than
/// Lambert on a rough surface and darker on a smooth one; URP's is Lambert's. A legacy
/// (not physically based) material is Lambert's without the diffuse share.
#[test]
fn the_built_in_diffuse_is_disneys_and_urps_lamberts() {
    let slanted = |material: Material, pipeline: Attenuation| {
        let mut s = SceneBuilder::new();
        let m = s.material(Material {
            highlights: false,
            ..material
        });
        s.floor(0.0, 0.0, 0.0, 20.0, m);
        s.camera(top_down_camera(Vec3::new(0.0, 10.0, 0.0), 5.0));
        let travel = Vec3::new(60f32.to_radians().sin(), -60f32.to_radians().cos(), 0.0);
        s.light(formats::Light {
            attenuation: pipeline,
            ..directional_light(travel, 2.0, Shadows::None)
        });
        let (soup, kd) = s.build();
        render(&soup, &kd, &opts(8, 8)).0.frame.pixel(4, 4)
    };
    let (nl, lv) = (0.5f32, 0.5f32);
    for (smoothness, shape) in [(0.0f32, 1.03125f32), (1.0, 0.984375), (0.5, 1.0078125)] {
        let f90_less_1 = (1.0 + lv) * (1.0 - smoothness) - 0.5;
        assert!((1.0 + f90_less_1 * (1.0 - nl).powi(5) - shape).abs() < 1e-6);
        let want = 2.0 * COLOUR * DIFFUSE * nl * shape;
        let got = slanted(glossy(0.0, smoothness), Attenuation::BuiltIn);
        assert_close(
            got,
            want,
            1e-5,
            &format!("built-in, smoothness {smoothness}"),
        );
        let got = slanted(glossy(0.0, smoothness), Attenuation::Universal);
        let want = 2.0 * COLOUR * DIFFUSE * nl;
        assert_close(got, want, 1e-5, &format!("URP, smoothness {smoothness}"));
    }
    let legacy = slanted(diffuse(COLOUR), Attenuation::BuiltIn);
    assert_close(legacy, 2.0 * COLOUR * nl, 1e-5, "legacy Lambert");
}

/// Ambient light is diffuse light too: a physically based surface shows the same share of
/// its albedo under it, with or without lights in the scene; a legacy one all of it.
#[test]
fn ambient_light_takes_the_diffuse_share_of_a_physically_based_albedo() {
    let ambient = |material: Material, pipeline: Option<Attenuation>| {
        let mut s = SceneBuilder::new();
        s.soup.environment.ambient.mode = formats::AmbientMode::Flat;
        s.soup.environment.ambient.sky = Vec3::splat(0.5);
        let m = s.material(material);
        s.floor(0.0, 0.0, 0.0, 20.0, m);
        s.camera(top_down_camera(Vec3::new(0.0, 10.0, 0.0), 5.0));
        if let Some(pipeline) = pipeline {
            // A light from below the floor: it lights nothing the camera sees.
            s.light(formats::Light {
                attenuation: pipeline,
                ..directional_light(Vec3::Y, 1.0, Shadows::None)
            });
        }
        let (soup, kd) = s.build();
        render(&soup, &kd, &opts(8, 8)).0.frame.pixel(4, 4)
    };
    let pbs = glossy(0.0, 0.5);
    let want = 0.5 * COLOUR * DIFFUSE;
    assert_close(ambient(pbs.clone(), None), want, 1e-6, "no lights");
    for pipeline in [Attenuation::BuiltIn, Attenuation::Universal] {
        assert_close(ambient(pbs.clone(), Some(pipeline)), want, 1e-6, "a light");
    }
    assert_close(ambient(diffuse(COLOUR), None), 0.5 * COLOUR, 1e-6, "legacy");
}

#[test]
fn highlights_off_leave_the_diffuse_light() {
    let off = |metallic: f32| {
        let m = Material {
            highlights: false,
            ..glossy(metallic, 0.8)
        };
        overhead(m, Attenuation::BuiltIn, ColorSpace::Linear)
    };
    assert_close(off(0.0), 2.0 * COLOUR * DIFFUSE, 1e-5, "highlights off");
    let got = off(1.0);
    assert_eq!(got, Vec3::ZERO, "a metal without highlights takes no light");
}

#[test]
fn the_plan_lights_a_scene_whose_only_material_is_a_metal() {
    let plan_of = |m: Material| {
        let mut s = SceneBuilder::new();
        let m = s.material(m);
        s.floor(0.0, 0.0, 0.0, 20.0, m);
        s.camera(top_down_camera(Vec3::new(0.0, 10.0, 0.0), 5.0));
        s.light(directional_light(-Vec3::Y, 2.0, Shadows::Hard));
        let (soup, kd) = s.build();
        render(&soup, &kd, &opts(4, 4)).1
    };
    let metal = plan_of(glossy(1.0, 0.5));
    assert!(metal.direct.enabled, "{}", metal.direct.reason);
    assert!(metal.lights[0].enabled);
    assert_eq!(metal.lights[0].shadow_rays, 1);
    let black = plan_of(Material {
        color: Vec3::ZERO,
        ..glossy(1.0, 0.5)
    });
    assert!(!black.direct.enabled);
    assert_eq!(
        black.direct.reason,
        "no material shows light (each is unlit, or black and fully metallic)"
    );
    assert!(!black.lights[0].enabled);
}

/// Tracing past the smooth floor's mirror and the highlight stay free of NaN at grazing
/// light and view, with a point light and a perfectly smooth metal.
#[test]
fn grazing_light_on_a_smooth_metal_stays_finite() {
    let mut s = SceneBuilder::new();
    let m = s.material(glossy(1.0, 1.0));
    s.floor(0.0, 0.0, 0.0, 200.0, m);
    s.camera(formats::Camera {
        name: "low".into(),
        position: Vec3::new(0.0, 0.01, -50.0),
        forward: Vec3::new(0.0, -0.0002, 1.0).normalize(),
        up: Vec3::Y,
        projection: formats::Projection::Perspective { fov_y: 30.0 },
        near: 0.01,
        far: 1000.0,
    });
    s.light(point_light(
        Vec3::new(0.0, 0.001, 40.0),
        5.0,
        100.0,
        Shadows::Hard,
    ));
    s.light(directional_light(
        Vec3::new(0.0, -1e-4, -1.0),
        1.0,
        Shadows::Hard,
    ));
    let (soup, kd) = s.build();
    let (out, _) = render(&soup, &kd, &opts(32, 16));
    let lit = (0..16)
        .flat_map(|y| (0..32).map(move |x| (x, y)))
        .filter(|&(x, y)| out.frame.pixel(x, y).max_element() > 0.0)
        .count();
    assert!(lit > 0, "the metal floor shows its highlights");
}

/// Smoothness from the albedo map's alpha (Smoothness Source: Albedo Alpha): a texel of
/// alpha 128/255 under a scale of 1 gives the highlight of smoothness 128/255.
#[test]
fn smoothness_can_come_from_the_albedo_alpha() {
    let pixel = |in_alpha: bool| {
        let mut s = SceneBuilder::new();
        let t = s.texture(texture(
            1,
            1,
            &[[255, 255, 255, 128]],
            formats::texture::Wrap::Repeat,
        ));
        let m = s.material(Material {
            smoothness: 1.0,
            smoothness_in_alpha: in_alpha,
            albedo_map: Some(formats::texture::TextureRef {
                texture: t,
                tiling: formats::texture::Tiling::default(),
            }),
            ..glossy(0.0, 1.0)
        });
        overhead_in(s, m, Attenuation::BuiltIn).frame.pixel(4, 4)
    };
    let want =
        |smoothness: f32| 2.0 * (COLOUR * DIFFUSE + Vec3::splat(0.04 * built_in_peak(smoothness)));
    assert_close(pixel(true), want(128.0 / 255.0), 2e-4, "alpha 128");
    // The same material reading its smoothness of 1 as it is: Unity's floor on the
    // roughness caps a perfect mirror's head-on peak at 10.
    assert_close(pixel(false), want(1.0), 2e-4, "smoothness 1");
    assert!((0.04 * built_in_peak(1.0) - 0.4).abs() < 0.01);
}
