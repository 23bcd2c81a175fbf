//! Camera rays: perspective (vertical field of view), physical (focal length, sensor, lens
//! shift and gate fit) or orthographic (half height).

use crate::cone::RayCone;
use crate::RenderError;
use formats::{Camera, Projection};
use glam::{Vec2, Vec3};
use kdtree::Ray;

/// A soup camera prepared for an image of `width`×`height` pixels.
#[derive(Clone, Debug)]
pub struct CameraModel {
    position: Vec3,
    forward: Vec3,
    right: Vec3,
    up: Vec3,
    /// Half extent of the view at unit distance (perspective) or in metres (orthographic).
    half_w: f32,
    half_h: f32,
    /// Where the view's centre lies off `forward` at unit distance (a physical camera's
    /// lens shift), along right and up.
    centre: Vec2,
    ortho: bool,
    near: f32,
    /// Infinite when the camera sets no far limit beyond `near`.
    far: f32,
    width: f32,
    height: f32,
}

impl CameraModel {
    pub fn new(cam: &Camera, width: u32, height: u32) -> Result<Self, RenderError> {
        let bad = |detail: String| RenderError::Camera {
            name: cam.name.clone(),
            detail,
        };
        let forward = cam.forward.normalize_or_zero();
        // Image right is forward × up in the right-handed soup, which puts +X of an unrotated
        // Unity camera on the right as in the Game view; re-derive up so the frame is orthonormal.
        let right = cam.right();
        if forward == Vec3::ZERO || right == Vec3::ZERO || !cam.position.is_finite() {
            return Err(bad(format!(
                "position {}, forward {} and up {} do not define a view",
                cam.position, cam.forward, cam.up
            )));
        }
        let up = right.cross(forward);
        if let Some(fault) = cam.projection.fault() {
            return Err(bad(fault));
        }
        let aspect = width as f32 / height as f32;
        let (half_w, half_h, centre, ortho) = match cam.projection.frustum(aspect) {
            Some(f) => (f.half_w, f.half_h, f.centre, false),
            None => {
                let Projection::Orthographic { half_height } = cam.projection else {
                    unreachable!("only an orthographic projection has no frustum")
                };
                (half_height * aspect, half_height, Vec2::ZERO, true)
            }
        };
        Ok(CameraModel {
            position: cam.position,
            forward,
            right,
            up,
            half_w,
            half_h,
            centre,
            ortho,
            near: if cam.near.is_finite() {
                cam.near.max(0.0)
            } else {
                0.0
            },
            far: if cam.far > cam.near {
                cam.far
            } else {
                f32::INFINITY
            },
            width: width as f32,
            height: height as f32,
        })
    }

    /// The ray cone of one pixel (the same for every pixel: the spread of the image centre's
    /// pixel, which the off-axis pixels of a wide lens exceed a little).
    pub fn cone(&self) -> RayCone {
        let pixel = 2.0 * self.half_h / self.height;
        if self.ortho {
            RayCone {
                width: pixel,
                spread: 0.0,
            }
        } else {
            RayCone {
                width: 0.0,
                spread: pixel,
            }
        }
    }

