//! The benchmark itself: for each scene, build every contender with 1 and 2 threads,
//! trace the same primary, shadow and random rays with each, and check that they agree.

use crate::error::BenchError;
use crate::measure::{median, pool, process_cpu_seconds, timed, trace};
use crate::rays::{self, View};
use crate::scenes::{self, Scene};
use formats::BuildParams;
use glam::Vec3;
use kdtree::testkit::brute;
use kdtree::{Accel, Ray};
use std::path::PathBuf;
use std::time::Instant;

pub const KDTREE: &str = "kdtree";
pub const MEDIAN: &str = "kdtree median";
pub const EMBREE: &str = "Embree";
pub const BRUTE: &str = "brute force";

#[derive(Clone, Debug)]
pub struct Config {
    /// A soup written by `unity2soup` (skipped with a message when absent).
    pub baseline: Option<PathBuf>,
    /// A folder of OBJ meshes (skipped loudly when absent).
    pub meshes: Option<PathBuf>,
    /// Triangles in the generated scene (0: none).
    pub generated: usize,
    /// Primary rays: an `image` × `image` camera.
    pub image: u32,
    pub random_rays: usize,
    /// Timed runs per measurement (the median is reported).
    pub runs: usize,
    /// Thread counts to measure (rayon pool sizes, and Embree build threads).
    pub threads: Vec<usize>,
    /// Brute force runs only on scenes with at most this many triangles …
    pub brute_max_triangles: usize,
    /// … and on this many rays of each set.
    pub brute_rays: usize,
    pub params: BuildParams,
    #[cfg(feature = "embree")]
    pub embree_quality: crate::embree::Quality,
    /// The exact command line, for the report's header.
    pub command: String,
    /// Extra header lines (e.g. which commit of the k-d tree was measured).
    pub remarks: Vec<String>,
}

impl Config {
    /// The full benchmark (issue 4 item 7).
    pub fn full() -> Config {
        Config {
            baseline: None,
            meshes: None,
            generated: 5_100_000,
            image: 512,
            random_rays: 262_144,
            runs: 3,
            threads: vec![1, 2],
            brute_max_triangles: 20_000,
            brute_rays: 4096,
            params: BuildParams::default(),
            #[cfg(feature = "embree")]
            embree_quality: crate::embree::Quality::High,
            command: String::new(),
            remarks: vec![],
        }
    }

    /// A smoke test that finishes in seconds: one small generated scene, few rays.
    pub fn quick() -> Config {
        Config {
            generated: 3000,
            image: 48,
            random_rays: 2048,
            brute_rays: 512,
            ..Config::full()
        }
    }
}

/// Which ray set.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    Primary,
    Shadow,
    Random,
}

impl Kind {
    pub const ALL: [Kind; 3] = [Kind::Primary, Kind::Shadow, Kind::Random];
    pub fn name(self) -> &'static str {
        match self {
            Kind::Primary => "primary",
            Kind::Shadow => "shadow",
            Kind::Random => "random",
        }
    }
}

#[derive(Clone, Debug)]
pub struct BuildRow {
    pub scene: String,
    pub triangles: usize,
    pub contender: String,
    pub threads: usize,
    /// Median wall time of the build.
    pub seconds: f64,
    pub sah_cost: Option<f64>,
    pub nodes: Option<u64>,
    /// Leaf references per input triangle.
    pub refs_per_triangle: Option<f64>,
    /// Memory held for queries, per input triangle.
    pub bytes_per_triangle: Option<f64>,
}

#[derive(Clone, Debug)]
pub struct TraceRow {
    pub scene: String,
    pub contender: String,
    pub threads: usize,
    pub kind: Kind,
    pub rays: usize,
    /// Median wall time of tracing all `rays`.
    pub seconds: f64,
}

impl TraceRow {
    pub fn mrays_per_s(&self) -> f64 {
        self.rays as f64 / self.seconds / 1e6
    }
}

