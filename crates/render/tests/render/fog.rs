//! RenderSettings fog and the far clip plane: known pixel values through each fog mode,
//! per blended layer and along mirror rays, and the background left clear.

use crate::common::*;
use formats::{Alpha, Camera, Fog, FogMode, Projection};
use glam::Vec3;

const FOG: Vec3 = Vec3::new(0.4, 0.5, 0.6);
const BACKGROUND: Vec3 = Vec3::new(0.0, 0.1, 0.0);
const NEAR: f32 = 0.3;
const FAR: f32 = 1000.0;

/// A camera at the origin looking along +Z.
fn camera() -> Camera {
    Camera {
        name: "fog camera".into(),
        position: Vec3::ZERO,
        forward: Vec3::Z,
        up: Vec3::Y,
        projection: Projection::Perspective { fov_y: 60.0 },
        near: NEAR,
        far: FAR,
    }
}

/// A glowing wall facing the camera at depth `z`, `half` metres either side of the axis.
fn wall(s: &mut SceneBuilder, z: f32, half: f32, material: u32) {
    s.quad(
        "wall",
        Vec3::new(-half, -half, z),
        Vec3::new(0.0, 2.0 * half, 0.0),
        Vec3::new(2.0 * half, 0.0, 0.0),
        material,
    );
}

/// Unity's fog coordinate for a surface at depth `z` (reversed-Z clip space, remapped).
fn coordinate(z: f32) -> f32 {
    FAR * (z - NEAR) / (FAR - NEAR)
}

fn fogged(l: Vec3, keep: f32) -> Vec3 {
    FOG + (l - FOG) * keep
}

fn scene_with(fog: Option<Fog>) -> SceneBuilder {
    let mut s = SceneBuilder::new();
    s.camera(camera());
    s.soup.environment.background = BACKGROUND;
    s.soup.environment.fog = fog;
    s
}

#[test]
fn each_fog_mode_mixes_a_surface_by_its_depth_and_leaves_the_background_clear() {
    let e = Vec3::new(2.0, 1.0, 0.5);
    let c = coordinate(10.0);
    let modes = [
        (FogMode::Exponential { density: 0.1 }, (-0.1 * c).exp()),
        (
            FogMode::ExponentialSquared { density: 0.1 },
            (-(0.1 * c) * (0.1 * c)).exp(),
        ),
        (
            FogMode::Linear {
                start: 2.0,
                end: 20.0,
            },
            (20.0 - c) / 18.0,
        ),
    ];
    for (mode, keep) in modes {
        let mut s = scene_with(Some(Fog { mode, colour: FOG }));
        let glow = s.material(emissive(e));
        // Every pixel of a wall square to the view is at depth 10, however oblique its ray.
        wall(&mut s, 10.0, 4.0, glow);
        let (soup, kd) = s.build();
        let out = render_alike_at_tiles(&soup, &kd, &opts(40, 40));
        let want = fogged(e, keep);
        let mut seen = 0u64;
        for (x, y) in [(20, 20), (10, 10), (29, 25)] {
            assert_close(out.frame.pixel(x, y), want, 1e-5, &format!("{mode:?}"));
        }
        for y in 0..40 {
            for x in 0..40 {
                let p = out.frame.pixel(x, y);
                if p == BACKGROUND {
                    continue;
                }
                assert_close(p, want, 1e-5, &format!("{mode:?} at ({x}, {y})"));
                seen += 1;
            }
        }
        assert!(
            out.frame.pixel(0, 0) == BACKGROUND,
            "the background is not fogged"
        );
        assert!(seen > 100 && seen < 1600, "{seen} pixels see the wall");
        assert_eq!(
            out.counts.fogged, seen,
            "one fogged hit per pixel on the wall"
        );
    }
}

