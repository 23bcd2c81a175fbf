//! From the object graph to the soup: world transforms, visibility, meshes, materials,
//! lights, camera and environment, converted to the soup's right-handed space (x → −x,
//! winding reversed; DESIGN §3).

use crate::docs;
use crate::embedded;
use crate::graph::{
    fref, is_transform, model_material_hash, model_material_name, ref_ctx, Graph, Obj,
};
use crate::material::{self, linear_rgb};
use crate::mesh::Mesh;
use crate::primitives::{self, BUILTIN_MESH_GUID};
use crate::project::ext;
use crate::yaml::Node;
use formats::{
    Ambient, AmbientMode, Camera, ClearFlags, Light, LightKind, Material, Object, Projection,
    Shadows, Soup,
};
use glam::{Mat3, Mat4, Quat, Vec3, Vec4Swizzles};
use std::collections::HashMap;
use std::sync::Arc;

const BUILTIN_EXTRA_GUID: &str = "0000000000000000f000000000000000";

#[derive(Debug, thiserror::Error)]
pub enum EmitError {
    #[error("{file}: object '{object}' (fileID {file_id}): {detail}")]
    NonFinite {
        file: String,
        object: String,
        file_id: i64,
        detail: String,
    },
}

/// Unity space → soup space for points and directions.
fn flip(v: Vec3) -> Vec3 {
    Vec3::new(-v.x, v.y, v.z)
}

struct Emitter<'g, 'p> {
    g: &'g Graph<'p>,
    soup: Soup,
    go_tf: HashMap<usize, usize>,
    go_comps: HashMap<usize, Vec<usize>>,
    world: HashMap<usize, Mat4>,
    meshes: HashMap<String, Option<Arc<Mesh>>>,
    materials: HashMap<String, u32>,
}

/// The soup, and how many enabled cameras on active objects the scene has.
pub fn emit(g: &Graph, scene_rel: &str) -> Result<(Soup, usize), EmitError> {
    let mut e = Emitter {
        g,
        soup: Soup::empty(),
        go_tf: HashMap::new(),
        go_comps: HashMap::new(),
        world: HashMap::new(),
        meshes: HashMap::new(),
        materials: HashMap::new(),
    };
    e.soup.warnings = g.warnings.clone();
    for (i, o) in g.objs.iter().enumerate() {
        let Some(go) = o.go else { continue };
        if is_transform(o.class) {
            e.go_tf.entry(go).or_insert(i);
        } else if !o.removed {
            e.go_comps.entry(go).or_default().push(i);
        }
    }
    let mut cameras: Vec<(usize, usize)> = Vec::new(); // (go, camera component)
    for (gi, o) in g.objs.iter().enumerate() {
        if o.class != docs::GAME_OBJECT || !e.active(gi) {
            continue;
        }
        let comps = e.go_comps.get(&gi).cloned().unwrap_or_default();
        let class_of = |c: u32| comps.iter().copied().find(|&i| g.objs[i].class == c);
        if let Some(mf) = class_of(docs::MESH_FILTER) {
            if let Some(mr) = class_of(docs::MESH_RENDERER) {
                if enabled(&g.objs[mr]) {
                    e.mesh_object(gi, mf, mr, scene_rel)?;
                }
            }
        }
        if let Some(smr) = class_of(docs::SKINNED_MESH_RENDERER) {
            if enabled(&g.objs[smr]) {
                let w = e.describe(gi, scene_rel);
                e.soup.warnings.push(format!("{w}: SkinnedMeshRenderer is not converted (skinned meshes need their rig); skipped"));
            }
        }
        if class_of(docs::TERRAIN).is_some() {
            let w = e.describe(gi, scene_rel);
            e.soup
                .warnings
                .push(format!("{w}: Terrain is not converted; skipped"));
        }
        for &c in comps.iter().filter(|&&i| g.objs[i].class == docs::LIGHT) {
            e.light(gi, c, scene_rel)?;
        }
        for &c in comps.iter().filter(|&&i| g.objs[i].class == docs::CAMERA) {
            if enabled(&g.objs[c]) {
                cameras.push((gi, c));
            }
        }
    }
    e.camera(&cameras, scene_rel)?;
    e.environment();
    e.soup.seal();
    Ok((e.soup, cameras.len()))
}

fn enabled(o: &Obj) -> bool {
    o.body.i64_at("m_Enabled") != Some(0)
}