#[derive(Clone, Debug)]
pub struct AgreeRow {
    pub scene: String,
    /// The contender compared with the k-d tree.
    pub other: String,
    pub kind: Kind,
    pub compared: usize,
    pub disagreements: usize,
    /// The first few disagreements, for the log.
    pub examples: Vec<String>,
    /// Brute force's verdict on the disagreements (Embree rows only).
    pub referee: Option<Referee>,
}

impl AgreeRow {
    pub fn agreement(&self) -> f64 {
        if self.compared == 0 {
            1.0
        } else {
            1.0 - self.disagreements as f64 / self.compared as f64
        }
    }
    /// The bar the brief sets: at least 99.99% of rays agree.
    pub fn ok(&self) -> bool {
        self.agreement() >= 0.9999
    }
}

/// Where a scene came from (the targets single out the baseline and generated scenes).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Role {
    Baseline,
    Mesh,
    Generated,
}

pub struct SceneResult {
    pub name: String,
    pub role: Role,
    pub triangles: usize,
    pub builds: Vec<BuildRow>,
    pub traces: Vec<TraceRow>,
    pub agreement: Vec<AgreeRow>,
    /// Per thread count: (CPU seconds, wall seconds) this process spent tracing. Their
    /// ratio is the number of cores the run actually got on a shared machine.
    pub cpu: std::collections::BTreeMap<usize, (f64, f64)>,
}

pub struct Report {
    pub config: Config,
    /// `- key: value` lines for the top of the report.
    pub header: Vec<String>,
    pub scenes: Vec<SceneResult>,
    /// Scenes skipped and why, notes on scenes.
    pub notes: Vec<String>,
}

impl Report {
    /// Every agreement check passed.
    pub fn all_agree(&self) -> bool {
        self.scenes
            .iter()
            .flat_map(|s| &s.agreement)
            .all(AgreeRow::ok)
    }
}

/// A closest hit as every contender reports it; `prim == u32::MAX` is a miss.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Found {
    pub t: f32,
    pub prim: u32,
    pub u: f32,
    pub v: f32,
}

impl Default for Found {
    fn default() -> Self {
        Found {
            t: f32::INFINITY,
            prim: u32::MAX,
            u: 0.0,
            v: 0.0,
        }
    }
}

impl Found {
    pub fn is_hit(&self) -> bool {
        self.prim != u32::MAX
    }
}

/// Same closest hit: both miss, or the same triangle, or (for ties at shared edges and
/// coincident faces) distances within 1e-4 relative.
pub fn same_closest(a: Found, b: Found) -> bool {
    match (a.is_hit(), b.is_hit()) {
        (false, false) => true,
        (true, true) => a.prim == b.prim || (a.t - b.t).abs() <= 1e-4 * a.t.abs().max(b.t.abs()),
        _ => false,
    }
}

/// What the benchmark asks of every contender.
trait Tracer: Sync {
    fn closest(&self, ray: &Ray) -> Found;
    fn occluded(&self, ray: &Ray) -> bool;
}

impl Tracer for Accel {
    #[inline]
    fn closest(&self, ray: &Ray) -> Found {
        self.intersect(ray)
            .map(|h| Found {
                t: h.t,
                prim: h.prim,
                u: h.u,
                v: h.v,
            })
            .unwrap_or_default()
    }
    #[inline]
    fn occluded(&self, ray: &Ray) -> bool {
        Accel::occluded(self, ray)
    }
}

#[cfg(feature = "embree")]
impl Tracer for crate::embree::EmbreeScene {
    #[inline]
    fn closest(&self, ray: &Ray) -> Found {
        self.intersect(ray)
            .map(|(t, prim, u, v)| Found { t, prim, u, v })
            .unwrap_or_default()
    }
    #[inline]
    fn occluded(&self, ray: &Ray) -> bool {
        crate::embree::EmbreeScene::occluded(self, ray)
    }
}

struct Brute<'a>(&'a [[Vec3; 3]]);

