//! Pixel values where the answer is known: the lighting formula, shadows, mirrors, image
//! orientation, spot cones, directional cosines, ambient and emission.

use crate::common::*;
use formats::{AmbientMode, Camera, Projection, Shadows};
use glam::Vec3;
use render::plan::ShadowMode;

const ALBEDO: Vec3 = Vec3::new(0.8, 0.6, 0.4);

/// Floor at y = 0 seen from above by an orthographic camera (pixel = 0.25 m).
fn floor_scene() -> SceneBuilder {
    let mut s = SceneBuilder::new();
    let m = s.diffuse(ALBEDO);
    s.floor(0.0, 0.0, 0.0, 20.0, m);
    s.camera(top_down_camera(Vec3::new(0.0, 10.0, 0.0), 5.0));
    s
}

/// The floor under a point light 2 m up (intensity 1.5, range 6) with `attenuation`,
/// 40 × 40 pixels, each held to albedo · 1.5 · `falloff(d)` · cos within 0.01; the
/// plan names the light `kind`. Returns the frame and the camera that took it.
fn floor_under_a_point_light(
    attenuation: formats::Attenuation,
    kind: &str,
    falloff: impl Fn(f32) -> f32,
) -> (render::Rendered, Camera) {
    let mut s = floor_scene();
    s.light(formats::Light {
        attenuation,
        ..point_light(LAMP, 1.5, 6.0, Shadows::Hard)
    });
    let (soup, kd) = s.build();
    let (w, h) = (40, 40);
    let (out, plan) = render(&soup, &kd, &opts(w, h));
    assert_eq!(plan.lights[0].kind, kind);
    let mut lit = 0;
    for py in 0..h {
        for px in 0..w {
            let p = ortho_point(&soup.camera, w, h, px, py, 0.0);
            let to = LAMP - p;
            let d = to.length();
            let want = ALBEDO * 1.5 * falloff(d) * (to.y / d);
            assert_close(
                out.frame.pixel(px, py),
                want,
                0.01,
                &format!("pixel ({px}, {py})"),
            );
            if want.x > 0.0 {
                lit += 1;
            }
        }
    }
    // The range (6 m from a light 2 m up) ends inside the view: both cases are checked.
    assert!(lit > 100 && lit < (w * h) as usize, "{lit} lit pixels");
    (out, soup.camera)
}

/// Where the point light of [`floor_under_a_point_light`] hangs.
const LAMP: Vec3 = Vec3::new(1.0, 2.0, 0.5);

#[test]
fn a_plane_lit_by_one_point_light_matches_the_formula() {
    floor_under_a_point_light(formats::Attenuation::BuiltIn, "point", |d| {
        unity_falloff(d, 6.0)
    });
}

#[test]
fn a_urp_point_light_follows_the_inverse_square_law_to_its_range() {
    let (out, camera) =
        floor_under_a_point_light(formats::Attenuation::Universal, "point, URP falloff", |d| {
            (1.0 - (d * d / 36.0).powi(2)).max(0.0).powi(2) / (d * d)
        });
    // Below the light the two pipelines differ by more than the tolerance above.
    let below = out.frame.pixel(24, 22);
    let p = ortho_point(&camera, 40, 40, 24, 22, 0.0);
    let d = (LAMP - p).length();
    let built_in = ALBEDO * 1.5 * unity_falloff(d, 6.0) * (LAMP.y - p.y) / d;
    assert!((below.x - built_in.x).abs() > 0.02, "{below} vs {built_in}");
}

#[test]
fn a_shadowed_point_is_dark_and_lit_without_shadows() {
    for shadows in [Shadows::Hard, Shadows::None] {
        let mut s = floor_scene();
        // The light at (3, 4, 0) throws the occluder's shadow (x ∈ [1, 2] at y = 2)
        // onto x ∈ [−1, 1] of the floor.
        let m = s.diffuse(Vec3::ONE);
        s.quad(
            "occluder",
            Vec3::new(1.0, 2.0, -1.0),
            Vec3::new(0.0, 0.0, 2.0),
            Vec3::new(1.0, 0.0, 0.0),
            m,
        );
        let light_pos = Vec3::new(3.0, 4.0, 0.0);
        s.light(point_light(light_pos, 1.0, 20.0, shadows));
        let (soup, kd) = s.build();
        let (out, _) = render(&soup, &kd, &opts(40, 40));
        let p = ortho_point(&soup.camera, 40, 40, 20, 20, 0.0);
        assert!(p.x.abs() < 0.2 && p.z.abs() < 0.2);
        let got = out.frame.pixel(20, 20);
        let to = light_pos - p;
        let d = to.length();
        let lit = ALBEDO * unity_falloff(d, 20.0) * (to.y / d);
        match shadows {
            Shadows::Hard => assert_eq!(
                got,
                Vec3::ZERO,
                "the shadowed point must get no direct light"
            ),
            _ => assert_close(got, lit, 0.01, "without shadows the point is lit"),
        }
        // A floor point outside the shadow is lit either way (x = −3: pixel column 7).
        let q = ortho_point(&soup.camera, 40, 40, 7, 20, 0.0);
        assert!(q.x > 1.5 || q.x < -1.5, "{q}");
        let to = light_pos - q;
        let want = ALBEDO * unity_falloff(to.length(), 20.0) * (to.y / to.length());
        assert_close(out.frame.pixel(7, 20), want, 0.01, "unshadowed floor");
    }
}

