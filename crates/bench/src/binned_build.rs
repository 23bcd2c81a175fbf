//! An approximate SAH k-d tree, for measuring what the product's exact plane search costs
//! in build time: every cell prices only the planes between `bins` equal slabs per axis
//! (counts of box starts and ends per slab), where the product's builder finds the
//! cheapest of all candidate planes. Same node format, the same clipping of straddlers
//! to each child (perfect splits), the same cost constants, leaf rule and depth bound, so
//! the same traversal runs on it and its SAH cost compares with the product's tree.

use formats::{BuildParams, KdFile, KdNode};
use glam::Vec3;
use kdtree::aabb::Aabb;
use kdtree::build::clip::clipped_bounds;
use kdtree::build::sah::AxisCost;
use rayon::prelude::*;

/// Subtrees of at least this many references are built as parallel tasks.
const JOIN_MIN: usize = 1024;

/// Cells of at least this many references count their slabs and split on every thread.
const PARALLEL_MIN: usize = 1 << 16;

#[derive(Clone, Copy)]
struct Ref {
    tri: u32,
    /// The triangle's bounds within the cell.
    b: Aabb,
}

struct Ctx<'a> {
    tris: &'a [[Vec3; 3]],
    kt: f64,
    ki: f64,
    bonus: f64,
    leaf_size: usize,
    max_depth: u32,
    bins: usize,
}

/// A subtree: flat below `JOIN_MIN`, linked above it (children built as separate tasks).
enum Part {
    Flat(Vec<KdNode>, Vec<u32>),
    Node(u32, f32, Box<[Part; 2]>),
}

impl Part {
    /// Depth-first, below before above, into one pair of arrays.
    fn flatten_into(self, nodes: &mut Vec<KdNode>, leaf_tris: &mut Vec<u32>) {
        match self {
            Part::Flat(n, t) => {
                let (nb, tb) = (nodes.len() as u32, leaf_tris.len() as u32);
                nodes.extend(n.into_iter().map(|n| {
                    if n.is_leaf() {
                        KdNode::leaf(n.count(), n.offset() + tb)
                    } else {
                        KdNode::interior(n.axis() as u32, n.split(), n.above_child() + nb)
                    }
                }));
                leaf_tris.extend(t);
            }
            Part::Node(axis, pos, children) => {
                let at = nodes.len();
                nodes.push(KdNode::leaf(0, 0));
                let [below, above] = *children;
                below.flatten_into(nodes, leaf_tris);
                let above_at = nodes.len() as u32;
                above.flatten_into(nodes, leaf_tris);
                nodes[at] = KdNode::interior(axis, pos, above_at);
            }
        }
    }
}

/// Build with `bins` slabs per axis (at least 2) and the product's other parameters.
pub fn build_binned(
    triangles: &[[Vec3; 3]],
    params: &BuildParams,
    bins: usize,
    geometry_hash: formats::Digest,
) -> KdFile {
    let start = std::time::Instant::now();
    let refs: Vec<Ref> = triangles
        .par_iter()
        .enumerate()
        .filter(|(_, t)| t.iter().all(|v| v.is_finite()))
        .map(|(i, t)| Ref {
            tri: i as u32,
            b: Aabb::of_triangle(t),
        })
        .collect();
    let cell = refs
        .par_iter()
        .map(|r| r.b)
        .reduce(|| Aabb::EMPTY, |a, b| a.union(&b));
    let ctx = Ctx {
        tris: triangles,
        kt: params.traversal_cost.max(0.0) as f64,
        ki: (params.intersect_cost as f64).max(1e-6),
        bonus: (params.empty_bonus as f64).clamp(0.0, 1.0),
        leaf_size: params.leaf_size.max(1) as usize,
        max_depth: kdtree::depth_bound(params, refs.len()),
        bins: bins.max(2),
    };
    let (mut nodes, mut leaf_tris) = (Vec::new(), Vec::new());
    if refs.is_empty() {
        nodes.push(KdNode::leaf(0, 0));
    } else {
        build_part(&ctx, refs, cell, 0).flatten_into(&mut nodes, &mut leaf_tris);
    }
    let mut kd = KdFile {
        geometry_hash,
        params: *params,
        stats: Default::default(),
        bounds: if cell.is_empty() {
            [Vec3::ZERO; 2]
        } else {
            cell.to_vec3()
        },
        nodes,
        leaf_tris,
    };
    kd.stats = kdtree::build::stats::measure(&kd, triangles.len() as u64, params);
    kd.stats.build_seconds = start.elapsed().as_secs_f64();
    kd
}

