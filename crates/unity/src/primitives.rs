//! Unity's built-in meshes (`guid: 0000000000000000e000000000000000`), generated at
//! Unity's dimensions. They are symmetric in X, so they are written here as right-handed
//! counter-clockwise data and imported like an OBJ ([`Mesh::import_rh`]).

use crate::mesh::Mesh;
use glam::{Vec2, Vec3};
use std::f32::consts::{PI, TAU};

pub const BUILTIN_MESH_GUID: &str = "0000000000000000e000000000000000";

/// Name of a built-in mesh by fileID.
pub fn name(file_id: i64) -> Option<&'static str> {
    Some(match file_id {
        10202 => "Cube",
        10206 => "Cylinder",
        10207 => "Sphere",
        10208 => "Capsule",
        10209 => "Plane",
        10210 => "Quad",
        _ => return None,
    })
}

/// The built-in mesh with this fileID, in Unity space.
pub fn mesh(file_id: i64) -> Option<Mesh> {
    let m = match file_id {
        10202 => cube(),
        10206 => cylinder(20),
        10207 => sphere(24, 16),
        10208 => capsule(24, 8),
        10209 => plane(),
        10210 => quad(),
        _ => return None,
    };
    let mut m = m.import_rh();
    match file_id {
        10202 => m.uvs = m.positions.iter().zip(&m.normals).map(cube_uv).collect(),
        10209 => m.uvs = m.positions.iter().map(plane_uv).collect(),
        _ => {}
    }
    Some(m)
}

/// Unity's Cube layout, in Unity space: every face spans the whole texture, upright seen
/// from outside on the four sides facing ±X and +Z, turned half a turn on the −Z face
/// (the one a default camera sees); the top runs u along −X, v along −Z, the bottom u
/// along −X, v along +Z.
fn cube_uv((p, n): (&Vec3, &Vec3)) -> Vec2 {
    let (x, y, z) = (p.x + 0.5, p.y + 0.5, p.z + 0.5);
    if n.x > 0.5 {
        Vec2::new(z, y)
    } else if n.x < -0.5 {
        Vec2::new(1.0 - z, y)
    } else if n.y > 0.5 {
        Vec2::new(1.0 - x, 1.0 - z)
    } else if n.y < -0.5 {
        Vec2::new(1.0 - x, z)
    } else if n.z > 0.5 {
        Vec2::new(1.0 - x, y)
    } else {
        Vec2::new(1.0 - x, 1.0 - y)
    }
}

/// Unity's Plane layout, in Unity space: (0, 0) at the (+5, 0, +5) corner, u along −X and
/// v along −Z, so seen from above with +Z up the texture is turned half a turn.
fn plane_uv(p: &Vec3) -> Vec2 {
    Vec2::new(0.5 - p.x / 10.0, 0.5 - p.z / 10.0)
}

#[derive(Default)]
struct Builder {
    p: Vec<Vec3>,
    n: Vec<Vec3>,
    t: Vec<[u32; 3]>,
    /// UV0 per vertex, for the primitives whose layout is known (else empty).
    uv: Vec<Vec2>,
}

impl Builder {
    fn v(&mut self, p: Vec3, n: Vec3) -> u32 {
        self.p.push(p);
        self.n.push(n);
        (self.p.len() - 1) as u32
    }
    /// Quad a-b-c-d counter-clockwise seen from the front.
    fn quad(&mut self, a: u32, b: u32, c: u32, d: u32) {
        self.t.push([a, b, c]);
        self.t.push([a, c, d]);
    }
    fn done(self) -> Mesh {
        Mesh {
            positions: self.p,
            normals: self.n,
            submeshes: vec![self.t],
            uvs: self.uv,
        }
    }
}

/// 1×1×1, 24 vertices, 12 triangles.
fn cube() -> Mesh {
    let mut b = Builder::default();
    for axis in 0..3 {
        for sign in [-1.0f32, 1.0] {
            let n = Vec3::from_array(std::array::from_fn(|i| if i == axis { sign } else { 0.0 }));
            // Two tangents with t1 × t2 = n.
            let t1 = Vec3::from_array(std::array::from_fn(|i| {
                if i == (axis + 1) % 3 {
                    1.0
                } else {
                    0.0
                }
            }));
            let t2 = n.cross(t1);
            let c = n * 0.5;
            let vs: Vec<u32> = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
                .iter()
                .map(|&(s, t)| b.v(c + t1 * (0.5 * s) + t2 * (0.5 * t), n))
                .collect();
            b.quad(vs[0], vs[1], vs[2], vs[3]);
        }
    }
    b.done()
}

