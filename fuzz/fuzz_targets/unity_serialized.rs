//! Binary serialized files (`TerrainData` `.asset`): the header and metadata parser, then
//! every object read through its type tree.
#![no_main]

use libfuzzer_sys::fuzz_target;
use unity::serialized::{SerializedFile, Value};

fuzz_target!(|data: &[u8]| {
    let Ok(file) = SerializedFile::parse(data.to_vec(), "fuzz.asset") else {
        return;
    };
    for e in &file.externals {
        assert_eq!(e.guid.len(), 32);
    }
    for o in file.objects.iter().take(16) {
        if let Ok(v) = file.read(o.path_id) {
            let _ = v.get("m_Name").and_then(Value::as_str);
            let _ = v.path(&["m_Heightmap", "m_Heights"]);
        }
    }
});
