//! Project settings: `ProjectSettings/*.asset` and a URP pipeline asset, read by every
//! settings reader, each of which may only say "unknown" to what it cannot read.
#![no_main]

use formats::ColorSpace;
use libfuzzer_sys::fuzz_target;
use unity::light::{LightUnits, UniversalAsset};
use unity::settings::{color_space, Pipeline, PipelineAsset};
use unity::quality;

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    if let Some(bias) = quality::lod_bias(&text) {
        assert!(bias.is_finite() && bias > 0.0, "lodBias {bias}");
    }
    let _ = quality::shadows(&text);
    let _ = quality::render_pipeline_asset(&text);
    let _ = PipelineAsset::of(Some(&text), Some(&text));
    let _ = color_space(&text);
    let _ = UniversalAsset::of_asset(&text);
    for pipeline in [Pipeline::BuiltIn, Pipeline::Universal, Pipeline::HighDefinition] {
        let units = LightUnits::of(pipeline, Some(&text), ColorSpace::Linear);
        // Whatever the file says, a finite light stays finite.
        let (c, i) = units.light(glam::Vec3::new(1.0, 0.5, 0.0), 1.5, Some(5000.0));
        assert!(c.is_finite() && i.is_finite(), "{c} {i}");
    }
});
