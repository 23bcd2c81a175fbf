//! The tree answers exactly what testing every triangle answers: same triangle, or the
//! same t within 1e-6 relative for ties.

use formats::{BuildParams, Hit};
use glam::Vec3;
use kdtree::testkit::{self, brute};
use kdtree::{Accel, Ray};
use proptest::prelude::*;

fn check(tris: &[[Vec3; 3]], accel: &Accel, ray: &Ray) -> Result<(), TestCaseError> {
    let want = brute::intersect(tris, ray);
    same_hit(ray, want, accel.intersect(ray))?;
    prop_assert_eq!(
        accel.occluded(ray),
        want.is_some(),
        "any-hit disagrees with closest-hit for {:?}",
        ray
    );
    // A filter that refuses every third triangle, as cut-out texels are refused, and the
    // back of every fifth, as culled faces are: the tree passes through them exactly as the
    // brute-force loop does.
    let keep = |h: &formats::Hit, front: bool| {
        !h.prim.is_multiple_of(3) && (front || !h.prim.is_multiple_of(5))
    };
    let want = brute::intersect_filtered(tris, ray, keep);
    same_hit(ray, want, accel.intersect_filtered(ray, keep))?;
    prop_assert_eq!(
        accel.occluded_filtered(ray, keep),
        want.is_some(),
        "filtered any-hit disagrees with filtered closest-hit for {:?}",
        ray
    );
    prop_assert_eq!(
        accel.occluded_filtered_in_order(ray, keep),
        want.is_some(),
        "in-order filtered any-hit disagrees with filtered closest-hit for {:?}",
        ray
    );
    Ok(())
}

fn same_hit(ray: &Ray, want: Option<Hit>, got: Option<Hit>) -> Result<(), TestCaseError> {
    match (want, got) {
        (None, None) => {}
        (Some(w), Some(g)) => {
            prop_assert!(
                w.prim == g.prim || (w.t - g.t).abs() <= 1e-6 * w.t.abs(),
                "ray {ray:?}: brute {w:?}, tree {g:?}"
            );
            if w.prim == g.prim {
                prop_assert_eq!(w.t, g.t);
            }
        }
        _ => prop_assert!(false, "ray {ray:?}: brute {want:?}, tree {got:?}"),
    }
    Ok(())
}

/// Coordinates on a coarse lattice, so that triangles share planes, edges and vertices
/// with each other and with the split planes the build picks.
fn lattice() -> impl Strategy<Value = f32> {
    (-8i32..=8).prop_map(|i| i as f32 * 0.5)
}

fn lattice_vec() -> impl Strategy<Value = Vec3> {
    (lattice(), lattice(), lattice()).prop_map(|(x, y, z)| Vec3::new(x, y, z))
}

fn free_vec() -> impl Strategy<Value = Vec3> {
    (-5.0f32..5.0, -5.0f32..5.0, -5.0f32..5.0).prop_map(|(x, y, z)| Vec3::new(x, y, z))
}

/// Directions: random, or axis-aligned with +0 and −0 in the other components.
fn direction() -> impl Strategy<Value = Vec3> {
    let zero = prop_oneof![Just(0.0f32), Just(-0.0f32)];
    let unit = prop_oneof![Just(1.0f32), Just(-1.0f32)];
    prop_oneof![
        free_vec().prop_filter("nonzero", |v| v.length() > 1e-3),
        (0usize..3, unit, zero.clone(), zero).prop_map(|(a, s, z1, z2)| {
            let mut d = [z1, z1, z2];
            d[(a + 1) % 3] = z1;
            d[(a + 2) % 3] = z2;
            d[a] = s;
            Vec3::from(d)
        }),
        // In a coordinate plane: one component ±0.
        (
            free_vec(),
            0usize..3,
            prop_oneof![Just(0.0f32), Just(-0.0f32)]
        )
            .prop_map(|(v, a, z)| {
                let mut d = v.to_array();
                d[a] = z;
                if d.iter().all(|c| *c == 0.0) {
                    d[(a + 1) % 3] = 1.0;
                }
                Vec3::from(d)
            }),
    ]
}

fn ray() -> impl Strategy<Value = Ray> {
    (
        prop_oneof![lattice_vec(), free_vec()],
        direction(),
        prop_oneof![Just(0.0f32), 0.0f32..2.0],
        prop_oneof![Just(f32::INFINITY), 0.5f32..20.0],
    )
        .prop_map(|(o, d, tmin, tmax)| Ray::new(o, d, tmin, tmax))
}

fn lattice_tri() -> impl Strategy<Value = [Vec3; 3]> {
    [lattice_vec(), lattice_vec(), lattice_vec()]
}

