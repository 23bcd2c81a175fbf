//! The quick benchmark, in process, on a tiny generated scene: the report has the rows
//! the tables need and every contender agrees with the k-d tree.

use bench::contenders::{BRUTE, EMBREE, KDTREE, MEDIAN};
use bench::results::{Kind, Role};
use bench::{report, run, scenes, Config};
use std::path::PathBuf;

fn quiet() -> impl FnMut(&str) {
    |_| {}
}

#[test]
fn quick_run_has_every_row_and_the_contenders_agree() {
    let cfg = Config {
        runs: 1,
        ..Config::quick()
    };
    let report = run(&cfg, &mut quiet()).unwrap();
    assert_eq!(report.scenes.len(), 1);
    let s = &report.scenes[0];
    assert_eq!(s.role, Role::Generated);
    let expected_tris = scenes::generated(cfg.generated).triangles.len();
    assert_eq!(s.triangles, expected_tris);
    assert!((2500..=3500).contains(&expected_tris), "{expected_tris}");

    let embree = cfg!(feature = "embree");
    let contenders: Vec<&str> = if embree {
        vec![KDTREE, MEDIAN, EMBREE]
    } else {
        vec![KDTREE, MEDIAN]
    };
    // Build rows: every contender (brute force has no build) at 1 and 2 threads.
    assert_eq!(s.builds.len(), 2 * contenders.len());
    for b in &s.builds {
        assert!(b.seconds > 0.0);
        assert_eq!(b.triangles, expected_tris);
    }
    // The k-d tree's statistics are those of the tree itself, built directly.
    let tris = scenes::generated(cfg.generated).triangles;
    let direct = kdtree::build(&tris, &cfg.params, formats::soup::geometry_hash(&tris));
    for kd in s.builds.iter().filter(|b| b.contender == KDTREE) {
        assert_eq!(kd.nodes, Some(direct.nodes.len() as u64));
        let sah = kd.sah_cost.unwrap();
        assert!((sah - direct.stats.sah_cost).abs() <= 1e-9 * sah.abs().max(1.0));
        let n = tris.len() as f64;
        // 8-byte nodes, 4-byte leaf entries, 36 bytes of vertices and a 4-byte soup index.
        let bytes = (direct.nodes.len() * 8 + direct.leaf_tris.len() * 4) as f64 + 40.0 * n;
        assert_eq!(kd.bytes_per_triangle, Some(bytes / n));
        assert_eq!(
            kd.refs_per_triangle,
            Some(direct.leaf_tris.len() as f64 / n)
        );
    }
    // The median-split tree is the k-d tree crate's too, and costs more by the SAH.
    let median = kdtree::build_median(&tris, &cfg.params, formats::soup::geometry_hash(&tris));
    let m = s.builds.iter().find(|b| b.contender == MEDIAN).unwrap();
    assert_eq!(m.nodes, Some(median.nodes.len() as u64));
    assert!(m.sah_cost.unwrap() > direct.stats.sah_cost);

    // Trace rows: every contender, brute force too (the scene is small), × 2 × every kind.
    let mut all = contenders.clone();
    all.push(BRUTE);
    let kinds = Kind::all(cfg.packet).len();
    assert_eq!(kinds, 11);
    assert_eq!(s.traces.len(), all.len() * 2 * kinds);
    let rays = |who: &str, kind: Kind| {
        s.traces
            .iter()
            .find(|r| r.contender == who && r.kind == kind && r.threads == 1)
            .unwrap()
            .rays
    };
    assert_eq!(rays(KDTREE, Kind::Primary), 48 * 48);
    assert_eq!(rays(KDTREE, Kind::PrimaryPackets(4)), 48 * 48);
    assert_eq!(rays(KDTREE, Kind::Random), 2048);
    // Shadow rays start at primary hits: most of a framed view hits the scene.
    let shadow = rays(KDTREE, Kind::Shadow);
    assert!(
        shadow > 48 * 48 / 2 && shadow <= 48 * 48,
        "{shadow} shadow rays"
    );
    // The same hits in block order: the same number of shadow rays.
    assert_eq!(rays(KDTREE, Kind::ShadowPackets(4)), shadow);
    // Four samples from every fourth hit that faces the sun: at most one per hit, whole
    // groups of four, the same rays singly and in packets.
    let soft = rays(KDTREE, Kind::Soft);
    assert!(
        soft > 0 && soft <= shadow + 3 && soft % 4 == 0,
        "{soft} soft rays"
    );
    assert_eq!(rays(KDTREE, Kind::SoftPackets(4)), soft);
    assert_eq!(rays(BRUTE, Kind::Primary), 512);
    assert_eq!(rays(BRUTE, Kind::PrimaryPackets(4)), 512);
    for k in [
        Kind::SurfaceLight,
        Kind::SurfaceLightAny,
        Kind::SurfaceHemisphere,
        Kind::SurfaceHemisphereAny,
    ] {
        assert_eq!(rays(KDTREE, k), 2048, "{k:?}");
        assert_eq!(rays(BRUTE, k), 512, "{k:?}");
    }
    // The k-d tree's work on each surface set, as spawned and moved 5 mm.
    assert_eq!(s.work.len(), 4 * 2);
    for w in &s.work {
        assert_eq!(w.rays, 2048);
        assert!(w.counts.nodes > 0 && w.counts.leaves > 0, "{w:?}");
    }
    for r in &s.traces {
        assert!(r.mrays_per_s() > 0.0 && r.mrays_per_s().is_finite());
    }

    // Agreement: each non-reference contender on each kind, nothing differs.
    assert_eq!(s.agreement.len(), (all.len() - 1) * kinds);
    for a in &s.agreement {
        assert!(a.compared > 0);
        assert_eq!(
            a.disagreements, 0,
            "{} {:?}: {:?}",
            a.other, a.kind, a.examples
        );
    }
    assert!(report.all_agree());

    let md = report::markdown(&report);
    let name = &s.name;
    assert!(md.contains(&format!("| {name} | {expected_tris} | kdtree | 1 |")));
    assert!(md.contains(&format!("| {name} | kdtree | 2 |")));
    assert!(md.contains(&format!("| {name} | kdtree median | 1 |")));
    assert!(md.contains(&format!("| {name} | brute force | 1 |")));
    assert!(md.contains(&format!(
        "| {name} | brute force | 0 / 512 | 0 / 512 | 0 / {0} | 0 / {0} | 0 / {1} | 0 / {1} | 0 / 512 | 0 / 512 | 0 / 512 | 0 / 512 | 0 / 512 | 100.0000% | ok | – |",
        shadow.min(512),
        soft.min(512)
    )));
    assert_eq!(
        md.contains(&format!("| {name} | **kdtree/Embree** | 1 |")),
        embree
    );
    assert!(!md.contains("**FAIL**"));
    for section in [
        "## Build",
        "## Traversal",
        "## k-d tree work per surface ray",
        "## Agreement",
        "- machine: nproc",
    ] {
        assert!(md.contains(section), "missing {section}");
    }
}

