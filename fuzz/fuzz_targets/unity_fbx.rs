//! The FBX reader on arbitrary bytes (binary or ASCII FBX, or neither), through the
//! in-memory loader so no file is written. Whatever it accepts must be a well-formed
//! model: indices in range, one material name per sub-mesh, parents before children,
//! skin weights per vertex.
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let meta = unity::meta::ModelMeta::parse("ModelImporter:\n  meshes:\n    useFileScale: 1\n");
    let path = Path::new("/nonexistent-unitrace-fuzz/model.fbx");
    if let Ok(m) = unity::fbx::load_bytes(data, path, &meta) {
        for (i, n) in m.nodes.iter().enumerate() {
            assert_eq!(n.parent.is_none(), i == 0);
            assert!(n.parent.is_none_or(|p| p < i));
            assert!(n.mesh.is_none_or(|k| k < m.meshes.len()));
        }
        for mm in &m.meshes {
            let n = mm.mesh.positions.len() as u32;
            assert_eq!(mm.mesh.normals.len(), n as usize);
            assert!(mm.mesh.submeshes.iter().flatten().flatten().all(|&i| i < n));
            assert_eq!(mm.mesh.submeshes.len(), mm.materials.len());
            if let Some(s) = &mm.skin {
                assert_eq!(s.weights.len(), n as usize);
                assert_eq!(s.bones.len(), s.bind_poses.len());
            }
        }
    }
});
