//! What robustness costs: the k-d tree traversed the textbook way (pbrt-v3's split rule,
//! unpadded cell intervals, plain IEEE arithmetic on ±0) with plain Möller–Trumbore
//! (1997), which leaks rays through shared edges and rejects hits with an absolute
//! determinant epsilon. Not watertight; `robustbench` races it against the product's
//! `Accel::intersect` and counts the rays each loses from inside closed meshes.
//!
//! This is a copy of the product's closest-hit loop (kdtree's `traverse.rs`) with the
//! textbook rules, not a type parameter of it. A generic traversal would need a hook for
//! every rule that differs (box clipping, the split step, interval padding, the leaf
//! test), and the product would then carry a measurement interface whose cost has to be
//! re-proven after each change to its hot loop. The copy keeps everything else equal to
//! compare like with like: the same tree and triangle order, the same fixed stack left
//! uninitialised, the same four-wide leaf groups and the same tie rule.

// `!(a <= b)` is deliberate, as in the product: true when either side is NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use formats::{Hit, KdFile, KdNode};
use glam::Vec3;
use kdtree::triangle::{widen, RawHit, RayPre};
use kdtree::Ray;
use std::mem::MaybeUninit;

/// Entries of the traversal stack, as in the product's traversal.
const STACK: usize = 64;

/// A soup's triangles and a compiled tree, laid out as `kdtree::Accel` lays them out.
pub struct PlainAccel {
    /// Vertices in the order the leaves first list them.
    tris: Vec<[[f32; 3]; 3]>,
    /// Soup index of each entry of `tris`.
    soup_index: Vec<u32>,
    nodes: Vec<KdNode>,
    /// The leaves' lists, as indices into `tris`.
    leaf_tris: Vec<u32>,
    lo: [f32; 3],
    hi: [f32; 3],
}

impl PlainAccel {
    /// Pair `triangles` with the tree built from them. Refuses a tree that does not fit
    /// (the loop below reads it unchecked) or that is deeper than the stack.
    pub fn new(triangles: &[[Vec3; 3]], kd: &KdFile) -> Result<PlainAccel, String> {
        kd.validate()?;
        if kd.stats.triangles != triangles.len() as u64 {
            return Err(format!(
                "the tree indexes {} triangles, the soup has {}",
                kd.stats.triangles,
                triangles.len()
            ));
        }
        if kd.height() as usize >= STACK {
            return Err(format!("the tree is {} levels deep", kd.height()));
        }
        let kdtree::Renumbered {
            tris,
            soup_index,
            leaf_tris,
        } = kdtree::renumber(triangles.len(), |t| triangles[t], kd.leaf_tris.clone());
        Ok(PlainAccel {
            tris,
            soup_index,
            nodes: kd.nodes.clone(),
            leaf_tris,
            lo: kd.bounds[0].to_array(),
            hi: kd.bounds[1].to_array(),
        })
    }

    #[inline(always)]
    fn node(&self, i: u32) -> KdNode {
        // SAFETY: `new` ran `KdFile::validate`, which proves every child index of an
        // interior node is inside `nodes`; the loop visits node 0 and such children.
        unsafe { *self.nodes.get_unchecked(i as usize) }
    }

    #[inline(always)]
    fn leaf(&self, node: KdNode) -> &[u32] {
        let off = node.offset() as usize;
        // SAFETY: `KdFile::validate` proves offset + count ≤ leaf_tris.len() for leaves.
        unsafe {
            self.leaf_tris
                .get_unchecked(off..off + node.count() as usize)
        }
    }

    #[inline(always)]
    fn tri(&self, p: u32) -> &[[f32; 3]; 3] {
        // SAFETY: `new` renumbers every leaf entry to its position in `tris`.
        unsafe { self.tris.get_unchecked(p as usize) }
    }

    #[inline(always)]
    fn soup_index(&self, p: u32) -> u32 {
        // SAFETY: `soup_index` has one entry per element of `tris`.
        unsafe { *self.soup_index.get_unchecked(p as usize) }
    }