impl Emitter<'_, '_> {
    fn name(&self, go: usize) -> String {
        self.g.objs[go]
            .body
            .str_at("m_Name")
            .unwrap_or("")
            .to_string()
    }

    /// Hierarchy path of a GameObject, segments joined by '/'.
    fn path(&self, go: usize) -> String {
        let mut parts = vec![self.name(go)];
        let mut tf = self.go_tf.get(&go).copied();
        let mut guard = 0;
        while let Some(t) = tf.and_then(|t| self.g.objs[t].father) {
            guard += 1;
            if guard > 256 {
                break;
            }
            if let Some(pg) = self.g.objs[t].go {
                parts.push(self.name(pg));
            }
            tf = Some(t);
        }
        parts.reverse();
        parts.join("/")
    }

    /// "scene: object 'path' (fileID n)" for messages.
    fn describe(&self, go: usize, scene_rel: &str) -> String {
        format!(
            "{scene_rel}: object '{}' (fileID {})",
            self.path(go),
            self.g.objs[go].file_id
        )
    }

    /// Active in the hierarchy: itself and every ancestor active and not removed.
    fn active(&self, go: usize) -> bool {
        let mut cur = Some(go);
        let mut guard = 0;
        while let Some(g) = cur {
            guard += 1;
            let o = &self.g.objs[g];
            if guard > 256 || o.removed || o.body.i64_at("m_IsActive") == Some(0) {
                return false;
            }
            cur = self
                .go_tf
                .get(&g)
                .and_then(|&t| self.g.objs[t].father)
                .and_then(|f| self.g.objs[f].go);
        }
        true
    }

    fn local(&self, t: usize) -> Mat4 {
        let b = &self.g.objs[t].body;
        let pos = b
            .get("m_LocalPosition")
            .and_then(Node::vec3)
            .unwrap_or(Vec3::ZERO);
        let rot = b
            .get("m_LocalRotation")
            .and_then(Node::quat)
            .unwrap_or(Quat::IDENTITY);
        let scale = b
            .get("m_LocalScale")
            .and_then(Node::vec3)
            .unwrap_or(Vec3::ONE);
        let rot = if rot.length_squared() > 0.0 {
            rot.normalize()
        } else {
            Quat::IDENTITY
        };
        Mat4::from_translation(pos) * Mat4::from_quat(rot) * Mat4::from_scale(scale)
    }

    /// Local-to-world of a Transform as a full matrix (parent·T·R·S).
    fn world(&mut self, t: usize) -> Mat4 {
        if let Some(m) = self.world.get(&t) {
            return *m;
        }
        let mut chain = vec![t];
        let mut cur = self.g.objs[t].father;
        while let Some(f) = cur {
            if self.world.contains_key(&f) || chain.contains(&f) || chain.len() > 256 {
                break;
            }
            chain.push(f);
            cur = self.g.objs[f].father;
        }
        let mut m = cur
            .and_then(|f| self.world.get(&f).copied())
            .unwrap_or(Mat4::IDENTITY);
        for &n in chain.iter().rev() {
            m *= self.local(n);
            self.world.insert(n, m);
        }
        m
    }

    fn go_world(&mut self, go: usize) -> Mat4 {
        match self.go_tf.get(&go).copied() {
            Some(t) => self.world(t),
            None => Mat4::IDENTITY,
        }
    }

    fn checked_world(&mut self, go: usize, scene_rel: &str) -> Result<Mat4, EmitError> {
        let m = self.go_world(go);
        if m.is_finite() {
            Ok(m)
        } else {
            Err(self.non_finite(
                go,
                scene_rel,
                "transform has a NaN or infinite value".into(),
            ))
        }
    }

    fn non_finite(&self, go: usize, scene_rel: &str, detail: String) -> EmitError {
        EmitError::NonFinite {
            file: scene_rel.to_string(),
            object: self.path(go),
            file_id: self.g.objs[go].file_id,
            detail,
        }
    }