impl Tracer for Brute<'_> {
    fn closest(&self, ray: &Ray) -> Found {
        brute::intersect_f64(self.0, ray)
            .map(|(t, prim)| Found {
                t,
                prim,
                u: 0.0,
                v: 0.0,
            })
            .unwrap_or_default()
    }
    fn occluded(&self, ray: &Ray) -> bool {
        brute::occluded_f64(self.0, ray)
    }
}

/// One contender's answers to one ray set.
enum Answers {
    Closest(Vec<Found>),
    Occluded(Vec<bool>),
}

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
                    let a = match kind {
                        Kind::Shadow => {
                            Answers::Occluded(trace(pool, rays, |r| tracer.occluded(r)))
                        }
                        _ => Answers::Closest(trace(pool, rays, |r| tracer.closest(r))),
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
                bytes_per_triangle: Some(kdtree::query_bytes(&tree) as f64 / n.max(1) as f64),
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

    /// Compare `other`'s answers with the k-d tree's (`reference`, indexed through `idx`
    /// when `other` ran on a subset). With `referee` triangles, up to [`REFEREE_RAYS`]
    /// disagreements are settled by brute force.
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
        let at = |j: usize| idx.map_or(j, |idx| idx[j]);
        // (ray index, the tree's answer, the other's answer) for every disagreement.
        let mut differ: Vec<(usize, Found, Found)> = vec![];
        let compared = match (reference, answers) {
            (Answers::Closest(r), Answers::Closest(a)) => {
                for (j, b) in a.iter().enumerate() {
                    let i = at(j);
                    if !same_closest(r[i], *b) {
                        differ.push((i, r[i], *b));
                    }
                }
                a.len()
            }
            (Answers::Occluded(r), Answers::Occluded(a)) => {
                // Occlusion as a hit at t = 0 on no particular triangle, to share the code.
                let f = |o: bool| Found {
                    t: if o { 0.0 } else { f32::INFINITY },
                    prim: if o { 0 } else { u32::MAX },
                    ..Found::default()
                };
                for (j, b) in a.iter().enumerate() {
                    let i = at(j);
                    if r[i] != *b {
                        differ.push((i, f(r[i]), f(*b)));
                    }
                }
                a.len()
            }
            _ => unreachable!("answers of one kind are compared with the same kind"),
        };
        let mut row = AgreeRow {
            scene: self.out.name.clone(),
            other: other.into(),
            kind,
            compared,
            disagreements: differ.len(),
            examples: vec![],
            referee: None,
        };
        let show = |f: Found| {
            if !f.is_hit() {
                "miss".to_string()
            } else if kind == Kind::Shadow {
                "occluded".to_string()
            } else {
                format!("t={} prim={}", f.t, f.prim)
            }
        };
        for (i, k, o) in differ.iter().take(3) {
            row.examples.push(format!(
                "{} ray {i} {:?}: kdtree {}, {other} {}",
                kind.name(),
                rays[*i],
                show(*k),
                show(*o)
            ));
        }
        if let Some(tris) = referee.filter(|_| !differ.is_empty()) {
            let mut r = Referee::default();
            for (i, k, o) in differ.iter().take(REFEREE_RAYS) {
                let ray = &rays[*i];
                let truth = if kind == Kind::Shadow {
                    let occ = brute::occluded_f64(tris, ray);
                    (occ == k.is_hit(), occ == o.is_hit())
                } else {
                    let b = Brute(tris).closest(ray);
                    (same_closest(b, *k), same_closest(b, *o))
                };
                r.checked += 1;
                r.kdtree_right += usize::from(truth.0);
                r.other_right += usize::from(truth.1);
            }
            row.referee = Some(r);
        }
        let referee_note = row.referee.map_or(String::new(), |r| {
            format!(
                "; brute force on {} of them sides with kdtree {} times, with {other} {} times",
                r.checked, r.kdtree_right, r.other_right
            )
        });
        (self.log)(&format!(
            "  agreement kdtree vs {other} ({}): {} of {} rays differ{referee_note}",
            kind.name(),
            row.disagreements,
            row.compared
        ));
        for e in &row.examples {
            (self.log)(&format!("    {e}"));
        }
        self.out.agreement.push(row);
    }
}

