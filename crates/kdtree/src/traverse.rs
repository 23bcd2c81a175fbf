//! k-d tree traversal with a fixed-size stack: front to back for closest hits and for
//! any-hit queries whose filter gathers along the ray, far child first for the other
//! any-hit queries ([`take_step_far_first`]).
//!
//! Robustness rules (docs/ROBUSTNESS.md):
//! * A direction component that is ±0 (or so small that its reciprocal overflows) makes
//!   the ray parallel to that axis's planes: the box test decides from the origin alone,
//!   and at a split the plane distance (split − o)·(±∞) is ±∞ on the origin's side, so
//!   that child alone is visited; a ray lying *in* a split plane (0·∞ = NaN) visits both
//!   children over its whole interval.
//! * Which child comes first is decided by the direction's sign alone (front to back, the
//!   child the ray comes from, then the one it goes to; far first, the other way round), so
//!   an origin on a split plane is handled by the same code as every other origin.
//! * The plane distance is compared with the cell's interval padded by a few ulps, so a
//!   cell the ray only grazes is visited rather than skipped by rounding.
//! * NaN or infinite rays, zero directions and empty intervals are misses, never a hang.
//!
//! This is the product's only traversal; the textbook variant that measures what these
//! rules cost lives in the bench crate.

use crate::aabb::Aabb;
use crate::triangle::{self, Hits4, RawHit, RayPre};
use crate::Ray;
use formats::{Hit, KdNode};
use std::mem::MaybeUninit;

/// What a traversal did, for benchmarks that explain its cost: interior nodes stepped
/// through, leaves reached and triangle tests (a four-wide group counts its real entries).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counts {
    pub nodes: u64,
    pub leaves: u64,
    pub tests: u64,
}

/// Where a traversal reports its steps. The plain queries use `()`, whose methods are
/// empty, so counting costs them nothing once inlined.
pub(crate) trait Counter {
    fn node(&mut self);
    fn leaf(&mut self, tests: usize);
}

impl Counter for () {
    #[inline(always)]
    fn node(&mut self) {}
    #[inline(always)]
    fn leaf(&mut self, _tests: usize) {}
}

impl Counter for Counts {
    #[inline(always)]
    fn node(&mut self) {
        self.nodes += 1;
    }
    #[inline(always)]
    fn leaf(&mut self, tests: usize) {
        self.leaves += 1;
        self.tests += tests as u64;
    }
}

/// Entries of the traversal stack (≥ the build's depth bound, which is at most 60).
pub const STACK: usize = 64;

/// Cell intervals are padded by [`triangle::PAD`]: a few ulps of the plane-distance
/// computation ((s − o)·(1/d) rounds three times). Up is `triangle::widen`'s padding.
#[inline(always)]
fn pad_up(t: f32) -> f32 {
    triangle::widen(t)
}

/// The lower end of a cell's interval, padded the same way down.
///
/// A spawned ray's interval starts at `f32::MIN_POSITIVE` (it excludes t = 0 and
/// subnormal t), whose padding is subnormal, and Intel cores take a microcode assist of
/// about a hundred cycles for every subnormal result. So each walk pads a lower end once,
/// when its interval starts, not at every step, and that one value comes from
/// [`MIN_POSITIVE_PADDED`].
#[inline(always)]
pub(crate) fn pad_down(t: f32) -> f32 {
    // The compiler computes both arms and selects, and it would pad `t` itself in both
    // (the result is the constant either way); the arithmetic pads 1 instead, behind a
    // value it cannot see through.
    let spawned = t == f32::MIN_POSITIVE;
    let x = std::hint::black_box(if spawned { 1.0 } else { t });
    let padded = x - x.abs() * triangle::PAD;
    if spawned {
        MIN_POSITIVE_PADDED
    } else {
        padded
    }
}

/// `pad_down(f32::MIN_POSITIVE)` as the compiler works it out: IEEE arithmetic, subnormals
/// included, so the same bits the processor would round to, without the assist.
pub(crate) const MIN_POSITIVE_PADDED: f32 = f32::MIN_POSITIVE - f32::MIN_POSITIVE * triangle::PAD;

