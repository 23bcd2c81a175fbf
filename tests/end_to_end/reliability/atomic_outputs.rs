//! Atomic outputs: a killed stage leaves the previous output intact, concurrent cache
//! builds both succeed.

use super::cases::*;
use super::noise::noise;
use formats::{KdFile, Soup};
use glam::Vec3;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Duration;
use unitrace::{bin, run};

/// A soup of `n` random small triangles in a 100 m cube.
fn big_soup(path: &Path, n: usize) {
    let mut soup = Soup::empty();
    let bytes = noise(n * 12, 11);
    let f = |i: usize| bytes[i] as f32 / 255.0;
    for t in 0..n {
        let c = Vec3::new(f(t * 12), f(t * 12 + 1), f(t * 12 + 2)) * 100.0;
        let v = |k: usize| c + Vec3::new(f(t * 12 + k), f(t * 12 + k + 1), f(t * 12 + k + 2)) - 0.5;
        soup.push_triangle([v(3), v(6), v(9)], [Vec3::Z; 3], None);
        soup.tri_material.push(0);
        soup.tri_object.push(0);
    }
    soup.objects.push(formats::Object::new("noise", "test"));
    soup.materials.push(formats::Material::unity_default());
    soup.camera.position = Vec3::new(50.0, 50.0, -150.0);
    soup.seal();
    soup.write(path).unwrap();
}

/// Start `name args`, let it run `after`, kill -9 it; returns whether it was still
/// running when killed (so the kill really landed mid-run).
fn kill_mid_run(name: &str, args: &[String], after: Duration) -> bool {
    let mut child = Command::new(bin(name))
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("spawn");
    std::thread::sleep(after);
    let running = child.try_wait().expect("try_wait").is_none();
    let _ = child.kill(); // SIGKILL
    let _ = child.wait();
    running
}

/// Files in `dir` apart from `keep` that a user or a later stage could mistake for
/// output: anything but the writers' hidden `.unitrace-*.tmp` temporaries.
fn litter(dir: &Path, keep: &[&Path]) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .filter_map(Result::ok)
        .map(|e| e.path())
        .filter(|p| !keep.contains(&p.as_path()))
        .filter_map(|p| p.file_name().map(|n| n.to_string_lossy().into_owned()))
        .filter(|n| !(n.starts_with(".unitrace-") && n.ends_with(".tmp")))
        .collect()
}

#[test]
fn killed_stages_leave_the_previous_output_intact() {
    let dir = tempfile::tempdir().unwrap();
    let soup = dir.path().join("big.soup");
    big_soup(&soup, 300_000);
    let out = dir.path().join("out");
    std::fs::create_dir_all(&out).unwrap();
    let kd = out.join("big.kd");
    // A previous, complete tree at the output path.
    let r = run("soup2kd", [s(&soup), "-o".into(), s(&kd)]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    let mut before = std::fs::read(&kd).unwrap();
    // Other parameters than the first tree's (so a run that lands is seen), and slow ones
    // (a low traversal cost and a deep bound make a big tree).
    let args = vec![
        s(&soup),
        "-o".into(),
        s(&kd),
        "--traversal-cost".into(),
        "1".into(),
        "--max-depth".into(),
        "40".into(),
    ];
    let mut landed = 0;
    for ms in [150, 400, 700] {
        let killed = kill_mid_run("soup2kd", &args, Duration::from_millis(ms));
        let now = std::fs::read(&kd).unwrap();
        if now == before {
            // Killed before its rename: the previous tree, byte for byte.
            assert!(
                killed,
                "soup2kd finished after {ms} ms but left the old tree"
            );
            landed += 1;
        } else {
            // It got as far as its rename (a kill can still land between the rename and
            // the exit): its whole tree, nothing half-written.
            KdFile::read(&kd).expect("a changed output is a complete tree");
            before = now;
        }
        assert_eq!(litter(&out, &[&kd]), Vec::<String>::new());
    }
    assert!(
        landed > 0,
        "soup2kd finished before every kill: make the input bigger"
    );
    KdFile::read(&kd).expect("the previous tree still reads");

    // kd2exr: a previous image, then a render killed mid-way.
    let exr = out.join("img.exr");
    let small = ["--width", "32", "--height", "24"].map(String::from);
    let mut a = vec![s(&soup), s(&kd), "-o".into(), s(&exr)];
    a.extend(small);
    let r = run("kd2exr", &a);
    assert_eq!(r.code, 0, "{}", r.stderr);
    let before = std::fs::read(&exr).unwrap();
    let mut a = vec![s(&soup), s(&kd), "-o".into(), s(&exr)];
    a.extend(
        [
            "--width",
            "3000",
            "--height",
            "3000",
            "--spp",
            "16",
            "--threads",
            "1",
        ]
        .map(String::from),
    );
    assert!(
        kill_mid_run("kd2exr", &a, Duration::from_millis(1500)),
        "kd2exr finished before the kill"
    );
    assert_eq!(
        std::fs::read(&exr).unwrap(),
        before,
        "kd2exr killed mid-render changed {}",
        exr.display()
    );
    assert_eq!(litter(&out, &[&kd, &exr]), Vec::<String>::new());
}

#[test]
fn concurrent_cache_builds_both_succeed() {
    let dir = tempfile::tempdir().unwrap();
    let soup = dir.path().join("s.soup");
    big_soup(&soup, 60_000);
    let cache = dir.path().join("cache");
    let spawn = || {
        Command::new(bin("soup2kd"))
            .args([s(&soup), "--cache".into(), s(&cache), "--json".into()])
            .output()
            .expect("spawn")
    };
    let (a, b) = std::thread::scope(|sc| {
        let a = sc.spawn(spawn);
        let b = sc.spawn(spawn);
        (a.join().unwrap(), b.join().unwrap())
    });
    for o in [&a, &b] {
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(o.status.success(), "{err}");
        assert!(!err.contains("panicked"), "{err}");
    }
    let entries: Vec<PathBuf> = std::fs::read_dir(&cache)
        .unwrap()
        .filter_map(Result::ok)
        .map(|e| e.path())
        .collect();
    assert_eq!(entries.len(), 1, "{entries:?}");
    let kd = KdFile::read(&entries[0]).unwrap();
    assert_eq!(kd.geometry_hash, Soup::read(&soup).unwrap().geometry_hash);
    // A third run is a cache hit on the same entry.
    let r = run(
        "soup2kd",
        [s(&soup), "--cache".into(), s(&cache), "--json".into()],
    );
    assert_eq!(r.json()["cache"], "hit");
}
