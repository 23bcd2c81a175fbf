//! The SAH k-d tree compiler (Wald & Havran 2006, "On building fast kd-trees for ray
//! tracing, and on doing that in O(N log N)").
//!
//! * Large cells (above `EVENT_MAX` triangles) keep a plain list of triangle references
//!   with their clipped bounds and find the SAH's cheapest plane by binning first and
//!   sweeping only the slabs that can hold it ([`binned`]): the same plane the full sweep
//!   finds, for far less work.
//! * Smaller cells sort their events once per axis and keep them sorted through the
//!   splits: the triangles that stay on one side keep their events (filtered in order),
//!   only the triangles that straddle the split get new events, from clipping them to each
//!   child cell (perfect splits, see [`clip`]), and those few are sorted and merged in.
//! * Triangles lying in a candidate plane are tried on both sides; a split that cuts off
//!   empty space gets the empty-space bonus; a node becomes a leaf when no split is
//!   cheaper than intersecting all its triangles, at the depth bound, or at `leaf_size`.
//! * Subtrees above `JOIN_MIN` triangles are built in parallel (`rayon::join`); cells of
//!   at least 65,536 references bin and partition on every thread, so both threads work
//!   from the first split on. The parallel subtrees are stitched together once, at the end.

pub mod binned;
pub mod clip;
pub mod events;
pub mod median;
pub mod sah;
pub mod stats;

use crate::aabb::Aabb;
use binned::Ref;
use events::{Event, END, START};
use formats::{BuildParams, KdFile, KdNode};
use glam::Vec3;
use rayon::prelude::*;
use sah::{AxisCost, Best};

/// The traversal stack holds this many entries; the build never goes deeper.
pub const MAX_DEPTH_LIMIT: u32 = 60;

/// Nodes with at least this many triangles work on their three axes in parallel.
const PARALLEL_MIN: usize = 8192;

/// Cells with more triangles than this are split by the binned search; smaller ones by
/// the sorted event lists, which pay off once a cell's events fit the caches.
const EVENT_MAX: usize = 4096;

/// Nodes with at least this many triangles build their two subtrees as parallel tasks:
/// far below `PARALLEL_MIN`, so that uneven subtrees (a floor next to small props) still
/// leave work for the other thread to steal.
const JOIN_MIN: usize = 1024;

/// The depth bound in force: `params.max_depth`, or 8 + 1.3·log2(N) when it is 0, never
/// above [`MAX_DEPTH_LIMIT`].
pub fn depth_bound(params: &BuildParams, n: usize) -> u32 {
    let d = if params.max_depth == 0 {
        (8.0 + 1.3 * (n.max(1) as f64).log2()).round() as u32
    } else {
        params.max_depth
    };
    d.min(MAX_DEPTH_LIMIT)
}

/// The SAH's constants as every builder and [`stats::measure`] price with them: the
/// parameters clamped to where the cost model means something.
#[derive(Clone, Copy, Debug)]
pub struct Costs {
    /// Cost of a traversal step.
    pub kt: f64,
    /// Cost of a triangle test.
    pub ki: f64,
    /// Share of a split's cost waived when one side is empty.
    pub bonus: f64,
    pub leaf_size: usize,
}

impl Costs {
    pub fn of(params: &BuildParams) -> Costs {
        Costs {
            kt: params.traversal_cost.max(0.0) as f64,
            ki: (params.intersect_cost as f64).max(1e-6),
            bonus: (params.empty_bonus as f64).clamp(0.0, 1.0),
            leaf_size: params.leaf_size.max(1) as usize,
        }
    }
}

/// A tree file around a builder's finished arrays: its bounds (`cell`, the finite
/// triangles' box), the statistics measured by walking it, and the time since `start`.
pub fn finish(
    triangles: usize,
    params: &BuildParams,
    geometry_hash: formats::Digest,
    cell: Aabb,
    tree: Subtree,
    start: std::time::Instant,
) -> KdFile {
    let mut kd = KdFile {
        geometry_hash,
        params: *params,
        stats: Default::default(),
        bounds: if cell.is_empty() {
            [Vec3::ZERO; 2]
        } else {
            cell.to_vec3()
        },
        nodes: tree.nodes,
        leaf_tris: tree.leaf_tris,
    };
    kd.stats = stats::measure(&kd, triangles as u64, params);
    kd.stats.build_seconds = start.elapsed().as_secs_f64();
    kd
}

