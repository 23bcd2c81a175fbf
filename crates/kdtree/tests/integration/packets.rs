//! Four rays traced together give each ray the answer it gets alone, bit for bit, and ask
//! the filter the same questions in the same order: closest hits and any hits.

use formats::{BuildParams, Hit};
use glam::Vec3;
use kdtree::testkit::{grid, grid_box, sphere, Rng};
use kdtree::{Accel, Ray, LANES};

/// What the filter was asked, per lane: (triangle, t bits, side).
type Asked = Vec<(u32, u32, bool)>;

/// Lane by lane, `intersect4` against `intersect` and `intersect4_filtered` against
/// `intersect_filtered` (refusing every third triangle and the back of every fifth), with
/// the filter's questions recorded on both sides, and the same for `occluded4` and
/// `occluded4_filtered`. Returns how many lanes hit.
fn check(accel: &Accel, rays: &[Ray; LANES]) -> usize {
    check_any(accel, rays);
    let got = accel.intersect4(rays);
    let keep =
        |h: &Hit, front: bool| !h.prim.is_multiple_of(3) && (front || !h.prim.is_multiple_of(5));
    let mut asked4: [Asked; LANES] = Default::default();
    let got_filtered = accel.intersect4_filtered(rays, |l, h, front| {
        asked4[l].push((h.prim, h.t.to_bits(), front));
        keep(h, front)
    });
    let mut hits = 0;
    for (l, ray) in rays.iter().enumerate() {
        let want = accel.intersect(ray);
        assert_eq!(got[l], want, "lane {l} of {rays:?}");
        hits += want.is_some() as usize;
        let mut asked = Asked::new();
        let want = accel.intersect_filtered(ray, |h, front| {
            asked.push((h.prim, h.t.to_bits(), front));
            keep(h, front)
        });
        assert_eq!(got_filtered[l], want, "filtered, lane {l} of {rays:?}");
        assert_eq!(asked4[l], asked, "filter questions, lane {l} of {rays:?}");
    }
    hits
}

/// Returns how many lanes are blocked. The filtered queries are checked in both orders.
fn check_any(accel: &Accel, rays: &[Ray; LANES]) -> usize {
    let got = accel.occluded4(rays);
    let blocks =
        |h: &Hit, front: bool| !h.prim.is_multiple_of(3) && (front || !h.prim.is_multiple_of(5));
    let mut blocked = 0;
    for (l, ray) in rays.iter().enumerate() {
        let want = accel.occluded(ray);
        assert_eq!(got[l], want, "any hit, lane {l} of {rays:?}");
        blocked += want as usize;
    }
    for in_order in [false, true] {
        let mut asked4: [Asked; LANES] = Default::default();
        let ask4 = |l: usize, h: &Hit, front: bool| {
            asked4[l].push((h.prim, h.t.to_bits(), front));
            blocks(h, front)
        };
        let got_filtered = if in_order {
            accel.occluded4_filtered_in_order(rays, ask4)
        } else {
            accel.occluded4_filtered(rays, ask4)
        };
        for (l, ray) in rays.iter().enumerate() {
            let mut asked = Asked::new();
            let ask = |h: &Hit, front: bool| {
                asked.push((h.prim, h.t.to_bits(), front));
                blocks(h, front)
            };
            let want = if in_order {
                accel.occluded_filtered_in_order(ray, ask)
            } else {
                accel.occluded_filtered(ray, ask)
            };
            assert_eq!(
                got_filtered[l], want,
                "filtered any hit (in order: {in_order}), lane {l} of {rays:?}"
            );
            assert_eq!(
                asked4[l], asked,
                "any-hit filter questions (in order: {in_order}), lane {l} of {rays:?}"
            );
        }
    }
    blocked
}