/// An unlit surface shows its colour as it is, whatever the light, and casts no shadow:
/// the floor under it is lit as if it were not there.
#[test]
fn an_unlit_surface_shows_its_colour_and_casts_no_shadow() {
    let mut s = floor_scene();
    let colour = Vec3::new(0.3, 0.5, 0.7);
    let m = s.material(formats::Material {
        unlit: true,
        metallic: 0.5,
        ..diffuse(colour)
    });
    s.quad(
        "unlit",
        Vec3::new(1.0, 2.0, -1.0),
        Vec3::new(0.0, 0.0, 2.0),
        Vec3::new(1.0, 0.0, 0.0),
        m,
    );
    let light_pos = Vec3::new(3.0, 4.0, 0.0);
    s.light(point_light(light_pos, 1.0, 20.0, Shadows::Hard));
    let (soup, kd) = s.build();
    let (out, plan) = render(&soup, &kd, &opts(40, 40));
    assert_eq!(plan.shadow_casting.unlit_materials, 1);
    assert!(plan.shadow_casting.enabled && plan.direct.enabled);
    // Where the lit quad of the test above throws its shadow, the floor is lit.
    let p = ortho_point(&soup.camera, 40, 40, 20, 20, 0.0);
    let to = light_pos - p;
    let d = to.length();
    let lit = ALBEDO * unity_falloff(d, 20.0) * (to.y / d);
    assert_close(
        out.frame.pixel(20, 20),
        lit,
        1e-4,
        "floor under the unlit quad",
    );
    // The quad (x 1–2, so pixel column 13) shows its colour: no light, metal or shading.
    let q = ortho_point(&soup.camera, 40, 40, 13, 20, 0.0);
    assert!(q.x > 1.0 && q.x < 2.0, "{q}");
    assert_eq!(out.frame.pixel(13, 20), colour);
}

/// A shadow of strength s takes s of the light it blocks away, hard or soft, one ray at a
/// time or in packets; at strength 0 no shadow ray is traced.
#[test]
fn shadow_strength_lets_the_rest_of_the_light_through() {
    for shadows in [Shadows::Hard, Shadows::Soft] {
        for strength in [1.0, 0.6, 0.0] {
            let mut s = floor_scene();
            let m = s.diffuse(Vec3::ONE);
            // The occluder of the test above, wide enough that the soft light's disc is
            // wholly hidden from the floor's centre too.
            s.quad(
                "occluder",
                Vec3::new(0.5, 2.0, -2.0),
                Vec3::new(0.0, 0.0, 4.0),
                Vec3::new(2.0, 0.0, 0.0),
                m,
            );
            let light_pos = Vec3::new(3.0, 4.0, 0.0);
            s.light(formats::Light {
                shadow_strength: strength,
                shadow_radius: 0.05,
                ..point_light(light_pos, 1.0, 20.0, shadows)
            });
            let (soup, kd) = s.build();
            let out = render_alike_at_tiles(&soup, &kd, &opts(40, 40));
            let (_, plan) = render(&soup, &kd, &opts(4, 4));
            let p = ortho_point(&soup.camera, 40, 40, 20, 20, 0.0);
            let to = light_pos - p;
            let d = to.length();
            let lit = ALBEDO * unity_falloff(d, 20.0) * (to.y / d);
            let got = out.frame.pixel(20, 20);
            let what = format!("{shadows:?} at strength {strength}");
            if strength == 1.0 {
                assert_eq!(got, Vec3::ZERO, "{what}");
            } else {
                assert_close(got, lit * (1.0 - strength), 0.01, &what);
            }
            let traced = out.counts.shadow + out.counts.soft_shadow;
            assert_eq!(traced == 0, strength == 0.0, "{what}: {traced} shadow rays");
            assert_eq!(
                plan.lights[0].shadows == ShadowMode::None,
                strength == 0.0,
                "{what}: {}",
                plan.lights[0].reason
            );
        }
    }
}

