//! Albedo textures and alpha with known pixel values: orientation, sRGB decoding, tiling,
//! wrap modes, cut-out holes in surfaces and shadows, blended surfaces; and that the plan
//! turns textures and alpha on only when a material needs them.

use crate::common::*;
use formats::texture::{TextureRef, Tiling, Wrap};
use formats::{Alpha, Camera, Cull, Material, Projection, Shadows};
use glam::{Vec2, Vec3};

const RED: [u8; 4] = [255, 0, 0, 255];
const GREEN: [u8; 4] = [0, 255, 0, 255];
const BLUE: [u8; 4] = [0, 0, 255, 255];
const WHITE: [u8; 4] = [255, 255, 255, 255];

fn rgb(t: [u8; 4]) -> Vec3 {
    Vec3::new(t[0] as f32, t[1] as f32, t[2] as f32) / 255.0
}

/// Bottom row red, green; top row blue, white (texel (0, 0), red, is the bottom-left).
fn four_colours(wrap: Wrap) -> formats::Texture {
    texture(2, 2, &[RED, GREEN, BLUE, WHITE], wrap)
}

/// A white material showing texture `t` through `tiling`.
fn mapped(t: u32, tiling: Tiling) -> Material {
    Material {
        normal_map: None,
        emission_map: None,
        occlusion_map: None,
        metallic_map: None,
        unlit: false,
        albedo_map: Some(TextureRef { texture: t, tiling }),
        ..diffuse(Vec3::ONE)
    }
}

/// A white flat ambient light: an unshadowed surface shows exactly its albedo.
fn ambient_white(s: &mut SceneBuilder) {
    s.soup.environment.ambient.sky = Vec3::ONE;
}

/// A camera as Unity's unrotated one sees the scene (at −Z looking along +Z, up +Y, image
/// right = soup −X = Unity +X), orthographic, `half_height` metres above and below its axis.
fn front_camera(half_height: f32) -> Camera {
    Camera {
        name: "front".into(),
        position: Vec3::new(0.0, 0.0, -5.0),
        forward: Vec3::Z,
        up: Vec3::Y,
        projection: Projection::Orthographic { half_height },
        near: 0.0,
        far: f32::INFINITY,
    }
}