    fn mesh_object(
        &mut self,
        go: usize,
        mf: usize,
        mr: usize,
        scene_rel: &str,
    ) -> Result<(), EmitError> {
        let g = self.g;
        let what = self.describe(go, scene_rel);
        let mesh_ref = g.objs[mf]
            .body
            .get("m_Mesh")
            .cloned()
            .unwrap_or(Node::Map(vec![]));
        let (mesh, source) = match self.resolve_mesh(&mesh_ref, &g.objs[mf], go) {
            Ok(x) => x,
            Err(reason) => {
                self.soup
                    .warnings
                    .push(format!("{what}: {reason}; skipped"));
                return Ok(());
            }
        };
        if mesh.positions.iter().any(|p| !p.is_finite()) {
            return Err(self.non_finite(
                go,
                scene_rel,
                format!("mesh {source} has a NaN or infinite vertex"),
            ));
        }
        let world = self.checked_world(go, scene_rel)?;
        let normal_m = Mat3::from_mat4(world).inverse().transpose();
        let flip_winding = world.determinant() < 0.0;
        let mat_refs: Vec<Node> = g.objs[mr]
            .body
            .get("m_Materials")
            .map(|n| n.as_seq().to_vec())
            .unwrap_or_default();
        let obj_index = self.soup.objects.len() as u32;
        self.soup.objects.push(Object {
            name: self.path(go),
            source,
        });
        let mut emitted = 0usize;
        for (si, tris) in mesh.submeshes.iter().enumerate() {
            if tris.is_empty() {
                continue;
            }
            let mat = match mat_refs.get(si) {
                Some(r) => self.material(r, &g.objs[mr], &what),
                None => {
                    // Unity draws nothing for a sub-mesh without a material slot.
                    self.soup.warnings.push(format!(
                        "{what}: sub-mesh {si} has no material slot, so Unity draws nothing for it; skipped"
                    ));
                    continue;
                }
            };
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
        }
        Ok(())
    }

    /// The mesh a reference names, with its source description.
    fn resolve_mesh(
        &mut self,
        r: &Node,
        holder: &Obj,
        go: usize,
    ) -> Result<(Arc<Mesh>, String), String> {
        let (id, guid) = fref(Some(r));
        if id == 0 {
            return Err("MeshFilter has no mesh".into());
        }
        let key = format!(
            "{id}:{}:{}",
            guid.as_deref().unwrap_or(""),
            ref_ctx(r, holder)
        );
        let Some(guid) = guid else {
            let ctx = ref_ctx(r, holder);
            let Some(file) = self.g.files.get(ctx) else {
                return Err(format!("local mesh fileID {id} has no file"));
            };
            let rel = self.g.project.rel(&file.path);
            let source = format!("{rel}#Mesh{id}");
            if let Some(Some(m)) = self.meshes.get(&key) {
                return Ok((m.clone(), source));
            }
            return match file.doc(id) {
                Some((docs::MESH, body)) => {
                    let m = Arc::new(
                        embedded::decode(&body)
                            .map_err(|e| format!("embedded Mesh fileID {id} in {rel}: {e}"))?,
                    );
                    self.meshes.insert(key, Some(m.clone()));
                    Ok((m, source))
                }
                _ => Err(format!("mesh fileID {id} is not a Mesh in {rel}")),
            };
        };
        if guid == BUILTIN_MESH_GUID {
            let name =
                primitives::name(id).ok_or_else(|| format!("unknown built-in mesh fileID {id}"))?;
            let m = self
                .meshes
                .entry(key)
                .or_insert_with(|| primitives::mesh(id).map(Arc::new))
                .clone()
                .ok_or("built-in mesh missing")?;
            return Ok((m, format!("builtin:{name}")));
        }
        let project = self.g.project;
        let Some(path) = project.resolve(&guid).cloned() else {
            return self.fallback_mesh(go, &format!("mesh GUID {guid} is not in the project"));
        };
        let rel = project.rel(&path);
        if ext(&path) != "obj" {
            return Err(format!(
                "mesh is in {rel}, a .{} model, which is not converted (only OBJ models are)",
                ext(&path)
            ));
        }
        let model = project.model(&path);
        let asset = model.as_ref().as_ref().map_err(|e| e.clone())?;
        let group = asset
            .obj
            .groups
            .iter()
            .position(|gr| asset.meta.ids(43, &gr.name, &gr.name).contains(&id));
        let group = match group {
            Some(gi) => gi,
            None if asset.obj.groups.len() == 1 => {
                self.soup.warnings.push(format!(
                    "{rel}: mesh fileID {id} matches no name in the model's .meta; using its only mesh '{}'",
                    asset.obj.groups[0].name
                ));
                0
            }
            None => return Err(format!("mesh fileID {id} names no mesh of {rel}")),
        };
        let gr = &asset.obj.groups[group];
        let scale = asset.meta.global_scale;
        let m = self
            .meshes
            .entry(key)
            .or_insert_with(|| Some(Arc::new(gr.mesh.clone().scaled(scale))))
            .clone()
            .ok_or("mesh missing")?;
        Ok((m, format!("{rel}#{}", gr.name)))
    }

