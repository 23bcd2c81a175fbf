//! `.meta` readers: the GUID line and the ModelImporter fileID tables.
#![no_main]

use libfuzzer_sys::fuzz_target;
use unity::meta::{guid_of, ModelMeta};

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    let _ = guid_of(&text);
    let m = ModelMeta::parse(&text);
    assert!(m.global_scale.is_finite() && m.global_scale > 0.0);
    for (_, name) in m.recycle.iter().take(8) {
        let _ = m.ids(43, name, name);
    }
});
