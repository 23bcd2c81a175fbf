//! Meshes in Unity space (left-handed, clockwise front faces), polygon triangulation and
//! normal generation.
//!
//! Everything that enters as right-handed data (OBJ files, and the primitives, which are
//! written here the way an OBJ would describe them) goes through [`Mesh::import_rh`],
//! which does what Unity's importer does: negate X and reverse each triangle's winding.

use glam::{Vec2, Vec3};
use std::collections::HashMap;

#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    pub positions: Vec<Vec3>,
    /// Unit normals, one per position.
    pub normals: Vec<Vec3>,
    /// Triangles of each sub-mesh (indices into `positions`).
    pub submeshes: Vec<Vec<[u32; 3]>>,
    /// First UV channel, one per position, (0, 0) at the texture's bottom-left; empty when
    /// the mesh has none. Unity space and file space agree on UVs: importing mirrors
    /// positions, never texture coordinates.
    pub uvs: Vec<Vec2>,
}

impl Mesh {
    pub fn triangle_count(&self) -> usize {
        self.submeshes.iter().map(Vec::len).sum()
    }

    /// Convert right-handed, counter-clockwise data into Unity space the way Unity's
    /// model importer does: x → −x for positions and normals, and reversed winding.
    pub fn import_rh(mut self) -> Mesh {
        for p in &mut self.positions {
            p.x = -p.x;
        }
        for n in &mut self.normals {
            n.x = -n.x;
        }
        for sm in &mut self.submeshes {
            for t in sm.iter_mut() {
                t.swap(1, 2);
            }
        }
        self
    }

    /// Scale positions uniformly (ModelImporter `globalScale`).
    pub fn scaled(mut self, s: f32) -> Mesh {
        for p in &mut self.positions {
            *p *= s;
        }
        self
    }
}

/// Newell's normal of a polygon (not normalised; zero for degenerate polygons).
fn newell(poly: &[Vec3]) -> Vec3 {
    let mut n = Vec3::ZERO;
    for i in 0..poly.len() {
        let a = poly[i];
        let b = poly[(i + 1) % poly.len()];
        n.x += (a.y - b.y) * (a.z + b.z);
        n.y += (a.z - b.z) * (a.x + b.x);
        n.z += (a.x - b.x) * (a.y + b.y);
    }
    n
}

/// Largest polygon that is ear-clipped. Ear clipping costs up to n³ steps, so a file
/// with one 20 000-corner face would hang the converter; larger non-convex polygons are
/// fanned like convex ones (they are not real modelling data).
pub const EAR_CLIP_MAX: usize = 512;

/// Triangulate a polygon given by its corner positions, returning corner-index triples
/// with the polygon's own orientation. Convex polygons are fanned from the first corner
/// (as Unity's importer does for quads); non-convex ones up to [`EAR_CLIP_MAX`] corners
/// are ear-clipped in the polygon's best-fit plane.
pub fn triangulate(poly: &[Vec3]) -> Vec<[usize; 3]> {
    let n = poly.len();
    if n < 3 {
        return vec![];
    }
    if n == 3 {
        return vec![[0, 1, 2]];
    }
    let normal = newell(poly);
    if normal.length_squared() == 0.0 || !normal.is_finite() || n > EAR_CLIP_MAX {
        return (1..n - 1).map(|i| [0, i, i + 1]).collect();
    }
    // Project onto the plane: a 2D frame (u, v) with u × v along the normal, so the
    // polygon is counter-clockwise in 2D.
    let nn = normal.normalize();
    let u = nn.any_orthonormal_vector();
    let v = nn.cross(u);
    let pts: Vec<Vec2> = poly.iter().map(|p| Vec2::new(p.dot(u), p.dot(v))).collect();
    let cross = |a: Vec2, b: Vec2, c: Vec2| (b - a).perp_dot(c - a);
    let convex = (0..n).all(|i| cross(pts[i], pts[(i + 1) % n], pts[(i + 2) % n]) >= 0.0);
    if convex {
        return (1..n - 1).map(|i| [0, i, i + 1]).collect();
    }
    let mut idx: Vec<usize> = (0..n).collect();
    let mut out = Vec::with_capacity(n - 2);
    let mut guard = 0;
    while idx.len() > 3 && guard < n * n {
        guard += 1;
        let m = idx.len();
        let mut clipped = false;
        for k in 0..m {
            let (ia, ib, ic) = (idx[(k + m - 1) % m], idx[k], idx[(k + 1) % m]);
            let (a, b, c) = (pts[ia], pts[ib], pts[ic]);
            if cross(a, b, c) <= 0.0 {
                continue; // reflex or flat corner: not an ear
            }
            let inside = idx.iter().any(|&j| {
                if j == ia || j == ib || j == ic {
                    return false;
                }
                let p = pts[j];
                cross(a, b, p) >= 0.0 && cross(b, c, p) >= 0.0 && cross(c, a, p) >= 0.0
            });
            if inside {
                continue;
            }
            out.push([ia, ib, ic]);
            idx.remove(k);
            clipped = true;
            break;
        }
        if !clipped {
            break; // self-intersecting polygon: fan what is left
        }
    }
    for i in 1..idx.len().saturating_sub(1) {
        out.push([idx[0], idx[i], idx[i + 1]]);
    }
    out
}