fn build_part(ctx: &Ctx, refs: Vec<Ref>, cell: Aabb, depth: u32) -> Part {
    if refs.len() < JOIN_MIN {
        let (mut nodes, mut leaf_tris) = (Vec::new(), Vec::new());
        build_rec(ctx, refs, cell, depth, &mut nodes, &mut leaf_tris);
        return Part::Flat(nodes, leaf_tris);
    }
    match find_split(ctx, &refs, &cell, depth) {
        None => Part::Flat(
            vec![KdNode::leaf(refs.len() as u32, 0)],
            refs.iter().map(|r| r.tri).collect(),
        ),
        Some((axis, pos)) => {
            let ([rb, ra], [cb, ca]) = split(ctx, &refs, &cell, axis, pos);
            drop(refs);
            let (b, a) = rayon::join(
                || build_part(ctx, rb, cb, depth + 1),
                || build_part(ctx, ra, ca, depth + 1),
            );
            Part::Node(axis as u32, pos, Box::new([b, a]))
        }
    }
}

fn build_rec(
    ctx: &Ctx,
    refs: Vec<Ref>,
    cell: Aabb,
    depth: u32,
    nodes: &mut Vec<KdNode>,
    leaf_tris: &mut Vec<u32>,
) {
    let Some((axis, pos)) = find_split(ctx, &refs, &cell, depth) else {
        nodes.push(KdNode::leaf(refs.len() as u32, leaf_tris.len() as u32));
        leaf_tris.extend(refs.iter().map(|r| r.tri));
        return;
    };
    let ([rb, ra], [cb, ca]) = split(ctx, &refs, &cell, axis, pos);
    drop(refs);
    let at = nodes.len();
    nodes.push(KdNode::leaf(0, 0)); // placeholder until `above` has an index
    build_rec(ctx, rb, cb, depth + 1, nodes, leaf_tris);
    let above_at = nodes.len() as u32;
    build_rec(ctx, ra, ca, depth + 1, nodes, leaf_tris);
    nodes[at] = KdNode::interior(axis as u32, pos, above_at);
}

/// Per axis and slab: how many boxes start there, then how many end there.
fn histogram(ctx: &Ctx, refs: &[Ref], cell: &Aabb) -> Vec<u32> {
    let b = ctx.bins;
    let scale: [f32; 3] = std::array::from_fn(|a| b as f32 / (cell.hi[a] - cell.lo[a]));
    let slab = |a: usize, x: f32| (((x - cell.lo[a]) * scale[a]) as usize).min(b - 1);
    let count = |refs: &[Ref]| {
        let mut h = vec![0u32; 6 * b];
        for r in refs {
            for a in 0..3 {
                h[2 * a * b + slab(a, r.b.lo[a])] += 1;
                h[(2 * a + 1) * b + slab(a, r.b.hi[a])] += 1;
            }
        }
        h
    };
    if refs.len() >= PARALLEL_MIN {
        refs.par_chunks(1 << 14).map(count).reduce(
            || vec![0u32; 6 * b],
            |mut x, y| {
                x.iter_mut().zip(y).for_each(|(x, y)| *x += y);
                x
            },
        )
    } else {
        count(refs)
    }
}

/// The cheapest slab boundary, if it beats a leaf.
fn find_split(ctx: &Ctx, refs: &[Ref], cell: &Aabb, depth: u32) -> Option<(usize, f32)> {
    let n = refs.len();
    let area = cell.area();
    if n <= ctx.leaf_size || depth >= ctx.max_depth || !(area > 0.0 && area.is_finite()) {
        return None;
    }
    let h = histogram(ctx, refs, cell);
    let b = ctx.bins;
    let mut best: Option<(f64, usize, f32)> = None;
    for a in 0..3 {
        let Some(ax) = AxisCost::new(cell, a, ctx.bonus, n) else {
            continue;
        };
        let width = (cell.hi[a] - cell.lo[a]) / b as f32;
        let (starts, ends) = (&h[2 * a * b..][..b], &h[(2 * a + 1) * b..][..b]);
        let (mut nl, mut nr) = (0u32, n as u32);
        for k in 1..b {
            nl += starts[k - 1];
            nr -= ends[k - 1];
            let p = cell.lo[a] + k as f32 * width;
            if !(p > cell.lo[a] && p < cell.hi[a]) {
                continue;
            }
            let (rank, _) = ax.at(p, nl as f64, nr as f64, 0.0);
            if best.is_none_or(|(r, _, _)| rank < r) {
                best = Some((rank, a, p));
            }
        }
    }
    let (rank, axis, pos) = best?;
    (AxisCost::cost(rank, ctx.kt, ctx.ki, area) < ctx.ki * n as f64).then_some((axis, pos))
}

