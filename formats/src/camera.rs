//! The soup's camera: where it stands and looks, and how it projects the scene onto the
//! image (perspective, orthographic, or a physical lens over a sensor).

use glam::{Vec2, Vec3};
use serde::{Deserialize, Serialize};

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum Projection {
    /// Vertical field of view in degrees.
    Perspective { fov_y: f32 },
    /// Half of the view's height in metres.
    Orthographic { half_height: f32 },
    /// A physical camera (Unity's Physical Camera): a lens of `focal_length` mm over a
    /// sensor `sensor` mm wide and high, shifted by `lens_shift` sensor widths and heights,
    /// its sensor fitted to the image as `gate_fit` says.
    Physical {
        focal_length: f32,
        sensor: Vec2,
        lens_shift: Vec2,
        gate_fit: GateFit,
    },
}

/// How a physical camera's sensor meets an image of another aspect ratio (Unity's
/// `Camera.GateFitMode`, in its numbering).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum GateFit {
    /// The sensor stretched to the image.
    None,
    /// The image as high as the sensor.
    Vertical,
    /// The image as wide as the sensor.
    Horizontal,
    /// The image inside the sensor: as wide or as high, whichever crops.
    Fill,
    /// The sensor inside the image: as wide or as high, whichever shows more.
    Overscan,
}

/// A perspective view's extent at unit distance in front of the camera: half its width and
/// height, and where its centre lies off the view direction (right, up).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frustum {
    pub half_w: f32,
    pub half_h: f32,
    pub centre: Vec2,
}

impl Projection {
    /// The view of a perspective or physical camera over an image `aspect` (width ÷ height)
    /// wide; None for an orthographic one. A physical camera's sensor spans sensor/focal
    /// length at unit distance, fitted to the image by its gate fit; its lens shift moves the
    /// view by that many sensor widths and heights.
    pub fn frustum(&self, aspect: f32) -> Option<Frustum> {
        match *self {
            Projection::Perspective { fov_y } => {
                let half_h = (fov_y.to_radians() * 0.5).tan();
                Some(Frustum {
                    half_w: half_h * aspect,
                    half_h,
                    centre: Vec2::ZERO,
                })
            }
            Projection::Orthographic { .. } => None,
            Projection::Physical {
                focal_length,
                sensor,
                lens_shift,
                gate_fit,
            } => {
                let half = sensor / (2.0 * focal_length);
                let wider = aspect > sensor.x / sensor.y;
                let vertical = match gate_fit {
                    GateFit::None => {
                        return Some(Frustum {
                            half_w: half.x,
                            half_h: half.y,
                            centre: lens_shift * sensor / focal_length,
                        })
                    }
                    GateFit::Vertical => true,
                    GateFit::Horizontal => false,
                    GateFit::Fill => !wider,
                    GateFit::Overscan => wider,
                };
                let (half_w, half_h) = if vertical {
                    (half.y * aspect, half.y)
                } else {
                    (half.x, half.x / aspect)
                };
                Some(Frustum {
                    half_w,
                    half_h,
                    centre: lens_shift * sensor / focal_length,
                })
            }
        }
    }

    /// The vertical field of view, in degrees, Unity's `Camera.fieldOfView` reports (a
    /// physical camera's is its sensor height's, before any gate fit); None for an
    /// orthographic camera.
    pub fn fov_y(&self) -> Option<f32> {
        match *self {
            Projection::Perspective { fov_y } => Some(fov_y),
            Projection::Orthographic { .. } => None,
            Projection::Physical {
                focal_length,
                sensor,
                ..
            } => Some((sensor.y / (2.0 * focal_length)).atan().to_degrees() * 2.0),
        }
    }

    /// Why the projection draws no image, if it draws none: a field of view outside
    /// (0°, 180°), an orthographic size that is not positive, a lens or sensor that is not.
    pub fn fault(&self) -> Option<String> {
        match *self {
            Projection::Perspective { fov_y } if !(fov_y > 0.0 && fov_y < 180.0) => Some(format!(
                "vertical field of view {fov_y}° is not in (0, 180)"
            )),
            Projection::Orthographic { half_height }
                if !(half_height > 0.0 && half_height.is_finite()) =>
            {
                Some(format!("orthographic size {half_height} is not positive"))
            }
            Projection::Physical {
                focal_length,
                sensor,
                lens_shift,
                ..
            } if !(focal_length > 0.0
                && focal_length.is_finite()
                && sensor.min_element() > 0.0
                && sensor.is_finite()
                && lens_shift.is_finite()) =>
            {
                Some(format!(
                    "physical camera with focal length {focal_length} mm, sensor {sensor} mm \
                     and lens shift {lens_shift} draws no view"
                ))
            }
            _ => None,
        }
    }
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Camera {
    pub name: String,
    pub position: Vec3,
    /// Unit view direction.
    pub forward: Vec3,
    /// Unit up vector, orthogonal to `forward`. Image right is `forward × up`.
    pub up: Vec3,
    pub projection: Projection,
    pub near: f32,
    /// Far clip plane, along `forward`: nothing further is seen (infinite: no limit).
    pub far: f32,
}

impl Camera {
    /// Image-right direction. Because the soup is right-handed, `forward × up` points to
    /// the right of the picture, exactly as Unity's +X does in the Game view.
    pub fn right(&self) -> Vec3 {
        self.forward.cross(self.up).normalize_or_zero()
    }
}

impl Default for Camera {
    /// Unity's new-scene camera: at (0, 1, −10) looking along +Z, 60° vertical FOV
    /// (converted to soup space).
    fn default() -> Self {
        Camera {
            name: "Default Camera".into(),
            position: Vec3::new(0.0, 1.0, -10.0),
            forward: Vec3::Z,
            up: Vec3::Y,
            projection: Projection::Perspective { fov_y: 60.0 },
            near: 0.3,
            far: 1000.0,
        }
    }
}
