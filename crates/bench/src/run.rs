//! The benchmark itself: for each scene, build every contender with 1 and 2 threads,
//! trace the same primary, shadow, soft-shadow, random and surface-origin rays with each,
//! and check that they agree.

use crate::agreement::{self, subset_indices, Answers};
use crate::config::Config;
#[cfg(feature = "embree")]
use crate::contenders::EMBREE;
use crate::contenders::{Brute, Tracer, BRUTE, KDTREE, MEDIAN};
use crate::error::BenchError;
use crate::header::{header, load_average};
use crate::measure::{median, pool, process_cpu_seconds, timed, trace, trace_packets};
use crate::rays::{self, View};
use crate::results::{BuildRow, Kind, Report, Role, SceneResult, TraceRow, WorkRow};
use crate::scenes::{self, Scene};
use formats::BuildParams;
use glam::Vec3;
use kdtree::{Accel, Ray};
use std::time::Instant;

/// Everything measured on one scene, and the helpers that fill it in.
struct Bench<'a> {
    cfg: &'a Config,
    pools: Vec<(usize, rayon::ThreadPool)>,
    log: &'a mut dyn FnMut(&str),
    out: SceneResult,
}

impl Bench<'_> {
    /// Time every tracer in `who` on `rays` for every thread count, and return their
    /// answers (identical across runs and thread counts, so the last is kept). Runs go
    /// round-robin over the tracers, so a burst of load from other processes on the
    /// shared machine hits every contender's runs alike rather than one contender's.
    fn traverse(&mut self, who: &[(&str, &dyn Tracer)], kind: Kind, rays: &[Ray]) -> Vec<Answers> {
        let mut answers: Vec<Option<Answers>> = who.iter().map(|_| None).collect();
        for (threads, pool) in &self.pools {
            let cpu0 = process_cpu_seconds();
            let wall0 = Instant::now();
            let mut times = vec![Vec::new(); who.len()];
            for _ in 0..self.cfg.runs.max(1) {
                for (c, (_, tracer)) in who.iter().enumerate() {
                    let start = Instant::now();
                    let around = |run: &mut dyn FnMut()| tracer.in_mode(run);
                    let a = match kind {
                        Kind::ShadowPackets(n) | Kind::SoftPackets(n) => {
                            Answers::Occluded(trace_packets(pool, rays, n, around, |p, o| {
                                tracer.occluded_packet(p, o)
                            }))
                        }
                        Kind::PrimaryPackets(n) => {
                            Answers::Closest(trace_packets(pool, rays, n, around, |p, o| {
                                tracer.closest_packet(p, o)
                            }))
                        }
                        _ if kind.any_hit() => {
                            Answers::Occluded(trace(pool, rays, around, |r| tracer.occluded(r)))
                        }
                        _ => Answers::Closest(trace(pool, rays, around, |r| tracer.closest(r))),
                    };
                    times[c].push(start.elapsed().as_secs_f64());
                    answers[c] = Some(a);
                }
            }
            if let Some((c0, c1)) = cpu0.zip(process_cpu_seconds()) {
                let e = self.out.cpu.entry(*threads).or_default();
                e.0 += c1 - c0;
                e.1 += wall0.elapsed().as_secs_f64();
            }
            for ((name, _), t) in who.iter().zip(times) {
                let row = TraceRow {
                    scene: self.out.name.clone(),
                    contender: (*name).into(),
                    threads: *threads,
                    kind,
                    rays: rays.len(),
                    seconds: median(t),
                };
                (self.log)(&format!(
                    "  {:<13} {:<7} {} thread(s): {:>8.3} Mrays/s ({} rays)",
                    name,
                    kind.name(),
                    threads,
                    row.mrays_per_s(),
                    rays.len()
                ));
                self.out.traces.push(row);
            }
        }
        answers
            .into_iter()
            .map(|a| a.unwrap_or(Answers::Closest(vec![])))
            .collect()
    }

    /// Build a k-d tree with `builder` for every thread count, record the builds, and
    /// return the last tree ready for queries (None when no thread count is configured).
    fn build_tree(
        &mut self,
        name: &str,
        builder: fn(&[[Vec3; 3]], &BuildParams, formats::Digest) -> formats::KdFile,
        tris: &[[Vec3; 3]],
        hash: formats::Digest,
    ) -> Result<Option<Accel>, BenchError> {
        let n = tris.len();
        let mut kd = None;
        for (threads, pool) in &self.pools {
            let (seconds, tree) = timed(self.cfg.runs, || {
                pool.install(|| builder(tris, &self.cfg.params, hash))
            });
            (self.log)(&format!(
                "  {name:<13} build {threads} thread(s): {:.1} ms",
                seconds * 1e3
            ));
            self.out.builds.push(BuildRow {
                scene: self.out.name.clone(),
                triangles: n,
                contender: name.into(),
                threads: *threads,
                seconds,
                sah_cost: Some(tree.stats.sah_cost),
                nodes: Some(tree.nodes.len() as u64),
                refs_per_triangle: Some(tree.leaf_tris.len() as f64 / n.max(1) as f64),
                bytes_per_triangle: Some(kdtree::query_bytes(&tree.stats) as f64 / n.max(1) as f64),
            });
            kd = Some(tree);
        }
        kd.map(|kd| {
            Accel::from_triangles(tris, &kd).map_err(|e| BenchError::Accel {
                scene: self.out.name.clone(),
                detail: format!("{name}: {e}"),
            })
        })
        .transpose()
    }

    /// Compare `other`'s answers with the k-d tree's (see [`agreement::compare`]), log
    /// the outcome and keep the row.
    #[allow(clippy::too_many_arguments)]
    fn agree(
        &mut self,
        other: &str,
        kind: Kind,
        rays: &[Ray],
        reference: &Answers,
        answers: &Answers,
        idx: Option<&[usize]>,
        referee: Option<&[[Vec3; 3]]>,
    ) {
        let row = agreement::compare(
            &self.out.name,
            other,
            kind,
            rays,
            reference,
            answers,
            idx,
            referee,
        );
        for line in agreement::summary(&row) {
            (self.log)(&line);
        }
        self.out.agreement.push(row);
    }
}

