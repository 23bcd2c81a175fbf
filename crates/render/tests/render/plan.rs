//! The effects plan traces no ray that cannot change the image: ray counts per kind, and
//! each effect, turned on, changes the pixels where it should.

use crate::common::*;
use formats::Shadows;
use glam::Vec3;
use render::plan::ShadowMode;

/// Floor seen from above, an occluder at y = 2 over x ∈ [1, 2], a point light at (3, 4, 0).
fn shadow_scene(shadows: Shadows, radius: f32) -> SceneBuilder {
    let mut s = SceneBuilder::new();
    let m = s.diffuse(Vec3::splat(0.5));
    s.floor(0.0, 0.0, 0.0, 20.0, m);
    s.quad(
        "occluder",
        Vec3::new(1.0, 2.0, -1.0),
        Vec3::new(0.0, 0.0, 2.0),
        Vec3::new(1.0, 0.0, 0.0),
        m,
    );
    let mut l = point_light(Vec3::new(3.0, 4.0, 0.0), 1.0, 20.0, shadows);
    l.shadow_radius = radius;
    s.light(l);
    s.camera(top_down_camera(Vec3::new(0.0, 10.0, 0.0), 5.0));
    s
}

#[test]
fn no_shadow_casting_light_means_no_shadow_rays() {
    let (soup, kd) = shadow_scene(Shadows::None, 0.0).build();
    let (out, plan) = render(&soup, &kd, &opts(40, 40));
    assert_eq!(plan.lights[0].shadows, ShadowMode::None);
    assert_eq!(out.counts.shadow, 0);
    assert_eq!(out.counts.soft_shadow, 0);
    assert_eq!(out.counts.camera, 1600);

    // Hard shadows: one shadow ray per lit point, and the shadow appears.
    let (soup, kd) = shadow_scene(Shadows::Hard, 0.0).build();
    let (hard, plan) = render(&soup, &kd, &opts(40, 40));
    assert_eq!(plan.lights[0].shadows, ShadowMode::Hard);
    assert_eq!(
        hard.counts.shadow, 1600,
        "every visible point faces the light, in range"
    );
    assert_eq!(hard.counts.soft_shadow, 0);
    assert!(out.frame.pixel(20, 20).x > 0.0);
    assert_eq!(hard.frame.pixel(20, 20), Vec3::ZERO);
    // Outside the shadow nothing changed, bit for bit.
    assert_eq!(hard.frame.pixel(3, 3), out.frame.pixel(3, 3));
}

#[test]
fn shadow_rays_only_where_a_light_can_contribute() {
    // A spot cone (60°) 4 m above the floor lights a disc of radius 2.3 m: points outside
    // it, out of range or facing away get no shadow ray.
    let mut s = SceneBuilder::new();
    let m = s.diffuse(Vec3::splat(0.5));
    s.floor(0.0, 0.0, 0.0, 20.0, m);
    let mut l = spot_light(Vec3::new(0.0, 4.0, 0.0), -Vec3::Y, 60.0, 60.0, 30.0);
    l.shadows = Shadows::Hard;
    s.light(l);
    s.camera(top_down_camera(Vec3::new(0.0, 10.0, 0.0), 5.0));
    let (soup, kd) = s.build();
    let (out, _) = render(&soup, &kd, &opts(40, 40));
    let lit = out.frame.color.iter().filter(|c| c.x > 0.0).count() as u64;
    assert!(lit > 100 && lit < 1600);
    assert_eq!(
        out.counts.shadow, lit,
        "one shadow ray per point inside the cone"
    );

    // A light under the floor faces no visible point: no shadow rays at all.
    let mut soup = soup;
    soup.lights[0].position = Vec3::new(0.0, -4.0, 0.0);
    soup.lights[0].direction = Vec3::Y;
    let (out, _) = render(&soup, &kd, &opts(40, 40));
    assert_eq!(out.counts.shadow, 0);
    assert!(out.frame.color.iter().all(|c| *c == Vec3::ZERO));
}

