//! FBX models (binary 6.1–7.7 and ASCII, read by the ufbx library) brought into Unity's
//! space the way Unity's model importer does it, as a format-neutral [`Model`].
//!
//! ufbx evaluates the FBX transform chain (pre/post rotation, offsets, pivots) into one
//! translation/rotation/scale per node and gives the geometric transform as a separate
//! geometry-to-node matrix. With pivots adjusted to the rotation pivot it also moves each
//! mesh so that its vertices are relative to its node's rotation pivot, the frame Unity's
//! imported Mesh is in. Everything else is done here, in this order, on file data:
//!
//! * units: positions and translations (never node scales) times the import scale,
//!   `UnitScaleFactor / 100 · globalScale` with `useFileScale: 1`, else `globalScale`;
//! * axes: the rotation that brings the file's up axis to +Y (Unity ignores the file's
//!   front and right axes: a Z-up file's (x, y, z) lands at Unity (x, z, y)), either on
//!   each node directly under the file's root (`bakeAxisConversion: 0`) or conjugated
//!   through every node and vertex (`1`);
//! * handedness: X negated (positions, normals, translations; rotations as
//!   (x, −y, −z, w)) and every triangle's winding reversed, as for OBJ.
//!
//! The root node is named after the file (Unity's `//RootNode`); when the file's root
//! has a single child, that child is the root.

use crate::fbx_pool::{thread_opts, Pool};
use crate::mesh::{smooth_normals, Mesh, EAR_CLIP_MAX};
use crate::meta::ModelMeta;
use crate::model::{Model, ModelMaterial, ModelMesh, ModelNode, Skin};
use glam::{DMat3, DMat4, DQuat, DVec3, Mat4, Vec2, Vec3};
use rayon::prelude::*;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

#[derive(Debug, thiserror::Error)]
pub enum FbxError {
    #[error("{path}: {error}")]
    Io {
        path: PathBuf,
        error: std::io::Error,
    },
    #[error("{0}: is a Git LFS pointer, not the model (run `git lfs pull` in the project)")]
    LfsPointer(PathBuf),
    #[error("{path}: not a readable FBX file: {detail}")]
    Corrupt { path: PathBuf, detail: String },
}

/// Unity welds the corners that share a source vertex and a normal (bit for bit) into
/// one vertex, numbered in the order corners first use them. Each source vertex keeps a
/// short chain of the vertices made from it, so the common case is a walk of one or two
/// entries and no hashing; a vertex with more distinct normals than a chain holds (a fan
/// of flat faces) spills into a hash map, which keeps a pathological file linear.
struct Weld {
    /// Per source vertex: the newest output vertex made from it (`NONE` if none).
    head: Vec<u32>,
    /// Per source vertex: how many outputs its chain holds.
    len: Vec<u8>,
    /// Per output vertex: the next older output of the same source vertex.
    next: Vec<u32>,
    /// Past the chain: (source vertex, normal and UV bits) → output vertex.
    overflow: HashMap<(u32, [u32; 5]), u32>,
}

const NONE: u32 = u32::MAX;
const CHAIN: u8 = 16;

impl Weld {
    fn new(vertices: usize, corners: usize) -> Weld {
        Weld {
            head: vec![NONE; vertices],
            len: vec![0; vertices],
            next: Vec::with_capacity(corners.min(vertices * 2)),
            overflow: HashMap::new(),
        }
    }

