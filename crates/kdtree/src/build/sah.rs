//! The SAH cost of candidate planes on one axis of a cell, and the sweep over sorted
//! events that ranks them. The event builder and the binned search both rank planes here,
//! with the same arithmetic, so that both pick bit-for-bit the same split.

use super::events::{self, Event, END, PLANAR, START};
use crate::aabb::Aabb;

/// One axis of one cell, ready to price planes.
pub struct AxisCost {
    lo: f32,
    hi: f32,
    cap: f64,
    ring: f64,
    keep: f64,
    /// The cell's triangle count: every plane has at least this many on its two sides.
    n: f64,
    lo_key: u32,
    hi_key: u32,
}

impl AxisCost {
    /// None when the cell is flat along `axis` (no plane strictly inside it). `n` is the
    /// number of triangles in the cell.
    pub fn new(cell: &Aabb, axis: usize, bonus: f64, n: usize) -> Option<AxisCost> {
        let lo = cell.lo[axis];
        let hi = cell.hi[axis];
        if !(lo < hi) {
            return None;
        }
        let e: [f64; 3] = std::array::from_fn(|a| cell.hi[a] as f64 - cell.lo[a] as f64);
        let (o1, o2) = ((axis + 1) % 3, (axis + 2) % 3);
        // A child's area is 2·(cap + d·ring) for its extent d along the axis. Planes are
        // ranked by (cap + dl·ring)·nl + (cap + dr·ring)·nr (times the empty-space factor)
        // and only the winner is scaled into the SAH cost; nl and nr are f64 (exact below
        // 2^53), so each position converts its three counts once.
        Some(AxisCost {
            lo,
            hi,
            cap: e[o1] * e[o2],
            ring: e[o1] + e[o2],
            keep: 1.0 - bonus,
            n: n as f64,
            lo_key: events::ordered(lo),
            hi_key: events::ordered(hi),
        })
    }

    /// A plane on the cell's face separates nothing.
    #[inline]
    pub fn inside(&self, key: u32) -> bool {
        key > self.lo_key && key < self.hi_key
    }

    /// Whether events between these two keys may lie strictly inside the cell.
    #[inline]
    pub fn may_hold_inside(&self, min_key: u32, max_key: u32) -> bool {
        max_key > self.lo_key && min_key < self.hi_key
    }

    #[inline]
    fn weights(&self, p_low: f32, p_high: f32) -> (f64, f64) {
        (
            self.cap + (p_low as f64 - self.lo as f64) * self.ring,
            self.cap + (self.hi as f64 - p_high as f64) * self.ring,
        )
    }

    #[inline]
    fn weigh(&self, (wl, wr): (f64, f64), l: f64, r: f64) -> f64 {
        let c = wl * l + wr * r;
        if l == 0.0 || r == 0.0 {
            self.keep * c
        } else {
            c
        }
    }

    /// The rank of the plane at `p` with `nl` triangles starting below it, `nr` ending
    /// above it and `pp` lying in it, and whether those go below: the cheaper side.
    #[inline]
    pub fn at(&self, p: f32, nl: f64, nr: f64, pp: f64) -> (f64, bool) {
        let w = self.weights(p, p);
        if nl > 0.0 && nr > 0.0 {
            // Inside the cell's run of triangles both sides hold some, wherever the planar
            // ones go: the same sums as `weigh`, without its empty-side test.
            let c_below = w.0 * (nl + pp) + w.1 * nr;
            if pp == 0.0 {
                return (c_below, true);
            }
            let c_above = w.0 * nl + w.1 * (nr + pp);
            return if c_below <= c_above {
                (c_below, true)
            } else {
                (c_above, false)
            };
        }
        let c_below = self.weigh(w, nl + pp, nr);
        if pp == 0.0 {
            // Nothing lies in the plane: both sides price the same, and below wins ties.
            return (c_below, true);
        }
        let c_above = self.weigh(w, nl, nr + pp);
        if c_below <= c_above {
            (c_below, true)
        } else {
            (c_above, false)
        }
    }

    /// A lower bound on [`AxisCost::at`] for every plane in `[p_low, p_high]` that has at
    /// least `l` triangles below and `r` above: every operation is monotone in its inputs,
    /// so the bound holds in floating point too.
    #[inline]
    pub fn bound(&self, p_low: f32, p_high: f32, l: f64, r: f64) -> f64 {
        self.weigh(self.weights(p_low, p_high), l, r)
    }

