//! RenderSettings fog, as Unity's shaders apply it: each drawn surface's colour is mixed
//! toward the fog colour by how far it lies, and what no surface covers (the background)
//! is left clear.

use formats::{Camera, Fog};
use glam::Vec3;
use kdtree::Ray;

/// The scene's fog prepared for the camera that sees it.
#[derive(Clone, Copy, Debug)]
pub struct FogModel {
    fog: Fog,
    forward: Vec3,
    near: f32,
    /// `far / (far − near)`, 1 without a far plane.
    stretch: f32,
}

impl FogModel {
    pub fn new(fog: Fog, cam: &Camera) -> Self {
        let near = if cam.near.is_finite() { cam.near } else { 0.0 };
        let stretch = if cam.far > near && cam.far.is_finite() {
            cam.far / (cam.far - near)
        } else {
            1.0
        };
        FogModel {
            fog,
            forward: cam.forward.normalize_or_zero(),
            near,
            stretch,
        }
    }

    /// Unity's fog coordinate of a hit at `t` along `ray` (unit direction). For the
    /// camera's own rays (`bounce` 0) it is what the shaders derive from clip-space depth,
    /// `far·(z − near)/(far − near)` with z the depth along the view direction; a mirror
    /// ray's segment is fogged by its length, as a reflection probe's camera at the
    /// mirror would fog what it sees.
    #[inline(always)]
    fn coordinate(&self, ray: &Ray, t: f32, bounce: u32) -> f32 {
        if bounce == 0 {
            (self.stretch * (t * ray.dir.dot(self.forward) - self.near)).max(0.0)
        } else {
            t
        }
    }

    /// The light `l` a surface at `t` along `ray` sends back, seen through the fog.
    #[inline(always)]
    pub fn apply(&self, l: Vec3, ray: &Ray, t: f32, bounce: u32) -> Vec3 {
        let keep = self.fog.keep(self.coordinate(ray, t, bounce));
        self.fog.colour.lerp(l, keep)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use formats::FogMode;

    fn model(mode: FogMode) -> FogModel {
        let cam = Camera {
            position: Vec3::ZERO,
            forward: Vec3::Z,
            near: 0.5,
            far: 100.5,
            ..Camera::default()
        };
        let fog = Fog {
            mode,
            colour: Vec3::new(0.5, 0.6, 0.7),
        };
        FogModel::new(fog, &cam)
    }

    fn ray(dir: Vec3) -> Ray {
        Ray {
            origin: Vec3::ZERO,
            dir,
            tmin: 0.0,
            tmax: f32::INFINITY,
        }
    }

    #[test]
    fn the_camera_fogs_by_depth_from_its_near_plane() {
        let m = model(FogMode::Exponential { density: 0.1 });
        // Depth 10.5 along the view: coordinate 100.5·10/100 = 10.05.
        let want = (-0.1f32 * 10.05).exp();
        let l = m.apply(Vec3::ONE, &ray(Vec3::Z), 10.5, 0);
        let c = Vec3::new(0.5, 0.6, 0.7);
        assert!(
            (l - (c + (Vec3::ONE - c) * want)).abs().max_element() < 1e-6,
            "{l}"
        );
        // The same depth seen obliquely: 60° off the axis is twice as far along the ray.
        let oblique = Vec3::new(3f32.sqrt() / 2.0, 0.0, 0.5);
        let o = m.apply(Vec3::ONE, &ray(oblique), 21.0, 0);
        assert!((o - l).abs().max_element() < 1e-5, "{o} {l}");
        // Nearer than the near plane: no fog.
        assert_eq!(m.apply(Vec3::ONE, &ray(Vec3::Z), 0.2, 0), Vec3::ONE);
    }

    #[test]
    fn a_mirror_segment_fogs_by_its_length() {
        let m = model(FogMode::ExponentialSquared { density: 0.05 });
        let keep = (-(0.05f32 * 8.0).powi(2)).exp();
        let l = m.apply(Vec3::ZERO, &ray(Vec3::X), 8.0, 1);
        let c = Vec3::new(0.5, 0.6, 0.7);
        assert!((l - c * (1.0 - keep)).abs().max_element() < 1e-6, "{l}");
    }

    #[test]
    fn linear_fog_is_clear_before_start_and_thick_past_end() {
        let m = model(FogMode::Linear {
            start: 2.0,
            end: 12.0,
        });
        let c = Vec3::new(0.5, 0.6, 0.7);
        let at = |t: f32| m.apply(Vec3::ZERO, &ray(Vec3::Z), t, 1);
        assert_eq!(at(1.0), Vec3::ZERO);
        assert!((at(7.0) - c * 0.5).abs().max_element() < 1e-6);
        assert_eq!(at(50.0), c);
    }
}