struct Ctx<'a> {
    tris: &'a [[Vec3; 3]],
    kt: f64,
    ki: f64,
    bonus: f64,
    leaf_size: usize,
    max_depth: u32,
    event_max: usize,
}

/// The triangles of one cell: global ids, and per axis the sorted events over local ids.
struct Work {
    tris: Vec<u32>,
    events: [Vec<Event>; 3],
    cell: Aabb,
}

#[derive(Clone, Copy, Debug)]
struct Split {
    /// The plane's rank on its axis ([`sah::AxisCost::at`]) and its SAH cost.
    rank: f64,
    cost: f64,
    axis: usize,
    pos: f32,
    planar_below: bool,
}

/// A flattened subtree: node indices and leaf offsets relative to its own arrays.
#[derive(Default)]
pub struct Subtree {
    pub nodes: Vec<KdNode>,
    pub leaf_tris: Vec<u32>,
}

impl Subtree {
    /// Append `other`, rebasing its child indices and leaf offsets.
    fn append(&mut self, other: Subtree) {
        let nb = self.nodes.len() as u32;
        let tb = self.leaf_tris.len() as u32;
        self.nodes.extend(other.nodes.into_iter().map(|n| {
            if n.is_leaf() {
                KdNode::leaf(n.count(), n.offset() + tb)
            } else {
                KdNode::interior(n.axis() as u32, n.split(), n.above_child() + nb)
            }
        }));
        self.leaf_tris.extend(other.leaf_tris);
    }
}

/// A subtree as the parallel tasks return it: serial parts already flat, the nodes above
/// them (whose children were built as separate tasks) still linked.
pub enum Part {
    Flat(Subtree),
    Node {
        axis: u32,
        pos: f32,
        children: Box<[Part; 2]>,
    },
}

impl Part {
    pub fn leaf(tris: Vec<u32>) -> Part {
        Part::Flat(Subtree {
            nodes: vec![KdNode::leaf(tris.len() as u32, 0)],
            leaf_tris: tris,
        })
    }

    fn sizes(&self) -> (usize, usize) {
        match self {
            Part::Flat(s) => (s.nodes.len(), s.leaf_tris.len()),
            Part::Node { children, .. } => {
                let (b, a) = (children[0].sizes(), children[1].sizes());
                (1 + b.0 + a.0, b.1 + a.1)
            }
        }
    }

    /// Depth-first, below before above: the order a serial build writes.
    fn flatten_into(self, out: &mut Subtree) {
        match self {
            Part::Flat(s) => out.append(s),
            Part::Node {
                axis,
                pos,
                children,
            } => {
                let at = out.nodes.len();
                out.nodes.push(KdNode::leaf(0, 0)); // placeholder until `above` has an index
                let [below, above] = *children;
                below.flatten_into(out);
                let above_at = out.nodes.len() as u32;
                above.flatten_into(out);
                out.nodes[at] = KdNode::interior(axis, pos, above_at);
            }
        }
    }

    /// One copy of every node and leaf list, into arrays of their final size.
    pub fn flatten(self) -> Subtree {
        let (nodes, leaf_tris) = self.sizes();
        let mut out = Subtree {
            nodes: Vec::with_capacity(nodes),
            leaf_tris: Vec::with_capacity(leaf_tris),
        };
        self.flatten_into(&mut out);
        out
    }
}

/// Build a tree over `triangles` (soup order), fewer than [`events::MAX_TRIANGLES`]
/// (callers check; `soup2kd` refuses larger soups). Non-finite triangles are left out (the
/// soup reader refuses them anyway); every other triangle, degenerate ones included, is
/// in the tree, so the tree answers exactly what a brute-force loop would.
pub fn build(
    triangles: &[[Vec3; 3]],
    params: &BuildParams,
    geometry_hash: formats::Digest,
) -> KdFile {
    build_with(triangles, params, geometry_hash, EVENT_MAX)
}

