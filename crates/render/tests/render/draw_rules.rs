//! Unity's draw rules with known pixel values: one-sided materials, shadow casting and
//! receiving, and light culling masks.

use crate::common::*;
use formats::{CastShadows, Cull, Material, Shadows};
use glam::Vec3;

const WALL: Vec3 = Vec3::new(0.2, 0.4, 0.6);
const QUAD: Vec3 = Vec3::new(0.9, 0.1, 0.3);

fn emissive_cull(e: Vec3, cull: Cull) -> Material {
    Material {
        cull,
        ..emissive(e)
    }
}

/// A glowing wall at y = 0 facing up, and a glowing quad at y = 5 over it whose front faces
/// `quad_up` (+Y, towards the camera) or −Y; a camera above looks down at both.
fn quad_over_wall(cull: Cull, quad_up: bool) -> SceneBuilder {
    let mut s = SceneBuilder::new();
    let wall = s.material(emissive_cull(WALL, Cull::Back));
    s.floor(0.0, 0.0, 0.0, 20.0, wall);
    let q = s.material(emissive_cull(QUAD, cull));
    let (u, v) = (Vec3::new(0.0, 0.0, 2.0), Vec3::new(2.0, 0.0, 0.0));
    let (u, v) = if quad_up { (u, v) } else { (v, u) };
    s.quad("quad", Vec3::new(-1.0, 5.0, -1.0), u, v, q);
    s.camera(top_down_camera(Vec3::new(0.0, 10.0, 0.0), 2.0));
    s
}

#[test]
fn a_one_sided_quad_seen_from_behind_shows_the_wall_behind_it() {
    let (soup, kd) = quad_over_wall(Cull::Back, false).build();
    let (out, plan) = render(&soup, &kd, &opts(20, 20));
    // The quad covers the middle half of the view; the camera sees its back.
    assert_eq!(out.frame.pixel(10, 10), WALL);
    assert_eq!(out.frame.pixel(0, 0), WALL);
    // One refused hit per pixel on the quad, two on the 10 pixels of its diagonal, where
    // the ray meets both of its triangles at the same t.
    assert_eq!(
        out.counts.pass_through,
        10 * 10 + 10,
        "pass-throughs on the quad"
    );
    assert!(plan.culling.enabled);
    assert!(
        plan.culling
            .reason
            .contains("back-face culling: 2 materials"),
        "{}",
        plan.culling.reason
    );
    assert!(plan.describe().contains("back-face culling: 2 materials"));
}

/// Culled faces met by camera rays traced in 2×2 blocks: tiles of one pixel (no blocks), of
/// 5 and of 32 give the same pixels and the same pass-throughs.
#[test]
fn culled_faces_are_passed_alike_in_blocks_and_alone() {
    let (soup, kd) = quad_over_wall(Cull::Back, false).build();
    let out = render_alike_at_tiles(&soup, &kd, &opts(21, 19));
    assert!(out.counts.pass_through > 50, "{:?}", out.counts);
    assert_eq!(out.frame.pixel(10, 9), WALL);
}

#[test]
fn a_two_sided_quad_seen_from_behind_shows() {
    let (soup, kd) = quad_over_wall(Cull::None, false).build();
    let (out, plan) = render(&soup, &kd, &opts(20, 20));
    assert_eq!(out.frame.pixel(10, 10), QUAD);
    assert_eq!(out.frame.pixel(0, 0), WALL);
    assert_eq!(out.counts.pass_through, 0);
    assert!(plan
        .culling
        .reason
        .contains("back-face culling: 1 materials"));
}

#[test]
fn a_front_culled_quad_facing_the_camera_is_invisible_and_back_culled_one_shows() {
    let (soup, kd) = quad_over_wall(Cull::Front, true).build();
    let (out, _) = render(&soup, &kd, &opts(20, 20));
    assert_eq!(out.frame.pixel(10, 10), WALL);
    let (soup, kd) = quad_over_wall(Cull::Back, true).build();
    let (out, _) = render(&soup, &kd, &opts(20, 20));
    assert_eq!(out.frame.pixel(10, 10), QUAD);
    assert_eq!(out.counts.pass_through, 0);
}

#[test]
fn two_sided_scenes_pay_nothing_for_culling() {
    let mut s = SceneBuilder::new();
    let m = s.material(emissive(WALL));
    s.floor(0.0, 0.0, 0.0, 20.0, m);
    s.camera(top_down_camera(Vec3::new(0.0, 10.0, 0.0), 2.0));
    let (soup, kd) = s.build();
    let (out, plan) = render(&soup, &kd, &opts(8, 8));
    assert!(!plan.culling.enabled);
    assert!(!plan.shadow_casting.enabled);
    assert_eq!(out.counts.pass_through + out.counts.shadow_pass_through, 0);
}

/// A white floor lit by a sun travelling along (−1, −1, 0) and a 1 m blocker quad at
/// y = 1 over x, z ∈ [−0.55, 0.45] (5 × 5 pixel centres, none on an edge) facing
/// `blocker_up`; its shadow falls on x ∈ [−1.55, −0.55]. The camera sees x, z ∈ [−2, 2]
/// from above, 20 × 20 pixels.
struct Shadowed {
    scene: SceneBuilder,
    floor: u32,
    blocker: u32,
}

