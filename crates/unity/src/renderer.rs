//! MeshRenderer (class 23) with its MeshFilter (class 33): the mesh's triangles in world
//! space, soup handedness, each with the material of its sub-mesh's slot. Skinned
//! renderers draw their posed mesh through the same `draw`.

use crate::emit::{flip, EmitError, Emitter};
use crate::layer::layer;
use crate::mesh::Mesh;
use formats::{CastShadows, Object, Soup};
use glam::{Mat3, Mat4, Vec2, Vec3};
use rayon::prelude::*;
use std::sync::Arc;

impl Emitter<'_, '_> {
    /// Draw the mesh of MeshFilter `mf` with the materials of MeshRenderer `mr`, both on
    /// GameObject `go`.
    pub(crate) fn mesh_object(&mut self, go: usize, mf: usize, mr: usize) -> Result<(), EmitError> {
        let g = self.g;
        let what = self.describe(go);
        let (mesh, source) = match self.resolve_mesh(&g.objs[mf].mesh, go) {
            Ok(x) => x,
            Err(reason) => {
                self.soup
                    .warnings
                    .push(format!("{what}: {reason}; skipped"));
                return Ok(());
            }
        };
        let world = self.checked_world(go)?;
        self.draw(go, mesh, source, world, mr)
    }

    /// Draw `mesh` placed by `world` (Unity space) with the material slots of renderer
    /// `renderer` on GameObject `go`. The object and its materials are decided here, in
    /// scene order; its vertices and triangles are computed with every other object's by
    /// [`Placements::fill`], on all threads.
    pub(crate) fn draw(
        &mut self,
        go: usize,
        mesh: Arc<Mesh>,
        source: String,
        world: Mat4,
        renderer: usize,
    ) -> Result<(), EmitError> {
        let g = self.g;
        let what = self.describe(go);
        if mesh.positions.iter().any(|p| !p.is_finite()) {
            return Err(self.non_finite(go, format!("mesh {source} has a NaN or infinite vertex")));
        }
        let slots = &g.objs[renderer].materials;
        let mut parts = Vec::new();
        let mut origins: Vec<(u32, String)> = Vec::new();
        for (si, tris) in mesh.submeshes.iter().enumerate() {
            if tris.is_empty() {
                continue;
            }
            let Some(slot) = slots.get(si) else {
                self.soup.warnings.push(format!(
                    "{what}: sub-mesh {si} has no material slot, so Unity draws nothing for it; skipped"
                ));
                continue;
            };
            let (mat, origin) = self.material(slot, &what);
            if !origins.iter().any(|(m, _)| *m == mat) {
                origins.push((mat, origin));
            }
            parts.push((si, mat));
        }
        if parts.is_empty() {
            return Ok(());
        }
        if self.placements.vertices + mesh.positions.len() > u32::MAX as usize {
            self.soup.warnings.push(format!(
                "{what}: the soup would hold more than 2^32 vertices with this mesh; skipped"
            ));
            return Ok(());
        }
        let r = &g.objs[renderer].body;
        let object = self.soup.objects.len() as u32;
        self.soup.objects.push(Object {
            name: self.path(go),
            source,
            layer: layer(&g.objs[go].body),
            cast_shadows: match r.i64_at("m_CastShadows") {
                Some(0) => CastShadows::Off,
                Some(2) => CastShadows::TwoSided,
                Some(3) => CastShadows::ShadowsOnly,
                _ => CastShadows::On,
            },
            receive_shadows: r.i64_at("m_ReceiveShadows") != Some(0),
        });
        self.material_origins.push(origins);
        self.placements.push(mesh, world, parts, object);
        Ok(())
    }
}

/// Every drawn mesh, in scene order, with where its vertices and triangles go in the soup.
#[derive(Default)]
pub(crate) struct Placements {
    jobs: Vec<Placement>,
    vertices: usize,
    triangles: usize,
}

