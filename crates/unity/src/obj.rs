//! Wavefront OBJ as Unity imports it: one mesh per `g`/`o` group name (`default` when
//! none; groups with the same name merge, groups without faces make no mesh), each
//! `usemtl` block a sub-mesh in order of first use, polygons triangulated, normals
//! computed when the file has none, X negated and winding reversed (Unity space).
//!
//! A hand-written reader rather than `tobj`: Unity's grouping (merge by name, faceless
//! groups dropped, sub-meshes per material inside a group) is what the scene's fileIDs
//! and material slots refer to, and it is simpler to follow exactly here.

use crate::material::linear_rgb;
use crate::mesh::{smooth_normals, triangulate, Mesh};
use crate::model::{Model, ModelMaterial, ModelMesh, ModelNode};
use glam::{Quat, Vec2, Vec3};
use std::collections::HashMap;
use std::path::{Path, PathBuf};

#[derive(Debug, thiserror::Error)]
pub enum ObjError {
    #[error("{path}: {error}")]
    Io {
        path: PathBuf,
        error: std::io::Error,
    },
    #[error("{0}: is a Git LFS pointer, not the model (run `git lfs pull` in the project)")]
    LfsPointer(PathBuf),
    #[error("{path}:{line}: {detail}")]
    Parse {
        path: PathBuf,
        line: usize,
        detail: String,
    },
}

#[derive(Clone, Debug)]
pub struct ObjGroup {
    pub name: String,
    /// Unity space.
    pub mesh: Mesh,
    /// The `usemtl` name of each sub-mesh (`""` when none was given).
    pub materials: Vec<String>,
}

#[derive(Clone, Debug)]
pub struct ObjModel {
    pub path: PathBuf,
    pub groups: Vec<ObjGroup>,
    /// `Kd` of each material in the `.mtl` files found.
    pub mtl_colors: HashMap<String, Vec3>,
    pub warnings: Vec<String>,
}

impl ObjModel {
    pub fn triangle_count(&self) -> usize {
        self.groups.iter().map(|g| g.mesh.triangle_count()).sum()
    }

    /// The hierarchy Unity imports: a root node named after the file, one child per
    /// group at the identity holding the group's mesh (named after the group), and the
    /// `.mtl` colours as the model's own materials (`Kd` is sRGB, like Unity's colours).
    pub fn to_model(&self) -> Model {
        let stem = self
            .path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        let node = |name: &str, parent, mesh| ModelNode {
            name: name.to_string(),
            parent,
            translation: Vec3::ZERO,
            rotation: Quat::IDENTITY,
            scale: Vec3::ONE,
            mesh,
        };
        let mut nodes = vec![node(&stem, None, None)];
        nodes.extend(
            self.groups
                .iter()
                .enumerate()
                .map(|(i, g)| node(&g.name, Some(0), Some(i))),
        );
        let meshes = self
            .groups
            .iter()
            .map(|g| ModelMesh {
                name: g.name.clone(),
                mesh: std::sync::Arc::new(g.mesh.clone()),
                materials: g.materials.clone(),
                skin: None,
            })
            .collect();
        let mut materials: Vec<ModelMaterial> = self
            .mtl_colors
            .iter()
            .map(|(name, &color)| ModelMaterial {
                name: name.clone(),
                color: linear_rgb(color.extend(1.0)),
                texture: None,
            })
            .collect();
        materials.sort_by(|a, b| a.name.cmp(&b.name));
        Model {
            nodes,
            meshes,
            materials,
            warnings: self.warnings.clone(),
        }
    }
}

/// A face corner: position index, and the file's normal and texture-coordinate indices,
/// if any.
type Corner = (u32, Option<u32>, Option<u32>);

struct GroupAcc {
    name: String,
    /// Per material (in order of first use): polygons as (position, normal) index lists.
    subs: Vec<(String, Vec<Vec<Corner>>)>,
}

/// A line or token as quoted in a message: at most 40 characters, control and
/// replacement characters shown as `?`, so binary garbage cannot flood or drive the
/// terminal.
fn shown(s: &str) -> String {
    let mut out: String = s
        .chars()
        .take(40)
        .map(|c| {
            if c.is_control() || c == char::REPLACEMENT_CHARACTER {
                '?'
            } else {
                c
            }
        })
        .collect();
    if s.chars().nth(40).is_some() {
        out.push('…');
    }
    out
}

