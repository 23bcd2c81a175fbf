//! The triangle sets the benchmark runs on: a soup file, OBJ meshes, and a generated
//! scene of any size (terrain plus a grid of tessellated spheres).

use crate::error::BenchError;
use crate::rays::View;
use glam::Vec3;
use std::path::{Path, PathBuf};

pub struct Scene {
    /// Short name for the tables (file stem, or `generated-5.1M`).
    pub name: String,
    pub triangles: Vec<[Vec3; 3]>,
    /// The scene's own camera when it has one (a soup's); otherwise the benchmark frames
    /// the bounds.
    pub view: Option<View>,
    /// Anything worth a line under the tables (skipped triangles, camera used).
    pub notes: Vec<String>,
}

/// Bounds of all vertices: [min, max].
pub fn bounds(triangles: &[[Vec3; 3]]) -> [Vec3; 2] {
    let mut lo = Vec3::splat(f32::INFINITY);
    let mut hi = Vec3::splat(f32::NEG_INFINITY);
    for t in triangles {
        for v in t {
            lo = lo.min(*v);
            hi = hi.max(*v);
        }
    }
    [lo, hi]
}

fn stem(path: &Path) -> String {
    path.file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| path.display().to_string())
}

/// A soup written by `unity2soup`, with its camera when it is a perspective one.
pub fn load_soup(path: &Path) -> Result<Scene, BenchError> {
    let soup = formats::Soup::read(path)?;
    if soup.triangles.is_empty() {
        return Err(BenchError::Empty {
            path: path.to_path_buf(),
        });
    }
    let mut notes = vec![];
    // A physical camera's rays are framed by its field of view (its sensor height's).
    let view = match soup.camera.projection.fov_y() {
        Some(fov_y) => {
            notes.push(format!(
                "{}: primary rays from the soup's camera `{}`",
                stem(path),
                soup.camera.name
            ));
            Some(View {
                eye: soup.camera.position,
                forward: soup.camera.forward,
                up: soup.camera.up,
                fov_y,
            })
        }
        None => None,
    };
    Ok(Scene {
        name: stem(path),
        triangles: soup.triangle_positions(),
        view,
        notes,
    })
}

/// An OBJ file, triangulated (tobj fans polygons), every object and group merged.
/// Triangles with non-finite vertices are skipped and counted in the notes.
///
/// The one mesh reader of the tests and benchmarks. It is not the product's reader
/// (`unity::obj`) because that one imports the way Unity does, X negated and winding
/// reversed: the benchmark meshes would no longer be the files' own coordinates, and
/// their trees, timings and digests would stop matching earlier runs.
pub fn load_obj(path: &Path) -> Result<Scene, BenchError> {
    // tobj's optional features add fields to LoadOptions: keep the update syntax.
    #[allow(clippy::needless_update)]
    let opts = tobj::LoadOptions {
        triangulate: true,
        single_index: false,
        ignore_points: true,
        ignore_lines: true,
        ..Default::default()
    };
    let (models, _materials) = tobj::load_obj(path, &opts).map_err(|source| BenchError::Obj {
        path: path.to_path_buf(),
        source,
    })?;
    let mut triangles = vec![];
    let mut bad = 0usize;
    for m in &models {
        let p = &m.mesh.positions;
        let vertex = |i: u32| -> Option<Vec3> {
            let i = i as usize * 3;
            p.get(i..i + 3).map(|c| Vec3::new(c[0], c[1], c[2]))
        };
        for f in m.mesh.indices.chunks_exact(3) {
            match (vertex(f[0]), vertex(f[1]), vertex(f[2])) {
                (Some(a), Some(b), Some(c)) if a.is_finite() && b.is_finite() && c.is_finite() => {
                    triangles.push([a, b, c])
                }
                _ => bad += 1,
            }
        }
    }
    if triangles.is_empty() {
        return Err(BenchError::Empty {
            path: path.to_path_buf(),
        });
    }
    let mut notes = vec![];
    if bad > 0 {
        notes.push(format!(
            "{}: skipped {bad} faces with a bad index or non-finite vertex",
            stem(path)
        ));
    }
    Ok(Scene {
        name: stem(path),
        triangles,
        view: None,
        notes,
    })
}

/// Every `*.obj` in `dir`, sorted by name.
pub fn obj_files(dir: &Path) -> Result<Vec<PathBuf>, BenchError> {
    let io = |source| BenchError::Io {
        path: dir.to_path_buf(),
        source,
    };
    let mut out = vec![];
    for entry in std::fs::read_dir(dir).map_err(io)? {
        let path = entry.map_err(io)?.path();
        if path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("obj"))
        {
            out.push(path);
        }
    }
    out.sort();
    Ok(out)
}