struct Placement {
    mesh: Arc<Mesh>,
    world: Mat4,
    /// (sub-mesh, soup material) of each drawn sub-mesh, in sub-mesh order.
    parts: Vec<(usize, u32)>,
    object: u32,
    /// Its first vertex in the soup, and how many triangles its parts hold.
    vertex: usize,
    triangles: usize,
}

impl Placements {
    pub(crate) fn push(
        &mut self,
        mesh: Arc<Mesh>,
        world: Mat4,
        parts: Vec<(usize, u32)>,
        object: u32,
    ) {
        let triangles = parts.iter().map(|&(si, _)| mesh.submeshes[si].len()).sum();
        let job = Placement {
            vertex: self.vertices,
            triangles,
            mesh,
            world,
            parts,
            object,
        };
        self.vertices += job.mesh.positions.len();
        self.triangles += triangles;
        self.jobs.push(job);
    }

    /// Write every placed mesh into the soup: vertices in world space, soup handedness
    /// (each transformed once and shared by the triangles that name it), triangles as
    /// indices with their material and object. The soup's arrays are allocated once and
    /// split into each mesh's share, so meshes fill on all threads, and large meshes in
    /// parallel pieces; the output is the same as a sequential loop's.
    ///
    /// UVs are stored only when some material has an albedo or normal map; then every vertex has its
    /// mesh's UVs, or (0, 0) when the mesh has none (or fewer than positions). Texture
    /// coordinates do not move with the mesh.
    ///
    /// Degenerate triangles are dropped and counted afterwards (they are rare), and an
    /// object left without triangles is dropped with them, so that object indices stay
    /// dense in what renders; `origins` is kept parallel to the objects.
    pub(crate) fn fill(self, soup: &mut Soup, origins: &mut Vec<Vec<(u32, String)>>) {
        let textured = soup.materials.iter().any(formats::Material::reads_uvs);
        let (nv, nt) = (self.vertices, self.triangles);
        let mut positions: Vec<Vec3> = bytemuck::zeroed_vec(nv);
        let mut normals: Vec<Vec3> = bytemuck::zeroed_vec(nv);
        let mut uvs: Vec<Vec2> = bytemuck::zeroed_vec(if textured { nv } else { 0 });
        let mut triangles: Vec<[u32; 3]> = bytemuck::zeroed_vec(nt);
        let mut tri_material: Vec<u32> = bytemuck::zeroed_vec(nt);
        let mut tri_object: Vec<u32> = bytemuck::zeroed_vec(nt);
        let dropped: usize = {
            let mut rest = Shares {
                positions: &mut positions,
                normals: &mut normals,
                uvs: &mut uvs,
                triangles: &mut triangles,
                tri_material: &mut tri_material,
                tri_object: &mut tri_object,
            };
            let shares: Vec<(&Placement, Shares)> = self
                .jobs
                .iter()
                .map(|job| {
                    let v = job.mesh.positions.len();
                    (
                        job,
                        rest.split_off(v, if textured { v } else { 0 }, job.triangles),
                    )
                })
                .collect();
            shares
                .into_par_iter()
                .map(|(job, share)| job.fill(share))
                .sum()
        };
        if dropped > 0 {
            compact(
                &positions,
                &mut triangles,
                &mut tri_material,
                &mut tri_object,
            );
            drop_empty_objects(soup, origins, &mut tri_object);
        }
        soup.positions = positions;
        soup.normals = normals;
        soup.uvs = uvs;
        soup.triangles = triangles;
        soup.tri_material = tri_material;
        soup.tri_object = tri_object;
        soup.dropped_degenerate += dropped as u64;
    }
}

/// One mesh's part of the soup's arrays.
struct Shares<'s> {
    positions: &'s mut [Vec3],
    normals: &'s mut [Vec3],
    uvs: &'s mut [Vec2],
    triangles: &'s mut [[u32; 3]],
    tri_material: &'s mut [u32],
    tri_object: &'s mut [u32],
}

