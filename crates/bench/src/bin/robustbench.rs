//! robustbench: build and traversal benchmarks, written as a markdown table.
//!
//! Per scene: SAH build time (1 and 2 threads), triangles/s, SAH cost, bytes/triangle;
//! Mrays/s of primary, shadow and random rays for the SAH tree, a median-split tree and
//! brute force (on a sample of rays), 1 thread. Then the robustness cost: watertight
//! test + robust traversal against plain Möller–Trumbore + unpadded traversal, with the
//! number of rays that leak out of closed meshes (the textbook variant is
//! [`bench::plain`]).

use anyhow::{Context, Result};
use bench::measure::pool;
use bench::plain::PlainAccel;
use bench::scenes::{self, bounds};
use clap::Parser;
use formats::BuildParams;
use glam::Vec3;
use kdtree::testkit::{self, brute, rays_inside, Rng};
use kdtree::{Accel, Ray};
use rayon::prelude::*;
use std::fmt::Write as _;
use std::path::PathBuf;
use std::time::Instant;

#[derive(Parser, Debug)]
#[command(name = "robustbench")]
struct Cli {
    /// Markdown report to write (default: stdout).
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Folder of real meshes (*.obj); default ../shared/corpus/meshes next to the repo.
    #[arg(long)]
    meshes: Option<PathBuf>,
    /// Also build a generated scene of about this many triangles (e.g. 5000000).
    #[arg(long)]
    large: Option<usize>,
    /// Rays per kind (primary rays are a square image of about this many pixels).
    #[arg(long, default_value_t = 262_144)]
    rays: usize,
    /// Rays per watertightness scene.
    #[arg(long, default_value_t = 1_000_000)]
    leak_rays: usize,
    /// Only these scenes (substring match on the name).
    #[arg(long)]
    only: Option<String>,
    #[arg(long)]
    empty_bonus: Option<f32>,
}

struct Rays {
    primary: Vec<Ray>,
    shadow: Vec<Ray>,
    random: Vec<Ray>,
}

fn make_rays(accel: &Accel, tris: &[[Vec3; 3]], n: usize) -> Rays {
    let [lo, hi] = bounds(tris);
    let c = 0.5 * (lo + hi);
    let r = 0.5 * (hi - lo).length();
    let eye = c + Vec3::new(0.3, 0.4, 1.0).normalize() * 2.2 * r;
    let fwd = (c - eye).normalize();
    let right = fwd.cross(Vec3::Y).normalize();
    let up = right.cross(fwd);
    let side = (n as f64).sqrt() as usize;
    let tan = (22.5f32).to_radians().tan();
    let mut primary = Vec::with_capacity(side * side);
    for y in 0..side {
        for x in 0..side {
            let sx = (2.0 * (x as f32 + 0.5) / side as f32 - 1.0) * tan;
            let sy = (1.0 - 2.0 * (y as f32 + 0.5) / side as f32) * tan;
            primary.push(Ray::new(
                eye,
                fwd + sx * right + sy * up,
                0.0,
                f32::INFINITY,
            ));
        }
    }
    let light = c + Vec3::new(1.0, 2.0, 0.5) * r;
    let shadow: Vec<Ray> = primary
        .par_iter()
        .filter_map(|ray| {
            let h = accel.intersect(ray)?;
            let p = ray.origin + h.t * ray.dir;
            Some(Ray::new(p, light - p, 1e-4, 0.9999))
        })
        .collect();
    let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
    let random = (0..n)
        .map(|_| {
            let o = Vec3::new(
                rng.range(lo.x, hi.x),
                rng.range(lo.y, hi.y),
                rng.range(lo.z, hi.z),
            );
            Ray::new(o, rng.dir(), 0.0, f32::INFINITY)
        })
        .collect();
    Rays {
        primary,
        shadow,
        random,
    }
}

/// Mrays/s of `f` over `rays` on the calling thread.
fn mrays<F: Fn(&Ray) -> bool>(rays: &[Ray], f: F) -> f64 {
    if rays.is_empty() {
        return 0.0;
    }
    let start = Instant::now();
    let mut n = 0usize;
    for r in rays {
        n += f(r) as usize;
    }
    std::hint::black_box(n);
    rays.len() as f64 / start.elapsed().as_secs_f64() / 1e6
}

