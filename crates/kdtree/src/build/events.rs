//! SAH split events (Wald & Havran 2006): per axis, one sorted list of the positions where
//! triangles start, end or lie flat. Kept sorted through every split, so the whole build
//! sorts once plus the few events of triangles that straddle a split.

use crate::aabb::Aabb;
use rayon::prelude::*;

pub const END: u32 = 0;
pub const PLANAR: u32 = 1;
pub const START: u32 = 2;

/// 8 bytes: a position and (local triangle index << 2 | kind).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Event {
    pub pos: f32,
    pub code: u32,
}

impl Event {
    #[inline]
    pub fn new(pos: f32, tri: u32, kind: u32) -> Event {
        // +0.0 turns −0.0 into +0.0, so equal positions sort and group together.
        Event {
            pos: pos + 0.0,
            code: (tri << 2) | kind,
        }
    }
    #[inline]
    pub fn tri(self) -> u32 {
        self.code >> 2
    }
    #[inline]
    pub fn kind(self) -> u32 {
        self.code & 3
    }
    /// Sort key: position, then end < planar < start at equal positions.
    #[inline]
    pub fn key(self) -> u64 {
        let b = self.pos.to_bits();
        let ordered = if b >> 31 == 1 { !b } else { b | 0x8000_0000 };
        ((ordered as u64) << 32) | self.kind() as u64
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
        events.par_sort_unstable_by_key(|e| e.key());
    } else {
        events.sort_unstable_by_key(|e| e.key());
    }
}

/// Merge two sorted lists into one sorted list.
pub fn merge(a: Vec<Event>, b: Vec<Event>) -> Vec<Event> {
    if b.is_empty() {
        return a;
    }
    if a.is_empty() {
        return b;
    }
    let mut out = Vec::with_capacity(a.len() + b.len());
    let (mut i, mut j) = (0, 0);
    while i < a.len() && j < b.len() {
        if a[i].key() <= b[j].key() {
            out.push(a[i]);
            i += 1;
        } else {
            out.push(b[j]);
            j += 1;
        }
    }
    out.extend_from_slice(&a[i..]);
    out.extend_from_slice(&b[j..]);
    out
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
        let merged = merge(vec![v[0], v[2], v[4]], vec![v[1], v[3], v[5]]);
        assert_eq!(merged, v);
    }
}