fn build_with(
    triangles: &[[Vec3; 3]],
    params: &BuildParams,
    geometry_hash: formats::Digest,
    event_max: usize,
) -> KdFile {
    let start = std::time::Instant::now();
    let n = triangles.len();
    let Costs {
        kt,
        ki,
        bonus,
        leaf_size,
    } = Costs::of(params);
    let ctx = Ctx {
        tris: triangles,
        kt,
        ki,
        bonus,
        leaf_size,
        max_depth: depth_bound(params, n),
        event_max,
    };
    // Written in place at their final size (a filtered parallel collect would gather
    // pieces and copy them into fresh pages); the rare non-finite triangles are marked,
    // then dropped.
    const NON_FINITE: u32 = u32::MAX;
    let mut refs: Vec<Ref> = triangles
        .par_iter()
        .enumerate()
        .map(|(i, t)| Ref {
            tri: if t.iter().all(|v| v.is_finite()) {
                i as u32
            } else {
                NON_FINITE
            },
            b: Aabb::of_triangle(t),
        })
        .collect();
    // One pass finds the bounds of the finite ones and whether any are to be dropped.
    let (cell, non_finite) = refs
        .par_iter()
        .map(|r| match r.tri {
            NON_FINITE => (Aabb::EMPTY, true),
            _ => (r.b, false),
        })
        .reduce(|| (Aabb::EMPTY, false), |a, b| (a.0.union(&b.0), a.1 | b.1));
    if non_finite {
        refs.retain(|r| r.tri != NON_FINITE);
    }
    let tree = if refs.is_empty() {
        Subtree {
            nodes: vec![KdNode::leaf(0, 0)],
            leaf_tris: vec![],
        }
    } else {
        build_refs(&ctx, refs, cell, 0).flatten()
    };
    finish(n, params, geometry_hash, cell, tree, start)
}

fn build_refs(ctx: &Ctx, refs: Vec<Ref>, cell: Aabb, depth: u32) -> Part {
    let n = refs.len();
    if n <= ctx.event_max {
        return build_events(ctx, binned::to_work(refs, cell), depth);
    }
    let leaf = |refs: Vec<Ref>| Part::leaf(refs.iter().map(|r| r.tri).collect());
    if n <= ctx.leaf_size || depth >= ctx.max_depth {
        return leaf(refs);
    }
    let split = match binned::find_split(ctx, &refs, &cell) {
        binned::Search::Found(Some(s)) if s.cost < ctx.ki * n as f64 => s,
        binned::Search::Found(_) => return leaf(refs),
        binned::Search::Crowded => {
            return build_events(ctx, binned::to_work(refs, cell), depth);
        }
    };
    let [(rb, cb), (ra, ca)] = binned::split(ctx, refs, &cell, &split);
    let (b, a) = rayon::join(
        || build_refs(ctx, rb, cb, depth + 1),
        || build_refs(ctx, ra, ca, depth + 1),
    );
    Part::Node {
        axis: split.axis as u32,
        pos: split.pos,
        children: Box::new([b, a]),
    }
}

fn build_events(ctx: &Ctx, w: Work, depth: u32) -> Part {
    let n = w.tris.len();
    if n < JOIN_MIN {
        let mut out = Subtree::default();
        build_rec(ctx, w, depth, &mut out, &mut Scratch::default());
        return Part::Flat(out);
    }
    if n <= ctx.leaf_size || depth >= ctx.max_depth {
        return Part::leaf(w.tris);
    }
    let parallel = n >= PARALLEL_MIN;
    let split = match find_split(ctx, &w, parallel) {
        Some(s) if s.cost < ctx.ki * n as f64 => s,
        _ => return Part::leaf(w.tris),
    };
    let (below, above) = split_work(ctx, w, &split, parallel, &mut Scratch::default());
    let (b, a) = rayon::join(
        || build_events(ctx, below, depth + 1),
        || build_events(ctx, above, depth + 1),
    );
    Part::Node {
        axis: split.axis as u32,
        pos: split.pos,
        children: Box::new([b, a]),
    }
}

fn make_leaf(w: Work, out: &mut Subtree, scratch: &mut Scratch) {
    out.nodes.push(KdNode::leaf(
        w.tris.len() as u32,
        out.leaf_tris.len() as u32,
    ));
    out.leaf_tris.extend_from_slice(&w.tris);
    scratch.recycle(w);
}

/// The serial build below `JOIN_MIN` triangles, straight into one flat subtree.
fn build_rec(ctx: &Ctx, w: Work, depth: u32, out: &mut Subtree, scratch: &mut Scratch) {
    let n = w.tris.len();
    if n <= ctx.leaf_size || depth >= ctx.max_depth {
        return make_leaf(w, out, scratch);
    }
    let split = match find_split(ctx, &w, false) {
        Some(s) if s.cost < ctx.ki * n as f64 => s,
        _ => return make_leaf(w, out, scratch),
    };
    let (below, above) = split_work(ctx, w, &split, false, scratch);
    let at = out.nodes.len();
    out.nodes.push(KdNode::leaf(0, 0)); // placeholder, set once `above` has an index
    build_rec(ctx, below, depth + 1, out, scratch);
    let above_at = out.nodes.len() as u32;
    build_rec(ctx, above, depth + 1, out, scratch);
    out.nodes[at] = KdNode::interior(split.axis as u32, split.pos, above_at);
}