    /// The output vertex of (`v`, `normal`, `uv`); `add` appends it to `mesh` when it is
    /// new. `uv` counts only when the mesh has UVs (`add` pushes one per vertex then).
    fn vertex(
        &mut self,
        v: u32,
        normal: Vec3,
        uv: Vec2,
        add: impl FnOnce(&mut Mesh),
        mesh: &mut Mesh,
    ) -> u32 {
        let nb = normal.to_array().map(f32::to_bits);
        let ub = uv.to_array().map(f32::to_bits);
        let bits = [nb[0], nb[1], nb[2], ub[0], ub[1]];
        let vi = v as usize;
        if vi >= self.head.len() {
            // Callers clamp `v`; stay total anyway.
            return 0;
        }
        let with_uv = !mesh.uvs.is_empty();
        let mut o = self.head[vi];
        while o != NONE {
            if mesh.normals[o as usize].to_array().map(f32::to_bits) == nb
                && (!with_uv || mesh.uvs[o as usize].to_array().map(f32::to_bits) == ub)
            {
                return o;
            }
            o = self.next[o as usize];
        }
        if self.len[vi] >= CHAIN {
            if let Some(&o) = self.overflow.get(&(v, bits)) {
                return o;
            }
        }
        let o = mesh.positions.len() as u32;
        add(mesh);
        if self.len[vi] < CHAIN {
            self.next.push(self.head[vi]);
            self.head[vi] = o;
            self.len[vi] += 1;
        } else {
            self.next.push(NONE);
            self.overflow.insert((v, bits), o);
        }
        o
    }
}

/// Deepest node hierarchy accepted (real files stay far below; a corrupt one could nest
/// without end).
const NODE_DEPTH_LIMIT: u32 = 1024;

/// Load an FBX model with the import settings of its `.meta`.
pub fn load(path: &Path, meta: &ModelMeta) -> Result<Model, FbxError> {
    let bytes = std::fs::read(path).map_err(|error| FbxError::Io {
        path: path.to_path_buf(),
        error,
    })?;
    load_bytes(&bytes, path, meta)
}

/// [`load`] on the file's bytes; `path` names the model (its stem is the root's name)
/// and is quoted in errors.
pub fn load_bytes(bytes: &[u8], path: &Path, meta: &ModelMeta) -> Result<Model, FbxError> {
    if bytes.starts_with(b"version https://git-lfs.github.com/spec") {
        return Err(FbxError::LfsPointer(path.to_path_buf()));
    }
    let pool = Arc::new(Pool::default());
    let scene =
        ufbx::load_memory(bytes, load_opts(bytes.len(), &pool)).map_err(|e| FbxError::Corrupt {
            path: path.to_path_buf(),
            detail: e.description.to_string(),
        })?;
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    Ok(Importer::new(&scene, meta).model(&scene, stem))
}

fn load_opts(file_len: usize, pool: &Arc<Pool>) -> ufbx::LoadOpts<'static> {
    // Compressed binary arrays legitimately inflate a file many times over; a bound
    // proportional to the file keeps a corrupt header from asking for gigabytes.
    let limit = file_len.saturating_mul(256).clamp(64 << 20, 2 << 30);
    let alloc = || ufbx::AllocatorOpts {
        memory_limit: limit,
        ..Default::default()
    };
    ufbx::LoadOpts {
        temp_allocator: alloc(),
        result_allocator: alloc(),
        thread_opts: thread_opts(pool),
        ignore_animation: true,
        ignore_embedded: true,
        load_external_files: false,
        generate_missing_normals: false,
        node_depth_limit: NODE_DEPTH_LIMIT,
        // Unity reads a `.fbx` as FBX whatever it holds; ufbx would otherwise sniff OBJ.
        file_format: ufbx::FileFormat::Fbx,
        pivot_handling: ufbx::PivotHandling::AdjustToRotationPivot,
        geometry_transform_handling: ufbx::GeometryTransformHandling::Preserve,
        ..Default::default()
    }
}

/// The file → Unity mapping of one import.
struct Importer {
    /// Metres per file unit as Unity scales it.
    scale: f64,
    /// File axes → Unity's before the mirror (a signed permutation; identity for +Y-up
    /// files).
    axes: DQuat,
    axes_mat: DMat3,
    /// `bakeAxisConversion: 1`.
    bake: bool,
    normal_import_mode: i64,
    smoothing_angle: f32,
    warnings: Vec<String>,
}

fn v3(v: ufbx::Vec3) -> DVec3 {
    DVec3::new(v.x, v.y, v.z)
}

fn mat4(m: &ufbx::Matrix) -> DMat4 {
    DMat4::from_cols_array(&[
        m.m00, m.m10, m.m20, 0.0, m.m01, m.m11, m.m21, 0.0, m.m02, m.m12, m.m22, 0.0, m.m03, m.m13,
        m.m23, 1.0,
    ])
}