pub(crate) struct Tree<'a> {
    pub tris: &'a [[[f32; 3]; 3]],
    pub soup_index: &'a [u32],
    pub nodes: &'a [KdNode],
    pub leaf_tris: &'a [u32],
    pub bounds: &'a Aabb,
}

/// Per-ray traversal constants.
#[derive(Clone, Copy)]
pub(crate) struct Setup {
    pub pre: RayPre,
    pub o: [f32; 3],
    pub inv: [f32; 3],
    pub t0: f32,
    /// `pad_down(t0)`, worked out once: see [`pad_down`].
    pub t0_pad: f32,
    pub t1: f32,
}

/// None when the ray cannot hit anything (bad numbers, empty interval, misses the box).
#[inline(always)]
pub(crate) fn setup(ray: &Ray, b: &Aabb) -> Option<Setup> {
    if !(ray.tmin <= ray.tmax) || ray.tmax == f32::NEG_INFINITY || ray.tmin == f32::INFINITY {
        return None;
    }
    let pre = RayPre::new(ray.origin, ray.dir)?;
    let o = ray.origin.to_array();
    let d = ray.dir.to_array();
    let inv = [1.0 / d[0], 1.0 / d[1], 1.0 / d[2]];
    let parallel = [
        !inv[0].is_finite(),
        !inv[1].is_finite(),
        !inv[2].is_finite(),
    ];
    let (mut t0, mut t1) = (ray.tmin, ray.tmax);
    for a in 0..3 {
        if parallel[a] {
            if o[a] < b.lo[a] || o[a] > b.hi[a] {
                return None;
            }
        } else {
            let ta = (b.lo[a] - o[a]) * inv[a];
            let tb = (b.hi[a] - o[a]) * inv[a];
            let (near, far) = if inv[a] > 0.0 { (ta, tb) } else { (tb, ta) };
            t0 = t0.max(near);
            t1 = t1.min(far);
        }
    }
    let t0_pad = pad_down(t0);
    (t0_pad <= pad_up(t1)).then_some(Setup {
        pre,
        o,
        inv,
        t0,
        t0_pad,
        t1,
    })
}

#[inline(always)]
fn test<const KZ: usize>(
    pre: &RayPre,
    ray: &Ray,
    tri: &[[f32; 3]; 3],
    tmax: f32,
) -> Option<RawHit> {
    triangle::intersect_along::<KZ>(pre, tri, ray.tmin, tmax)
}

/// Children of interior node `i` to visit, in order, with their intervals.
enum Step {
    One(u32),
    /// Both children: `first` over [t0, min(t_split, t1)], `second` over
    /// [max(t_split, t0), t1] (see [`near_end`] and [`far_start`]).
    Two {
        first: u32,
        second: u32,
        t_split: f32,
    },
}

/// End of the first child's interval. A NaN `t_split` (a ray in the split plane, below)
/// gives the whole interval; `t_split` beyond `t1` (within the padding) gives `t1`.
#[inline(always)]
fn near_end(t_split: f32, t1: f32) -> f32 {
    if t_split <= t1 {
        t_split
    } else {
        t1
    }
}

/// Start of the second child's interval; NaN gives `t0`, as in [`near_end`].
#[inline(always)]
fn far_start(t_split: f32, t0: f32) -> f32 {
    if t_split >= t0 {
        t_split
    } else {
        t0
    }
}

/// No case is needed for rays parallel to the split plane (a direction component of ±0,
/// or one whose reciprocal overflowed): `inv` is then ±∞ with the direction's sign, so the
/// plane distance is ±∞ on the side the origin is on and picks that child alone by the
/// same comparisons as every other ray, and a ray lying in the plane gets 0·∞ = NaN,
/// which no comparison accepts: both children, over the whole interval ([`near_end`],
/// [`far_start`]).
#[inline(always)]
fn step(s: &Setup, i: u32, node: KdNode, t0_pad: f32, t1: f32) -> Step {
    let a = node.axis();
    let below = i + 1;
    let above = node.above_child();
    let tp = (node.split() - s.o[a]) * s.inv[a];
    // The ray comes from the side opposite its direction and goes to the other.
    let (first, second) = if s.inv[a] > 0.0 {
        (below, above)
    } else {
        (above, below)
    };
    if tp > pad_up(t1) {
        Step::One(first)
    } else if tp < t0_pad {
        Step::One(second)
    } else {
        Step::Two {
            first,
            second,
            t_split: tp,
        }
    }
}