/// The cheapest split of the cell that beats a leaf (None when no plane does).
fn find_split(ctx: &Ctx, w: &Work, parallel: bool) -> Option<Split> {
    let area = w.cell.area();
    if !(area > 0.0) || !area.is_finite() {
        return None;
    }
    let n = w.tris.len();
    // Planes ranked at or above this cost at least a leaf: no sweep needs to look at them.
    let leaf = leaf_rank(ctx, n, area);
    let sweep = |axis: usize, beat: f64| {
        let ax = AxisCost::new(&w.cell, axis, ctx.bonus, n)?;
        let mut best = Best {
            rank: beat,
            at: None,
        };
        sah::sweep(&ax, &w.events[axis], 0.0, n as f64, &mut best);
        best.at.map(|(pos, planar_below)| Split {
            rank: best.rank,
            cost: AxisCost::cost(best.rank, ctx.kt, ctx.ki, area),
            axis,
            pos,
            planar_below,
        })
    };
    let best = if parallel {
        let (a, (b, c)) = rayon::join(
            || sweep(0, leaf),
            || rayon::join(|| sweep(1, leaf), || sweep(2, leaf)),
        );
        [a, b, c]
    } else {
        // Each axis only has to beat the ranks found on the axes before it: a plane ranked
        // no lower than an earlier axis's best costs no less, and equal costs go to the
        // earlier axis anyway.
        let a = sweep(0, leaf);
        let b = sweep(1, a.map_or(leaf, |s| s.rank));
        let c = sweep(
            2,
            [&a, &b]
                .into_iter()
                .flatten()
                .fold(leaf, |r, s| r.min(s.rank)),
        );
        [a, b, c]
    };
    best.into_iter()
        .flatten()
        .min_by(|a, b| a.cost.total_cmp(&b.cost))
}

/// A rank at and above which a plane's SAH cost is no less than the leaf's, `ki · n`: the
/// threshold solved for, then raised until the cost formula itself, monotone in the rank,
/// confirms it.
fn leaf_rank(ctx: &Ctx, n: usize, area: f64) -> f64 {
    let leaf = ctx.ki * n as f64;
    let mut rank = ((leaf - ctx.kt) * area / (2.0 * ctx.ki)).max(0.0);
    for _ in 0..64 {
        if !rank.is_finite() {
            break;
        }
        if AxisCost::cost(rank, ctx.kt, ctx.ki, area) >= leaf {
            return rank;
        }
        // A few ulps usually do; steps grow so that a cost dominated by `kt` gets there too.
        rank = (rank * (1.0 + 4.0 * f64::EPSILON)).max(rank.next_up());
    }
    f64::INFINITY
}

// A triangle's side of a split; then its place: in the low 2 bits the child that keeps it
// (BELOW or ABOVE; 0 for a straddler, whose events no child keeps) and above them its local
// index in that child.
const BELOW: u32 = 1;
const ABOVE: u32 = 2;
const BOTH: u32 = 3;

/// The working lists of a split that do not outlive it, kept from one split to the next of
/// a serial build instead of allocated and freed at every node.
#[derive(Default)]
struct Scratch {
    place: Vec<u32>,
    straddlers: Vec<usize>,
    clipped: Vec<(Option<Aabb>, Option<Aabb>)>,
    /// Per child: the straddlers that reach into it (local index in the child, clipped box).
    new: [Vec<(u32, Aabb)>; 2],
    /// Both children's fresh events of one axis.
    fresh: Vec<Event>,
    /// The lists of cells already split or made leaves, handed out again for children's
    /// lists: a serial build then allocates only while its lists grow deeper.
    spare_tris: Vec<Vec<u32>>,
    spare_events: Vec<Vec<Event>>,
}

impl Scratch {
    fn recycle(&mut self, w: Work) {
        self.spare_tris.push(w.tris);
        self.spare_events.extend(w.events);
    }

    /// An empty list from the spares (the last given back: the largest, most often).
    fn events(&mut self) -> Vec<Event> {
        let mut v = self.spare_events.pop().unwrap_or_default();
        v.clear();
        v
    }

    fn tris(&mut self) -> Vec<u32> {
        let mut v = self.spare_tris.pop().unwrap_or_default();
        v.clear();
        v
    }
}

