//! Four rays through the tree together, for rays that travel side by side (a camera's
//! neighbouring pixels, and their shadow rays toward one light): one walk of the tree
//! fetches each node and leaf list once for all four, where four single walks fetch them
//! four times.
//!
//! Each lane sees exactly what its own single-ray walk would: the same cells in the same
//! order over the same intervals, the same triangles with the same arithmetic, and the same
//! questions to the filter in the same order. Where it takes no more tests than each lane's
//! own groups of four triangles, a leaf's triangles are tested one at a time against all
//! four rays (each read once, not once per lane); a closest-hit lane's bound is then its
//! best hit after the previous triangle rather than after the previous group of four, which
//! refuses earlier only hits that the exact comparison would refuse anyway. At a node a
//! lane goes to the first child, the second or both by the single walk's rule (front to
//! back, or far child first for any-hit queries that allow it, as the single walk), with the
//! single walk's intervals; the packet goes where any of its lanes goes and carries a mask
//! of the lanes that go there. A closest-hit lane skips a waiting cell that starts beyond
//! its best hit, an any-hit lane leaves the walk at its first blocker, as in the single
//! walks. The four answers are therefore the single queries' answers, bit for bit. Rays
//! whose directions differ in sign on some axis or in their dominant axis would want the
//! children in different orders: they are traced one by one.

use crate::aabb::Aabb;
use crate::traverse::{candidate, keep_closer, Tree, MIN_POSITIVE_PADDED, STACK};
use crate::triangle::{self, RayPre4, PAD};
use crate::Ray;
use formats::{Hit, KdNode};
use glam::Vec4;
use std::mem::MaybeUninit;

/// Rays per packet.
pub const LANES: usize = 4;

/// A far child waiting, with each lane's interval and the lanes that visit it.
#[derive(Clone, Copy)]
struct Waiting {
    t0: Vec4,
    t1: Vec4,
    node: u32,
    lanes: u8,
}

/// The lanes set in `mask`, lowest first.
#[inline(always)]
fn lanes_of(mask: u8) -> impl Iterator<Item = usize> {
    (0..LANES).filter(move |l| mask >> l & 1 != 0)
}

/// Four rays' numbers for one walk, lane by lane: the lanes that meet the tree, their
/// watertight-test constants, intervals within the tree's box, origins and reciprocal
/// directions axis by axis (so that a node's four plane distances are one vector
/// operation), and which child comes first. A lane that does not meet the tree holds
/// numbers nobody reads.
struct Packet {
    live: u8,
    o: [Vec4; 3],
    inv: [Vec4; 3],
    forward: [bool; 3],
    pre: RayPre4,
    tmin: [f32; LANES],
    tmax: [f32; LANES],
    t0: Vec4,
    /// `down4(t0)`, worked out once (see `traverse::pad_down`).
    t0_pad: Vec4,
    t1: Vec4,
}

/// How four rays go through the tree. Built and taken apart within one query, on the
/// stack: boxing the large variant would allocate per packet.
#[allow(clippy::large_enum_variant)]
enum Walk {
    /// As one packet.
    Together(Packet),
    /// One by one: their directions differ in sign on some axis or in their dominant axis,
    /// so they would want the children in different orders, or only one meets the tree.
    Alone,
    /// Not at all: none meets the tree's box with a usable direction and interval.
    Nowhere,
}