fn resolve(idx: i64, len: usize) -> Option<u32> {
    let i = if idx < 0 { len as i64 + idx } else { idx - 1 };
    (i >= 0 && (i as usize) < len).then_some(i as u32)
}

/// Load an OBJ, reading `mtllib` files only inside the OBJ's own folder.
pub fn load(path: &Path) -> Result<ObjModel, ObjError> {
    load_in(path, path.parent().unwrap_or(Path::new(".")))
}

/// Load an OBJ whose `mtllib` files may be anywhere under `root` (the project), and
/// nowhere else: a `../../x.mtl` or absolute path that leaves it is not read.
pub fn load_in(path: &Path, root: &Path) -> Result<ObjModel, ObjError> {
    let bytes = std::fs::read(path).map_err(|error| ObjError::Io {
        path: path.to_path_buf(),
        error,
    })?;
    if bytes.starts_with(b"version https://git-lfs.github.com/spec") {
        return Err(ObjError::LfsPointer(path.to_path_buf()));
    }
    let text = String::from_utf8_lossy(&bytes);
    parse_in(&text, path, root)
}

/// Parse OBJ text read from `path` (`mtllib` files only inside its folder).
pub fn parse(text: &str, path: &Path) -> Result<ObjModel, ObjError> {
    parse_in(text, path, path.parent().unwrap_or(Path::new(".")))
}

