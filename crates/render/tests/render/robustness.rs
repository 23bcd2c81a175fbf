//! Secondary rays stay robust: no self-intersection at any scale or distance from the
//! origin, no acne under grazing light, finite images always.

use crate::common::*;
use formats::{Camera, Projection, Shadows};
use glam::Vec3;
use kdtree::{Accel, Ray};
use render::offset::{hit_point, intersector_margin, offset_origin};
use render::sampling::Rng;

fn unit_sphere_dir(rng: &mut Rng) -> Vec3 {
    loop {
        let v = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0 - 1.0;
        let l = v.length_squared();
        if l > 1e-4 && l <= 1.0 {
            return v / l.sqrt();
        }
    }
}

#[test]
fn spawned_rays_never_rehit_their_own_triangle() {
    // (size of the triangle, distance of its corner from the origin)
    let cases = [
        (1e-5f32, 0.0f32),
        (1e-3, 1e3),
        (1.0, 0.0),
        (1.0, 1e5),
        (1e5, 0.0),
        (10.0, -1e5),
    ];
    let mut rng = Rng::new(42);
    for (size, at) in cases {
        for _ in 0..4 {
            // A randomly oriented triangle near `at` on every axis.
            let o = Vec3::splat(at) + unit_sphere_dir(&mut rng) * size;
            let tri = [
                o,
                o + unit_sphere_dir(&mut rng) * size,
                o + unit_sphere_dir(&mut rng) * size,
            ];
            let ng = (tri[1] - tri[0]).cross(tri[2] - tri[0]).normalize_or_zero();
            if ng == Vec3::ZERO {
                continue;
            }
            let mut b = SceneBuilder::new();
            let m = b.diffuse(Vec3::ONE);
            b.soup.objects.push(formats::Object::new("tri", "test"));
            b.soup.push_triangle(tri, [ng; 3], None);
            b.soup.tri_material.push(m);
            b.soup.tri_object.push(0);
            let (soup, kd) = b.build();
            let accel = Accel::new(&soup, kd).unwrap();
            let mut spawned = 0;
            for _ in 0..2500 {
                // Aim a primary ray at a random interior point, from a random side.
                let (mut u, mut v) = (rng.next_f32(), rng.next_f32());
                if u + v > 1.0 {
                    (u, v) = (1.0 - u, 1.0 - v);
                }
                let target = tri[0] * (1.0 - u - v) + tri[1] * u + tri[2] * v;
                let from = target + unit_sphere_dir(&mut rng) * size * 2.0;
                let dir = (target - from).normalize();
                let Some(hit) = accel.intersect(&Ray {
                    origin: from,
                    dir,
                    tmin: render::offset::SPAWN_TMIN,
                    tmax: f32::INFINITY,
                }) else {
                    continue;
                };
                let (p, err) = hit_point(&tri, hit.u, hit.v);
                let margin = intersector_margin(&tri);
                // Leave towards either side (reflection and transmission-like directions).
                for w in [unit_sphere_dir(&mut rng), -dir, dir] {
                    let origin = offset_origin(p, err, margin, ng, w);
                    let again = accel.intersect(&Ray {
                        origin,
                        dir: w,
                        tmin: render::offset::SPAWN_TMIN,
                        tmax: f32::INFINITY,
                    });
                    assert!(
                        again.is_none(),
                        "size {size} at {at}: a ray spawned at {p} along {w} re-hit its triangle at t = {}",
                        again.unwrap().t
                    );
                    // The offset follows the rounding error, not a fixed epsilon.
                    assert!(
                        (origin - p).length()
                            <= (err.length() + margin + p.abs().max_element() * 1e-6) * 4.0
                    );
                    spawned += 1;
                }
            }
            assert!(spawned > 3000, "{spawned} rays spawned");
        }
    }
}

/// A floor far from the origin lit by a sun at 89° from its normal, with hard shadows:
/// any self-shadowing (acne) would darken pixels below the cosine law.
#[test]
fn grazing_light_far_from_the_origin_makes_no_acne() {
    for centre in [Vec3::ZERO, Vec3::new(1e5, 1e5, -1e5), Vec3::splat(-3e4)] {
        let mut s = SceneBuilder::new();
        let m = s.diffuse(Vec3::splat(0.8));
        s.floor(centre.y, centre.x, centre.z, 40.0, m);
        let r = 89.0f32.to_radians();
        s.light(directional_light(
            Vec3::new(r.sin(), -r.cos(), 0.0),
            10.0,
            Shadows::Hard,
        ));
        // A point light skimming the floor too.
        let mut p = point_light(
            centre + Vec3::new(-30.0, 0.3, 0.0),
            5.0,
            100.0,
            Shadows::Hard,
        );
        p.name = "skimming".into();
        s.light(p);
        s.camera(top_down_camera(centre + Vec3::new(0.0, 10.0, 0.0), 8.0));
        let (soup, kd) = s.build();
        let (w, h) = (48, 48);
        let (out, _) = render(&soup, &kd, &opts(w, h));
        assert_eq!(out.counts.shadow, 2 * (w * h) as u64);
        for py in 0..h {
            for px in 0..w {
                let q = ortho_point(&soup.camera, w, h, px, py, centre.y);
                let to = soup.lights[1].position - q;
                let d = to.length();
                let want = 0.8 * 10.0 * r.cos() + 0.8 * 5.0 * unity_falloff(d, 100.0) * (to.y / d);
                let got = out.frame.pixel(px, py).x;
                assert!(
                    (got - want).abs() <= want * 0.01,
                    "floor at {centre}: pixel ({px}, {py}) is {got}, want {want} (acne?)"
                );
            }
        }
    }
}

