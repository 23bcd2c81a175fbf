//! The upper levels of the build: triangle references with their (clipped) bounds, split
//! by an exact search that bins before it sorts.
//!
//! Keeping three sorted event lists through every split costs a pass over 48 bytes of
//! events per reference and level, with random reads of each triangle's side; large cells
//! instead keep a plain list of references (28 bytes each) and find the split like this:
//!
//! 1. One pass bins every event (start, end, planar) of every axis into `BINS` (256) equal
//!    slabs, counting kinds and keeping each slab's lowest and highest position.
//! 2. Per slab, the SAH is bounded from above (the cost at its lowest or highest event,
//!    with counts that can only be worse) and from below (the best area at either end of
//!    the slab with the counts that can only be better).
//! 3. Only the slabs whose lower bound reaches the best upper bound can hold the cheapest
//!    plane: their events are gathered, sorted and swept exactly as the event builder
//!    sweeps them. A slab with a single position is priced directly.
//!
//! The winner is the plane the full event sweep would pick (same arithmetic in
//! [`super::sah`], same tie rule: the first of the cheapest), so the tree is the same
//! tree; only the work is less. Children keep their references in the parent's order,
//! straddlers (clipped to each child) after them, as the event builder orders them.

use super::events::{self, Event, END, PLANAR, START};
use super::sah::{self, AxisCost, Best};
use super::{clip, Ctx, Split, Work};
use crate::aabb::Aabb;
use rayon::prelude::*;

/// Slabs per axis: enough that the slabs around the cheapest plane hold few events.
const BINS: usize = 256;

/// Cells with at least this many references bin, gather and partition on every thread.
const PARALLEL_MIN: usize = 1 << 16;

/// References per task when a cell is worked on in parallel.
const CHUNK: usize = 1 << 14;

/// Slabs whose lower bound is within this factor of the best upper bound are swept: ranks
/// that differ by less may still round to the same SAH cost, and the tie rule must see them.
const SLACK: f64 = 1.0 + 1e-9;

/// Cells at least this large whose candidate slabs hold more events than the cell has
/// references (a dense cluster in one slab) go to the event builder, which sorts their
/// events once, rather than gathering and sorting most of them at every level.
const CROWDED_MIN: usize = 1 << 14;

/// What the binned search found: the cheapest split (or none), or that the slabs that may
/// hold it are too crowded to gather.
pub(super) enum Search {
    Found(Option<Split>),
    Crowded,
}

/// A triangle (global id) and its bounds inside the current cell.
#[derive(Clone, Copy, Debug)]
pub(super) struct Ref {
    pub tri: u32,
    pub b: Aabb,
}

#[derive(Clone, Copy)]
struct Bin {
    starts: u32,
    ends: u32,
    planars: u32,
    /// Lowest and highest position key of the slab's events.
    min: u32,
    max: u32,
}

const EMPTY_BIN: Bin = Bin {
    starts: 0,
    ends: 0,
    planars: 0,
    min: u32::MAX,
    max: 0,
};

impl Bin {
    #[inline]
    fn add(&mut self, key: u32) {
        self.min = self.min.min(key);
        self.max = self.max.max(key);
    }

    fn merge(&mut self, o: &Bin) {
        self.starts += o.starts;
        self.ends += o.ends;
        self.planars += o.planars;
        self.min = self.min.min(o.min);
        self.max = self.max.max(o.max);
    }

    fn events(&self) -> usize {
        (self.starts + self.ends + self.planars) as usize
    }
}

type Histogram = Box<[[Bin; BINS]; 3]>;

/// Maps positions to slabs: monotone (a higher position never gets a lower slab) and
/// equal positions, −0 and +0 included, to one slab, which is all the search needs.
struct Slabs {
    lo: [f32; 3],
    scale: [f32; 3],
    live: [bool; 3],
}

impl Slabs {
    fn new(cell: &Aabb) -> Slabs {
        let live = std::array::from_fn(|a| cell.lo[a] < cell.hi[a]);
        Slabs {
            lo: cell.lo,
            scale: std::array::from_fn(|a| {
                if live[a] {
                    BINS as f32 / (cell.hi[a] - cell.lo[a])
                } else {
                    0.0
                }
            }),
            live,
        }
    }