#[test]
fn no_reflective_material_means_no_reflection_rays() {
    let (soup, kd) = shadow_scene(Shadows::Hard, 0.0).build();
    let (out, plan) = render(&soup, &kd, &opts(20, 20));
    assert!(!plan.reflections.enabled);
    assert_eq!(out.counts.reflection, 0);

    // Make the floor a 50% mirror: the occluder's underside... and the floor pixels change.
    let mut soup = soup;
    soup.materials[0].reflectivity = Some(0.5);
    soup.environment.background = Vec3::new(0.0, 0.0, 1.0);
    let (refl, plan) = render(&soup, &kd, &opts(20, 20));
    assert!(plan.reflections.enabled);
    assert!(refl.counts.reflection > 0);
    // A floor pixel away from the occluder now reflects the blue background.
    let (a, b) = (out.frame.pixel(2, 2), refl.frame.pixel(2, 2));
    assert_eq!(a.z, a.x, "grey without reflection");
    assert!(
        (b.z - a.z - 0.5).abs() < 1e-5,
        "half the blue sky is added: {a} → {b}"
    );

    // A reflectance below the cutoff traces nothing.
    soup.materials[0].reflectivity = Some(0.003);
    let (low, plan) = render(&soup, &kd, &opts(20, 20));
    assert!(!plan.reflections.enabled);
    assert_eq!(low.counts.reflection, 0);
}

#[test]
fn the_path_weight_cutoff_ends_reflections() {
    // Two facing 50% mirrors: bounce k carries weight 0.5^k. With cutoff 0.1 the path
    // stops after 3 bounces (0.125 ≥ 0.1 > 0.0625) even though --depth allows 16.
    let mut s = SceneBuilder::new();
    let m = s.material(mirror(0.5));
    s.quad(
        "a",
        Vec3::new(-50.0, -50.0, 1.0),
        Vec3::new(100.0, 0.0, 0.0),
        Vec3::new(0.0, 100.0, 0.0),
        m,
    );
    s.quad(
        "b",
        Vec3::new(-50.0, -50.0, -1.0),
        Vec3::new(0.0, 100.0, 0.0),
        Vec3::new(100.0, 0.0, 0.0),
        m,
    );
    s.camera(formats::Camera {
        name: "between".into(),
        position: Vec3::ZERO,
        forward: Vec3::Z,
        up: Vec3::Y,
        projection: formats::Projection::Orthographic { half_height: 1.0 },
        near: 0.0,
        far: f32::INFINITY,
    });
    s.soup.environment.background = Vec3::ONE;
    let (soup, kd) = s.build();
    let mut o = opts(4, 4);
    o.depth = 16;
    o.cutoff = 0.1;
    let (out, _) = render(&soup, &kd, &o);
    assert_eq!(out.counts.reflection, 16 * 3);
    o.cutoff = 0.0;
    let (out, _) = render(&soup, &kd, &o);
    assert_eq!(
        out.counts.reflection,
        16 * 16,
        "cutoff 0: the depth limit rules"
    );
    // Mirrors (albedo 0) between mirrors: the image is the product of reflectances → 0.
    assert!(out.frame.color.iter().all(|c| c.is_finite() && c.x < 1e-4));
}

#[test]
fn no_soft_light_means_no_soft_shadow_rays_and_soft_lights_blur_the_edge() {
    let (soup, kd) = shadow_scene(Shadows::Hard, 0.5).build();
    let (hard, _) = render(&soup, &kd, &opts(40, 40));
    assert_eq!(hard.counts.soft_shadow, 0);

    // Soft with zero radius is a point emitter: traced as hard.
    let (soup, kd) = shadow_scene(Shadows::Soft, 0.0).build();
    let (pointlike, plan) = render(&soup, &kd, &opts(40, 40));
    assert_eq!(plan.lights[0].shadows, ShadowMode::Hard);
    assert_eq!(pointlike.counts.soft_shadow, 0);
    assert_eq!(pointlike.frame, hard.frame);

    let (soup, kd) = shadow_scene(Shadows::Soft, 0.5).build();
    let mut o = opts(40, 40);
    o.soft_samples = 16;
    let (soft, plan) = render(&soup, &kd, &o);
    assert_eq!(plan.lights[0].shadows, ShadowMode::Soft);
    assert_eq!(soft.counts.shadow, 0);
    // A 0.5 m disc 4 m away is wider than the rim probe asks about: every sample traced.
    assert_eq!(soft.counts.soft_shadow, 1600 * 16);
    assert_eq!(soft.counts.soft_decided, 0);

    // Unshadowed reference: the same scene without shadows.
    let (soup_n, kd_n) = shadow_scene(Shadows::None, 0.0).build();
    let (free, _) = render(&soup_n, &kd_n, &opts(40, 40));
    let (mut partial_hard, mut partial_soft) = (0, 0);
    for i in 0..1600 {
        let f = free.frame.color[i].x;
        if f <= 0.0 {
            continue;
        }
        let (h, s) = (hard.frame.color[i].x / f, soft.frame.color[i].x / f);
        if h > 1e-6 && h < 1.0 - 1e-6 {
            partial_hard += 1;
        }
        if s > 1e-6 && s < 1.0 - 1e-6 {
            partial_soft += 1;
        }
    }
    // The occluder's own top face is lit in all three renders; only shadow edges differ.
    assert_eq!(partial_hard, 0, "hard shadows are all or nothing");
    assert!(partial_soft > 20, "{partial_soft} penumbra pixels");
}