/// A camera at (0, 1, −5) looking at a mirror at z = 0; behind the camera, at z = −10,
/// a red emitter that the camera cannot see directly.
fn mirror_scene(reflectivity: f32) -> SceneBuilder {
    let mut s = SceneBuilder::new();
    let mirror_m = s.material(mirror(reflectivity));
    s.quad(
        "mirror",
        Vec3::new(-3.0, -2.0, 0.0),
        Vec3::new(0.0, 6.0, 0.0),
        Vec3::new(6.0, 0.0, 0.0),
        mirror_m,
    );
    let red = s.material(emissive(Vec3::new(1.0, 0.0, 0.0)));
    s.quad(
        "red wall",
        Vec3::new(-10.0, -9.0, -10.0),
        Vec3::new(20.0, 0.0, 0.0),
        Vec3::new(0.0, 20.0, 0.0),
        red,
    );
    s.camera(Camera {
        name: "cam".into(),
        position: Vec3::new(0.0, 1.0, -5.0),
        forward: Vec3::Z,
        up: Vec3::Y,
        projection: Projection::Perspective { fov_y: 40.0 },
        near: 0.3,
        far: f32::INFINITY,
    });
    s
}

#[test]
fn a_mirror_shows_the_colour_behind_the_camera() {
    let (soup, kd) = mirror_scene(1.0).build();
    let (out, plan) = render(&soup, &kd, &opts(32, 24));
    assert!(plan.reflections.enabled);
    assert_close(
        out.frame.pixel(16, 12),
        Vec3::new(1.0, 0.0, 0.0),
        1e-5,
        "mirror centre",
    );
    assert_eq!(
        out.counts.reflection,
        32 * 24,
        "one reflection ray per mirror pixel"
    );

    // Half a mirror shows half the red.
    let (soup, kd) = mirror_scene(0.5).build();
    let (out, _) = render(&soup, &kd, &opts(32, 24));
    assert_close(
        out.frame.pixel(16, 12),
        Vec3::new(0.5, 0.0, 0.0),
        1e-5,
        "50% mirror",
    );

    // Depth 0: no reflection rays, the mirror (albedo 0) is black.
    let (soup, kd) = mirror_scene(1.0).build();
    let mut o = opts(32, 24);
    o.depth = 0;
    let (out, plan) = render(&soup, &kd, &o);
    assert!(!plan.reflections.enabled);
    assert_eq!(out.counts.reflection, 0);
    assert_eq!(out.frame.pixel(16, 12), Vec3::ZERO);
}

#[test]
fn an_object_at_camera_right_lands_in_the_right_half() {
    let mut s = SceneBuilder::new();
    let cam = Camera::default();
    let centre = cam.position + cam.forward * 5.0 + cam.right() * 1.5;
    let m = s.material(emissive(Vec3::ONE));
    s.quad(
        "marker",
        centre - Vec3::new(0.5, 0.5, 0.0),
        Vec3::Y,
        Vec3::X,
        m,
    );
    s.camera(cam);
    let (soup, kd) = s.build();
    let (w, h) = (64, 32);
    let (out, _) = render(&soup, &kd, &opts(w, h));
    let mut lit = Vec::new();
    for y in 0..h {
        for x in 0..w {
            if out.frame.pixel(x, y).x > 0.5 {
                lit.push((x, y));
            }
        }
    }
    assert!(!lit.is_empty());
    assert!(
        lit.iter().all(|&(x, _)| x >= w / 2),
        "marker pixels {lit:?}"
    );
    // Camera right is −X in the soup (forward +Z × up +Y): the marker is at x < 0.
    assert!(centre.x < 0.0);
}

