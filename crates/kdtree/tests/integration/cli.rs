//! The real binaries: soup2kd (file, cache hit/miss, concurrent builders, --stats, bad
//! input) and raycast (hits equal brute force, any-hit, --json).

use formats::{rays, BuildParams, KdFile, Material, Object, RayRecord, Soup};
use glam::Vec3;
use kdtree::testkit::{self, brute, Rng};
use kdtree::Ray;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn soup2kd() -> Command {
    Command::new(env!("CARGO_BIN_EXE_soup2kd"))
}

fn raycast() -> Command {
    Command::new(env!("CARGO_BIN_EXE_raycast"))
}

fn make_soup(dir: &Path, tris: Vec<[Vec3; 3]>) -> PathBuf {
    let mut soup = Soup::empty();
    let n = tris.len();
    for t in tris {
        let n = (t[1] - t[0]).cross(t[2] - t[0]).normalize_or_zero();
        soup.push_triangle(t, [n; 3], None);
    }
    soup.tri_material = vec![0; n];
    soup.tri_object = vec![0; n];
    soup.materials = vec![Material::unity_default()];
    soup.objects = vec![Object::new("test", "generated")];
    soup.seal();
    let path = dir.join("scene.soup");
    soup.write(&path).unwrap();
    path
}

fn scene() -> Vec<[Vec3; 3]> {
    let mut tris = testkit::sphere(Vec3::new(0.0, 1.0, 0.0), 1.0, 24, 48);
    tris.extend(testkit::grid_box(Vec3::new(3.0, 0.5, 0.0), 0.5, 3));
    tris.extend(testkit::grid(10, 10.0, 0.0));
    tris
}

fn json(out: &Output) -> serde_json::Value {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("one JSON object on stdout")
}

#[test]
fn builds_caches_and_reports() {
    let dir = tempfile::tempdir().unwrap();
    let tris = scene();
    let soup = make_soup(dir.path(), tris.clone());
    let cache = dir.path().join("cache");

    let out = soup2kd()
        .arg(&soup)
        .arg("--cache")
        .arg(&cache)
        .arg("--json")
        .output()
        .unwrap();
    let v = json(&out);
    assert_eq!(v["cache"], "miss");
    assert_eq!(v["triangles"], tris.len());
    let path = PathBuf::from(v["path"].as_str().unwrap());
    let soup_hash = formats::soup::geometry_hash(&tris);
    assert_eq!(
        path,
        cache.join(BuildParams::default().cache_name(&soup_hash))
    );
    let kd = KdFile::read(&path).unwrap();
    assert_eq!(kd.stats.triangles, tris.len() as u64);
    assert_eq!(v["nodes"], kd.stats.nodes);
    assert!(
        kd.stats.leaves > 10,
        "a real tree, not one leaf: {:?}",
        kd.stats
    );

    // Second run: a cache hit, said on stderr without --json.
    let out = soup2kd()
        .arg(&soup)
        .arg("--cache")
        .arg(&cache)
        .output()
        .unwrap();
    assert!(out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains(&format!("cache hit: {}", path.display())),
        "{err}"
    );
    let miss = v;
    let v = json(
        &soup2kd()
            .arg(&soup)
            .arg("--cache")
            .arg(&cache)
            .arg("--json")
            .output()
            .unwrap(),
    );
    assert_eq!(v["cache"], "hit");
    assert_eq!(v["path"], miss["path"]);
    for field in [
        "triangles",
        "nodes",
        "leaves",
        "max_depth",
        "sah_cost",
        "bytes_per_triangle",
    ] {
        assert_eq!(v[field], miss[field], "{field}");
    }
    assert_eq!(v["build_seconds"], 0.0);

    // Other parameters: another cache entry.
    let v = json(
        &soup2kd()
            .arg(&soup)
            .args([
                "--leaf-size",
                "4",
                "--empty-bonus",
                "0.5",
                "--json",
                "--cache",
            ])
            .arg(&cache)
            .output()
            .unwrap(),
    );
    assert_eq!(v["cache"], "miss");
    assert_ne!(PathBuf::from(v["path"].as_str().unwrap()), path);
    let kd4 = KdFile::read(Path::new(v["path"].as_str().unwrap())).unwrap();
    assert_eq!(kd4.params.leaf_size, 4);

    // A corrupt cache entry is rebuilt, not trusted.
    std::fs::write(&path, b"UTKD garbage").unwrap();
    let v = json(
        &soup2kd()
            .arg(&soup)
            .arg("--cache")
            .arg(&cache)
            .arg("--json")
            .output()
            .unwrap(),
    );
    assert_eq!(v["cache"], "miss");
    assert!(KdFile::read(&path).is_ok());

    // --stats
    let v = json(
        &soup2kd()
            .arg("--stats")
            .arg(&path)
            .arg("--json")
            .output()
            .unwrap(),
    );
    assert_eq!(v["triangles"], tris.len());
    assert!(v["bytes_per_triangle"].as_f64().unwrap() > 36.0, "{v}");
    let out = soup2kd().arg("--stats").arg(&path).output().unwrap();
    assert!(String::from_utf8_lossy(&out.stdout).contains("references/triangle"));
}

