//! LODGroup (class 205): the level the scene's camera shows, chosen as Unity chooses it
//! at run time; drawing every level would show the object several times over.
//!
//! A group's world size is `m_Size` times the largest of its Transform's world axis
//! lengths (Unity's `lossyScale`, exact without skew); its distance is the Euclidean one
//! from the camera to `m_LocalReferencePoint` carried to world space. Its relative screen
//! height is
//!
//! * perspective: `size · 0.5 / (distance / lodBias · tan(fov_y / 2))`;
//! * orthographic: `size · 0.5 / (orthographic size / lodBias)`, whatever the distance.
//!
//! The first level whose `screenRelativeHeight` that height reaches is shown; below the
//! last level's, the group shows nothing. (Unity's run-time test is strict, its editor's
//! is not; they differ only exactly at a threshold.) Cross-fading is not simulated: at a
//! transition one level is shown whole. lodBias is that of the project's current quality
//! level (`ProjectSettings/QualitySettings.asset`), 1 when the file is absent or does not
//! say. Without a camera LOD0 is kept.

use crate::docs;
use crate::emit::{enabled, Emitter};
use crate::reference::fref;
use crate::yaml::Node;
use formats::Projection;
use glam::Vec3;
use std::collections::{HashMap, HashSet};

/// Relative screen height of a group of world size `size` whose reference point is
/// `distance` from a camera with `projection`, under `lod_bias`.
pub fn relative_height(size: f32, distance: f32, projection: Projection, lod_bias: f32) -> f32 {
    // A physical camera counts by its field of view, as Unity's LOD code takes it.
    match (projection, projection.fov_y()) {
        (Projection::Orthographic { half_height }, _) => size * 0.5 / (half_height / lod_bias),
        (_, fov_y) => {
            let half_angle = (fov_y.unwrap_or(60.0).to_radians() * 0.5).tan();
            size * 0.5 / (distance / lod_bias * half_angle)
        }
    }
}

/// The level shown at relative height `height`: the first whose threshold it reaches,
/// `None` below the last one.
pub fn shown_level(height: f32, thresholds: &[f32]) -> Option<usize> {
    thresholds.iter().position(|&t| height >= t)
}

impl Emitter<'_, '_> {
    /// Renderers (arena indices) that an enabled LODGroup on an active GameObject lists
    /// in a level its camera does not show, each with the reason.
    pub(crate) fn lod_hidden(&mut self) -> HashMap<usize, String> {
        let g = self.g;
        // `renderer: {fileID: N}` names a renderer of the group's own file.
        let mut by_id: HashMap<(usize, i64), Vec<usize>> = HashMap::new();
        for (i, o) in g.objs.iter().enumerate() {
            if matches!(o.class, docs::MESH_RENDERER | docs::SKINNED_MESH_RENDERER) {
                by_id.entry((o.file, o.file_id)).or_default().push(i);
            }
        }
        let mut hidden = HashMap::new();
        for o in &g.objs {
            if o.class != docs::LOD_GROUP || o.removed || !enabled(o) {
                continue;
            }
            let Some(go) = o.go.filter(|&go| self.active(go)) else {
                continue;
            };
            let group = self.path(go);
            let lods = o.body.get("m_LODs").map(Node::as_seq).unwrap_or_default();
            let thresholds: Vec<f32> = lods
                .iter()
                .map(|l| l.f32_at("screenRelativeHeight").unwrap_or(0.0))
                .collect();
            let levels: Vec<Vec<usize>> = lods
                .iter()
                .map(|level| {
                    level
                        .get("renderers")
                        .map(Node::as_seq)
                        .unwrap_or_default()
                        .iter()
                        .flat_map(|r| {
                            let (id, _) = fref(r.get("renderer"));
                            by_id.get(&(o.file, id)).cloned().unwrap_or_default()
                        })
                        .collect()
                })
                .collect();
            if levels.is_empty() {
                continue;
            }
            let height = self
                .lod_camera
                .map(|(camera, projection)| self.group_height(go, &o.body, camera, projection));
            let (shown, why) = match height {
                None => (Some(0), "there is no camera; LOD0 kept".to_string()),
                Some(h) if h.is_nan() => (
                    Some(0),
                    "its screen height is undefined; LOD0 kept".to_string(),
                ),
                Some(h) => match shown_level(h, &thresholds) {
                    Some(k) => (
                        Some(k),
                        format!("the camera shows LOD{k} (relative screen height {h:.3})"),
                    ),
                    None => {
                        let last = thresholds.len() - 1;
                        let t = thresholds[last];
                        let why = format!("relative screen height {h:.3} < LOD{last}'s {t:.3}");
                        (None, why)
                    }
                },
            };
            let kept: HashSet<usize> = shown
                .map(|k| levels[k].iter().copied().collect())
                .unwrap_or_default();
            for (k, level) in levels.iter().enumerate() {
                for &r in level.iter().filter(|r| !kept.contains(r)) {
                    hidden.entry(r).or_insert_with(|| match shown {
                        Some(_) => format!("LOD{k} of LODGroup {group:?}; {why}"),
                        None => format!(
                            "culled: LODGroup {group:?} is below its last level's screen height ({why})"
                        ),
                    });
                }
            }
        }
        hidden
    }

