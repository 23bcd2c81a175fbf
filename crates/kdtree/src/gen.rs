//! Scene generators for tests and benchmarks: closed meshes whose neighbouring triangles
//! share bit-identical vertices (the watertightness premise), grids, a small
//! deterministic RNG, and a minimal OBJ reader for the benchmark's real meshes.

use glam::Vec3;

/// xorshift64*: deterministic, dependency-free.
pub struct Rng(pub u64);

impl Rng {
    pub fn next_u64(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    /// Uniform in [0, 1).
    pub fn f32(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 / (1u64 << 24) as f32
    }
    pub fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.f32()
    }
    /// Uniform direction on the unit sphere.
    pub fn dir(&mut self) -> Vec3 {
        loop {
            let v = Vec3::new(
                self.range(-1.0, 1.0),
                self.range(-1.0, 1.0),
                self.range(-1.0, 1.0),
            );
            let l = v.length_squared();
            if l > 1e-4 && l <= 1.0 {
                return v / l.sqrt();
            }
        }
    }
}

/// Indexed mesh → triangle soup (vertices shared bit for bit).
fn soup(verts: &[Vec3], faces: &[[usize; 3]]) -> Vec<[Vec3; 3]> {
    faces
        .iter()
        .map(|f| [verts[f[0]], verts[f[1]], verts[f[2]]])
        .collect()
}

/// Closed UV sphere: `rings` latitude bands, `segs` longitudes, single pole vertices.
pub fn sphere(center: Vec3, radius: f32, rings: usize, segs: usize) -> Vec<[Vec3; 3]> {
    let mut v = vec![center + Vec3::new(0.0, radius, 0.0)];
    for r in 1..rings {
        let th = std::f32::consts::PI * r as f32 / rings as f32;
        for s in 0..segs {
            let ph = std::f32::consts::TAU * s as f32 / segs as f32;
            v.push(center + radius * Vec3::new(th.sin() * ph.cos(), th.cos(), th.sin() * ph.sin()));
        }
    }
    let south = v.len();
    v.push(center - Vec3::new(0.0, radius, 0.0));
    let idx = |r: usize, s: usize| 1 + (r - 1) * segs + s % segs;
    let mut f = Vec::new();
    for s in 0..segs {
        f.push([0, idx(1, s + 1), idx(1, s)]);
        f.push([south, idx(rings - 1, s), idx(rings - 1, s + 1)]);
    }
    for r in 1..rings - 1 {
        for s in 0..segs {
            let (a, b, c, d) = (idx(r, s), idx(r, s + 1), idx(r + 1, s), idx(r + 1, s + 1));
            f.push([a, b, d]);
            f.push([a, d, c]);
        }
    }
    soup(&v, &f)
}

/// Closed axis-aligned box, each face an n×n grid of quads (two triangles each).
pub fn grid_box(center: Vec3, half: f32, n: usize) -> Vec<[Vec3; 3]> {
    // Vertices on the box surface, indexed by integer lattice coordinates so that the
    // faces' shared edges use the very same f32 values.
    let coord = |i: usize| -half + 2.0 * half * i as f32 / n as f32;
    let p = |i: usize, j: usize, k: usize| center + Vec3::new(coord(i), coord(j), coord(k));
    let mut tris = Vec::new();
    for axis in 0..3 {
        for &side in &[0usize, n] {
            for a in 0..n {
                for b in 0..n {
                    let at = |u: usize, w: usize| {
                        let mut c = [0usize; 3];
                        c[axis] = side;
                        c[(axis + 1) % 3] = u;
                        c[(axis + 2) % 3] = w;
                        p(c[0], c[1], c[2])
                    };
                    let (q0, q1, q2, q3) = (at(a, b), at(a + 1, b), at(a + 1, b + 1), at(a, b + 1));
                    tris.push([q0, q1, q2]);
                    tris.push([q0, q2, q3]);
                }
            }
        }
    }
    tris
}

/// Flat n×n grid of quads in the plane y = `y`, spanning [0, size]² in x and z.
pub fn grid(n: usize, size: f32, y: f32) -> Vec<[Vec3; 3]> {
    let c = |i: usize| size * i as f32 / n as f32;
    let mut tris = Vec::new();
    for i in 0..n {
        for k in 0..n {
            let p = |a: usize, b: usize| Vec3::new(c(a), y, c(b));
            tris.push([p(i, k), p(i + 1, k), p(i + 1, k + 1)]);
            tris.push([p(i, k), p(i + 1, k + 1), p(i, k + 1)]);
        }
    }
    tris
}

/// Random triangles of random size in a cube of half-width `extent`.
pub fn random_soup(rng: &mut Rng, n: usize, extent: f32) -> Vec<[Vec3; 3]> {
    (0..n)
        .map(|_| {
            let c = Vec3::new(
                rng.range(-extent, extent),
                rng.range(-extent, extent),
                rng.range(-extent, extent),
            );
            let s = extent * 0.1 * rng.f32();
            [c + s * rng.dir(), c + s * rng.dir(), c + s * rng.dir()]
        })
        .collect()
}

/// Positions and faces of an OBJ file (`v` and `f` lines; polygons fan-triangulated,
/// negative indices resolved). Enough for the benchmark meshes; not a general loader.
pub fn load_obj(path: &std::path::Path) -> Result<Vec<[Vec3; 3]>, String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut verts: Vec<Vec3> = Vec::new();
    let mut tris = Vec::new();
    for (ln, line) in text.lines().enumerate() {
        let mut it = line.split_whitespace();
        match it.next() {
            Some("v") => {
                let c: Vec<f32> = it.take(3).filter_map(|x| x.parse().ok()).collect();
                if c.len() != 3 {
                    return Err(format!("{}:{}: bad vertex", path.display(), ln + 1));
                }
                verts.push(Vec3::new(c[0], c[1], c[2]));
            }
            Some("f") => {
                let mut idx = Vec::new();
                for w in it {
                    let i: i64 = w
                        .split('/')
                        .next()
                        .and_then(|x| x.parse().ok())
                        .ok_or_else(|| format!("{}:{}: bad face", path.display(), ln + 1))?;
                    let i = if i < 0 { verts.len() as i64 + i } else { i - 1 };
                    let v = usize::try_from(i)
                        .ok()
                        .and_then(|i| verts.get(i))
                        .ok_or_else(|| {
                            format!("{}:{}: index out of range", path.display(), ln + 1)
                        })?;
                    idx.push(*v);
                }
                for k in 1..idx.len().saturating_sub(1) {
                    tris.push([idx[0], idx[k], idx[k + 1]]);
                }
            }
            _ => {}
        }
    }
    Ok(tris)
}
