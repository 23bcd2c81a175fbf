//! Ray cones: how wide the bundle of rays one pixel stands for is where a ray hits, so a
//! texture lookup can filter over that footprint instead of aliasing.
//!
//! A camera ray starts as a cone one pixel wide: zero width and the pixel's spread angle
//! for a perspective camera, one pixel's width and no spread for an orthographic one. The
//! width grows linearly with the distance travelled. A mirror keeps the spread and starts
//! the reflected cone at the width reached at the hit: mirrors are treated as flat, so a
//! curved mirror's widening or narrowing of the bundle is ignored (curved metal shows its
//! reflected textures slightly too sharp or too blurred). Continuing past a blended surface
//! keeps the cone unchanged.

/// A cone `width + spread·t` wide at distance t along a unit-direction ray.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayCone {
    /// Width at the ray's origin, in world units.
    pub width: f32,
    /// Growth of the width per unit distance (the full spread angle, small-angle).
    pub spread: f32,
}

impl RayCone {
    /// The width at distance `t`.
    pub fn at(&self, t: f32) -> f32 {
        self.width + self.spread * t
    }

    /// The cone of one of `samples` stratified samples of a pixel: each stands for a
    /// 1/√samples share of the pixel's width, so the box filter over the samples and the
    /// texture filter over each sample's footprint do not blur the same pixel twice.
    pub fn per_sample(&self, samples: u32) -> RayCone {
        let k = 1.0 / (samples.max(1) as f32).sqrt();
        RayCone {
            width: self.width * k,
            spread: self.spread * k,
        }
    }

    /// The cone of a mirror ray leaving a hit at distance `t`.
    pub fn reflected(&self, t: f32) -> RayCone {
        RayCone {
            width: self.at(t),
            spread: self.spread,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn width_grows_with_distance_and_mirrors_keep_it() {
        let c = RayCone {
            width: 0.0,
            spread: 0.125,
        };
        assert_eq!(c.at(10.0), 1.25);
        let r = c.reflected(10.0);
        assert_eq!(r.at(0.0), 1.25);
        assert_eq!(r.at(2.0), 1.5);
        assert_eq!(c.per_sample(1), c);
        assert_eq!(c.per_sample(16).at(10.0), 1.25 / 4.0);
    }
}