#[test]
fn a_spot_cone_ends_at_half_its_angle() {
    let spot_pos = Vec3::new(0.0, 4.0, 0.0);
    let (w, h) = (80, 80);
    for (angle, inner) in [(60.0f32, 60.0f32), (60.0, 40.0)] {
        let mut s = floor_scene();
        s.light(spot_light(spot_pos, -Vec3::Y, angle, inner, 30.0));
        let (soup, kd) = s.build();
        let (out, _) = render(&soup, &kd, &opts(w, h));
        let (mut inside, mut outside, mut edge) = (0, 0, 0);
        for py in 0..h {
            for px in 0..w {
                let p = ortho_point(&soup.camera, w, h, px, py, 0.0);
                let to = spot_pos - p;
                let d = to.length();
                let theta = (to.y / d).acos().to_degrees();
                let lit = ALBEDO * unity_falloff(d, 30.0) * (to.y / d);
                let got = out.frame.pixel(px, py);
                if theta > angle / 2.0 + 0.3 {
                    assert_eq!(got, Vec3::ZERO, "θ = {theta}° is outside the {angle}° cone");
                    outside += 1;
                } else if theta < inner / 2.0 - 0.3 {
                    assert_close(got, lit, 0.01, &format!("θ = {theta}° inside the core"));
                    inside += 1;
                } else if theta > inner / 2.0 + 0.3 && theta < angle / 2.0 - 0.3 {
                    // Smooth edge: smoothstep on cos θ between the two half-angles.
                    let (co, ci) = (
                        (angle / 2.0).to_radians().cos(),
                        (inner / 2.0).to_radians().cos(),
                    );
                    let t = ((theta.to_radians().cos() - co) / (ci - co)).clamp(0.0, 1.0);
                    assert_close(
                        got,
                        lit * (t * t * (3.0 - 2.0 * t)),
                        0.01,
                        &format!("θ = {theta}° on the edge"),
                    );
                    edge += 1;
                }
            }
        }
        assert!(
            inside > 50 && outside > 50,
            "{inside} inside, {outside} outside"
        );
        if inner < angle {
            assert!(edge > 50, "{edge} pixels on the smooth edge");
        }
    }
}

#[test]
fn a_directional_light_shades_by_the_cosine() {
    for deg in [0.0f32, 30.0, 60.0, 85.0] {
        let mut s = floor_scene();
        let r = deg.to_radians();
        s.light(directional_light(
            Vec3::new(r.sin(), -r.cos(), 0.0),
            2.0,
            Shadows::Hard,
        ));
        let (soup, kd) = s.build();
        let (out, _) = render(&soup, &kd, &opts(16, 16));
        let want = ALBEDO * 2.0 * r.cos();
        for (x, y) in [(0, 0), (8, 8), (15, 3)] {
            assert_close(
                out.frame.pixel(x, y),
                want,
                1e-4,
                &format!("{deg}° at ({x}, {y})"),
            );
        }
    }
}

/// A procedural sky, bluish, its sun 30° up.
fn bluish_sky() -> formats::ProceduralSky {
    formats::ProceduralSky {
        sun_disk: formats::SunDisk::HighQuality,
        sun_size: 0.04,
        sun_size_convergence: 5.0,
        atmosphere_thickness: 1.0,
        exposure: 1.3,
        sky_tint: Vec3::splat(0.214),
        ground: Vec3::splat(0.11),
        sun_direction: Vec3::new(0.0, 0.5, 1.0).normalize(),
        sun_colour: Vec3::ONE,
    }
}

/// The floor under [`bluish_sky`], lit by its Skybox ambient light `intensity` times (black
/// gradient colours), in a project of colour space `space`.
fn floor_in_skybox_ambient(
    intensity: f32,
    space: formats::ColorSpace,
) -> (formats::Soup, formats::KdFile) {
    let mut s = floor_scene();
    s.soup.environment.color_space = space;
    s.soup.environment.sky = Some(formats::Sky::Procedural(bluish_sky()));
    s.soup.environment.ambient = formats::Ambient {
        mode: AmbientMode::Skybox,
        sky: Vec3::ZERO,
        equator: Vec3::ZERO,
        ground: Vec3::ZERO,
        intensity,
    };
    s.build()
}

