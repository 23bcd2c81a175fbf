//! MeshRenderer (class 23) with its MeshFilter (class 33): the mesh's triangles in world
//! space, soup handedness, each with the material of its sub-mesh's slot. Skinned
//! renderers draw their posed mesh through the same `draw`.

use crate::emit::{flip, EmitError, Emitter};
use crate::layer::layer;
use crate::mesh::Mesh;
use formats::{CastShadows, Object};
use glam::{Mat3, Mat4, Vec2, Vec3};
use rayon::prelude::*;

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
        self.draw(go, &mesh, source, world, mr)
    }

    /// Draw `mesh` placed by `world` (Unity space) with the material slots of renderer
    /// `renderer` on GameObject `go`.
    pub(crate) fn draw(
        &mut self,
        go: usize,
        mesh: &Mesh,
        source: String,
        world: Mat4,
        renderer: usize,
    ) -> Result<(), EmitError> {
        let g = self.g;
        let what = self.describe(go);
        if mesh.positions.iter().any(|p| !p.is_finite()) {
            return Err(self.non_finite(go, format!("mesh {source} has a NaN or infinite vertex")));
        }
        let flip_winding = world.determinant() < 0.0;
        let slots = &g.objs[renderer].materials;
        let obj_index = self.soup.objects.len() as u32;
        let r = &g.objs[renderer].body;
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
        let placed = Placed::new(mesh, world);
        let mut origins: Vec<(u32, String)> = Vec::new();
        let mut emitted = 0usize;
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
            emitted += self.place(&placed, tris, flip_winding, mat, obj_index);
        }
        if emitted == 0 {
            // Keep object indices dense in what renders: drop an object without triangles.
            self.soup.objects.pop();
        } else {
            self.material_origins.push(origins);
        }
        Ok(())
    }
}

/// Sub-meshes and meshes smaller than this are placed on the calling thread: waking the
/// pool costs more than transforming a few thousand triangles, and real scenes have
/// hundreds of small objects.
const PARALLEL_MIN: usize = 8192;

/// A mesh's vertices in world space, soup handedness. Each vertex is transformed once
/// rather than once per corner (a closed mesh has about six corners per vertex); a corner
/// then copies the very values the per-corner transform computed. Texture coordinates do
/// not move with the mesh, so they are the mesh's own.
struct Placed<'m> {
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
    uvs: &'m [Vec2],
}

impl<'m> Placed<'m> {
    fn new(mesh: &'m Mesh, world: Mat4) -> Self {
        let normal_m = Mat3::from_mat4(world).inverse().transpose();
        let position = |p: &Vec3| flip(world.transform_point3(*p));
        let normal = |n: &Vec3| {
            let n = flip((normal_m * *n).normalize_or_zero());
            if n == Vec3::ZERO {
                Vec3::Y
            } else {
                n
            }
        };
        if mesh.positions.len() < PARALLEL_MIN {
            Placed {
                positions: mesh.positions.iter().map(position).collect(),
                normals: mesh.normals.iter().map(normal).collect(),
                uvs: &mesh.uvs,
            }
        } else {
            Placed {
                positions: mesh.positions.par_iter().map(position).collect(),
                normals: mesh.normals.par_iter().map(normal).collect(),
                uvs: &mesh.uvs,
            }
        }
    }
}