fn axis_vec(a: ufbx::CoordinateAxis) -> Option<DVec3> {
    use ufbx::CoordinateAxis as A;
    Some(match a {
        A::PositiveX => DVec3::X,
        A::NegativeX => DVec3::NEG_X,
        A::PositiveY => DVec3::Y,
        A::NegativeY => DVec3::NEG_Y,
        A::PositiveZ => DVec3::Z,
        A::NegativeZ => DVec3::NEG_Z,
        A::Unknown => return None,
    })
}

/// Unity's mirror: a vector with X negated.
fn mirror(v: DVec3) -> DVec3 {
    DVec3::new(-v.x, v.y, v.z)
}

/// The rotation `q` seen through the X mirror.
fn mirror_q(q: DQuat) -> DQuat {
    DQuat::from_xyzw(q.x, -q.y, -q.z, q.w)
}

/// Coordinates `m` produces, re-expressed in Unity's mirrored frame.
fn mirror_m(m: DMat4) -> DMat4 {
    DMat4::from_scale(DVec3::new(-1.0, 1.0, 1.0)) * m
}

impl Importer {
    fn new(scene: &ufbx::Scene, meta: &ModelMeta) -> Importer {
        let mut warnings = Vec::new();
        let file_scale = if meta.use_file_scale == Some(true) {
            scene.settings.unit_meters
        } else {
            1.0
        };
        let mut scale = file_scale * meta.global_scale as f64;
        if !(scale.is_finite() && scale > 0.0) {
            warnings.push(format!(
                "unit scale {} is not a positive number; using 1",
                scene.settings.unit_meters
            ));
            scale = meta.global_scale as f64;
        }
        // Unity goes by the file's up axis alone: it takes the right-handed system with
        // that up whose front is the FBX "odd parity" axis (Z for X or Y up, Y for Z up)
        // with a positive sign, whatever the file's FrontAxisSign and CoordAxis say. Its
        // own numbers show it: 3ds Max files (right +X, front −Y) baked into the mesh
        // (bakeAxisConversion 1) land at Unity (x, z, y), and a Blender-style Z-up file
        // (right −X, front +Y) gets the same conversion as its root rotation.
        let (mut axes, mut axes_mat) = (DQuat::IDENTITY, DMat3::IDENTITY);
        if let Some(up) = axis_vec(scene.settings.axes.up) {
            let front = if up.z != 0.0 { DVec3::Y } else { DVec3::Z };
            let right = up.cross(front);
            // Sends right, up and front to +X, +Y, +Z (right-handed Y-up, before the
            // mirror), so its rows are those three axes.
            axes_mat = DMat3::from_cols(right, up, front).transpose();
            axes = DQuat::from_mat3(&axes_mat);
        }
        if meta.normal_import_mode == 2 {
            warnings.push("normalImportMode None: normals are computed instead".into());
        }
        Importer {
            scale,
            axes,
            axes_mat,
            bake: meta.bake_axis_conversion,
            normal_import_mode: meta.normal_import_mode,
            smoothing_angle: meta.normal_smoothing_angle,
            warnings,
        }
    }

    /// A node's local transform in Unity space (before the root's axis rotation).
    fn node_trs(&self, t: &ufbx::Transform) -> (DVec3, DQuat, DVec3) {
        let (mut tr, mut q, mut s) = (
            v3(t.translation) * self.scale,
            DQuat::from_xyzw(t.rotation.x, t.rotation.y, t.rotation.z, t.rotation.w),
            v3(t.scale),
        );
        if self.bake {
            // A·T·A⁻¹ with A a signed permutation: scale components are permuted.
            tr = self.axes * tr;
            q = self.axes * q * self.axes.inverse();
            s = (self.axes_mat.abs() * s).abs();
        }
        (mirror(tr), mirror_q(q).normalize(), s)
    }