impl<'s> Shares<'s> {
    /// The first `v` vertices (`uv` UVs) and `t` triangles, leaving the rest in `self`.
    fn split_off(&mut self, v: usize, uv: usize, t: usize) -> Shares<'s> {
        fn take<'a, T>(s: &mut &'a mut [T], n: usize) -> &'a mut [T] {
            let (head, tail) = std::mem::take(s).split_at_mut(n);
            *s = tail;
            head
        }
        Shares {
            positions: take(&mut self.positions, v),
            normals: take(&mut self.normals, v),
            uvs: take(&mut self.uvs, uv),
            triangles: take(&mut self.triangles, t),
            tri_material: take(&mut self.tri_material, t),
            tri_object: take(&mut self.tri_object, t),
        }
    }
}

/// Pieces of a mesh filled by one task: large enough that waking a thread pays.
const PIECE: usize = 4096;

impl Placement {
    /// Fill this mesh's share of the soup; how many of its triangles are degenerate (they
    /// are tested here, while the mesh's placed vertices are in cache).
    fn fill(&self, share: Shares) -> usize {
        let (mesh, world) = (&*self.mesh, self.world);
        let normal_m = Mat3::from_mat4(world).inverse().transpose();
        share
            .positions
            .par_iter_mut()
            .zip(share.normals.par_iter_mut())
            .zip(mesh.positions.par_iter().zip(&mesh.normals))
            .with_min_len(PIECE)
            .for_each(|((p, n), (mp, mn))| {
                *p = flip(world.transform_point3(*mp));
                let placed = flip((normal_m * *mn).normalize_or_zero());
                *n = if placed == Vec3::ZERO {
                    Vec3::Y
                } else {
                    placed
                };
            });
        if !share.uvs.is_empty() && mesh.uvs.len() == mesh.positions.len() {
            share.uvs.copy_from_slice(&mesh.uvs);
        }
        // The flip to right-handed space reverses the winding once; a mirroring transform
        // (negative determinant) reverses it again.
        let flip_winding = world.determinant() < 0.0;
        let base = self.vertex as u32;
        let placed: &[Vec3] = share.positions;
        let (mut triangles, mut materials, mut objects) =
            (share.triangles, share.tri_material, share.tri_object);
        let mut dropped = 0;
        for &(si, mat) in &self.parts {
            let tris = &self.mesh.submeshes[si];
            let (t, rest) = triangles.split_at_mut(tris.len());
            dropped += t
                .par_iter_mut()
                .zip(tris.par_iter())
                .with_min_len(PIECE)
                .map(|(out, t)| {
                    *out = t.map(|i| base + i);
                    if !flip_winding {
                        out.swap(1, 2);
                    }
                    degenerate(t.map(|i| placed[i as usize])) as usize
                })
                .sum::<usize>();
            let (m, more_m) = materials.split_at_mut(tris.len());
            let (o, more_o) = objects.split_at_mut(tris.len());
            m.fill(mat);
            o.fill(self.object);
            (triangles, materials, objects) = (rest, more_m, more_o);
        }
        dropped
    }
}

/// Squeeze degenerate triangles out of the arrays, keeping order (there are rarely any).
fn compact(
    positions: &[Vec3],
    triangles: &mut Vec<[u32; 3]>,
    tri_material: &mut Vec<u32>,
    tri_object: &mut Vec<u32>,
) {
    let bad = |t: &[u32; 3]| degenerate(t.map(|i| positions[i as usize]));
    let mut kept = 0;
    for i in 0..triangles.len() {
        if !bad(&triangles[i]) {
            triangles[kept] = triangles[i];
            tri_material[kept] = tri_material[i];
            tri_object[kept] = tri_object[i];
            kept += 1;
        }
    }
    triangles.truncate(kept);
    tri_material.truncate(kept);
    tri_object.truncate(kept);
}

