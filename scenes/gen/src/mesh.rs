//! Triangle meshes built from tessellated primitives, and their OBJ text.
//!
//! Every primitive states its exact triangle count in its doc comment, because the
//! baseline models must match the original Haskell ray tracer's scene to the triangle. Winding is
//! counter-clockwise seen from outside (OBJ's right-handed convention).

use glam::{Affine3A, Vec3};
use std::f32::consts::{PI, TAU};
use std::fmt::Write;

/// An indexed triangle mesh with one normal per vertex.
#[derive(Clone, Debug, Default)]
pub struct Mesh {
    pub positions: Vec<Vec3>,
    pub normals: Vec<Vec3>,
    pub triangles: Vec<[u32; 3]>,
}

impl Mesh {
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// Append `part` transformed by `xf`. Normals follow the inverse transpose, and a
    /// mirroring transform flips the winding so that faces keep pointing outwards.
    pub fn add(&mut self, part: &Mesh, xf: Affine3A) {
        let base = self.positions.len() as u32;
        let normal_xf = xf.matrix3.inverse().transpose();
        let mirror = xf.matrix3.determinant() < 0.0;
        self.positions
            .extend(part.positions.iter().map(|&p| xf.transform_point3(p)));
        self.normals.extend(
            part.normals
                .iter()
                .map(|&n| (normal_xf * n).normalize_or_zero()),
        );
        self.triangles.extend(part.triangles.iter().map(|t| {
            let [a, b, c] = t.map(|i| i + base);
            if mirror {
                [a, c, b]
            } else {
                [a, b, c]
            }
        }));
    }

    /// Smooth normals: area-weighted sum of the face normals around each vertex. A
    /// primitive that wants hard edges (box faces, cylinder caps) gives each face its own
    /// vertices, so the same rule yields flat normals there.
    pub fn with_normals(mut self) -> Self {
        let mut acc = vec![Vec3::ZERO; self.positions.len()];
        for t in &self.triangles {
            let [a, b, c] = t.map(|i| self.positions[i as usize]);
            let n = (b - a).cross(c - a);
            for &i in t {
                acc[i as usize] += n;
            }
        }
        self.normals = acc.into_iter().map(|n| n.normalize_or_zero()).collect();
        self
    }

    /// Wavefront OBJ text: a comment, one `g` group, `v`, `vn` and `f v//vn` lines.
    /// Numbers are rounded to 5 decimals so the files stay small and diff-friendly.
    pub fn to_obj(&self, group: &str, comment: &str) -> String {
        let mut s = String::with_capacity(self.positions.len() * 64 + self.triangles.len() * 32);
        for line in comment.lines() {
            let _ = writeln!(s, "# {line}");
        }
        let _ = writeln!(s, "g {group}");
        for p in &self.positions {
            let _ = writeln!(s, "v {} {} {}", num(p.x), num(p.y), num(p.z));
        }
        for n in &self.normals {
            let _ = writeln!(s, "vn {} {} {}", num(n.x), num(n.y), num(n.z));
        }
        for t in &self.triangles {
            let [a, b, c] = t.map(|i| i + 1);
            let _ = writeln!(s, "f {a}//{a} {b}//{b} {c}//{c}");
        }
        s
    }
}

