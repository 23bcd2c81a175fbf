//! SAH k-d tree: build, traversal and ray/triangle intersection.
//!
//! PLACEHOLDER API (brute force) — the kdtree work replaces the internals, keeping
//! these signatures, which the renderer and the `raycast` tool use.

use formats::{BuildParams, KdFile, Soup};
use glam::Vec3;

pub use formats::Hit;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    pub origin: Vec3,
    pub dir: Vec3,
    pub tmin: f32,
    pub tmax: f32,
}

#[derive(Debug, thiserror::Error)]
pub enum AccelError {
    #[error("the k-d tree was built from geometry {tree}, the soup's geometry is {soup}: rebuild it with soup2kd")]
    HashMismatch { tree: String, soup: String },
}

/// A soup's triangles plus a compiled tree, ready for ray queries.
pub struct Accel {
    tris: Vec<[Vec3; 3]>,
}

impl Accel {
    pub fn new(soup: &Soup, kd: &KdFile) -> Result<Accel, AccelError> {
        if soup.geometry_hash != kd.geometry_hash {
            return Err(AccelError::HashMismatch {
                tree: formats::hex(&kd.geometry_hash),
                soup: formats::hex(&soup.geometry_hash),
            });
        }
        Ok(Accel {
            tris: soup.triangles.clone(),
        })
    }

    /// Closest hit with t in [tmin, tmax], or None.
    pub fn intersect(&self, ray: &Ray) -> Option<Hit> {
        let mut best: Option<Hit> = None;
        let mut tmax = ray.tmax;
        for (i, t) in self.tris.iter().enumerate() {
            if let Some((d, u, v)) = moller(ray, t) {
                if d >= ray.tmin && d <= tmax {
                    tmax = d;
                    best = Some(Hit {
                        t: d,
                        prim: i as u32,
                        u,
                        v,
                    });
                }
            }
        }
        best
    }

    /// Whether anything blocks the ray in [tmin, tmax].
    pub fn occluded(&self, ray: &Ray) -> bool {
        self.tris
            .iter()
            .any(|t| matches!(moller(ray, t), Some((d, _, _)) if d >= ray.tmin && d <= ray.tmax))
    }
}

fn moller(ray: &Ray, t: &[Vec3; 3]) -> Option<(f32, f32, f32)> {
    let e1 = t[1] - t[0];
    let e2 = t[2] - t[0];
    let p = ray.dir.cross(e2);
    let det = e1.dot(p);
    if det == 0.0 {
        return None;
    }
    let inv = 1.0 / det;
    let s = ray.origin - t[0];
    let u = s.dot(p) * inv;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let q = s.cross(e1);
    let v = ray.dir.dot(q) * inv;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    Some((e2.dot(q) * inv, u, v))
}

/// Build a tree over the triangles (placeholder: one leaf).
pub fn build(
    triangles: &[[Vec3; 3]],
    params: &BuildParams,
    geometry_hash: formats::Digest,
) -> KdFile {
    let mut lo = Vec3::splat(f32::INFINITY);
    let mut hi = Vec3::splat(f32::NEG_INFINITY);
    for t in triangles {
        for v in t {
            lo = lo.min(*v);
            hi = hi.max(*v);
        }
    }
    let n = triangles.len() as u32;
    KdFile {
        geometry_hash,
        params: *params,
        stats: formats::TreeStats {
            triangles: n as u64,
            nodes: 1,
            leaves: 1,
            references: n as u64,
            ..Default::default()
        },
        bounds: [lo, hi],
        nodes: vec![formats::KdNode::leaf(n, 0)],
        leaf_tris: (0..n).collect(),
    }
}