#[test]
fn a_missing_baseline_is_skipped_with_a_note() {
    let cfg = Config {
        baseline: Some(PathBuf::from("/nonexistent/baseline.soup")),
        generated: 0,
        ..Config::quick()
    };
    let mut lines = vec![];
    let report = run(&cfg, &mut |l: &str| lines.push(l.to_string())).unwrap();
    assert!(report.scenes.is_empty());
    assert_eq!(report.notes.len(), 1);
    assert!(report.notes[0].starts_with("SKIPPED: baseline soup /nonexistent/baseline.soup"));
    assert_eq!(lines, report.notes);
}

#[test]
fn quick_run_in_packets_of_sixteen_traces_every_ray_and_agrees() {
    let cfg = Config {
        runs: 1,
        packet: 16,
        threads: vec![1],
        ..Config::quick()
    };
    let report = run(&cfg, &mut quiet()).unwrap();
    let s = &report.scenes[0];
    let rays = |kind: Kind| {
        s.traces
            .iter()
            .find(|r| r.contender == KDTREE && r.kind == kind)
            .unwrap()
            .rays
    };
    assert_eq!(rays(Kind::PrimaryPackets(16)), 48 * 48);
    assert_eq!(rays(Kind::ShadowPackets(16)), rays(Kind::Shadow));
    assert!(s.traces.iter().all(|r| r.kind != Kind::PrimaryPackets(4)));
    // Every contender, Embree's `rtcIntersect16` included, answers as the k-d tree does.
    assert!(report.all_agree());
    let md = report::markdown(&report);
    assert!(md.contains(" primary ×16 | shadow | shadow ×16 |"), "{md}");
    assert!(md.contains("primary ×16: the same rays in 4×4 (four 2×2) pixel blocks"));
}
