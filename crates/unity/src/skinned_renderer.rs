//! SkinnedMeshRenderer (class 137): the mesh posed by its bone Transforms as they stand
//! in the scene, by linear blend skinning, which is what the editor shows. A renderer
//! whose bones cannot be matched to the mesh's skin is drawn rigidly at its own
//! Transform in the bind pose.

use crate::emit::{EmitError, Emitter};
use crate::mesh::Mesh;
use crate::model::Skin;
use glam::{Mat3, Mat4, Vec3};

impl Emitter<'_, '_> {
    /// Draw SkinnedMeshRenderer `smr` of GameObject `go`.
    pub(crate) fn skinned_object(&mut self, go: usize, smr: usize) -> Result<(), EmitError> {
        let g = self.g;
        let what = self.describe(go);
        let r = g.objs[smr].mesh.clone();
        let (mesh, source) = match self.resolve_mesh(&r, go) {
            Ok(x) => x,
            Err(reason) => {
                self.soup
                    .warnings
                    .push(format!("{what}: SkinnedMeshRenderer: {reason}; skipped"));
                return Ok(());
            }
        };
        let skin = self.model_skin(&r);
        let posed = match self.bone_matrices(smr, skin.as_ref(), &mesh) {
            Ok(bones) => skin.as_ref().map(|s| pose(&mesh, s, &bones)),
            Err(why) => {
                self.soup.warnings.push(format!(
                    "{what}: SkinnedMeshRenderer {why}; drawn in its bind pose at the renderer's transform"
                ));
                None
            }
        };
        match posed {
            Some(m) => self.draw(go, std::sync::Arc::new(m), source, Mat4::IDENTITY, smr),
            None => {
                let world = self.checked_world(go)?;
                self.draw(go, mesh, source, world, smr)
            }
        }
    }

    /// boneWorld · bindPose for every bone of the renderer, or why the bones do not fit
    /// the skin.
    fn bone_matrices(
        &mut self,
        smr: usize,
        skin: Option<&Skin>,
        mesh: &Mesh,
    ) -> Result<Vec<Mat4>, String> {
        let Some(skin) = skin else {
            return Err("has a mesh without skin weights".into());
        };
        let bones = self.g.objs[smr].bones.clone();
        if bones.is_empty() {
            return Err("has no bones (m_Bones is empty)".into());
        }
        if bones.len() != skin.bind_poses.len() {
            return Err(format!(
                "has {} bones but its mesh's skin has {}",
                bones.len(),
                skin.bind_poses.len()
            ));
        }
        if skin.weights.len() != mesh.positions.len() {
            return Err("has skin weights that do not match its mesh's vertices".into());
        }
        let mut out = Vec::with_capacity(bones.len());
        for (i, (b, bind)) in bones.iter().zip(&skin.bind_poses).enumerate() {
            let Some(t) = *b else {
                return Err(format!("bone {i} is not a Transform of the scene"));
            };
            let m = self.world(t) * *bind;
            if !m.is_finite() {
                return Err(format!("bone {i} has a NaN or infinite transform"));
            }
            out.push(m);
        }
        Ok(out)
    }
}

/// The mesh in world space (Unity's): each vertex by Σ wᵢ·(boneWorldᵢ·bindPoseᵢ), its
/// normal by the inverse transpose of that blend.
fn pose(mesh: &Mesh, skin: &Skin, bones: &[Mat4]) -> Mesh {
    let mut out = mesh.clone();
    for (v, w) in skin.weights.iter().enumerate() {
        let mut m = Mat4::ZERO;
        for &(b, wt) in w {
            if wt > 0.0 {
                if let Some(bm) = bones.get(b as usize) {
                    m += *bm * wt;
                }
            }
        }
        if m == Mat4::ZERO {
            continue;
        }
        out.positions[v] = m.transform_point3(mesh.positions[v]);
        let n = (Mat3::from_mat4(m).inverse().transpose() * mesh.normals[v]).normalize_or_zero();
        out.normals[v] = if n.is_finite() { n } else { Vec3::ZERO };
    }
    out
}