fn bench_scene(
    name: &str,
    tris: &[[Vec3; 3]],
    cli: &Cli,
    params: &BuildParams,
    out: &mut String,
) -> Result<()> {
    eprintln!("robustbench: {name}: {} triangles", tris.len());
    let hash = formats::soup::geometry_hash(tris);
    let (one, two) = (pool(1)?, pool(2)?);
    let kd1 = one.install(|| kdtree::build(tris, params, hash));
    let kd2 = two.install(|| kdtree::build(tris, params, hash));
    let kdm = kdtree::build_median(tris, params, hash);
    let sah = Accel::from_triangles(tris, &kd2)?;
    let med = Accel::from_triangles(tris, &kdm)?;
    eprintln!("  SAH tree: {:?}", kd2.stats);
    eprintln!("  median tree: {:?}", kdm.stats);
    let rays = make_rays(&sah, tris, cli.rays);
    let brute_sample = (200_000_000 / tris.len().max(1)).clamp(50, 20_000);
    let mut row = format!(
        "| {name} | {} | {:.3} | {:.3} | {:.2}× | {:.2} | {:.2} | {:.2} | {:.1} |",
        tris.len(),
        kd1.stats.build_seconds,
        kd2.stats.build_seconds,
        kd1.stats.build_seconds / kd2.stats.build_seconds,
        tris.len() as f64 / kd2.stats.build_seconds / 1e6,
        kd2.stats.sah_cost,
        kdm.stats.sah_cost,
        sah.bytes_per_triangle(),
    );
    for (kind, rs) in [
        ("primary", &rays.primary),
        ("shadow", &rays.shadow),
        ("random", &rays.random),
    ] {
        let any = kind == "shadow";
        let q = |a: &Accel, r: &Ray| {
            if any {
                a.occluded(r)
            } else {
                a.intersect(r).is_some()
            }
        };
        let m_sah = mrays(rs, |r| q(&sah, r));
        let m_med = mrays(rs, |r| q(&med, r));
        let sample = &rs[..rs.len().min(brute_sample)];
        let m_brute = mrays(sample, |r| brute::intersect(tris, r).is_some());
        let m2 = two.install(|| {
            let start = Instant::now();
            let n: usize = rs.par_iter().map(|r| q(&sah, r) as usize).sum();
            std::hint::black_box(n);
            rs.len() as f64 / start.elapsed().as_secs_f64() / 1e6
        });
        write!(row, " {m_sah:.2} / {m2:.2} / {m_med:.2} / {m_brute:.4} |").unwrap();
        eprintln!("  {kind}: {} rays, SAH {m_sah:.2} Mrays/s (2 threads {m2:.2}), median {m_med:.2}, brute {m_brute:.4}", rs.len());
    }
    out.push_str(&row);
    out.push('\n');
    Ok(())
}

fn leak_scene(
    name: &str,
    tris: &[[Vec3; 3]],
    center: Vec3,
    scale: f32,
    n: usize,
    out: &mut String,
) -> Result<()> {
    let kd = kdtree::build(
        tris,
        &BuildParams::default(),
        formats::soup::geometry_hash(tris),
    );
    let accel = Accel::from_triangles(tris, &kd)?;
    let textbook = PlainAccel::new(tris, &kd).map_err(anyhow::Error::msg)?;
    let rays: Vec<Ray> = rays_inside(&mut Rng(12345), center, scale)
        .take(n)
        .collect();
    let leaks = |f: &dyn Fn(&Ray) -> bool| rays.iter().filter(|r| !f(r)).count();
    let wt = mrays(&rays, |r| accel.intersect(r).is_some());
    let plain = mrays(&rays, |r| textbook.intersect(r).is_some());
    let lw = leaks(&|r| accel.intersect(r).is_some());
    let lp = leaks(&|r| textbook.intersect(r).is_some());
    eprintln!(
        "robustbench: leaks {name}: watertight {lw} ({wt:.2} Mrays/s), plain {lp} ({plain:.2} Mrays/s)"
    );
    writeln!(
        out,
        "| {name} | {} | {n} | {wt:.2} | {lw} | {plain:.2} | {lp} |",
        tris.len()
    )
    .unwrap();
    Ok(())
}