/// The k-d tree's nodes, leaves and triangle tests summed over `rays` (one thread).
fn work(accel: &Accel, kind: Kind, rays: &[Ray]) -> kdtree::Counts {
    let mut c = kdtree::Counts::default();
    for r in rays {
        if kind.any_hit() {
            accel.occluded_counted(r, &mut c);
        } else {
            accel.intersect_counted(r, &mut c);
        }
    }
    c
}

fn run_scene(
    cfg: &Config,
    scene: &Scene,
    role: Role,
    log: &mut dyn FnMut(&str),
) -> Result<SceneResult, BenchError> {
    let tris = &scene.triangles;
    let n = tris.len();
    let name = scene.name.clone();
    log(&format!("scene {name}: {n} triangles"));
    let pools = cfg
        .threads
        .iter()
        .map(|&t| pool(t).map(|p| (t, p)))
        .collect::<Result<Vec<_>, _>>()?;
    let mut b = Bench {
        cfg,
        pools,
        log,
        out: SceneResult {
            name: name.clone(),
            role,
            triangles: n,
            builds: vec![],
            traces: vec![],
            agreement: vec![],
            work: vec![],
            cpu: Default::default(),
        },
    };
    let hash = formats::soup::geometry_hash(tris);

    // Builds, 1 and 2 threads; the last tree of each kind is kept for tracing.
    let Some(accel) = b.build_tree(KDTREE, kdtree::build, tris, hash)? else {
        return Ok(b.out);
    };
    let median = b.build_tree(MEDIAN, kdtree::build_median, tris, hash)?;

    #[cfg(feature = "embree")]
    let embree = {
        use crate::embree::{Device, EmbreeScene, SCENE_FLAG_NONE};
        let err = |source| BenchError::Embree {
            scene: name.clone(),
            source,
        };
        let mut last = None;
        for (threads, _) in &b.pools {
            // Embree builds on its own thread pool: a device of `threads` threads.
            let device = Device::new(*threads).map_err(err)?;
            let (seconds, s) = timed(cfg.runs, || {
                EmbreeScene::build(&device, tris, cfg.embree_quality, SCENE_FLAG_NONE)
            });
            let s = s.map_err(err)?;
            (b.log)(&format!(
                "  {EMBREE:<13} build {threads} thread(s): {:.1} ms",
                seconds * 1e3
            ));
            b.out.builds.push(BuildRow {
                scene: name.clone(),
                triangles: n,
                contender: EMBREE.into(),
                threads: *threads,
                seconds,
                sah_cost: None,
                nodes: None,
                refs_per_triangle: None,
                bytes_per_triangle: Some(s.memory_bytes() as f64 / n.max(1) as f64),
            });
            last = Some(s);
        }
        last
    };

    // Ray sets: the same for every contender.
    let bounds = scenes::bounds(tris);
    let view: View = scene.view.unwrap_or_else(|| rays::framing(bounds));
    let primary = rays::primary(&view, cfg.image);
    let primary_blocks = rays::in_blocks(&primary, cfg.image, cfg.packet);
    let random = rays::random(bounds, cfg.random_rays, 0x5EED ^ n as u64);
    let brute = (n <= cfg.brute_max_triangles).then_some(Brute(tris));
    let light = rays::light_above(bounds);
    let surface_light = rays::surface(tris, cfg.random_rays, 0x5EEF ^ n as u64, |_, _| {
        rays::Toward::Point(light)
    });
    let surface_hemisphere = rays::surface(tris, cfg.random_rays, 0x5EF0 ^ n as u64, |rng, ng| {
        rays::Toward::Direction(rays::hemisphere(rng, ng))
    });

    let (mut shadow, mut shadow_blocks, mut soft) = (vec![], vec![], vec![]);
    for kind in Kind::all(cfg.packet) {
        let set: &[Ray] = match kind {
            Kind::Primary => &primary,
            Kind::PrimaryPackets(_) => &primary_blocks,
            Kind::Shadow => &shadow,
            Kind::ShadowPackets(_) => &shadow_blocks,
            Kind::Soft | Kind::SoftPackets(_) => &soft,
            Kind::Random => &random,
            Kind::SurfaceLight | Kind::SurfaceLightAny => &surface_light,
            Kind::SurfaceHemisphere | Kind::SurfaceHemisphereAny => &surface_hemisphere,
        };
        if matches!(
            kind,
            Kind::SurfaceLight
                | Kind::SurfaceLightAny
                | Kind::SurfaceHemisphere
                | Kind::SurfaceHemisphereAny
        ) {
            for moved in [false, true] {
                let counts = if moved {
                    work(&accel, kind, &rays::moved_along(set, rays::MOVED))
                } else {
                    work(&accel, kind, set)
                };
                b.out.work.push(WorkRow {
                    kind,
                    moved,
                    rays: set.len(),
                    counts,
                });
            }
        }
        // The k-d tree first: its answers are the reference the others are checked on.
        let mut who: Vec<(&str, &dyn Tracer)> = vec![(KDTREE, &accel)];
        if let Some(m) = &median {
            who.push((MEDIAN, m));
        }
        #[cfg(feature = "embree")]
        if let Some(e) = &embree {
            who.push((EMBREE, e));
        }
        let mut answers = b.traverse(&who, kind, set).into_iter();
        let reference = answers.next().unwrap_or(Answers::Closest(vec![]));
        for ((name, _), a) in who.iter().skip(1).zip(answers) {
            b.agree(name, kind, set, &reference, &a, None, Some(tris));
        }
        if let Some(brute) = &brute {
            let idx = subset_indices(set.len(), cfg.brute_rays);
            let sub: Vec<Ray> = idx.iter().map(|&i| set[i]).collect();
            let answers = b.traverse(&[(BRUTE, brute)], kind, &sub);
            b.agree(BRUTE, kind, set, &reference, &answers[0], Some(&idx), None);
        }
        // Shadow rays start at the k-d tree's primary hits, in the order of their set (so
        // block by block for the packets).
        if let (Kind::Primary | Kind::PrimaryPackets(_), Answers::Closest(hits)) =
            (kind, &reference)
        {
            let hits: Vec<_> = hits
                .iter()
                .map(|h| h.is_hit().then_some((h.prim, h.u, h.v)))
                .collect();
            let rays = rays::shadow(tris, &hits, rays::light_above(bounds), bounds);
            match kind {
                Kind::Primary => {
                    let sun = (rays::light_above(bounds) - (bounds[0] + bounds[1]) * 0.5)
                        .normalize_or(Vec3::Y);
                    soft = rays::soft(tris, &primary, &hits, sun, cfg.packet, 0x50F7 ^ n as u64);
                    shadow = rays;
                }
                _ => shadow_blocks = rays,
            }
        }
    }
    Ok(b.out)
}

