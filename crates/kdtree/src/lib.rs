//! SAH k-d tree: build, traversal and watertight ray/triangle intersection.
//!
//! * [`build()`] compiles triangles into a [`KdFile`] (Wald & Havran's O(N log N) SAH build
//!   with perfect splits, parallel over subtrees).
//! * [`Accel`] pairs a soup's triangles with a compiled tree and answers closest-hit
//!   ([`Accel::intersect`]) and any-hit ([`Accel::occluded`]) queries.
//! * `testkit` (feature `testkit`, and this crate's own tests) holds what tests and
//!   benchmarks need and the product does not: test meshes, an RNG and brute-force
//!   references.
//!
//! See docs/ROBUSTNESS.md for the numerical hard cases and the tests that pin them.

// `!(a <= b)` is deliberate throughout: it is true when either side is NaN, which is
// exactly when a ray or a cell must be refused.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod aabb;
pub mod build;
mod packet;
#[cfg(any(test, feature = "testkit"))]
pub mod testkit;
mod traverse;
pub mod triangle;

use aabb::Aabb;
use formats::{BuildParams, KdFile, KdNode, Soup, TreeStats};
use glam::Vec3;
use rayon::prelude::*;

pub use build::events::MAX_TRIANGLES;
pub use build::median::build_median;
pub use build::{build, depth_bound};
pub use formats::Hit;
pub use packet::LANES;
pub use traverse::Counts;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    pub origin: Vec3,
    pub dir: Vec3,
    pub tmin: f32,
    pub tmax: f32,
}

impl Ray {
    pub fn new(origin: Vec3, dir: Vec3, tmin: f32, tmax: f32) -> Ray {
        Ray {
            origin,
            dir,
            tmin,
            tmax,
        }
    }
}

#[derive(Debug, thiserror::Error)]
pub enum AccelError {
    #[error("the k-d tree was built from geometry {tree}, the soup's geometry is {soup}: rebuild it with soup2kd")]
    HashMismatch { tree: String, soup: String },
    #[error("the k-d tree does not fit its soup: {detail}")]
    Corrupt { detail: String },
    #[error("the k-d tree is {depth}{more} levels deep; traversal supports at most {max}: rebuild it with a smaller --max-depth", more = if *depth >= formats::kd::HEIGHT_CAP { " or more" } else { "" })]
    TooDeep { depth: u32, max: u32 },
}

/// A soup's triangles plus a compiled tree, ready for ray queries. Send + Sync: share one
/// across threads by reference.
pub struct Accel {
    /// Triangle vertices (36 bytes each) in the order the leaves first list them, so a
    /// ray walking neighbouring leaves reads neighbouring memory.
    tris: Vec<[[f32; 3]; 3]>,
    /// Soup index of each entry of `tris`: hits and the tie rule speak soup indices.
    soup_index: Vec<u32>,
    nodes: Vec<KdNode>,
    /// The leaves' lists, as indices into `tris`.
    leaf_tris: Vec<u32>,
    /// Triangles of the input (the denominator of bytes per triangle).
    input_triangles: usize,
    bounds: Aabb,
}

impl Accel {
    /// Pair a soup with its tree; refuses a tree built from other geometry. The tree's
    /// arrays become the accelerator's (its leaf lists renumbered in place), so a large
    /// scene's nodes and lists are not held twice.
    pub fn new(soup: &Soup, kd: KdFile) -> Result<Accel, AccelError> {
        if soup.geometry_hash != kd.geometry_hash {
            return Err(AccelError::HashMismatch {
                tree: formats::hex(&kd.geometry_hash),
                soup: formats::hex(&soup.geometry_hash),
            });
        }
        Self::assemble(soup.triangle_count(), |t| soup.corners(t), kd)
    }

