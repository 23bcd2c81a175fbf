//! A model as the scene sees it: the GameObject, Transform, MeshFilter and MeshRenderer
//! (SkinnedMeshRenderer for a skinned mesh, its bones the model's own Transforms) Unity
//! creates for every node of an imported [`crate::model::Model`], and the fileIDs
//! under which the scene refers to them and to the model's meshes and materials.

use crate::docs;
use crate::graph::{game_object_body, transform_body, Graph, IdMap};
use crate::meta::IdCounter;
use crate::model::Model;
use crate::project::ModelAsset;
use crate::reference::Ref;
use crate::yaml::Node;

/// The name Unity's legacy tables and name hashes give a model's root objects.
const ROOT_NAME: &str = "//RootNode";

/// Synthesised objects hold no guid-less references, so they belong to no file.
const NO_FILE: usize = usize::MAX;

impl ModelAsset {
    /// Every fileID of each mesh of the model, in [`Model::meshes`] order.
    pub fn mesh_ids(&self) -> Vec<Vec<i64>> {
        let mut counter = IdCounter::default();
        self.model
            .meshes
            .iter()
            .map(|m| counter.ids(&self.meta, docs::MESH, &m.name, &m.name))
            .collect()
    }

    /// Every fileID of the model's material named `name` (as Unity names it).
    pub fn material_ids(&self, name: &str) -> Vec<i64> {
        self.meta.ids(docs::MATERIAL, name, "")
    }

    /// Unity's names of the materials the model's sub-meshes use, in order of use.
    pub fn material_names(&self) -> impl Iterator<Item = &str> {
        self.model
            .meshes
            .iter()
            .flat_map(|m| &m.materials)
            .map(|m| Model::material_name(m))
    }
}

impl Graph<'_> {
    /// Build the objects of one instance of a model, parents before children, each
    /// registered under every fileID its `.meta` implies; returns them by fileID and the
    /// root Transform.
    pub(crate) fn add_model(&mut self, asset: &ModelAsset, guid: &str) -> (IdMap, Vec<usize>) {
        let (model, meta) = (&asset.model, &asset.meta);
        let mesh_ids = asset.mesh_ids();
        let mut counter = IdCounter::default();
        let mut map = IdMap::new();
        let mut transforms: Vec<usize> = Vec::with_capacity(model.nodes.len());
        // (SkinnedMeshRenderer, mesh): bones are named nodes, which may come later.
        let mut skinned: Vec<(usize, usize)> = Vec::new();
        for (i, node) in model.nodes.iter().enumerate() {
            let name = if node.parent.is_some() {
                node.name.as_str()
            } else {
                ROOT_NAME
            };
            let path = model.node_path(i);
            let go = self.push(docs::GAME_OBJECT, game_object_body(&node.name), 0, NO_FILE);
            let tf = self.push(
                docs::TRANSFORM,
                transform_body(node.translation, node.rotation, node.scale),
                0,
                NO_FILE,
            );
            self.objs[tf].go = Some(go);
            self.objs[tf].father = node.parent.and_then(|p| transforms.get(p).copied());
            transforms.push(tf);
            let mut parts = vec![(docs::GAME_OBJECT, go, path.clone())];
            parts.push((docs::TRANSFORM, tf, format!("{path}/Transform")));
            if let Some(mi) = node.mesh {
                let mesh = &model.meshes[mi];
                let materials: Vec<Ref> = mesh
                    .materials
                    .iter()
                    .map(|m| Ref::asset(asset.material_ids(Model::material_name(m))[0], guid))
                    .collect();
                let enabled = Node::Map(vec![("m_Enabled".into(), Node::Scalar("1".into()))]);
                if mesh.skin.is_some() {
                    // Unity gives a skinned mesh a SkinnedMeshRenderer (which holds the
                    // mesh itself) instead of a MeshFilter and MeshRenderer.
                    let smr = self.push(docs::SKINNED_MESH_RENDERER, enabled, 0, NO_FILE);
                    self.objs[smr].mesh = Ref::asset(mesh_ids[mi][0], guid);
                    self.objs[smr].materials = materials;
                    self.objs[smr].go = Some(go);
                    skinned.push((smr, mi));
                    parts.push((
                        docs::SKINNED_MESH_RENDERER,
                        smr,
                        format!("{path}/SkinnedMeshRenderer"),
                    ));
                } else {
                    let mf = self.push(docs::MESH_FILTER, Node::Map(vec![]), 0, NO_FILE);
                    self.objs[mf].mesh = Ref::asset(mesh_ids[mi][0], guid);
                    let mr = self.push(docs::MESH_RENDERER, enabled, 0, NO_FILE);
                    self.objs[mr].materials = materials;
                    self.objs[mf].go = Some(go);
                    self.objs[mr].go = Some(go);
                    parts.push((docs::MESH_FILTER, mf, format!("{path}/MeshFilter")));
                    parts.push((docs::MESH_RENDERER, mr, format!("{path}/MeshRenderer")));
                }
            }
            for (class, idx, path) in parts {
                for id in counter.ids(meta, class, name, &path) {
                    map.entry(id).or_insert(idx);
                }
            }
        }
        for (smr, mi) in skinned {
            let Some(skin) = &model.meshes[mi].skin else {
                continue;
            };
            self.objs[smr].bones = skin
                .bones
                .iter()
                .map(|b| {
                    let node = model
                        .nodes
                        .iter()
                        .position(|n| !b.is_empty() && n.name == *b);
                    node.and_then(|n| transforms.get(n).copied())
                })
                .collect();
        }
        (map, transforms.first().copied().into_iter().collect())
    }
}