fn free_tri() -> impl Strategy<Value = [Vec3; 3]> {
    [free_vec(), free_vec(), free_vec()]
}

fn params() -> impl Strategy<Value = BuildParams> {
    (1u32..4, 0.0f32..1.0, 0u32..12).prop_map(|(leaf, bonus, depth)| BuildParams {
        leaf_size: leaf,
        empty_bonus: bonus,
        max_depth: depth,
        ..BuildParams::default()
    })
}

/// A flat 4 × 4 grid of `n` × `n` cells at y = 0, then one right-triangle wall per entry
/// `(axis, c, a, b)`: in the plane `axis` = c, legs of length 1 from (a, b) in the next two
/// axes' coordinates.
fn grid_with_walls(n: usize, walls: &[(usize, f32, f32, f32)]) -> Vec<[Vec3; 3]> {
    let mut tris = testkit::grid(n, 4.0, 0.0);
    for &(axis, c, a, b) in walls {
        let p = |u: f32, w: f32| {
            let mut v = [0.0; 3];
            v[axis] = c;
            v[(axis + 1) % 3] = u;
            v[(axis + 2) % 3] = w;
            Vec3::from(v)
        };
        tris.push([p(a, b), p(a + 1.0, b), p(a, b + 1.0)]);
    }
    tris
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn random_soups(
        tris in prop::collection::vec(prop_oneof![lattice_tri(), free_tri()], 1..80),
        rays in prop::collection::vec(ray(), 64),
        p in params(),
    ) {
        let accel = Accel::build(&tris, &p);
        for r in &rays {
            check(&tris, &accel, r)?;
        }
    }

    /// All triangles in one plane (y = 1), rays in that plane and through it.
    #[test]
    fn planar_scene(
        xz in prop::collection::vec(((lattice(), lattice()), (lattice(), lattice()), (lattice(), lattice())), 1..60),
        rays in prop::collection::vec(ray(), 64),
        in_plane in prop::collection::vec((free_vec(), free_vec()), 16),
    ) {
        let tris: Vec<[Vec3; 3]> = xz
            .iter()
            .map(|&((a, b), (c, d), (e, f))| [Vec3::new(a, 1.0, b), Vec3::new(c, 1.0, d), Vec3::new(e, 1.0, f)])
            .collect();
        let accel = Accel::build(&tris, &BuildParams::default());
        for r in &rays {
            check(&tris, &accel, r)?;
        }
        for (o, d) in &in_plane {
            let r = Ray::new(Vec3::new(o.x, 1.0, o.z), Vec3::new(d.x, 0.0, d.z + 0.1), 0.0, f32::INFINITY);
            check(&tris, &accel, &r)?;
        }
    }

    /// A flat grid of shared edges plus axis-aligned walls lying in lattice planes (where
    /// the build puts its splits); rays aimed at grid vertices and edge midpoints.
    #[test]
    fn shared_edges_and_split_planes(
        n in 2usize..9,
        walls in prop::collection::vec((0usize..3, lattice(), lattice(), lattice()), 0..12),
        targets in prop::collection::vec((0usize..9, 0usize..9, 0usize..3, free_vec()), 48),
    ) {
        let tris = grid_with_walls(n, &walls);
        let accel = Accel::build(&tris, &BuildParams::default());
        let step = 4.0 / n as f32;
        for &(i, k, kind, o) in &targets {
            let (i, k) = (i.min(n - 1) as f32, k.min(n - 1) as f32);
            let target = match kind {
                0 => Vec3::new(i * step, 0.0, k * step),                 // vertex
                1 => Vec3::new((i + 0.5) * step, 0.0, k * step),         // edge midpoint
                _ => Vec3::new((i + 0.5) * step, 0.0, (k + 0.5) * step), // diagonal midpoint
            };
            let origin = Vec3::new(o.x, o.y.abs() + 0.5, o.z);
            let r = Ray::new(origin, target - origin, 0.0, f32::INFINITY);
            check(&tris, &accel, &r)?;
            // Straight down, with ±0 sideways components.
            for d in [Vec3::new(0.0, -1.0, 0.0), Vec3::new(-0.0, -1.0, -0.0)] {
                let r = Ray::new(target + Vec3::Y, d, 0.0, f32::INFINITY);
                check(&tris, &accel, &r)?;
                let hit = accel.intersect(&r);
                prop_assert!(hit.is_some(), "vertical ray at {target} slipped through the grid");
            }
        }
    }
}