    /// Every position lands in a slab: below the cell and NaN (from 0·∞ at the low face of
    /// a very thin cell) in the first, beyond it in the last. Clamped before it is
    /// truncated, so the conversion is one instruction, not a saturating sequence.
    #[inline]
    fn of(&self, axis: usize, pos: f32) -> usize {
        let x = (pos - self.lo[axis]) * self.scale[axis];
        let x = if x > 0.0 {
            x.min((BINS - 1) as f32)
        } else {
            0.0
        };
        // SAFETY: NaN fails `x > 0.0`, so `x` is a number in [0, BINS − 1]: its truncation
        // fits a u32.
        unsafe { x.to_int_unchecked::<u32>() as usize }
    }
}

fn histogram(refs: &[Ref], slabs: &Slabs) -> Histogram {
    let mut h: Histogram = Box::new([[EMPTY_BIN; BINS]; 3]);
    for axis in (0..3).filter(|&a| slabs.live[a]) {
        let bins = &mut h[axis];
        for r in refs {
            let (l, u) = (r.b.lo[axis], r.b.hi[axis]);
            let bl = slabs.of(axis, l);
            let kl = events::ordered(l);
            if l == u {
                bins[bl].planars += 1;
                bins[bl].add(kl);
            } else {
                let bu = slabs.of(axis, u);
                bins[bl].starts += 1;
                bins[bl].add(kl);
                bins[bu].ends += 1;
                bins[bu].add(events::ordered(u));
            }
        }
    }
    h
}

/// The events of the chosen slabs, per axis, unsorted (their triangle field is unused).
fn gather(refs: &[Ref], slabs: &Slabs, chosen: &[[bool; BINS]; 3]) -> [Vec<Event>; 3] {
    let mut out: [Vec<Event>; 3] = Default::default();
    for axis in (0..3).filter(|&a| chosen[a].iter().any(|&c| c)) {
        let (sel, ev) = (&chosen[axis], &mut out[axis]);
        for r in refs {
            let (l, u) = (r.b.lo[axis], r.b.hi[axis]);
            let bl = slabs.of(axis, l);
            if l == u {
                if sel[bl] {
                    ev.push(Event::new(l, 0, PLANAR));
                }
                continue;
            }
            if sel[bl] {
                ev.push(Event::new(l, 0, START));
            }
            let bu = slabs.of(axis, u);
            if sel[bu] {
                ev.push(Event::new(u, 0, END));
            }
        }
    }
    out
}