    /// The ray through image position (`px`, `py`) in pixels of the full image, with
    /// (0, 0) the top-left corner of the top-left pixel and y growing downwards. Geometry
    /// nearer than the camera's near clip plane or beyond its far one is not seen, as in
    /// Unity.
    pub fn ray(&self, px: f32, py: f32) -> Ray {
        let sx = (2.0 * px / self.width - 1.0) * self.half_w + self.centre.x;
        let sy = (1.0 - 2.0 * py / self.height) * self.half_h + self.centre.y;
        if self.ortho {
            Ray {
                origin: self.position + self.right * sx + self.up * sy,
                dir: self.forward,
                tmin: self.near,
                tmax: self.far,
            }
        } else {
            let dir = (self.forward + self.right * sx + self.up * sy).normalize();
            // The clip planes are at `near` and `far` along forward: further along an
            // oblique ray.
            let along = dir.dot(self.forward);
            Ray {
                origin: self.position,
                dir,
                tmin: self.near / along,
                tmax: self.far / along,
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn centre_ray_looks_forward_and_right_is_right() {
        let cam = Camera::default();
        let m = CameraModel::new(&cam, 200, 100).unwrap();
        let r = m.ray(100.0, 50.0);
        assert!((r.dir - cam.forward).length() < 1e-6);
        let right = m.ray(200.0, 50.0);
        assert!(right.dir.dot(cam.right()) > 0.0);
        let top = m.ray(100.0, 0.0);
        assert!(top.dir.y > 0.0);
        // The top edge is at fov/2 above the axis.
        let a = top.dir.dot(cam.forward).acos().to_degrees();
        assert!((a - 30.0).abs() < 1e-3, "{a}");
    }

    #[test]
    fn orthographic_rays_are_parallel_and_span_the_half_height() {
        let cam = Camera {
            projection: Projection::Orthographic { half_height: 2.0 },
            ..Camera::default()
        };
        let m = CameraModel::new(&cam, 100, 100).unwrap();
        let top = m.ray(50.0, 0.0);
        assert_eq!(top.dir, cam.forward);
        assert!((top.origin - (cam.position + Vec3::Y * 2.0)).length() < 1e-5);
    }

    #[test]
    fn a_pixel_cone_spans_one_pixel() {
        let m = CameraModel::new(&Camera::default(), 200, 100).unwrap();
        let c = m.cone();
        // Two neighbouring centre rays are one cone width apart at unit distance.
        let (a, b) = (m.ray(100.0, 50.0).dir, m.ray(101.0, 50.0).dir);
        assert!((c.at(1.0) - (a - b).length()).abs() < 1e-5, "{c:?}");
        let ortho = Camera {
            projection: Projection::Orthographic { half_height: 2.0 },
            ..Camera::default()
        };
        let c = CameraModel::new(&ortho, 100, 100).unwrap().cone();
        assert_eq!((c.width, c.spread), (0.04, 0.0));
    }

    #[test]
    fn a_physical_cameras_rays_cross_its_shifted_sensor() {
        // 50 mm over 36 × 24 mm, shifted a quarter of the sensor up, fitted horizontally
        // to a 2:1 image: at unit distance the image spans ±0.36 across and ±0.18 up,
        // centred 0.12 above the view direction.
        let cam = Camera {
            projection: Projection::Physical {
                focal_length: 50.0,
                sensor: glam::Vec2::new(36.0, 24.0),
                lens_shift: glam::Vec2::new(0.0, 0.25),
                gate_fit: formats::GateFit::Horizontal,
            },
            ..Camera::default()
        };
        let m = CameraModel::new(&cam, 200, 100).unwrap();
        let at = |px: f32, py: f32| {
            let d = m.ray(px, py).dir;
            (d / d.dot(cam.forward)) - cam.forward
        };
        let close = |a: Vec3, b: Vec3| (a - b).length() < 1e-6;
        let up = Vec3::Y;
        let right = cam.right();
        assert!(close(at(100.0, 50.0), up * 0.12), "{}", at(100.0, 50.0));
        assert!(close(at(0.0, 0.0), right * -0.36 + up * 0.30));
        assert!(close(at(200.0, 100.0), right * 0.36 + up * -0.06));
        let blind = Camera {
            projection: Projection::Physical {
                focal_length: -1.0,
                sensor: glam::Vec2::new(36.0, 24.0),
                lens_shift: glam::Vec2::ZERO,
                gate_fit: formats::GateFit::Fill,
            },
            ..Camera::default()
        };
        let err = CameraModel::new(&blind, 10, 10).unwrap_err().to_string();
        assert!(err.contains("focal length -1 mm"), "{err}");
    }

    #[test]
    fn a_degenerate_camera_is_refused() {
        let mut cam = Camera::default();
        cam.up = cam.forward;
        assert!(CameraModel::new(&cam, 10, 10).is_err());
    }
}
