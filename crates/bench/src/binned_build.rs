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
use kdtree::build::{Costs, Part, Subtree};
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
    costs: Costs,
    max_depth: u32,
    bins: usize,
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
        costs: Costs::of(params),
        max_depth: kdtree::depth_bound(params, refs.len()),
        bins: bins.max(2),
    };
    // No references: one empty leaf, as `find_split` refuses to split them.
    let tree = build_part(&ctx, refs, cell, 0).flatten();
    kdtree::build::finish(triangles.len(), params, geometry_hash, cell, tree, start)
}

fn build_part(ctx: &Ctx, refs: Vec<Ref>, cell: Aabb, depth: u32) -> Part {
    if refs.len() < JOIN_MIN {
        let mut out = Subtree::default();
        build_rec(ctx, refs, cell, depth, &mut out);
        return Part::Flat(out);
    }
    match find_split(ctx, &refs, &cell, depth) {
        None => Part::leaf(refs.iter().map(|r| r.tri).collect()),
        Some((axis, pos)) => {
            let ([rb, ra], [cb, ca]) = split(ctx, &refs, &cell, axis, pos);
            drop(refs);
            let (b, a) = rayon::join(
                || build_part(ctx, rb, cb, depth + 1),
                || build_part(ctx, ra, ca, depth + 1),
            );
            Part::Node {
                axis: axis as u32,
                pos,
                children: Box::new([b, a]),
            }
        }
    }
}

fn build_rec(ctx: &Ctx, refs: Vec<Ref>, cell: Aabb, depth: u32, out: &mut Subtree) {
    let Some((axis, pos)) = find_split(ctx, &refs, &cell, depth) else {
        out.nodes
            .push(KdNode::leaf(refs.len() as u32, out.leaf_tris.len() as u32));
        out.leaf_tris.extend(refs.iter().map(|r| r.tri));
        return;
    };
    let ([rb, ra], [cb, ca]) = split(ctx, &refs, &cell, axis, pos);
    drop(refs);
    let at = out.nodes.len();
    out.nodes.push(KdNode::leaf(0, 0)); // placeholder until `above` has an index
    build_rec(ctx, rb, cb, depth + 1, out);
    let above_at = out.nodes.len() as u32;
    build_rec(ctx, ra, ca, depth + 1, out);
    out.nodes[at] = KdNode::interior(axis as u32, pos, above_at);
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
    if n <= ctx.costs.leaf_size || depth >= ctx.max_depth || !(area > 0.0 && area.is_finite()) {
        return None;
    }
    let h = histogram(ctx, refs, cell);
    let b = ctx.bins;
    let mut best: Option<(f64, usize, f32)> = None;
    for a in 0..3 {
        let Some(ax) = AxisCost::new(cell, a, ctx.costs.bonus, n) else {
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
    (AxisCost::cost(rank, ctx.costs.kt, ctx.costs.ki, area) < ctx.costs.ki * n as f64)
        .then_some((axis, pos))
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
