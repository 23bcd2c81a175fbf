//! MeshRenderer (class 23) with its MeshFilter (class 33): the mesh's triangles in world
//! space, soup handedness, each with the material of its sub-mesh's slot. Skinned
//! renderers draw their posed mesh through the same `draw`.

use crate::emit::{flip, EmitError, Emitter};
use crate::layer::layer;
use crate::mesh::Mesh;
use formats::{CastShadows, Object};
use glam::{Mat3, Mat4, Vec3};

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
        let normal_m = Mat3::from_mat4(world).inverse().transpose();
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
            for t in tris {
                let p = t.map(|i| flip(world.transform_point3(mesh.positions[i as usize])));
                let n = t.map(|i| {
                    let n = flip((normal_m * mesh.normals[i as usize]).normalize_or_zero());
                    if n == Vec3::ZERO {
                        Vec3::Y
                    } else {
                        n
                    }
                });
                if degenerate(p) {
                    self.soup.dropped_degenerate += 1;
                    continue;
                }
                // The flip to right-handed space reverses the winding once; a mirroring
                // transform (negative determinant) reverses it again.
                let (p, n) = if flip_winding {
                    (p, n)
                } else {
                    ([p[0], p[2], p[1]], [n[0], n[2], n[1]])
                };
                self.soup.triangles.push(p);
                self.soup.normals.push(n);
                self.soup.tri_material.push(mat);
                self.soup.tri_object.push(obj_index);
                emitted += 1;
            }
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

/// Zero area, repeated or collinear vertices (up to float noise).
fn degenerate(p: [Vec3; 3]) -> bool {
    if p[0] == p[1] || p[1] == p[2] || p[0] == p[2] {
        return true;
    }
    let a = p[0].as_dvec3();
    let e1 = p[1].as_dvec3() - a;
    let e2 = p[2].as_dvec3() - a;
    let c = e1.cross(e2).length();
    c <= 1e-9 * e1.length() * e2.length()
}
