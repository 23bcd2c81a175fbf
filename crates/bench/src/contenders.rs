//! The contenders: their names in the tables, the hit they all report, and the one query
//! interface the benchmark times them through.

use glam::Vec3;
use kdtree::testkit::brute;
use kdtree::{Accel, Ray};

pub const KDTREE: &str = "kdtree";
pub const MEDIAN: &str = "kdtree median";
pub const EMBREE: &str = "Embree";
pub const BRUTE: &str = "brute force";

/// A closest hit as every contender reports it; `prim == u32::MAX` is a miss.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Found {
    pub t: f32,
    pub prim: u32,
    pub u: f32,
    pub v: f32,
}

impl Default for Found {
    fn default() -> Self {
        Found {
            t: f32::INFINITY,
            prim: u32::MAX,
            u: 0.0,
            v: 0.0,
        }
    }
}

impl Found {
    pub fn is_hit(&self) -> bool {
        self.prim != u32::MAX
    }
}

/// What the benchmark asks of every contender.
pub(crate) trait Tracer: Sync {
    fn closest(&self, ray: &Ray) -> Found;
    fn occluded(&self, ray: &Ray) -> bool;
    /// Four rays at once, through the contender's packet query where it has one.
    fn closest4(&self, rays: &[Ray; 4]) -> [Found; 4] {
        rays.each_ref().map(|r| self.closest(r))
    }
    /// Four any-hit rays at once, likewise.
    fn occluded4(&self, rays: &[Ray; 4]) -> [bool; 4] {
        rays.each_ref().map(|r| self.occluded(r))
    }
}

fn found(hit: Option<(f32, u32, f32, f32)>) -> Found {
    hit.map(|(t, prim, u, v)| Found { t, prim, u, v })
        .unwrap_or_default()
}

fn found_kd(hit: Option<kdtree::Hit>) -> Found {
    found(hit.map(|h| (h.t, h.prim, h.u, h.v)))
}

impl Tracer for Accel {
    #[inline]
    fn closest(&self, ray: &Ray) -> Found {
        found_kd(self.intersect(ray))
    }
    #[inline]
    fn occluded(&self, ray: &Ray) -> bool {
        Accel::occluded(self, ray)
    }
    #[inline]
    fn closest4(&self, rays: &[Ray; 4]) -> [Found; 4] {
        self.intersect4(rays).map(found_kd)
    }
    #[inline]
    fn occluded4(&self, rays: &[Ray; 4]) -> [bool; 4] {
        Accel::occluded4(self, rays)
    }
}

#[cfg(feature = "embree")]
impl Tracer for crate::embree::EmbreeScene {
    #[inline]
    fn closest(&self, ray: &Ray) -> Found {
        found(self.intersect(ray))
    }
    #[inline]
    fn occluded(&self, ray: &Ray) -> bool {
        crate::embree::EmbreeScene::occluded(self, ray)
    }
    #[inline]
    fn closest4(&self, rays: &[Ray; 4]) -> [Found; 4] {
        self.intersect4(rays).map(found)
    }
    #[inline]
    fn occluded4(&self, rays: &[Ray; 4]) -> [bool; 4] {
        crate::embree::EmbreeScene::occluded4(self, rays)
    }
}

/// Brute force with the independent f64 reference: every ray against every triangle.
pub(crate) struct Brute<'a>(pub &'a [[Vec3; 3]]);

impl Tracer for Brute<'_> {
    fn closest(&self, ray: &Ray) -> Found {
        brute::intersect_f64(self.0, ray)
            .map(|(t, prim)| Found {
                t,
                prim,
                u: 0.0,
                v: 0.0,
            })
            .unwrap_or_default()
    }
    fn occluded(&self, ray: &Ray) -> bool {
        brute::occluded_f64(self.0, ray)
    }
}
