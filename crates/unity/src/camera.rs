//! Camera (class 20) → the soup's camera and the environment's clear flags and
//! background: the Game view's camera among the scene's enabled ones.

use crate::docs;
use crate::emit::{flip, EmitError, Emitter};
use crate::material::shaded_rgb;
use crate::reference::fref;
use crate::settings::Pipeline;
use crate::yaml::Node;
use formats::{Camera, ClearFlags, GateFit, Projection};
use glam::{Mat4, Vec2, Vec3, Vec4Swizzles};

/// The camera a body and world transform describe; `None` when its orientation is
/// degenerate.
pub fn convert(b: &Node, world: Mat4, name: String) -> Option<Camera> {
    let forward = flip(world.transform_vector3(Vec3::Z)).normalize_or_zero();
    let up0 = flip(world.transform_vector3(Vec3::Y));
    let up = (up0 - forward * up0.dot(forward)).normalize_or_zero();
    if forward == Vec3::ZERO || up == Vec3::ZERO {
        return None;
    }
    let projection = if b.i64_at("orthographic") == Some(1) {
        Projection::Orthographic {
            half_height: b.f32_at("orthographic size").unwrap_or(5.0),
        }
    } else if b.i64_at("m_projectionMatrixMode") == Some(PHYSICAL) {
        physical(b)
    } else {
        Projection::Perspective {
            fov_y: b.f32_at("field of view").unwrap_or(60.0),
        }
    };
    Some(Camera {
        name,
        position: flip(world.w_axis.xyz()),
        forward,
        up,
        projection,
        near: b.f32_at("near clip plane").unwrap_or(0.3),
        far: b.f32_at("far clip plane").unwrap_or(1000.0),
    })
}

/// `m_projectionMatrixMode` of a Physical Camera (its projection from lens and sensor).
const PHYSICAL: i64 = 2;

/// A Physical Camera's lens, sensor, lens shift and gate fit; a field it lacks takes the
/// default of a new camera: 50 mm over a 36 × 24 mm sensor, no shift, Horizontal fit.
fn physical(b: &Node) -> Projection {
    let vec2 = |key: &str, default: Vec2| {
        b.get(key)
            .and_then(|v| Some(Vec2::new(v.f32_at("x")?, v.f32_at("y")?)))
            .unwrap_or(default)
    };
    Projection::Physical {
        focal_length: b.f32_at("m_FocalLength").unwrap_or(50.0),
        sensor: vec2("m_SensorSize", Vec2::new(36.0, 24.0)),
        lens_shift: vec2("m_LensShift", Vec2::ZERO),
        gate_fit: match b.i64_at("m_GateFitMode") {
            Some(0) => GateFit::None,
            Some(1) => GateFit::Vertical,
            Some(3) => GateFit::Fill,
            Some(4) => GateFit::Overscan,
            _ => GateFit::Horizontal,
        },
    }
}

/// A (GameObject, Camera component) pair.
type Pair = (usize, usize);

/// The script of URP's per-camera settings (`UniversalAdditionalCameraData`).
pub(crate) const URP_CAMERA_DATA: &str = "a79441f348de89743a2939f4d699eac1";

/// What the camera clears to: the skybox (`m_ClearFlags` 1) or a solid colour.
pub fn clear_flags(b: &Node) -> ClearFlags {
    if b.i64_at("m_ClearFlags").unwrap_or(1) == 1 {
        ClearFlags::Skybox
    } else {
        ClearFlags::SolidColor
    }
}

impl Emitter<'_, '_> {
    /// URP's settings for the camera on GameObject `go`, where a URP project has them.
    fn urp_camera_data(&self, go: usize) -> Option<&Node> {
        if self.g.project.settings.pipeline != Pipeline::Universal {
            return None;
        }
        self.go_comps.get(&go)?.iter().find_map(|&i| {
            let o = &self.g.objs[i];
            let script = fref(o.body.get("m_Script")).1;
            (o.class == docs::MONO_BEHAVIOUR && script.as_deref() == Some(URP_CAMERA_DATA))
                .then_some(&o.body)
        })
    }

    /// Camera component `c` on `go` draws over the image of the cameras below it: in URP an
    /// Overlay camera (`m_CameraType` 1), else one that clears only depth or nothing
    /// (`m_ClearFlags` 3 or 4).
    fn overlay(&self, go: usize, c: usize) -> bool {
        if self.g.project.settings.pipeline == Pipeline::Universal {
            return self
                .urp_camera_data(go)
                .and_then(|d| d.i64_at("m_CameraType"))
                == Some(1);
        }
        matches!(self.g.objs[c].body.i64_at("m_ClearFlags"), Some(3 | 4))
    }