#[test]
fn soft_directional_shadows_sample_a_cone() {
    let mut s = shadow_scene(Shadows::None, 0.0);
    s.soup.lights.clear();
    let mut sun = directional_light(Vec3::new(-0.6, -0.8, 0.0), 1.0, Shadows::Soft);
    sun.shadow_radius = 10.0;
    s.light(sun);
    let (soup, kd) = s.build();
    let mut o = opts(40, 40);
    o.soft_samples = 9;
    let (out, plan) = render(&soup, &kd, &o);
    assert_eq!(plan.lights[0].shadow_rays, 9);
    // A 10° cone is wider than the rim probe asks about.
    assert_eq!(out.counts.soft_shadow, 1600 * 9);
    let full = 0.5 * 0.8;
    let partial = out
        .frame
        .color
        .iter()
        .filter(|c| c.x > 1e-6 && c.x < full - 1e-6)
        .count();
    assert!(partial > 10, "{partial} penumbra pixels");
}

#[test]
fn lights_that_deliver_nothing_are_planned_off() {
    let mut s = shadow_scene(Shadows::Hard, 0.0);
    s.soup.lights[0].intensity = 0.0;
    let mut far = point_light(Vec3::ZERO, 1.0, 0.0, Shadows::Hard);
    far.name = "zero range".into();
    s.light(far);
    let (soup, kd) = s.build();
    let (out, plan) = render(&soup, &kd, &opts(10, 10));
    assert!(!plan.direct.enabled);
    assert!(plan.lights.iter().all(|l| !l.enabled));
    assert_eq!(out.counts.shadow, 0);
    let text = plan.describe();
    assert!(
        text.contains("zero range") && text.contains("range 0 lights nothing"),
        "{text}"
    );
}

#[test]
fn anti_aliasing_samples_only_when_asked_and_is_deterministic() {
    let (soup, kd) = shadow_scene(Shadows::Hard, 0.0).build();
    let (one, plan) = render(&soup, &kd, &opts(20, 20));
    assert!(!plan.anti_aliasing.enabled);
    assert_eq!(one.counts.camera, 400);

    let mut o = opts(20, 20);
    o.spp = 4;
    let (a, plan) = render(&soup, &kd, &o);
    assert!(plan.anti_aliasing.enabled);
    assert_eq!(a.counts.camera, 1600);
    let (b, _) = render(&soup, &kd, &o);
    assert_eq!(a.frame, b.frame, "same seed, same image");
    // The occluder's edges are anti-aliased: some pixels differ from the 1-spp render.
    let differ = (0..400)
        .filter(|&i| a.frame.color[i] != one.frame.color[i])
        .count();
    assert!(differ > 0);
    o.seed = 7;
    let (c, _) = render(&soup, &kd, &o);
    assert_ne!(a.frame, c.frame, "another seed jitters differently");
}

#[test]
fn pixels_do_not_depend_on_threads_or_tiles() {
    let (soup, kd) = shadow_scene(Shadows::Soft, 0.5).build();
    let mut o = opts(37, 29);
    o.spp = 3;
    o.soft_samples = 4;
    o.threads = Some(1);
    o.tile = 32;
    let (a, _) = render(&soup, &kd, &o);
    o.threads = Some(2);
    o.tile = 5;
    let (b, _) = render(&soup, &kd, &o);
    assert_eq!(a.frame, b.frame);
    assert_eq!(a.counts, b.counts);
}