fn shadowed(blocker_cull: Cull, blocker_up: bool) -> Shadowed {
    let mut s = SceneBuilder::new();
    let white = s.material(Material {
        cull: Cull::Back,
        ..diffuse(Vec3::ONE)
    });
    let floor = s.floor(0.0, 0.0, 0.0, 20.0, white);
    let grey = s.material(Material {
        cull: blocker_cull,
        ..diffuse(Vec3::splat(0.5))
    });
    let (u, v) = (Vec3::new(0.0, 0.0, 1.0), Vec3::new(1.0, 0.0, 0.0));
    let (u, v) = if blocker_up { (u, v) } else { (v, u) };
    let blocker = s.quad("blocker", Vec3::new(-0.55, 1.0, -0.55), u, v, grey);
    s.light(directional_light(
        Vec3::new(-1.0, -1.0, 0.0),
        1.0,
        Shadows::Hard,
    ));
    s.camera(top_down_camera(Vec3::new(0.0, 10.0, 0.0), 2.0));
    Shadowed {
        scene: s,
        floor,
        blocker,
    }
}

/// Pixel (14, 10) sees the floor at (−0.9, 0, −0.1): in the blocker's shadow, not under it.
const IN_SHADOW: (u32, u32) = (14, 10);
/// Pixel (10, 10) sees the blocker from above (or the floor under it).
const UNDER: (u32, u32) = (10, 10);
const LIT: f32 = std::f32::consts::FRAC_1_SQRT_2;

fn pixel(s: Shadowed, at: (u32, u32)) -> (Vec3, render::Rendered, render::Plan) {
    let (soup, kd) = s.scene.build();
    let p = ortho_point(&soup.camera, 20, 20, IN_SHADOW.0, IN_SHADOW.1, 0.0);
    assert!((p - Vec3::new(-0.9, 0.0, -0.1)).length() < 1e-5, "{p}");
    let (out, plan) = render(&soup, &kd, &opts(20, 20));
    (out.frame.pixel(at.0, at.1), out, plan)
}

#[test]
fn a_blocker_casting_on_throws_a_shadow_from_the_face_the_light_sees() {
    let (v, _, plan) = pixel(shadowed(Cull::Back, true), IN_SHADOW);
    assert_eq!(v, Vec3::ZERO);
    assert!(
        plan.shadow_casting.enabled,
        "{}",
        plan.shadow_casting.reason
    );
    // Lit floor elsewhere: n·l = 1/√2.
    let (v, _, _) = pixel(shadowed(Cull::Back, true), (3, 10));
    assert_close(v, Vec3::splat(LIT), 1e-5, "lit floor");
}

#[test]
fn a_one_sided_blocker_facing_away_from_the_light_casts_no_shadow_unless_two_sided() {
    let (v, out, _) = pixel(shadowed(Cull::Back, false), IN_SHADOW);
    assert_close(
        v,
        Vec3::splat(LIT),
        1e-5,
        "the light sees the blocker's back",
    );
    assert!(out.counts.shadow_pass_through > 0);
    let mut s = shadowed(Cull::Back, false);
    s.scene.soup.objects[s.blocker as usize].cast_shadows = CastShadows::TwoSided;
    let (v, _, _) = pixel(s, IN_SHADOW);
    assert_eq!(v, Vec3::ZERO, "two-sided shadows cast from the back face");
}

#[test]
fn a_shadows_only_blocker_is_invisible_but_its_shadow_is_on_the_floor() {
    let mut s = shadowed(Cull::Back, true);
    s.scene.soup.objects[s.blocker as usize].cast_shadows = CastShadows::ShadowsOnly;
    let (v, out, plan) = pixel(s, IN_SHADOW);
    assert_eq!(v, Vec3::ZERO, "no direct light in its shadow");
    assert_eq!(plan.culling.shadows_only, 1);
    // From above the camera sees through the blocker to the lit floor under it.
    assert_close(
        out.frame.pixel(UNDER.0, UNDER.1),
        Vec3::splat(LIT),
        1e-5,
        "under",
    );
    // One refused hit per pixel on the blocker's top, two on its diagonal's 5 pixels.
    assert_eq!(
        out.counts.pass_through,
        5 * 5 + 5,
        "pass-throughs on the blocker"
    );
}

#[test]
fn a_blocker_casting_off_casts_no_shadow_but_shows() {
    let mut s = shadowed(Cull::None, true);
    s.scene.soup.objects[s.blocker as usize].cast_shadows = CastShadows::Off;
    let (v, out, plan) = pixel(s, IN_SHADOW);
    assert_close(v, Vec3::splat(LIT), 1e-5, "floor in the would-be shadow");
    assert_eq!(plan.shadow_casting.non_casting, 1);
    assert!(plan.shadow_casting.enabled);
    // The blocker itself is drawn, lit from its front: 0.5 · 1/√2.
    assert_close(
        out.frame.pixel(UNDER.0, UNDER.1),
        Vec3::splat(0.5 * LIT),
        1e-5,
        "blocker",
    );
}