    /// Pair bare triangles with their tree (the geometry hash is recomputed and checked).
    pub fn from_triangles(triangles: &[[Vec3; 3]], kd: &KdFile) -> Result<Accel, AccelError> {
        let hash = formats::soup::geometry_hash(triangles);
        if hash != kd.geometry_hash {
            return Err(AccelError::HashMismatch {
                tree: formats::hex(&kd.geometry_hash),
                soup: formats::hex(&hash),
            });
        }
        Self::assemble(triangles.len(), |t| triangles[t], kd.clone())
    }

    /// Build a tree with `params` and wrap it (tests, benchmarks, tools).
    pub fn build(triangles: &[[Vec3; 3]], params: &BuildParams) -> Accel {
        let kd = build(triangles, params, formats::soup::geometry_hash(triangles));
        Self::assemble(triangles.len(), |t| triangles[t], kd)
            .expect("a freshly built tree fits its triangles")
    }

    /// `count` triangles, the corners of each given by `corners`.
    fn assemble(
        count: usize,
        corners: impl Fn(usize) -> [Vec3; 3] + Sync,
        kd: KdFile,
    ) -> Result<Accel, AccelError> {
        kd.validate()
            .map_err(|detail| AccelError::Corrupt { detail })?;
        if kd.stats.triangles != count as u64 {
            return Err(AccelError::Corrupt {
                detail: format!(
                    "the tree indexes {} triangles, the soup has {count}",
                    kd.stats.triangles,
                ),
            });
        }
        let height = kd.height();
        let max = (traverse::STACK - 1) as u32;
        if height > max {
            return Err(AccelError::TooDeep { depth: height, max });
        }
        let bounds = kd.bounds;
        let Renumbered {
            tris,
            soup_index,
            leaf_tris,
        } = renumber(count, corners, kd.leaf_tris);
        Ok(Accel {
            tris,
            soup_index,
            nodes: kd.nodes,
            leaf_tris,
            input_triangles: count,
            bounds: Aabb {
                lo: bounds[0].to_array(),
                hi: bounds[1].to_array(),
            },
        })
    }

