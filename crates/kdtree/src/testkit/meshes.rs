//! Test meshes: closed ones (a UV sphere, a box of grid faces) whose neighbouring
//! triangles share bit-identical vertices, a flat grid, and the rays that start inside a
//! closed mesh and so must hit it.

use super::Rng;
use crate::{Accel, Ray};
use formats::BuildParams;
use glam::Vec3;

/// Indexed mesh → triangle soup (vertices shared bit for bit).
fn soup(verts: &[Vec3], faces: &[[usize; 3]]) -> Vec<[Vec3; 3]> {
    faces
        .iter()
        .map(|f| [verts[f[0]], verts[f[1]], verts[f[2]]])
        .collect()
}

/// Closed UV sphere: `rings` latitude bands, `segs` longitudes, single pole vertices.
pub fn sphere(center: Vec3, radius: f32, rings: usize, segs: usize) -> Vec<[Vec3; 3]> {
    let mut v = vec![center + Vec3::new(0.0, radius, 0.0)];
    for r in 1..rings {
        let th = std::f32::consts::PI * r as f32 / rings as f32;
        for s in 0..segs {
            let ph = std::f32::consts::TAU * s as f32 / segs as f32;
            v.push(center + radius * Vec3::new(th.sin() * ph.cos(), th.cos(), th.sin() * ph.sin()));
        }
    }
    let south = v.len();
    v.push(center - Vec3::new(0.0, radius, 0.0));
    let idx = |r: usize, s: usize| 1 + (r - 1) * segs + s % segs;
    let mut f = Vec::new();
    for s in 0..segs {
        f.push([0, idx(1, s + 1), idx(1, s)]);
        f.push([south, idx(rings - 1, s), idx(rings - 1, s + 1)]);
    }
    for r in 1..rings - 1 {
        for s in 0..segs {
            let (a, b, c, d) = (idx(r, s), idx(r, s + 1), idx(r + 1, s), idx(r + 1, s + 1));
            f.push([a, b, d]);
            f.push([a, d, c]);
        }
    }
    soup(&v, &f)
}

/// Closed axis-aligned box, each face an n×n grid of quads (two triangles each).
pub fn grid_box(center: Vec3, half: f32, n: usize) -> Vec<[Vec3; 3]> {
    // Vertices on the box surface, indexed by integer lattice coordinates so that the
    // faces' shared edges use the very same f32 values.
    let coord = |i: usize| -half + 2.0 * half * i as f32 / n as f32;
    let p = |i: usize, j: usize, k: usize| center + Vec3::new(coord(i), coord(j), coord(k));
    let mut tris = Vec::new();
    for axis in 0..3 {
        for &side in &[0usize, n] {
            for a in 0..n {
                for b in 0..n {
                    let at = |u: usize, w: usize| {
                        let mut c = [0usize; 3];
                        c[axis] = side;
                        c[(axis + 1) % 3] = u;
                        c[(axis + 2) % 3] = w;
                        p(c[0], c[1], c[2])
                    };
                    let (q0, q1, q2, q3) = (at(a, b), at(a + 1, b), at(a + 1, b + 1), at(a, b + 1));
                    tris.push([q0, q1, q2]);
                    tris.push([q0, q2, q3]);
                }
            }
        }
    }
    tris
}

/// Flat n×n grid of quads in the plane y = `y`, spanning [0, size]² in x and z.
pub fn grid(n: usize, size: f32, y: f32) -> Vec<[Vec3; 3]> {
    let c = |i: usize| size * i as f32 / n as f32;
    let mut tris = Vec::new();
    for i in 0..n {
        for k in 0..n {
            let p = |a: usize, b: usize| Vec3::new(c(a), y, c(b));
            tris.push([p(i, k), p(i + 1, k), p(i + 1, k + 1)]);
            tris.push([p(i, k), p(i + 1, k + 1), p(i, k + 1)]);
        }
    }
    tris
}

/// Rays from random points strictly inside a closed mesh around `center` (within 0.45 of
/// its half-size `half`, so no origin rounds onto a face), in random directions, over
/// [0, ∞). A watertight tracer finds a hit for every one of them.
pub fn rays_inside(rng: &mut Rng, center: Vec3, half: f32) -> impl Iterator<Item = Ray> + '_ {
    std::iter::repeat_with(move || {
        let o = center + rng.dir() * (0.45 * half * rng.unit());
        Ray::new(o, rng.dir(), 0.0, f32::INFINITY)
    })
}

/// How many of `n` rays from inside a closed mesh ([`rays_inside`], generator seeded with
/// `seed`) escape it, finding no hit. Every hit must be finite and agree with the any-hit
/// query.
pub fn escapes(tris: &[[Vec3; 3]], center: Vec3, half: f32, n: usize, seed: u64) -> usize {
    let accel = Accel::build(tris, &BuildParams::default());
    let mut rng = Rng(seed);
    let mut leaks = 0;
    for r in rays_inside(&mut rng, center, half).take(n) {
        match accel.intersect(&r) {
            Some(h) => {
                assert!(
                    h.t.is_finite() && h.u.is_finite() && h.v.is_finite(),
                    "{h:?}"
                );
                assert!(
                    accel.occluded(&r),
                    "closest hit and any-hit disagree on {r:?}"
                );
            }
            None => leaks += 1,
        }
    }
    leaks
}