/// 10×10 in XZ at y = 0, facing +Y: 11×11 vertices, 200 triangles.
fn plane() -> Mesh {
    let mut b = Builder::default();
    let idx = |i: u32, j: u32| i * 11 + j;
    for i in 0..11 {
        for j in 0..11 {
            b.v(Vec3::new(-5.0 + j as f32, 0.0, -5.0 + i as f32), Vec3::Y);
        }
    }
    for i in 0..10 {
        for j in 0..10 {
            // Counter-clockwise seen from +Y: (x, z) → (x, z+1) → (x+1, z+1) → (x+1, z).
            b.quad(idx(i, j), idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1));
        }
    }
    b.done()
}

/// 1×1 in XY at z = 0, facing −Z.
fn quad() -> Mesh {
    let mut b = Builder::default();
    let n = Vec3::NEG_Z;
    let a = b.v(Vec3::new(-0.5, -0.5, 0.0), n);
    let c = b.v(Vec3::new(-0.5, 0.5, 0.0), n);
    let d = b.v(Vec3::new(0.5, 0.5, 0.0), n);
    let e = b.v(Vec3::new(0.5, -0.5, 0.0), n);
    // Counter-clockwise seen from −Z.
    b.quad(a, c, d, e);
    // Unity's Quad maps the texture upright seen from its front (from −Z, +X to the
    // right): (0, 0) at Unity's (−0.5, −0.5), which is this right-handed (+0.5, −0.5).
    // Cube and Plane get theirs in Unity space (see `mesh`).
    b.uv =
        b.p.iter()
            .map(|p| Vec2::new(0.5 - p.x, p.y + 0.5))
            .collect();
    b.done()
}

/// A UV sphere around the origin; `rings` latitude bands.
fn sphere_points(b: &mut Builder, seg: u32, rings: u32, r: f32, y_of: impl Fn(f32) -> f32) {
    // Rows of vertices from the north pole (ring 0) to the south pole (ring `rings`);
    // the poles are single-triangle fans.
    let mut rows: Vec<Vec<u32>> = Vec::new();
    for ri in 0..=rings {
        let theta = PI * ri as f32 / rings as f32;
        let (st, ct) = theta.sin_cos();
        // Exactly on the equator when there is an equator row (the capsule splits there).
        let ct = if 2 * ri == rings { 0.0 } else { ct };
        let row = (0..=seg)
            .map(|si| {
                let phi = TAU * si as f32 / seg as f32;
                let n = Vec3::new(st * phi.cos(), ct, -st * phi.sin());
                let p = Vec3::new(n.x * r, y_of(n.y * r), n.z * r);
                // Unity's Sphere layout: v the latitude, 0 at the south pole; u the
                // longitude, 0 (and 1) on Unity's −X side (this builder's +X), rising
                // counter-clockwise seen from above. The seam columns exist twice already.
                b.uv.push(Vec2::new(
                    si as f32 / seg as f32,
                    1.0 - ri as f32 / rings as f32,
                ));
                b.v(p, n)
            })
            .collect();
        rows.push(row);
    }
    for ri in 0..rings as usize {
        for si in 0..seg as usize {
            let (a, bb) = (rows[ri][si], rows[ri][si + 1]);
            let (c, d) = (rows[ri + 1][si + 1], rows[ri + 1][si]);
            // Outward-facing: north row a→b runs counter-clockwise seen from above.
            if ri == 0 {
                b.t.push([a, d, c]);
            } else if ri == rings as usize - 1 {
                b.t.push([a, d, bb]);
            } else {
                b.quad(a, d, c, bb);
            }
        }
    }
}

/// Diameter 1.
fn sphere(seg: u32, rings: u32) -> Mesh {
    let mut b = Builder::default();
    sphere_points(&mut b, seg, rings, 0.5, |y| y);
    b.done()
}

/// Diameter 1, height 2: hemispheres of radius 0.5 centred at y = ±0.5.
fn capsule(seg: u32, half_rings: u32) -> Mesh {
    let mut b = Builder::default();
    // An even number of rings puts a row on the equator; shifting the two halves apart
    // there stretches that band into the cylindrical side.
    sphere_points(&mut b, seg, half_rings * 2, 0.5, |y| {
        if y > 0.0 {
            y + 0.5
        } else if y < 0.0 {
            y - 0.5
        } else {
            0.0
        }
    });
    // The equator row sits at y = 0 from the closure above; rebuild it as two rows so
    // the side spans y ∈ [−0.5, 0.5].
    let m = b.done();
    fix_capsule_equator(m, seg)
}