impl Packet {
    /// `traverse::setup` on four lanes at once, the same operations on each lane's numbers
    /// (so each lane's interval and test constants are its single query's), then whether
    /// the lanes can walk together.
    #[inline(always)]
    fn walk(rays: &[Ray; LANES], b: &Aabb) -> Walk {
        let lanes = |f: fn(&Ray) -> f32| Vec4::from_array(rays.each_ref().map(f));
        let o = [
            lanes(|r| r.origin.x),
            lanes(|r| r.origin.y),
            lanes(|r| r.origin.z),
        ];
        let d = [lanes(|r| r.dir.x), lanes(|r| r.dir.y), lanes(|r| r.dir.z)];
        let (tmin, tmax) = (lanes(|r| r.tmin), lanes(|r| r.tmax));
        // The refusals of `setup` and `RayPre::new` as a lane mask: a bad interval, an
        // origin or direction not finite, a zero dominant component, the box missed.
        let inf = Vec4::splat(f32::INFINITY);
        let mut ok = tmin.cmple(tmax) & tmax.cmpne(-inf) & tmin.cmpne(inf);
        for a in 0..3 {
            ok &= o[a].is_finite_mask() & d[a].is_finite_mask();
        }
        let abs = d.map(Vec4::abs);
        let kz0 = abs[0].cmpge(abs[1]) & abs[0].cmpge(abs[2]);
        let kz1 = !kz0 & abs[1].cmpge(abs[2]);
        ok &= Vec4::select(kz0, d[0], Vec4::select(kz1, d[1], d[2])).cmpne(Vec4::ZERO);
        let inv = d.map(|d| Vec4::ONE / d);
        let (mut t0, mut t1) = (tmin, tmax);
        for a in 0..3 {
            let parallel = !inv[a].is_finite_mask();
            let (lo, hi) = (Vec4::splat(b.lo[a]), Vec4::splat(b.hi[a]));
            ok &= !(parallel & (o[a].cmplt(lo) | o[a].cmpgt(hi)));
            let ta = (lo - o[a]) * inv[a];
            let tb = (hi - o[a]) * inv[a];
            let positive = inv[a].cmpgt(Vec4::ZERO);
            // No NaN reaches these in a lane that meets the box, so the vector maximum and
            // minimum are `f32::max` and `f32::min`.
            let near = Vec4::select(positive, ta, tb);
            let far = Vec4::select(positive, tb, ta);
            t0 = Vec4::select(parallel, t0, t0.max(near));
            t1 = Vec4::select(parallel, t1, t1.min(far));
        }
        let t0_pad = down4(t0);
        ok &= t0_pad.cmple(up4(t1));
        let live = ok.bitmask() as u8;
        if live == 0 {
            return Walk::Nowhere;
        }
        // Together when every lane that meets the tree has the lead's dominant axis and
        // direction signs.
        let alike = |m: u32| {
            let m = m as u8 & live;
            m == 0 || m == live
        };
        let positive = inv.map(|i| i.cmpgt(Vec4::ZERO).bitmask());
        let together = live.count_ones() > 1
            && alike(kz0.bitmask())
            && alike(kz1.bitmask())
            && positive.iter().all(|&m| alike(m));
        if !together {
            return Walk::Alone;
        }
        let lead = live & live.wrapping_neg();
        let kz = if kz0.bitmask() as u8 & lead != 0 {
            0
        } else if kz1.bitmask() as u8 & lead != 0 {
            1
        } else {
            2
        };
        let (kx, ky) = ((kz + 1) % 3, (kz + 2) % 3);
        let shear = [d[kx] / d[kz], d[ky] / d[kz], Vec4::ONE / d[kz]];
        Walk::Together(Packet {
            live,
            forward: positive.map(|m| m as u8 & lead != 0),
            pre: RayPre4::from_lanes(kz, o, shear),
            o,
            inv,
            tmin: tmin.to_array(),
            tmax: tmax.to_array(),
            t0,
            t0_pad,
            t1,
        })
    }
}

/// `traverse::take_step` in four lanes at once, the same operations on each lane's
/// numbers: only the first child, only the second, or both, split at the plane. The packet
/// goes where any of the lanes in `mask` goes, and a child visited by some waits on the
/// stack with their intervals: the far one front to back, the near one with `FAR_FIRST`
/// (`traverse::take_step_far_first` in four lanes).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn step4<const FAR_FIRST: bool>(
    p: &Packet,
    node: KdNode,
    node_i: &mut u32,
    mask: &mut u8,
    t0: &mut Vec4,
    t0_pad: &mut Vec4,
    t1: &mut Vec4,
    stack: &mut [MaybeUninit<Waiting>; STACK],
    sp: &mut usize,
) {
    let a = node.axis();
    let (below, above) = (*node_i + 1, node.above_child());
    let (first, second) = if p.forward[a] {
        (below, above)
    } else {
        (above, below)
    };
    let tp = (Vec4::splat(node.split()) - p.o[a]) * p.inv[a];
    let only_first = tp.cmpgt(up4(*t1));
    let only_second = tp.cmplt(*t0_pad) & !only_first;
    let both = !(only_first | only_second);
    let near = (!only_second).bitmask() as u8 & *mask;
    let far = (!only_first).bitmask() as u8 & *mask;
    // `near_end` and `far_start`: a NaN plane distance keeps the whole interval.
    let near_t1 = Vec4::select(both & tp.cmple(*t1), tp, *t1);
    let far_t0 = Vec4::select(both & tp.cmpge(*t0), tp, *t0);
    if FAR_FIRST {
        if far == 0 {
            (*node_i, *mask, *t1) = (first, near, near_t1);
        } else {
            if near != 0 {
                push(stack, sp, first, near, *t0, near_t1);
            }
            (*node_i, *mask, *t0, *t0_pad) = (second, far, far_t0, down4(far_t0));
        }
    } else if near == 0 {
        (*node_i, *mask, *t0, *t0_pad) = (second, far, far_t0, down4(far_t0));
    } else {
        if far != 0 {
            push(stack, sp, second, far, far_t0, *t1);
        }
        (*node_i, *mask, *t1) = (first, near, near_t1);
    }
}