#[test]
fn a_floor_that_receives_no_shadows_is_lit_under_the_occluder() {
    let mut s = shadowed(Cull::Back, true);
    s.scene.soup.objects[s.floor as usize].receive_shadows = false;
    let (v, out, plan) = pixel(s, IN_SHADOW);
    assert_close(v, Vec3::splat(LIT), 1e-5, "floor under the occluder");
    assert_eq!(plan.shadow_casting.not_receiving, 1);
    // Only the blocker's 25 pixels send shadow rays.
    assert_eq!(out.counts.shadow, 5 * 5);
}

#[test]
fn a_light_leaves_objects_outside_its_culling_mask_unlit() {
    let mut s = shadowed(Cull::None, true);
    s.scene.soup.objects[s.blocker as usize].layer = 8;
    s.scene.soup.lights[0].culling_mask = !(1 << 8);
    let (v, out, plan) = pixel(s, UNDER);
    assert_eq!(v, Vec3::ZERO, "the blocker on layer 8 is unlit");
    // Still casting: the light's mask decides what it lights, not what casts.
    assert_eq!(out.frame.pixel(IN_SHADOW.0, IN_SHADOW.1), Vec3::ZERO);
    assert_close(
        out.frame.pixel(3, 10),
        Vec3::splat(LIT),
        1e-5,
        "layer 0 floor",
    );
    // No shadow rays towards a light for a surface it does not light.
    assert_eq!(out.counts.shadow, 20 * 20 - 5 * 5);
    assert!(plan.lights[0]
        .reason
        .contains("lights layers 0xfffffeff only"));
}

/// A white floor lit by a sun travelling along `sun`, and a 1 m box over it at
/// y ∈ [1, 2], x, z ∈ [−0.5, 0.5] whose material culls `cull`; `open_top` leaves out its
/// two top triangles. The camera sees x, z ∈ [−2, 2] from above, 20 × 20 pixels.
fn box_over_floor(cull: Cull, open_top: bool, sun: Vec3) -> render::Rendered {
    let mut s = SceneBuilder::new();
    let white = s.material(Material {
        cull: Cull::Back,
        ..diffuse(Vec3::ONE)
    });
    s.floor(0.0, 0.0, 0.0, 20.0, white);
    let grey = s.material(Material {
        cull,
        ..diffuse(Vec3::splat(0.5))
    });
    let first = s.soup.triangles.len();
    s.cube(
        "box",
        Vec3::new(-0.5, 1.0, -0.5),
        Vec3::new(0.5, 2.0, 0.5),
        grey,
    );
    if open_top {
        // The builder writes bottom, top, −Z, +Z, −X, +X, two triangles each.
        let top = first + 2..first + 4;
        // Their vertices stay, unused.
        s.soup.triangles.drain(top.clone());
        s.soup.tri_material.drain(top.clone());
        s.soup.tri_object.drain(top);
    }
    s.light(directional_light(sun, 1.0, Shadows::Hard));
    s.camera(top_down_camera(Vec3::new(0.0, 10.0, 0.0), 2.0));
    let (soup, kd) = s.build();
    render(&soup, &kd, &opts(20, 20)).0
}

#[test]
fn a_closed_back_culled_box_shadows_exactly_as_a_two_sided_one() {
    // Shadow rays from the floor enter the box by a face the shadow pass culls and leave
    // by one that casts: whichever of the two the walk meets first, the ray is blocked,
    // and the image is the two-sided box's to the bit.
    let sun = Vec3::new(-1.0, -1.0, 0.0);
    let culled = box_over_floor(Cull::Back, false, sun);
    let two_sided = box_over_floor(Cull::None, false, sun);
    assert_eq!(two_sided.counts.shadow_pass_through, 0);
    for y in 0..20 {
        for x in 0..20 {
            let (a, b) = (culled.frame.pixel(x, y), two_sided.frame.pixel(x, y));
            let bits = |v: Vec3| v.to_array().map(f32::to_bits);
            assert_eq!(bits(a), bits(b), "pixel ({x}, {y})");
        }
    }
    // (−0.9, 0, −0.1) lies in the box's shadow, (−0.9, 0, −1.9) beside it (n·l = 1/√2).
    assert_eq!(culled.frame.pixel(14, 10), Vec3::ZERO);
    assert_close(
        culled.frame.pixel(14, 19),
        Vec3::splat(LIT),
        1e-5,
        "lit floor",
    );
}

#[test]
fn a_box_open_at_the_top_lets_the_light_through_its_culled_bottom() {
    // Under a sun straight above, the floor's shadow ray enters by the culled bottom and
    // leaves through the missing top: nothing casts, and the camera sees the lit floor
    // through the open top and the culled bottom.
    let out = box_over_floor(Cull::Back, true, Vec3::new(0.0, -1.0, 0.0));
    assert!(out.counts.shadow_pass_through > 0, "{:?}", out.counts);
    assert_close(
        out.frame.pixel(10, 10),
        Vec3::ONE,
        1e-5,
        "floor under the open box",
    );
}