    fn tree(&self) -> traverse::Tree<'_> {
        traverse::Tree {
            tris: &self.tris,
            soup_index: &self.soup_index,
            nodes: &self.nodes,
            leaf_tris: &self.leaf_tris,
            bounds: &self.bounds,
        }
    }

    /// Closest hit with t in [tmin, tmax], or None. Ties in t go to the lower triangle
    /// index. NaN/infinite rays, zero directions and tmin > tmax are misses.
    pub fn intersect(&self, ray: &Ray) -> Option<Hit> {
        self.tree().closest(ray, |_, _| true, &mut ())
    }

    /// Whether anything blocks the ray in [tmin, tmax]; stops at the first blocker. The
    /// walk takes each node's far child first: a ray leaving a surface meets a blocker
    /// sooner from the far end than through the cells of the surface it leaves.
    pub fn occluded(&self, ray: &Ray) -> bool {
        self.tree().any::<true, _, _>(ray, |_, _| true, &mut ())
    }

    /// The closest hit that `accept` takes (it is asked about each hit that would be the
    /// closest so far, soup index and barycentrics filled in, and whether the ray meets the
    /// triangle's front, its vertices counter-clockwise as the ray sees them): what surfaces
    /// that are not drawn from every side or at every texel need, without restarting the
    /// traversal for each refused hit. Ties go to the lower index among accepted hits.
    pub fn intersect_filtered(
        &self,
        ray: &Ray,
        accept: impl FnMut(&Hit, bool) -> bool,
    ) -> Option<Hit> {
        self.tree().closest(ray, accept, &mut ())
    }

    /// [`Accel::intersect`] on four rays at once, the same answers bit for bit. Rays that
    /// travel side by side (neighbouring pixels of a camera) share the walk down the tree;
    /// rays whose directions differ in sign or dominant axis are traced one by one.
    pub fn intersect4(&self, rays: &[Ray; LANES]) -> [Option<Hit>; LANES] {
        self.tree().closest4(rays, |_, _, _| true)
    }

    /// [`Accel::intersect_filtered`] on four rays at once; `accept` is told the lane too.
    pub fn intersect4_filtered(
        &self,
        rays: &[Ray; LANES],
        accept: impl FnMut(usize, &Hit, bool) -> bool,
    ) -> [Option<Hit>; LANES] {
        self.tree().closest4(rays, accept)
    }

    /// Whether a hit that `blocks` takes lies in [tmin, tmax]; stops at the first one.
    /// `blocks` is asked about hits in no set order (the walk takes the far child first, as
    /// [`Accel::occluded`]'s does), with the side as for [`Accel::intersect_filtered`], so
    /// it must judge each hit on its own: a face that casts from that side, a texel that
    /// is solid.
    pub fn occluded_filtered(&self, ray: &Ray, blocks: impl FnMut(&Hit, bool) -> bool) -> bool {
        self.tree().any::<true, _, _>(ray, blocks, &mut ())
    }

    /// [`Accel::occluded_filtered`] with the hits reaching `blocks` front to back, cell by
    /// cell (not sorted by t within a cell): for filters that gather along the ray, such as
    /// a product of transmittances that should round in the order the layers lie.
    pub fn occluded_filtered_in_order(
        &self,
        ray: &Ray,
        blocks: impl FnMut(&Hit, bool) -> bool,
    ) -> bool {
        self.tree().any::<false, _, _>(ray, blocks, &mut ())
    }

    /// [`Accel::occluded`] on four rays at once, the same answers bit for bit (rays that do
    /// not travel side by side are traced one by one, as for [`Accel::intersect4`]).
    pub fn occluded4(&self, rays: &[Ray; LANES]) -> [bool; LANES] {
        self.tree().any4::<true, _>(rays, |_, _, _| true)
    }

    /// [`Accel::occluded_filtered`] on four rays at once; `blocks` is told the lane too.
    pub fn occluded4_filtered(
        &self,
        rays: &[Ray; LANES],
        blocks: impl FnMut(usize, &Hit, bool) -> bool,
    ) -> [bool; LANES] {
        self.tree().any4::<true, _>(rays, blocks)
    }

    /// [`Accel::occluded_filtered_in_order`] on four rays at once; `blocks` is told the
    /// lane too, and each lane's hits reach it in that lane's front-to-back order.
    pub fn occluded4_filtered_in_order(
        &self,
        rays: &[Ray; LANES],
        blocks: impl FnMut(usize, &Hit, bool) -> bool,
    ) -> [bool; LANES] {
        self.tree().any4::<false, _>(rays, blocks)
    }

    /// [`Accel::intersect`] that also adds what the traversal did to `counts` (benchmarks;
    /// the plain query is a separate instantiation and counts nothing).
    pub fn intersect_counted(&self, ray: &Ray, counts: &mut Counts) -> Option<Hit> {
        self.tree().closest(ray, |_, _| true, counts)
    }

    /// [`Accel::occluded`] that also adds what the traversal did to `counts`.
    pub fn occluded_counted(&self, ray: &Ray, counts: &mut Counts) -> bool {
        self.tree().any::<true, _, _>(ray, |_, _| true, counts)
    }

    /// Bytes held for queries: nodes, leaf lists and triangle data.
    pub fn memory_bytes(&self) -> usize {
        self.nodes.len() * std::mem::size_of::<KdNode>()
            + self.leaf_tris.len() * 4
            + self.tris.len() * std::mem::size_of::<[[f32; 3]; 3]>()
            + self.soup_index.len() * 4
    }

    /// [`Accel::memory_bytes`] per input triangle.
    pub fn bytes_per_triangle(&self) -> f64 {
        self.memory_bytes() as f64 / self.input_triangles.max(1) as f64
    }

    /// Triangles the tree holds (soup triangles with non-finite vertices are left out).
    pub fn triangle_count(&self) -> usize {
        self.tris.len()
    }
}