/// The two children's references and cells. A box on one side of the plane (or touching
/// it from one side) goes to that side, one lying in it to both; a straddler is clipped
/// to each child and goes where it reaches.
fn split(
    ctx: &Ctx,
    refs: &[Ref],
    cell: &Aabb,
    axis: usize,
    pos: f32,
) -> ([Vec<Ref>; 2], [Aabb; 2]) {
    let (cb, ca) = cell.split(axis, pos);
    let place = |r: &Ref| -> [Option<Ref>; 2] {
        let (lo, hi) = (r.b.lo[axis], r.b.hi[axis]);
        if lo < pos && hi > pos {
            let t = &ctx.tris[r.tri as usize];
            [&cb, &ca].map(|c| clipped_bounds(t, c).map(|b| Ref { tri: r.tri, b }))
        } else {
            [
                (lo < pos || hi <= pos).then_some(*r),
                (hi > pos || lo >= pos).then_some(*r),
            ]
        }
    };
    let sides = if refs.len() >= PARALLEL_MIN {
        let placed: Vec<[Option<Ref>; 2]> = refs.par_iter().map(place).collect();
        let side = |s: usize| placed.par_iter().filter_map(|p| p[s]).collect::<Vec<_>>();
        let (b, a) = rayon::join(|| side(0), || side(1));
        [b, a]
    } else {
        let (mut b, mut a) = (
            Vec::with_capacity(refs.len()),
            Vec::with_capacity(refs.len()),
        );
        for r in refs {
            let [pb, pa] = place(r);
            b.extend(pb);
            a.extend(pa);
        }
        [b, a]
    };
    (sides, [cb, ca])
}

#[cfg(test)]
mod tests {
    use super::*;
    use kdtree::testkit::{brute, grid, sphere, Rng};
    use kdtree::{Accel, Ray};

    /// Closest hits through the binned tree agree with brute force on a scene of spheres
    /// and a floor, at each slab count.
    #[test]
    fn binned_trees_answer_as_brute_force() {
        let mut tris = sphere(Vec3::new(0.0, 1.0, 0.0), 1.0, 24, 48);
        tris.extend(sphere(Vec3::new(2.5, 0.5, 1.0), 0.5, 16, 32));
        tris.extend(grid(40, 10.0, 0.0));
        let params = BuildParams::default();
        let mut rng = Rng(5);
        let rays: Vec<Ray> = (0..4000)
            .map(|_| {
                let o = Vec3::new(
                    rng.range(-5.0, 5.0),
                    rng.range(0.1, 4.0),
                    rng.range(-5.0, 5.0),
                );
                Ray::new(o, rng.dir(), 0.0, f32::INFINITY)
            })
            .collect();
        for bins in [2, 8, 32] {
            let kd = build_binned(&tris, &params, bins, formats::soup::geometry_hash(&tris));
            kd.validate().unwrap();
            assert!(
                kd.stats.leaves > 100,
                "{bins} slabs: {} leaves",
                kd.stats.leaves
            );
            let a = Accel::from_triangles(&tris, &kd).unwrap();
            let mut hits = 0;
            for r in &rays {
                let (got, want) = (a.intersect(r), brute::intersect(&tris, r));
                assert_eq!(
                    got.map(|h| h.prim),
                    want.map(|h| h.prim),
                    "{bins} slabs, {r:?}"
                );
                assert_eq!(got.map(|h| h.t), want.map(|h| h.t));
                hits += got.is_some() as usize;
            }
            assert!(hits > 400, "{hits} hits");
        }
    }
}