    /// Geometry space → the mesh's Unity space: the node's geometry-to-node matrix
    /// (geometric transform and pivot), units, baked axes, mirror.
    fn geometry_to_mesh(&self, node: &ufbx::Node) -> DMat4 {
        let mut m = DMat4::from_scale(DVec3::splat(self.scale)) * mat4(&node.geometry_to_node);
        if self.bake {
            m = DMat4::from_mat3(self.axes_mat) * m;
        }
        mirror_m(m)
    }

    /// A node's frame in the file → the same node's frame in Unity (units, baked axes,
    /// mirror): the change of coordinates every node goes through.
    fn node_space(&self) -> DMat4 {
        let mut m = DMat4::from_scale(DVec3::splat(self.scale));
        if self.bake {
            m = DMat4::from_mat3(self.axes_mat) * m;
        }
        mirror_m(m)
    }

    fn model(mut self, scene: &ufbx::SceneRoot, stem: String) -> Model {
        let mut model = Model::default();
        let root = &scene.root_node;
        // Without baking, the axis conversion is a rotation on each node directly under
        // the file's root (as the FBX SDK's scene conversion does it), so it is on the
        // root GameObject only when the model collapses into its single top node: Unity
        // made target.fbx's collapsed root the converted rotation, while Car.FBX (six top
        // nodes) keeps an identity root in its prefab variant.
        let top_axes = if self.bake {
            DQuat::IDENTITY
        } else {
            mirror_q(self.axes)
        };
        // (ufbx node, parent index, directly under the file's root) in depth-first order.
        let mut stack: Vec<(&ufbx::Node, Option<usize>, bool)> = Vec::new();
        // (model node index, ufbx node id) of every node with a mesh, in order.
        let mut mesh_nodes: Vec<(usize, u32)> = Vec::new();
        if root.children.len() == 1 {
            stack.push((&root.children[0], None, true));
        } else {
            model.nodes.push(ModelNode {
                name: stem.clone(),
                parent: None,
                translation: Vec3::ZERO,
                rotation: glam::Quat::IDENTITY,
                scale: Vec3::ONE,
                mesh: None,
            });
            stack.extend(root.children.iter().rev().map(|c| (&**c, Some(0), true)));
        }
        while let Some((node, parent, top)) = stack.pop() {
            let (mut t, mut q, s) = self.node_trs(&node.local_transform);
            if top {
                t = top_axes * t;
                q = top_axes * q;
            }
            let name = if parent.is_none() {
                stem.clone()
            } else {
                node.element.name.to_string()
            };
            let index = model.nodes.len();
            if node.mesh.is_some() {
                mesh_nodes.push((index, node.element.typed_id));
            }
            model.nodes.push(ModelNode {
                name,
                parent,
                translation: t.as_vec3(),
                rotation: q.as_quat(),
                scale: s.as_vec3(),
                mesh: None,
            });
            stack.extend(
                node.children
                    .iter()
                    .rev()
                    .map(|c| (&**c, Some(index), false)),
            );
        }
        // Meshes are independent: converted in parallel, numbered in depth-first order.
        let importer = &self;
        let built: Vec<(Option<ModelMesh>, Vec<String>)> = mesh_nodes
            .par_iter()
            .map(|&(_, id)| {
                let node = &scene.nodes[id as usize];
                match node.mesh.as_ref() {
                    Some(m) => importer.mesh(node, m),
                    None => (None, Vec::new()),
                }
            })
            .collect();
        for (&(index, _), (mesh, warnings)) in mesh_nodes.iter().zip(built) {
            self.warnings.extend(warnings);
            if let Some(mesh) = mesh {
                model.meshes.push(mesh);
                model.nodes[index].mesh = Some(model.meshes.len() - 1);
            }
        }
        for m in scene.materials.iter() {
            let diffuse = &m.fbx.diffuse_color;
            let c = diffuse.value_vec4;
            let texture = diffuse.texture.as_ref().map(|t| {
                if t.relative_filename.is_empty() {
                    t.filename.to_string()
                } else {
                    t.relative_filename.to_string()
                }
            });
            model.materials.push(ModelMaterial {
                name: m.element.name.to_string(),
                color: crate::material::linear_rgb(glam::Vec4::new(
                    c.x as f32, c.y as f32, c.z as f32, 1.0,
                )),
                texture: texture.filter(|t| !t.is_empty()),
            });
        }
        model.warnings = self.warnings;
        model
    }

