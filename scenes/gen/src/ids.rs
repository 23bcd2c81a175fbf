//! Deterministic Unity identifiers: asset GUIDs, in-scene fileIDs and imported-mesh fileIDs.

use std::collections::BTreeSet;
use xxhash_rust::xxh64::xxh64;

/// A Unity asset GUID (32 lower-case hex digits) derived from the project and asset path,
/// so regenerating a project never changes its references.
pub fn guid(project: &str, asset_path: &str) -> String {
    let h = blake3::hash(format!("unitrace-scenegen:{project}/{asset_path}").as_bytes());
    h.to_hex()[..32].to_string()
}

/// The fileID Unity gives mesh `name` of a model imported with `fileIdsGeneration: 2`:
/// xxHash64 (seed 0) of `Type:Mesh-><name>0`, read as a signed 64-bit integer.
pub fn mesh_file_id(name: &str) -> i64 {
    imported_id(&format!("Type:Mesh->{name}0"))
}

/// The fileIDs of an imported model's root GameObject and its Transform under
/// `fileIdsGeneration: 2`, the targets a PrefabInstance of the model modifies.
pub fn model_root_ids() -> (i64, i64) {
    (
        imported_id("Type:GameObject->//RootNode/root0"),
        imported_id("Type:Transform->//RootNode/root/Transform0"),
    )
}

/// xxHash64 (seed 0) of an imported object's key, read as a signed 64-bit integer.
fn imported_id(key: &str) -> i64 {
    xxh64(key.as_bytes(), 0) as i64
}

/// Hands out in-scene fileIDs. Unity's are random positive numbers below 2³¹ with a
/// GameObject's components numbered right after it; these are the same shape, seeded from
/// the scene and object name so they are stable across runs.
#[derive(Default)]
pub struct FileIds {
    used: BTreeSet<i64>,
}

impl FileIds {
    /// `count` consecutive fresh ids for the object `key` (GameObject first, then its
    /// components).
    pub fn block(&mut self, key: &str, count: i64) -> Vec<i64> {
        let h = blake3::hash(key.as_bytes());
        let seed = u64::from_le_bytes(h.as_bytes()[..8].try_into().unwrap_or([0; 8]));
        let mut base = 100_000_000 + (seed % 2_000_000_000) as i64;
        while (base..base + count).any(|id| self.used.contains(&id)) {
            base += 1_000;
        }
        let ids: Vec<i64> = (base..base + count).collect();
        self.used.extend(&ids);
        ids
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mesh_file_id_matches_unity_on_the_corpus_value() {
        // Read from a real fileIdsGeneration 2 project.
        assert_eq!(mesh_file_id("default"), -2_432_090_755_550_338_912);
    }

    #[test]
    fn model_root_ids_match_unity_on_the_corpus_values() {
        // A real 2022 scene's PrefabInstance of a fileIdsGeneration 2 model.
        assert_eq!(
            model_root_ids(),
            (919_132_149_155_446_097, -8_679_921_383_154_817_045)
        );
    }

    #[test]
    fn guids_are_32_hex_and_stable() {
        let g = guid("baseline", "Assets/Models/Man.obj");
        assert_eq!(g.len(), 32);
        assert!(g
            .bytes()
            .all(|b| b.is_ascii_hexdigit() && !b.is_ascii_uppercase()));
        assert_eq!(g, guid("baseline", "Assets/Models/Man.obj"));
        assert_ne!(g, guid("baseline", "Assets/Models/Car.obj"));
    }

    #[test]
    fn file_id_blocks_never_overlap() {
        let mut ids = FileIds::default();
        let a = ids.block("same", 4);
        let b = ids.block("same", 4);
        assert_eq!(a.len(), 4);
        assert!(a.iter().all(|x| !b.contains(x)));
        assert!(a
            .iter()
            .chain(&b)
            .all(|&x| x > 0 && x < i64::from(i32::MAX)));
    }
}
