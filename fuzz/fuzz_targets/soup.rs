//! The soup reader: first the bytes as a whole file, then the bytes as the payload of a
//! well-framed file (right magic, version, length and checksum), so the fuzzer reaches
//! the bincode decoder and the cross-reference checks behind the checksum. The partial
//! reads `soup2kd` makes (the cache key, the geometry) run on the same bytes and must
//! agree with the whole reader wherever it accepts them.
#![no_main]

use formats::envelope::Checked;
use formats::{soup, Soup};
use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let path = Path::new("fuzz.soup");
    let _ = Soup::from_bytes(data, path);
    let _ = Checked::<Soup>::from_bytes(data.to_vec(), path).map(|c| (c.key(), c.geometry()));
    let mut framed = Vec::with_capacity(52 + data.len());
    framed.extend_from_slice(soup::MAGIC);
    framed.extend_from_slice(&soup::VERSION.to_le_bytes());
    framed.extend_from_slice(&(data.len() as u64).to_le_bytes());
    framed.extend_from_slice(blake3::hash(data).as_bytes());
    framed.extend_from_slice(data);
    let checked = Checked::<Soup>::from_bytes(framed.clone(), path).expect("a valid frame");
    let (key, geometry) = (checked.key(), checked.geometry());
    if let Ok(g) = &geometry {
        // Geometry that decodes has a key, and it is the geometry's.
        let k = key.as_ref().expect("geometry decodes, so its key does");
        assert_eq!(k.triangles, g.triangles.len());
        assert_eq!(k.geometry_hash, g.geometry_hash);
    }
    if let Ok(s) = Soup::from_bytes(&framed, path) {
        // A soup the reader accepts is one the renderer can index without checks.
        assert!(s
            .tri_material
            .iter()
            .all(|&m| (m as usize) < s.materials.len()));
        assert!(s.tri_object.iter().all(|&o| (o as usize) < s.objects.len()));
        // And the partial reads of an accepted soup are its own fields.
        let g = geometry.expect("an accepted soup's geometry decodes");
        assert_eq!(g.positions, s.positions);
        assert_eq!(g.triangles, s.triangles);
        assert_eq!(g.geometry_hash, s.geometry_hash);
    }
});
