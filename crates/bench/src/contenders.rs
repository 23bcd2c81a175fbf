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
    /// Runs a chunk of this contender's queries in the floating-point mode it asks its
    /// callers for: the default mode, but for Embree.
    fn in_mode(&self, run: &mut dyn FnMut()) {
        run()
    }
    /// A packet of 4, 8 or 16 rays (neighbouring pixels, or their shadow rays) at once,
    /// answers into `out`, through the contender's widest packet query that fits.
    fn closest_packet(&self, rays: &[Ray], out: &mut [Found]) {
        for (o, r) in out.iter_mut().zip(rays) {
            *o = self.closest(r);
        }
    }
    /// Any-hit packets, likewise.
    fn occluded_packet(&self, rays: &[Ray], out: &mut [bool]) {
        for (o, r) in out.iter_mut().zip(rays) {
            *o = self.occluded(r);
        }
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
    /// Four-ray packets, the widest the tree has: a packet of 8 or 16 is 2 or 4 of them.
    #[inline]
    fn closest_packet(&self, rays: &[Ray], out: &mut [Found]) {
        for (o, r) in out.chunks_mut(4).zip(rays.chunks(4)) {
            match <&[Ray; 4]>::try_from(r) {
                Ok(four) => o.copy_from_slice(&self.intersect4(four).map(found_kd)),
                Err(_) => o.iter_mut().zip(r).for_each(|(o, r)| *o = self.closest(r)),
            }
        }
    }
    #[inline]
    fn occluded_packet(&self, rays: &[Ray], out: &mut [bool]) {
        for (o, r) in out.chunks_mut(4).zip(rays.chunks(4)) {
            match <&[Ray; 4]>::try_from(r) {
                Ok(four) => o.copy_from_slice(&Accel::occluded4(self, four)),
                Err(_) => o.iter_mut().zip(r).for_each(|(o, r)| *o = self.occluded(r)),
            }
        }
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
    /// Subnormals flushed, as Embree asks ([`crate::embree::flushing_subnormals`]).
    fn in_mode(&self, run: &mut dyn FnMut()) {
        crate::embree::flushing_subnormals(run)
    }
    /// `rtcIntersect4`, `8` or `16`, by the packet's size.
    #[inline]
    fn closest_packet(&self, rays: &[Ray], out: &mut [Found]) {
        if let Ok(p) = <&[Ray; 16]>::try_from(rays) {
            out.copy_from_slice(&self.intersect_n(p).map(found));
        } else if let Ok(p) = <&[Ray; 8]>::try_from(rays) {
            out.copy_from_slice(&self.intersect_n(p).map(found));
        } else if let Ok(p) = <&[Ray; 4]>::try_from(rays) {
            out.copy_from_slice(&self.intersect_n(p).map(found));
        } else {
            out.iter_mut()
                .zip(rays)
                .for_each(|(o, r)| *o = self.closest(r));
        }
    }
    /// `rtcOccluded4`, `8` or `16`, by the packet's size.
    #[inline]
    fn occluded_packet(&self, rays: &[Ray], out: &mut [bool]) {
        if let Ok(p) = <&[Ray; 16]>::try_from(rays) {
            out.copy_from_slice(&self.occluded_n(p));
        } else if let Ok(p) = <&[Ray; 8]>::try_from(rays) {
            out.copy_from_slice(&self.occluded_n(p));
        } else if let Ok(p) = <&[Ray; 4]>::try_from(rays) {
            out.copy_from_slice(&self.occluded_n(p));
        } else {
            out.iter_mut()
                .zip(rays)
                .for_each(|(o, r)| *o = self.occluded(r));
        }
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