fn run(cli: Cli) -> Result<()> {
    let mut params = BuildParams::default();
    if let Some(b) = cli.empty_bonus {
        params.empty_bonus = b;
    }
    let want = |name: &str| cli.only.as_ref().is_none_or(|o| name.contains(o.as_str()));
    let mut out = String::new();
    writeln!(out, "## k-d tree build and traversal (robustbench)\n").unwrap();
    writeln!(out, "Build parameters: {params:?}. Mrays/s columns: SAH 1 thread / SAH 2 threads / median-split 1 thread / brute force 1 thread (on a sample).\n").unwrap();
    writeln!(out, "| scene | triangles | build 1T s | build 2T s | speedup | Mtris/s (2T) | SAH cost | median SAH cost | bytes/tri | primary | shadow | random |").unwrap();
    writeln!(out, "|---|---|---|---|---|---|---|---|---|---|---|---|").unwrap();
    let mut meshes_out: Vec<(String, Vec<[Vec3; 3]>)> = Vec::new();
    // Generated: scattered spheres on a floor, roughly the baseline scene's size.
    let mut rng = Rng(42);
    let mut spheres = testkit::grid(40, 40.0, 0.0);
    for _ in 0..14 {
        let c = Vec3::new(
            rng.range(2.0, 38.0),
            rng.range(1.0, 4.0),
            rng.range(2.0, 38.0),
        );
        spheres.extend(testkit::sphere(c, rng.range(0.5, 3.0), 40, 80));
    }
    meshes_out.push(("generated spheres".into(), spheres));
    let meshes = cli.meshes.clone().unwrap_or_else(|| {
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/corpus/meshes")
    });
    if meshes.is_dir() {
        for f in scenes::obj_files(&meshes)? {
            let name = f
                .file_stem()
                .unwrap_or_default()
                .to_string_lossy()
                .into_owned();
            if want(&name) {
                let scene = scenes::load_obj(&f)?;
                for note in &scene.notes {
                    eprintln!("robustbench: {note}");
                }
                meshes_out.push((name, scene.triangles));
            }
        }
    } else {
        eprintln!(
            "robustbench: SKIPPED real meshes because {} is absent",
            meshes.display()
        );
    }
    if let Some(n) = cli.large {
        let per = 80 * 160 * 2;
        let mut tris = Vec::with_capacity(n);
        let side = ((n / per) as f32).cbrt().ceil().max(1.0);
        while tris.len() < n {
            let c = Vec3::new(
                rng.range(0.0, 10.0 * side),
                rng.range(0.0, 10.0 * side),
                rng.range(0.0, 10.0 * side),
            );
            tris.extend(testkit::sphere(c, rng.range(1.0, 6.0), 80, 160));
        }
        meshes_out.push((format!("generated {}M", tris.len() / 1_000_000), tris));
    }
    for (name, tris) in &meshes_out {
        if want(name) {
            bench_scene(name, tris, &cli, &params, &mut out)?;
        }
    }
    writeln!(out, "\n## Robustness cost: watertight + robust traversal vs Möller–Trumbore + textbook traversal\n").unwrap();
    writeln!(
        out,
        "Rays start at random points inside a closed mesh; a miss is a leak.\n"
    )
    .unwrap();
    writeln!(out, "| closed mesh | triangles | rays | watertight Mrays/s | watertight leaks | plain Mrays/s | plain leaks |").unwrap();
    writeln!(out, "|---|---|---|---|---|---|---|").unwrap();
    for (name, scale, center) in [
        ("sphere, scale 1", 1.0f32, Vec3::ZERO),
        ("sphere, scale 1e-3", 1e-3, Vec3::ZERO),
        ("sphere, scale 1e5", 1e5, Vec3::ZERO),
        ("sphere, offset 1e5", 1.0, Vec3::splat(1e5)),
    ] {
        let tris = testkit::sphere(center, scale, 48, 96);
        leak_scene(name, &tris, center, scale, cli.leak_rays, &mut out)?;
        let b = testkit::grid_box(center, 0.5 * scale, 12);
        leak_scene(
            &name.replace("sphere", "box"),
            &b,
            center,
            scale,
            cli.leak_rays,
            &mut out,
        )?;
    }
    let spot = meshes.join("spot.obj");
    if spot.exists() {
        let tris = scenes::load_obj(&spot)?.triangles;
        let [lo, hi] = bounds(&tris);
        // The body's centre is inside spot (a cow); start rays within a small ball there.
        leak_scene(
            "spot.obj",
            &tris,
            0.5 * (lo + hi),
            0.1 * (hi - lo).min_element(),
            cli.leak_rays,
            &mut out,
        )?;
    }
    match &cli.output {
        Some(p) => formats::write_atomic(p, out.as_bytes())
            .with_context(|| format!("writing {}", p.display()))?,
        None => print!("{out}"),
    }
    Ok(())
}

fn main() {
    let cli = Cli::parse();
    if let Err(e) = run(cli) {
        eprintln!("robustbench: {e:#}");
        std::process::exit(1);
    }
}