/// The equator ring of the capsule generator is at y = 0: split the bands touching it so
/// that the upper band ends at y = +0.5 and the lower starts at y = −0.5, joined by a side
/// band. UVs keep the sphere's longitude as u and take v from the height, 0 at the bottom
/// pole and 1 at the top (Unity's own Capsule layout could not be confirmed; this is the
/// Sphere's convention stretched over the capsule).
fn fix_capsule_equator(m: Mesh, seg: u32) -> Mesh {
    let mut b = Builder::default();
    let mut remap_up = vec![u32::MAX; m.positions.len()];
    let mut remap_down = vec![u32::MAX; m.positions.len()];
    let vertex = |b: &mut Builder, p: Vec3, n: Vec3, u: f32| {
        b.uv.push(Vec2::new(u, (p.y + 1.0) * 0.5));
        b.v(p, n)
    };
    for (i, (&p, &n)) in m.positions.iter().zip(&m.normals).enumerate() {
        let u = m.uvs[i].x;
        if p.y == 0.0 {
            remap_up[i] = vertex(&mut b, Vec3::new(p.x, 0.5, p.z), n, u);
            remap_down[i] = vertex(&mut b, Vec3::new(p.x, -0.5, p.z), n, u);
        } else {
            remap_up[i] = vertex(&mut b, p, n, u);
            remap_down[i] = remap_up[i];
        }
    }
    for t in &m.submeshes[0] {
        let above = t.iter().any(|&i| m.positions[i as usize].y > 0.0);
        let r = if above { &remap_up } else { &remap_down };
        b.t.push(t.map(|i| r[i as usize]));
    }
    // Side band between the two equator copies.
    let eq: Vec<usize> = (0..m.positions.len())
        .filter(|&i| m.positions[i].y == 0.0)
        .collect();
    debug_assert_eq!(eq.len(), seg as usize + 1);
    for w in eq.windows(2) {
        let (a, c) = (w[0], w[1]);
        b.quad(remap_up[a], remap_down[a], remap_down[c], remap_up[c]);
    }
    b.done()
}

/// Diameter 1, height 2 (y ∈ [−1, 1]), `seg` sides, capped. Unity's own Cylinder layout
/// could not be confirmed, so the UVs follow the Sphere's convention: the side spans the
/// texture once around (u as the Sphere's longitude) and once from bottom (v = 0) to top;
/// each cap shows the disc inscribed in the texture, upright seen from outside with
/// Unity's +Z up (from above) or down (from below), Unity's +X to the right.
fn cylinder(seg: u32) -> Mesh {
    let mut b = Builder::default();
    let ring = |b: &mut Builder, y: f32, side: bool| -> Vec<u32> {
        (0..=seg)
            .map(|si| {
                let phi = TAU * si as f32 / seg as f32;
                let d = Vec3::new(phi.cos(), 0.0, -phi.sin());
                let (n, uv) = if side {
                    (d, Vec2::new(si as f32 / seg as f32, (y + 1.0) * 0.5))
                } else {
                    (Vec3::new(0.0, y.signum(), 0.0), cap_uv(d * 0.5, y))
                };
                b.uv.push(uv);
                b.v(d * 0.5 + Vec3::Y * y, n)
            })
            .collect()
    };
    let top = ring(&mut b, 1.0, true);
    let bot = ring(&mut b, -1.0, true);
    for i in 0..seg as usize {
        b.quad(top[i], bot[i], bot[i + 1], top[i + 1]);
    }
    for (y, up) in [(1.0f32, true), (-1.0, false)] {
        let r = ring(&mut b, y, false);
        b.uv.push(cap_uv(Vec3::ZERO, y));
        let c = b.v(Vec3::Y * y, Vec3::Y * y.signum());
        for i in 0..seg as usize {
            // φ increases counter-clockwise seen from +Y (x = cos φ, z = −sin φ).
            if up {
                b.t.push([c, r[i], r[i + 1]]);
            } else {
                b.t.push([c, r[i + 1], r[i]]);
            }
        }
    }
    b.done()
}