/// Classify the triangles against the split and build both children's work, keeping each
/// axis's events sorted.
fn split_work(
    ctx: &Ctx,
    w: Work,
    s: &Split,
    parallel: bool,
    scratch: &mut Scratch,
) -> (Work, Work) {
    let n = w.tris.len();
    // Lists for the children, from the spares (empty ones in a parallel split: the three
    // axes' partitions then allocate their own).
    let (mut tris_b, mut tris_a) = (scratch.tris(), scratch.tris());
    let mut lists: [[Vec<Event>; 2]; 3] = Default::default();
    if !parallel {
        for l in lists.iter_mut().flatten() {
            *l = scratch.events();
        }
    }
    let Scratch {
        place,
        straddlers,
        clipped,
        new: [new_b, new_a],
        fresh,
        ..
    } = scratch;
    place.clear();
    place.resize(n, BOTH);
    // The split axis's events are sorted, so the ones before, at and after the plane are
    // three runs; before and after are classified without branching on the kind.
    let ev = &w.events[s.axis];
    let split_key = events::ordered(s.pos);
    let at = ev.partition_point(|e| e.pos_key() < split_key);
    let after = at + ev[at..].partition_point(|e| e.pos_key() == split_key);
    for e in &ev[..at] {
        // Ends and planars before the plane are below. A start before the plane comes
        // before its own end, so its triangle is still undecided there.
        place[e.tri() as usize] = if e.kind() == START { BOTH } else { BELOW };
    }
    for e in &ev[at..after] {
        let t = e.tri() as usize;
        match e.kind() {
            END => place[t] = BELOW,
            START => place[t] = ABOVE,
            _ => place[t] = if s.planar_below { BELOW } else { ABOVE },
        }
    }
    for e in &ev[after..] {
        // Starts and planars after the plane are above; an end there keeps what its start
        // decided.
        let t = e.tri() as usize;
        place[t] = if e.kind() == END { place[t] } else { ABOVE };
    }
    let (cell_b, cell_a) = w.cell.split(s.axis, s.pos);
    // Local indices in each child: kept triangles first in parent order, then straddlers.
    // Branch-free as well: each triangle is written to both lists and to the straddlers,
    // and only the one its side names advances.
    let kept_b = place.iter().filter(|&&p| p == BELOW).count();
    let n_both = place.iter().filter(|&&p| p == BOTH).count();
    let kept_a = n - kept_b - n_both;
    tris_b.resize(kept_b + n_both + 1, 0);
    tris_a.resize(kept_a + n_both + 1, 0);
    straddlers.clear();
    straddlers.resize(n_both + 1, 0);
    let (mut nb, mut na, mut ns) = (0, 0, 0);
    for (i, (p, &t)) in place.iter_mut().zip(&w.tris).enumerate() {
        let side = *p;
        tris_b[nb] = t;
        tris_a[na] = t;
        straddlers[ns] = i;
        let index = if side == BELOW { nb } else { na };
        let kept = if side == BOTH { 0 } else { side };
        *p = kept | (index as u32) << 2;
        nb += (side == BELOW) as usize;
        na += (side == ABOVE) as usize;
        ns += (side == BOTH) as usize;
    }
    tris_b.truncate(nb);
    tris_a.truncate(na);
    straddlers.truncate(ns);
    // Straddling triangles: clip to each child (perfect splits). A triangle whose box
    // straddles the plane may still miss one child entirely; it then leaves that child.
    let clip = |&i: &usize| {
        let tri = &ctx.tris[w.tris[i] as usize];
        (
            clip::clipped_bounds(tri, &cell_b),
            clip::clipped_bounds(tri, &cell_a),
        )
    };
    clipped.clear();
    if straddlers.len() > 4096 {
        straddlers.par_iter().map(clip).collect_into_vec(clipped);
    } else {
        clipped.extend(straddlers.iter().map(clip));
    }
    new_b.clear();
    new_a.clear();
    for (&i, (cb, ca)) in straddlers.iter().zip(clipped.iter()) {
        if let Some(b) = cb {
            new_b.push((tris_b.len() as u32, *b));
            tris_b.push(w.tris[i]);
        }
        if let Some(b) = ca {
            new_a.push((tris_a.len() as u32, *b));
            tris_a.push(w.tris[i]);
        }
    }
    let (new_b, new_a, place) = (&*new_b, &*new_a, &*place);
    let child_events = |axis: usize,
                        ev: &[Event],
                        fresh: &mut Vec<Event>,
                        [mut eb, mut ea]: [Vec<Event>; 2]|
     -> (Vec<Event>, Vec<Event>) {
        // Both children's fresh events in one list: the below child's, then the above's.
        fresh.clear();
        for (t, b) in new_b {
            events::push_events(fresh, b, axis, *t);
        }
        let mid = fresh.len();
        for (t, b) in new_a {
            events::push_events(fresh, b, axis, *t);
        }
        let (fb, fa) = fresh.split_at_mut(mid);
        events::sort(fb, false);
        events::sort(fa, false);
        partition(ev, place, [fb, fa], [&mut eb, &mut ea]);
        (eb, ea)
    };
    let [ex, ey, ez] = &w.events;
    let [lx, ly, lz] = lists;
    let ((bx, ax), ((by, ay), (bz, az))) = if parallel {
        rayon::join(
            || child_events(0, ex, &mut Vec::new(), lx),
            || {
                rayon::join(
                    || child_events(1, ey, &mut Vec::new(), ly),
                    || child_events(2, ez, &mut Vec::new(), lz),
                )
            },
        )
    } else {
        (
            child_events(0, ex, fresh, lx),
            (
                child_events(1, ey, fresh, ly),
                child_events(2, ez, fresh, lz),
            ),
        )
    };
    scratch.recycle(w);
    (
        Work {
            tris: tris_b,
            events: [bx, by, bz],
            cell: cell_b,
        },
        Work {
            tris: tris_a,
            events: [ax, ay, az],
            cell: cell_a,
        },
    )
}

