//! Axis-aligned boxes in f32 (cells, scene bounds) and the SAH's surface areas.

use glam::Vec3;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    pub lo: [f32; 3],
    pub hi: [f32; 3],
}

impl Aabb {
    pub const EMPTY: Aabb = Aabb {
        lo: [f32::INFINITY; 3],
        hi: [f32::NEG_INFINITY; 3],
    };

    pub fn of_triangle(t: &[Vec3; 3]) -> Aabb {
        let lo = t[0].min(t[1]).min(t[2]);
        let hi = t[0].max(t[1]).max(t[2]);
        Aabb {
            lo: lo.to_array(),
            hi: hi.to_array(),
        }
    }

    pub fn union(&self, o: &Aabb) -> Aabb {
        let mut r = *self;
        for a in 0..3 {
            r.lo[a] = r.lo[a].min(o.lo[a]);
            r.hi[a] = r.hi[a].max(o.hi[a]);
        }
        r
    }

    pub fn is_empty(&self) -> bool {
        (0..3).any(|a| !(self.lo[a] <= self.hi[a]))
    }

    /// Surface area in f64 (the SAH needs ratios of areas that may differ by 10¹⁰).
    pub fn area(&self) -> f64 {
        let e: [f64; 3] = std::array::from_fn(|a| (self.hi[a] as f64 - self.lo[a] as f64).max(0.0));
        2.0 * (e[0] * e[1] + e[1] * e[2] + e[0] * e[2])
    }

    /// The two halves of this box cut by the plane `axis = pos`.
    pub fn split(&self, axis: usize, pos: f32) -> (Aabb, Aabb) {
        let mut below = *self;
        let mut above = *self;
        below.hi[axis] = pos;
        above.lo[axis] = pos;
        (below, above)
    }

    pub fn to_vec3(&self) -> [Vec3; 2] {
        [Vec3::from(self.lo), Vec3::from(self.hi)]
    }
}