    /// The Mesh Unity makes for `node` (`None` when it has no polygon), and what it could
    /// not honour.
    fn mesh(&self, node: &ufbx::Node, m: &ufbx::Mesh) -> (Option<ModelMesh>, Vec<String>) {
        let mut warnings = Vec::new();
        let mesh = self.mesh_into(node, m, &mut warnings);
        (mesh, warnings)
    }

    fn mesh_into(
        &self,
        node: &ufbx::Node,
        m: &ufbx::Mesh,
        warnings: &mut Vec<String>,
    ) -> Option<ModelMesh> {
        let name = node.element.name.to_string();
        let g2m = self.geometry_to_mesh(node);
        let normal_m = DMat3::from_mat4(g2m).inverse().transpose();
        let positions: Vec<Vec3> = m
            .vertices
            .iter()
            .map(|&p| g2m.transform_point3(v3(p)).as_vec3())
            .collect();
        let nv = positions.len() as u32;
        // Sub-meshes in the order of the node's material slots; a slot no polygon uses
        // makes none.
        let slot_names: Vec<String> = if node.materials.len() >= m.materials.len() {
            node.materials
                .iter()
                .map(|x| x.element.name.to_string())
                .collect()
        } else {
            m.materials
                .iter()
                .map(|x| x.element.name.to_string())
                .collect()
        };
        let mut scratch = vec![0u32; 3 * m.max_face_triangles.max(1)];
        // Triangles as ufbx index numbers (corners), per sub-mesh.
        let mut subs: Vec<Vec<[u32; 3]>> = Vec::new();
        let mut materials = Vec::new();
        for part in m.material_parts.iter() {
            let mut tris = Vec::with_capacity(part.num_triangles);
            for &fi in part.face_indices.iter() {
                let Some(&face) = m.faces.get(fi as usize) else {
                    continue;
                };
                let n = face.num_indices as usize;
                if n < 3 {
                    continue;
                }
                let b = face.index_begin;
                if n == 3 {
                    tris.push([b, b + 1, b + 2]);
                } else if n > EAR_CLIP_MAX || scratch.len() < 3 * (n - 2) {
                    tris.extend((1..n as u32 - 1).map(|i| [b, b + i, b + i + 1]));
                } else {
                    let k = ufbx::triangulate_face(&mut scratch, m, face) as usize;
                    tris.extend(scratch[..3 * k].chunks_exact(3).map(|c| [c[0], c[1], c[2]]));
                }
            }
            if tris.is_empty() {
                continue;
            }
            materials.push(
                slot_names
                    .get(part.index as usize)
                    .cloned()
                    .unwrap_or_default(),
            );
            subs.push(tris);
        }
        if subs.is_empty() {
            return None;
        }
        let vertex_of = |ix: u32| -> Option<u32> {
            m.vertex_indices
                .get(ix as usize)
                .copied()
                .filter(|&v| v < nv)
        };
        // The mirror reverses the winding; a mirroring geometric transform undoes that.
        let reverse = g2m.determinant() < 0.0;
        let file_normals = m.vertex_normal.exists && self.normal_import_mode == 0;
        let smooth = if file_normals {
            Vec::new()
        } else {
            let tris: Vec<[u32; 3]> = subs
                .iter()
                .flatten()
                .map(|t| {
                    let mut p = t.map(|c| vertex_of(c).unwrap_or(0));
                    if reverse {
                        p.swap(1, 2);
                    }
                    p
                })
                .collect();
            smooth_normals(&positions, &tris, self.smoothing_angle)
        };
        // Each normal value once in the mesh's frame (files index them per corner).
        let normal_values: Vec<Vec3> = if file_normals {
            m.vertex_normal
                .values
                .iter()
                .map(|&n| {
                    let n = (normal_m * v3(n)).normalize_or_zero().as_vec3();
                    if n.is_finite() {
                        n
                    } else {
                        Vec3::ZERO
                    }
                })
                .collect()
        } else {
            Vec::new()
        };
        let corners: usize = subs.iter().map(|t| 3 * t.len()).sum();
        // UV0 as Unity imports it: the file's values, not flipped.
        let uv_values: Vec<Vec2> = if m.vertex_uv.exists {
            m.vertex_uv
                .values
                .iter()
                .map(|t| Vec2::new(t.x as f32, t.y as f32))
                .collect()
        } else {
            Vec::new()
        };
        let has_uv = !uv_values.is_empty();
        let mut mesh = Mesh {
            positions: Vec::with_capacity(positions.len()),
            normals: Vec::with_capacity(positions.len()),
            submeshes: Vec::with_capacity(subs.len()),
            uvs: Vec::with_capacity(if has_uv { positions.len() } else { 0 }),
        };
        let mut src_vertex: Vec<u32> = Vec::with_capacity(positions.len());
        let mut weld = Weld::new(positions.len().max(1), corners);
        let mut k = 0usize;
        // Corners are replaced by output vertices in place: the sub-mesh lists become
        // the Mesh's.
        for mut tris in subs {
            for t in tris.iter_mut() {
                let mut corners = [0u32; 3];
                for (j, &ix) in t.iter().enumerate() {
                    let v = vertex_of(ix).unwrap_or(0);
                    let jj = if reverse { [0, 2, 1][j] } else { j };
                    let normal = if file_normals {
                        m.vertex_normal
                            .indices
                            .get(ix as usize)
                            .and_then(|&i| normal_values.get(i as usize))
                            .copied()
                            .unwrap_or(Vec3::ZERO)
                    } else {
                        smooth[k][jj]
                    };
                    let uv = if has_uv {
                        m.vertex_uv
                            .indices
                            .get(ix as usize)
                            .and_then(|&i| uv_values.get(i as usize))
                            .copied()
                            .unwrap_or(Vec2::ZERO)
                    } else {
                        Vec2::ZERO
                    };
                    corners[jj] = weld.vertex(
                        v,
                        normal,
                        uv,
                        |o| {
                            o.positions
                                .push(positions.get(v as usize).copied().unwrap_or_default());
                            o.normals.push(normal);
                            if has_uv {
                                o.uvs.push(uv);
                            }
                            src_vertex.push(v);
                        },
                        &mut mesh,
                    );
                }
                *t = corners;
                k += 1;
            }
            mesh.submeshes.push(tris);
        }
        if !m.blend_deformers.is_empty() {
            warnings.push(format!("mesh {name}: blend shapes ignored"));
        }
        let skin = m.skin_deformers.first().map(|sk| {
            if m.skin_deformers.len() > 1 {
                warnings.push(format!(
                    "mesh {name}: {} skin deformers; only the first is used",
                    m.skin_deformers.len()
                ));
            }
            self.skin(sk, &g2m, &src_vertex)
        });
        Some(ModelMesh {
            name,
            mesh: Arc::new(mesh),
            materials,
            skin,
        })
    }

