//! Four rays through the tree together, for rays that travel side by side (a camera's
//! neighbouring pixels): one walk of the tree fetches each node and leaf list once for all
//! four, where four single walks fetch them four times.
//!
//! Each lane sees exactly what its own single-ray walk would: the same cells in the same
//! order over the same intervals, the same triangle tests against the same bounds, and the
//! same questions to `accept`. At a node a lane goes to the first child, the second or both
//! by the single walk's rule, with the single walk's intervals; the packet goes where any of
//! its lanes goes and carries a mask of the lanes that go there. A waiting cell is skipped
//! for a lane whose best hit is before it, as in the single walk. The four answers are
//! therefore the single queries' answers, bit for bit. Rays whose directions differ in sign
//! on some axis or in their dominant axis would want the children in different orders: they
//! are traced one by one.

use crate::traverse::{setup, Setup, Tree, STACK};
use crate::triangle::PAD;
use crate::Ray;
use formats::Hit;
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

impl Tree<'_> {
    /// The closest hits of four rays: lane `l` is `closest(&rays[l], accept for l)`.
    /// `accept` is asked with the lane first.
    #[inline(always)]
    pub fn closest4<F: FnMut(usize, &Hit, bool) -> bool>(
        &self,
        rays: &[Ray; LANES],
        mut accept: F,
    ) -> [Option<Hit>; LANES] {
        let setups = rays.each_ref().map(|r| setup(r, self.bounds));
        let mut live = 0u8;
        for (l, s) in setups.iter().enumerate() {
            live |= (s.is_some() as u8) << l;
        }
        let Some(lead) = setups.iter().flatten().next().copied() else {
            return [None; LANES];
        };
        let together = live.count_ones() > 1
            && setups.iter().flatten().all(|s| {
                s.pre.kz == lead.pre.kz && (0..3).all(|a| (s.inv[a] > 0.0) == (lead.inv[a] > 0.0))
            });
        if !together {
            return std::array::from_fn(|l| {
                self.closest(&rays[l], |h, front| accept(l, h, front), &mut ())
            });
        }
        // A lane without a setup never becomes active; it borrows the lead's numbers.
        let s = setups.map(|s| s.unwrap_or(lead));
        match lead.pre.kz {
            0 => self.closest4_along::<0, F>(rays, &s, live, &mut accept),
            1 => self.closest4_along::<1, F>(rays, &s, live, &mut accept),
            _ => self.closest4_along::<2, F>(rays, &s, live, &mut accept),
        }
    }

    #[inline(always)]
    fn closest4_along<const KZ: usize, F: FnMut(usize, &Hit, bool) -> bool>(
        &self,
        rays: &[Ray; LANES],
        s: &[Setup; LANES],
        live: u8,
        accept: &mut F,
    ) -> [Option<Hit>; LANES] {
        let mut best = [Hit::MISS; LANES];
        // An array, not a `Vec4`: a `Vec4` indexed by a variable lane is a jump table.
        let mut best_t = rays.each_ref().map(|r| r.tmax);
        let mut stack = [MaybeUninit::<Waiting>::uninit(); STACK];
        let mut sp = 0;
        let (mut node_i, mut mask) = (0u32, live);
        let mut t0 = Vec4::from_array(s.each_ref().map(|s| s.t0));
        let mut t1 = Vec4::from_array(s.each_ref().map(|s| s.t1));
        // The lanes share the direction's signs, so the children's order.
        let lead = &s[live.trailing_zeros() as usize];
        let forward = [lead.inv[0] > 0.0, lead.inv[1] > 0.0, lead.inv[2] > 0.0];
        // Origins and reciprocal directions axis by axis, so a node's four plane distances
        // are one vector operation.
        let o: [Vec4; 3] = std::array::from_fn(|a| Vec4::from_array(s.each_ref().map(|s| s.o[a])));
        let inv: [Vec4; 3] =
            std::array::from_fn(|a| Vec4::from_array(s.each_ref().map(|s| s.inv[a])));
        loop {
            let node = self.node(node_i);
            if !node.is_leaf() {
                let a = node.axis();
                let (below, above) = (node_i + 1, node.above_child());
                let (first, second) = if forward[a] {
                    (below, above)
                } else {
                    (above, below)
                };
                // `traverse::step` in four lanes at once, the same operations on each lane's
                // numbers: only the first child, only the second, or both, split at the plane.
                let tp = (Vec4::splat(node.split()) - o[a]) * inv[a];
                let only_first = tp.cmpgt(up4(t1));
                let only_second = tp.cmplt(down4(t0)) & !only_first;
                let both = !(only_first | only_second);
                let near = (!only_second).bitmask() as u8 & mask;
                let far = (!only_first).bitmask() as u8 & mask;
                // `near_end` and `far_start`: a NaN plane distance keeps the whole interval.
                let near_t1 = Vec4::select(both & tp.cmple(t1), tp, t1);
                let far_t0 = Vec4::select(both & tp.cmpge(t0), tp, t0);
                if near == 0 {
                    (node_i, mask, t0) = (second, far, far_t0);
                } else {
                    if far != 0 {
                        stack[sp] = MaybeUninit::new(Waiting {
                            node: second,
                            t0: far_t0,
                            t1,
                            lanes: far,
                        });
                        sp += 1;
                    }
                    (node_i, mask, t1) = (first, near, near_t1);
                }
                continue;
            }
            let leaf = self.leaf(node);
            for l in lanes_of(mask) {
                let mut accept_l = |h: &Hit, front: bool| accept(l, h, front);
                self.leaf_closest::<KZ, _>(
                    &s[l],
                    &rays[l],
                    leaf,
                    &mut best[l],
                    &mut best_t[l],
                    &mut accept_l,
                );
            }
            loop {
                if sp == 0 {
                    return std::array::from_fn(|l| (!best[l].is_miss()).then_some(best[l]));
                }
                sp -= 1;
                // SAFETY: entries below `sp` were written by the push that raised `sp`
                // past them.
                let w = unsafe { stack[sp].assume_init() };
                let ahead = Vec4::from_array(best_t).cmpge(down4(w.t0)).bitmask() as u8;
                if w.lanes & ahead != 0 {
                    (node_i, mask, t0, t1) = (w.node, w.lanes & ahead, w.t0, w.t1);
                    break;
                }
            }
        }
    }
}

/// `traverse::pad_up` on four lanes.
#[inline(always)]
fn up4(t: Vec4) -> Vec4 {
    t + t.abs() * PAD
}

/// `traverse::pad_down` on four lanes.
#[inline(always)]
fn down4(t: Vec4) -> Vec4 {
    t - t.abs() * PAD
}
