//! The corpus meshes next to the repository (`../shared/corpus/meshes`), read with the
//! benchmark's OBJ loader; each test is skipped, saying so, when the corpus is absent.

use bench::scenes;
use kdtree::testkit::escapes;
use std::path::PathBuf;

fn corpus_mesh(name: &str) -> Option<PathBuf> {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/corpus/meshes")
        .join(name);
    if path.exists() {
        Some(path)
    } else {
        println!(
            "SKIPPED: corpus mesh test because {} is absent (the shared corpus is not next to the repo)",
            path.display()
        );
        None
    }
}

#[test]
fn loads_the_corpus_suzanne_triangulated() {
    let Some(path) = corpus_mesh("suzanne.obj") else {
        return;
    };
    let s = scenes::load_obj(&path).unwrap();
    // 32 triangles + 468 quads (two triangles each), per the corpus MANIFEST.
    assert_eq!(s.triangles.len(), 32 + 2 * 468);
    assert_eq!(s.name, "suzanne");
    assert!(s.notes.is_empty());
}

/// The k-d tree's leak test on a real closed mesh: rays from a small ball inside spot (a
/// cow) all hit it.
#[test]
fn spot_never_leaks() {
    let Some(path) = corpus_mesh("spot.obj") else {
        return;
    };
    let tris = scenes::load_obj(&path).expect("spot.obj loads").triangles;
    assert_eq!(tris.len(), 5856);
    // Spot's body is around its bounding box centre; a small ball there is inside.
    let [lo, hi] = scenes::bounds(&tris);
    let c = 0.5 * (lo + hi);
    let half = 0.1 * (hi - lo).min_element();
    let leaks = escapes(&tris, c, half, 50_000, 77);
    assert_eq!(leaks, 0);
}
