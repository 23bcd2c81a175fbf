//! RenderSettings (class 104): the ambient light of the scene.

use crate::material::linear_rgb;
use crate::yaml::Node;
use formats::{Ambient, AmbientMode};
use glam::Vec3;

/// The ambient light a RenderSettings body sets; `None` when a colour is not finite
/// (the soup keeps its default).
pub fn ambient(rs: &Node) -> Option<Ambient> {
    let intensity = rs.f32_at("m_AmbientIntensity").unwrap_or(1.0);
    let col = |k: &str| {
        rs.get(k)
            .and_then(Node::color)
            .map(linear_rgb)
            .unwrap_or(Vec3::ZERO)
            * intensity
    };
    let mode = match rs.i64_at("m_AmbientMode").unwrap_or(0) {
        1 => AmbientMode::Trilight,
        3 => AmbientMode::Flat,
        _ => AmbientMode::Skybox,
    };
    let amb = Ambient {
        mode,
        sky: col("m_AmbientSkyColor"),
        equator: col("m_AmbientEquatorColor"),
        ground: col("m_AmbientGroundColor"),
    };
    [amb.sky, amb.equator, amb.ground]
        .iter()
        .all(|c| c.is_finite())
        .then_some(amb)
}
