//! Numerical hard cases (docs/ROBUSTNESS.md): closed meshes never leak, vertex and edge
//! hits are never lost, tiny/huge/needle triangles are hit, degenerate input is harmless,
//! and the f32 intersector agrees with an f64 reference. (The same leak test on a corpus
//! mesh is in the bench crate, which reads OBJ files.)

use formats::BuildParams;
use glam::{DVec3, Vec3};
use kdtree::testkit::{brute, escapes, grid, grid_box, sphere, Rng};
use kdtree::triangle::{intersect, RayPre};
use kdtree::{Accel, Ray};
use proptest::prelude::*;

/// The closed test meshes: (name, triangles, centre, half-size).
fn closed_meshes() -> Vec<(String, Vec<[Vec3; 3]>, Vec3, f32)> {
    let mut v = Vec::new();
    for (label, scale, center) in [
        ("scale 1", 1.0f32, Vec3::ZERO),
        ("scale 1e-3", 1e-3, Vec3::ZERO),
        ("scale 1e5", 1e5, Vec3::ZERO),
        ("offset 1e5", 1.0, Vec3::splat(1e5)),
        ("offset 1e5 on one axis", 1.0, Vec3::new(1e5, 0.0, 0.0)),
    ] {
        v.push((
            format!("sphere {label}"),
            sphere(center, scale, 32, 64),
            center,
            scale,
        ));
        v.push((
            format!("box {label}"),
            grid_box(center, 0.5 * scale, 8),
            center,
            0.5 * scale,
        ));
    }
    v
}

#[test]
fn closed_meshes_never_leak_million() {
    for (i, (name, tris, c, half)) in closed_meshes().iter().enumerate() {
        let leaks = escapes(tris, *c, *half, 1_000_000, 2000 + i as u64);
        assert_eq!(leaks, 0, "{name}: {leaks} rays escaped");
    }
}

/// Rays from the centre aimed exactly at every vertex and every edge midpoint.
#[test]
fn vertices_and_edge_midpoints_always_hit() {
    for (name, tris, c, _) in closed_meshes() {
        let accel = Accel::build(&tris, &BuildParams::default());
        let mut aimed = 0;
        for t in &tris {
            for k in 0..3 {
                for target in [t[k], 0.5 * (t[k] + t[(k + 1) % 3])] {
                    let r = Ray::new(c, target - c, 0.0, f32::INFINITY);
                    let h = accel.intersect(&r);
                    assert!(
                        h.is_some(),
                        "{name}: ray at {target} from the centre escaped"
                    );
                    aimed += 1;
                }
            }
        }
        assert_eq!(aimed, tris.len() * 6);
    }
}

/// Aim at a triangle's centroid from a few directions; it must be hit, at the right t.
fn hit_at_centroid(tri: [Vec3; 3], what: &str) {
    let scale = (tri[1] - tri[0]).length().max((tri[2] - tri[0]).length());
    // A second triangle well away, so the tree has something to split.
    let away = Vec3::splat(5.0 * scale);
    let tris = vec![tri, [tri[0] + away, tri[1] + away, tri[2] + away]];
    let accel = Accel::build(&tris, &BuildParams::default());
    let c = (tri[0] + tri[1] + tri[2]) / 3.0;
    let n = (tri[1] - tri[0]).cross(tri[2] - tri[0]).normalize();
    for d in [
        n,
        -n,
        (n + 0.3 * Vec3::X).normalize(),
        (n - 0.5 * Vec3::Z).normalize(),
    ] {
        let origin = c - d * scale;
        let r = Ray::new(origin, d, 0.0, f32::INFINITY);
        let h = accel
            .intersect(&r)
            .unwrap_or_else(|| panic!("{what}: missed from {d}"));
        assert_eq!(h.prim, 0, "{what}");
        let p = origin + h.t * d;
        assert!(
            (p - c).length() <= 1e-3 * scale + 1e-6 * c.abs().max_element(),
            "{what}: {p} vs {c}"
        );
        assert_eq!(brute::intersect(&tris, &r), Some(h));
    }
}