fn scene() -> Vec<[Vec3; 3]> {
    let mut tris = sphere(Vec3::new(0.0, 1.0, 0.0), 1.0, 16, 32);
    tris.extend(grid_box(Vec3::new(2.5, 0.5, -1.0), 0.5, 4));
    tris.extend(
        grid(16, 8.0, 0.0)
            .iter()
            .map(|t| t.map(|v| v - Vec3::new(4.0, 0.0, 4.0))),
    );
    let mut rng = Rng(11);
    for _ in 0..300 {
        let c = Vec3::new(
            rng.range(-4.0, 4.0),
            rng.range(0.0, 3.0),
            rng.range(-4.0, 4.0),
        );
        tris.push([c, c + 0.3 * rng.dir(), c + 0.3 * rng.dir()]);
    }
    tris
}

/// A camera at `eye` looking at the sphere's centre: its forward, right and up axes.
fn looking_at_scene(eye: Vec3) -> [Vec3; 3] {
    let forward = (Vec3::new(0.0, 0.8, 0.0) - eye).normalize();
    let right = forward.cross(Vec3::Y).normalize();
    [forward, right, right.cross(forward)]
}

/// The direction (not unit) through the centre of lane `l`'s pixel of the 2×2 block at
/// (`px`, `py`) of an `n`×`n` image (lanes row by row).
fn pixel_dir([forward, right, up]: [Vec3; 3], n: u32, px: u32, py: u32, l: usize) -> Vec3 {
    let (x, y) = ((px + l as u32 % 2) as f32, (py + l as u32 / 2) as f32);
    let sx = (x + 0.5) / n as f32 * 2.0 - 1.0;
    let sy = 1.0 - (y + 0.5) / n as f32 * 2.0;
    forward + 0.7 * (sx * right + sy * up)
}

/// Camera rays of 2×2 pixel blocks (the packets a renderer forms), from several viewpoints,
/// some with the lanes' intervals cut differently.
#[test]
fn neighbouring_camera_rays_get_their_single_answers() {
    let tris = scene();
    let accel = Accel::build(&tris, &BuildParams::default());
    let mut rng = Rng(3);
    let (mut hits, mut lanes) = (0, 0);
    for view in 0..12 {
        let eye = Vec3::new(
            rng.range(-6.0, 6.0),
            rng.range(0.5, 5.0),
            rng.range(-6.0, 6.0),
        );
        let axes = looking_at_scene(eye);
        let n = 48;
        for py in (0..n).step_by(2) {
            for px in (0..n).step_by(2) {
                let rays: [Ray; LANES] = std::array::from_fn(|l| {
                    let dir = pixel_dir(axes, n, px, py, l);
                    let (tmin, tmax) = match (view + l) % 4 {
                        0 => (0.0, f32::INFINITY),
                        1 => (0.0, rng.range(2.0, 9.0)),
                        2 => (rng.range(0.0, 4.0), f32::INFINITY),
                        _ => (1e-4, 1e30),
                    };
                    Ray::new(eye, dir, tmin, tmax)
                });
                hits += check(&accel, &rays);
                lanes += LANES;
            }
        }
    }
    assert!(
        hits > lanes / 3 && hits < lanes,
        "{hits} of {lanes} lanes hit"
    );
}