    /// Relative screen height of the LODGroup with body `b` on GameObject `go`, seen from
    /// `camera` (Unity space) with `projection`.
    fn group_height(&mut self, go: usize, b: &Node, camera: Vec3, projection: Projection) -> f32 {
        let world = match self.go_tf.get(&go).copied() {
            Some(t) => self.world(t),
            None => glam::Mat4::IDENTITY,
        };
        let local_point = b
            .get("m_LocalReferencePoint")
            .and_then(Node::vec3)
            .unwrap_or(Vec3::ZERO);
        let point = world.transform_point3(local_point);
        let scale = Vec3::new(
            world.x_axis.truncate().length(),
            world.y_axis.truncate().length(),
            world.z_axis.truncate().length(),
        )
        .max_element();
        let size = b.f32_at("m_Size").unwrap_or(1.0) * scale;
        relative_height(
            size,
            camera.distance(point),
            projection,
            self.g.project.settings.lod_bias,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn relative_height_matches_unitys_rule() {
        let tan30 = 30f32.to_radians().tan();
        let p = Projection::Perspective { fov_y: 60.0 };
        let h = relative_height(1.0, 2.0, p, 1.0);
        assert!((h - 0.5 / (2.0 * tan30)).abs() < 1e-6, "{h}");
        // lodBias 2 halves the distance.
        assert!((relative_height(1.0, 2.0, p, 2.0) - 2.0 * h).abs() < 1e-6);
        let o = Projection::Orthographic { half_height: 4.0 };
        assert_eq!(relative_height(1.0, 100.0, o, 1.0), 0.125);
        assert_eq!(relative_height(1.0, 1.0, o, 2.0), 0.25);
        // A physical camera counts by its sensor height's field of view: 24 mm at 50 mm
        // spans tan = 0.24 either side.
        let lens = Projection::Physical {
            focal_length: 50.0,
            sensor: glam::Vec2::new(36.0, 24.0),
            lens_shift: glam::Vec2::ZERO,
            gate_fit: formats::GateFit::Horizontal,
        };
        let h = relative_height(1.0, 2.0, lens, 1.0);
        assert!((h - 0.5 / (2.0 * 0.24)).abs() < 1e-5, "{h}");
        assert_eq!(shown_level(0.3, &[0.5, 0.2, 0.05]), Some(1));
        assert_eq!(shown_level(0.5, &[0.5, 0.2, 0.05]), Some(0));
        assert_eq!(shown_level(0.01, &[0.5, 0.2, 0.05]), None);
        assert_eq!(shown_level(f32::INFINITY, &[0.5]), Some(0));
    }
}