/// A cylinder cap's UV at offset `d` from its centre (this builder's right-handed space,
/// whose +X is Unity's −X) on the cap at height `y`: see [`cylinder`].
fn cap_uv(d: Vec3, y: f32) -> Vec2 {
    let v = if y > 0.0 { d.z } else { -d.z };
    Vec2::new(0.5 - d.x, 0.5 + v)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bounds(m: &Mesh) -> (Vec3, Vec3) {
        m.positions.iter().fold(
            (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)),
            |(lo, hi), &p| (lo.min(p), hi.max(p)),
        )
    }

    /// Unity's front faces wind clockwise as seen on a left-handed screen, which is the
    /// same as (b−a)×(c−a) (the component formula) pointing out of the front; check each
    /// triangle's geometric normal against its stored vertex normals.
    fn assert_outward(m: &Mesh, name: &str) {
        for t in &m.submeshes[0] {
            let [a, b, c] = t.map(|i| m.positions[i as usize]);
            let g = (b - a).cross(c - a);
            if g.length() < 1e-9 {
                continue;
            }
            let n: Vec3 = t.iter().map(|&i| m.normals[i as usize]).sum();
            assert!(g.dot(n) > 0.0, "{name}: triangle {t:?} faces the wrong way");
        }
    }

    #[test]
    fn dimensions_counts_and_facing() {
        let close = |a: Vec3, b: Vec3| (a - b).length() < 1e-5;
        let cube = mesh(10202).unwrap();
        assert_eq!(cube.triangle_count(), 12);
        assert!(
            close(bounds(&cube).0, Vec3::splat(-0.5)) && close(bounds(&cube).1, Vec3::splat(0.5))
        );
        let plane = mesh(10209).unwrap();
        assert_eq!(plane.triangle_count(), 200);
        let (lo, hi) = bounds(&plane);
        assert!(close(lo, Vec3::new(-5.0, 0.0, -5.0)) && close(hi, Vec3::new(5.0, 0.0, 5.0)));
        assert!(plane.normals.iter().all(|&n| n == Vec3::Y));
        let quad = mesh(10210).unwrap();
        assert_eq!(quad.triangle_count(), 2);
        let (lo, hi) = bounds(&quad);
        assert!(close(lo, Vec3::new(-0.5, -0.5, 0.0)) && close(hi, Vec3::new(0.5, 0.5, 0.0)));
        assert!(quad.normals.iter().all(|&n| n == Vec3::NEG_Z));
        let sphere = mesh(10207).unwrap();
        let (lo, hi) = bounds(&sphere);
        assert!(
            close(lo, Vec3::splat(-0.5)) && close(hi, Vec3::splat(0.5)),
            "{lo} {hi}"
        );
        assert!(sphere
            .positions
            .iter()
            .all(|p| (p.length() - 0.5).abs() < 1e-5));
        let cyl = mesh(10206).unwrap();
        let (lo, hi) = bounds(&cyl);
        assert!(close(lo, Vec3::new(-0.5, -1.0, -0.5)) && close(hi, Vec3::new(0.5, 1.0, 0.5)));
        let cap = mesh(10208).unwrap();
        let (lo, hi) = bounds(&cap);
        assert!(
            close(lo, Vec3::new(-0.5, -1.0, -0.5)) && close(hi, Vec3::new(0.5, 1.0, 0.5)),
            "{lo} {hi}"
        );
        for (id, m) in [
            (10202, &cube),
            (10209, &plane),
            (10210, &quad),
            (10207, &sphere),
            (10206, &cyl),
            (10208, &cap),
        ] {
            assert_outward(m, name(id).unwrap());
        }
        assert_eq!(name(10202), Some("Cube"));
        assert!(mesh(10303).is_none());
    }

    #[test]
    fn quad_uvs_are_upright_from_the_front() {
        let q = mesh(10210).unwrap();
        assert_eq!(q.uvs.len(), q.positions.len());
        // Unity space: the front is seen from −Z, where +X is to the right.
        for (p, uv) in q.positions.iter().zip(&q.uvs) {
            assert_eq!(*uv, Vec2::new(p.x + 0.5, p.y + 0.5), "{p}");
        }
        assert!(q.uvs.contains(&Vec2::ZERO) && q.uvs.contains(&Vec2::ONE));
    }

    #[test]
    fn sphere_uvs_are_latitude_and_longitude_from_unitys_minus_x() {
        let m = mesh(10207).unwrap();
        assert_eq!(m.uvs.len(), m.positions.len());
        let at = |p: Vec3| -> Vec<Vec2> {
            let found: Vec<Vec2> = (0..m.positions.len())
                .filter(|&i| (m.positions[i] - p).length() < 1e-6)
                .map(|i| m.uvs[i])
                .collect();
            assert!(!found.is_empty(), "no vertex at {p}");
            found
        };
        // Unity space, on the equator: −X is the seam (u 0 on one side, 1 on the other),
        // then −Z, +X and +Z a quarter turn apart, counter-clockwise seen from above.
        let mut seam = at(Vec3::new(-0.5, 0.0, 0.0));
        seam.sort_by(|a, b| a.x.total_cmp(&b.x));
        assert_eq!(seam, [Vec2::new(0.0, 0.5), Vec2::new(1.0, 0.5)]);
        assert_eq!(at(Vec3::new(0.0, 0.0, -0.5)), [Vec2::new(0.25, 0.5)]);
        assert_eq!(at(Vec3::new(0.5, 0.0, 0.0)), [Vec2::new(0.5, 0.5)]);
        assert_eq!(at(Vec3::new(0.0, 0.0, 0.5)), [Vec2::new(0.75, 0.5)]);
        // The poles: v = 1 at the top, 0 at the bottom, whatever the longitude.
        assert!(at(Vec3::new(0.0, 0.5, 0.0)).iter().all(|uv| uv.y == 1.0));
        assert!(at(Vec3::new(0.0, -0.5, 0.0)).iter().all(|uv| uv.y == 0.0));
    }

    /// The UV of the Unity-space corner `p` of the face with normal `n`.
    fn uv_at(m: &Mesh, p: Vec3, n: Vec3) -> Vec2 {
        let i = (0..m.positions.len())
            .find(|&i| m.positions[i] == p && m.normals[i] == n)
            .unwrap_or_else(|| panic!("no corner {p} on face {n}"));
        m.uvs[i]
    }

    #[test]
    fn cube_uvs_as_unity_lays_them_out() {
        let c = mesh(10202).unwrap();
        assert_eq!(c.uvs.len(), 24);
        let h = 0.5;
        // (face normal, corner, uv) in Unity space.
        let cases = [
            (Vec3::Z, Vec3::new(h, -h, h), Vec2::new(0.0, 0.0)),
            (Vec3::Z, Vec3::new(-h, -h, h), Vec2::new(1.0, 0.0)),
            (Vec3::Z, Vec3::new(h, h, h), Vec2::new(0.0, 1.0)),
            (Vec3::Y, Vec3::new(h, h, h), Vec2::new(0.0, 0.0)),
            (Vec3::Y, Vec3::new(-h, h, h), Vec2::new(1.0, 0.0)),
            (Vec3::Y, Vec3::new(h, h, -h), Vec2::new(0.0, 1.0)),
            (Vec3::NEG_Z, Vec3::new(h, h, -h), Vec2::new(0.0, 0.0)),
            (Vec3::NEG_Z, Vec3::new(-h, h, -h), Vec2::new(1.0, 0.0)),
            (Vec3::NEG_Z, Vec3::new(h, -h, -h), Vec2::new(0.0, 1.0)),
            (Vec3::NEG_Y, Vec3::new(h, -h, -h), Vec2::new(0.0, 0.0)),
            (Vec3::NEG_Y, Vec3::new(h, -h, h), Vec2::new(0.0, 1.0)),
            (Vec3::NEG_Y, Vec3::new(-h, -h, h), Vec2::new(1.0, 1.0)),
            (Vec3::NEG_X, Vec3::new(-h, -h, h), Vec2::new(0.0, 0.0)),
            (Vec3::NEG_X, Vec3::new(-h, h, h), Vec2::new(0.0, 1.0)),
            (Vec3::NEG_X, Vec3::new(-h, h, -h), Vec2::new(1.0, 1.0)),
            (Vec3::X, Vec3::new(h, -h, -h), Vec2::new(0.0, 0.0)),
            (Vec3::X, Vec3::new(h, h, -h), Vec2::new(0.0, 1.0)),
            (Vec3::X, Vec3::new(h, h, h), Vec2::new(1.0, 1.0)),
        ];
        for (n, p, uv) in cases {
            assert_eq!(uv_at(&c, p, n), uv, "face {n} corner {p}");
        }
    }

    #[test]
    fn plane_uvs_as_unity_lays_them_out() {
        let p = mesh(10209).unwrap();
        assert_eq!(p.uvs.len(), 121);
        assert_eq!(uv_at(&p, Vec3::new(5.0, 0.0, 5.0), Vec3::Y), Vec2::ZERO);
        assert_eq!(uv_at(&p, Vec3::new(-5.0, 0.0, -5.0), Vec3::Y), Vec2::ONE);
        assert_eq!(
            uv_at(&p, Vec3::new(-5.0, 0.0, 5.0), Vec3::Y),
            Vec2::new(1.0, 0.0)
        );
        assert_eq!(
            uv_at(&p, Vec3::new(0.0, 0.0, 0.0), Vec3::Y),
            Vec2::splat(0.5)
        );
    }

    /// The UVs of the vertices within 1e-6 of the Unity-space point `p` whose normal leans
    /// towards `n`, sorted by u (a point on a seam has two).
    fn uvs_near(m: &Mesh, p: Vec3, n: Vec3) -> Vec<Vec2> {
        let mut found: Vec<Vec2> = (0..m.positions.len())
            .filter(|&i| (m.positions[i] - p).length() < 1e-6 && m.normals[i].dot(n) > 0.7)
            .map(|i| m.uvs[i])
            .collect();
        assert!(!found.is_empty(), "no vertex at {p} facing {n}");
        found.sort_by(|a, b| a.x.total_cmp(&b.x));
        found
    }

    /// Each case's point and facing has exactly the listed UVs (within 1e-6), in u order.
    fn assert_uvs(m: &Mesh, cases: &[(Vec3, Vec3, Vec<Vec2>)]) {
        for (p, n, want) in cases {
            let got = uvs_near(m, *p, *n);
            let close = got.len() == want.len()
                && got.iter().zip(want).all(|(g, w)| (*g - *w).length() < 1e-6);
            assert!(close, "at {p} facing {n}: {got:?}, want {want:?}");
        }
    }

    #[test]
    fn cylinder_uvs_wrap_the_side_and_inscribe_the_caps() {
        let m = mesh(10206).unwrap();
        assert_eq!(m.uvs.len(), m.positions.len());
        let v2 = Vec2::new;
        let cases = [
            // Side: u as the Sphere's longitude (seam on −X), v from 0 at the bottom.
            (
                Vec3::new(-0.5, 1.0, 0.0),
                Vec3::NEG_X,
                vec![v2(0.0, 1.0), v2(1.0, 1.0)],
            ),
            (Vec3::new(0.0, -1.0, -0.5), Vec3::NEG_Z, vec![v2(0.25, 0.0)]),
            (Vec3::new(0.5, 1.0, 0.0), Vec3::X, vec![v2(0.5, 1.0)]),
            (Vec3::new(0.0, -1.0, 0.5), Vec3::Z, vec![v2(0.75, 0.0)]),
            // Top, from above: +X right, +Z up; bottom, from below: +X right, +Z down.
            (Vec3::new(0.0, 1.0, 0.0), Vec3::Y, vec![v2(0.5, 0.5)]),
            (Vec3::new(0.5, 1.0, 0.0), Vec3::Y, vec![v2(1.0, 0.5)]),
            (Vec3::new(0.0, 1.0, 0.5), Vec3::Y, vec![v2(0.5, 1.0)]),
            (Vec3::new(0.5, -1.0, 0.0), Vec3::NEG_Y, vec![v2(1.0, 0.5)]),
            (Vec3::new(0.0, -1.0, 0.5), Vec3::NEG_Y, vec![v2(0.5, 0.0)]),
        ];
        assert_uvs(&m, &cases);
    }

    #[test]
    fn capsule_uvs_run_from_pole_to_pole_by_height() {
        let m = mesh(10208).unwrap();
        assert_eq!(m.uvs.len(), m.positions.len());
        let v2 = Vec2::new;
        let cases = [
            (
                Vec3::new(-0.5, 0.5, 0.0),
                Vec3::NEG_X,
                vec![v2(0.0, 0.75), v2(1.0, 0.75)],
            ),
            (Vec3::new(0.0, 0.5, -0.5), Vec3::NEG_Z, vec![v2(0.25, 0.75)]),
            (Vec3::new(0.5, -0.5, 0.0), Vec3::X, vec![v2(0.5, 0.25)]),
            (Vec3::new(0.0, -0.5, 0.5), Vec3::Z, vec![v2(0.75, 0.25)]),
        ];
        assert_uvs(&m, &cases);
        // The poles: v = 1 at the top, 0 at the bottom, whatever the longitude.
        assert!(uvs_near(&m, Vec3::Y, Vec3::Y).iter().all(|uv| uv.y == 1.0));
        assert!(uvs_near(&m, Vec3::NEG_Y, Vec3::NEG_Y)
            .iter()
            .all(|uv| uv.y == 0.0));
    }
}