#[test]
fn tiny_huge_and_needle_triangles_hit_at_centroid() {
    let base = [
        Vec3::ZERO,
        Vec3::new(1.0, 0.0, 0.2),
        Vec3::new(0.1, 1.0, 0.0),
    ];
    for (what, s, off) in [
        ("tiny 1e-6 at the origin", 1e-6f32, Vec3::ZERO),
        ("tiny 1e-6 at 1", 1e-6, Vec3::ONE),
        ("huge 1e5", 1e5, Vec3::ZERO),
        ("unit at offset 1e5", 1.0, Vec3::splat(1e5)),
    ] {
        hit_at_centroid(
            [base[0] * s + off, base[1] * s + off, base[2] * s + off],
            what,
        );
    }
    hit_at_centroid(
        [
            Vec3::ZERO,
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.5, 1e-5, 1e-6),
        ],
        "needle 1 × 1e-5",
    );
    hit_at_centroid(
        [
            Vec3::ZERO,
            Vec3::new(1e3, 0.0, 0.0),
            Vec3::new(0.0, 1e-2, 0.0),
        ],
        "needle 1e3 × 1e-2",
    );
}

#[test]
fn degenerate_triangles_give_no_nan() {
    let p = Vec3::new(0.3, 0.2, 0.1);
    let mut tris = vec![
        [p, p, p],                                       // a point
        [Vec3::ZERO, Vec3::X, Vec3::X],                  // duplicate vertex
        [Vec3::ZERO, Vec3::X, Vec3::new(2.0, 0.0, 0.0)], // collinear
        [
            Vec3::ZERO,
            Vec3::new(1.0, 1.0, 1.0),
            Vec3::new(1e-30, 1e-30, 1e-30),
        ], // near-collinear
    ];
    // Coplanar overlapping and exactly duplicated triangles.
    let a = [
        Vec3::new(-1.0, 0.0, -1.0),
        Vec3::new(1.0, 0.0, -1.0),
        Vec3::new(0.0, 0.0, 1.0),
    ];
    tris.extend([
        a,
        a,
        [a[0], a[2], a[1]],
        [a[0] * 0.5, a[1] * 0.5, a[2] * 0.5],
    ]);
    let accel = Accel::build(&tris, &BuildParams::default());
    let mut rng = Rng(5);
    let mut hits = 0;
    for i in 0..20_000 {
        let o = Vec3::new(
            rng.range(-2.0, 2.0),
            rng.range(-2.0, 2.0),
            rng.range(-2.0, 2.0),
        );
        let d = if i % 4 == 0 { p - o } else { rng.dir() };
        let r = Ray::new(o, d, 0.0, f32::INFINITY);
        let h = accel.intersect(&r);
        let want = brute::intersect(&tris, &r);
        // Overlapping coplanar triangles tie in t: the same t is the same answer.
        assert_eq!(h.map(|h| h.t), want.map(|h| h.t), "{r:?}");
        if let Some(h) = h {
            assert!(
                h.t.is_finite() && h.u.is_finite() && h.v.is_finite(),
                "{h:?}"
            );
            hits += 1;
        }
    }
    assert!(
        hits > 1000,
        "the overlapping floor triangles are hit: {hits}"
    );
    // Straight down onto the overlapping floor: one of the tied floor triangles, at t = 1.
    let h = accel
        .intersect(&Ray::new(Vec3::new(0.1, 1.0, 0.0), -Vec3::Y, 0.0, 9.0))
        .unwrap();
    assert!((4..8).contains(&h.prim) && h.t == 1.0, "{h:?}");
}