    /// The seed's rule: `<GameObject name>.obj` anywhere under the assets folder.
    fn fallback_mesh(&mut self, go: usize, why: &str) -> Result<(Arc<Mesh>, String), String> {
        let name = format!("{}.obj", self.name(go));
        let project = self.g.project;
        let Some(path) = find_file(&project.assets, &name) else {
            return Err(format!("{why}, and no {name} is under the assets folder"));
        };
        let model = project.model(&path);
        let asset = model
            .as_ref()
            .as_ref()
            .map_err(|e| format!("{why}; fallback {name}: {e}"))?;
        let mut all = Mesh::default();
        for gr in &asset.obj.groups {
            let base = all.positions.len() as u32;
            all.positions.extend(
                gr.mesh
                    .positions
                    .iter()
                    .map(|p| *p * asset.meta.global_scale),
            );
            all.normals.extend(&gr.mesh.normals);
            for sm in &gr.mesh.submeshes {
                all.submeshes
                    .push(sm.iter().map(|t| t.map(|i| i + base)).collect());
            }
        }
        let rel = project.rel(&path);
        self.soup.warnings.push(format!(
            "object '{}': {why}; used {rel} by name (the seed's fallback)",
            self.path(go)
        ));
        Ok((Arc::new(all), rel))
    }

    fn default_material(&mut self) -> u32 {
        self.add_material("builtin:Default-Material".into(), Material::unity_default)
    }

    fn add_material(&mut self, key: String, make: impl FnOnce() -> Material) -> u32 {
        if let Some(&i) = self.materials.get(&key) {
            return i;
        }
        let i = self.soup.materials.len() as u32;
        self.soup.materials.push(make());
        self.materials.insert(key, i);
        i
    }

    /// Resolve a material reference to a soup material index (deduplicated by source).
    fn material(&mut self, r: &Node, holder: &Obj, what: &str) -> u32 {
        let (id, guid) = fref(Some(r));
        let project = self.g.project;
        let warn_default = |s: &mut Self, why: String| {
            s.soup
                .warnings
                .push(format!("{what}: {why}; Unity's default material used"));
            s.default_material()
        };
        if id == 0 {
            return warn_default(self, "material slot is empty".into());
        }
        let Some(guid) = guid else {
            let ctx = ref_ctx(r, holder);
            let key = format!("local:{ctx}:{id}");
            if let Some(&i) = self.materials.get(&key) {
                return i;
            }
            let Some(file) = self.g.files.get(ctx) else {
                return warn_default(self, format!("local material {id} not found"));
            };
            return match file.doc(id) {
                Some((docs::MATERIAL, body)) => {
                    let src = format!("{}#{id}", project.rel(&file.path));
                    let (m, _notes) = material::convert(&body, &src);
                    self.add_material(key, || m)
                }
                _ => warn_default(
                    self,
                    format!("material fileID {id} is not in {}", project.rel(&file.path)),
                ),
            };
        };
        if guid == BUILTIN_EXTRA_GUID {
            if id != 10303 {
                self.soup.warnings.push(format!(
                    "{what}: built-in material {id} approximated by Default-Material"
                ));
            }
            return self.default_material();
        }
        let Some(path) = project.resolve(&guid).cloned() else {
            return warn_default(
                self,
                format!("material GUID {guid} is not in the project (a package or deleted asset)"),
            );
        };
        let rel = project.rel(&path);
        match ext(&path).as_str() {
            "mat" => {
                let key = format!("mat:{rel}");
                if let Some(&i) = self.materials.get(&key) {
                    return i;
                }
                let text = match std::fs::read_to_string(&path) {
                    Ok(t) => t,
                    Err(e) => return warn_default(self, format!("{rel}: {e}")),
                };
                let body = docs::split(&text)
                    .into_iter()
                    .find(|d| d.class == docs::MATERIAL)
                    .map(|d| d.parse());
                match body {
                    Some(b) => {
                        let (m, notes) = material::convert(&b, &rel);
                        for n in notes {
                            self.soup.warnings.push(format!("{rel}: {n}"));
                        }
                        self.add_material(key, || m)
                    }
                    None => warn_default(self, format!("{rel} holds no Material")),
                }
            }
            "obj" => {
                let model = project.model(&path);
                let Ok(asset) = model.as_ref() else {
                    return warn_default(self, format!("{rel} could not be read"));
                };
                let name = asset
                    .obj
                    .groups
                    .iter()
                    .flat_map(|g| &g.materials)
                    .map(|m| model_material_name(m))
                    .find(|n| {
                        asset.meta.ids(21, n, "").contains(&id) || model_material_hash(n) == id
                    });
                let Some(name) = name else {
                    return warn_default(
                        self,
                        format!("material fileID {id} names no material of {rel}"),
                    );
                };
                let key = format!("objmat:{rel}:{name}");
                if let Some(&i) = self.materials.get(&key) {
                    return i;
                }
                match asset.obj.mtl_colors.get(&name) {
                    Some(kd) => {
                        let mut m = Material::unity_default();
                        m.name = name.clone();
                        m.source = format!("{rel}#{name}");
                        m.color = linear_rgb(kd.extend(1.0));
                        self.add_material(key, || m)
                    }
                    // No `usemtl`: Unity's importer gives the mesh its default material.
                    None if name == model_material_name("") => self.default_material(),
                    None => {
                        let why = format!("{rel}: material '{name}' has no Kd in a .mtl");
                        warn_default(self, why)
                    }
                }
            }
            other => warn_default(self, format!("{rel} is a .{other}, not a material")),
        }
    }

