//! The tangents normal maps are read in: MikkTSpace, the algorithm Unity's model importer
//! runs on every mesh by default, so a map bends the normal in the frame it was baked for.
//!
//! MikkTSpace gives each corner of a triangle a unit tangent (where u grows) and a sign
//! (which way v grows from `n × t`), shared by the corners that meet at a vertex of the
//! same position, normal, UV and orientation. Interpolated across a triangle, the frame
//! turns smoothly over a curved mesh; a triangle's own `∂p/∂u` turns from one triangle to
//! the next and makes a bumpy surface look faceted.
//!
//! Unity runs it on each mesh in the mesh's own space; here it runs on all the triangles
//! of each object with a normal-mapped material, in the soup's world space. A linear map
//! carries `∂p/∂u` along with the positions, so under rotation, uniform scale and the
//! converter's mirroring the tangents are Unity's carried into the soup; under non-uniform
//! scale only MikkTSpace's weighting of the faces around a vertex differs. Only objects
//! with a material that reads a normal map are processed and stored (48 bytes per triangle
//! and 4 for its listing, and 4 per triangle of the scene for the lookup), each only when
//! a ray first reads its map.

use crate::normal_map::Tangent;
use bevy_mikktspace::{Geometry, TangentSpace};
use formats::soup::Soup;
use glam::{Vec3, Vec4};
use std::sync::OnceLock;

/// Per-corner tangents of the objects that read a normal map, each object's computed
/// when a ray first needs one of them, so objects no ray shows cost only their listing.
pub struct Tangents<'a> {
    soup: &'a Soup,
    /// Per soup triangle, its index in its object's list, or [`NONE`].
    slot: Vec<u32>,
    /// Per object that reads a normal map, its triangles in soup order.
    tris: Vec<Vec<u32>>,
    /// Per object, each corner's unit tangent and sign (x, y, z, ±1), zero where
    /// MikkTSpace gave none (a degenerate triangle with no neighbour to lend it one).
    corners: Vec<OnceLock<Vec<[Vec4; 3]>>>,
}

const NONE: u32 = u32::MAX;

/// One object's triangles, as MikkTSpace reads them and writes back.
struct Mesh<'a> {
    soup: &'a Soup,
    tris: &'a [u32],
    out: Vec<[Vec4; 3]>,
}

impl Mesh<'_> {
    fn vertex(&self, face: usize, vert: usize) -> usize {
        self.soup.triangles[self.tris[face] as usize][vert] as usize
    }
}

impl Geometry for Mesh<'_> {
    fn num_faces(&self) -> usize {
        self.tris.len()
    }

    fn num_vertices_of_face(&self, _face: usize) -> usize {
        3
    }

    fn position(&self, face: usize, vert: usize) -> [f32; 3] {
        self.soup.positions[self.vertex(face, vert)].to_array()
    }

    fn normal(&self, face: usize, vert: usize) -> [f32; 3] {
        self.soup.normals[self.vertex(face, vert)].to_array()
    }

    fn tex_coord(&self, face: usize, vert: usize) -> [f32; 2] {
        // A soup has UVs whenever a material has a map.
        self.soup
            .uvs
            .get(self.vertex(face, vert))
            .map_or([0.0; 2], |uv| uv.to_array())
    }

    fn set_tangent(&mut self, ts: Option<TangentSpace>, face: usize, vert: usize) {
        self.out[face][vert] = ts.map_or(Vec4::ZERO, |ts| Vec4::from(ts.tangent_encoded()));
    }
}