/// Far children waiting with their intervals. Left uninitialised: zeroing 768 bytes per
/// ray was a memset call on every ray. Entries below the stack length are always written
/// before they are read (`pop`).
type Stack = [MaybeUninit<(u32, f32, f32)>; STACK];

/// A new, empty stack.
#[inline(always)]
fn new_stack() -> Stack {
    [MaybeUninit::uninit(); STACK]
}

/// The entry below `sp`, which a push wrote (every push writes `stack[sp]` before the
/// length can grow past it).
#[inline(always)]
fn pop(stack: &Stack, sp: usize) -> (u32, f32, f32) {
    // SAFETY: callers pop only below the length, and each entry below the length was
    // written by the push that grew the length past it.
    unsafe { stack[sp].assume_init() }
}

/// One interior step: moves to the next cell (`node_i`, and `t1` when the far child waits)
/// and pushes the far child with its interval when the ray crosses the plane. Branches on
/// `step`: right for closest-hit rays, where a predicted branch lets the next node's load
/// start before the plane distance is known (branch-free, random rays lost 10–15 %).
///
/// The cursor (node, interval, stack and its length) stays in separate locals: bundled
/// into a struct it cost 4–12 % of ray speed.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn take_step(
    s: &Setup,
    node: KdNode,
    node_i: &mut u32,
    t0: f32,
    t0_pad: f32,
    t1: &mut f32,
    stack: &mut Stack,
    sp: &mut usize,
) {
    match step(s, *node_i, node, t0_pad, *t1) {
        Step::One(c) => *node_i = c,
        Step::Two {
            first,
            second,
            t_split,
        } => {
            stack[*sp] = MaybeUninit::new((second, far_start(t_split, t0), *t1));
            *sp += 1;
            *node_i = first;
            *t1 = near_end(t_split, *t1);
        }
    }
}

/// `take_step` for any-hit (shadow) rays, whose choice of children changes from ray to
/// ray and mispredicts: branch-free (the far child is always written
/// and the stack only grows when both children are visited; the cases and their order are
/// `step`'s), with the far child's node prefetched, as it is the next node or waits on
/// the stack. Shadow rays +10–12 %.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn take_step_branch_free(
    nodes: &[KdNode],
    s: &Setup,
    node: KdNode,
    node_i: &mut u32,
    t0: f32,
    t0_pad: f32,
    t1: &mut f32,
    stack: &mut Stack,
    sp: &mut usize,
) {
    let a = node.axis();
    let below = *node_i + 1;
    let above = node.above_child();
    let tp = (node.split() - s.o[a]) * s.inv[a];
    let first = if s.inv[a] > 0.0 { below } else { above };
    let second = below ^ above ^ first;
    prefetch(nodes.as_ptr().wrapping_add(second as usize));
    let only_first = tp > pad_up(*t1);
    let only_second = !only_first & (tp < t0_pad);
    let both = !only_first & !only_second;
    stack[*sp] = MaybeUninit::new((second, far_start(tp, t0), *t1));
    *sp += usize::from(both);
    *node_i = if only_second { second } else { first };
    *t1 = if both { near_end(tp, *t1) } else { *t1 };
}

/// The interior step of an any-hit walk that takes the far child first. Whether a
/// blocker exists does not depend on the order, and a ray leaving a surface finds a blocker
/// sooner from the far end: its near cells hold the surface it leaves, whose triangles
/// rarely block it (blocked bunny surface rays: 30 steps and 16 triangle tests instead of 45
/// and 34). Branches rather than selects, as `take_step` does: written with selects as
/// `take_step_branch_free` is, unblocked rays visited the same cells at two thirds of the
/// speed (and as slowly with the scene mirrored, so not for the nodes' layout).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn take_step_far_first(
    s: &Setup,
    node: KdNode,
    node_i: &mut u32,
    t0: &mut f32,
    t0_pad: &mut f32,
    t1: f32,
    stack: &mut Stack,
    sp: &mut usize,
) {
    // `step` names the children in front-to-back order: `first` is the near one.
    match step(s, *node_i, node, *t0_pad, t1) {
        Step::One(c) => *node_i = c,
        Step::Two {
            first,
            second,
            t_split,
        } => {
            stack[*sp] = MaybeUninit::new((first, *t0, near_end(t_split, t1)));
            *sp += 1;
            *node_i = second;
            *t0 = far_start(t_split, *t0);
            *t0_pad = pad_down(*t0);
        }
    }
}