/// Rays along the grid's lines and in its plane (split planes, zero direction components,
/// rays in a plane visiting both children), lanes that cannot hit anything (zero or NaN
/// directions, empty intervals, rays that miss the scene's box), and packets whose lanes
/// point different ways (traced one by one).
#[test]
fn hard_lanes_and_mixed_packets_get_their_single_answers() {
    let tris = scene();
    let accel = Accel::build(&tris, &BuildParams::default());
    let mut rng = Rng(5);
    let mut hits = 0;
    for i in 0..3000 {
        let rays: [Ray; LANES] = std::array::from_fn(|l| {
            let o = Vec3::new(
                rng.range(-5.0, 5.0),
                rng.range(-1.0, 4.0),
                rng.range(-5.0, 5.0),
            );
            match (i + l) % 8 {
                // On the grid's lattice, along an axis, in the plane y = 0.
                0 => Ray::new(
                    Vec3::new((o.x * 2.0).round() / 2.0, 0.0, (o.z * 2.0).round() / 2.0),
                    Vec3::X,
                    0.0,
                    f32::INFINITY,
                ),
                1 => Ray::new(o, Vec3::new(0.3, -1.0, 0.0), 0.0, f32::INFINITY),
                2 => Ray::new(o, Vec3::ZERO, 0.0, f32::INFINITY),
                3 => Ray::new(o, Vec3::new(f32::NAN, 1.0, 0.0), 0.0, f32::INFINITY),
                4 => Ray::new(o, Vec3::new(0.2, -1.0, 0.1), 5.0, 1.0),
                5 => Ray::new(o + Vec3::splat(100.0), Vec3::new(0.2, -1.0, 0.1), 0.0, 1e3),
                6 => Ray::new(o, rng.dir(), 0.0, f32::INFINITY),
                _ => Ray::new(o, Vec3::new(0.25, -1.0, 0.15), 0.0, rng.range(0.5, 8.0)),
            }
        });
        hits += check(&accel, &rays);
    }
    assert!(hits > 1000, "{hits} lanes hit");
}

/// Shadow rays as a renderer forms them: from the surface points that a 2×2 block of camera
/// rays hits, just off the surface, toward a point light, stopping short of it.
#[test]
fn shadow_rays_of_neighbouring_pixels_get_their_single_answers() {
    let tris = scene();
    let accel = Accel::build(&tris, &BuildParams::default());
    let mut rng = Rng(7);
    let (mut blocked, mut lanes) = (0, 0);
    for _ in 0..8 {
        let eye = Vec3::new(
            rng.range(-6.0, 6.0),
            rng.range(1.0, 5.0),
            rng.range(-6.0, 6.0),
        );
        let light = Vec3::new(
            rng.range(-3.0, 3.0),
            rng.range(3.0, 6.0),
            rng.range(-3.0, 3.0),
        );
        let axes = looking_at_scene(eye);
        let n = 40;
        for py in (0..n).step_by(2) {
            for px in (0..n).step_by(2) {
                let shadow: [Ray; LANES] = std::array::from_fn(|l| {
                    let dir = pixel_dir(axes, n, px, py, l).normalize();
                    // A miss leaves from far along the ray, toward the light all the same.
                    let t = accel
                        .intersect(&Ray::new(eye, dir, 0.0, f32::INFINITY))
                        .map_or(20.0, |h| h.t);
                    let p = eye + dir * (t * (1.0 - 1e-4));
                    let to = light - p;
                    Ray::new(p, to / to.length(), 1e-4, to.length() * 0.999)
                });
                blocked += check_any(&accel, &shadow);
                lanes += LANES;
            }
        }
    }
    assert!(
        blocked > lanes / 10 && blocked < lanes * 9 / 10,
        "{blocked} of {lanes} shadow rays blocked"
    );
}

/// `n` triangles across the z axis at z = 1, 2, …, two corners raised by `tilt` and twice
/// `tilt`.
fn walls(n: u32, tilt: f32) -> Vec<[Vec3; 3]> {
    (1..=n)
        .map(|z| {
            let z = z as f32;
            [
                Vec3::new(-1.0, -1.0, z),
                Vec3::new(2.0, -1.0, z + 2.0 * tilt),
                Vec3::new(-1.0, 2.0, z + tilt),
            ]
        })
        .collect()
}

/// Four rays from near the origin that pass through every one of [`walls`].
fn through_walls() -> [Ray; LANES] {
    std::array::from_fn(|l| {
        let o = Vec3::new(0.1 * l as f32, 0.05 * l as f32, 0.0);
        Ray::new(o, Vec3::new(0.01, 0.02, 1.0), 0.0, f32::INFINITY)
    })
}

