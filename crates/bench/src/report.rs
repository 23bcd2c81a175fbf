//! The report as markdown: header, the performance targets, build, traversal (with the
//! kdtree/Embree ratio) and agreement tables, then notes.

use crate::contenders::{BRUTE, EMBREE, KDTREE, MEDIAN};
use crate::results::{Kind, Referee, Report, Role, SceneResult, TraceRow};
use std::fmt::Write;

fn trace<'a>(s: &'a SceneResult, who: &str, threads: usize, kind: Kind) -> Option<&'a TraceRow> {
    s.traces
        .iter()
        .find(|r| r.contender == who && r.threads == threads && r.kind == kind)
}

/// kdtree Mrays/s over Embree Mrays/s on the same rays and thread count.
pub fn ratio(s: &SceneResult, threads: usize, kind: Kind) -> Option<f64> {
    let k = trace(s, KDTREE, threads, kind)?;
    let e = trace(s, EMBREE, threads, kind)?;
    Some(k.mrays_per_s() / e.mrays_per_s())
}

fn build_secs(s: &SceneResult, who: &str, threads: usize) -> Option<f64> {
    s.builds
        .iter()
        .find(|b| b.contender == who && b.threads == threads)
        .map(|b| b.seconds)
}

fn opt<T>(v: Option<T>, f: impl Fn(T) -> String) -> String {
    v.map_or_else(|| "–".to_string(), f)
}

fn yes(ok: bool) -> &'static str {
    if ok {
        "yes"
    } else {
        "**no**"
    }
}

/// The performance targets, for the scenes this run measured.
fn targets(r: &Report, out: &mut String) {
    let mut rows = vec![];
    for s in &r.scenes {
        // Every ray kind at or above Embree's single-ray speed: the row shows the slowest.
        let worst = Kind::all(r.config.packet)
            .iter()
            .filter_map(|&kind| ratio(s, 1, kind).map(|x| (x, kind)))
            .min_by(|a, b| a.0.total_cmp(&b.0));
        if let Some((x, kind)) = worst {
            rows.push((
                format!(
                    "{}: every ray kind, 1 thread, kdtree ≥ 1.0× Embree (slowest shown)",
                    s.name
                ),
                format!("{x:.2}× ({})", kind.name()),
                x >= 1.0,
            ));
        }
        if s.role == Role::Baseline {
            let best = r
                .config
                .threads
                .iter()
                .filter_map(|&t| build_secs(s, KDTREE, t))
                .reduce(f64::min);
            if let Some(secs) = best {
                rows.push((
                    format!("{}: tree builds in < 50 ms", s.name),
                    format!("{:.1} ms", secs * 1e3),
                    secs < 0.050,
                ));
            }
        }
        if s.role == Role::Generated && s.triangles >= 5_000_000 {
            if let Some(secs) = build_secs(s, KDTREE, 2) {
                let rate = s.triangles as f64 / secs / 1e6;
                rows.push((
                    format!("{}: build ≥ 2 M triangles/s on 2 cores", s.name),
                    format!("{rate:.2} M/s"),
                    rate >= 2.0,
                ));
            }
            if let (Some(a), Some(b)) = (build_secs(s, KDTREE, 1), build_secs(s, KDTREE, 2)) {
                rows.push((
                    format!("{}: parallel build speed-up ≥ 1.7× on 2 cores", s.name),
                    format!("{:.2}×", a / b),
                    a / b >= 1.7,
                ));
            }
        }
    }
    let worst = r
        .scenes
        .iter()
        .flat_map(|s| &s.builds)
        .filter(|b| b.contender == KDTREE)
        .filter_map(|b| b.bytes_per_triangle.map(|x| (x, b.scene.clone())))
        .max_by(|a, b| a.0.total_cmp(&b.0));
    if let Some((bytes, scene)) = worst {
        rows.push((
            "tree memory ≤ 64 bytes per triangle (worst scene)".into(),
            format!("{bytes:.1} ({scene})"),
            bytes <= 64.0,
        ));
    }
    if rows.is_empty() {
        return;
    }
    out.push_str("## Targets\n\n| target | measured | met |\n|---|---:|:---:|\n");
    for (what, measured, ok) in rows {
        let _ = writeln!(out, "| {what} | {measured} | {} |", yes(ok));
    }
    out.push('\n');
}