/// A number with at most 5 decimals, no trailing zeros, and no `-0`.
fn num(x: f32) -> String {
    let s = format!("{x:.5}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" || s.is_empty() {
        "0".into()
    } else {
        s.into()
    }
}

/// Point on the unit sphere at polar angle `theta` (from +Y) and azimuth `phi`.
fn spherical(theta: f32, phi: f32) -> Vec3 {
    Vec3::new(
        theta.sin() * phi.cos(),
        theta.cos(),
        theta.sin() * phi.sin(),
    )
}

/// Unit UV sphere at the origin: `2·segments·(rings − 1)` triangles (triangle fans at
/// the poles, quads between). 80 × 40 gives 6,240.
pub fn uv_sphere(segments: u32, rings: u32) -> Mesh {
    assert!(segments >= 3 && rings >= 2);
    let mut m = Mesh::default();
    m.positions.push(Vec3::Y);
    for r in 1..rings {
        let theta = PI * r as f32 / rings as f32;
        for s in 0..segments {
            m.positions
                .push(spherical(theta, TAU * s as f32 / segments as f32));
        }
    }
    m.positions.push(-Vec3::Y);
    let bottom = m.positions.len() as u32 - 1;
    let ring = |r: u32, s: u32| 1 + (r - 1) * segments + s % segments;
    for s in 0..segments {
        m.triangles.push([0, ring(1, s + 1), ring(1, s)]);
    }
    for r in 1..rings - 1 {
        for s in 0..segments {
            let (a, b) = (ring(r, s), ring(r, s + 1));
            let (c, d) = (ring(r + 1, s), ring(r + 1, s + 1));
            m.triangles.push([a, b, d]);
            m.triangles.push([a, d, c]);
        }
    }
    for s in 0..segments {
        m.triangles
            .push([bottom, ring(rings - 1, s), ring(rings - 1, s + 1)]);
    }
    m.with_normals()
}

/// Disc of radius 1 in the XZ plane facing +Y, as a fan: `n` triangles. Open (one-sided),
/// which is how a model reaches an odd triangle count.
pub fn disc(n: u32) -> Mesh {
    assert!(n >= 3);
    let mut m = Mesh::default();
    m.positions.push(Vec3::ZERO);
    for i in 0..n {
        let a = TAU * i as f32 / n as f32;
        m.positions.push(Vec3::new(a.cos(), 0.0, a.sin()));
    }
    for i in 0..n {
        m.triangles.push([0, 1 + (i + 1) % n, 1 + i]);
    }
    m.with_normals()
}

/// Closed cylinder of radius 1 from y = 0 to y = 1, `stacks` rows of quads on the side
/// and a fan on each cap: `2·segments·(stacks + 1)` triangles.
pub fn cylinder(segments: u32, stacks: u32) -> Mesh {
    tapered(segments, stacks, 1.0, 1.0)
}

/// Like [`cylinder`] but with top radius `top` and bottom radius `bottom` (a frustum):
/// `2·segments·(stacks + 1)` triangles.
pub fn tapered(segments: u32, stacks: u32, bottom: f32, top: f32) -> Mesh {
    assert!(segments >= 3 && stacks >= 1);
    let mut m = Mesh::default();
    let side = |i: u32, st: u32| i % segments + st * segments;
    for st in 0..=stacks {
        let t = st as f32 / stacks as f32;
        let r = bottom + (top - bottom) * t;
        for i in 0..segments {
            let a = TAU * i as f32 / segments as f32;
            m.positions.push(Vec3::new(r * a.cos(), t, r * a.sin()));
        }
    }
    for st in 0..stacks {
        for i in 0..segments {
            let (a, b) = (side(i, st), side(i + 1, st));
            let (c, d) = (side(i, st + 1), side(i + 1, st + 1));
            m.triangles.push([a, c, d]);
            m.triangles.push([a, d, b]);
        }
    }
    let mut m = m.with_normals();
    // Caps get their own vertices so the rim stays a hard edge.
    let mut bottom_cap = disc(segments);
    flip(&mut bottom_cap);
    m.add(
        &bottom_cap,
        Affine3A::from_scale(Vec3::new(bottom, 1.0, bottom)),
    );
    let top_cap = disc(segments);
    m.add(
        &top_cap,
        Affine3A::from_scale_rotation_translation(
            Vec3::new(top, 1.0, top),
            glam::Quat::IDENTITY,
            Vec3::Y,
        ),
    );
    m
}

/// Cone of base radius 1 at y = 0 and apex at y = 1, closed by a base fan:
/// `2·segments` triangles.
pub fn cone(segments: u32) -> Mesh {
    assert!(segments >= 3);
    let mut m = Mesh::default();
    for i in 0..segments {
        let a0 = TAU * i as f32 / segments as f32;
        let a1 = TAU * (i + 1) as f32 / segments as f32;
        let base = m.positions.len() as u32;
        // One apex per face keeps the flanks from sharing a single smeared normal.
        m.positions.push(Vec3::new(a0.cos(), 0.0, a0.sin()));
        m.positions.push(Vec3::Y);
        m.positions.push(Vec3::new(a1.cos(), 0.0, a1.sin()));
        m.triangles.push([base, base + 1, base + 2]);
    }
    let mut m = m.with_normals();
    let mut base = disc(segments);
    flip(&mut base);
    m.add(&base, Affine3A::IDENTITY);
    m
}

/// Torus around the Y axis, ring radius `major`, tube radius `minor`:
/// `2·ring_segments·tube_segments` triangles.
pub fn torus(ring_segments: u32, tube_segments: u32, major: f32, minor: f32) -> Mesh {
    assert!(ring_segments >= 3 && tube_segments >= 3);
    let mut m = Mesh::default();
    for i in 0..ring_segments {
        let a = TAU * i as f32 / ring_segments as f32;
        let radial = Vec3::new(a.cos(), 0.0, a.sin());
        for j in 0..tube_segments {
            let b = TAU * j as f32 / tube_segments as f32;
            m.positions
                .push(radial * (major + minor * b.cos()) + Vec3::Y * (minor * b.sin()));
        }
    }
    let idx = |i: u32, j: u32| (i % ring_segments) * tube_segments + j % tube_segments;
    for i in 0..ring_segments {
        for j in 0..tube_segments {
            let (a, b) = (idx(i, j), idx(i + 1, j));
            let (c, d) = (idx(i, j + 1), idx(i + 1, j + 1));
            m.triangles.push([a, c, d]);
            m.triangles.push([a, d, b]);
        }
    }
    m.with_normals()
}

/// Unit cube centred at the origin, each face an `n × n` grid of quads: `12·n²`
/// triangles. Faces have their own vertices (hard edges).
pub fn box_grid(n: u32) -> Mesh {
    assert!(n >= 1);
    let mut m = Mesh::default();
    // (normal, u axis, v axis) with u × v = normal, so the grid winds outwards.
    let faces = [
        (Vec3::X, Vec3::NEG_Z, Vec3::Y),
        (Vec3::NEG_X, Vec3::Z, Vec3::Y),
        (Vec3::Y, Vec3::X, Vec3::NEG_Z),
        (Vec3::NEG_Y, Vec3::X, Vec3::Z),
        (Vec3::Z, Vec3::X, Vec3::Y),
        (Vec3::NEG_Z, Vec3::NEG_X, Vec3::Y),
    ];
    for (normal, u, v) in faces {
        let base = m.positions.len() as u32;
        for j in 0..=n {
            for i in 0..=n {
                let (s, t) = (i as f32 / n as f32 - 0.5, j as f32 / n as f32 - 0.5);
                m.positions.push(normal * 0.5 + u * s + v * t);
            }
        }
        let at = |i: u32, j: u32| base + j * (n + 1) + i;
        for j in 0..n {
            for i in 0..n {
                m.triangles.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
                m.triangles.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
            }
        }
    }
    m.with_normals()
}

/// Tube of radius `radius` along a polyline, `sides` around, open at the start and
/// closed by a fan at the end: `2·sides·(points − 1) + sides` triangles.
pub fn tube(path: &[Vec3], radius: f32, sides: u32) -> Mesh {
    assert!(path.len() >= 2 && sides >= 3);
    let mut m = Mesh::default();
    let mut prev_normal = None;
    for (k, &p) in path.iter().enumerate() {
        let dir = if k + 1 < path.len() {
            path[k + 1] - p
        } else {
            p - path[k - 1]
        }
        .normalize();
        // Parallel-transport a frame along the path so the tube does not twist.
        let n = match prev_normal {
            None => dir.any_orthonormal_vector(),
            Some(pn) => {
                let v: Vec3 = pn - dir * dir.dot(pn);
                v.normalize()
            }
        };
        prev_normal = Some(n);
        let b = dir.cross(n);
        for i in 0..sides {
            let a = TAU * i as f32 / sides as f32;
            m.positions.push(p + (n * a.cos() + b * a.sin()) * radius);
        }
    }
    let at = |k: u32, i: u32| k * sides + i % sides;
    for k in 0..path.len() as u32 - 1 {
        for i in 0..sides {
            let (a, b) = (at(k, i), at(k, i + 1));
            let (c, d) = (at(k + 1, i), at(k + 1, i + 1));
            m.triangles.push([a, b, d]);
            m.triangles.push([a, d, c]);
        }
    }
    let mut m = m.with_normals();
    // End cap fan around the last point.
    let last = path.len() as u32 - 1;
    let mut cap = Mesh::default();
    let tip = path[last as usize];
    cap.positions.push(tip);
    for i in 0..sides {
        cap.positions.push(m.positions[at(last, i) as usize]);
    }
    for i in 0..sides {
        cap.triangles.push([0, 1 + i, 1 + (i + 1) % sides]);
    }
    // Orient the cap outwards (along the path's last direction).
    let dir = tip - path[last as usize - 1];
    let [a, b, c] = cap.triangles[0].map(|i| cap.positions[i as usize]);
    if (b - a).cross(c - a).dot(dir) < 0.0 {
        flip(&mut cap);
    }
    m.add(&cap.with_normals(), Affine3A::IDENTITY);
    m
}

/// A single leaf-shaped triangle in the XY plane, pointing +Y, facing +Z: 1 triangle.
pub fn leaf() -> Mesh {
    let m = Mesh {
        positions: vec![
            Vec3::new(-0.35, 0.0, 0.0),
            Vec3::new(0.35, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        ],
        normals: Vec::new(),
        triangles: vec![[0, 1, 2]],
    };
    m.with_normals()
}

/// Reverse every triangle (and so its normal).
pub fn flip(m: &mut Mesh) {
    for t in &mut m.triangles {
        t.swap(1, 2);
    }
    for n in &mut m.normals {
        *n = -*n;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Signed volume by the divergence theorem: positive when faces wind outwards.
    fn volume(m: &Mesh) -> f32 {
        m.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| m.positions[i as usize]);
                a.dot(b.cross(c)) / 6.0
            })
            .sum()
    }

    #[test]
    fn primitive_counts_match_their_formulas() {
        assert_eq!(uv_sphere(80, 40).triangle_count(), 6240);
        assert_eq!(cylinder(16, 10).triangle_count(), 2 * 16 * 11);
        assert_eq!(cone(8).triangle_count(), 16);
        assert_eq!(torus(32, 12, 1.0, 0.3).triangle_count(), 768);
        assert_eq!(box_grid(3).triangle_count(), 108);
        assert_eq!(disc(25).triangle_count(), 25);
        let path = [Vec3::ZERO, Vec3::X, Vec3::new(2.0, 1.0, 0.0)];
        assert_eq!(tube(&path, 0.1, 6).triangle_count(), 2 * 6 * 2 + 6);
    }

    #[test]
    fn closed_primitives_wind_outwards_with_the_right_volume() {
        let v = volume(&uv_sphere(64, 32));
        assert!((v - 4.0 / 3.0 * PI).abs() < 0.02, "sphere volume {v}");
        let v = volume(&cylinder(64, 2));
        assert!((v - PI).abs() < 0.01, "cylinder volume {v}");
        let v = volume(&box_grid(4));
        assert!((v - 1.0).abs() < 1e-5, "box volume {v}");
        let v = volume(&cone(64));
        assert!((v - PI / 3.0).abs() < 0.01, "cone volume {v}");
        let v = volume(&torus(64, 32, 1.0, 0.25));
        let exact = 2.0 * PI * PI * 1.0 * 0.25 * 0.25;
        assert!(
            (v - exact).abs() < 0.01 * exact,
            "torus volume {v} vs {exact}"
        );
    }

    #[test]
    fn normals_point_away_from_the_centre() {
        let s = uv_sphere(16, 8);
        for (p, n) in s.positions.iter().zip(&s.normals) {
            assert!(p.dot(*n) > 0.95, "normal {n} at {p}");
        }
    }

    #[test]
    fn mirrored_parts_keep_outward_winding() {
        let mut m = Mesh::default();
        m.add(
            &box_grid(1),
            Affine3A::from_scale(Vec3::new(-2.0, 1.0, 1.0)),
        );
        assert!((volume(&m) - 2.0).abs() < 1e-5);
    }

    #[test]
    fn obj_numbers_are_short_and_never_negative_zero() {
        assert_eq!(num(-0.0), "0");
        assert_eq!(num(-0.000001), "0");
        assert_eq!(num(1.5), "1.5");
        assert_eq!(num(-0.25), "-0.25");
        assert_eq!(num(2.0), "2");
    }
}