#[test]
fn concurrent_builders_both_succeed() {
    let dir = tempfile::tempdir().unwrap();
    let soup = make_soup(dir.path(), scene());
    let cache = dir.path().join("cache");
    let children: Vec<_> = (0..2)
        .map(|_| {
            soup2kd()
                .arg(&soup)
                .arg("--cache")
                .arg(&cache)
                .arg("--json")
                .stdout(std::process::Stdio::piped())
                .stderr(std::process::Stdio::piped())
                .spawn()
                .unwrap()
        })
        .collect();
    let mut paths = Vec::new();
    for c in children {
        let v = json(&c.wait_with_output().unwrap());
        paths.push(v["path"].as_str().unwrap().to_string());
    }
    assert_eq!(paths[0], paths[1]);
    assert!(KdFile::read(Path::new(&paths[0])).is_ok());
    let files: Vec<_> = std::fs::read_dir(&cache).unwrap().collect();
    assert_eq!(files.len(), 1, "one file, no temporaries left behind");
}

#[test]
fn bad_input_is_one_clear_line() {
    let dir = tempfile::tempdir().unwrap();
    let bogus = dir.path().join("bogus.soup");
    std::fs::write(&bogus, b"not a soup at all").unwrap();
    let out = soup2kd()
        .arg(&bogus)
        .arg("-o")
        .arg(dir.path().join("x.kd"))
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("bogus.soup") && err.lines().count() == 1,
        "{err}"
    );
    // Missing destination: a usage error (2).
    let out = soup2kd().arg(&bogus).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    // A tree from other geometry is refused by raycast.
    let a = make_soup(dir.path(), scene());
    let kd = dir.path().join("a.kd");
    assert!(soup2kd()
        .arg(&a)
        .arg("-o")
        .arg(&kd)
        .status()
        .unwrap()
        .success());
    let other = dir.path().join("other");
    std::fs::create_dir(&other).unwrap();
    let b = make_soup(&other, testkit::grid(3, 1.0, 0.0));
    let r = dir.path().join("r.rays");
    rays::write_rays(&r, &[]).unwrap();
    let out = raycast()
        .arg(&b)
        .arg(&kd)
        .arg(&r)
        .arg("-o")
        .arg(dir.path().join("h"))
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("geometry"));
}

#[test]
fn raycast_matches_brute_force() {
    let dir = tempfile::tempdir().unwrap();
    let tris = scene();
    let soup = make_soup(dir.path(), tris.clone());
    let kd = dir.path().join("scene.kd");
    assert!(soup2kd()
        .arg(&soup)
        .arg("-o")
        .arg(&kd)
        .status()
        .unwrap()
        .success());
    let mut rng = Rng(7);
    let mut input: Vec<RayRecord> = (0..20_000)
        .map(|_| RayRecord {
            origin: Vec3::new(
                rng.range(-6.0, 6.0),
                rng.range(-1.0, 4.0),
                rng.range(-6.0, 6.0),
            ),
            tmin: 0.0,
            dir: rng.dir(),
            tmax: if rng.unit() < 0.5 {
                f32::INFINITY
            } else {
                rng.range(0.1, 5.0)
            },
        })
        .collect();
    input.push(RayRecord {
        origin: Vec3::new(0.5, 5.0, 0.5),
        tmin: 0.0,
        dir: Vec3::new(0.0, -1.0, -0.0),
        tmax: f32::INFINITY,
    });
    let rays_path = dir.path().join("in.rays");
    rays::write_rays(&rays_path, &input).unwrap();
    let hits_path = dir.path().join("out.hits");
    let v = json(
        &raycast()
            .arg(&soup)
            .arg(&kd)
            .arg(&rays_path)
            .arg("-o")
            .arg(&hits_path)
            .args(["--json", "--threads", "2"])
            .output()
            .unwrap(),
    );
    assert_eq!(v["rays"], input.len());
    let hits = rays::read_hits(&hits_path).unwrap();
    assert_eq!(hits.len(), input.len());
    let mut n_hits = 0;
    for (r, h) in input.iter().zip(&hits) {
        let want = brute::intersect(&tris, &Ray::new(r.origin, r.dir, r.tmin, r.tmax));
        match want {
            Some(w) => {
                assert_eq!((h.prim, h.t), (w.prim, w.t), "{r:?}");
                n_hits += 1;
            }
            None => assert!(h.is_miss() && h.t == f32::INFINITY, "{r:?}: {h:?}"),
        }
    }
    assert_eq!(v["hits"], n_hits);
    assert!(n_hits > 1000, "the scene is in the rays' way: {n_hits}");
    // The straight-down ray lands on the sphere's top (y = 2 at the pole, sphere is
    // tessellated so slightly lower at x = z = 0.5).
    let last = hits.last().unwrap();
    assert!(last.t > 3.0 && last.t < 3.8, "{last:?}");

    // Any-hit: t = 0 exactly for the occluded rays.
    let v = json(
        &raycast()
            .arg(&soup)
            .arg(&kd)
            .arg(&rays_path)
            .arg("-o")
            .arg(&hits_path)
            .args(["--json", "--any-hit"])
            .output()
            .unwrap(),
    );
    assert_eq!(v["hits"], n_hits);
    let any = rays::read_hits(&hits_path).unwrap();
    for (a, h) in any.iter().zip(&hits) {
        assert_eq!(a.is_miss(), h.is_miss());
        if !a.is_miss() {
            assert_eq!(a.t, 0.0);
        }
    }
}