/// Bytes an [`Accel`] holds for the queries of a tree with these statistics: 8 per node,
/// 4 per leaf entry, 36 of vertices and 4 of soup index per triangle.
pub fn query_bytes(s: &TreeStats) -> usize {
    s.nodes as usize * std::mem::size_of::<KdNode>()
        + s.references as usize * 4
        + s.triangles as usize * (std::mem::size_of::<[[f32; 3]; 3]>() + 4)
}

/// A tree's triangles renumbered by first appearance in its leaves (depth-first order),
/// so that a ray walking the tree reads them from memory mostly in order.
pub struct Renumbered {
    /// The triangles in leaf order.
    pub tris: Vec<[[f32; 3]; 3]>,
    /// Soup index of each triangle in leaf order (hits report soup indices).
    pub soup_index: Vec<u32>,
    /// The leaves' triangle lists in leaf-order indices.
    pub leaf_tris: Vec<u32>,
}

/// Renumber `triangles` by their first appearance in `leaf_tris` (a tree's leaf lists in
/// soup indices, renumbered in place).
pub fn renumber(
    count: usize,
    corners: impl Fn(usize) -> [Vec3; 3] + Sync,
    mut leaf_tris: Vec<u32>,
) -> Renumbered {
    // New number + 1 of each soup triangle, 0 while unseen: zeroed memory comes fresh
    // from the kernel, so no pass fills it first. Branch-free, as whether a reference is a
    // triangle's first varies from entry to entry (`just large`'s tree: 0.11 s instead of
    // 0.12–0.17 s with a branch).
    let mut slot = vec![0u32; count];
    // One spare entry: each step writes at `next`, which only a first sighting keeps.
    let mut soup_index = vec![0u32; count + 1];
    let mut next = 0u32;
    for p in &mut leaf_tris {
        let s = &mut slot[*p as usize];
        let first = *s == 0;
        let number = if first { next } else { *s - 1 };
        *s = number + 1;
        soup_index[next as usize] = *p;
        next += u32::from(first);
        *p = number;
    }
    soup_index.truncate(next as usize);
    // The numbering is sequential by nature; gathering the corners in the new order (a
    // read from anywhere in the soup per triangle) is not.
    let tris = soup_index
        .par_iter()
        .with_min_len(1 << 14)
        .map(|&p| corners(p as usize).map(|v| v.to_array()))
        .collect();
    Renumbered {
        tris,
        soup_index,
        leaf_tris,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn assert_send_sync<T: Send + Sync>() {}

    #[test]
    fn accel_is_send_and_sync() {
        assert_send_sync::<Accel>();
    }

    /// Triangles are numbered by their first reference; later references reuse the number,
    /// unreferenced triangles get none, and the last reference may repeat one when every
    /// triangle is already numbered.
    #[test]
    fn renumbers_by_first_reference() {
        let corners = |t: usize| [Vec3::splat(t as f32), Vec3::X, Vec3::Y];
        let r = renumber(8, corners, vec![5, 2, 5, 7, 2, 0]);
        assert_eq!(r.soup_index, [5, 2, 7, 0]);
        assert_eq!(r.leaf_tris, [0, 1, 0, 2, 1, 3]);
        let firsts: Vec<f32> = r.tris.iter().map(|t| t[0][0]).collect();
        assert_eq!(firsts, [5.0, 2.0, 7.0, 0.0]);
        let r = renumber(3, corners, vec![2, 0, 1, 0, 2]);
        assert_eq!(r.soup_index, [2, 0, 1]);
        assert_eq!(r.leaf_tris, [0, 1, 2, 1, 0]);
    }

    #[test]
    fn refuses_other_geometry() {
        let a = [[Vec3::ZERO, Vec3::X, Vec3::Y]];
        let b = [[Vec3::ZERO, Vec3::X, Vec3::Z]];
        let kd = build(
            &a,
            &BuildParams::default(),
            formats::soup::geometry_hash(&a),
        );
        assert!(Accel::from_triangles(&a, &kd).is_ok());
        assert!(matches!(
            Accel::from_triangles(&b, &kd),
            Err(AccelError::HashMismatch { .. })
        ));
    }
}

#[cfg(test)]
mod tree_tests {
    use super::*;

    fn scene() -> Vec<[Vec3; 3]> {
        let mut t = testkit::sphere(Vec3::new(0.0, 1.0, 0.0), 1.0, 16, 32);
        t.extend(testkit::grid(8, 8.0, 0.0));
        t
    }

    #[test]
    fn stats_describe_the_tree() {
        let tris = scene();
        let kd = build(&tris, &BuildParams::default(), [7; 32]);
        let s = &kd.stats;
        assert_eq!(s.triangles, tris.len() as u64);
        assert_eq!(s.nodes, kd.nodes.len() as u64);
        assert_eq!(
            s.leaves,
            kd.nodes.iter().filter(|n| n.is_leaf()).count() as u64
        );
        assert_eq!(s.nodes, 2 * s.leaves - 1, "a full binary tree");
        assert_eq!(s.references, kd.leaf_tris.len() as u64);
        assert!(
            s.references >= tris.len() as u64,
            "every triangle is in some leaf"
        );
        let mut seen = vec![false; tris.len()];
        for &t in &kd.leaf_tris {
            seen[t as usize] = true;
        }
        assert!(seen.iter().all(|&b| b));
        assert!(s.max_depth <= depth_bound(&BuildParams::default(), tris.len()));
        assert!(s.sah_cost > 0.0 && s.sah_cost < tris.len() as f64);
        // The SAH tree is cheaper than the spatial-median tree on the same input.
        let median = build_median(&tris, &BuildParams::default(), [7; 32]);
        assert!(
            s.sah_cost < median.stats.sah_cost,
            "{} vs {}",
            s.sah_cost,
            median.stats.sah_cost
        );
        assert!(kd.validate().is_ok());
    }

    #[test]
    fn depth_bound_and_leaf_size_are_obeyed() {
        let tris = scene();
        for (max_depth, leaf_size) in [(1, 1), (4, 1), (0, 16)] {
            let p = BuildParams {
                max_depth,
                leaf_size,
                ..BuildParams::default()
            };
            let kd = build(&tris, &p, [0; 32]);
            assert!(kd.stats.max_depth <= depth_bound(&p, tris.len()), "{p:?}");
            if max_depth == 1 {
                assert_eq!(kd.stats.nodes, 3);
            }
        }
        assert_eq!(depth_bound(&BuildParams::default(), 1 << 20), 34);
        let huge = BuildParams {
            max_depth: 500,
            ..BuildParams::default()
        };
        assert_eq!(depth_bound(&huge, 10), build::MAX_DEPTH_LIMIT);
    }

    #[test]
    fn refuses_corrupt_and_too_deep_trees() {
        let tris = scene();
        let hash = formats::soup::geometry_hash(&tris);
        // Chains of interior nodes deeper than the traversal stack; heights from 255 on
        // are reported as "255 or more".
        for (levels, said) in [(70u32, "70 levels"), (300, "255 or more levels")] {
            let mut nodes = Vec::new();
            for i in 0..levels {
                nodes.push(KdNode::interior(0, 0.0, 2 * i + 2));
                nodes.push(KdNode::leaf(0, 0));
            }
            nodes.pop();
            nodes.push(KdNode::leaf(0, 0));
            nodes.push(KdNode::leaf(0, 0));
            let mut kd = build(&tris, &BuildParams::default(), hash);
            kd.nodes = nodes;
            assert!(kd.validate().is_ok(), "{:?}", kd.validate());
            assert_eq!(kd.height(), levels.min(formats::kd::HEIGHT_CAP));
            let err = Accel::from_triangles(&tris, &kd).err().expect("too deep");
            assert!(matches!(err, AccelError::TooDeep { .. }));
            assert!(err.to_string().contains(said), "{err}");
        }
        // A tree indexing fewer triangles than the soup holds.
        let mut kd = build(&tris, &BuildParams::default(), hash);
        kd.stats.triangles -= 1;
        kd.leaf_tris.retain(|&t| (t as u64) < kd.stats.triangles);
        kd.nodes = vec![KdNode::leaf(kd.leaf_tris.len() as u32, 0)];
        assert!(matches!(
            Accel::from_triangles(&tris, &kd),
            Err(AccelError::Corrupt { .. })
        ));
    }

    /// The counting instantiation is the same traversal: same answers, and counts that
    /// add up (every ray that reaches a leaf stepped through the root first).
    #[test]
    fn counted_queries_answer_as_the_plain_ones() {
        let tris = scene();
        let a = Accel::build(&tris, &BuildParams::default());
        let mut rng = testkit::Rng(3);
        let mut total = Counts::default();
        for _ in 0..2000 {
            let o = Vec3::new(rng.unit(), rng.unit(), rng.unit()) * 8.0 - Vec3::splat(4.0);
            let d = Vec3::new(rng.unit(), rng.unit(), rng.unit()) * 2.0 - Vec3::ONE;
            let r = Ray::new(o, d, 0.0, f32::INFINITY);
            let mut c = Counts::default();
            assert_eq!(a.intersect_counted(&r, &mut c), a.intersect(&r));
            assert_eq!(a.occluded_counted(&r, &mut c), a.occluded(&r));
            assert!(c.leaves == 0 || c.nodes > 0, "{c:?}");
            total.nodes += c.nodes;
            total.leaves += c.leaves;
            total.tests += c.tests;
        }
        assert!(
            total.nodes > 0 && total.leaves > 0 && total.tests > 0,
            "{total:?}"
        );
    }

    /// Triangles with a NaN or infinite vertex are left out of the tree, wherever they
    /// lie in the soup; every other triangle is in it.
    #[test]
    fn non_finite_triangles_are_left_out() {
        let mut tris = testkit::sphere(Vec3::ZERO, 1.0, 120, 300); // 72,000: binned in parallel
        let bad = [0, 17, 40_000, tris.len() - 1];
        for (k, &i) in bad.iter().enumerate() {
            tris[i][k % 3] = [Vec3::NAN, Vec3::INFINITY, Vec3::NEG_INFINITY][k % 3];
        }
        let kd = build(
            &tris,
            &BuildParams::default(),
            formats::soup::geometry_hash(&tris),
        );
        let mut held: Vec<u32> = kd.leaf_tris.clone();
        held.sort_unstable();
        held.dedup();
        let want: Vec<u32> = (0..tris.len() as u32)
            .filter(|i| !bad.contains(&(*i as usize)))
            .collect();
        assert_eq!(held, want);
        let a = Accel::from_triangles(&tris, &kd).unwrap();
        let r = Ray::new(Vec3::new(0.0, 0.0, -5.0), Vec3::Z, 0.0, f32::INFINITY);
        assert!((a.intersect(&r).unwrap().t - 4.0).abs() < 0.01);
    }

    #[test]
    fn empty_soup_builds_and_misses() {
        let kd = build(
            &[],
            &BuildParams::default(),
            formats::soup::geometry_hash(&[]),
        );
        assert_eq!(kd.stats.nodes, 1);
        let a = Accel::from_triangles(&[], &kd).unwrap();
        let r = Ray::new(Vec3::ZERO, Vec3::Z, 0.0, f32::INFINITY);
        assert_eq!(a.intersect(&r), None);
        assert!(!a.occluded(&r));
    }
}