    /// Closest hit in [tmin, tmax]; ties in t go to the lower triangle index.
    pub fn intersect(&self, ray: &Ray) -> Option<Hit> {
        if !(ray.tmin <= ray.tmax) || ray.tmax == f32::NEG_INFINITY || ray.tmin == f32::INFINITY {
            return None;
        }
        // The product refuses the same rays (zero or non-finite directions and origins).
        RayPre::new(ray.origin, ray.dir)?;
        let o = ray.origin.to_array();
        let d = ray.dir.to_array();
        let inv = [1.0 / d[0], 1.0 / d[1], 1.0 / d[2]];
        let (mut t0, mut t1) = (ray.tmin, ray.tmax);
        for a in 0..3 {
            let ta = (self.lo[a] - o[a]) * inv[a];
            let tb = (self.hi[a] - o[a]) * inv[a];
            let (near, far) = if inv[a] > 0.0 { (ta, tb) } else { (tb, ta) };
            // Plain slabs: NaN from 0·∞ falls through, as in textbook code.
            if near > t0 {
                t0 = near;
            }
            if far < t1 {
                t1 = far;
            }
        }
        if !(t0 <= t1) {
            return None;
        }
        let mut best = Hit::MISS;
        let mut best_t = ray.tmax;
        let mut stack = [MaybeUninit::<(u32, f32, f32)>::uninit(); STACK];
        let mut sp = 0;
        let mut node_i = 0u32;
        loop {
            let node = self.node(node_i);
            if !node.is_leaf() {
                // pbrt-v3's rule: the child holding the origin first.
                let a = node.axis();
                let (below, above) = (node_i + 1, node.above_child());
                let split = node.split();
                let tp = (split - o[a]) * inv[a];
                let below_first = o[a] < split || (o[a] == split && inv[a] <= 0.0);
                let (first, second) = if below_first {
                    (below, above)
                } else {
                    (above, below)
                };
                if tp > t1 || tp <= 0.0 {
                    node_i = first;
                } else if tp < t0 {
                    node_i = second;
                } else {
                    let far_start = if tp >= t0 { tp } else { t0 };
                    stack[sp] = MaybeUninit::new((second, far_start, t1));
                    sp += 1;
                    node_i = first;
                    t1 = if tp <= t1 { tp } else { t1 };
                }
                continue;
            }
            let leaf = self.leaf(node);
            if leaf.len() >= 2 {
                for group in leaf.chunks(4) {
                    let bound = widen(best_t);
                    let last = group[group.len() - 1];
                    let lanes: [u32; 4] = std::array::from_fn(|l| *group.get(l).unwrap_or(&last));
                    let hits = moller4(
                        ray.origin,
                        ray.dir,
                        lanes.map(|p| self.tri(p)),
                        ray.tmin,
                        bound,
                    );
                    for (p, h) in lanes.into_iter().zip(hits) {
                        if let Some(h) = h {
                            keep_closer(&mut best, &mut best_t, self.soup_index(p), h);
                        }
                    }
                }
            } else {
                for &p in leaf {
                    if let Some(h) =
                        moller(ray.origin, ray.dir, self.tri(p), ray.tmin, widen(best_t))
                    {
                        keep_closer(&mut best, &mut best_t, self.soup_index(p), h);
                    }
                }
            }
            if sp == 0 {
                break;
            }
            sp -= 1;
            // SAFETY: entries below `sp` were written by the push that grew it past them.
            (node_i, t0, t1) = unsafe { stack[sp].assume_init() };
            if best_t < t0 {
                break;
            }
        }
        (!best.is_miss()).then_some(best)
    }
}

/// The product's rule: closer, or as close with a lower soup index.
#[inline(always)]
fn keep_closer(best: &mut Hit, best_t: &mut f32, prim: u32, h: RawHit) {
    if h.t <= *best_t && (h.t < *best_t || prim < best.prim) {
        *best_t = h.t;
        *best = Hit {
            t: h.t,
            prim,
            u: h.u,
            v: h.v,
        };
    }
}

/// Plain Möller–Trumbore on one triangle, in [tmin, tmax].
#[inline(always)]
fn moller(origin: Vec3, dir: Vec3, tri: &[[f32; 3]; 3], tmin: f32, tmax: f32) -> Option<RawHit> {
    let v0 = Vec3::from(tri[0]);
    let e1 = Vec3::from(tri[1]) - v0;
    let e2 = Vec3::from(tri[2]) - v0;
    let p = dir.cross(e2);
    let det = e1.dot(p);
    if det.abs() < 1e-8 {
        return None;
    }
    let inv = 1.0 / det;
    let s = origin - v0;
    let u = s.dot(p) * inv;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let q = s.cross(e1);
    let v = dir.dot(q) * inv;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    let t = e2.dot(q) * inv;
    // det = e1 · (d × e2) = −d · n: positive when the ray meets the front.
    (t >= tmin && t <= tmax).then_some(RawHit {
        t,
        u,
        v,
        front: det > 0.0,
    })
}

/// [`moller`] on four triangles, lane by lane, as the product's four-wide test is.
#[inline(always)]
fn moller4(
    origin: Vec3,
    dir: Vec3,
    tri: [&[[f32; 3]; 3]; 4],
    tmin: f32,
    tmax: f32,
) -> [Option<RawHit>; 4] {
    let lanes = |f: &dyn Fn(&[[f32; 3]; 3]) -> f32| -> [f32; 4] {
        [f(tri[0]), f(tri[1]), f(tri[2]), f(tri[3])]
    };
    let (o, d) = (origin.to_array(), dir.to_array());
    let e1: [[f32; 4]; 3] = std::array::from_fn(|k| lanes(&|t| t[1][k] - t[0][k]));
    let e2: [[f32; 4]; 3] = std::array::from_fn(|k| lanes(&|t| t[2][k] - t[0][k]));
    let s: [[f32; 4]; 3] = std::array::from_fn(|k| lanes(&|t| o[k] - t[0][k]));
    let mut out = [None; 4];
    let mut candidate = [false; 4];
    let (mut u, mut inv) = ([0f32; 4], [0f32; 4]);
    for l in 0..4 {
        // p = d × e2, det = e1 · p, u = s · p / det
        let p = [
            d[1] * e2[2][l] - d[2] * e2[1][l],
            d[2] * e2[0][l] - d[0] * e2[2][l],
            d[0] * e2[1][l] - d[1] * e2[0][l],
        ];
        let det = e1[0][l] * p[0] + e1[1][l] * p[1] + e1[2][l] * p[2];
        inv[l] = 1.0 / det;
        u[l] = (s[0][l] * p[0] + s[1][l] * p[1] + s[2][l] * p[2]) * inv[l];
        candidate[l] = det.abs() >= 1e-8 && (0.0..=1.0).contains(&u[l]);
    }
    for l in 0..4 {
        if !candidate[l] {
            continue;
        }
        let q = Vec3::from([s[0][l], s[1][l], s[2][l]])
            .cross(Vec3::from([e1[0][l], e1[1][l], e1[2][l]]));
        let v = dir.dot(q) * inv[l];
        if v < 0.0 || u[l] + v > 1.0 {
            continue;
        }
        let t = Vec3::from([e2[0][l], e2[1][l], e2[2][l]]).dot(q) * inv[l];
        if t >= tmin && t <= tmax {
            out[l] = Some(RawHit {
                t,
                u: u[l],
                v,
                front: inv[l] > 0.0,
            });
        }
    }
    out
}