/// Per-corner normals for triangles that have none: angle-weighted averages of the face
/// normals around each position, leaving out faces more than `crease_deg` away (Unity's
/// default smoothing angle is 60°), so hard edges stay hard.
///
/// Returns, for each triangle, the three corner normals.
pub fn smooth_normals(positions: &[Vec3], tris: &[[u32; 3]], crease_deg: f32) -> Vec<[Vec3; 3]> {
    let face_n: Vec<Vec3> = tris
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| positions[i as usize]);
            (b - a).cross(c - a).normalize_or_zero()
        })
        .collect();
    let corner_angle = |t: &[u32; 3], k: usize| -> f32 {
        let p = positions[t[k] as usize];
        let e1 = positions[t[(k + 1) % 3] as usize] - p;
        let e2 = positions[t[(k + 2) % 3] as usize] - p;
        e1.angle_between(e2)
    };
    // Faces around a position are grouped by their exact normal: every corner whose
    // face has the same normal gets the same smoothed normal, so the crease comparison
    // runs once per pair of distinct normals, not per pair of faces (a 20 000-triangle
    // fan around one vertex is one group, not 4·10⁸ comparisons).
    let key = |n: Vec3| n.to_array().map(f32::to_bits);
    let mut groups: Vec<Vec<(Vec3, Vec3)>> = vec![Vec::new(); positions.len()]; // (normal, Σ n·w)
    let mut group_ix: Vec<HashMap<[u32; 3], u32>> = vec![HashMap::new(); positions.len()];
    let mut corner_group = vec![0u32; tris.len() * 3];
    for (ti, t) in tris.iter().enumerate() {
        let nf = face_n[ti];
        for (k, &v) in t.iter().enumerate() {
            let v = v as usize;
            let gi = *group_ix[v].entry(key(nf)).or_insert_with(|| {
                groups[v].push((nf, Vec3::ZERO));
                (groups[v].len() - 1) as u32
            });
            let w = corner_angle(t, k);
            if w.is_finite() {
                groups[v][gi as usize].1 += nf * w;
            }
            corner_group[ti * 3 + k] = gi;
        }
    }
    let cos_crease = crease_deg.to_radians().cos();
    // Smoothed normal per (position, group). Past this many distinct normals at one
    // position (never in modelling data) the crease is ignored to stay linear.
    const MAX_CREASE_GROUPS: usize = 1024;
    let smoothed: Vec<Vec<Vec3>> = groups
        .iter()
        .map(|gs| {
            let all: Vec3 = gs.iter().map(|g| g.1).sum();
            gs.iter()
                .map(|&(nf, _)| {
                    let sum = if gs.len() > MAX_CREASE_GROUPS {
                        all
                    } else {
                        gs.iter()
                            .filter(|g| g.0.dot(nf) >= cos_crease)
                            .map(|g| g.1)
                            .sum()
                    };
                    let s = sum.normalize_or_zero();
                    if s != Vec3::ZERO {
                        s
                    } else {
                        nf
                    }
                })
                .collect()
        })
        .collect();
    tris.iter()
        .enumerate()
        .map(|(ti, t)| {
            std::array::from_fn(|k| smoothed[t[k] as usize][corner_group[ti * 3 + k] as usize])
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn convex_quad_is_fanned() {
        let q = [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        ];
        assert_eq!(triangulate(&q), vec![[0, 1, 2], [0, 2, 3]]);
    }

    #[test]
    fn non_convex_polygon_covers_its_area_with_its_orientation() {
        // An L shape (area 3), counter-clockwise seen from +Z; a fan from corner 0 would
        // cover area outside it.
        let l = [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(2.0, 1.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(1.0, 2.0, 0.0),
            Vec3::new(0.0, 2.0, 0.0),
        ];
        // Rotate the start so that corner 0 is the reflex one.
        let rot: Vec<Vec3> = (0..6).map(|i| l[(i + 3) % 6]).collect();
        let tris = triangulate(&rot);
        assert_eq!(tris.len(), 4);
        let mut area = 0.0;
        for t in &tris {
            let [a, b, c] = t.map(|i| rot[i]);
            let n = (b - a).cross(c - a);
            assert!(n.z > 0.0, "triangle {t:?} flipped");
            area += n.z / 2.0;
        }
        assert!((area - 3.0).abs() < 1e-6, "area {area}");
    }

    #[test]
    fn creases_split_normals() {
        // Two faces of a cube meeting at 90°: their shared corners keep the face normals.
        let p = vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 1.0),
            Vec3::new(0.0, 1.0, 0.0),
        ];
        let tris = [[0, 2, 1], [0, 1, 3]];
        let n = smooth_normals(&p, &tris, 60.0);
        assert!((n[0][0] - Vec3::new(0.0, 1.0, 0.0)).length() < 1e-6);
        assert!((n[1][0] - Vec3::new(0.0, 0.0, 1.0)).length() < 1e-6);
        // With a 180° smoothing angle they average.
        let s = smooth_normals(&p, &tris, 180.0);
        assert!(s[0][0].y > 0.1 && s[0][0].z > 0.1);
    }

    #[test]
    fn huge_fans_and_polygons_stay_bounded() {
        // A 20 000-corner star (non-convex): fanned, not ear-clipped (n³).
        let n = 20_000;
        let star: Vec<Vec3> = (0..n)
            .map(|i| {
                let a = i as f32 / n as f32 * std::f32::consts::TAU;
                let r = if i % 2 == 0 { 1.0 } else { 0.5 };
                Vec3::new(r * a.cos(), r * a.sin(), 0.0)
            })
            .collect();
        let tris = triangulate(&star);
        assert_eq!(tris.len(), n - 2);
        assert_eq!(tris[5], [0, 6, 7]);
        // All of them share corner 0: one normal group there, so smoothing is linear;
        // every corner of this flat fan gets the fan's normal (+Z for CCW corners).
        let t32: Vec<[u32; 3]> = tris.iter().map(|t| t.map(|i| i as u32)).collect();
        let sn = smooth_normals(&star, &t32, 60.0);
        assert_eq!(sn.len(), n - 2);
        let flat = sn.iter().flatten().filter(|v| v.z.abs() > 0.999).count();
        assert_eq!(flat, 3 * (n - 2));
        // A cone of 3 000 distinct face normals around its apex: past the group cap the
        // apex normal is the plain weighted average (straight up), still unit length.
        let m = 3_000;
        let mut pts = vec![Vec3::new(0.0, 1.0, 0.0)];
        pts.extend((0..m).map(|i| {
            let a = i as f32 / m as f32 * std::f32::consts::TAU;
            Vec3::new(a.cos(), 0.0, -a.sin())
        }));
        let cone: Vec<[u32; 3]> = (0..m as u32)
            .map(|i| [0, 1 + i, 1 + (i + 1) % m as u32])
            .collect();
        let cn = smooth_normals(&pts, &cone, 60.0);
        assert!(
            cn.iter().all(|t| (t[0] - Vec3::Y).length() < 1e-3),
            "{:?}",
            cn[0][0]
        );
    }
}