/// The cheapest split of a cell's references, as the full event sweep would find it.
pub(super) fn find_split(ctx: &Ctx, refs: &[Ref], cell: &Aabb) -> Search {
    let area = cell.area();
    if !(area > 0.0) || !area.is_finite() {
        return Search::Found(None);
    }
    let n = refs.len() as f64;
    let parallel = refs.len() >= PARALLEL_MIN;
    let slabs = Slabs::new(cell);
    let h = if parallel {
        refs.par_chunks(CHUNK)
            .map(|c| histogram(c, &slabs))
            .reduce_with(|mut a, b| {
                for (x, y) in a.iter_mut().zip(b.iter()) {
                    for (p, q) in x.iter_mut().zip(y) {
                        p.merge(q);
                    }
                }
                a
            })
            .unwrap_or_else(|| histogram(&[], &slabs))
    } else {
        histogram(refs, &slabs)
    };
    let axes: [Option<AxisCost>; 3] =
        std::array::from_fn(|a| AxisCost::new(cell, a, ctx.bonus, refs.len()));
    let pos = events::unordered;

    // Upper bounds from each slab's end positions, and the lower bound of each slab.
    let mut upper = f64::INFINITY;
    let mut lower = [[f64::INFINITY; BINS]; 3];
    for (axis, ax) in axes.iter().enumerate() {
        let Some(ax) = ax else { continue };
        let (mut below, mut ended) = (0.0f64, 0.0f64); // starts + planars, ends + planars
        for (k, bin) in h[axis].iter().enumerate() {
            if bin.events() == 0 {
                continue;
            }
            let (s, e, p) = (bin.starts as f64, bin.ends as f64, bin.planars as f64);
            if bin.min == bin.max {
                if ax.inside(bin.min) {
                    upper = upper.min(ax.at(pos(bin.min), below, n - ended - e - p, p).0);
                }
            } else {
                // At the lowest event nothing of the slab is below yet and at most all of
                // its planars are added there; at the highest event everything of the
                // slab has ended or is below.
                if ax.inside(bin.min) {
                    upper = upper.min(ax.bound(pos(bin.min), pos(bin.min), below + p, n - ended));
                }
                if ax.inside(bin.max) {
                    let (l, r) = (below + s + p, n - ended - e - p);
                    upper = upper.min(ax.bound(pos(bin.max), pos(bin.max), l, r));
                }
                if ax.may_hold_inside(bin.min, bin.max) {
                    let r = n - ended - e - p;
                    lower[axis][k] = ax.bound(pos(bin.min), pos(bin.max), below, r);
                }
            }
            below += s + p;
            ended += e + p;
        }
    }
    let limit = upper * SLACK;
    let mut chosen = [[false; BINS]; 3];
    for axis in 0..3 {
        for k in 0..BINS {
            // Infinite: a slab with one position (priced directly) or none inside the cell.
            chosen[axis][k] = lower[axis][k] < f64::INFINITY && lower[axis][k] <= limit;
        }
    }
    let gathered: usize = (0..3)
        .flat_map(|a| h[a].iter().zip(&chosen[a]))
        .filter(|(_, &c)| c)
        .map(|(b, _)| b.events())
        .sum();
    if refs.len() >= CROWDED_MIN && gathered > refs.len() {
        return Search::Crowded;
    }
    let mut ev = if parallel {
        refs.par_chunks(CHUNK)
            .map(|c| gather(c, &slabs, &chosen))
            .reduce(Default::default, |mut a, b| {
                for (x, y) in a.iter_mut().zip(b) {
                    x.extend(y);
                }
                a
            })
    } else {
        gather(refs, &slabs, &chosen)
    };
    for e in ev.iter_mut() {
        let parallel = e.len() >= PARALLEL_MIN;
        events::sort(e, parallel);
    }

    // Exact prices, slab by slab in position order, so the first of the cheapest wins.
    let mut found: [Option<Split>; 3] = [None; 3];
    for (axis, ax) in axes.iter().enumerate() {
        let Some(ax) = ax else { continue };
        let mut best = Best::NONE;
        let mut next = 0; // the chosen slabs' events, in slab order
        let (mut below, mut ended) = (0.0f64, 0.0f64);
        for (k, bin) in h[axis].iter().enumerate() {
            if bin.events() == 0 {
                continue;
            }
            let (s, e, p) = (bin.starts as f64, bin.ends as f64, bin.planars as f64);
            if bin.min == bin.max {
                if ax.inside(bin.min) {
                    best.offer(
                        ax.at(pos(bin.min), below, n - ended - e - p, p),
                        pos(bin.min),
                    );
                }
            } else if chosen[axis][k] {
                let run = &ev[axis][next..next + bin.events()];
                sah::sweep(ax, run, below, n - ended, &mut best);
                next += bin.events();
            }
            below += s + p;
            ended += e + p;
        }
        found[axis] = best.at.map(|(pos, planar_below)| Split {
            rank: best.rank,
            cost: AxisCost::cost(best.rank, ctx.kt, ctx.ki, area),
            axis,
            pos,
            planar_below,
        });
    }
    Search::Found(
        found
            .into_iter()
            .flatten()
            .min_by(|a, b| a.cost.total_cmp(&b.cost)),
    )
}

// A reference's side of the split plane.
const BELOW: u8 = 1;
const ABOVE: u8 = 2;
const BOTH: u8 = 3;

/// The side the event builder's classification gives: a box ending at the plane is
/// below, one starting at it above, one lying in it on the split's planar side.
#[inline]
fn side(r: &Ref, s: &Split, split_key: u32) -> u8 {
    let (l, u) = (r.b.lo[s.axis], r.b.hi[s.axis]);
    let (kl, ku) = (events::ordered(l), events::ordered(u));
    if l == u {
        match kl.cmp(&split_key) {
            std::cmp::Ordering::Less => BELOW,
            std::cmp::Ordering::Greater => ABOVE,
            std::cmp::Ordering::Equal if s.planar_below => BELOW,
            std::cmp::Ordering::Equal => ABOVE,
        }
    } else if ku <= split_key {
        BELOW
    } else if kl >= split_key {
        ABOVE
    } else {
        BOTH
    }
}

