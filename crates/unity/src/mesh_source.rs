//! Where a MeshFilter's `m_Mesh` comes from: a Mesh embedded in the scene or prefab
//! (class 43), one of Unity's built-in primitives, a mesh of an imported model, or, when
//! the GUID is not in the project, a model file named after the GameObject.

use crate::docs;
use crate::embedded;
use crate::emit::Emitter;
use crate::mesh::Mesh;
use crate::model::Skin;
use crate::primitives::{self, BUILTIN_MESH_GUID};
use crate::project::{ModelAsset, ModelError};
use crate::reference::Ref;
use std::sync::Arc;

/// A mesh and the soup's description of where it came from.
type Resolved = Result<(Arc<Mesh>, String), String>;

impl Emitter<'_, '_> {
    /// The mesh a MeshFilter of GameObject `go` names, or why there is none.
    pub(crate) fn resolve_mesh(&mut self, r: &Ref, go: usize) -> Resolved {
        let id = r.file_id;
        if id == 0 {
            return Err("MeshFilter has no mesh".into());
        }
        let Some(guid) = r.guid.as_deref() else {
            return self.embedded_mesh(id, r.file);
        };
        let key = format!("{id}:{guid}:{}", r.file);
        match guid {
            BUILTIN_MESH_GUID => {
                let name = primitives::name(id)
                    .ok_or_else(|| format!("unknown built-in mesh fileID {id}"))?;
                let m = self
                    .meshes
                    .entry(key)
                    .or_insert_with(|| primitives::mesh(id).map(Arc::new))
                    .clone()
                    .ok_or("built-in mesh missing")?;
                Ok((m, format!("builtin:{name}")))
            }
            _ => self.model_mesh(id, guid, go, key),
        }
    }

    /// A Mesh document of file `file` (guid-less reference), decoded once for every
    /// instance of the prefab that holds it.
    fn embedded_mesh(&mut self, id: i64, file: usize) -> Resolved {
        let Some(f) = self.g.files.get(file) else {
            return Err(format!("local mesh fileID {id} has no file"));
        };
        let key = format!("local:{}:{id}", f.path.display());
        let rel = self.g.project.rel(&f.path);
        let source = format!("{rel}#Mesh{id}");
        if let Some(Some(m)) = self.meshes.get(&key) {
            return Ok((m.clone(), source));
        }
        match f.doc(id) {
            Some((docs::MESH, body)) => {
                let m = Arc::new(
                    embedded::decode(&body)
                        .map_err(|e| format!("embedded Mesh fileID {id} in {rel}: {e}"))?,
                );
                self.meshes.insert(key, Some(m.clone()));
                Ok((m, source))
            }
            _ => Err(format!("mesh fileID {id} is not a Mesh in {rel}")),
        }
    }

    /// The mesh of the model asset `guid` whose fileID is `id`.
    fn model_mesh(&mut self, id: i64, guid: &str, go: usize, key: String) -> Resolved {
        let project = self.g.project;
        let Some(path) = project.resolve(guid).cloned() else {
            return self.mesh_by_name(go, &format!("mesh GUID {guid} is not in the project"));
        };
        let rel = project.rel(&path);
        let loaded = project.model(&path);
        let asset = match loaded.as_ref() {
            Ok(a) => a,
            Err(e @ (ModelError::Unsupported(_) | ModelError::Authoring(..))) => {
                return Err(format!("mesh is in {rel}, {e}"))
            }
            Err(e) => return Err(e.to_string()),
        };
        let meshes = &asset.model.meshes;
        let index = match mesh_index(asset, id) {
            Some(i) => i,
            None if meshes.len() == 1 => {
                self.soup.warnings.push(format!(
                    "{rel}: mesh fileID {id} matches no name in the model's .meta; using its only mesh '{}'",
                    meshes[0].name
                ));
                0
            }
            None => return Err(format!("mesh fileID {id} names no mesh of {rel}")),
        };
        let mesh = &meshes[index];
        let m = self
            .meshes
            .entry(key)
            .or_insert_with(|| Some(mesh.mesh.clone()))
            .clone()
            .ok_or("mesh missing")?;
        Ok((m, format!("{rel}#{}", mesh.name)))
    }

    /// The skin of the model mesh `r` names, if it has one.
    pub(crate) fn model_skin(&self, r: &Ref) -> Option<Skin> {
        let path = self.g.project.resolve(r.guid.as_deref()?)?;
        let loaded = self.g.project.model(path);
        let asset = loaded.as_ref().as_ref().ok()?;
        let meshes = &asset.model.meshes;
        let index = mesh_index(asset, r.file_id).or((meshes.len() == 1).then_some(0))?;
        meshes[index].skin.clone()
    }

    /// `<GameObject name>.obj` anywhere under the assets folder, all its meshes as one: a
    /// project copied without its `.meta` files has lost every model GUID, and the
    /// object's name is then the only link left to its mesh.
    fn mesh_by_name(&mut self, go: usize, why: &str) -> Resolved {
        let name = format!("{}.obj", self.name(go));
        let project = self.g.project;
        let Some(path) = project.find_by_name(&name).cloned() else {
            return Err(format!("{why}, and no {name} is under the assets folder"));
        };
        let loaded = project.model(&path);
        let asset = loaded
            .as_ref()
            .as_ref()
            .map_err(|e| format!("{why}; fallback {name}: {e}"))?;
        let mut all = Mesh::default();
        // UVs survive the merge only if every part has them (one per position or none).
        let uvs = asset.model.meshes.iter().all(|m| !m.mesh.uvs.is_empty());
        for m in &asset.model.meshes {
            let base = all.positions.len() as u32;
            all.positions.extend(&m.mesh.positions);
            all.normals.extend(&m.mesh.normals);
            if uvs {
                all.uvs.extend(&m.mesh.uvs);
            }
            for sm in &m.mesh.submeshes {
                all.submeshes
                    .push(sm.iter().map(|t| t.map(|i| i + base)).collect());
            }
        }
        let rel = project.rel(&path);
        self.soup.warnings.push(format!(
            "object '{}': {why}; used {rel}, found by the object's name",
            self.path(go)
        ));
        Ok((Arc::new(all), rel))
    }
}

/// The index of the model's mesh whose fileID is `id`.
fn mesh_index(asset: &ModelAsset, id: i64) -> Option<usize> {
    asset.mesh_ids().iter().position(|ids| ids.contains(&id))
}
