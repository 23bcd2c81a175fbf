//! The raw rays and hits readers (RAYS.md).
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    if let Ok(r) = formats::rays::decode_rays(data, Path::new("fuzz.rays")) {
        assert_eq!(16 + r.len() * 32, data.len());
    }
    if let Ok(h) = formats::rays::decode_hits(data, Path::new("fuzz.hits")) {
        assert_eq!(16 + h.len() * 16, data.len());
    }
});
