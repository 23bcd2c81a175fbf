//! `.mat` files: parsed like any Unity document, then mapped to a soup material.
#![no_main]

use libfuzzer_sys::fuzz_target;
use unity::{docs, material, yaml};

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    // A .mat is one document; also try the text as a bare body (no header).
    let mut bodies: Vec<yaml::Node> = docs::split(&text).iter().map(|d| d.parse()).collect();
    bodies.push(match yaml::parse(&text) {
        yaml::Node::Map(mut kv) if !kv.is_empty() => kv.swap_remove(0).1,
        other => other,
    });
    for b in &bodies {
        let (m, _notes) = material::convert(b, "Assets/fuzz.mat");
        let _ = (m.albedo(), m.reflectance());
    }
});
