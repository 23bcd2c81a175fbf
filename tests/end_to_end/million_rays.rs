//! The k-d tree's exactness at full size: `raycast` on a file of a million random rays against the
//! baseline scene gives exactly the brute-force hits (same triangle and t, or the same
//! miss). Brute force here is `brute::Runs`: the tree's triangle test and tie rule on every
//! triangle except those in runs of the soup the ray provably cannot hit, so it gives
//! exactly the answers of testing all 41,833 triangles per ray (its own test checks that) in
//! about 10 s on 2 cores instead of several minutes.

use formats::rays::{self, RayRecord};
use kdtree::testkit::brute;
use kdtree::Ray;
use rayon::prelude::*;
use unitrace::run_ok;

#[test]
fn raycast_a_million_random_rays_against_the_baseline_equals_brute_force() {
    let dir = tempfile::tempdir().unwrap();
    let soup_path = dir.path().join("baseline.soup");
    let kd_path = dir.path().join("baseline.kd");
    run_ok(
        "unity2soup",
        [
            "scenes/baseline/Assets/Scenes/Baseline.unity".as_ref(),
            "-o".as_ref(),
            soup_path.as_os_str(),
        ],
    );
    run_ok(
        "soup2kd",
        [soup_path.as_os_str(), "-o".as_ref(), kd_path.as_os_str()],
    );
    let soup = formats::Soup::read(&soup_path).unwrap();
    assert_eq!(soup.triangles.len(), 41_833);
    // Origins uniform in the bounds, directions uniform on the sphere (kdbench's random set).
    let input: Vec<RayRecord> = bench::rays::random(
        bench::scenes::bounds(&soup.triangle_positions()),
        1_000_000,
        0x5eed,
    )
    .into_iter()
    .map(|r| RayRecord {
        origin: r.origin,
        tmin: r.tmin,
        dir: r.dir,
        tmax: r.tmax,
    })
    .collect();
    let rays_path = dir.path().join("random.rays");
    let hits_path = dir.path().join("random.hits");
    rays::write_rays(&rays_path, &input).unwrap();
    let v = run_ok(
        "raycast",
        [
            soup_path.as_os_str(),
            kd_path.as_os_str(),
            rays_path.as_os_str(),
            "-o".as_ref(),
            hits_path.as_os_str(),
            "--json".as_ref(),
        ],
    )
    .json();
    assert_eq!(v["rays"], 1_000_000);
    let hits = rays::read_hits(&hits_path).unwrap();
    let triangles = soup.triangle_positions();
    let brute = brute::Runs::new(&triangles, 128);
    let differ: Vec<usize> = (0..input.len())
        .into_par_iter()
        .filter(|&i| {
            let r = &input[i];
            let want = brute.intersect(&Ray::new(r.origin, r.dir, r.tmin, r.tmax));
            let h = hits[i];
            match want {
                Some(w) => (h.prim, h.t) != (w.prim, w.t),
                None => !h.is_miss(),
            }
        })
        .collect();
    let n_hits = hits.iter().filter(|h| !h.is_miss()).count();
    eprintln!(
        "1,000,000 rays, {n_hits} hits, {} differ from brute force",
        differ.len()
    );
    assert!(
        n_hits > 100_000,
        "the rays must meet the scene: {n_hits} hits"
    );
    assert!(
        differ.is_empty(),
        "rays that differ: {:?}",
        &differ[..differ.len().min(20)]
    );
    assert_eq!(v["hits"], n_hits);
}
