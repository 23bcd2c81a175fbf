use std::time::Instant;
fn walk(d: &std::path::Path, out: &mut Vec<std::path::PathBuf>) {
    for e in std::fs::read_dir(d).unwrap().flatten() {
        let p = e.path();
        if p.is_dir() {
            walk(&p, out)
        } else if p.extension().is_some_and(|e| e.eq_ignore_ascii_case("fbx")) {
            out.push(p)
        }
    }
}
fn main() {
    let root = std::path::Path::new("/work/shared/corpus/unity");
    let big = root.join("Astraela__Escape-The-Room/Assets/Models/Puzzle3/remote.FBX");
    let meta = unity::meta::ModelMeta::read(&big);
    let mut best = f64::MAX;
    let mut tris = 0;
    for _ in 0..10 {
        let t = Instant::now();
        let m = unity::fbx::load(&big, &meta).unwrap();
        best = best.min(t.elapsed().as_secs_f64());
        tris = m.triangle_count();
    }
    println!(
        "remote.FBX: best of 10 {:.2} ms, {tris} triangles",
        best * 1e3
    );
    let mut files = Vec::new();
    walk(root, &mut files);
    let metas: Vec<_> = files
        .iter()
        .map(|p| unity::meta::ModelMeta::read(p))
        .collect();
    let mut best = f64::MAX;
    let mut total = 0;
    for _ in 0..5 {
        let t = Instant::now();
        total = 0;
        for (p, m) in files.iter().zip(&metas) {
            total += unity::fbx::load(p, m).unwrap().triangle_count();
        }
        best = best.min(t.elapsed().as_secs_f64());
    }
    println!(
        "{} files, {total} triangles: best of 5 {:.1} ms, {:.2} M tri/s",
        files.len(),
        best * 1e3,
        total as f64 / best / 1e6
    );
}