/// At most this many disagreements per ray set are settled by brute force (each costs
/// a pass over every triangle).
pub const REFEREE_RAYS: usize = 200;

/// Brute force's verdict on disagreeing rays (a ray can side with both when the two
/// answers are ties, or with neither).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Referee {
    pub checked: usize,
    pub kdtree_right: usize,
    pub other_right: usize,
}

/// Indices of every `len / n`-th element (at most `n`), spread over the whole set.
fn subset_indices(len: usize, n: usize) -> Vec<usize> {
    if len <= n {
        return (0..len).collect();
    }
    let stride = len / n.max(1);
    (0..len).step_by(stride).take(n).collect()
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
    let random = rays::random(bounds, cfg.random_rays, 0x5EED ^ n as u64);
    let brute = (n <= cfg.brute_max_triangles).then_some(Brute(tris));

    let mut shadow = vec![];
    for kind in Kind::ALL {
        let set: &[Ray] = match kind {
            Kind::Primary => &primary,
            Kind::Shadow => &shadow,
            Kind::Random => &random,
        };
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
        if kind == Kind::Primary {
            // Shadow rays start at the k-d tree's primary hits.
            if let Answers::Closest(hits) = &reference {
                let hits: Vec<_> = hits
                    .iter()
                    .map(|h| h.is_hit().then_some((h.prim, h.u, h.v)))
                    .collect();
                shadow = rays::shadow(tris, &hits, rays::light_above(bounds), bounds);
            }
        }
    }
    Ok(b.out)
}

/// Machine and run description for the report's header.
fn header(cfg: &Config) -> Vec<String> {
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split_once(':'))
                .map(|(_, v)| v.trim().to_string())
        })
        .unwrap_or_else(|| "unknown".into());
    let nproc = std::thread::available_parallelism().map_or(0, |n| n.get());
    let p = &cfg.params;
    let mut h = vec![
        format!("date: {}", utc_now()),
        format!(
            "machine: nproc {nproc}, CPU {cpu}; load average at start {} (other processes share the cores: compare contenders within a run, not across runs)",
            load_average()
        ),
        format!("command: `{}`", cfg.command),
        format!(
            "kdtree build parameters: traversal cost {}, intersection cost {}, empty bonus {}, max depth {}, leaf size {}",
            p.traversal_cost,
            p.intersect_cost,
            p.empty_bonus,
            if p.max_depth == 0 { "auto".to_string() } else { p.max_depth.to_string() },
            p.leaf_size
        ),
        format!(
            "rays: primary {0}×{0} camera (the soup's when it has one, else a 45° view framing the bounds); \
             shadow rays from every primary hit of the k-d tree to a light above the scene (any-hit); \
             {1} random rays (origins uniform in the bounds, directions uniform on the sphere)",
            cfg.image, cfg.random_rays
        ),
        format!(
            "timing: median of {} runs (traversal runs go round-robin over the contenders); threads {:?} (rayon pools of that size; Embree builds on a device of that many threads); \
             brute force only on scenes ≤ {} triangles, on {} rays of each set",
            cfg.runs.max(1),
            cfg.threads,
            cfg.brute_max_triangles,
            cfg.brute_rays
        ),
    ];
    h.extend(cfg.remarks.iter().cloned());
    #[cfg(feature = "embree")]
    {
        let version = crate::embree::Device::new(1)
            .map(|d| d.version())
            .unwrap_or_else(|e| format!("unavailable ({e})"));
        h.push(format!(
            "Embree {version}: build quality {}, scene flags none, rtcIntersect1 / rtcOccluded1, incoherent context; \
             build time includes filling its vertex and index buffers; bytes/tri from its memory monitor",
            cfg.embree_quality.name()
        ));
    }
    #[cfg(not(feature = "embree"))]
    h.push("Embree: not measured (build with `--features embree`)".into());
    h
}