/// Parse OBJ text read from `path`, reading `mtllib` files only under `root`.
pub fn parse_in(text: &str, path: &Path, root: &Path) -> Result<ObjModel, ObjError> {
    let mut pos: Vec<Vec3> = Vec::new();
    let mut nrm: Vec<Vec3> = Vec::new();
    let mut tex: Vec<Vec2> = Vec::new();
    let mut groups: Vec<GroupAcc> = Vec::new();
    let mut group_of: HashMap<String, usize> = HashMap::new();
    let mut current_group = "default".to_string();
    let mut current_mtl = String::new();
    let mut mtllibs: Vec<String> = Vec::new();
    // Faces of 0–2 corners (Unity skips them): how many, and the first line.
    let mut short_faces = (0usize, 0usize);
    let bad = |line: usize, detail: String| ObjError::Parse {
        path: path.to_path_buf(),
        line,
        detail,
    };
    let mut lines = text.lines().enumerate().peekable();
    while let Some((ln, raw)) = lines.next() {
        let mut line = raw.trim().to_string();
        // Backslash continues a line.
        while line.ends_with('\\') {
            line.pop();
            match lines.next() {
                Some((_, more)) => line.push_str(more.trim()),
                None => break,
            }
        }
        let line = line.split('#').next().unwrap_or("").trim();
        let mut it = line.split_whitespace();
        let Some(tag) = it.next() else { continue };
        let lno = ln + 1;
        let floats = |it: std::str::SplitWhitespace| -> Result<Vec3, ObjError> {
            let v: Vec<f32> = it
                .take(3)
                .map(|s| s.parse::<f32>())
                .collect::<Result<_, _>>()
                .map_err(|e| bad(lno, format!("bad number in `{}`: {e}", shown(line))))?;
            if v.len() < 3 {
                return Err(bad(lno, format!("expected 3 numbers in `{}`", shown(line))));
            }
            // Non-finite numbers are kept: the converter refuses the mesh with an error
            // that names the scene object using it.
            Ok(Vec3::new(v[0], v[1], v[2]))
        };
        match tag {
            "v" => pos.push(floats(it)?),
            "vn" => nrm.push(floats(it)?),
            // Texture coordinates are not validated like positions: before UVs were read,
            // a file with odd `vt` lines converted, and it still does (without them).
            "vt" => {
                let mut f = it.map(|s| s.parse::<f32>().ok());
                let u = f.next().flatten();
                let v = f.next().flatten().or(u.map(|_| 0.0));
                tex.push(match (u, v) {
                    (Some(u), Some(v)) => Vec2::new(u, v),
                    _ => Vec2::NAN,
                });
            }
            // Unity's OBJ importer names meshes by `g` only: `o` is ignored (corpus:
            // COMP396 suzanne.obj has only `o Suzanne_Suzanne.001`, and its .meta calls
            // the mesh `default`).
            "g" => {
                let name = it.collect::<Vec<_>>().join(" ");
                current_group = if name.is_empty() {
                    "default".into()
                } else {
                    name
                };
            }
            "usemtl" => current_mtl = it.collect::<Vec<_>>().join(" "),
            "mtllib" => mtllibs.push(it.collect::<Vec<_>>().join(" ")),
            "f" => {
                let mut poly = Vec::new();
                for c in it {
                    let mut parts = c.split('/');
                    let vi: i64 = parts
                        .next()
                        .and_then(|s| s.parse().ok())
                        .ok_or_else(|| bad(lno, format!("bad face corner `{}`", shown(c))))?;
                    let v = resolve(vi, pos.len())
                        .ok_or_else(|| bad(lno, format!("vertex index {vi} out of range")))?;
                    // A missing or out-of-range `vt` index leaves the corner without UV
                    // rather than failing a file Unity imports.
                    let t = parts
                        .next()
                        .and_then(|s| s.parse::<i64>().ok())
                        .and_then(|ti| resolve(ti, tex.len()))
                        .filter(|&ti| tex[ti as usize].is_finite());
                    let n = match parts.next().filter(|s| !s.is_empty()) {
                        Some(s) => {
                            let ni: i64 = s.parse().map_err(|_| {
                                bad(lno, format!("bad normal index in `{}`", shown(c)))
                            })?;
                            Some(resolve(ni, nrm.len()).ok_or_else(|| {
                                bad(lno, format!("normal index {ni} out of range"))
                            })?)
                        }
                        None => None,
                    };
                    poly.push((v, n, t));
                }
                if poly.len() < 3 {
                    if short_faces.0 == 0 {
                        short_faces.1 = lno;
                    }
                    short_faces.0 += 1;
                    continue;
                }
                let gi = *group_of.entry(current_group.clone()).or_insert_with(|| {
                    groups.push(GroupAcc {
                        name: current_group.clone(),
                        subs: Vec::new(),
                    });
                    groups.len() - 1
                });
                let g = &mut groups[gi];
                let si = match g.subs.iter().position(|(m, _)| *m == current_mtl) {
                    Some(i) => i,
                    None => {
                        g.subs.push((current_mtl.clone(), Vec::new()));
                        g.subs.len() - 1
                    }
                };
                g.subs[si].1.push(poly);
            }
            _ => {}
        }
    }

    let mut warnings = Vec::new();
    if short_faces.0 > 0 {
        warnings.push(format!(
            "{} faces with fewer than 3 corners skipped (the first on line {})",
            short_faces.0, short_faces.1
        ));
    }
    let mut mtl_colors = HashMap::new();
    let dir = path.parent().unwrap_or(Path::new("."));
    let root = root.canonicalize().ok();
    for lib in &mtllibs {
        // Resolve links and `..` before deciding: only files under the root are read.
        let p = dir.join(lib).canonicalize();
        match p {
            Ok(p) if root.as_ref().is_some_and(|r| p.starts_with(r)) => {
                match std::fs::read_to_string(&p) {
                    Ok(t) => parse_mtl(&t, &mut mtl_colors),
                    Err(e) => warnings.push(format!(
                        "material library {lib}: {e}; its materials use Unity's default"
                    )),
                }
            }
            Ok(_) => warnings.push(format!(
                "material library {lib} is outside the project; not read, its materials use Unity's default"
            )),
            Err(_) => warnings.push(format!(
                "material library {lib} not found; its materials use Unity's default"
            )),
        }
    }

    let groups = groups
        .into_iter()
        .map(|g| build_group(g, &pos, &nrm, &tex))
        .collect();
    Ok(ObjModel {
        path: path.to_path_buf(),
        groups,
        mtl_colors,
        warnings,
    })
}

