//! The OBJ loader on arbitrary text. The path's folder does not exist, so `mtllib`
//! lines never read a real file.
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    let path = Path::new("/nonexistent-unitrace-fuzz/model.obj");
    if let Ok(m) = unity::obj::parse(&text, path) {
        for g in &m.groups {
            let n = g.mesh.positions.len() as u32;
            assert!(g.mesh.submeshes.iter().flatten().flatten().all(|&i| i < n));
            assert_eq!(g.mesh.submeshes.len(), g.materials.len());
        }
    }
});