impl Emitter<'_, '_> {
    /// Append sub-mesh `tris` of the `placed` mesh to the soup; how many triangles it kept
    /// (degenerate ones are dropped and counted).
    ///
    /// Large sub-meshes are gathered on all threads straight into the soup's vectors
    /// (rayon's indexed `par_extend` writes in place, in order), positions and normals as
    /// two passes, so the output is the same as a sequential loop's. Degenerate triangles
    /// are found afterwards and squeezed out in order; they are rare.
    ///
    /// UVs cost a third pass, so they are gathered only once a textured material has been
    /// seen: until then `soup.uvs` stays empty (and an untextured soup never pays), from
    /// then on every triangle gets a triple — its mesh's UVs when its material is
    /// textured, zeros otherwise, since nothing samples them.
    fn place(
        &mut self,
        placed: &Placed,
        tris: &[[u32; 3]],
        flip_winding: bool,
        mat: u32,
        obj_index: u32,
    ) -> usize {
        // The flip to right-handed space reverses the winding once; a mirroring transform
        // (negative determinant) reverses it again.
        fn wind<T: Copy>(flip_winding: bool, v: [T; 3]) -> [T; 3] {
            if flip_winding {
                v
            } else {
                [v[0], v[2], v[1]]
            }
        }
        let position = |t: &[u32; 3]| wind(flip_winding, t.map(|i| placed.positions[i as usize]));
        let normal = |t: &[u32; 3]| wind(flip_winding, t.map(|i| placed.normals[i as usize]));
        let textured = self.soup.materials[mat as usize].albedo_map.is_some();
        let soup = &mut self.soup;
        let start = soup.triangles.len();
        if textured && soup.uvs.len() < start {
            soup.uvs.resize(start, [Vec2::ZERO; 3]);
        }
        let uvs_on = textured || !soup.uvs.is_empty();
        // A mesh without UVs (or with fewer than positions) samples texel (0, 0).
        let mesh_uvs = if textured && placed.uvs.len() == placed.positions.len() {
            placed.uvs
        } else {
            &[]
        };
        let uv = |t: &[u32; 3]| {
            if mesh_uvs.is_empty() {
                [Vec2::ZERO; 3]
            } else {
                wind(flip_winding, t.map(|i| mesh_uvs[i as usize]))
            }
        };
        let n = tris.len();
        let dropped = if n < PARALLEL_MIN {
            soup.triangles.extend(tris.iter().map(position));
            soup.normals.extend(tris.iter().map(normal));
            if uvs_on {
                soup.uvs.extend(tris.iter().map(uv));
            }
            soup.triangles[start..]
                .iter()
                .filter(|p| degenerate(**p))
                .count()
        } else {
            soup.triangles
                .par_extend(tris.par_iter().with_min_len(PARALLEL_MIN / 2).map(position));
            soup.normals
                .par_extend(tris.par_iter().with_min_len(PARALLEL_MIN / 2).map(normal));
            if uvs_on {
                soup.uvs
                    .par_extend(tris.par_iter().with_min_len(PARALLEL_MIN / 2).map(uv));
            }
            soup.triangles[start..]
                .par_iter()
                .with_min_len(PARALLEL_MIN / 2)
                .filter(|p| degenerate(**p))
                .count()
        };
        if dropped > 0 {
            let mut kept = start;
            for i in start..start + n {
                if !degenerate(soup.triangles[i]) {
                    soup.triangles[kept] = soup.triangles[i];
                    soup.normals[kept] = soup.normals[i];
                    if uvs_on {
                        soup.uvs[kept] = soup.uvs[i];
                    }
                    kept += 1;
                }
            }
            soup.triangles.truncate(kept);
            soup.normals.truncate(kept);
            if uvs_on {
                soup.uvs.truncate(kept);
            }
            soup.dropped_degenerate += dropped as u64;
        }
        let kept = n - dropped;
        soup.tri_material.extend(std::iter::repeat_n(mat, kept));
        soup.tri_object.extend(std::iter::repeat_n(obj_index, kept));
        kept
    }
}

/// Zero area, repeated or collinear vertices (up to float noise): |e1 × e2| ≤ 10⁻⁹·|e1|·|e2|,
/// compared squared, so that no square root is taken for the millions of triangles that
/// pass.
fn degenerate(p: [Vec3; 3]) -> bool {
    if p[0] == p[1] || p[1] == p[2] || p[0] == p[2] {
        return true;
    }
    let a = p[0].as_dvec3();
    let e1 = p[1].as_dvec3() - a;
    let e2 = p[2].as_dvec3() - a;
    e1.cross(e2).length_squared() <= 1e-18 * e1.length_squared() * e2.length_squared()
}