#[test]
fn without_fog_or_with_none_to_see_the_plan_is_off_and_pixels_unchanged() {
    let e = Vec3::new(2.0, 1.0, 0.5);
    let frame = |fog: Option<Fog>| {
        let mut s = scene_with(fog);
        let glow = s.material(emissive(e));
        wall(&mut s, 10.0, 2.0, glow);
        let (soup, kd) = s.build();
        let (out, plan) = render(&soup, &kd, &opts(24, 24));
        assert_eq!(out.counts.fogged, 0);
        (out.frame, plan.fog.enabled)
    };
    let (clear, on) = frame(None);
    assert!(!on);
    assert_eq!(clear.pixel(12, 12), e);
    for mode in [
        FogMode::Exponential { density: 0.0 },
        FogMode::ExponentialSquared { density: 0.0 },
        FogMode::Exponential { density: -0.5 },
    ] {
        let (f, on) = frame(Some(Fog { mode, colour: FOG }));
        assert!(!on, "{mode:?}");
        assert_eq!(f, clear, "{mode:?}");
    }
}

#[test]
fn each_blended_layer_is_fogged_by_its_own_depth() {
    let (front, back) = (Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 0.0, 3.0));
    let mode = FogMode::Exponential { density: 0.05 };
    let mut s = scene_with(Some(Fog { mode, colour: FOG }));
    let glass = s.material(formats::Material {
        opacity: 0.5,
        alpha: Alpha::Blend,
        ..emissive(front)
    });
    let glow = s.material(emissive(back));
    wall(&mut s, 5.0, 1.0, glass);
    wall(&mut s, 10.0, 3.0, glow);
    let (soup, kd) = s.build();
    let out = render_alike_at_tiles(&soup, &kd, &opts(41, 41));
    let keep = |z: f32| (-0.05 * coordinate(z)).exp();
    let want = fogged(front, keep(5.0)) * 0.5 + fogged(back, keep(10.0)) * 0.5;
    assert_close(out.frame.pixel(20, 20), want, 1e-5, "through the glass");
}

#[test]
fn a_mirror_fogs_its_reflection_by_the_reflected_ray_and_itself_by_its_depth() {
    let e = Vec3::new(0.0, 2.0, 1.0);
    let mode = FogMode::ExponentialSquared { density: 0.08 };
    let mut s = scene_with(Some(Fog { mode, colour: FOG }));
    let m = s.material(mirror(0.8));
    let glow = s.material(emissive(e));
    // The mirror 5 m ahead; behind the camera, out of its view, a glowing wall facing it.
    wall(&mut s, 5.0, 2.0, m);
    wall(&mut s, -5.0, 20.0, glow);
    let (soup, kd) = s.build();
    // The centre pixel of an odd image looks straight ahead: it meets the mirror at depth
    // 5 and its reflection travels 10 m back to the wall.
    let out = render_alike_at_tiles(&soup, &kd, &opts(41, 41));
    let keep = |c: f32| (-(0.08 * c) * (0.08 * c)).exp();
    let reflected = fogged(e, keep(10.0));
    let want = fogged(reflected * 0.8, keep(coordinate(5.0)));
    assert_close(out.frame.pixel(20, 20), want, 1e-4, "the mirror's centre");
}

#[test]
fn the_far_plane_hides_what_lies_beyond_it() {
    let e = Vec3::new(1.0, 2.0, 3.0);
    for ortho in [false, true] {
        let see = |far: f32| {
            let mut s = SceneBuilder::new();
            s.camera(Camera {
                far,
                projection: if ortho {
                    Projection::Orthographic { half_height: 5.0 }
                } else {
                    Projection::Perspective { fov_y: 60.0 }
                },
                ..camera()
            });
            s.soup.environment.background = BACKGROUND;
            let glow = s.material(emissive(e));
            wall(&mut s, 50.0, 100.0, glow);
            let (soup, kd) = s.build();
            let (out, _) = render(&soup, &kd, &opts(16, 16));
            // A corner pixel's ray is oblique: the plane is at 50 along the view there too.
            [out.frame.pixel(8, 8), out.frame.pixel(0, 0)]
        };
        assert_eq!(see(49.9), [BACKGROUND; 2], "ortho {ortho}");
        assert_eq!(see(50.1), [e; 2], "ortho {ortho}");
        // A far plane not beyond the near one sets no limit.
        assert_eq!(see(0.1), [e; 2], "ortho {ortho}");
    }
}
