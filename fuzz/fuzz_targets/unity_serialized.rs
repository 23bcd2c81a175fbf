//! Binary serialized files (`TerrainData` `.asset`): the header and metadata parser, then
//! every object read through its type tree, and every TerrainData as a terrain: its
//! heights, holes, splat maps and trees, and the grid drawn from them.
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
        if let Ok(t) = unity::terrain::read(&file, o.path_id) {
            // The input bounds the grid: its heights are in it.
            let mesh = t.field.mesh(2, |u, v| (u < 0.9).then_some(usize::from(u < v)));
            assert!(mesh.positions.iter().all(|p| p.is_finite()));
            assert!(mesh.normals.iter().all(|n| n.is_finite()));
            for tree in &t.trees.instances {
                assert!(tree.position.is_finite() && tree.width.is_finite());
            }
        }
    }
});