#[test]
fn a_tiny_box_casts_a_shadow_and_leaks_no_light() {
    // At millimetre scale: a 1 mm box on a floor, lit from above; the floor under the box
    // is seen through no gap and the shadow beside it is dark.
    let mut s = SceneBuilder::new();
    let m = s.diffuse(Vec3::ONE);
    s.floor(0.0, 0.0, 0.0, 0.02, m);
    s.cube(
        "mm box",
        Vec3::new(-0.0005, 0.0, -0.0005),
        Vec3::new(0.0005, 0.001, 0.0005),
        m,
    );
    let r = 45.0f32.to_radians();
    s.light(directional_light(
        Vec3::new(r.sin(), -r.cos(), 0.0),
        1.0,
        Shadows::Hard,
    ));
    s.camera(top_down_camera(Vec3::new(0.0, 0.01, 0.0), 0.002));
    let (soup, kd) = s.build();
    let (out, _) = render(&soup, &kd, &opts(40, 40));
    let lit = r.cos();
    let mut dark = 0;
    for py in 0..40 {
        for px in 0..40 {
            let q = ortho_point(&soup.camera, 40, 40, px, py, 0.0);
            let got = out.frame.pixel(px, py).x;
            let on_box = q.x.abs() < 0.0005 && q.z.abs() < 0.0005;
            // The sun travels towards +X and down at 45°: the 1 mm box's shadow falls on
            // x ∈ [0.5, 1.5] mm.
            let shadowed = q.x > 0.0005 + 1e-5 && q.x < 0.0015 - 1e-5 && q.z.abs() < 0.0005 - 1e-5;
            if shadowed {
                assert_eq!(got, 0.0, "light leaks at {q}");
                dark += 1;
            } else if !on_box && (q.x.abs() > 0.0016 || q.z.abs() > 0.0006) {
                assert!((got - lit).abs() < lit * 1e-3, "acne at {q}: {got}");
            }
        }
    }
    assert!(dark > 20, "{dark} shadowed pixels");
}

#[test]
fn facing_mirrors_at_depth_16_stay_finite() {
    let mut s = SceneBuilder::new();
    let m = s.material(mirror(1.0));
    for z in [-1.0f32, 1.0] {
        s.quad(
            "mirror",
            Vec3::new(-1e3, -1e3, z),
            Vec3::new(2e3, 0.0, 0.0),
            Vec3::new(0.0, 2e3, 0.0),
            m,
        );
    }
    s.camera(Camera {
        name: "between".into(),
        position: Vec3::new(0.0, 0.0, 0.0),
        forward: Vec3::new(0.2, 0.1, 1.0).normalize(),
        up: Vec3::Y,
        projection: Projection::Perspective { fov_y: 60.0 },
        near: 0.01,
        far: f32::INFINITY,
    });
    s.soup.environment.background = Vec3::splat(1e30);
    let (soup, kd) = s.build();
    let mut o = opts(16, 16);
    o.depth = 16;
    let (out, _) = render(&soup, &kd, &o);
    assert_eq!(
        out.counts.reflection,
        256 * 16,
        "every path bounces to the depth limit"
    );
    assert!(out.frame.color.iter().all(|c| c.is_finite()));
}

#[test]
fn nan_and_infinite_radiance_is_sanitised_and_counted() {
    let mut s = SceneBuilder::new();
    let mut m = emissive(Vec3::new(f32::NAN, 1.0, f32::INFINITY));
    m.color = Vec3::ZERO;
    let id = s.material(m);
    s.floor(0.0, 0.0, 0.0, 20.0, id);
    s.camera(top_down_camera(Vec3::new(0.0, 10.0, 0.0), 5.0));
    // A light of infinite intensity is planned off, not traced.
    s.light(point_light(
        Vec3::new(0.0, 1.0, 0.0),
        f32::INFINITY,
        10.0,
        Shadows::Hard,
    ));
    let (soup, kd) = s.build();
    let (out, plan) = render(&soup, &kd, &opts(8, 8));
    assert!(!plan.lights[0].enabled);
    assert_eq!(out.counts.sanitized, 64);
    assert_eq!(out.frame.pixel(4, 4), Vec3::new(0.0, 1.0, 0.0));
}