    fn skin(&self, sk: &ufbx::SkinDeformer, g2m: &DMat4, src_vertex: &[u32]) -> Skin {
        let conj = self.node_space();
        let mesh_to_geometry = g2m.inverse();
        let mut bones = Vec::new();
        let mut bind_poses = Vec::new();
        for c in sk.clusters.iter() {
            bones.push(
                c.bone_node
                    .as_ref()
                    .map(|b| b.element.name.to_string())
                    .unwrap_or_default(),
            );
            // Unity mesh space → geometry → file bone space → Unity bone space.
            let bind = conj * mat4(&c.geometry_to_bone) * mesh_to_geometry;
            bind_poses.push(Mat4::from_cols_array(
                &bind.to_cols_array().map(|x| x as f32),
            ));
        }
        let weights = src_vertex
            .iter()
            .map(|&v| {
                let mut ws: Vec<(u32, f64)> = match sk.vertices.get(v as usize) {
                    Some(sv) => (sv.weight_begin..sv.weight_begin.saturating_add(sv.num_weights))
                        .filter_map(|i| sk.weights.get(i as usize))
                        .filter(|w| w.weight.is_finite() && w.weight > 0.0)
                        .map(|w| (w.cluster_index, w.weight))
                        .collect(),
                    None => Vec::new(),
                };
                ws.sort_by(|a, b| b.1.total_cmp(&a.1));
                ws.truncate(4);
                let sum: f64 = ws.iter().map(|w| w.1).sum();
                let mut out = [(0u32, 0.0f32); 4];
                if sum > 0.0 {
                    for (o, w) in out.iter_mut().zip(&ws) {
                        *o = (w.0, (w.1 / sum) as f32);
                    }
                } else {
                    out[0] = (0, 1.0);
                }
                out
            })
            .collect();
        Skin {
            bones,
            bind_poses,
            weights,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The welding Unity does, written the obvious way: first use of (vertex, normal
    /// bits) makes the next output vertex.
    fn weld_by_map(corners: &[(u32, Vec3)]) -> Vec<u32> {
        let mut map = HashMap::new();
        corners
            .iter()
            .map(|&(v, n)| {
                let next = map.len() as u32;
                *map.entry((v, n.to_array().map(f32::to_bits)))
                    .or_insert(next)
            })
            .collect()
    }

    #[test]
    fn weld_numbers_vertices_as_a_map_would_past_the_chain_length() {
        // Vertex 0 is a fan with 40 distinct normals (past the 16 a chain holds), each
        // used twice; vertices 1..8 have a few normals, interleaved; −0 and 0 differ.
        let mut corners = Vec::new();
        for round in 0..2 {
            for k in 0..40u32 {
                corners.push((0, Vec3::new(k as f32, 1.0, 0.0)));
                corners.push((1 + k % 8, Vec3::new(0.0, (k % 3) as f32, 1.0)));
            }
            corners.push((2, Vec3::new(if round == 0 { 0.0 } else { -0.0 }, 0.0, 1.0)));
        }
        let mut mesh = Mesh::default();
        let mut weld = Weld::new(9, corners.len());
        let got: Vec<u32> = corners
            .iter()
            .map(|&(v, n)| {
                weld.vertex(
                    v,
                    n,
                    Vec2::ZERO,
                    |o| {
                        o.positions.push(Vec3::splat(v as f32));
                        o.normals.push(n);
                    },
                    &mut mesh,
                )
            })
            .collect();
        let want = weld_by_map(&corners);
        assert_eq!(got, want);
        assert_eq!(mesh.positions.len(), 40 + 8 * 3 + 1);
        assert_eq!(mesh.normals.len(), mesh.positions.len());
    }

    #[test]
    fn weld_splits_where_uvs_differ() {
        // Vertex 0 with one normal and 20 UVs (past the chain), each twice; vertex 1 with
        // one UV. Numbering must match a map keyed by (vertex, normal, UV).
        let mut corners = Vec::new();
        for _ in 0..2 {
            for k in 0..20u32 {
                corners.push((0, Vec2::new(k as f32 * 0.5, -1.0)));
                corners.push((1, Vec2::new(0.25, 0.75)));
            }
        }
        let mut mesh = Mesh::default();
        let mut weld = Weld::new(2, corners.len());
        let got: Vec<u32> = corners
            .iter()
            .map(|&(v, uv)| {
                weld.vertex(
                    v,
                    Vec3::Z,
                    uv,
                    |o| {
                        o.positions.push(Vec3::splat(v as f32));
                        o.normals.push(Vec3::Z);
                        o.uvs.push(uv);
                    },
                    &mut mesh,
                )
            })
            .collect();
        let mut map = HashMap::new();
        let want: Vec<u32> = corners
            .iter()
            .map(|&(v, uv)| {
                let next = map.len() as u32;
                *map.entry((v, uv.to_array().map(f32::to_bits)))
                    .or_insert(next)
            })
            .collect();
        assert_eq!(got, want);
        assert_eq!(mesh.uvs.len(), 21);
        assert_eq!(mesh.uvs[want[2] as usize], Vec2::new(0.5, -1.0));
    }
}