/// Split a cell's references into its children's: each child keeps its side's references
/// in the parent's order, then the straddlers that reach into it, clipped to it (perfect
/// splits). A straddler whose box crosses the plane may still miss one child entirely.
///
/// Each child's list is allocated once at its final size (kept plus straddlers bound it),
/// so no list grows by copying itself into fresh pages.
pub(super) fn split(
    ctx: &Ctx,
    mut refs: Vec<Ref>,
    cell: &Aabb,
    s: &Split,
) -> [(Vec<Ref>, Aabb); 2] {
    let (cell_b, cell_a) = cell.split(s.axis, s.pos);
    let key = events::ordered(s.pos);
    let clip = |&Ref { tri: t, .. }: &Ref| {
        let tri = &ctx.tris[t as usize];
        (
            clip::clipped_bounds(tri, &cell_b).map(|b| Ref { tri: t, b }),
            clip::clipped_bounds(tri, &cell_a).map(|b| Ref { tri: t, b }),
        )
    };
    let (mut below, mut above, straddlers) = if refs.len() >= PARALLEL_MIN {
        let sides: Vec<u8> = refs.par_iter().map(|r| side(r, s, key)).collect();
        let counts: Vec<[usize; 4]> = sides
            .par_chunks(CHUNK)
            .map(|c| {
                let mut n = [0; 4];
                for &x in c {
                    n[x as usize] += 1;
                }
                n
            })
            .collect();
        let n_both: usize = counts.iter().map(|n| n[BOTH as usize]).sum();
        let pick = |want: u8, room: usize| pick(&refs, &sides, &counts, want, room);
        (pick(BELOW, n_both), pick(ABOVE, n_both), pick(BOTH, 0))
    } else {
        // The below child compacts into the parent's list (it never needs more room: the
        // kept and the straddlers of one side are at most all of the parent); the above
        // child's list gets that much room at once.
        let mut above = Vec::with_capacity(refs.len());
        let mut straddlers = Vec::new();
        let mut kept = 0;
        for i in 0..refs.len() {
            let r = refs[i];
            match side(&r, s, key) {
                BELOW => {
                    refs[kept] = r;
                    kept += 1;
                }
                ABOVE => above.push(r),
                _ => straddlers.push(r),
            }
        }
        refs.truncate(kept);
        (refs, above, straddlers)
    };
    let clipped: Vec<(Option<Ref>, Option<Ref>)> = if straddlers.len() > 4096 {
        straddlers.par_iter().map(clip).collect()
    } else {
        straddlers.iter().map(clip).collect()
    };
    below.extend(clipped.iter().filter_map(|c| c.0));
    above.extend(clipped.iter().filter_map(|c| c.1));
    [(below, cell_b), (above, cell_a)]
}

/// The references on side `want`, in order, in a list with room for `extra` more: every
/// chunk of `CHUNK` references writes its part of the list in parallel, at the place the
/// counts before it (`counts`, per chunk and side) give it.
fn pick(refs: &[Ref], sides: &[u8], counts: &[[usize; 4]], want: u8, extra: usize) -> Vec<Ref> {
    let total: usize = counts.iter().map(|n| n[want as usize]).sum();
    let mut out = Vec::with_capacity(total + extra);
    let mut rest = &mut out.spare_capacity_mut()[..total];
    let mut parts = Vec::with_capacity(counts.len());
    for n in counts {
        let (part, tail) = rest.split_at_mut(n[want as usize]);
        parts.push(part);
        rest = tail;
    }
    refs.par_chunks(CHUNK)
        .zip(sides.par_chunks(CHUNK))
        .zip(parts)
        .for_each(|((refs, sides), part)| {
            let mut k = 0;
            for (r, &x) in refs.iter().zip(sides) {
                if x == want {
                    part[k].write(*r);
                    k += 1;
                }
            }
            // Checked once per chunk: it is what makes `set_len` below sound.
            assert_eq!(k, part.len(), "a chunk's count differs from its sides");
        });
    // SAFETY: the parts tile the first `total` slots, and each chunk filled its part
    // (asserted above), so all `total` are initialised.
    unsafe { out.set_len(total) };
    out
}

/// Hand a cell over to the event builder: its triangles in reference order and each
/// axis's events, sorted.
pub(super) fn to_work(refs: Vec<Ref>, cell: Aabb) -> Work {
    let parallel = refs.len() >= PARALLEL_MIN;
    let events = std::array::from_fn(|axis| {
        let mut ev = Vec::with_capacity(2 * refs.len());
        for (local, r) in refs.iter().enumerate() {
            events::push_events(&mut ev, &r.b, axis, local as u32);
        }
        events::sort(&mut ev, parallel);
        ev
    });
    Work {
        tris: refs.iter().map(|r| r.tri).collect(),
        events,
        cell,
    }
}

#[cfg(test)]
mod tests {
    use super::super::build_with;
    use super::PARALLEL_MIN;
    use crate::testkit::{self as meshes, Rng};
    use formats::BuildParams;
    use glam::Vec3;
    use proptest::prelude::*;