/// Rays on a lattice whose origins lie exactly on the split planes of a regular grid
/// of boxes, with every combination of ±0 direction components.
#[test]
fn origins_on_split_planes_with_signed_zeros() {
    let mut tris = Vec::new();
    for i in 0..4 {
        for j in 0..4 {
            let c = Vec3::new(i as f32 * 2.0, j as f32 * 2.0, 0.0);
            tris.extend(testkit::grid_box(c, 0.5, 1));
        }
    }
    let accel = Accel::build(&tris, &BuildParams::default());
    let mut hits = 0;
    for x in 0..13 {
        for y in 0..13 {
            let o = Vec3::new(x as f32 * 0.5 - 0.5, y as f32 * 0.5 - 0.5, -5.0);
            for sx in [0.0f32, -0.0] {
                for sy in [0.0f32, -0.0] {
                    let r = Ray::new(o, Vec3::new(sx, sy, 1.0), 0.0, f32::INFINITY);
                    let want = brute::intersect(&tris, &r);
                    assert_eq!(accel.intersect(&r), want, "{r:?}");
                    assert_eq!(accel.occluded(&r), want.is_some());
                    hits += want.is_some() as usize;
                }
            }
        }
    }
    // Origins at x, y ∈ {−0.5, 0, …, 5.5}; boxes span [c−0.5, c+0.5] for c = 0, 2, 4, 6,
    // edges included, so 10 of the 13 positions per axis are over a box: 100 origins
    // hit, times 4 sign pairs.
    assert_eq!(hits, 100 * 4);
}

/// Bad rays are misses: NaN, infinities, zero direction, empty interval.
#[test]
fn nan_and_infinite_rays_miss() {
    let tris = testkit::grid_box(Vec3::ZERO, 1.0, 2);
    let accel = Accel::build(&tris, &BuildParams::default());
    let o = Vec3::new(0.0, 0.0, -5.0);
    let bad = [
        Ray::new(Vec3::NAN, Vec3::Z, 0.0, f32::INFINITY),
        Ray::new(o, Vec3::new(f32::NAN, 0.0, 1.0), 0.0, f32::INFINITY),
        Ray::new(o, Vec3::new(f32::INFINITY, 0.0, 1.0), 0.0, f32::INFINITY),
        Ray::new(
            Vec3::new(f32::NEG_INFINITY, 0.0, 0.0),
            Vec3::X,
            0.0,
            f32::INFINITY,
        ),
        Ray::new(o, Vec3::ZERO, 0.0, f32::INFINITY),
        Ray::new(o, Vec3::Z, f32::NAN, f32::INFINITY),
        Ray::new(o, Vec3::Z, 0.0, f32::NAN),
        Ray::new(o, Vec3::Z, 10.0, 1.0),
        Ray::new(o, Vec3::Z, f32::INFINITY, f32::INFINITY),
    ];
    for r in &bad {
        assert_eq!(accel.intersect(r), None, "{r:?}");
        assert!(!accel.occluded(r), "{r:?}");
        assert_eq!(brute::intersect(&tris, r), None, "{r:?}");
    }
    // The same ray with sane numbers hits the box's −z face at t = 4.
    let good = accel
        .intersect(&Ray::new(o, Vec3::Z, 0.0, f32::INFINITY))
        .unwrap();
    assert_eq!(good.t, 4.0);
}

/// A ray lying in two split planes at once (x = 2 and z = 1, straight down) through the
/// corner of a small wall above a grid. Both children of each such split wait over the whole
/// interval, so the waiting cells are not front to back: the closest-hit loop once took a
/// waiting cell that starts beyond the grid hit for the end of the search and missed the
/// wall's corner at t = 0.5 (found by `shared_edges_and_split_planes`).
#[test]
fn a_ray_in_two_split_planes_finds_the_nearer_corner() {
    let walls = [
        (1, 0.5, 1.0, 2.0),
        (0, 0.0, 0.0, -3.5),
        (2, 0.0, 0.0, -0.5),
        (1, -2.5, 1.0, 0.0),
    ];
    let tris = grid_with_walls(4, &walls);
    let accel = Accel::build(&tris, &BuildParams::default());
    let ray = Ray::new(Vec3::new(2.0, 1.0, 1.0), Vec3::NEG_Y, 0.0, f32::INFINITY);
    let hit = accel.intersect(&ray).expect("the wall's corner is hit");
    // The first wall, y = 0.5 with corner (2, 0.5, 1), is triangle 32 (after the grid's 32).
    assert_eq!((hit.t, hit.prim), (0.5, 32));
    let want = brute::intersect(&tris, &ray).expect("brute force hits it too");
    assert_eq!((hit.t, hit.prim), (want.t, want.prim));
}