/// The 1, 5 and 15 minute load averages from /proc/loadavg ("unknown" elsewhere).
pub fn load_average() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .ok()
        .map(|s| s.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
        .filter(|s| !s.is_empty())
        .unwrap_or_else(|| "unknown".into())
}

/// `YYYY-MM-DD HH:MM UTC` from the system clock (civil-from-days, Howard Hinnant).
pub fn utc_now() -> String {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs()) as i64;
    let (days, rem) = (secs.div_euclid(86400), secs.rem_euclid(86400));
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + i64::from(m <= 2);
    format!(
        "{y:04}-{m:02}-{d:02} {:02}:{:02} UTC",
        rem / 3600,
        (rem % 3600) / 60
    )
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closest_agreement_rules() {
        let hit = |t, prim| Found {
            t,
            prim,
            u: 0.0,
            v: 0.0,
        };
        assert!(same_closest(Found::default(), Found::default()));
        assert!(same_closest(hit(2.0, 3), hit(2.5, 3)));
        assert!(same_closest(hit(2.0, 3), hit(2.0001, 4)));
        assert!(!same_closest(hit(2.0, 3), hit(2.1, 4)));
        assert!(!same_closest(hit(2.0, 3), Found::default()));
    }

    #[test]
    fn brute_force_settles_disagreements() {
        let tris = [[
            Vec3::new(-1.0, -1.0, 2.0),
            Vec3::new(1.0, -1.0, 2.0),
            Vec3::new(0.0, 1.0, 2.0),
        ]];
        let rays = [
            rays::ray(Vec3::ZERO, Vec3::Z, 0.0, f32::INFINITY),
            rays::ray(Vec3::new(5.0, 0.0, 0.0), Vec3::Z, 0.0, f32::INFINITY),
        ];
        let hit = Found {
            t: 2.0,
            prim: 0,
            u: 0.25,
            v: 0.5,
        };
        let cfg = Config::quick();
        let mut lines = vec![];
        let mut log = |l: &str| lines.push(l.to_string());
        let mut b = Bench {
            cfg: &cfg,
            pools: vec![],
            log: &mut log,
            out: SceneResult {
                name: "t".into(),
                role: Role::Mesh,
                triangles: 1,
                builds: vec![],
                traces: vec![],
                agreement: vec![],
                cpu: Default::default(),
            },
        };
        // The tree is right on ray 0 (the other misses); the other is wrong on ray 1 too.
        let reference = Answers::Closest(vec![hit, Found::default()]);
        let other = Answers::Closest(vec![Found::default(), hit]);
        b.agree(
            "X",
            Kind::Primary,
            &rays,
            &reference,
            &other,
            None,
            Some(&tris),
        );
        let occ_ref = Answers::Occluded(vec![true, false]);
        let occ_other = Answers::Occluded(vec![true, true]);
        b.agree(
            "X",
            Kind::Shadow,
            &rays,
            &occ_ref,
            &occ_other,
            None,
            Some(&tris),
        );
        let rows = b.out.agreement;
        assert_eq!((rows[0].compared, rows[0].disagreements), (2, 2));
        let want = Referee {
            checked: 2,
            kdtree_right: 2,
            other_right: 0,
        };
        assert_eq!(rows[0].referee, Some(want));
        assert!(!rows[0].ok());
        assert_eq!((rows[1].compared, rows[1].disagreements), (2, 1));
        let want = Referee {
            checked: 1,
            kdtree_right: 1,
            other_right: 0,
        };
        assert_eq!(rows[1].referee, Some(want));
        assert!(rows[1].examples[0].contains("kdtree miss, X occluded"));
    }

    #[test]
    fn subset_indices_spread() {
        assert_eq!(subset_indices(10, 20), (0..10).collect::<Vec<_>>());
        assert_eq!(subset_indices(100, 4), vec![0, 25, 50, 75]);
    }

    #[test]
    fn utc_now_is_well_formed() {
        let s = utc_now();
        assert_eq!(s.len(), "2026-11-22 03:20 UTC".len(), "{s}");
        assert!(s.starts_with("20") && s.ends_with(" UTC"));
    }
}