/// Drop the objects no triangle names any more (all of theirs were degenerate) and
/// renumber the rest.
fn drop_empty_objects(
    soup: &mut Soup,
    origins: &mut Vec<Vec<(u32, String)>>,
    tri_object: &mut [u32],
) {
    let mut used = vec![false; soup.objects.len()];
    for &o in tri_object.iter() {
        used[o as usize] = true;
    }
    if used.iter().all(|&u| u) {
        return;
    }
    let mut number = vec![u32::MAX; used.len()];
    let mut next = 0;
    for (o, &u) in used.iter().enumerate() {
        if u {
            number[o] = next;
            next += 1;
        }
    }
    for o in tri_object.iter_mut() {
        *o = number[*o as usize];
    }
    let mut keep = used.iter().copied();
    soup.objects.retain(|_| keep.next().unwrap_or(false));
    let mut keep = used.iter().copied();
    origins.retain(|_| keep.next().unwrap_or(false));
}

/// Zero area, repeated or collinear vertices (up to float noise): |e1 × e2| ≤ 10⁻⁹·|e1|·|e2|
/// in f64, compared squared, so that no square root is taken for the millions of
/// triangles that pass.
///
/// Most triangles are nowhere near the bound, and f32 says so at a third of the cost:
/// rounding moves the f32 |e1 × e2| by less than 10⁻⁶·|e1|·|e2|, so above 10⁻⁴·|e1|·|e2|
/// the f64 test passes too. Where the f32 products overflow or underflow, or the triangle
/// is anywhere near the bound, the f64 test decides.
#[inline(always)]
fn degenerate(p: [Vec3; 3]) -> bool {
    // Inlined into the placing loop, the corners taken apart and put together again for the
    // f64 test: handed on as an array, they went through memory, narrow stores read back
    // wide, and the test cost about 24 ns a triangle instead of 5.5 (a loop over 16,384
    // triangles); placing `fbxlarge` took 52 ms instead of 31.
    let [a, b, c] = p;
    let (e1, e2) = (b - a, c - a);
    let scale = e1.length_squared() * e2.length_squared();
    let area = e1.cross(e2).length_squared();
    if scale.is_normal() && area.is_finite() && area >= 1e-8 * scale {
        return false;
    }
    degenerate_f64([a, b, c])
}

#[cold]
#[inline(never)]
fn degenerate_f64(p: [Vec3; 3]) -> bool {
    if p[0] == p[1] || p[1] == p[2] || p[0] == p[2] {
        return true;
    }
    let a = p[0].as_dvec3();
    let e1 = p[1].as_dvec3() - a;
    let e2 = p[2].as_dvec3() - a;
    e1.cross(e2).length_squared() <= 1e-18 * e1.length_squared() * e2.length_squared()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// xorshift64: enough randomness for a sweep, and the same every run.
    struct Rng(u64);

    impl Rng {
        fn f(&mut self) -> f64 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            (self.0 >> 11) as f64 / (1u64 << 53) as f64
        }

        fn v(&mut self) -> Vec3 {
            Vec3::new(self.f() as f32, self.f() as f32, self.f() as f32) * 2.0 - 1.0
        }
    }

    /// The f32 shortcut never changes the answer: random triangles at every scale and far
    /// from the origin, and nearly collinear ones on both sides of the bound.
    #[test]
    fn the_f32_shortcut_agrees_with_the_f64_test() {
        let mut r = Rng(0x9e37_79b9_7f4a_7c15);
        let (mut near, mut degenerate_seen) = (0, 0);
        for i in 0..200_000 {
            let scale = 10f64.powf(r.f() * 40.0 - 20.0) as f32;
            let far = if i % 2 == 0 {
                10f64.powf(r.f() * 10.0) as f32
            } else {
                0.0
            };
            let (a, b) = (r.v() * scale + far, r.v() * scale + far);
            let c = if i % 4 < 2 {
                // Collinear up to a relative offset around the 10⁻⁹ bound.
                near += 1;
                let off = 10f64.powf(r.f() * 8.0 - 12.0) as f32;
                a + (b - a) * r.f() as f32 + r.v() * scale * off
            } else {
                r.v() * scale + far
            };
            let p = [a, b, c];
            let want = degenerate_f64(p);
            degenerate_seen += want as usize;
            assert_eq!(degenerate(p), want, "{p:?}");
        }
        assert!(near > 0 && degenerate_seen > 1000, "{degenerate_seen}");
    }
}