/// Unity's sRGB decoding of a gamma-space frame's value in [0, 1].
fn srgb_decode(v: f32) -> f32 {
    if v <= 0.04045 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

/// In a gamma-space project the shaders light the stored colours and the frame holds what
/// the display shows: each pixel is the sRGB decoding of albedo · intensity · cos, so the
/// light falls off with the cosine far faster than in a linear project; a procedural sky
/// shows the square root of its light, and its ambient light is projected from that.
#[test]
fn a_gamma_space_frame_is_lit_on_stored_values_and_decoded() {
    for deg in [0.0f32, 60.0] {
        let mut s = floor_scene();
        s.soup.environment.color_space = formats::ColorSpace::Gamma;
        let r = deg.to_radians();
        s.light(directional_light(
            Vec3::new(r.sin(), -r.cos(), 0.0),
            1.2,
            Shadows::Hard,
        ));
        let (soup, kd) = s.build();
        let (w, h) = (16, 16);
        let o = render::RenderOptions {
            aovs: render::AovSet::parse("albedo").unwrap(),
            ..opts(w, h)
        };
        let out = render_alike_at_tiles(&soup, &kd, &o);
        let stored = ALBEDO * 1.2 * r.cos();
        let want = stored.map(srgb_decode);
        for (x, y) in [(0, 0), (8, 8), (15, 3)] {
            assert_close(
                out.frame.pixel(x, y),
                want,
                1e-6,
                &format!("{deg}° at ({x}, {y})"),
            );
            let i = out.frame.index(x, y).unwrap();
            assert_close(
                out.frame.albedo[i],
                ALBEDO.map(srgb_decode),
                1e-6,
                "albedo AOV",
            );
        }
    }
    let sky = bluish_sky();
    let (soup, kd) = floor_in_skybox_ambient(1.0, formats::ColorSpace::Gamma);
    let (out, _) = render(&soup, &kd, &opts(8, 8));
    let gamma = render::sky::SkyModel::new(sky).in_space(formats::ColorSpace::Gamma);
    let want = (ALBEDO * gamma.ambient(1.0).at(Vec3::Y)).map(srgb_decode);
    assert_close(
        out.frame.pixel(4, 4),
        want,
        1e-6,
        "the floor in gamma skybox ambient",
    );
    // The gamma sky writes √ of the linear one's light.
    let linear = render::sky::SkyModel::new(sky);
    let up = Vec3::new(0.0, 0.8, 0.6).normalize();
    let (g, l) = (gamma.radiance(up), linear.radiance(up));
    assert!((g - l.map(f32::sqrt)).abs().max_element() < 1e-6, "{g} {l}");
}

#[test]
fn ambient_lights_a_face_no_light_reaches() {
    for ambient_on in [false, true] {
        let mut s = SceneBuilder::new();
        let m = s.diffuse(Vec3::new(0.5, 0.5, 0.5));
        s.cube(
            "box",
            Vec3::new(-1.0, 0.0, -1.0),
            Vec3::new(1.0, 2.0, 1.0),
            m,
        );
        // The sun shines straight down: the box's −Z side face gets no direct light.
        s.light(directional_light(-Vec3::Y, 1.0, Shadows::Hard));
        s.camera(Camera {
            name: "front".into(),
            position: Vec3::new(0.0, 1.0, -6.0),
            forward: Vec3::Z,
            up: Vec3::Y,
            projection: Projection::Perspective { fov_y: 30.0 },
            near: 0.3,
            far: f32::INFINITY,
        });
        if ambient_on {
            s.soup.environment.ambient = formats::Ambient {
                mode: AmbientMode::Trilight,
                sky: Vec3::new(0.4, 0.4, 0.6),
                equator: Vec3::new(0.2, 0.1, 0.05),
                ground: Vec3::new(0.05, 0.05, 0.05),
                intensity: 1.0,
            };
        }
        let (soup, kd) = s.build();
        let (out, plan) = render(&soup, &kd, &opts(20, 20));
        assert_eq!(plan.ambient.enabled, ambient_on);
        let got = out.frame.pixel(10, 10);
        if ambient_on {
            // A vertical face (n.y = 0) gets the equator colour.
            assert_close(
                got,
                Vec3::new(0.1, 0.05, 0.025),
                1e-5,
                "ambient on the side face",
            );
        } else {
            assert_eq!(got, Vec3::ZERO, "nothing lights the side face");
        }
    }
}

#[test]
fn flat_ambient_and_a_face_turned_down_get_their_colours() {
    let mut s = SceneBuilder::new();
    let m = s.diffuse(Vec3::ONE);
    // Seen from below: the floor's underside faces −Y (the ground colour in trilight).
    s.floor(0.0, 0.0, 0.0, 20.0, m);
    s.camera(Camera {
        name: "below".into(),
        position: Vec3::new(0.0, -5.0, 0.0),
        forward: Vec3::Y,
        up: Vec3::Z,
        projection: Projection::Orthographic { half_height: 2.0 },
        near: 0.0,
        far: f32::INFINITY,
    });
    let ground = Vec3::new(0.03, 0.02, 0.01);
    s.soup.environment.ambient = formats::Ambient {
        mode: AmbientMode::Trilight,
        sky: Vec3::ONE,
        equator: Vec3::splat(0.5),
        ground,
        intensity: 1.0,
    };
    let (soup, kd) = s.build();
    let (out, _) = render(&soup, &kd, &opts(8, 8));
    assert_close(
        out.frame.pixel(4, 4),
        ground,
        1e-5,
        "underside gets the ground colour",
    );

    let mut soup = soup;
    soup.environment.ambient.mode = AmbientMode::Flat;
    let (out, _) = render(&soup, &kd, &opts(8, 8));
    assert_close(
        out.frame.pixel(4, 4),
        Vec3::ONE,
        1e-5,
        "flat ambient is the sky colour",
    );
}

#[test]
fn emission_is_added_where_the_material_emits() {
    let e = Vec3::new(2.0, 1.0, 0.5);
    let mut s = floor_scene();
    let glow = s.material(emissive(e));
    s.quad(
        "panel",
        Vec3::new(-1.0, 1.0, -1.0),
        Vec3::new(0.0, 0.0, 2.0),
        Vec3::new(2.0, 0.0, 0.0),
        glow,
    );
    let (soup, kd) = s.build();
    let (out, plan) = render(&soup, &kd, &opts(40, 40));
    assert!(plan.emission.enabled);
    assert_eq!(out.frame.pixel(20, 20), e);
    assert_eq!(
        out.frame.pixel(2, 2),
        Vec3::ZERO,
        "the unlit floor stays black"
    );

    let mut soup = soup;
    soup.materials[glow as usize].emission = Vec3::ZERO;
    let (out, plan) = render(&soup, &kd, &opts(40, 40));
    assert!(!plan.emission.enabled);
    assert_eq!(out.frame.pixel(20, 20), Vec3::ZERO);
}

#[test]
fn the_background_is_the_clear_colour_or_a_sky() {
    let mut s = SceneBuilder::new();
    s.soup.environment.background = Vec3::new(0.1, 0.2, 0.3);
    let m = s.diffuse(Vec3::ONE);
    s.floor(-100.0, 0.0, 0.0, 1.0, m);
    let (soup, kd) = s.build();
    let (out, _) = render(&soup, &kd, &opts(8, 8));
    assert_eq!(out.frame.pixel(3, 3), Vec3::new(0.1, 0.2, 0.3));

    let mut soup = soup;
    soup.environment.clear = formats::ClearFlags::Skybox;
    let (out, _) = render(&soup, &kd, &opts(8, 64));
    // The default camera looks at the horizon: brighter than the zenith-ward top row,
    // and the top row is bluer than it is red.
    let top = out.frame.pixel(4, 0);
    assert!(top.z > top.x, "{top}");
    assert_ne!(top, out.frame.pixel(4, 63));

    // With a procedural sky each background pixel is that sky along its camera ray, in
    // single rays and in packets alike.
    let sky = bluish_sky();
    soup.environment.sky = Some(formats::Sky::Procedural(sky));
    let out = render_alike_at_tiles(&soup, &kd, &opts(8, 64));
    let camera = render::CameraModel::new(&soup.camera, 8, 64).unwrap();
    let model = render::sky::SkyModel::new(sky);
    for (x, y) in [(4, 0), (2, 40), (7, 63)] {
        let dir = camera.ray(x as f32 + 0.5, y as f32 + 0.5).dir;
        assert_eq!(out.frame.pixel(x, y), model.radiance(dir), "({x}, {y})");
    }
    assert!(out.frame.pixel(4, 0).z > out.frame.pixel(4, 0).x);
}

/// Skybox ambient under a procedural sky is that sky's light, whatever the stored
/// gradient colours say, scaled by the ambient intensity; the camera may clear to a colour.
#[test]
fn skybox_ambient_is_the_procedural_skys_light() {
    let sky = bluish_sky();
    let (soup, kd) = floor_in_skybox_ambient(1.5, formats::ColorSpace::Linear);
    let (out, plan) = render(&soup, &kd, &opts(8, 8));
    assert!(plan.ambient.enabled, "{}", plan.ambient.reason);
    let want = ALBEDO * render::sky::SkyModel::new(sky).ambient(1.5).at(Vec3::Y);
    assert_close(out.frame.pixel(4, 4), want, 1e-6, "the floor under the sky");
    assert!(
        want.z > want.x && want.x > 0.05,
        "a bluish sky's light: {want}"
    );
}

/// Nothing in view but `sky`, shown by a Skybox camera (a small floor far below keeps the
/// tree non-empty).
fn sky_scene(sky: &formats::TexturedSky) -> (formats::Soup, formats::KdFile) {
    let mut s = SceneBuilder::new();
    let m = s.diffuse(Vec3::ONE);
    s.floor(-100.0, 0.0, 0.0, 1.0, m);
    let (mut soup, kd) = s.build();
    soup.environment.clear = formats::ClearFlags::Skybox;
    soup.environment.sky = Some(formats::Sky::Textured(sky.clone()));
    (soup, kd)
}

/// A sky from images: each background pixel is the image sky along its camera ray (single
/// rays and packets alike), the plan names the image, and Skybox ambient under a uniform
/// image is that image's radiance times the tint, exposure and ambient intensity.
#[test]
fn an_image_sky_is_the_background_and_the_skybox_ambient() {
    use formats::{Panorama, Sky, SkyImage, SkyLayout, TexturedSky};
    let rgb: Vec<Vec3> = (0..64 * 32)
        .map(|i| Vec3::new((i % 64) as f32, (i / 64) as f32, 1.0) * 0.25)
        .collect();
    let gradient = TexturedSky {
        scale: Vec3::new(0.98, 0.9, 1.1),
        rotation: 40.0,
        layout: SkyLayout::LatLong {
            image: SkyImage::from_linear("Assets/Sky.hdr", 64, 32, &rgb),
            panorama: Panorama::Full,
        },
    };
    let (soup, kd) = sky_scene(&gradient);
    let out = render_alike_at_tiles(&soup, &kd, &opts(16, 16));
    let camera = render::CameraModel::new(&soup.camera, 16, 16).unwrap();
    let model = render::sky_image::ImageSky::new(&gradient);
    for (x, y) in [(0, 0), (8, 3), (15, 15), (3, 12)] {
        let dir = camera.ray(x as f32 + 0.5, y as f32 + 0.5).dir;
        assert_eq!(out.frame.pixel(x, y), model.radiance(dir), "({x}, {y})");
    }
    // Higher rows of the image are higher in the sky.
    assert!(out.frame.pixel(8, 0).y > out.frame.pixel(8, 15).y);
    let (_, plan) = render(&soup, &kd, &opts(4, 4));
    assert!(
        plan.background
            .starts_with("latitude-longitude sky Assets/Sky.hdr (64x32)"),
        "{}",
        plan.background
    );

    let l = Vec3::new(0.5, 1.0, 2.0);
    let uniform = TexturedSky {
        scale: Vec3::splat(0.98),
        rotation: 0.0,
        layout: SkyLayout::Cube {
            faces: vec![SkyImage::from_linear("f", 8, 8, &[l; 64]); 6],
        },
    };
    let mut s = floor_scene();
    s.soup.environment.sky = Some(Sky::Textured(uniform));
    s.soup.environment.ambient = formats::Ambient {
        mode: AmbientMode::Skybox,
        sky: Vec3::ZERO,
        equator: Vec3::ZERO,
        ground: Vec3::ZERO,
        intensity: 1.5,
    };
    let (soup, kd) = s.build();
    let (out, plan) = render(&soup, &kd, &opts(8, 8));
    assert!(plan.ambient.enabled, "{}", plan.ambient.reason);
    assert_close(
        out.frame.pixel(4, 4),
        ALBEDO * l * 0.98 * 1.5,
        5e-3,
        "the floor under a uniform sky",
    );
}

/// A panorama of one-texel columns alternating 0 and 2, seen by a camera whose pixels
/// each span about 2.7 texels: every background pixel is their mean, 1 (times the tint),
/// where a lookup in the full-size image along the pixel's ray reads 0 or 2.
#[test]
fn an_image_sky_seen_small_is_filtered_not_aliased() {
    use formats::{Panorama, SkyImage, SkyLayout, TexturedSky};
    let (w, h) = (512u32, 256u32);
    let rgb: Vec<Vec3> = (0..w * h)
        .map(|i| Vec3::splat(if i % 2 == 0 { 0.0 } else { 2.0 }))
        .collect();
    let striped = TexturedSky {
        scale: Vec3::new(0.98, 0.9, 1.1),
        rotation: 0.0,
        layout: SkyLayout::LatLong {
            image: SkyImage::from_linear("Assets/Stripes.hdr", w, h, &rgb),
            panorama: Panorama::Full,
        },
    };
    let (soup, kd) = sky_scene(&striped);
    let out = render_alike_at_tiles(&soup, &kd, &opts(32, 32));
    let camera = render::CameraModel::new(&soup.camera, 32, 32).unwrap();
    let full_size = render::sky_image::ImageSky::new(&striped);
    let mut aliased = 0;
    for y in 0..32 {
        for x in 0..32 {
            let got = out.frame.pixel(x, y);
            assert_close(got, striped.scale, 1e-5, "a background pixel");
            let dir = camera.ray(x as f32 + 0.5, y as f32 + 0.5).dir;
            let l = full_size.radiance(dir);
            aliased += usize::from((l - striped.scale).abs().max_element() > 0.5);
        }
    }
    assert!(
        aliased > 500,
        "unfiltered, {aliased} of 1,024 pixels would be off by half"
    );
}

#[test]
fn an_orthographic_camera_spans_its_half_height() {
    // An emitter filling exactly the upper half of the orthographic view.
    let mut s = SceneBuilder::new();
    let m = s.material(emissive(Vec3::ONE));
    s.quad(
        "upper",
        Vec3::new(-10.0, 1.0, 0.0),
        Vec3::new(20.0, 0.0, 0.0),
        Vec3::new(0.0, 10.0, 0.0),
        m,
    );
    s.camera(Camera {
        name: "ortho".into(),
        position: Vec3::new(0.0, 1.0, -5.0),
        forward: Vec3::Z,
        up: Vec3::Y,
        projection: Projection::Orthographic { half_height: 2.0 },
        near: 0.1,
        far: f32::INFINITY,
    });
    let (soup, kd) = s.build();
    let (out, _) = render(&soup, &kd, &opts(8, 8));
    for y in 0..8 {
        let want = if y < 4 { Vec3::ONE } else { Vec3::ZERO };
        assert_eq!(out.frame.pixel(4, y), want, "row {y}");
    }
}

/// URP's shadow distance: a shadow fades from whole to none as d² runs from (1 − border)²·D²
/// to D² (d the distance from the camera), the light becoming lerp(shadowed, lit, fade);
/// beyond D no shadow ray is traced. Hard and soft, alone and in packets.
#[test]
fn shadows_fade_out_toward_the_pipelines_shadow_distance() {
    for shadows in [Shadows::Hard, Shadows::Soft] {
        let mut s = floor_scene();
        // A shadows-only roof over the whole floor, under a sun straight above.
        let m = s.diffuse(Vec3::ONE);
        let roof = s.quad(
            "roof",
            Vec3::new(-6.0, 2.0, -6.0),
            Vec3::new(0.0, 0.0, 12.0),
            Vec3::new(12.0, 0.0, 0.0),
            m,
        );
        s.soup.objects[roof as usize].cast_shadows = formats::CastShadows::ShadowsOnly;
        s.light(formats::Light {
            shadow_radius: 0.5,
            ..directional_light(-Vec3::Y, 1.0, shadows)
        });
        // Seen from 10 m up, the floor's points lie 10–11.2 m from the camera: shadows
        // fade from 8.8 m to 11 m, so the middle is half faded and the corners bare.
        s.soup.environment.shadow_distance = Some(formats::ShadowDistance {
            distance: 11.0,
            border: 0.2,
        });
        let (soup, kd) = s.build();
        let (w, h) = (40, 40);
        let out = render_alike_at_tiles(&soup, &kd, &opts(w, h));
        let (start, end) = (8.8f32 * 8.8, 11.0f32 * 11.0);
        let (mut faded, mut bare) = (0, 0);
        for py in 0..h {
            for px in 0..w {
                let p = ortho_point(&soup.camera, w, h, px, py, 0.0);
                let d2 = (p - soup.camera.position).length_squared();
                let fade = ((d2 - start) / (end - start)).clamp(0.0, 1.0);
                let got = out.frame.pixel(px, py);
                assert_close(got, ALBEDO * fade, 1e-3, &format!("pixel ({px}, {py})"));
                if fade >= 1.0 {
                    bare += 1;
                } else {
                    faded += 1;
                }
            }
        }
        assert!(
            faded > 400 && bare > 100,
            "{faded} faded, {bare} bare pixels"
        );
        // No shadow ray leaves a point whose shadow has faded out entirely (a soft
        // shadow's rim probes decide each point here: four rays).
        let (rays, per_point) = match shadows {
            Shadows::Hard => (out.counts.shadow, 1),
            _ => (out.counts.soft_shadow, 4),
        };
        assert_eq!(rays, faded * per_point, "{shadows:?}: shadow rays");
    }
}
