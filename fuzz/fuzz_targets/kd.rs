//! The k-d tree reader, raw and behind a valid frame (see soup.rs).
#![no_main]

use formats::{kd, KdFile};
use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let path = Path::new("fuzz.kd");
    let _ = KdFile::from_bytes(data, path);
    let mut framed = Vec::with_capacity(52 + data.len());
    framed.extend_from_slice(kd::MAGIC);
    framed.extend_from_slice(&kd::VERSION.to_le_bytes());
    framed.extend_from_slice(&(data.len() as u64).to_le_bytes());
    framed.extend_from_slice(blake3::hash(data).as_bytes());
    framed.extend_from_slice(data);
    if let Ok(t) = KdFile::from_bytes(&framed, path) {
        // Every node reference of an accepted tree stays inside its arrays.
        for (i, n) in t.nodes.iter().enumerate() {
            if n.is_leaf() {
                assert!(n.offset() as usize + n.count() as usize <= t.leaf_tris.len());
            } else {
                assert!((n.above_child() as usize) > i + 1);
                assert!((n.above_child() as usize) < t.nodes.len());
            }
        }
    }
});