impl<'a> Tangents<'a> {
    /// Lists the triangles of every object with a triangle whose material `mapped` says
    /// reads a normal map: all of the object's triangles, since Unity runs MikkTSpace on the
    /// whole mesh, and a vertex shared with a triangle of another material weighs that one
    /// in too.
    pub fn new(soup: &'a Soup, mapped: &[bool]) -> Tangents<'a> {
        let mut wanted = vec![false; soup.objects.len()];
        for (&m, &o) in soup.tri_material.iter().zip(&soup.tri_object) {
            if mapped.get(m as usize).copied().unwrap_or(false) {
                wanted[o as usize] = true;
            }
        }
        let mut tris = vec![Vec::new(); soup.objects.len()];
        let mut slot = vec![NONE; soup.triangles.len()];
        for (t, &o) in soup.tri_object.iter().enumerate() {
            if wanted[o as usize] {
                let list: &mut Vec<u32> = &mut tris[o as usize];
                slot[t] = list.len() as u32;
                list.push(t as u32);
            }
        }
        let corners = tris.iter().map(|_| OnceLock::new()).collect();
        Tangents {
            soup,
            slot,
            tris,
            corners,
        }
    }

    /// The frame of triangle `prim` at barycentrics (u, v) (corner 0 weighs 1 − u − v):
    /// the corners' tangents interpolated, as Unity's shaders interpolate them. None where
    /// the triangle's object reads no normal map or MikkTSpace gave a corner no finite
    /// tangent. The first call for an object runs MikkTSpace on its triangles; a thread
    /// that asks meanwhile waits for it.
    pub fn at(&self, prim: usize, u: f32, v: f32) -> Option<Tangent> {
        let i = *self.slot.get(prim)?;
        if i == NONE {
            return None;
        }
        let o = self.soup.tri_object[prim] as usize;
        let c = self.corners[o].get_or_init(|| self.compute(o))[i as usize];
        // No tangent, or one MikkTSpace's arithmetic overflowed (coordinates near 1e30).
        if c.iter().any(|c| c.w == 0.0 || !c.is_finite()) {
            return None;
        }
        let t = c[0].truncate() * (1.0 - u - v) + c[1].truncate() * u + c[2].truncate() * v;
        (t != Vec3::ZERO).then_some(Tangent { t, sign: c[0].w })
    }

    /// MikkTSpace on object `o`'s triangles.
    fn compute(&self, o: usize) -> Vec<[Vec4; 3]> {
        let tris = &self.tris[o];
        let mut mesh = Mesh {
            soup: self.soup,
            tris,
            out: vec![[Vec4::ZERO; 3]; tris.len()],
        };
        // Its error type has no values: generation cannot fail.
        let _ = bevy_mikktspace::generate_tangents(&mut mesh);
        mesh.out
    }

    /// Objects whose tangents have been computed.
    #[cfg(test)]
    fn computed(&self) -> usize {
        self.corners.iter().filter(|c| c.get().is_some()).count()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::normal_map::{bend, triangle_tangent};
    use formats::soup::Object;
    use glam::Vec2;

    fn soup_of(tris: &[([Vec3; 3], [Vec3; 3], [Vec2; 3])]) -> Soup {
        // Materials are only named by index: which ones read a map is `Tangents::new`'s
        // argument.
        let mut s = Soup::empty();
        s.objects.push(Object::new("mesh", "test"));
        for (p, n, uv) in tris {
            let base = s.positions.len() as u32;
            s.positions.extend(p);
            s.normals.extend(n);
            s.uvs.extend(uv);
            s.triangles.push([base, base + 1, base + 2]);
            s.tri_material.push(0);
            s.tri_object.push(0);
        }
        s
    }

    fn texel(x: f32, y: f32) -> Vec4 {
        Vec4::new(x * 0.5 + 0.5, y * 0.5 + 0.5, 1.0, 1.0)
    }

    #[test]
    fn a_flat_square_gets_its_triangles_own_frame() {
        // The unit square in the xz plane facing +y, u along +x, v along −z, as two
        // triangles sharing the diagonal.
        let n = [Vec3::Y; 3];
        let s = soup_of(&[
            (
                [Vec3::ZERO, Vec3::X, Vec3::new(1.0, 0.0, -1.0)],
                n,
                [Vec2::ZERO, Vec2::X, Vec2::ONE],
            ),
            (
                [Vec3::ZERO, Vec3::new(1.0, 0.0, -1.0), Vec3::NEG_Z],
                n,
                [Vec2::ZERO, Vec2::ONE, Vec2::Y],
            ),
        ]);
        let tangents = Tangents::new(&s, &[true]);
        for prim in 0..2 {
            let f = tangents.at(prim, 0.3, 0.2).expect("a tangent");
            assert!((f.t.normalize() - Vec3::X).length() < 1e-6, "{f:?}");
            assert_eq!(f.sign, 1.0);
            let bent = bend(Vec3::Y, f, texel(0.6, 0.0), 1.0);
            assert!((bent - Vec3::new(0.6, 0.8, 0.0)).length() < 1e-6, "{bent}");
            let bent = bend(Vec3::Y, f, texel(0.0, 0.6), 1.0);
            assert!((bent - Vec3::new(0.0, 0.8, -0.6)).length() < 1e-6, "{bent}");
        }
    }

    /// A strip folded along the edge x = 0 (a roof, normals averaged along the ridge) whose
    /// UVs are sheared differently on each side, so each triangle's own ∂p/∂u points
    /// elsewhere: the shared vertices' tangents make one frame along the ridge, so a map
    /// bends the normal the same on either side of it.
    #[test]
    fn the_frame_is_continuous_across_a_shared_edge() {
        let (a, b) = (Vec3::new(0.0, 1.0, 0.0), Vec3::new(0.0, 1.0, -1.0));
        let (l, r) = (Vec3::new(-1.0, 0.0, 0.0), Vec3::new(1.0, 0.0, -0.5));
        let nl = Vec3::new(-1.0, 1.0, 0.0).normalize();
        let nr = Vec3::new(1.0, 1.0, 0.0).normalize();
        let ridge = Vec3::Y;
        let (ua, ub) = (Vec2::new(0.5, 0.0), Vec2::new(0.5, 1.0));
        let s = soup_of(&[
            // Left: ridge a → b, then l. u grows towards +x, sheared one way.
            ([a, l, b], [ridge, nl, ridge], [ua, Vec2::new(0.0, 0.3), ub]),
            // Right: ridge a → b, then r, the shear the other way.
            ([a, b, r], [ridge, ridge, nr], [ua, ub, Vec2::new(1.0, 0.7)]),
        ]);
        let tangents = Tangents::new(&s, &[true]);
        // The midpoint of the ridge: corners 0 and 2 of the left triangle, 0 and 1 of the
        // right one.
        let left = tangents.at(0, 0.0, 0.5).expect("left tangent");
        let right = tangents.at(1, 0.5, 0.0).expect("right tangent");
        let t = texel(0.5, 0.3);
        let (bl, br) = (bend(ridge, left, t, 1.0), bend(ridge, right, t, 1.0));
        assert!((bl - br).length() < 1e-5, "{bl} against {br}");
        // Each triangle's own frame disagrees there: what the shared tangents fix.
        let own = |prim: usize| {
            let f = triangle_tangent(ridge, s.corners(prim), s.corner_uvs(prim)).unwrap();
            bend(ridge, f, t, 1.0)
        };
        assert!((own(0) - own(1)).length() > 0.05, "{} {}", own(0), own(1));
    }

    /// Two halves of a square mapped onto the same half of the texture, the right one
    /// mirrored (u runs back along +x): MikkTSpace keeps their frames apart at the shared
    /// edge, and red tilts each half towards its own increasing u.
    #[test]
    fn mirrored_halves_keep_their_own_frames() {
        let n = [Vec3::Y; 3];
        let (a, b) = (Vec3::ZERO, Vec3::NEG_Z);
        let s = soup_of(&[
            (
                [a, b, Vec3::new(-1.0, 0.0, 0.0)],
                n,
                [Vec2::new(1.0, 0.0), Vec2::new(1.0, 1.0), Vec2::ZERO],
            ),
            (
                [a, Vec3::X, b],
                n,
                [Vec2::new(1.0, 0.0), Vec2::ZERO, Vec2::new(1.0, 1.0)],
            ),
        ]);
        let tangents = Tangents::new(&s, &[true]);
        let (l, r) = (
            tangents.at(0, 0.2, 0.2).unwrap(),
            tangents.at(1, 0.2, 0.2).unwrap(),
        );
        let red = texel(0.6, 0.0);
        let (bl, br) = (bend(Vec3::Y, l, red, 1.0), bend(Vec3::Y, r, red, 1.0));
        assert!((bl - Vec3::new(0.6, 0.8, 0.0)).length() < 1e-6, "{bl}");
        assert!((br - Vec3::new(-0.6, 0.8, 0.0)).length() < 1e-6, "{br}");
        // Green tilts both towards −z, where v grows on both halves.
        let green = texel(0.0, 0.6);
        for f in [l, r] {
            let g = bend(Vec3::Y, f, green, 1.0);
            assert!((g - Vec3::new(0.0, 0.8, -0.6)).length() < 1e-6, "{g}");
        }
    }

    #[test]
    fn only_objects_that_read_a_normal_map_get_tangents() {
        let n = [Vec3::Y; 3];
        let tri = (
            [Vec3::ZERO, Vec3::X, Vec3::NEG_Z],
            n,
            [Vec2::ZERO, Vec2::X, Vec2::Y],
        );
        // Object 0 without a map; object 1 with one mapped triangle and one not.
        let mut s = soup_of(&[tri, tri, tri]);
        s.objects.push(Object::new("mapped", "test"));
        s.tri_object = vec![0, 1, 1];
        s.tri_material = vec![0, 1, 0];
        let tangents = Tangents::new(&s, &[false, true]);
        assert_eq!(tangents.tris, [vec![], vec![1, 2]]);
        assert_eq!(tangents.computed(), 0);
        assert!(tangents.at(0, 0.2, 0.2).is_none());
        assert_eq!(
            tangents.computed(),
            0,
            "an object without a map computes nothing"
        );
        let f = tangents.at(1, 0.2, 0.2).expect("a tangent");
        assert!((f.t - Vec3::X).length() < 1e-6, "{f:?}");
        assert_eq!(tangents.computed(), 1);
        assert_eq!(tangents.at(2, 0.2, 0.2), Some(f));
    }

    /// Meshes MikkTSpace may choke on: corners drawn from a small pool (so vertices weld,
    /// triangles repeat, collapse to a line or a point), coordinates from zero and
    /// subnormal to 1e30, normals zero or not finite, UVs all equal: every lookup returns
    /// a finite frame or none, and nothing panics.
    #[test]
    fn degenerate_meshes_give_finite_frames_or_none() {
        let mut rng = crate::sampling::Rng::new(7);
        let mut pick = |n: u32| rng.next_u32() % n;
        let values = [
            0.0, -0.0, 1.0, -1.0, 0.5, 1e-30, 1e-40, 1e30, -1e30, 3.0, 7.5e-3,
        ];
        let normals = [0.0, 1.0, -1.0, 0.6, f32::NAN, f32::INFINITY];
        for _ in 0..2_000 {
            let pool: Vec<(Vec3, Vec3, Vec2)> = (0..1 + pick(6))
                .map(|_| {
                    let mut v = || values[pick(values.len() as u32) as usize];
                    let p = Vec3::new(v(), v(), v());
                    let uv = Vec2::new(v(), v());
                    let mut m = || normals[pick(normals.len() as u32) as usize];
                    (p, Vec3::new(m(), m(), m()), uv)
                })
                .collect();
            let tris: Vec<_> = (0..1 + pick(12))
                .map(|_| {
                    let c: [_; 3] = std::array::from_fn(|_| pool[pick(pool.len() as u32) as usize]);
                    (c.map(|c| c.0), c.map(|c| c.1), c.map(|c| c.2))
                })
                .collect();
            let s = soup_of(&tris);
            let tangents = Tangents::new(&s, &[true]);
            for prim in 0..tris.len() {
                if let Some(f) = tangents.at(prim, 0.25, 0.5) {
                    assert!(f.t.is_finite() && f.sign.abs() == 1.0, "{f:?} on {tris:?}");
                }
            }
        }
    }
}
