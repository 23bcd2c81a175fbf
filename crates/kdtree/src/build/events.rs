//! SAH split events (Wald & Havran 2006): per axis, one sorted list of the positions where
//! triangles start, end or lie flat. Kept sorted through every split, so the whole build
//! sorts once plus the few events of triangles that straddle a split.

use crate::aabb::Aabb;
use rayon::prelude::*;

pub const END: u32 = 0;
pub const PLANAR: u32 = 1;
pub const START: u32 = 2;

/// Local triangle indices take the low 30 bits of an event.
pub const MAX_TRIANGLES: usize = 1 << 30;

/// 8 bytes, ordered as a plain integer: the position's bits mapped to an unsigned order
/// (high 32 bits), the kind (2 bits: end < planar < start at equal positions), and the
/// local triangle index (low 30 bits). Sorting, merging and grouping by position are
/// then integer operations.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord)]
pub struct Event(u64);

/// f32 bits to an unsigned key with the same order (for non-NaN values); −0.0 maps to
/// +0.0's key, so equal positions sort and group together.
#[inline]
pub fn ordered(pos: f32) -> u32 {
    let b = (pos + 0.0).to_bits();
    if b >> 31 == 1 {
        !b
    } else {
        b | 0x8000_0000
    }
}

/// The position of an [`ordered`] key.
#[inline]
pub fn unordered(key: u32) -> f32 {
    f32::from_bits(if key >> 31 == 1 {
        key & 0x7fff_ffff
    } else {
        !key
    })
}

impl Event {
    #[inline]
    pub fn new(pos: f32, tri: u32, kind: u32) -> Event {
        debug_assert!((tri as usize) < MAX_TRIANGLES && kind <= START);
        Event(((ordered(pos) as u64) << 32) | ((kind as u64) << 30) | tri as u64)
    }
    /// The position's order key ([`ordered`]); equal keys are equal positions.
    #[inline]
    pub fn pos_key(self) -> u32 {
        (self.0 >> 32) as u32
    }
    #[inline]
    pub fn pos(self) -> f32 {
        unordered(self.pos_key())
    }
    /// Position and kind: the order of events of different triangles at equal keys.
    #[inline]
    pub fn pos_kind(self) -> u64 {
        self.0 >> 30
    }
    #[inline]
    pub fn tri(self) -> u32 {
        self.0 as u32 & (MAX_TRIANGLES as u32 - 1)
    }
    #[inline]
    pub fn kind(self) -> u32 {
        (self.0 >> 30) as u32 & 3
    }
    /// The same event for another local triangle index.
    #[inline]
    pub fn with_tri(self, tri: u32) -> Event {
        Event(self.0 & !(MAX_TRIANGLES as u64 - 1) | tri as u64)
    }
}

/// Events of one triangle's box on one axis.
#[inline]
pub fn push_events(out: &mut Vec<Event>, b: &Aabb, axis: usize, tri: u32) {
    if b.lo[axis] == b.hi[axis] {
        out.push(Event::new(b.lo[axis], tri, PLANAR));
    } else {
        out.push(Event::new(b.lo[axis], tri, START));
        out.push(Event::new(b.hi[axis], tri, END));
    }
}

pub fn sort(events: &mut [Event], parallel: bool) {
    if parallel {
        events.par_sort_unstable();
    } else {
        events.sort_unstable();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn order_is_position_then_end_planar_start() {
        let mut v = vec![
            Event::new(1.0, 0, START),
            Event::new(1.0, 1, PLANAR),
            Event::new(1.0, 2, END),
            Event::new(-0.0, 3, START),
            Event::new(0.0, 4, END),
            Event::new(-2.0, 5, END),
        ];
        sort(&mut v, false);
        let tris: Vec<u32> = v.iter().map(|e| e.tri()).collect();
        assert_eq!(tris, vec![5, 4, 3, 2, 1, 0]);
    }

    #[test]
    fn fields_survive_the_packing() {
        for pos in [-3.5f32, -0.0, 0.0, 1e-30, 7.25, f32::MAX, f32::NEG_INFINITY] {
            let e = Event::new(pos, MAX_TRIANGLES as u32 - 1, PLANAR);
            assert_eq!(e.pos(), pos + 0.0);
            assert_eq!(e.tri(), MAX_TRIANGLES as u32 - 1);
            assert_eq!(e.kind(), PLANAR);
            let f = e.with_tri(5);
            assert_eq!((f.pos(), f.tri(), f.kind()), (pos + 0.0, 5, PLANAR));
        }
        assert!(Event::new(-1.0, 9, START) < Event::new(-0.5, 0, END));
        assert!(ordered(-1.0) < ordered(0.0) && ordered(0.0) < ordered(1e-45));
    }
}
