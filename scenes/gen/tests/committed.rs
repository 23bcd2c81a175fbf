//! The committed projects under `scenes/` are exactly what the generator makes: same
//! files, same bytes. Run `just scenes` (or `cargo run -p scenegen`) after changing it.

use scenegen::project::existing_files;
use std::path::Path;

#[test]
fn committed_projects_match_the_generator_byte_for_byte() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    for p in scenegen::all_projects() {
        let dir = root.join(&p.name);
        let on_disk = existing_files(&dir).expect("read committed project");
        let made: std::collections::BTreeSet<String> = p.files.keys().cloned().collect();
        assert_eq!(
            on_disk, made,
            "file list of scenes/{} differs from the generator's; run `just scenes`",
            p.name
        );
        for (rel, bytes) in &p.files {
            let committed = std::fs::read(dir.join(rel)).expect("read committed file");
            assert!(
                committed == *bytes,
                "scenes/{}/{rel} differs from the generator's output; run `just scenes`",
                p.name
            );
        }
    }
}