fn builds(r: &Report, out: &mut String) {
    out.push_str(
        "## Build\n\n\
         | scene | triangles | contender | threads | build ms | M tri/s | SAH cost | nodes | refs/tri | bytes/tri |\n\
         |---|---:|---|---:|---:|---:|---:|---:|---:|---:|\n",
    );
    for b in r.scenes.iter().flat_map(|s| &s.builds) {
        let _ = writeln!(
            out,
            "| {} | {} | {} | {} | {:.1} | {:.2} | {} | {} | {} | {} |",
            b.scene,
            b.triangles,
            b.contender,
            b.threads,
            b.seconds * 1e3,
            b.triangles as f64 / b.seconds / 1e6,
            opt(b.sah_cost, |x| format!("{x:.1}")),
            opt(b.nodes, |x| x.to_string()),
            opt(b.refs_per_triangle, |x| format!("{x:.2}")),
            opt(b.bytes_per_triangle, |x| format!("{x:.1}")),
        );
    }
    out.push('\n');
}

fn traversal(r: &Report, out: &mut String) {
    out.push_str(
        "## Traversal (Mrays/s)\n\n\
         Brute force runs on a subset of each ray set (see the header). The ratio rows are \
         kdtree ÷ Embree on the same rays with the same thread count. Surface rays leave \
         random points of random triangles (offset as the renderer offsets secondary rays) \
         toward the shadow rays' light or into the normal's hemisphere; \"any\" columns \
         trace the same rays as any-hit queries. Soft rays are a soft shadow's samples as \
         the renderer traces them: from every n-th primary hit that faces the sun (a \
         direction toward the shadow rays' light), n per hit within a cone of 2°, n the \
         packet size; the soft packet column traces each hit's samples as one packet.\n\n\
         | scene | contender | threads |",
    );
    for k in Kind::all(r.config.packet) {
        let _ = write!(out, " {} |", k.name());
    }
    out.push_str("\n|---|---|---:|");
    for _ in Kind::all(r.config.packet) {
        out.push_str("---:|");
    }
    out.push('\n');
    for s in &r.scenes {
        let contenders = [KDTREE, MEDIAN, EMBREE, BRUTE];
        for who in contenders {
            for &t in &r.config.threads {
                let cells: Vec<Option<&TraceRow>> = Kind::all(r.config.packet)
                    .iter()
                    .map(|&k| trace(s, who, t, k))
                    .collect();
                if cells.iter().all(Option::is_none) {
                    continue;
                }
                let _ = write!(out, "| {} | {who} | {t} |", s.name);
                for c in cells {
                    let _ = write!(out, " {} |", opt(c, |r| format!("{:.3}", r.mrays_per_s())));
                }
                out.push('\n');
            }
        }
        for &t in &r.config.threads {
            let cells: Vec<Option<f64>> = Kind::all(r.config.packet)
                .iter()
                .map(|&k| ratio(s, t, k))
                .collect();
            if cells.iter().all(Option::is_none) {
                continue;
            }
            let _ = write!(out, "| {} | **kdtree/Embree** | {t} |", s.name);
            for c in cells {
                let _ = write!(out, " {} |", opt(c, |x| format!("**{x:.2}×**")));
            }
            out.push('\n');
        }
    }
    let cores: Vec<String> = r
        .scenes
        .iter()
        .map(|s| {
            let per: Vec<String> = s
                .cpu
                .iter()
                .filter(|(_, (_, wall))| *wall > 0.0)
                .map(|(t, (cpu, wall))| format!("{t} thread(s) got {:.2}", cpu / wall))
                .collect();
            format!("{}: {}", s.name, per.join(", "))
        })
        .collect();
    if !cores.is_empty() {
        let _ = writeln!(
            out,
            "\nCores this process actually got while tracing (CPU time ÷ wall time; other \
             processes share the machine, so 2 threads may get less than 2): {}.",
            cores.join("; ")
        );
    }
    let counts: Vec<String> = r
        .scenes
        .iter()
        .map(|s| {
            let n = |k| trace(s, KDTREE, r.config.threads[0], k).map_or(0, |t| t.rays);
            format!(
                "{}: {}/{}/{}/{}/{}",
                s.name,
                n(Kind::Primary),
                n(Kind::Shadow),
                n(Kind::Random),
                n(Kind::SurfaceLight),
                n(Kind::SurfaceHemisphere)
            )
        })
        .collect();
    if !r.config.threads.is_empty() && !counts.is_empty() {
        let _ = writeln!(
            out,
            "\nRays per set (primary/shadow/random/surface→light/surface→hemisphere): {}.",
            counts.join("; ")
        );
    }
    out.push('\n');
}