/// The quad Unity's built-in Quad becomes in the soup: 1 × 1 in XY facing the camera,
/// uv (0, 0) at its bottom-left as that camera sees it (Unity (−½, −½), soup (½, −½)) and
/// u growing to the image's right, `w` metres wide.
fn unity_quad(s: &mut SceneBuilder, w: f32, material: u32, uv: [Vec2; 2]) -> u32 {
    s.quad_uv(
        "quad",
        Vec3::new(w / 2.0, -0.5, 0.0),
        Vec3::new(-w, 0.0, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
        material,
        uv,
    )
}

fn textured_quad(tex: formats::Texture, tiling: Tiling, w: f32, uv: [Vec2; 2]) -> SceneBuilder {
    let mut s = SceneBuilder::new();
    let t = s.texture(tex);
    let m = s.material(mapped(t, tiling));
    unity_quad(&mut s, w, m, uv);
    ambient_white(&mut s);
    s.camera(front_camera(0.5));
    s
}

#[test]
fn each_texel_lands_in_its_image_corner_not_mirrored() {
    let s = textured_quad(
        four_colours(Wrap::Clamp),
        Tiling::default(),
        1.0,
        [Vec2::ZERO, Vec2::ONE],
    );
    let (soup, kd) = s.build();
    let (out, plan) = render(&soup, &kd, &opts(4, 4));
    // Image rows run top to bottom: the bottom-left pixel is (0, 3).
    assert_eq!(out.frame.pixel(0, 3), rgb(RED), "bottom-left");
    assert_eq!(out.frame.pixel(3, 3), rgb(GREEN), "bottom-right");
    assert_eq!(out.frame.pixel(0, 0), rgb(BLUE), "top-left");
    assert_eq!(out.frame.pixel(3, 0), rgb(WHITE), "top-right");
    assert!(plan.textures.enabled, "{}", plan.textures.reason);
    assert!(!plan.alpha.enabled);
    // One albedo lookup per shaded pixel, nothing else.
    assert_eq!(out.counts.texture_lookups, 16);
    assert_eq!(out.counts.alpha_lookups, 0);
    assert_eq!(plan.textures.textures, 1);
    // The 2×2 image is the soup's; its 1×1 mip level is one texel of 4 bytes.
    assert_eq!(plan.textures.bytes, 4);
    assert!(
        plan.describe().contains("textures       on "),
        "{}",
        plan.describe()
    );
}

/// The full-size image is sampled where the soup holds it; mip levels are built for the
/// textures a used material reads, and for no other.
#[test]
fn only_the_textures_a_used_material_reads_get_mip_levels() {
    let mut s = textured_quad(
        four_colours(Wrap::Clamp),
        Tiling::default(),
        1.0,
        [Vec2::ZERO, Vec2::ONE],
    );
    // A 4×4 texture of a material no triangle uses.
    let unread = s.texture(texture(4, 4, &[GREEN; 16], Wrap::Repeat));
    s.material(mapped(unread, Tiling::default()));
    let (soup, kd) = s.build();
    let (out, plan) = render(&soup, &kd, &opts(4, 4));
    assert_eq!(out.frame.pixel(0, 3), rgb(RED));
    assert_eq!(
        (plan.textures.textures, plan.textures.read.clone()),
        (1, vec![true, false])
    );
    let accel = kdtree::Accel::new(&soup, kd).expect("tree fits");
    let it = render::integrator::Integrator::new(
        &soup,
        &accel,
        &plan,
        &render::RenderOptions::default(),
    );
    // The 2×2 image's 1×1 level: one 8-bit RGBA texel; none of the 4×4 image's.
    assert_eq!((plan.textures.bytes, it.texture_bytes()), (4, 4));
}

#[test]
fn a_mid_grey_srgb_texel_is_0_2158_linear() {
    let mut grey = texture(1, 1, &[[128, 128, 128, 255]], Wrap::Repeat);
    grey.srgb = true;
    let (soup, kd) = textured_quad(grey, Tiling::default(), 1.0, [Vec2::ZERO, Vec2::ONE]).build();
    let (out, _) = render(&soup, &kd, &opts(2, 2));
    // ((128/255 + 0.055) / 1.055)^2.4, under a white ambient light of 1.
    let want = ((128.0f64 / 255.0 + 0.055) / 1.055).powf(2.4) as f32;
    assert!((want - 0.2158).abs() < 1e-4);
    for p in out.frame.color.iter() {
        assert_close(*p, Vec3::splat(want), 1e-6, "grey texel");
    }
}

#[test]
fn tiling_scales_then_offsets_the_uv() {
    let tiling = Tiling {
        scale: [2.0, 1.0],
        offset: [0.5, 0.0],
    };
    let s = textured_quad(
        four_colours(Wrap::Repeat),
        tiling,
        4.0,
        [Vec2::ZERO, Vec2::ONE],
    );
    let (soup, kd) = s.build();
    let (out, _) = render(&soup, &kd, &opts(8, 2));
    let bottom = [RED, GREEN];
    for x in 0..8 {
        // Pixel centre u, then u' = 2u + 0.5, repeated into the 2-texel row.
        let u = (x as f32 + 0.5) / 8.0;
        let col = ((2.0 * u + 0.5).fract() * 2.0).floor() as usize;
        assert_eq!(
            out.frame.pixel(x, 1),
            rgb(bottom[col]),
            "pixel {x}, u' {}",
            2.0 * u + 0.5
        );
    }
    // u = 1/16 → u' = 0.625: the second texel (green), not the first.
    assert_eq!(out.frame.pixel(0, 1), rgb(GREEN));
}

#[test]
fn wrap_modes_outside_the_unit_square() {
    // A 3 m quad with u from −1 to 2 seen by 6 pixels: centres at u = −0.75, −0.25, 0.25,
    // 0.75, 1.25, 1.75, i.e. texel columns −2 … 3 of the 2-texel rows.
    let r = rgb(RED);
    let g = rgb(GREEN);
    for (wrap, want) in [
        (Wrap::Repeat, [r, g, r, g, r, g]),
        (Wrap::Clamp, [r, r, r, g, g, g]),
        (Wrap::Mirror, [g, r, r, g, g, r]),
    ] {
        let s = textured_quad(
            four_colours(wrap),
            Tiling::default(),
            3.0,
            [Vec2::new(-1.0, 0.0), Vec2::new(2.0, 1.0)],
        );
        let (soup, kd) = s.build();
        let (out, _) = render(&soup, &kd, &opts(6, 2));
        let row: Vec<Vec3> = (0..6).map(|x| out.frame.pixel(x, 1)).collect();
        assert_eq!(row, want, "{wrap:?}");
    }
}

/// A white floor at y = 0 lit by a sun travelling along (−1, −1, 0) (n·l = 1/√2), and a
/// grey quad over x, z ∈ [−0.5, 0.5] at y = 1 with material `quad`; its shadow falls on
/// x ∈ [−1.5, −0.5]. The camera sees x, z ∈ [−2, 2] from above, 40 × 40 pixels of 0.1 m
/// (no pixel centre on an edge).
fn quad_over_lit_floor(quad: Material, tex: Option<formats::Texture>) -> SceneBuilder {
    let mut s = SceneBuilder::new();
    let white = s.diffuse(Vec3::ONE);
    s.floor(0.0, 0.0, 0.0, 20.0, white);
    let quad = match tex {
        Some(t) => {
            let t = s.texture(t);
            Material {
                normal_map: None,
                emission_map: None,
                occlusion_map: None,
                metallic_map: None,
                unlit: false,
                albedo_map: Some(TextureRef {
                    texture: t,
                    tiling: Tiling::default(),
                }),
                ..quad
            }
        }
        None => quad,
    };
    let q = s.material(quad);
    // u along +X, so uv.x = x + 0.5.
    s.quad(
        "quad",
        Vec3::new(-0.5, 1.0, -0.5),
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(0.0, 0.0, 1.0),
        q,
    );
    s.light(directional_light(
        Vec3::new(-1.0, -1.0, 0.0),
        1.0,
        Shadows::Hard,
    ));
    s.camera(top_down_camera(Vec3::new(0.0, 10.0, 0.0), 2.0));
    s
}

const LIT: f32 = std::f32::consts::FRAC_1_SQRT_2;

fn inside(p: Vec3, x0: f32, x1: f32) -> bool {
    p.x > x0 && p.x < x1 && p.z > -0.5 && p.z < 0.5
}

#[test]
fn a_cut_out_shows_the_wall_behind_and_casts_a_cut_out_shadow() {
    // Texel 0 (uv.x < ½, x < 0) is a hole, texel 1 solid.
    let tex = texture(
        2,
        1,
        &[[255, 255, 255, 0], [255, 255, 255, 255]],
        Wrap::Clamp,
    );
    let grey = Material {
        alpha: Alpha::Cutout { cutoff: 0.5 },
        ..diffuse(Vec3::splat(0.5))
    };
    let (soup, kd) = quad_over_lit_floor(grey, Some(tex)).build();
    let o = opts(40, 40);
    let (out, plan) = render(&soup, &kd, &o);
    assert!(plan.alpha.enabled, "{}", plan.alpha.reason);
    assert_eq!(plan.alpha.cutout_materials, 1);
    let (mut holes, mut solid, mut shadow, mut hole_shadow) = (0, 0, 0, 0);
    for py in 0..40 {
        for px in 0..40 {
            let p = ortho_point(&soup.camera, 40, 40, px, py, 0.0);
            let got = out.frame.pixel(px, py);
            let want = if inside(p, 0.0, 0.5) {
                solid += 1;
                Vec3::splat(0.5 * LIT)
            } else if inside(p, -0.5, 0.0) {
                // Through the hole: the floor, lit (its light passes the hole too).
                holes += 1;
                Vec3::splat(LIT)
            } else if inside(p, -1.0, -0.5) {
                // Behind the solid half.
                shadow += 1;
                Vec3::ZERO
            } else {
                // Including x ∈ [−1.5, −1], where the hole's light lands.
                hole_shadow += inside(p, -1.5, -1.0) as u32;
                Vec3::splat(LIT)
            };
            assert_close(got, want, 1e-5, &format!("pixel ({px}, {py}) at {p}"));
        }
    }
    assert_eq!((holes, solid, shadow, hole_shadow), (50, 50, 50, 50));
    // Camera rays over the hole pass its triangles; shadow rays through it too.
    assert!(out.counts.pass_through >= 50, "{:?}", out.counts);
    assert!(out.counts.shadow_pass_through >= 50, "{:?}", out.counts);
    assert!(out.counts.alpha_lookups >= 200, "{:?}", out.counts);
}

#[test]
fn a_blended_quad_at_half_alpha_averages_its_colour_and_the_wall() {
    let mut s = SceneBuilder::new();
    ambient_white(&mut s);
    let wall = s.diffuse(Vec3::new(0.2, 0.4, 0.6));
    s.floor(0.0, 0.0, 0.0, 20.0, wall);
    let t = s.texture(texture(1, 1, &[[255, 0, 0, 255]], Wrap::Repeat));
    let glass = s.material(Material {
        alpha: Alpha::Blend,
        opacity: 0.5,
        cull: Cull::None,
        ..mapped(t, Tiling::default())
    });
    s.quad(
        "glass",
        Vec3::new(-1.0, 1.0, -1.0),
        Vec3::new(2.0, 0.0, 0.0),
        Vec3::new(0.0, 0.0, 2.0),
        glass,
    );
    s.camera(top_down_camera(Vec3::new(0.0, 10.0, 0.0), 2.0));
    let (soup, kd) = s.build();
    let (out, plan) = render(&soup, &kd, &opts(20, 20));
    assert!(plan.alpha.enabled);
    assert_eq!(plan.alpha.blend_materials, 1);
    let want = Vec3::new(1.0, 0.0, 0.0) * 0.5 + Vec3::new(0.2, 0.4, 0.6) * 0.5;
    assert_close(out.frame.pixel(10, 10), want, 1e-6, "through the glass");
    assert_close(
        out.frame.pixel(0, 0),
        Vec3::new(0.2, 0.4, 0.6),
        1e-6,
        "the wall",
    );
    // One continuation per pixel behind the glass (10 × 10), also on its diagonal.
    assert_eq!(out.counts.blend_continuation, 100, "{:?}", out.counts);
}

#[test]
fn a_blended_quad_passes_half_the_light_to_its_shadow() {
    let glass = Material {
        alpha: Alpha::Blend,
        opacity: 0.5,
        ..diffuse(Vec3::splat(0.5))
    };
    let (soup, kd) = quad_over_lit_floor(glass, None).build();
    // Traced alone and in 2×2 blocks (whose shadow rays go as packets) alike.
    let out = render_alike_at_tiles(&soup, &kd, &opts(40, 40));
    let mut n = 0;
    for py in 0..40 {
        for px in 0..40 {
            let p = ortho_point(&soup.camera, 40, 40, px, py, 0.0);
            if inside(p, -1.5, -0.5) {
                n += 1;
                // Half the light on every shadowed pixel, those whose shadow ray crosses the
                // quad's diagonal (meeting both its triangles) included.
                assert_close(
                    out.frame.pixel(px, py),
                    Vec3::splat(0.5 * LIT),
                    1e-5,
                    &format!("{p}"),
                );
            }
        }
    }
    assert_eq!(n, 100);
    assert!(out.counts.shadow_blend >= 100, "{:?}", out.counts);
}

#[test]
fn an_opaque_at_every_texel_alpha_material_costs_nothing() {
    // Blend at opacity 1 with an opaque map, and cut-out above the cut-off at every texel.
    for (alpha, a) in [(Alpha::Blend, 255), (Alpha::Cutout { cutoff: 0.5 }, 200)] {
        let quad = Material {
            alpha,
            ..diffuse(Vec3::splat(0.5))
        };
        let tex = texture(1, 1, &[[255, 255, 255, a]], Wrap::Repeat);
        let (soup, kd) = quad_over_lit_floor(quad, Some(tex)).build();
        let (out, plan) = render(&soup, &kd, &opts(20, 20));
        assert!(!plan.alpha.enabled, "{alpha:?}: {}", plan.alpha.reason);
        assert_eq!(out.counts.alpha_lookups + out.counts.blend_continuation, 0);
        assert!(out.counts.texture_lookups > 0);
    }
}

#[test]
fn an_untextured_scene_plans_no_texture_or_alpha_work() {
    let quad = diffuse(Vec3::splat(0.5));
    let (soup, kd) = quad_over_lit_floor(quad, None).build();
    assert!(soup.uvs.is_empty());
    let (out, plan) = render(&soup, &kd, &opts(20, 20));
    assert!(!plan.textures.enabled);
    assert!(!plan.alpha.enabled);
    assert_eq!(plan.textures.reason, "no material has an albedo map");
    assert!(plan.describe().contains("textures       off"));
    assert!(plan.describe().contains("alpha          off"));
    let c = out.counts;
    assert_eq!(
        c.texture_lookups + c.alpha_lookups + c.blend_continuation + c.shadow_blend,
        0
    );
}

#[test]
fn a_mirror_shows_a_texture_where_its_reflection_lands() {
    let mut s = SceneBuilder::new();
    ambient_white(&mut s);
    let m = s.material(mirror(1.0));
    s.floor(0.0, 0.0, 0.0, 20.0, m);
    let t = s.texture(four_colours(Wrap::Clamp));
    let c = s.material(mapped(t, Tiling::default()));
    // A 4 m ceiling above the camera, uv = ((x + 2) / 4, (z + 2) / 4).
    s.quad(
        "ceiling",
        Vec3::new(-2.0, 20.0, -2.0),
        Vec3::new(4.0, 0.0, 0.0),
        Vec3::new(0.0, 0.0, 4.0),
        c,
    );
    s.camera(top_down_camera(Vec3::new(0.0, 10.0, 0.0), 2.0));
    let (soup, kd) = s.build();
    // Mirror rays traced alone and in 2×2 blocks alike.
    let out = render_alike_at_tiles(&soup, &kd, &opts(4, 4));
    let colours = [RED, GREEN, BLUE, WHITE];
    for py in 0..4 {
        for px in 0..4 {
            // The camera looks straight down at a flat mirror: the reflection is the
            // ceiling point straight above the mirror point.
            let p = ortho_point(&soup.camera, 4, 4, px, py, 0.0);
            let (u, v) = ((p.x + 2.0) / 4.0, (p.z + 2.0) / 4.0);
            let i = (v * 2.0).floor() as usize * 2 + (u * 2.0).floor() as usize;
            assert_eq!(
                out.frame.pixel(px, py),
                rgb(colours[i]),
                "pixel ({px}, {py})"
            );
        }
    }
    assert_eq!(out.counts.texture_lookups, 16);
    assert_eq!(out.counts.reflection, 16);
}

/// A white diffuse material whose one-texel normal map, (204, 128), tilts every normal
/// by 0.6 towards increasing u and 1/255 towards increasing v at `scale` 1.
fn tilted_normals(s: &mut SceneBuilder, scale: f32) -> u32 {
    let t = s.texture(texture(1, 1, &[[204, 128, 255, 255]], Wrap::Repeat));
    s.material(Material {
        normal_map: Some(formats::NormalMap {
            map: TextureRef {
                texture: t,
                tiling: Tiling::default(),
            },
            scale,
        }),
        ..diffuse(Vec3::ONE)
    })
}

/// A quad whose normal map tilts every normal by 0.6 towards increasing u (the image's
/// right) and 1/255 towards increasing v, lit by a sun 30° off its normal from the u side:
/// each pixel is the cosine between the light and the bent normal. The plan reads the map
/// only while something shows the normal: a light, an ambient that depends on it, or the
/// normal AOV.
#[test]
fn normal_maps_bend_the_light_and_are_read_only_where_they_show() {
    let (x, y) = (2.0 * 204.0 / 255.0 - 1.0f32, 2.0 * 128.0 / 255.0 - 1.0f32);
    let z = (1.0 - x * x - y * y).sqrt();
    let cos30 = 30f32.to_radians().cos();
    let scene = |sun: bool, ambient: formats::AmbientMode, scale: f32| {
        let mut s = SceneBuilder::new();
        let m = tilted_normals(&mut s, scale);
        unity_quad(&mut s, 1.0, m, [Vec2::ZERO, Vec2::ONE]);
        if sun {
            // Travelling towards +Z and soup +X: it arrives from soup −X, where u grows.
            let d = Vec3::new(0.5, 0.0, cos30);
            s.light(directional_light(d, 1.0, Shadows::None));
        }
        s.soup.environment.ambient.mode = ambient;
        s.soup.environment.ambient.sky = Vec3::splat(if sun { 0.0 } else { 1.0 });
        s.camera(front_camera(0.5));
        s.build()
    };
    let flat = formats::AmbientMode::Flat;
    let (soup, kd) = scene(true, flat, 1.0);
    let mut o = opts(4, 4);
    o.aovs.normal = true;
    let (out, plan) = render(&soup, &kd, &o);
    assert!(plan.normal_maps.enabled, "{}", plan.normal_maps.reason);
    assert_eq!(out.counts.normal_lookups, 16);
    let cos = 0.5 * x + cos30 * z;
    for (px, py) in [(0, 0), (3, 0), (1, 2), (3, 3)] {
        assert_close(out.frame.pixel(px, py), Vec3::splat(cos), 1e-5, "bent");
    }
    // The normal AOV holds the bent normal, facing the camera (soup −Z); u grows along −X.
    let bent = Vec3::new(-x, y, -z);
    assert_close(out.frame.normal[5], bent, 1e-5, "normal AOV");
    // Half the scale halves the tilt.
    let (soup, kd) = scene(true, flat, 0.5);
    let (out, _) = render(&soup, &kd, &opts(4, 4));
    let (hx, hy) = (x / 2.0, y / 2.0);
    let half = 0.5 * hx + cos30 * (1.0 - hx * hx - hy * hy).sqrt();
    assert_close(out.frame.pixel(1, 1), Vec3::splat(half), 1e-5, "scale 0.5");

    // Flat ambient alone: the normal cannot show, the map is not read, the pixel is white.
    let (soup, kd) = scene(false, flat, 1.0);
    o.aovs.normal = false;
    let (out, plan) = render(&soup, &kd, &o);
    assert!(!plan.normal_maps.enabled, "{}", plan.normal_maps.reason);
    assert_eq!(out.counts.normal_lookups, 0);
    assert_eq!(out.frame.pixel(2, 2), Vec3::ONE);
    // The same scene with the normal AOV written reads it.
    o.aovs.normal = true;
    let (out, plan) = render(&soup, &kd, &o);
    assert!(plan.normal_maps.enabled);
    assert_eq!(out.counts.normal_lookups, 16);
    assert_eq!(out.frame.pixel(2, 2), Vec3::ONE);
    // A trilight ambient depends on the normal.
    let (soup, kd) = scene(false, formats::AmbientMode::Trilight, 1.0);
    o.aovs.normal = false;
    let (out, plan) = render(&soup, &kd, &o);
    assert!(plan.normal_maps.enabled);
    assert_eq!(out.counts.normal_lookups, 16);
}

/// A smooth cylinder whose UVs are sheared one way and the other in alternate columns, so
/// each triangle's own ∂p/∂u leans up or down, under a normal map that tilts every normal
/// towards increasing u: read in the mesh's MikkTSpace tangents, which the columns share
/// at their edges, the shading along a row stays smooth (its slope changes by at most 0.0041
/// from one pixel to the next); read in each triangle's own frame it jumps at every column
/// edge (by up to 0.37 between neighbouring pixels).
#[test]
fn normal_maps_shade_a_curved_mesh_smoothly_across_its_triangles() {
    let mut s = SceneBuilder::new();
    let m = tilted_normals(&mut s, 1.0);
    s.soup
        .objects
        .push(formats::Object::new("cylinder", "test"));
    let columns = 24;
    let vertex = |i: usize, y: f32| {
        // Starting at the back, so the UV seam (u = 0 and u = 1) is out of sight.
        let a = std::f32::consts::PI + std::f32::consts::TAU * i as f32 / columns as f32;
        let n = Vec3::new(a.sin(), 0.0, -a.cos());
        let shear = if i.is_multiple_of(2) { 0.0 } else { 0.3 };
        (
            n + Vec3::Y * y,
            n,
            Vec2::new(i as f32 / columns as f32, y + 0.5 + shear),
        )
    };
    for i in 0..columns {
        let c = [
            vertex(i, -0.5),
            vertex(i + 1, -0.5),
            vertex(i + 1, 0.5),
            vertex(i, 0.5),
        ];
        for tri in [[0, 2, 1], [0, 3, 2]] {
            s.soup.push_triangle(
                tri.map(|k| c[k].0),
                tri.map(|k| c[k].1),
                Some(tri.map(|k| c[k].2)),
            );
            s.soup.tri_material.push(m);
            s.soup.tri_object.push(0);
        }
    }
    s.light(directional_light(
        Vec3::new(-0.2, -0.4, 0.9).normalize(),
        1.0,
        Shadows::None,
    ));
    s.camera(front_camera(0.5));
    let (soup, kd) = s.build();
    let (w, h) = (128, 64);
    let (out, plan) = render(&soup, &kd, &opts(w, h));
    assert!(plan.normal_maps.enabled, "{}", plan.normal_maps.reason);
    // The row through the middle, inside the silhouette (|x| < 0.8 m).
    let row: Vec<f32> = (13..w - 13).map(|x| out.frame.pixel(x, h / 2).x).collect();
    assert!(row.iter().all(|v| v.is_finite() && *v > 0.0), "{row:?}");
    // The change of slope from one pixel to the next: the light's falloff across the
    // cylinder bends slowly, a jump at a column edge does not.
    let bend = row
        .windows(3)
        .map(|p| (p[2] - 2.0 * p[1] + p[0]).abs())
        .fold(0.0, f32::max);
    assert!(bend < 0.006, "largest change of slope {bend}: {row:?}");
    assert!(out.counts.normal_lookups > 0);
}

/// An emission map multiplies the emission colour texel by texel; a material that does not
/// glow never reads it.
#[test]
fn emission_maps_multiply_the_glow_and_are_read_only_when_it_shows() {
    let scene = |emission: Vec3| {
        let mut s = SceneBuilder::new();
        let t = s.texture(four_colours(Wrap::Clamp));
        let m = s.material(Material {
            emission,
            emission_map: Some(TextureRef {
                texture: t,
                tiling: Tiling::default(),
            }),
            ..diffuse(Vec3::ONE)
        });
        unity_quad(&mut s, 1.0, m, [Vec2::ZERO, Vec2::ONE]);
        s.camera(front_camera(0.5));
        s.build()
    };
    let (soup, kd) = scene(Vec3::new(2.0, 1.0, 0.5));
    let (out, plan) = render(&soup, &kd, &opts(4, 4));
    assert!(plan.emission.enabled);
    assert_eq!(plan.textures.textures, 1);
    assert_eq!(out.counts.emission_lookups, 16);
    let glow = Vec3::new(2.0, 1.0, 0.5);
    assert_eq!(out.frame.pixel(0, 3), glow * rgb(RED), "bottom-left");
    assert_eq!(out.frame.pixel(3, 0), glow * rgb(WHITE), "top-right");
    let (soup, kd) = scene(Vec3::ZERO);
    let (out, plan) = render(&soup, &kd, &opts(4, 4));
    assert!(!plan.emission.enabled);
    assert_eq!(plan.textures.textures, 0);
    assert_eq!(out.counts.emission_lookups, 0);
    assert_eq!(out.frame.pixel(0, 3), Vec3::ZERO);
}

/// An occlusion map leaves 1 + (g − 1)·strength of the ambient light and of a mirror's
/// reflection, texel by texel (g the texel's green); with neither to darken it is not read.
#[test]
fn occlusion_maps_darken_ambient_light_and_reflections_only() {
    let scene = |material: Material, ambient: Vec3| {
        let mut s = SceneBuilder::new();
        let t = s.texture(four_colours(Wrap::Clamp));
        let m = s.material(Material {
            occlusion_map: Some(formats::OcclusionMap {
                map: TextureRef {
                    texture: t,
                    tiling: Tiling::default(),
                },
                strength: 0.5,
            }),
            ..material
        });
        unity_quad(&mut s, 1.0, m, [Vec2::ZERO, Vec2::ONE]);
        s.soup.environment.ambient.sky = ambient;
        s.soup.environment.background = Vec3::new(0.25, 0.5, 1.0);
        s.camera(front_camera(0.5));
        s.build()
    };
    // Red and blue texels have no green: half the light is left; green and white keep it.
    let half_and_whole = |out: &render::Rendered, full: Vec3| {
        assert_eq!(out.frame.pixel(0, 3), full * 0.5, "bottom-left, red");
        assert_eq!(out.frame.pixel(3, 3), full, "bottom-right, green");
        assert_eq!(out.frame.pixel(0, 0), full * 0.5, "top-left, blue");
        assert_eq!(out.frame.pixel(3, 0), full, "top-right, white");
    };
    let grey = Vec3::splat(0.6);
    let (soup, kd) = scene(diffuse(Vec3::ONE), grey);
    let (out, plan) = render(&soup, &kd, &opts(4, 4));
    assert!(
        plan.ambient.reason.contains("1 materials darken it"),
        "{}",
        plan.ambient.reason
    );
    assert_eq!(out.counts.occlusion_lookups, 16);
    half_and_whole(&out, grey);

    // A mirror facing the camera reflects the background, darkened alike.
    let (soup, kd) = scene(mirror(1.0), Vec3::ZERO);
    let out = render_alike_at_tiles(&soup, &kd, &opts(4, 4));
    half_and_whole(&out, soup.environment.background);

    // No ambient light and no mirror: nothing to darken, no texel read.
    let (soup, kd) = scene(diffuse(Vec3::ONE), Vec3::ZERO);
    let (out, plan) = render(&soup, &kd, &opts(4, 4));
    assert_eq!(
        (plan.textures.textures, out.counts.occlusion_lookups),
        (0, 0)
    );
    assert_eq!(out.frame.pixel(0, 3), Vec3::ZERO);
}
