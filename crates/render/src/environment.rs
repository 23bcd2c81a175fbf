//! What the scene's surroundings contribute: the background seen by rays that miss and
//! the ambient light on surfaces.

use crate::sky::Skybox;
use formats::{AmbientMode, ClearFlags, Environment};
use glam::Vec3;

/// Sky gradient used for a Skybox camera when the scene's ambient colours are all black
/// (a plain blue sky over a grey ground, linear RGB).
pub const DEFAULT_SKY: [Vec3; 3] = [
    Vec3::new(0.22, 0.36, 0.62),
    Vec3::new(0.70, 0.76, 0.84),
    Vec3::new(0.20, 0.19, 0.18),
];

/// Blend sky (y = 1), equator (y = 0) and ground (y = −1) linearly by `y`.
pub fn trilight(sky: Vec3, equator: Vec3, ground: Vec3, y: f32) -> Vec3 {
    let y = y.clamp(-1.0, 1.0);
    if y >= 0.0 {
        equator.lerp(sky, y)
    } else {
        equator.lerp(ground, -y)
    }
}

/// Radiance of a ray that hits nothing, travelling along unit `dir`: the camera's solid
/// colour, or for Skybox cameras the skybox `sky` where the scene has one, else a
/// sky gradient by the direction's height (the scene's ambient sky/equator/ground colours,
/// or [`DEFAULT_SKY`] when those are black).
pub fn background(env: &Environment, sky: Option<&Skybox>, dir: Vec3, spread: f32) -> Vec3 {
    match (env.clear, sky) {
        (ClearFlags::SolidColor, _) => env.background,
        (ClearFlags::Skybox, Some(sky)) => sky.radiance(dir, spread),
        (ClearFlags::Skybox, None) => {
            let a = &env.ambient;
            let [s, e, g] = if a.sky.max(a.equator).max(a.ground).max_element() > 0.0 {
                match a.mode {
                    AmbientMode::Flat => [a.sky, a.sky, a.sky],
                    _ => [a.sky, a.equator, a.ground],
                }
            } else {
                DEFAULT_SKY
            };
            trilight(s, e, g, dir.y)
        }
    }
}

/// Ambient light reaching a surface with unit normal `n`: Flat → the sky colour;
/// Trilight and Skybox → sky/equator/ground blended by n.y.
pub fn ambient(env: &Environment, n: Vec3) -> Vec3 {
    let a = &env.ambient;
    match a.mode {
        AmbientMode::Flat => a.sky,
        AmbientMode::Trilight | AmbientMode::Skybox => trilight(a.sky, a.equator, a.ground, n.y),
    }
}