fn agreement(r: &Report, out: &mut String) {
    out.push_str(
        "## Agreement with the k-d tree\n\n\
         Closest hit: same triangle, or t within 1e-4 relative (ties at shared edges); \
         shadow: same occlusion answer. The bar is 99.99% of rays. Where the k-d tree and \
         Embree (or the median-split tree) differ, brute force (f64) re-traces up to 200 of those rays per set: the last \
         column counts how often it sides with each (both on ties, neither when all three differ).\n\n\
         | scene | contender |",
    );
    for k in Kind::all(r.config.packet) {
        let _ = write!(out, " {} differ |", k.name());
    }
    out.push_str(" agreement | verdict | brute force sides with kdtree / other, of |\n|---|---|");
    for _ in Kind::all(r.config.packet) {
        out.push_str("---:|");
    }
    out.push_str("---:|:---:|---:|\n");
    for s in &r.scenes {
        for who in [EMBREE, MEDIAN, BRUTE] {
            let rows: Vec<_> = s.agreement.iter().filter(|a| a.other == who).collect();
            if rows.is_empty() {
                continue;
            }
            let cell = |k: Kind| {
                opt(rows.iter().find(|a| a.kind == k), |a| {
                    format!("{} / {}", a.disagreements, a.compared)
                })
            };
            let worst = rows.iter().map(|a| a.agreement()).fold(1.0f64, f64::min);
            let ok = rows.iter().all(|a| a.ok());
            let referee = rows
                .iter()
                .filter_map(|a| a.referee)
                .reduce(|a, b| Referee {
                    checked: a.checked + b.checked,
                    kdtree_right: a.kdtree_right + b.kdtree_right,
                    other_right: a.other_right + b.other_right,
                });
            let cells: Vec<String> = Kind::all(r.config.packet)
                .iter()
                .map(|&k| cell(k))
                .collect();
            let _ = writeln!(
                out,
                "| {} | {who} | {} | {:.4}% | {} | {} |",
                s.name,
                cells.join(" | "),
                worst * 100.0,
                if ok { "ok" } else { "**FAIL**" },
                opt(referee, |r| format!(
                    "{} / {} of {}",
                    r.kdtree_right, r.other_right, r.checked
                ))
            );
        }
    }
    out.push('\n');
}

/// The k-d tree's work per surface ray, for both origin placements.
fn work(r: &Report, out: &mut String) {
    if r.scenes.iter().all(|s| s.work.is_empty()) {
        return;
    }
    out.push_str(
        "## k-d tree work per surface ray\n\n\
         Interior nodes stepped through, leaves reached and triangle tests per ray (one \
         counting pass, not timed), with the origins as spawned and moved 5 mm along the \
         ray.\n\n\
         | scene | rays | origin | nodes | leaves | tests |\n\
         |---|---|---|---:|---:|---:|\n",
    );
    for s in &r.scenes {
        for w in &s.work {
            let per = |x: u64| x as f64 / w.rays.max(1) as f64;
            let _ = writeln!(
                out,
                "| {} | {} | {} | {:.1} | {:.2} | {:.1} |",
                s.name,
                w.kind.name(),
                if w.moved { "+5 mm" } else { "on surface" },
                per(w.counts.nodes),
                per(w.counts.leaves),
                per(w.counts.tests)
            );
        }
    }
    out.push('\n');
}

/// The whole report as markdown.
pub fn markdown(r: &Report) -> String {
    let mut out = String::from("# k-d tree benchmark (kdbench)\n\n");
    for h in &r.header {
        let _ = writeln!(out, "- {h}");
    }
    out.push('\n');
    targets(r, &mut out);
    builds(r, &mut out);
    traversal(r, &mut out);
    work(r, &mut out);
    agreement(r, &mut out);
    if !r.notes.is_empty() {
        out.push_str("## Notes\n\n");
        for n in &r.notes {
            let _ = writeln!(out, "- {n}");
        }
        out.push('\n');
    }
    out
}