/// Triangulate a group's polygons and give every corner a normal (the file's, or a
/// smoothed one split at 60° creases), then convert to Unity space.
fn build_group(g: GroupAcc, pos: &[Vec3], nrm: &[Vec3], tex: &[Vec2]) -> ObjGroup {
    // Triangles as (position index, file normal index) corners, per sub-mesh.
    let mut subs_tris: Vec<Vec<[Corner; 3]>> = Vec::new();
    let mut materials = Vec::new();
    for (mtl, polys) in g.subs {
        let mut tris = Vec::new();
        for poly in polys {
            let pts: Vec<Vec3> = poly.iter().map(|&(v, ..)| pos[v as usize]).collect();
            for t in triangulate(&pts) {
                tris.push(t.map(|k| poly[k]));
            }
        }
        materials.push(mtl);
        subs_tris.push(tris);
    }
    // Normals the file lacks are computed over the whole group, so smoothing crosses
    // sub-mesh borders like Unity's.
    let all: Vec<[u32; 3]> = subs_tris.iter().flatten().map(|t| t.map(|c| c.0)).collect();
    let needs = subs_tris.iter().flatten().flatten().any(|c| c.1.is_none());
    let smooth = if needs {
        smooth_normals(pos, &all, 60.0)
    } else {
        Vec::new()
    };
    // A group with texture coordinates on any corner has one UV per vertex (zero where a
    // corner has none, as Unity fills a missing channel entry).
    let has_uv = subs_tris.iter().flatten().flatten().any(|c| c.2.is_some());
    let mut mesh = Mesh::default();
    let mut vmap: HashMap<(u32, [u32; 3], [u32; 2]), u32> = HashMap::new();
    let mut k = 0usize;
    for tris in subs_tris {
        let mut out = Vec::with_capacity(tris.len());
        for t in tris {
            let mut tri = [0u32; 3];
            for (j, &(v, n, ti)) in t.iter().enumerate() {
                let normal = match n {
                    Some(ni) => nrm[ni as usize].normalize_or_zero(),
                    None => smooth[k][j],
                };
                let uv = ti.map_or(Vec2::ZERO, |ti| tex[ti as usize]);
                // Vertices split where their UV differs, as at a texture seam.
                let key = (
                    v,
                    normal.to_array().map(f32::to_bits),
                    uv.to_array().map(f32::to_bits),
                );
                tri[j] = *vmap.entry(key).or_insert_with(|| {
                    mesh.positions.push(pos[v as usize]);
                    mesh.normals.push(normal);
                    if has_uv {
                        mesh.uvs.push(uv);
                    }
                    (mesh.positions.len() - 1) as u32
                });
            }
            out.push(tri);
            k += 1;
        }
        mesh.submeshes.push(out);
    }
    ObjGroup {
        name: g.name,
        mesh: mesh.import_rh(),
        materials,
    }
}