/// A 2×2 block's hard shadow rays towards each light, and its mirror rays, are traced
/// together. With lights of every shadow kind (hard point and sun, soft spot, none), one
/// lighting only some layers, a tilted mirror, an object that casts no shadow, one that
/// receives none and a face culled from above, and then with a cut-out quad (shadow rays
/// walk far child first) and with a blended quad as well (front to back), at 1, 3 and 4
/// samples per pixel, tiles of 1, 5 and 32 pixels give the same pixels and counts.
#[test]
fn shadow_and_mirror_rays_traced_in_blocks_equal_rays_traced_alone() {
    for (alpha, blend, spp) in [
        (false, false, 1),
        (true, false, 1),
        (true, true, 1),
        (false, false, 4),
        (true, false, 3),
        (true, true, 3),
    ] {
        let mut s = shadow_scene(Shadows::Hard, 0.0);
        let grey = s.diffuse(Vec3::splat(0.7));
        let ghost = s.cube(
            "casts nothing",
            Vec3::new(-2.5, 0.0, 1.0),
            Vec3::new(-1.5, 1.5, 2.0),
            grey,
        );
        s.soup.objects[ghost as usize].cast_shadows = formats::CastShadows::Off;
        let unshadowed = s.cube(
            "receives nothing",
            Vec3::new(2.0, 0.0, -3.0),
            Vec3::new(3.0, 1.0, -2.0),
            grey,
        );
        s.soup.objects[unshadowed as usize].receive_shadows = false;
        s.soup.objects[unshadowed as usize].layer = 3;
        let one_sided = s.material(formats::Material {
            cull: formats::Cull::Back,
            ..diffuse(Vec3::new(0.9, 0.2, 0.2))
        });
        // Facing down: culled seen from the camera, drawn seen in the mirror.
        s.quad(
            "one-sided",
            Vec3::new(-1.0, 1.0, -3.0),
            Vec3::new(1.5, 0.0, 0.0),
            Vec3::new(0.0, 0.0, 1.5),
            one_sided,
        );
        let glass = s.material(mirror(0.8));
        s.quad(
            "mirror",
            Vec3::new(-4.0, 0.0, -3.0),
            Vec3::new(0.0, 0.0, 6.0),
            Vec3::new(1.0, 2.0, 0.0),
            glass,
        );
        if alpha {
            let holes = s.texture(texture(
                2,
                1,
                &[[255, 255, 255, 0], [255, 255, 255, 255]],
                formats::texture::Wrap::Clamp,
            ));
            let map = Some(formats::texture::TextureRef {
                texture: holes,
                tiling: Default::default(),
            });
            let cut_out = s.material(formats::Material {
                alpha: formats::Alpha::Cutout { cutoff: 0.5 },
                normal_map: None,
                emission_map: None,
                occlusion_map: None,
                metallic_map: None,
                unlit: false,
                albedo_map: map,
                ..diffuse(Vec3::splat(0.6))
            });
            s.quad(
                "cut-out",
                Vec3::new(-1.0, 2.5, -1.0),
                Vec3::new(0.0, 0.0, 2.0),
                Vec3::new(1.5, 0.0, 0.0),
                cut_out,
            );
        }
        if blend {
            let blended = s.material(formats::Material {
                alpha: formats::Alpha::Blend,
                opacity: 0.5,
                ..diffuse(Vec3::new(0.2, 0.3, 0.9))
            });
            s.quad(
                "blended",
                Vec3::new(1.0, 1.0, 1.5),
                Vec3::new(0.0, 0.0, 1.5),
                Vec3::new(2.0, 0.0, 0.0),
                blended,
            );
        }
        let mut sun = directional_light(Vec3::new(-1.0, -2.0, 0.5), 0.8, Shadows::Hard);
        sun.culling_mask = !(1 << 3);
        s.light(sun);
        let mut spot = spot_light(Vec3::new(-1.0, 5.0, 0.0), -Vec3::Y, 70.0, 50.0, 20.0);
        spot.shadows = Shadows::Soft;
        spot.shadow_radius = 0.4;
        s.light(spot);
        s.light(point_light(
            Vec3::new(0.0, 3.0, 3.0),
            0.5,
            10.0,
            Shadows::None,
        ));
        let (soup, kd) = s.build();
        let mut o = opts(37, 29);
        o.soft_samples = 4;
        o.spp = spp;
        let out = render_alike_at_tiles(&soup, &kd, &o);
        let c = &out.counts;
        assert_eq!(c.camera, 37 * 29 * spp as u64);
        assert!(c.shadow > (2 * 37 * 29 - 400) * spp as u64, "{c:?}");
        assert!(c.soft_shadow > 0 && c.reflection > 40, "{c:?}");
        assert!(c.pass_through > 0 && c.shadow_pass_through > 0, "{c:?}");
        assert_eq!(c.alpha_lookups > 0, alpha, "{c:?}");
        assert_eq!(
            c.blend_continuation > 0 && c.shadow_blend > 0,
            blend,
            "{c:?}"
        );
    }
}

/// The camera rays of 2×2 blocks are traced together: tiles of one
/// pixel (no blocks), of 5 (blocks, and a last row and column alone) and of 32 give the
/// same pixels and the same counts.
#[test]
fn pixels_traced_in_blocks_equal_pixels_traced_alone() {
    let (soup, kd) = shadow_scene(Shadows::Hard, 0.5).build();
    let out = render_alike_at_tiles(&soup, &kd, &opts(37, 29));
    assert_eq!(out.counts.camera, 37 * 29);
}