/// A child waiting for `lanes`, over their intervals `t0`–`t1`, on top of the stack.
#[inline(always)]
fn push(
    stack: &mut [MaybeUninit<Waiting>; STACK],
    sp: &mut usize,
    node: u32,
    lanes: u8,
    t0: Vec4,
    t1: Vec4,
) {
    stack[*sp] = MaybeUninit::new(Waiting {
        t0,
        t1,
        node,
        lanes,
    });
    *sp += 1;
}

impl Tree<'_> {
    /// Steps from node `node_i` down to the leaf the packet reaches first, pushing the far
    /// children it passes; returns that leaf.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn to_leaf<const FAR_FIRST: bool>(
        &self,
        p: &Packet,
        node_i: &mut u32,
        mask: &mut u8,
        t0: &mut Vec4,
        t0_pad: &mut Vec4,
        t1: &mut Vec4,
        stack: &mut [MaybeUninit<Waiting>; STACK],
        sp: &mut usize,
    ) -> &[u32] {
        loop {
            let node = self.node(*node_i);
            if node.is_leaf() {
                return self.leaf(node);
            }
            step4::<FAR_FIRST>(p, node, node_i, mask, t0, t0_pad, t1, stack, sp);
        }
    }

    /// The closest hits of four rays: lane `l` is `closest(&rays[l], accept for l)`.
    /// `accept` is asked with the lane first.
    #[inline(always)]
    pub fn closest4<F: FnMut(usize, &Hit, bool) -> bool>(
        &self,
        rays: &[Ray; LANES],
        mut accept: F,
    ) -> [Option<Hit>; LANES] {
        let p = match Packet::walk(rays, self.bounds) {
            Walk::Together(p) => p,
            Walk::Alone => {
                return std::array::from_fn(|l| {
                    self.closest(&rays[l], |h, front| accept(l, h, front), &mut ())
                })
            }
            Walk::Nowhere => return [None; LANES],
        };
        match p.pre.rays[0].kz {
            0 => self.closest4_along::<0, F>(rays, &p, &mut accept),
            1 => self.closest4_along::<1, F>(rays, &p, &mut accept),
            _ => self.closest4_along::<2, F>(rays, &p, &mut accept),
        }
    }

    #[inline(always)]
    fn closest4_along<const KZ: usize, F: FnMut(usize, &Hit, bool) -> bool>(
        &self,
        rays: &[Ray; LANES],
        p: &Packet,
        accept: &mut F,
    ) -> [Option<Hit>; LANES] {
        let mut best = [Hit::MISS; LANES];
        // An array, not a `Vec4`: a `Vec4` indexed by a variable lane is a jump table.
        let mut best_t = rays.each_ref().map(|r| r.tmax);
        let mut stack = [MaybeUninit::<Waiting>::uninit(); STACK];
        let mut sp = 0;
        let (mut node_i, mut mask, mut t0, mut t1) = (0u32, p.live, p.t0, p.t1);
        let mut t0_pad = p.t0_pad;
        loop {
            let leaf = self.to_leaf::<false>(
                p,
                &mut node_i,
                &mut mask,
                &mut t0,
                &mut t0_pad,
                &mut t1,
                &mut stack,
                &mut sp,
            );
            if shared(leaf, mask) {
                for &i in leaf {
                    let bound = best_t.map(triangle::widen);
                    let hits =
                        triangle::intersect_rays4_along::<KZ>(&p.pre, self.tri(i), p.tmin, bound);
                    for l in hits.hit_lanes().filter(|l| mask >> l & 1 != 0) {
                        let mut accept_l = |h: &Hit, front: bool| accept(l, h, front);
                        let prim = self.soup_index(i);
                        keep_closer(
                            &mut best[l],
                            &mut best_t[l],
                            prim,
                            hits.raw(l),
                            &mut accept_l,
                        );
                    }
                }
            } else {
                for l in lanes_of(mask) {
                    let mut accept_l = |h: &Hit, front: bool| accept(l, h, front);
                    self.leaf_closest::<KZ, _>(
                        &p.pre.rays[l],
                        &rays[l],
                        leaf,
                        &mut best[l],
                        &mut best_t[l],
                        &mut accept_l,
                    );
                }
            }
            loop {
                if sp == 0 {
                    return std::array::from_fn(|l| (!best[l].is_miss()).then_some(best[l]));
                }
                sp -= 1;
                // SAFETY: entries below `sp` were written by the push that raised `sp`
                // past them.
                let w = unsafe { stack[sp].assume_init() };
                let w_pad = down4(w.t0);
                let ahead = Vec4::from_array(best_t).cmpge(w_pad).bitmask() as u8;
                if w.lanes & ahead != 0 {
                    (node_i, mask, t0, t1) = (w.node, w.lanes & ahead, w.t0, w.t1);
                    t0_pad = w_pad;
                    break;
                }
            }
        }
    }

    /// Whether each of four rays is blocked: lane `l` is
    /// `any::<FAR_FIRST>(&rays[l], blocks for l)`, `blocks` asked with the lane first. A
    /// lane leaves the walk at its first blocker.
    #[inline(always)]
    pub fn any4<const FAR_FIRST: bool, F: FnMut(usize, &Hit, bool) -> bool>(
        &self,
        rays: &[Ray; LANES],
        mut blocks: F,
    ) -> [bool; LANES] {
        let p = match Packet::walk(rays, self.bounds) {
            Walk::Together(p) => p,
            Walk::Alone => {
                return std::array::from_fn(|l| {
                    self.any::<FAR_FIRST, _, _>(&rays[l], |h, front| blocks(l, h, front), &mut ())
                })
            }
            Walk::Nowhere => return [false; LANES],
        };
        let blocked = match p.pre.rays[0].kz {
            0 => self.any4_along::<0, FAR_FIRST, F>(rays, &p, &mut blocks),
            1 => self.any4_along::<1, FAR_FIRST, F>(rays, &p, &mut blocks),
            _ => self.any4_along::<2, FAR_FIRST, F>(rays, &p, &mut blocks),
        };
        std::array::from_fn(|l| blocked >> l & 1 != 0)
    }

    /// The lanes blocked, as a mask.
    #[inline(always)]
    fn any4_along<const KZ: usize, const FAR_FIRST: bool, F: FnMut(usize, &Hit, bool) -> bool>(
        &self,
        rays: &[Ray; LANES],
        p: &Packet,
        blocks: &mut F,
    ) -> u8 {
        let mut blocked = 0u8;
        let mut stack = [MaybeUninit::<Waiting>::uninit(); STACK];
        let mut sp = 0;
        let (mut node_i, mut mask, mut t0, mut t1) = (0u32, p.live, p.t0, p.t1);
        let mut t0_pad = p.t0_pad;
        loop {
            let leaf = self.to_leaf::<FAR_FIRST>(
                p,
                &mut node_i,
                &mut mask,
                &mut t0,
                &mut t0_pad,
                &mut t1,
                &mut stack,
                &mut sp,
            );
            if shared(leaf, mask) {
                let mut open = mask;
                for &i in leaf {
                    let hits =
                        triangle::intersect_rays4_along::<KZ>(&p.pre, self.tri(i), p.tmin, p.tmax);
                    let wanted = open;
                    for l in hits.hit_lanes().filter(|l| wanted >> l & 1 != 0) {
                        let h = hits.raw(l);
                        if blocks(l, &candidate(self.soup_index(i), h), h.front) {
                            open &= !(1 << l);
                        }
                    }
                    if open == 0 {
                        break;
                    }
                }
                blocked |= mask & !open;
            } else {
                for l in lanes_of(mask) {
                    let mut blocks_l = |h: &Hit, front: bool| blocks(l, h, front);
                    if self.leaf_any::<KZ, _>(&p.pre.rays[l], &rays[l], leaf, &mut blocks_l) {
                        blocked |= 1 << l;
                    }
                }
            }
            if blocked == p.live {
                return blocked;
            }
            loop {
                if sp == 0 {
                    return blocked;
                }
                sp -= 1;
                // SAFETY: as in `closest4_along`.
                let w = unsafe { stack[sp].assume_init() };
                if w.lanes & !blocked != 0 {
                    (node_i, mask, t0, t1) = (w.node, w.lanes & !blocked, w.t0, w.t1);
                    t0_pad = down4(t0);
                    break;
                }
            }
        }
    }
}

/// Whether the lanes in `mask` test `leaf` together, each triangle against all four rays
/// at once, rather than each lane its four-triangle groups: when that is no more tests.
#[inline(always)]
fn shared(leaf: &[u32], mask: u8) -> bool {
    leaf.len() <= mask.count_ones() as usize * leaf.len().div_ceil(4)
}

/// `traverse::pad_up` on four lanes.
#[inline(always)]
fn up4(t: Vec4) -> Vec4 {
    t + t.abs() * PAD
}

/// `traverse::pad_down` on four lanes, its subnormal case included: a lane at
/// `f32::MIN_POSITIVE` takes the constant and pads 1 instead (behind a value the compiler
/// cannot see through, as there), so that no lane's result is subnormal.
#[inline(always)]
fn down4(t: Vec4) -> Vec4 {
    let spawned = t.cmpeq(Vec4::splat(f32::MIN_POSITIVE));
    let t = std::hint::black_box(Vec4::select(spawned, Vec4::ONE, t));
    Vec4::select(spawned, Vec4::splat(MIN_POSITIVE_PADDED), t - t.abs() * PAD)
}