/// Rolling terrain height at (x, z).
fn terrain_height(x: f32, z: f32) -> f32 {
    2.0 * (0.3 * x).sin() * (0.2 * z).cos() + 0.5 * (1.7 * x + 0.9 * z).sin()
}

/// A generated scene of about `target` triangles: a 100 m × 100 m heightfield (40% of
/// the budget) and an 8 × 8 grid of UV spheres of radius 4 sitting half-sunk in it (the
/// rest). Dense, overlapping, with large empty regions above: a fair test of both
/// builders. Small targets get a 2 × 2 grid.
pub fn generated(target: usize) -> Scene {
    let target = target.max(200);
    let mut triangles = Vec::with_capacity(target + target / 20);
    // Terrain: g × g quads, two triangles each.
    let g = (((target as f64 * 0.4) / 2.0).sqrt().round() as usize).max(2);
    let size = 100.0f32;
    let step = size / g as f32;
    let at = |i: usize, j: usize| {
        let x = -size / 2.0 + i as f32 * step;
        let z = -size / 2.0 + j as f32 * step;
        Vec3::new(x, terrain_height(x, z), z)
    };
    for j in 0..g {
        for i in 0..g {
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            triangles.push([a, c, b]);
            triangles.push([a, d, c]);
        }
    }
    // Spheres: k × k, each with `stacks` rings and 2·stacks slices ≈ 4·stacks² triangles.
    let k = if target >= 100_000 { 8 } else { 2 };
    let budget = (target.saturating_sub(triangles.len()) / (k * k)).max(16);
    let stacks = (((budget as f64) / 4.0).sqrt().round() as usize).max(3);
    let slices = 2 * stacks;
    let radius = 4.0f32;
    for sj in 0..k {
        for si in 0..k {
            let cx = -size / 2.0 + (si as f32 + 0.5) * size / k as f32;
            let cz = -size / 2.0 + (sj as f32 + 0.5) * size / k as f32;
            let centre = Vec3::new(cx, terrain_height(cx, cz) + 0.5 * radius, cz);
            sphere(&mut triangles, centre, radius, stacks, slices);
        }
    }
    let n = triangles.len();
    Scene {
        name: format!("generated-{}", short_count(n)),
        triangles,
        view: None,
        notes: vec![format!(
            "generated-{}: {g}×{g} terrain quads and {k}×{k} spheres of {stacks}×{slices}",
            short_count(n)
        )],
    }
}

/// Append a UV sphere (pole rows as single triangles, so no degenerate ones).
fn sphere(out: &mut Vec<[Vec3; 3]>, c: Vec3, r: f32, stacks: usize, slices: usize) {
    let p = |i: usize, j: usize| {
        let theta = std::f32::consts::PI * i as f32 / stacks as f32;
        let phi = std::f32::consts::TAU * (j % slices) as f32 / slices as f32;
        c + r * Vec3::new(
            theta.sin() * phi.cos(),
            theta.cos(),
            theta.sin() * phi.sin(),
        )
    };
    for i in 0..stacks {
        for j in 0..slices {
            let (a, b, cc, d) = (p(i, j), p(i, j + 1), p(i + 1, j + 1), p(i + 1, j));
            if i != 0 {
                out.push([a, b, cc]);
            }
            if i != stacks - 1 {
                out.push([a, cc, d]);
            }
        }
    }
}

/// 5_123_456 → "5.1M", 12_000 → "12k".
pub fn short_count(n: usize) -> String {
    if n >= 1_000_000 {
        format!("{:.1}M", n as f64 / 1e6)
    } else if n >= 1000 {
        format!("{}k", n / 1000)
    } else {
        n.to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn generated_scene_has_about_the_asked_size_and_no_degenerate_triangles() {
        let s = generated(50_000);
        let n = s.triangles.len();
        assert!((45_000..=55_000).contains(&n), "{n} triangles");
        let degenerate = s
            .triangles
            .iter()
            .filter(|t| (t[1] - t[0]).cross(t[2] - t[0]).length() < 1e-9)
            .count();
        assert_eq!(degenerate, 0);
        let [lo, hi] = bounds(&s.triangles);
        assert_eq!((lo.x, hi.x), (-50.0, 50.0));
    }

    #[test]
    fn sphere_has_the_expected_triangle_count() {
        let mut v = vec![];
        sphere(&mut v, Vec3::ZERO, 1.0, 4, 8);
        // 8 slices × (2·4 − 2) triangles.
        assert_eq!(v.len(), 48);
    }
}
