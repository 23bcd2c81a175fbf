//! `kd2exr`'s library: renders a unitrace soup through its compiled k-d tree into an
//! OpenEXR image, Whitted style.
//!
//! The steps, each in its own module:
//! * [`plan`]: decide from the soup which effects can change the image (and why);
//! * [`camera`]: pixel → ray (perspective or orthographic, y = 0 at the top row);
//! * [`cone`]: how wide a pixel's rays are at a hit, for texture filtering;
//! * [`texture`], [`alpha`]: albedo lookups, cut-out holes and blended surfaces;
//! * [`normal_map`], [`tangents`]: normal maps, read in each mesh's MikkTSpace tangents;
//! * [`lights`]: Unity's range falloff and spot cones;
//! * [`integrator`]: emission, ambient, direct light with hard/soft shadows, mirrors;
//! * `soft`: a soft shadow's sample rays, four at a time;
//! * [`offset`]: secondary rays spawned past the hit point's rounding error;
//! * [`sampling`]: per-pixel seeded RNG, stratified pixel and shadow samples;
//! * [`mod@render`]: tiles in parallel (rayon work stealing), ray counters;
//! * [`exrio`], [`preview`]: EXR with AOVs, crop windows and merging; PNG preview;
//! * [`memory`]: refuse a render that cannot fit before it starts.

pub mod alpha;
pub mod aov;
pub mod brdf;
pub mod camera;
pub mod cone;
pub mod counters;
pub mod environment;
pub mod error;
pub mod exrio;
pub mod exrread;
pub mod fog;
pub mod frame;
pub mod integrator;
pub mod lights;
pub mod memory;
pub mod normal_map;
pub mod offset;
pub mod options;
pub mod plan;
pub mod preview;
pub mod probe;
pub mod render;
pub mod sampling;
pub mod sky;
pub mod sky_image;
mod soft;
pub mod tangents;
pub mod texture;

pub use aov::{Aov, AovSet};
pub use camera::CameraModel;
pub use counters::RayCounts;
pub use error::RenderError;
pub use exrio::ExrImage;
pub use frame::Frame;
pub use options::{RenderOptions, TextureFilter, Window};
pub use plan::Plan;
pub use render::{render, render_scene, Rendered};

/// The header attributes unitrace stores in every EXR it renders (`unitrace.*` text
/// attributes, shown by `exrheader`).
pub fn header_attributes(
    plan: &Plan,
    opts: &RenderOptions,
    seconds: f64,
    geometry_hash: &formats::Digest,
) -> std::collections::BTreeMap<String, String> {
    let p = exrio::ATTR_PREFIX;
    let mut a = std::collections::BTreeMap::new();
    a.insert(format!("{p}plan"), exrio::ascii_json(&plan.to_json()));
    a.insert(format!("{p}spp"), opts.spp.to_string());
    a.insert(format!("{p}depth"), opts.depth.to_string());
    a.insert(format!("{p}seed"), opts.seed.to_string());
    a.insert(format!("{p}softSamples"), opts.soft_samples.to_string());
    a.insert(format!("{p}softProbe"), opts.soft_probe.to_string());
    a.insert(format!("{p}cutoff"), opts.cutoff.to_string());
    a.insert(format!("{p}textureFilter"), opts.texture_filter.to_string());
    a.insert(format!("{p}renderSeconds"), format!("{seconds:.6}"));
    a.insert(format!("{p}geometryHash"), formats::hex(geometry_hash));
    a.insert(format!("{p}version"), env!("CARGO_PKG_VERSION").to_string());
    if let Some(c) = opts.crop {
        a.insert(format!("{p}crop"), c.to_string());
    }
    a
}

/// The header attributes that tie an EXR to the exact inputs it was rendered from, so
/// `kd2exr merge` refuses crops of another soup or tree even when the geometry is the same:
/// the soup file's payload checksum (it also covers materials, lights and camera) and the
/// tree's build parameters.
pub fn source_attributes(
    soup_digest: &formats::Digest,
    tree: &formats::BuildParams,
) -> std::collections::BTreeMap<String, String> {
    let p = exrio::ATTR_PREFIX;
    std::collections::BTreeMap::from([
        (format!("{p}soupDigest"), formats::hex(soup_digest)),
        (format!("{p}treeParams"), tree.short_hash()),
    ])
}