/// Run the benchmark described by `cfg`, reporting progress lines to `log`.
///
/// Missing inputs (no baseline soup, no mesh folder) are skipped with a note; a file
/// that exists but cannot be read is an error.
pub fn run(cfg: &Config, log: &mut dyn FnMut(&str)) -> Result<Report, BenchError> {
    let header_start = header(cfg);
    let mut notes = vec![];
    let mut scenes_out = vec![];
    let skip = |notes: &mut Vec<String>, log: &mut dyn FnMut(&str), msg: String| {
        log(&msg);
        notes.push(msg);
    };

    if let Some(path) = &cfg.baseline {
        if path.exists() {
            let scene = scenes::load_soup(path)?;
            notes.extend(scene.notes.iter().cloned());
            scenes_out.push(run_scene(cfg, &scene, Role::Baseline, log)?);
        } else {
            skip(
                &mut notes,
                log,
                format!(
                    "SKIPPED: baseline soup {} because it does not exist (make it with unity2soup)",
                    path.display()
                ),
            );
        }
    }
    if let Some(dir) = &cfg.meshes {
        if dir.is_dir() {
            let files = scenes::obj_files(dir)?;
            if files.is_empty() {
                skip(
                    &mut notes,
                    log,
                    format!("SKIPPED: meshes because {} holds no .obj", dir.display()),
                );
            }
            for path in files {
                let scene = scenes::load_obj(&path)?;
                notes.extend(scene.notes.iter().cloned());
                scenes_out.push(run_scene(cfg, &scene, Role::Mesh, log)?);
            }
        } else {
            skip(
                &mut notes,
                log,
                format!("SKIPPED: real meshes because {} is absent", dir.display()),
            );
        }
    }
    if cfg.generated > 0 {
        log(&format!(
            "generating a scene of ~{} triangles",
            cfg.generated
        ));
        let scene = scenes::generated(cfg.generated);
        notes.extend(scene.notes.iter().cloned());
        scenes_out.push(run_scene(cfg, &scene, Role::Generated, log)?);
    }
    let mut header = header_start;
    header.push(format!("load average at the end: {}", load_average()));
    Ok(Report {
        config: cfg.clone(),
        header,
        scenes: scenes_out,
        notes,
    })
}