fn parse_mtl(text: &str, out: &mut HashMap<String, Vec3>) {
    let mut current: Option<String> = None;
    for line in text.lines() {
        let mut it = line.split_whitespace();
        match it.next() {
            Some("newmtl") => current = Some(it.collect::<Vec<_>>().join(" ")),
            Some("Kd") => {
                let v: Vec<f32> = it.filter_map(|s| s.parse().ok()).collect();
                if let (Some(name), [r, g, b, ..]) = (&current, v.as_slice()) {
                    out.insert(name.clone(), Vec3::new(*r, *g, *b));
                }
            }
            _ => {}
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn texture_coordinates_split_vertices_at_seams() {
        // Two triangles sharing the edge 1–3; corner 3 has a different vt in each face
        // (a seam), corner 1 the same. Group B has no vt at all.
        let text =
            "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0.5 0.25\nvt 0 1\n\
                    g A\nf 1/1 2/2 3/3\nf 1/1 3/4 4/5\ng B\nf 1 2 3\ng C\nf 1/1 2/9 3/-1\n";
        let m = parse(text, Path::new("t.obj")).unwrap();
        let a = &m.groups[0].mesh;
        assert_eq!(a.positions.len(), 5);
        assert_eq!(a.uvs.len(), a.positions.len());
        // Positions are mirrored (x → −x) on import; UVs are not.
        let uv_at = |p: Vec3| -> Vec<Vec2> {
            (0..a.positions.len())
                .filter(|&i| a.positions[i] == p)
                .map(|i| a.uvs[i])
                .collect()
        };
        assert_eq!(uv_at(Vec3::ZERO), vec![Vec2::ZERO]);
        assert_eq!(uv_at(Vec3::new(-1.0, 0.0, 0.0)), vec![Vec2::X]);
        assert_eq!(
            uv_at(Vec3::new(-1.0, 1.0, 0.0)),
            vec![Vec2::ONE, Vec2::new(0.5, 0.25)]
        );
        assert!(m.groups[1].mesh.uvs.is_empty());
        // An out-of-range vt index leaves that corner at (0, 0), as before UVs were read.
        let c = &m.groups[2].mesh;
        assert_eq!(c.uvs, vec![Vec2::ZERO, Vec2::ZERO, Vec2::Y]);
    }

    #[test]
    fn groups_merge_by_name_and_faceless_groups_vanish() {
        let text = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\ng default\ng A\nusemtl red\nf 1 2 3\nusemtl blue\nf 1 3 4\ng B\nf -4 -3 -2 -1\ng A\nusemtl red\nf 1 2 4\n";
        let m = parse(text, Path::new("t.obj")).unwrap();
        let names: Vec<_> = m.groups.iter().map(|g| g.name.as_str()).collect();
        assert_eq!(names, ["A", "B"]);
        assert_eq!(m.groups[0].materials, ["red", "blue"]);
        assert_eq!(m.groups[0].mesh.submeshes[0].len(), 2);
        assert_eq!(m.groups[0].mesh.submeshes[1].len(), 1);
        assert_eq!(m.groups[1].mesh.triangle_count(), 2);
        // Unity space: x negated; the computed normals of faces that point +Z in the file
        // still point +Z (negating X keeps Z).
        assert!(m.groups[1].mesh.positions.iter().any(|p| p.x == -1.0));
        assert!(m.groups[1]
            .mesh
            .normals
            .iter()
            .all(|n| (*n - Vec3::Z).length() < 1e-6));
        assert!(m.warnings.is_empty());
    }

    #[test]
    fn imports_as_a_root_named_after_the_file_with_one_child_per_group() {
        let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\ng A\nf 1 2 3\ng B\nusemtl red\nf 1 3 2\n";
        let m = parse(text, Path::new("dir/chair.obj")).unwrap().to_model();
        let names: Vec<_> = m.nodes.iter().map(|n| n.name.as_str()).collect();
        assert_eq!(names, ["chair", "A", "B"]);
        assert_eq!(m.nodes[0].parent, None);
        assert!(m.nodes[1..]
            .iter()
            .all(|n| n.parent == Some(0) && n.translation == Vec3::ZERO));
        assert_eq!((m.nodes[1].mesh, m.nodes[2].mesh), (Some(0), Some(1)));
        assert_eq!(m.meshes[1].name, "B");
        assert_eq!(m.meshes[1].materials, ["red"]);
        assert_eq!(
            Model::material_name(&m.meshes[0].materials[0]),
            "defaultMat"
        );
        assert_eq!(m.node_path(2), "//RootNode/root/B");
    }

    #[test]
    fn short_faces_are_counted_and_mtllib_stays_inside_the_root() {
        let dir = tempfile::tempdir().unwrap();
        let root = dir.path().join("Proj");
        std::fs::create_dir_all(root.join("Assets/m")).unwrap();
        std::fs::write(dir.path().join("out.mtl"), "newmtl red\nKd 0.1 0.2 0.3\n").unwrap();
        std::fs::write(root.join("Assets/in.mtl"), "newmtl blue\nKd 0 0 1\n").unwrap();
        let text = "mtllib ../../../out.mtl\nmtllib ../in.mtl\nmtllib /etc/hostname\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\nf 3\nf 1 2 3\n";
        let m = parse_in(text, &root.join("Assets/m/a.obj"), &root).unwrap();
        assert_eq!(m.triangle_count(), 1);
        assert!(
            !m.mtl_colors.contains_key("red"),
            "read outside the project"
        );
        assert_eq!(m.mtl_colors.get("blue"), Some(&Vec3::Z));
        let outside: Vec<_> = m
            .warnings
            .iter()
            .filter(|w| w.contains("outside the project"))
            .collect();
        assert_eq!(outside.len(), 2, "{:?}", m.warnings);
        assert!(
            m.warnings.contains(
                &"2 faces with fewer than 3 corners skipped (the first on line 7)".to_string()
            ),
            "{:?}",
            m.warnings
        );
    }

    #[test]
    fn garbage_is_quoted_short_and_escaped() {
        let text = format!("v \u{1b}[2J{}\n", "\u{fffd}".repeat(100));
        let e = parse(&text, Path::new("g.obj")).unwrap_err().to_string();
        assert!(e.starts_with("g.obj:1: bad number in `v ?[2J???"), "{e}");
        assert!(e.contains("…`"), "{e}");
        assert!(e.chars().count() < 90, "{e}");
    }

    #[test]
    fn lfs_pointer_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("b.obj");
        std::fs::write(
            &p,
            "version https://git-lfs.github.com/spec/v1\noid sha256:00\nsize 3\n",
        )
        .unwrap();
        assert!(matches!(load(&p), Err(ObjError::LfsPointer(_))));
    }
}
