//! Metallic maps: each point's metallic value is its texel's red channel and its smoothness
//! the texel's alpha times the map's scale, for the diffuse light, the highlight and the
//! mirror alike; the map is read only where one of them shows.

use crate::common::*;
use crate::highlights::{built_in_peak, glossy, overhead_in, urp_peak, COLOUR, DIFFUSE};
use formats::texture::{TextureRef, Tiling, Wrap};
use formats::{Attenuation, Material, MetallicMap, Shadows};
use glam::Vec3;
use render::RenderOptions;

/// Material `m`'s metallic map: texture `t` over the whole surface, its alpha scaled by
/// `smoothness`.
fn metal_map(t: u32, smoothness: f32) -> Option<MetallicMap> {
    Some(MetallicMap {
        map: TextureRef {
            texture: t,
            tiling: Tiling::default(),
        },
        smoothness,
    })
}

/// A floor of `material` whose metallic map is one texel of red `r` and alpha `a` with
/// smoothness scale `scale`, under a directional light of intensity 2 straight down, seen
/// straight down by an 8×8 orthographic camera in a project of `pipeline`: the centre
/// pixel and the metallic texels read.
fn mapped(material: Material, r: u8, a: u8, scale: f32, pipeline: Attenuation) -> (Vec3, u64) {
    let mut s = SceneBuilder::new();
    let t = s.texture(texture(1, 1, &[[r, 0, 0, a]], Wrap::Repeat));
    let m = s.material(Material {
        metallic_map: metal_map(t, scale),
        ..material
    });
    let out = overhead_in(s, m, pipeline);
    (out.frame.pixel(4, 4), out.counts.metallic_lookups)
}

#[test]
fn the_maps_red_channel_is_metallic_and_its_alpha_times_the_scale_smoothness() {
    // The material's own metallic 1 and smoothness 0.1 are what the map replaces.
    let material = glossy(1.0, 0.1);
    let (dielectric, lookups) = mapped(material.clone(), 0, 128, 1.0, Attenuation::BuiltIn);
    let s = 128.0 / 255.0;
    let want = 2.0 * (COLOUR * DIFFUSE + Vec3::splat(0.04 * built_in_peak(s)));
    assert_close(dielectric, want, 2e-4, "metallic 0, smoothness 128/255");
    assert_eq!(lookups, 64, "one texel per pixel");

    let (metal, _) = mapped(material.clone(), 255, 255, 0.5, Attenuation::BuiltIn);
    assert_close(
        metal,
        2.0 * COLOUR * built_in_peak(0.5),
        2e-4,
        "metallic 1, smoothness 0.5",
    );

    let (half, _) = mapped(material, 128, 255, 0.5, Attenuation::Universal);
    let m = 128.0 / 255.0;
    let f0 = Vec3::splat(0.04 * (1.0 - m)) + COLOUR * m;
    assert_close(
        half,
        2.0 * (COLOUR * (1.0 - m) * DIFFUSE + f0 * urp_peak(0.5)),
        2e-3,
        "metallic 128/255, URP",
    );
}

/// Where smoothness is in the albedo map's alpha, the metallic map gives metallic alone.
#[test]
fn with_smoothness_in_the_albedo_alpha_the_map_gives_metallic_alone() {
    let mut s = SceneBuilder::new();
    let albedo = s.texture(texture(1, 1, &[[255, 255, 255, 128]], Wrap::Repeat));
    let metal = s.texture(texture(1, 1, &[[255, 0, 0, 0]], Wrap::Repeat));
    let m = s.material(Material {
        smoothness: 1.0,
        smoothness_in_alpha: true,
        albedo_map: Some(TextureRef {
            texture: albedo,
            tiling: Tiling::default(),
        }),
        metallic_map: metal_map(metal, 0.25),
        ..glossy(0.0, 1.0)
    });
    let got = overhead_in(s, m, Attenuation::BuiltIn).frame.pixel(4, 4);
    let want = 2.0 * COLOUR * built_in_peak(128.0 / 255.0);
    assert_close(got, want, 2e-4, "metal, smoothness from the albedo's alpha");
}

/// A floor whose scalar metallic is 0 mirrors a red wall through its map's metallic texels;
/// a map of dielectric texels leaves it diffuse. Without lights, ambient or mirrors the map
/// is never read.
#[test]
fn a_mapped_metal_mirrors_and_an_unseen_map_is_not_read() {
    let scene = |r: u8, lit: bool, depth: u32| {
        let mut s = SceneBuilder::new();
        let t = s.texture(texture(1, 1, &[[r, 0, 0, 255]], Wrap::Repeat));
        let floor = s.material(Material {
            metallic_map: metal_map(t, 1.0),
            ..diffuse(Vec3::ONE)
        });
        s.floor(0.0, 0.0, 0.0, 20.0, floor);
        let red = s.material(emissive(Vec3::new(1.0, 0.0, 0.0)));
        // A glowing ceiling above the camera, facing down: what the floor mirrors.
        s.quad(
            "ceiling",
            Vec3::new(-10.0, 5.0, -10.0),
            Vec3::new(20.0, 0.0, 0.0),
            Vec3::new(0.0, 0.0, 20.0),
            red,
        );
        s.camera(top_down_camera(Vec3::new(0.0, 4.0, 0.0), 2.0));
        if lit {
            s.light(directional_light(-Vec3::Y, 1.0, Shadows::None));
        }
        let (soup, kd) = s.build();
        let o = RenderOptions {
            depth,
            ..opts(4, 4)
        };
        let (out, plan) = render(&soup, &kd, &o);
        (out.frame.pixel(2, 2), out.counts.metallic_lookups, plan)
    };
    let (metal, lookups, plan) = scene(255, false, 4);
    assert!(plan.reflections.enabled, "{}", plan.reflections.reason);
    assert_close(
        metal,
        Vec3::new(1.0, 0.0, 0.0),
        1e-5,
        "the red ceiling, mirrored",
    );
    assert_eq!(lookups, 16);
    let (dielectric, _, _) = scene(0, false, 4);
    assert_eq!(dielectric, Vec3::ZERO, "no light, no mirror: black");
    let (lit, _, _) = scene(0, true, 4);
    assert_close(lit, Vec3::ONE, 1e-5, "diffuse white under light 1");
    // The same floor with no reflections asked for, no light and no ambient: nothing shows
    // what its map holds.
    let (_, lookups, plan) = scene(255, false, 0);
    assert_eq!(lookups, 0);
    assert_eq!(plan.textures.textures, 0, "{}", plan.textures.reason);
}