    fn light(&mut self, go: usize, c: usize, scene_rel: &str) -> Result<(), EmitError> {
        let o = &self.g.objs[c];
        if !enabled(o) {
            return Ok(());
        }
        let b = o.body.clone();
        let what = self.describe(go, scene_rel);
        let ty = b.i64_at("m_Type").unwrap_or(2);
        let angle = b.f32_at("m_SpotAngle").unwrap_or(30.0);
        let kind = match ty {
            0 => LightKind::Spot {
                angle,
                inner_angle: b.f32_at("m_InnerSpotAngle").unwrap_or(angle).min(angle),
            },
            1 => LightKind::Directional,
            2 => LightKind::Point,
            _ => {
                self.soup.warnings.push(format!(
                    "{what}: area light (m_Type {ty}) is not converted; skipped"
                ));
                return Ok(());
            }
        };
        let world = self.checked_world(go, scene_rel)?;
        let color = b
            .get("m_Color")
            .and_then(Node::color)
            .map(linear_rgb)
            .unwrap_or(Vec3::ONE);
        let mut intensity = b.f32_at("m_Intensity").unwrap_or(1.0);
        let range = b.f32_at("m_Range").unwrap_or(10.0);
        let shadows = match b
            .path(&["m_Shadows", "m_Type"])
            .and_then(Node::as_i64)
            .unwrap_or(0)
        {
            1 => Shadows::Hard,
            2 => Shadows::Soft,
            _ => Shadows::None,
        };
        let shadow_radius = if ty == 1 {
            b.f32_at("m_ShadowAngle")
                .filter(|&a| a > 0.0)
                .unwrap_or(1.0)
        } else {
            b.f32_at("m_ShadowRadius")
                .filter(|&r| r > 0.0)
                .unwrap_or(0.1)
        };
        // HDRP stores physical units (lux for the sun, lumen for lamps); the built-in
        // model of DESIGN §6 wants about 1 for a typical light.
        if self.g.project.hdrp {
            let div = if ty == 1 { 100_000.0 } else { 1_000.0 };
            let mapped = intensity / div;
            self.soup.warnings.push(format!(
                "{what}: HDRP project: intensity {intensity} (physical units) mapped to {mapped} (÷{div})"
            ));
            intensity = mapped;
        }
        let position = flip(world.w_axis.xyz());
        let direction = flip(world.transform_vector3(Vec3::Z)).normalize_or_zero();
        let all = [
            color.x,
            color.y,
            color.z,
            intensity,
            range,
            angle,
            shadow_radius,
        ];
        if all.iter().any(|v| !v.is_finite()) || direction == Vec3::ZERO {
            return Err(self.non_finite(
                go,
                scene_rel,
                "light has a NaN, infinite or degenerate value".into(),
            ));
        }
        self.soup.lights.push(Light {
            name: self.path(go),
            kind,
            position,
            direction,
            color,
            intensity,
            range,
            shadows,
            shadow_radius,
        });
        Ok(())
    }