    /// A lower bound on the rank of every plane above `p` (or of every plane, with `p` at
    /// the cell's low face) when `nl` triangles start or lie at or below `p`: such a plane
    /// has at least `nl` triangles below, a larger area below, and every triangle on at
    /// least one side, each side weighing at least `cap`. So a plane with `l` below and
    /// `r` above ranks at least `wl·nl + cap·(n − nl)` (or, with a side empty, `keep` times
    /// `wl·n` or `cap·n`, no less than `keep` times that bound). The inequality holds for
    /// exact numbers; rounding moves either side by far less than the factor below.
    #[inline]
    fn floor(&self, p: f32, nl: f64) -> f64 {
        let (wl, _) = self.weights(p, p);
        self.keep * (wl * nl + self.cap * (self.n - nl)) * (1.0 - 1e-12)
    }

    /// The SAH cost of a ranked plane.
    #[inline]
    pub fn cost(rank: f64, kt: f64, ki: f64, area: f64) -> f64 {
        kt + ki * 2.0 * rank / area
    }
}

/// The best plane of one axis so far: the first of the cheapest in position order.
#[derive(Clone, Copy, Debug)]
pub struct Best {
    pub rank: f64,
    pub at: Option<(f32, bool)>,
}

impl Best {
    pub const NONE: Best = Best {
        rank: f64::INFINITY,
        at: None,
    };

    #[inline]
    pub fn offer(&mut self, (rank, planar_below): (f64, bool), p: f32) {
        if rank < self.rank {
            self.rank = rank;
            self.at = Some((p, planar_below));
        }
    }
}

/// A table indexed by an event's kind (two bits: the fourth entry is never read, and
/// makes the index need no bounds check).
const fn per_kind(end: f64, planar: f64, start: f64) -> [f64; 4] {
    let mut t = [0.0; 4];
    t[END as usize] = end;
    t[PLANAR as usize] = planar;
    t[START as usize] = start;
    t
}

/// Sweep sorted events in position order, starting from the counts the positions before
/// them leave: `nl` triangles started (or planar) below, `nr` not yet ended. `best` may
/// come in with a rank to beat and no plane (a bound from elsewhere): only planes ranked
/// strictly below it are taken.
pub fn sweep(ax: &AxisCost, ev: &[Event], mut nl: f64, mut nr: f64, best: &mut Best) {
    // What one event of each kind (END, PLANAR, START) does to the counts of the planes
    // from its own on: it takes one from those not yet ended at its position, adds one to
    // those lying in it, and one to those below every later plane. The counts stay whole
    // numbers in f64, so adding one event at a time gives the very sums of adding a
    // position's counts at once, without converting counts at every position.
    const ENDED: [f64; 4] = per_kind(1.0, 1.0, 0.0);
    const IN_PLANE: [f64; 4] = per_kind(0.0, 1.0, 0.0);
    const BELOW_NEXT: [f64; 4] = per_kind(0.0, 1.0, 1.0);
    let Some(first) = ev.first() else { return };
    if ax.floor(ax.lo, nl) >= best.rank {
        return;
    }
    let mut key = first.pos_key();
    // `nl` for the planes after the current position, and those lying in it.
    let (mut next_nl, mut pp) = (nl, 0.0);
    for e in ev {
        if e.pos_key() != key {
            if !ax.price(key, nl, nr, pp, next_nl, best) {
                return;
            }
            key = e.pos_key();
            (nl, pp) = (next_nl, 0.0);
        }
        let kind = e.kind() as usize;
        nr -= ENDED[kind];
        pp += IN_PLANE[kind];
        next_nl += BELOW_NEXT[kind];
    }
    ax.price(key, nl, nr, pp, next_nl, best);
}

impl AxisCost {
    /// Offer the plane at `key` with its counts, and say whether a later plane (with
    /// `next_nl` triangles below) can still beat `best`.
    // Always inlined: at every position of every sweep, and the compiler's own weighing
    // of the grown `at` left it a call.
    #[inline(always)]
    fn price(&self, key: u32, nl: f64, nr: f64, pp: f64, next_nl: f64, best: &mut Best) -> bool {
        if !self.inside(key) {
            return true;
        }
        let p = events::unordered(key);
        best.offer(self.at(p, nl, nr, pp), p);
        // Ties go to the earlier plane: stop once no later one can rank strictly lower.
        self.floor(p, next_nl) < best.rank
    }
}