/// Three triangles in one leaf, all passed by the filter: each ray is asked about each
/// triangle once, alone and in a packet, closest hit and any hit. (A short four-wide group
/// repeats its last triangle in its spare lane; that lane's hit must not be asked about
/// again, or a face passed would count twice.)
#[test]
fn a_leaf_asks_about_each_triangle_once() {
    let tris = walls(3, 0.0);
    let params = BuildParams {
        leaf_size: 8,
        ..BuildParams::default()
    };
    let accel = Accel::build(&tris, &params);
    let rays = through_walls();
    let sorted = |mut asked: Vec<u32>| {
        asked.sort_unstable();
        asked
    };
    for ray in &rays {
        let mut asked = vec![];
        assert_eq!(
            accel.intersect_filtered(ray, |h, _| {
                asked.push(h.prim);
                false
            }),
            None
        );
        assert_eq!(sorted(asked), [0, 1, 2], "closest hit, {ray:?}");
        let mut asked = vec![];
        assert!(!accel.occluded_filtered(ray, |h, _| {
            asked.push(h.prim);
            false
        }));
        assert_eq!(sorted(asked), [0, 1, 2], "any hit, {ray:?}");
    }
    let mut asked: [Vec<u32>; LANES] = Default::default();
    let got = accel.intersect4_filtered(&rays, |l, h, _| {
        asked[l].push(h.prim);
        false
    });
    assert_eq!(got, [None; LANES]);
    assert_eq!(asked.map(sorted), [[0, 1, 2]; LANES], "closest hit, packet");
    let mut asked: [Vec<u32>; LANES] = Default::default();
    let got = accel.occluded4_filtered(&rays, |l, h, _| {
        asked[l].push(h.prim);
        false
    });
    assert_eq!(got, [false; LANES]);
    assert_eq!(asked.map(sorted), [[0, 1, 2]; LANES], "any hit, packet");
    let mut asked: [Vec<u32>; LANES] = Default::default();
    let got = accel.occluded4_filtered_in_order(&rays, |l, h, _| {
        asked[l].push(h.prim);
        false
    });
    assert_eq!(got, [false; LANES]);
    assert_eq!(
        asked.map(sorted),
        [[0, 1, 2]; LANES],
        "any hit in order, packet"
    );
}

/// Ten walls one behind the other, each in a leaf of its own, and a filter that passes
/// them all: the in-order query asks about them nearest first, the other query farthest
/// first (its walk takes each far child first), alone and in a packet.
#[test]
fn filtered_any_hit_queries_meet_the_walls_in_their_order() {
    // Tilted, so that a plane between two walls separates them.
    let tris = walls(10, 0.1);
    // Triangle tests priced far above steps: the build splits between every two walls.
    let params = BuildParams {
        traversal_cost: 1.0,
        intersect_cost: 100.0,
        ..BuildParams::default()
    };
    let accel = Accel::build(&tris, &params);
    let rays = through_walls();
    let nearest_first: Vec<u32> = (0..10).collect();
    let farthest_first: Vec<u32> = (0..10).rev().collect();
    for ray in &rays {
        let mut asked = vec![];
        assert!(!accel.occluded_filtered_in_order(ray, |h, _| {
            asked.push(h.prim);
            false
        }));
        assert_eq!(asked, nearest_first, "in order, {ray:?}");
        let mut asked = vec![];
        assert!(!accel.occluded_filtered(ray, |h, _| {
            asked.push(h.prim);
            false
        }));
        assert_eq!(asked, farthest_first, "far child first, {ray:?}");
    }
    let mut asked: [Vec<u32>; LANES] = Default::default();
    accel.occluded4_filtered_in_order(&rays, |l, h, _| {
        asked[l].push(h.prim);
        false
    });
    assert!(asked.iter().all(|a| *a == nearest_first), "{asked:?}");
    let mut asked: [Vec<u32>; LANES] = Default::default();
    accel.occluded4_filtered(&rays, |l, h, _| {
        asked[l].push(h.prim);
        false
    });
    assert!(asked.iter().all(|a| *a == farthest_first), "{asked:?}");
}