/// Asks for the cache line at `p` ahead of its use; a no-op elsewhere than x86_64.
#[inline(always)]
fn prefetch<T>(p: *const T) {
    #[cfg(target_arch = "x86_64")]
    {
        use core::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
        // SAFETY: a prefetch never faults and reads nothing; SSE is part of x86_64.
        unsafe { _mm_prefetch::<_MM_HINT_T0>(p.cast()) };
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = p;
}

impl Tree<'_> {
    #[inline(always)]
    pub(crate) fn node(&self, i: u32) -> KdNode {
        debug_assert!((i as usize) < self.nodes.len());
        // SAFETY: `Accel::assemble` ran `KdFile::validate`, which proves every child index
        // (i + 1 and `above_child`) of an interior node is inside `nodes`; traversal only
        // visits node 0 and such children.
        unsafe { *self.nodes.get_unchecked(i as usize) }
    }

    #[inline(always)]
    pub(crate) fn leaf(&self, node: KdNode) -> &[u32] {
        let off = node.offset() as usize;
        let end = off + node.count() as usize;
        debug_assert!(end <= self.leaf_tris.len());
        // SAFETY: `KdFile::validate` proves offset + count ≤ leaf_tris.len() for leaves.
        unsafe { self.leaf_tris.get_unchecked(off..end) }
    }

    #[inline(always)]
    pub(crate) fn tri(&self, p: u32) -> &[[f32; 3]; 3] {
        debug_assert!((p as usize) < self.tris.len());
        // SAFETY: `Accel::assemble` renumbers every leaf entry to the position where it
        // pushed that triangle into `tris`, so each entry is < tris.len().
        unsafe { self.tris.get_unchecked(p as usize) }
    }

    /// The watertight test on a group of 1–4 leaf entries; returns the entries lane by lane.
    /// A short group repeats its last entry in the lanes beyond it, which report no hit, so
    /// that no filter is asked twice about one triangle (a face passed would count twice).
    #[inline(always)]
    fn test4<const KZ: usize>(
        &self,
        pre: &RayPre,
        ray: &Ray,
        group: &[u32],
        tmax: f32,
    ) -> ([u32; 4], Hits4) {
        let last = group[group.len() - 1];
        let lanes: [u32; 4] = std::array::from_fn(|l| *group.get(l).unwrap_or(&last));
        let tris = lanes.map(|p| self.tri(p));
        let mut hits = triangle::intersect4_along::<KZ>(pre, tris, ray.tmin, tmax);
        hits.hit[group.len()..].fill(false);
        (lanes, hits)
    }

    #[inline(always)]
    pub(crate) fn soup_index(&self, p: u32) -> u32 {
        debug_assert!((p as usize) < self.soup_index.len());
        // SAFETY: as for `tri`: `soup_index` has one entry per element of `tris`.
        unsafe { *self.soup_index.get_unchecked(p as usize) }
    }

    /// Closest hit in [tmin, tmax]; ties in t go to the lower triangle index (so the
    /// answer is the brute-force loop's, whatever the leaf order).
    /// `accept` sees each candidate that would become the best hit (soup index, t, u, v)
    /// and may refuse it (a culled face, a cut-out texel); refused hits are passed through
    /// inside the same traversal, with no restart from the root.
    #[inline(always)]
    pub fn closest<F: FnMut(&Hit, bool) -> bool, C: Counter>(
        &self,
        ray: &Ray,
        mut accept: F,
        count: &mut C,
    ) -> Option<Hit> {
        let s = setup(ray, self.bounds)?;
        // One instantiation per dominant axis: the triangle test's permutation is then a
        // constant (see `triangle::intersect_along`).
        match s.pre.kz {
            0 => self.closest_along::<0, F, C>(ray, &s, &mut accept, count),
            1 => self.closest_along::<1, F, C>(ray, &s, &mut accept, count),
            _ => self.closest_along::<2, F, C>(ray, &s, &mut accept, count),
        }
    }

    #[inline(always)]
    fn closest_along<const KZ: usize, F: FnMut(&Hit, bool) -> bool, C: Counter>(
        &self,
        ray: &Ray,
        s: &Setup,
        accept: &mut F,
        count: &mut C,
    ) -> Option<Hit> {
        let mut best = Hit::MISS;
        let mut best_t = ray.tmax;
        let mut stack = new_stack();
        let mut sp = 0;
        let (mut node_i, mut t0, mut t0_pad, mut t1) = (0u32, s.t0, s.t0_pad, s.t1);
        loop {
            let node = self.node(node_i);
            if !node.is_leaf() {
                count.node();
                take_step(
                    s,
                    node,
                    &mut node_i,
                    t0,
                    t0_pad,
                    &mut t1,
                    &mut stack,
                    &mut sp,
                );
                continue;
            }
            let leaf = self.leaf(node);
            count.leaf(leaf.len());
            self.leaf_closest::<KZ, F>(&s.pre, ray, leaf, &mut best, &mut best_t, accept);
            // Next cell: the first waiting one that starts before the best hit. The stack
            // is not always front to back, so a cell that starts beyond the hit is skipped,
            // not taken as the end: a ray lying in a split plane waits on the far child over
            // its whole interval, and cells pushed later inside the near child may start
            // after it.
            loop {
                if sp == 0 {
                    return (!best.is_miss()).then_some(best);
                }
                sp -= 1;
                (node_i, t0, t1) = pop(&stack, sp);
                t0_pad = pad_down(t0);
                if best_t >= t0_pad {
                    break;
                }
            }
        }
    }

    /// A leaf's triangles for a closest-hit walk: keeps the closer hits `accept` takes.
    #[inline(always)]
    pub(crate) fn leaf_closest<const KZ: usize, F: FnMut(&Hit, bool) -> bool>(
        &self,
        pre: &RayPre,
        ray: &Ray,
        leaf: &[u32],
        best: &mut Hit,
        best_t: &mut f32,
        accept: &mut F,
    ) {
        if leaf.len() >= 2 {
            for group in leaf.chunks(4) {
                let bound = triangle::widen(*best_t);
                let (lanes, hits) = self.test4::<KZ>(pre, ray, group, bound);
                for l in hits.hit_lanes() {
                    let p = self.soup_index(lanes[l]);
                    keep_closer(best, best_t, p, hits.raw(l), accept);
                }
            }
        } else {
            for &p in leaf {
                if let Some(h) = test::<KZ>(pre, ray, self.tri(p), triangle::widen(*best_t)) {
                    keep_closer(best, best_t, self.soup_index(p), h, accept);
                }
            }
        }
    }

    /// Whether any triangle that `blocks` (soup index, t, u, v) is hit in [tmin, tmax];
    /// stops at the first one found. `FAR_FIRST` walks the far child of each node first
    /// ([`take_step_far_first`]), for queries whose answer cannot depend on the order;
    /// otherwise the walk goes front to back, the order filters that gather along the ray
    /// (a product of transmittances) rely on.
    #[inline(always)]
    pub fn any<const FAR_FIRST: bool, F: FnMut(&Hit, bool) -> bool, C: Counter>(
        &self,
        ray: &Ray,
        mut blocks: F,
        count: &mut C,
    ) -> bool {
        let Some(s) = setup(ray, self.bounds) else {
            return false;
        };
        match s.pre.kz {
            0 => self.any_along::<0, FAR_FIRST, F, C>(ray, &s, &mut blocks, count),
            1 => self.any_along::<1, FAR_FIRST, F, C>(ray, &s, &mut blocks, count),
            _ => self.any_along::<2, FAR_FIRST, F, C>(ray, &s, &mut blocks, count),
        }
    }

    #[inline(always)]
    fn any_along<
        const KZ: usize,
        const FAR_FIRST: bool,
        F: FnMut(&Hit, bool) -> bool,
        C: Counter,
    >(
        &self,
        ray: &Ray,
        s: &Setup,
        blocks: &mut F,
        count: &mut C,
    ) -> bool {
        let mut stack = new_stack();
        let mut sp = 0;
        let (mut node_i, mut t0, mut t0_pad, mut t1) = (0u32, s.t0, s.t0_pad, s.t1);
        loop {
            let node = self.node(node_i);
            if !node.is_leaf() {
                count.node();
                if FAR_FIRST {
                    take_step_far_first(
                        s,
                        node,
                        &mut node_i,
                        &mut t0,
                        &mut t0_pad,
                        t1,
                        &mut stack,
                        &mut sp,
                    );
                } else {
                    take_step_branch_free(
                        self.nodes,
                        s,
                        node,
                        &mut node_i,
                        t0,
                        t0_pad,
                        &mut t1,
                        &mut stack,
                        &mut sp,
                    );
                }
                continue;
            }
            let leaf = self.leaf(node);
            count.leaf(leaf.len());
            if self.leaf_any::<KZ, F>(&s.pre, ray, leaf, blocks) {
                return true;
            }
            if sp == 0 {
                return false;
            }
            sp -= 1;
            (node_i, t0, t1) = pop(&stack, sp);
            t0_pad = pad_down(t0);
        }
    }
}

