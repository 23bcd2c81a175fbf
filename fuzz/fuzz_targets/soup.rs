//! The soup reader: first the bytes as a whole file, then the bytes as the payload of a
//! well-framed file (right magic, version, length and checksum), so the fuzzer reaches
//! the bincode decoder and the cross-reference checks behind the checksum.
#![no_main]

use formats::{soup, Soup};
use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let path = Path::new("fuzz.soup");
    let _ = Soup::from_bytes(data, path);
    let mut framed = Vec::with_capacity(52 + data.len());
    framed.extend_from_slice(soup::MAGIC);
    framed.extend_from_slice(&soup::VERSION.to_le_bytes());
    framed.extend_from_slice(&(data.len() as u64).to_le_bytes());
    framed.extend_from_slice(blake3::hash(data).as_bytes());
    framed.extend_from_slice(data);
    if let Ok(s) = Soup::from_bytes(&framed, path) {
        // A soup the reader accepts is one the renderer can index without checks.
        assert!(s
            .tri_material
            .iter()
            .all(|&m| (m as usize) < s.materials.len()));
        assert!(s.tri_object.iter().all(|&o| (o as usize) < s.objects.len()));
    }
});
