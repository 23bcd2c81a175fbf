//! MeshRenderer (class 23) with its MeshFilter (class 33): the mesh's triangles in world
//! space, soup handedness, each with the material of its sub-mesh's slot. Skinned
//! renderers draw their posed mesh through the same `draw`.

use crate::emit::{flip, EmitError, Emitter};
use crate::layer::layer;
use crate::mesh::Mesh;
use formats::{CastShadows, Object, Soup};
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
        // Resolve every slot first: whether any of them is textured decides whether the
        // vertices carry UVs.
        let mut parts: Vec<(&[[u32; 3]], u32)> = Vec::new();
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
            parts.push((tris, mat));
        }
        if self.soup.positions.len() + mesh.positions.len() > u32::MAX as usize {
            self.soup.objects.pop();
            self.soup.warnings.push(format!(
                "{what}: the soup would hold more than 2^32 vertices with this mesh; skipped"
            ));
            return Ok(());
        }
        let textured = parts
            .iter()
            .any(|&(_, m)| self.soup.materials[m as usize].albedo_map.is_some());
        let base = place_vertices(&mut self.soup, mesh, world, textured);
        let mut emitted = 0usize;
        for (tris, mat) in parts {
            emitted += place_triangles(&mut self.soup, base, tris, flip_winding, mat, obj_index);
        }
        if emitted == 0 {
            // Keep object indices dense in what renders: drop an object without triangles,
            // and its vertices.
            self.soup.objects.pop();
            let soup = &mut self.soup;
            soup.positions.truncate(base as usize);
            soup.normals.truncate(base as usize);
            soup.uvs.truncate(base.min(soup.uvs.len() as u32) as usize);
        } else {
            self.material_origins.push(origins);
        }
        Ok(())
    }
}

/// Sub-meshes and meshes smaller than this are placed on the calling thread: waking the
/// pool costs more than transforming a few thousand vertices, and real scenes have
/// hundreds of small objects.
const PARALLEL_MIN: usize = 8192;

/// Append `mesh`'s vertices placed by `world` (Unity space) to the soup, in soup
/// handedness, on all threads for large meshes (rayon's indexed `par_extend` writes in
/// place, in order); the index of the first. Each vertex is transformed once and shared by
/// the triangles that name it (a closed mesh has about six corners per vertex).
///
/// UVs are stored only once a textured material has been seen: until then `soup.uvs` stays
/// empty (and an untextured soup never pays), from then on every vertex gets its mesh's
/// UVs, or (0, 0) when the mesh has none (or fewer than positions). Texture coordinates do
/// not move with the mesh.
fn place_vertices(soup: &mut Soup, mesh: &Mesh, world: Mat4, textured: bool) -> u32 {
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
    let base = soup.positions.len();
    if textured && soup.uvs.len() < base {
        soup.uvs.resize(base, Vec2::ZERO);
    }
    if mesh.positions.len() < PARALLEL_MIN {
        soup.positions.extend(mesh.positions.iter().map(position));
        soup.normals.extend(mesh.normals.iter().map(normal));
    } else {
        soup.positions
            .par_extend(mesh.positions.par_iter().map(position));
        soup.normals.par_extend(mesh.normals.par_iter().map(normal));
    }
    if !soup.uvs.is_empty() || textured {
        if mesh.uvs.len() == mesh.positions.len() {
            soup.uvs.extend_from_slice(&mesh.uvs);
        } else {
            soup.uvs.resize(soup.positions.len(), Vec2::ZERO);
        }
    }
    base as u32
}

/// Append sub-mesh `tris` of the mesh whose vertices start at `base` to the soup; how many
/// triangles it kept (degenerate ones are dropped and counted). Large sub-meshes are
/// gathered on all threads; degenerate triangles are found afterwards and squeezed out in
/// order, since they are rare.
fn place_triangles(
    soup: &mut Soup,
    base: u32,
    tris: &[[u32; 3]],
    flip_winding: bool,
    mat: u32,
    obj_index: u32,
) -> usize {
    // The flip to right-handed space reverses the winding once; a mirroring transform
    // (negative determinant) reverses it again.
    let index = |t: &[u32; 3]| {
        let t = t.map(|i| base + i);
        if flip_winding {
            t
        } else {
            [t[0], t[2], t[1]]
        }
    };
    let start = soup.triangles.len();
    let n = tris.len();
    let Soup {
        positions,
        triangles,
        ..
    } = soup;
    let bad = |t: &[u32; 3]| degenerate(t.map(|i| positions[i as usize]));
    let dropped = if n < PARALLEL_MIN {
        triangles.extend(tris.iter().map(index));
        triangles[start..].iter().filter(|t| bad(t)).count()
    } else {
        triangles.par_extend(tris.par_iter().with_min_len(PARALLEL_MIN / 2).map(index));
        triangles[start..]
            .par_iter()
            .with_min_len(PARALLEL_MIN / 2)
            .filter(|t| bad(t))
            .count()
    };
    if dropped > 0 {
        let mut kept = start;
        for i in start..start + n {
            if !bad(&triangles[i]) {
                triangles[kept] = triangles[i];
                kept += 1;
            }
        }
        triangles.truncate(kept);
        soup.dropped_degenerate += dropped as u64;
    }
    let kept = n - dropped;
    soup.tri_material.extend(std::iter::repeat_n(mat, kept));
    soup.tri_object.extend(std::iter::repeat_n(obj_index, kept));
    kept
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
