//! Meshes embedded in scenes (class 43 documents): hex vertex streams and index buffers
//! whose counts, strides and offsets all come from the file.
#![no_main]

use libfuzzer_sys::fuzz_target;
use unity::{embedded, yaml};

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    let body = match yaml::parse(&text) {
        yaml::Node::Map(mut kv) if !kv.is_empty() => kv.swap_remove(0).1,
        other => other,
    };
    if let Ok(mesh) = embedded::decode(&body) {
        // Every index the decoder returns must name a vertex it returned.
        let n = mesh.positions.len() as u32;
        assert!(mesh.submeshes.iter().flatten().flatten().all(|&i| i < n));
        assert_eq!(mesh.normals.len(), mesh.positions.len());
    }
});