impl Tree<'_> {
    /// A leaf's triangles for an any-hit walk: whether `blocks` takes one of its hits,
    /// asked in the leaf's order.
    #[inline(always)]
    pub(crate) fn leaf_any<const KZ: usize, F: FnMut(&Hit, bool) -> bool>(
        &self,
        pre: &RayPre,
        ray: &Ray,
        leaf: &[u32],
        blocks: &mut F,
    ) -> bool {
        if leaf.len() >= 2 {
            for group in leaf.chunks(4) {
                let (lanes, hits) = self.test4::<KZ>(pre, ray, group, ray.tmax);
                for l in hits.hit_lanes() {
                    let h = hits.raw(l);
                    if blocks(&candidate(self.soup_index(lanes[l]), h), h.front) {
                        return true;
                    }
                }
            }
        } else {
            for &p in leaf {
                if let Some(h) = test::<KZ>(pre, ray, self.tri(p), ray.tmax) {
                    if blocks(&candidate(self.soup_index(p), h), h.front) {
                        return true;
                    }
                }
            }
        }
        false
    }
}

/// Take hit `h` on triangle `prim` if it is closer than the best so far, or as close with
/// a lower index. Candidates are tested against `widen(best_t)` (see `triangle::widen`),
/// and four-wide groups against the bound at the group's start, so `h.t <= best_t` here is
/// the exact test.
/// `accept` is asked only about a hit that would be kept.
#[inline(always)]
pub(crate) fn keep_closer<F: FnMut(&Hit, bool) -> bool>(
    best: &mut Hit,
    best_t: &mut f32,
    prim: u32,
    h: RawHit,
    accept: &mut F,
) {
    if h.t <= *best_t && (h.t < *best_t || prim < best.prim) {
        let c = candidate(prim, h);
        if accept(&c, h.front) {
            *best_t = h.t;
            *best = c;
        }
    }
}

#[inline(always)]
pub(crate) fn candidate(prim: u32, h: RawHit) -> Hit {
    Hit {
        t: h.t,
        prim,
        u: h.u,
        v: h.v,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::hint::black_box;

    /// The padding the processor rounds to, subnormals included.
    fn padded_at_run_time(t: f32) -> f32 {
        let t = black_box(t);
        t - t.abs() * black_box(triangle::PAD)
    }

    #[test]
    fn the_lower_padding_has_the_run_time_bits_and_a_spawned_ray_s_is_subnormal() {
        for t in [
            f32::MIN_POSITIVE,
            f32::MIN_POSITIVE * 2.0,
            0.0,
            -0.0,
            1.0,
            -3.5,
            1e-30,
            f32::INFINITY,
        ] {
            assert_eq!(
                pad_down(t).to_bits(),
                padded_at_run_time(t).to_bits(),
                "{t:e}"
            );
        }
        const { assert!(MIN_POSITIVE_PADDED.is_subnormal() && MIN_POSITIVE_PADDED > 0.0) };
        assert!(pad_down(f32::NAN).is_nan());
    }
}