    /// The binned search must find the very plane the full event sweep finds: a build
    /// that bins every cell and one that bins none give the same tree, node for node.
    fn same_tree(tris: &[[Vec3; 3]], params: &BuildParams) -> Result<(), TestCaseError> {
        let events = build_with(tris, params, [0; 32], usize::MAX);
        for event_max in [0, 7, 64] {
            let binned = build_with(tris, params, [0; 32], event_max);
            prop_assert_eq!(&binned.nodes, &events.nodes, "event_max {}", event_max);
            prop_assert_eq!(&binned.leaf_tris, &events.leaf_tris);
        }
        Ok(())
    }

    #[test]
    fn meshes_build_the_same_tree_binned_or_not() {
        let mut tris = meshes::sphere(Vec3::new(0.3, 0.1, -0.2), 2.0, 24, 48);
        tris.extend(meshes::grid_box(Vec3::new(3.0, 0.0, 0.0), 1.0, 12));
        tris.extend(meshes::grid(40, 20.0, -2.0));
        let mut rng = Rng(7);
        for _ in 0..2000 {
            let c = Vec3::new(
                rng.range(-9.0, 9.0),
                rng.range(-3.0, 5.0),
                rng.range(-9.0, 9.0),
            );
            tris.push([c, c + 0.3 * rng.dir(), c + 0.3 * rng.dir()]);
        }
        for params in [
            BuildParams::default(),
            BuildParams {
                empty_bonus: 0.8,
                traversal_cost: 1.0,
                ..BuildParams::default()
            },
            BuildParams {
                leaf_size: 4,
                max_depth: 12,
                ..BuildParams::default()
            },
        ] {
            same_tree(&tris, &params).unwrap();
        }
    }

    /// Cells of at least `PARALLEL_MIN` references split on both threads, each chunk
    /// writing its part of the children's lists: the same tree as the event builder's.
    #[test]
    fn large_cells_split_on_both_threads_into_the_same_tree() {
        let mut tris = meshes::sphere(Vec3::new(0.2, 0.4, -0.1), 3.0, 200, 300);
        tris.extend(meshes::grid(90, 30.0, -3.5));
        assert!(tris.len() >= 2 * PARALLEL_MIN, "{}", tris.len());
        let params = BuildParams::default();
        let events = build_with(&tris, &params, [0; 32], usize::MAX);
        let binned = build_with(&tris, &params, [0; 32], 0);
        assert_eq!(binned.nodes, events.nodes);
        assert_eq!(binned.leaf_tris, events.leaf_tris);
        assert!(binned.nodes.len() > 20_000, "{}", binned.nodes.len());
    }

    #[test]
    fn a_dense_cluster_beside_an_outlier_builds_the_same_tree() {
        // Every event of the cluster falls in the first slab of each axis: the crowded
        // cells go to the event builder.
        let mut rng = Rng(11);
        let mut tris: Vec<[Vec3; 3]> = (0..20_000)
            .map(|_| {
                let c = Vec3::new(rng.unit(), rng.unit(), rng.unit());
                [c, c + 0.01 * rng.dir(), c + 0.01 * rng.dir()]
            })
            .collect();
        tris.push([
            Vec3::splat(1000.0),
            Vec3::new(1001.0, 1000.0, 1000.0),
            Vec3::splat(1001.0),
        ]);
        let params = BuildParams::default();
        let events = build_with(&tris, &params, [0; 32], usize::MAX);
        let binned = build_with(&tris, &params, [0; 32], 0);
        assert_eq!(binned.nodes, events.nodes);
        assert_eq!(binned.leaf_tris, events.leaf_tris);
    }

    /// Coordinates on a coarse lattice: shared planes, planar and degenerate triangles,
    /// equal positions in many slabs' ends.
    fn lattice_tri() -> impl Strategy<Value = [Vec3; 3]> {
        let v = (-6i32..=6, -6i32..=6, -6i32..=6)
            .prop_map(|(x, y, z)| Vec3::new(x as f32, y as f32 * 0.5, z as f32 * 0.25));
        [v.clone(), v.clone(), v]
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]
        #[test]
        fn lattice_soups_build_the_same_tree_binned_or_not(
            tris in prop::collection::vec(lattice_tri(), 1..400),
            bonus in prop_oneof![Just(0.1f32), Just(0.0), Just(1.0)],
        ) {
            let params = BuildParams { empty_bonus: bonus, ..BuildParams::default() };
            same_tree(&tris, &params)?;
        }
    }
}