    fn camera(&mut self, cams: &[(usize, usize)], scene_rel: &str) -> Result<(), EmitError> {
        // The Game view shows the display cameras; the highest depth draws last.
        let display: Vec<&(usize, usize)> = cams
            .iter()
            .filter(|(_, c)| fref(self.g.objs[*c].body.get("m_TargetTexture")).0 == 0)
            .collect();
        let mut best: Option<&(usize, usize)> = None;
        for c in &display {
            let d = self.g.objs[c.1].body.f32_at("m_Depth").unwrap_or(0.0);
            if best.is_none_or(|b| d > self.g.objs[b.1].body.f32_at("m_Depth").unwrap_or(0.0)) {
                best = Some(c);
            }
        }
        let Some(&(go, c)) = best else {
            self.soup.warnings.push(format!("{scene_rel}: no enabled camera renders to the display; Unity's default camera used"));
            return Ok(());
        };
        if display.len() > 1 {
            self.soup.warnings.push(format!(
                "{scene_rel}: {} enabled cameras; using '{}' (highest depth, first in the file)",
                display.len(),
                self.path(go)
            ));
        }
        let b = self.g.objs[c].body.clone();
        let world = self.checked_world(go, scene_rel)?;
        let forward = flip(world.transform_vector3(Vec3::Z)).normalize_or_zero();
        let up0 = flip(world.transform_vector3(Vec3::Y));
        let up = (up0 - forward * up0.dot(forward)).normalize_or_zero();
        if forward == Vec3::ZERO || up == Vec3::ZERO {
            return Err(self.non_finite(go, scene_rel, "camera orientation is degenerate".into()));
        }
        let projection = if b.i64_at("orthographic") == Some(1) {
            Projection::Orthographic {
                half_height: b.f32_at("orthographic size").unwrap_or(5.0),
            }
        } else {
            Projection::Perspective {
                fov_y: b.f32_at("field of view").unwrap_or(60.0),
            }
        };
        self.soup.camera = Camera {
            name: self.path(go),
            position: flip(world.w_axis.xyz()),
            forward,
            up,
            projection,
            near: b.f32_at("near clip plane").unwrap_or(0.3),
        };
        let clear = b.i64_at("m_ClearFlags").unwrap_or(1);
        self.soup.environment.clear = if clear == 1 {
            ClearFlags::Skybox
        } else {
            ClearFlags::SolidColor
        };
        if let Some(bg) = b.get("m_BackGroundColor").and_then(Node::color) {
            self.soup.environment.background = linear_rgb(bg);
        }
        Ok(())
    }

    fn environment(&mut self) {
        let Some(rs) = self.g.render_settings.as_ref() else {
            return;
        };
        let intensity = rs.f32_at("m_AmbientIntensity").unwrap_or(1.0);
        let col = |k: &str| {
            rs.get(k)
                .and_then(Node::color)
                .map(linear_rgb)
                .unwrap_or(Vec3::ZERO)
                * intensity
        };
        let mode = match rs.i64_at("m_AmbientMode").unwrap_or(0) {
            1 => AmbientMode::Trilight,
            3 => AmbientMode::Flat,
            _ => AmbientMode::Skybox,
        };
        let amb = Ambient {
            mode,
            sky: col("m_AmbientSkyColor"),
            equator: col("m_AmbientEquatorColor"),
            ground: col("m_AmbientGroundColor"),
        };
        if [amb.sky, amb.equator, amb.ground]
            .iter()
            .all(|c| c.is_finite())
        {
            self.soup.environment.ambient = amb;
        }
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

fn find_file(dir: &std::path::Path, name: &str) -> Option<std::path::PathBuf> {
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        let mut entries: Vec<_> = std::fs::read_dir(&d)
            .ok()?
            .filter_map(Result::ok)
            .map(|e| e.path())
            .collect();
        entries.sort();
        for p in entries {
            if p.is_dir() {
                stack.push(p);
            } else if p
                .file_name()
                .is_some_and(|f| f.to_string_lossy().eq_ignore_ascii_case(name))
            {
                return Some(p);
            }
        }
    }
    None
}
