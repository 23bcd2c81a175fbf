//! The FBX reader gives ufbx a thread pool (rayon's), and ufbx inflates a binary file's
//! compressed arrays as tasks on it: the model must not depend on how many loads run at
//! once or how many threads the pool has. Real files from `../shared/corpus/unity/` (or
//! `UNITRACE_CORPUS`), the largest, which compress their arrays.

use rayon::prelude::*;
use std::path::{Path, PathBuf};
use unity::meta::ModelMeta;
use unity::model::Model;

fn largest_corpus_fbx(n: usize) -> Vec<PathBuf> {
    let root = std::env::var_os("UNITRACE_CORPUS")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/corpus"))
        .join("unity");
    if !root.is_dir() {
        eprintln!(
            "SKIPPED: FBX thread tests, because {} does not exist",
            root.display()
        );
        return Vec::new();
    }
    let mut files = Vec::new();
    let mut dirs = vec![root];
    while let Some(d) = dirs.pop() {
        for e in std::fs::read_dir(&d).unwrap().flatten() {
            let p = e.path();
            if p.is_dir() {
                dirs.push(p);
            } else if p.extension().is_some_and(|x| x.eq_ignore_ascii_case("fbx")) {
                files.push((e.metadata().map(|m| m.len()).unwrap_or(0), p));
            }
        }
    }
    files.sort();
    files.into_iter().rev().take(n).map(|(_, p)| p).collect()
}

fn load(p: &Path) -> Model {
    unity::fbx::load(p, &ModelMeta::read(p)).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn a_model_is_the_same_alone_concurrently_and_on_one_thread() {
    let files = largest_corpus_fbx(6);
    if files.is_empty() {
        return;
    }
    let alone: Vec<Model> = files.iter().map(|p| load(p)).collect();
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let single: Vec<Model> = one.install(|| files.par_iter().map(|p| load(p)).collect());
    assert!(single == alone, "one-thread pool differs");
    let four = rayon::ThreadPoolBuilder::new()
        .num_threads(4)
        .build()
        .unwrap();
    // Every file three times over, all at once.
    let many: Vec<Model> = four.install(|| {
        (0..3 * files.len())
            .into_par_iter()
            .map(|k| load(&files[k % files.len()]))
            .collect()
    });
    for (k, m) in many.iter().enumerate() {
        assert!(
            *m == alone[k % files.len()],
            "{} differs under concurrent loads",
            files[k % files.len()].display()
        );
    }
}