/// Axis-aligned rays with +0/−0 components against Unity-style axis-aligned geometry:
/// a cube and a 10×10 plane floor whose faces lie in split planes.
#[test]
fn axis_aligned_rays_on_axis_aligned_geometry() {
    let mut tris = grid_box(Vec3::new(0.0, 0.5, 0.0), 0.5, 1); // Unity Cube on the floor
    tris.extend(
        grid(10, 10.0, 0.0)
            .iter()
            .map(|t| t.map(|v| v - Vec3::new(5.0, 0.0, 5.0))),
    );
    let accel = Accel::build(&tris, &BuildParams::default());
    let zeros = [0.0f32, -0.0];
    let mut checked = 0;
    for xi in -12..=12 {
        for zi in -12..=12 {
            let (x, z) = (xi as f32 * 0.5, zi as f32 * 0.5);
            for &zx in &zeros {
                for &zz in &zeros {
                    let r = Ray::new(
                        Vec3::new(x, 3.0, z),
                        Vec3::new(zx, -1.0, zz),
                        0.0,
                        f32::INFINITY,
                    );
                    let h = accel.intersect(&r);
                    assert_eq!(h, brute::intersect(&tris, &r));
                    let on_floor = x.abs() <= 5.0 && z.abs() <= 5.0;
                    let on_cube = x.abs() <= 0.5 && z.abs() <= 0.5;
                    match h {
                        Some(h) if on_cube => assert_eq!(h.t, 2.0, "cube top at ({x}, {z})"),
                        Some(h) => assert!(on_floor && h.t == 3.0, "floor at ({x}, {z}): {h:?}"),
                        None => assert!(!on_floor, "lost the floor at ({x}, {z})"),
                    }
                    checked += 1;
                }
            }
        }
    }
    assert_eq!(checked, 25 * 25 * 4);
    // Rays lying in the floor's plane (y = 0) and in the cube's side planes.
    for (o, d) in [
        (Vec3::new(-8.0, 0.0, 0.3), Vec3::new(1.0, 0.0, 0.0)),
        (Vec3::new(-8.0, 0.0, 0.3), Vec3::new(1.0, -0.0, 0.0)),
        (Vec3::new(0.5, 0.5, -8.0), Vec3::new(0.0, 0.0, 1.0)),
        (Vec3::new(-0.5, 2.0, 0.0), Vec3::new(-0.0, -1.0, 0.0)),
    ] {
        let r = Ray::new(o, d, 0.0, f32::INFINITY);
        assert_eq!(accel.intersect(&r), brute::intersect(&tris, &r), "{r:?}");
        assert!(
            accel.intersect(&r).is_some(),
            "in-plane ray {r:?} hits the geometry it lies on"
        );
    }
}

/// f64 reference: barycentrics of the ray's crossing of the triangle's plane.
fn reference(o: Vec3, d: Vec3, t: &[Vec3; 3]) -> Option<(f64, [f64; 3])> {
    let (o, d) = (o.as_dvec3(), d.as_dvec3());
    let [a, b, c] = t.map(|v| v.as_dvec3());
    let n = (b - a).cross(c - a);
    let dn = d.dot(n);
    if dn.abs() < 1e-12 * n.length() * d.length() {
        return None;
    }
    let tt = (a - o).dot(n) / dn;
    let p = o + tt * d;
    let area = |x: DVec3, y: DVec3, z: DVec3| (y - x).cross(z - x).dot(n) / n.length_squared();
    Some((tt, [area(p, b, c), area(a, p, c), area(a, b, p)]))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    /// Never a miss where the f64 reference hits well inside, never a hit well outside.
    #[test]
    fn f32_intersector_agrees_with_f64_reference(
        v in prop::array::uniform3(prop::array::uniform3(-10.0f32..10.0)),
        o in prop::array::uniform3(-20.0f32..20.0),
        aim in prop::array::uniform3(-0.2f64..1.2),
        scale_exp in -3i32..5,
    ) {
        let s = 10f32.powi(scale_exp);
        let tri = v.map(|p| Vec3::from(p) * s);
        let origin = Vec3::from(o) * s;
        // Aim at a point given by barycentrics (some outside the triangle).
        let w = [aim[0], aim[1], 1.0 - aim[0] - aim[1]];
        let target = tri[0].as_dvec3() * w[2] + tri[1].as_dvec3() * w[0] + tri[2].as_dvec3() * w[1];
        let d = (target - origin.as_dvec3()).as_vec3();
        prop_assume!(d.length() > 1e-3 * s);
        let Some((t, b)) = reference(origin, d, &tri) else { return Ok(()) };
        let pre = RayPre::new(origin, d).unwrap();
        let arr = tri.map(|p| p.to_array());
        let got = intersect(&pre, &arr, 0.0, f32::INFINITY);
        let min_b = b.iter().cloned().fold(f64::INFINITY, f64::min);
        if t > 1e-3 && min_b > 1e-3 {
            prop_assert!(got.is_some(), "missed: t {t}, barycentrics {b:?}");
            let h = got.unwrap();
            prop_assert!(((h.t as f64) - t).abs() <= 1e-3 * t.abs().max(1.0), "t {} vs {t}", h.t);
        }
        if min_b < -1e-3 {
            prop_assert!(got.is_none(), "hit outside: barycentrics {b:?}, got {got:?}");
        }
    }
}