/// One axis's events of both children, in one pass over the parent's: the events of the
/// triangles each child keeps (`place`), in order and renumbered, with the child's `fresh`
/// events (sorted) merged in. `out` are the children's lists, empty.
fn partition(ev: &[Event], place: &[u32], fresh: [&[Event]; 2], out: [&mut Vec<Event>; 2]) {
    let [fb, fa] = fresh;
    let [eb, ea] = out;
    // Room for every event and every fresh event: each step below writes at most one of
    // either, so the counts stay below the capacities without a check per write.
    debug_assert!(eb.is_empty() && ea.is_empty());
    eb.reserve(ev.len() + fb.len() + 1);
    ea.reserve(ev.len() + fa.len() + 1);
    let (pb, pa) = (eb.as_mut_ptr(), ea.as_mut_ptr());
    let (mut nb, mut na, mut jb, mut ja, mut i) = (0, 0, 0, 0, 0);
    let key = |f: &[Event], j: usize| f.get(j).map_or(u64::MAX, |f| f.pos_kind());
    loop {
        // A fresh event goes after every parent event of a lower or equal position and
        // kind (it follows the kept ones at equal position and kind, whose indices are
        // lower). The parent's events run in a tight loop up to where the nearer of the
        // two children's next fresh events goes in.
        let next = key(fb, jb).min(key(fa, ja));
        while let Some(&e) = ev.get(i) {
            if e.pos_kind() > next {
                break;
            }
            let p = place[e.tri() as usize];
            let moved = e.with_tri(p >> 2);
            // Branch-free: every event is written to both lists and kept where its side
            // says (sides are random along the other axes, a branch would mispredict).
            debug_assert!(nb <= i + jb && na <= i + ja);
            // SAFETY: `nb` grows by at most one per parent event before this one (`i` of
            // them) and by one per fresh event written (`jb ≤ fb.len()`), so
            // `nb ≤ i + jb < ev.len() + fb.len() + 1`, within the capacity `pb` points at,
            // and `eb` is not touched until the end; likewise `na`.
            unsafe {
                pb.add(nb).write(moved);
                pa.add(na).write(moved);
            }
            nb += (p & BELOW) as usize;
            na += (p >> 1 & 1) as usize;
            i += 1;
        }
        // The fresh events that go before the parent's next event (at the end, all left).
        let limit = ev.get(i).map_or(u64::MAX, |e| e.pos_kind());
        while key(fb, jb) < limit {
            // SAFETY: as above, with `jb < fb.len()` and `i ≤ ev.len()`.
            unsafe { pb.add(nb).write(fb[jb]) };
            (nb, jb) = (nb + 1, jb + 1);
        }
        while key(fa, ja) < limit {
            // SAFETY: as above.
            unsafe { pa.add(na).write(fa[ja]) };
            (na, ja) = (na + 1, ja + 1);
        }
        if i == ev.len() {
            break;
        }
    }
    // SAFETY: the first `nb` (`na`) elements were written above, within the capacity.
    unsafe {
        eb.set_len(nb);
        ea.set_len(na);
    }
}
