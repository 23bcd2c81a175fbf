//! The k-d tree reader, raw and behind a valid frame (see soup.rs), and the header read
//! a cache hit makes, which must agree with the whole reader wherever it accepts a tree.
#![no_main]

use formats::envelope::Checked;
use formats::{kd, KdFile};
use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let path = Path::new("fuzz.kd");
    let _ = KdFile::from_bytes(data, path);
    let _ = Checked::<KdFile>::from_bytes(data.to_vec(), path).map(|c| c.header());
    let mut framed = Vec::with_capacity(52 + data.len());
    framed.extend_from_slice(kd::MAGIC);
    framed.extend_from_slice(&kd::VERSION.to_le_bytes());
    framed.extend_from_slice(&(data.len() as u64).to_le_bytes());
    framed.extend_from_slice(blake3::hash(data).as_bytes());
    framed.extend_from_slice(data);
    let header = Checked::<KdFile>::from_bytes(framed.clone(), path)
        .expect("a valid frame")
        .header();
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
        // Compared as printed: the tree's numbers are not checked, and NaN ≠ NaN.
        let h = header.expect("an accepted tree's header decodes");
        let whole = (t.geometry_hash, t.params, t.stats, t.bounds);
        assert_eq!(
            format!("{:?}", (h.geometry_hash, h.params, h.stats, h.bounds)),
            format!("{whole:?}")
        );
    }
});