    /// The soup's camera from the enabled `(GameObject, Camera)` pairs: the one `asked`
    /// names (by GameObject name or path), else the Game view's.
    pub(crate) fn camera(&mut self, cams: &[Pair], asked: Option<&str>) -> Result<(), EmitError> {
        let (g, scene_rel) = (self.g, self.scene_rel);
        if let Some(name) = asked {
            let named = cams.iter().find(|&&(go, _)| {
                let path = self.path(go);
                path == name || path.rsplit('/').next() == Some(name)
            });
            let Some(&(go, c)) = named else {
                let mut all: Vec<String> = cams.iter().map(|&(go, _)| self.path(go)).collect();
                if all.is_empty() {
                    all.push("none".into());
                }
                return Err(EmitError::NoSuchCamera {
                    file: scene_rel.to_string(),
                    asked: name.to_string(),
                    cameras: all.join(", "),
                });
            };
            return self.use_camera(go, c);
        }
        let depth = |c: usize| g.objs[c].body.f32_at("m_Depth").unwrap_or(0.0);
        // The Game view shows the display cameras; the highest depth draws last.
        let display: Vec<(usize, usize)> = cams
            .iter()
            .copied()
            .filter(|(_, c)| fref(g.objs[*c].body.get("m_TargetTexture")).0 == 0)
            .collect();
        // A camera that draws over the others' image (a depth-only or URP overlay camera:
        // a weapon, a UI) is not the view; the highest camera that clears is.
        let (overlays, base): (Vec<Pair>, Vec<Pair>) =
            display.iter().partition(|&&(go, c)| self.overlay(go, c));
        let candidates = if base.is_empty() { &overlays } else { &base };
        let mut best: Option<(usize, usize)> = None;
        for &c in candidates {
            if best.is_none_or(|b| depth(c.1) > depth(b.1)) {
                best = Some(c);
            }
        }
        let Some((go, c)) = best else {
            self.soup.warnings.push(format!("{scene_rel}: no enabled camera renders to the display; Unity's default camera used"));
            return Ok(());
        };
        if candidates.len() > 1 {
            self.soup.warnings.push(format!(
                "{scene_rel}: {} enabled cameras; using '{}' (highest depth, first in the file)",
                candidates.len(),
                self.path(go)
            ));
        }
        // A built-in depth-only camera below the view is cleared away by it; URP draws an
        // overlay camera in the stack of a base camera, whatever its depth.
        let urp = g.project.settings.pipeline == Pipeline::Universal;
        let names: Vec<String> = overlays
            .iter()
            .filter(|&&(_, o)| !base.is_empty() && (urp || depth(o) > depth(c)))
            .map(|&(o, _)| self.path(o))
            .collect();
        if !names.is_empty() {
            self.soup.warnings.push(format!(
                "{scene_rel}: camera(s) '{}' draw over '{}' in Unity (depth-only or URP \
                 overlay); not composited: the image is '{}''s view alone",
                names.join("', '"),
                self.path(go),
                self.path(go)
            ));
        }
        self.use_camera(go, c)
    }

    /// Camera component `c` on GameObject `go` becomes the soup's camera.
    fn use_camera(&mut self, go: usize, c: usize) -> Result<(), EmitError> {
        let (g, scene_rel) = (self.g, self.scene_rel);
        if self
            .urp_camera_data(go)
            .and_then(|d| d.i64_at("m_RenderShadows"))
            == Some(0)
        {
            self.camera_shadows = false;
        }
        let b = &g.objs[c].body;
        let world = self.checked_world(go)?;
        let Some(mut camera) = convert(b, world, self.path(go)) else {
            return Err(self.non_finite(go, "camera orientation is degenerate".into()));
        };
        // Unity's inspector keeps the far plane beyond the near one; a file that does not
        // is drawn without a far limit rather than empty.
        let beyond = camera.far > camera.near;
        if !beyond {
            self.soup.warnings.push(format!(
                "{scene_rel}: camera '{}': far clip plane {} is not beyond the near plane {}; \
                 drawn without a far limit",
                camera.name, camera.far, camera.near
            ));
            camera.far = f32::INFINITY;
        }
        self.lod_camera = Some((world.w_axis.xyz(), camera.projection));
        self.soup.camera = camera;
        self.camera_mask = crate::layer::culling_mask(b);
        self.soup.environment.clear = clear_flags(b);
        if let Some(bg) = b.get("m_BackGroundColor").and_then(Node::color) {
            self.soup.environment.background = shaded_rgb(bg, g.project.settings.color_space);
        }
        Ok(())
    }
}
