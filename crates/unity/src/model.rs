//! A model file as Unity imports it, whatever its format: a tree of nodes (each becomes a
//! GameObject with a Transform), the meshes hung on them, and the names of their material
//! slots. OBJ and FBX readers both produce this; prefab instances of a model and
//! MeshFilters that point into one are resolved against it.
//!
//! Everything is in Unity's space (left-handed, clockwise front faces) and already scaled
//! by the importer's unit and scale settings, so a node's transform is exactly what Unity
//! shows in the Inspector of the imported GameObject.

use crate::mesh::Mesh;
use glam::{Quat, Vec3};
use std::sync::Arc;

#[derive(Clone, Debug, PartialEq)]
pub struct ModelNode {
    /// The name Unity gives the GameObject (the FBX Model node's name, the OBJ group's).
    pub name: String,
    /// Index of the parent in [`Model::nodes`]; `None` only for the root (index 0).
    pub parent: Option<usize>,
    /// Local transform in Unity space (`m_LocalPosition`, `m_LocalRotation`,
    /// `m_LocalScale`).
    pub translation: Vec3,
    pub rotation: Quat,
    pub scale: Vec3,
    /// Index into [`Model::meshes`] of the mesh its MeshFilter (or SkinnedMeshRenderer)
    /// holds.
    pub mesh: Option<usize>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct ModelMesh {
    /// The Mesh asset's name (what `Type:Mesh-><name>` hashes).
    pub name: String,
    /// Vertices in the node's frame, Unity space. Shared: every object drawing it
    /// reads this one copy.
    pub mesh: Arc<Mesh>,
    /// The model's own material name for each sub-mesh (`""` when the file names none).
    pub materials: Vec<String>,
    /// Skinning data when the mesh is deformed by bones.
    pub skin: Option<Skin>,
}

/// Linear blend skinning data of one mesh.
#[derive(Clone, Debug, PartialEq)]
pub struct Skin {
    /// Bone names in the order of the renderer's `m_Bones`.
    pub bones: Vec<String>,
    /// Mesh space → bone space at bind time, one per bone (Unity's `bindposes`).
    pub bind_poses: Vec<glam::Mat4>,
    /// Up to four (bone index, weight) pairs per vertex; weights sum to 1.
    pub weights: Vec<[(u32, f32); 4]>,
}

/// A material the model file defines itself (used when no `.mat` replaces it).
#[derive(Clone, Debug, PartialEq)]
pub struct ModelMaterial {
    pub name: String,
    /// Diffuse colour, linear.
    pub color: Vec3,
    /// File name of the diffuse texture the file names, if any (as written in the file).
    pub texture: Option<String>,
}

#[derive(Clone, Debug, Default, PartialEq)]
pub struct Model {
    /// Depth-first order: a parent comes before its children; index 0 is the root.
    pub nodes: Vec<ModelNode>,
    pub meshes: Vec<ModelMesh>,
    pub materials: Vec<ModelMaterial>,
    /// What the reader could not honour, one line each, without the file name.
    pub warnings: Vec<String>,
}

impl Model {
    pub fn triangle_count(&self) -> usize {
        self.meshes.iter().map(|m| m.mesh.triangle_count()).sum()
    }

    /// Scale every node's translation and mesh (ModelImporter `globalScale`).
    pub fn scale(&mut self, s: f32) {
        for n in &mut self.nodes {
            n.translation *= s;
        }
        for m in &mut self.meshes {
            let mesh = Arc::make_mut(&mut m.mesh);
            *mesh = std::mem::take(mesh).scaled(s);
        }
    }

    /// The model's own material of that name.
    pub fn material(&self, name: &str) -> Option<&ModelMaterial> {
        self.materials.iter().find(|m| m.name == name)
    }

    /// The name Unity gives the material of a sub-mesh whose file names none.
    pub const UNNAMED_MATERIAL: &'static str = "defaultMat";

    /// The name Unity's FBX importer gives the material of a mesh that has none (the
    /// legacy tables, `externalObjects` remaps and extracted `No Name.mat` files of real
    /// projects all use it).
    pub const FBX_UNNAMED_MATERIAL: &'static str = "No Name";

    /// The name of the material Unity imports for a sub-mesh's own material name.
    pub fn material_name(own: &str) -> &str {
        if own.is_empty() {
            Self::UNNAMED_MATERIAL
        } else {
            own
        }
    }

    /// The path Unity hashes for a node under `fileIdsGeneration: 2`:
    /// `//RootNode/root/<child>/<grandchild>` (the root itself is `//RootNode/root`).
    pub fn node_path(&self, index: usize) -> String {
        let mut names = Vec::new();
        let mut cur = Some(index);
        while let Some(i) = cur {
            if self.nodes[i].parent.is_some() {
                names.push(self.nodes[i].name.as_str());
            }
            cur = self.nodes[i].parent;
        }
        names.reverse();
        let mut p = String::from("//RootNode/root");
        for n in names {
            p.push('/');
            p.push_str(n);
        }
        p
    }
}
