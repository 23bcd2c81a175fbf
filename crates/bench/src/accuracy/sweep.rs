//! The measurements: one converged reference per scene, then each knob swept alone from
//! the renderer's defaults, every point timed (median of several runs) and compared with
//! the reference.

use super::metrics::{compare, Errors};
use super::scenes::Scene;
use anyhow::{Context, Result};
use formats::{BuildParams, KdFile};
use glam::Vec3;
use kdtree::Accel;
use render::{Plan, RayCounts, RenderOptions, TextureFilter};
use std::time::Instant;

/// What to measure.
#[derive(Clone, Debug)]
pub struct Config {
    pub width: u32,
    pub height: u32,
    /// Timed runs per point; the median is reported.
    pub runs: usize,
    pub reference_spp: u32,
    pub reference_depth: u32,
    pub reference_soft: u32,
    pub spp: Vec<u32>,
    pub depth: Vec<u32>,
    pub cutoff: Vec<f32>,
    pub soft: Vec<u32>,
    /// Texture filters, swept on scenes whose plan reads textures.
    pub texture_filter: Vec<TextureFilter>,
    /// Worker threads (None: one per core).
    pub threads: Option<usize>,
}

impl Default for Config {
    fn default() -> Self {
        Config {
            width: 160,
            height: 120,
            runs: 3,
            reference_spp: 256,
            reference_depth: 8,
            reference_soft: 64,
            spp: vec![1, 2, 4, 8, 16, 64],
            depth: (0..=8).collect(),
            cutoff: vec![0.1, 0.03, 0.01, 0.004, 0.001, 0.0],
            soft: vec![1, 2, 4, 8, 16, 32, 64],
            texture_filter: TextureFilter::ALL.to_vec(),
            threads: None,
        }
    }
}

/// The renderer's own defaults at the sweep's image size: the starting point of every
/// sweep.
pub fn defaults(cfg: &Config) -> RenderOptions {
    RenderOptions {
        width: cfg.width,
        height: cfg.height,
        threads: cfg.threads,
        ..RenderOptions::default()
    }
}

/// The converged reference's options: many samples, deep mirrors, no cut-off, textures
/// read bilinearly at full size (the samples integrate the texture over each pixel, with
/// no mip level's blur and no point lookup's steps). Its seed differs from the sweep's so
/// no point shares its noise with the reference.
pub fn reference_options(cfg: &Config) -> RenderOptions {
    RenderOptions {
        spp: cfg.reference_spp,
        depth: cfg.reference_depth,
        soft_samples: cfg.reference_soft,
        soft_probe: false,
        cutoff: 0.0,
        seed: 0x0005_eed0_f4ef,
        texture_filter: TextureFilter::Bilinear,
        ..defaults(cfg)
    }
}

/// One measured point of one sweep.
#[derive(Clone, Debug)]
pub struct Point {
    pub scene: String,
    /// `spp`, `depth`, `cutoff`, `soft`, `probe`, `texture`, `tree`.
    pub knob: &'static str,
    pub value: String,
    /// Whether this point is the renderer's default setting of the knob.
    pub is_default: bool,
    /// Median render wall time over the runs (tracing only, tree prebuilt).
    pub seconds: f64,
    pub rays: RayCounts,
    pub errors: Errors,
    /// For the bias knobs (depth, cut-off, soft samples): RMSE against the sweep's most
    /// accurate setting rendered with the same seed, so the 1-spp noise they share cancels
    /// and only what the knob changes is left.
    pub bias: Option<f64>,
    /// Tree build time, for the `tree` knob only.
    pub build_seconds: Option<f64>,
}

/// Robust (watertight, padded) against plain Möller–Trumbore traversal on the primary
/// rays of the reference image. The renderer always uses the robust one, so this is
/// measured on kdtree's own API.
#[derive(Clone, Debug)]
pub struct Intersector {
    pub scene: String,
    pub rays: usize,
    pub robust_seconds: f64,
    pub plain_seconds: f64,
    /// Rays whose hit (triangle, or hit vs miss) differs between the two.
    pub disagreements: usize,
}

/// Everything measured on one scene.
#[derive(Clone, Debug)]
pub struct SceneResult {
    pub scene: String,
    pub triangles: usize,
    pub reference_seconds: f64,
    pub reference_rays: RayCounts,
    pub points: Vec<Point>,
    pub intersector: Intersector,
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    v[v.len() / 2]
}

fn sah_tree(scene: &Scene) -> (KdFile, f64) {
    let t = Instant::now();
    let kd = kdtree::build(
        &scene.soup.triangle_positions(),
        &BuildParams::default(),
        scene.soup.geometry_hash,
    );
    (kd, t.elapsed().as_secs_f64())
}

fn median_tree(scene: &Scene) -> (KdFile, f64) {
    let t = Instant::now();
    let kd = kdtree::build_median(
        &scene.soup.triangle_positions(),
        &BuildParams::default(),
        scene.soup.geometry_hash,
    );
    (kd, t.elapsed().as_secs_f64())
}

/// Render once, returning the colour and the result's counts and seconds.
pub fn render_once(
    scene: &Scene,
    accel: &Accel,
    opts: &RenderOptions,
) -> Result<(Vec<Vec3>, RayCounts, f64)> {
    let plan = Plan::derive(&scene.soup, opts);
    let out = render::render(&scene.soup, accel, &plan, opts, None)
        .with_context(|| format!("scene {}: render failed", scene.name))?;
    Ok((out.frame.color, out.counts, out.seconds))
}

/// Render `runs` times; the image of the first run and the median time.
fn timed(
    scene: &Scene,
    accel: &Accel,
    opts: &RenderOptions,
    runs: usize,
) -> Result<(Vec<Vec3>, RayCounts, f64)> {
    let (img, counts, first) = render_once(scene, accel, opts)?;
    let mut times = vec![first];
    for _ in 1..runs.max(1) {
        times.push(render_once(scene, accel, opts)?.2);
    }
    Ok((img, counts, median(times)))
}

/// Render the reference of `scene` (one run).
pub fn reference(
    scene: &Scene,
    accel: &Accel,
    cfg: &Config,
) -> Result<(Vec<Vec3>, RayCounts, f64)> {
    render_once(scene, accel, &reference_options(cfg))
}

/// Measure one scene. `log` receives one line per finished point.
pub fn measure(scene: &Scene, cfg: &Config, log: &dyn Fn(&str)) -> Result<SceneResult> {
    let (kd, sah_build) = sah_tree(scene);
    let accel = Accel::new(&scene.soup, kd.clone())
        .with_context(|| format!("scene {}: SAH tree does not fit", scene.name))?;
    let (w, h) = (cfg.width as usize, cfg.height as usize);
    let (reference, reference_rays, reference_seconds) = reference(scene, &accel, cfg)?;
    log(&format!(
        "{}: reference {:.1} s, {} rays",
        scene.name,
        reference_seconds,
        reference_rays.total()
    ));
    let base = defaults(cfg);
    let mut points = vec![];
    let mut point = |knob: &'static str,
                     value: String,
                     is_default: bool,
                     accel: &Accel,
                     opts: &RenderOptions,
                     build_seconds: Option<f64>,
                     anchor: Option<&[Vec3]>|
     -> Result<()> {
        let (img, rays, seconds) = timed(scene, accel, opts, cfg.runs)?;
        let errors = compare(&img, &reference, w, h);
        let bias = anchor.map(|a| compare(&img, a, w, h).rmse);
        log(&format!(
            "{}: {knob} = {value}: {seconds:.3} s, rmse {:.4}, 1-ssim {:.4}",
            scene.name,
            errors.rmse,
            errors.dssim()
        ));
        points.push(Point {
            scene: scene.name.clone(),
            knob,
            value,
            is_default,
            seconds,
            rays,
            errors,
            bias,
            build_seconds,
        });
        Ok(())
    };
    for &spp in &cfg.spp {
        let o = RenderOptions {
            spp,
            ..base.clone()
        };
        point(
            "spp",
            spp.to_string(),
            spp == base.spp,
            &accel,
            &o,
            None,
            None,
        )?;
    }
    // The bias knobs are compared with their own most accurate setting at the same seed.
    // The cut-off is swept at the reference depth: at depth 2 the depth bound ends every
    // path before any weight falls below the cut-off, so it could not show its effect.
    let depth_opts = |depth| RenderOptions {
        depth,
        ..base.clone()
    };
    let cutoff_opts = |cutoff| RenderOptions {
        cutoff,
        depth: cfg.reference_depth,
        ..base.clone()
    };
    // Soft samples are swept with every sample traced; the rim probe is the `probe` knob,
    // at the default sample count, against that count with every sample traced.
    let soft_opts = |soft_samples| RenderOptions {
        soft_samples,
        soft_probe: false,
        ..base.clone()
    };
    let anchor = |o: RenderOptions| render_once(scene, &accel, &o).map(|r| r.0);
    let a = anchor(depth_opts(cfg.reference_depth))?;
    for &depth in &cfg.depth {
        let o = depth_opts(depth);
        let d = depth == base.depth;
        point("depth", depth.to_string(), d, &accel, &o, None, Some(&a))?;
    }
    let a = anchor(cutoff_opts(0.0))?;
    for &cutoff in &cfg.cutoff {
        let o = cutoff_opts(cutoff);
        let d = cutoff == base.cutoff;
        point("cutoff", cutoff.to_string(), d, &accel, &o, None, Some(&a))?;
    }
    let a = anchor(soft_opts(cfg.reference_soft))?;
    for &soft in &cfg.soft {
        let o = soft_opts(soft);
        let d = soft == base.soft_samples;
        point("soft", soft.to_string(), d, &accel, &o, None, Some(&a))?;
    }
    let a = anchor(soft_opts(base.soft_samples))?;
    for soft_probe in [true, false] {
        let o = RenderOptions {
            soft_probe,
            ..base.clone()
        };
        let v = if soft_probe { "on" } else { "off" };
        let d = soft_probe == base.soft_probe;
        point("probe", v.into(), d, &accel, &o, None, Some(&a))?;
    }
    if Plan::derive(&scene.soup, &base).textures.enabled {
        for &f in &cfg.texture_filter {
            let o = RenderOptions {
                texture_filter: f,
                ..base.clone()
            };
            let d = f == base.texture_filter;
            point("texture", f.to_string(), d, &accel, &o, None, None)?;
        }
    }
    let b = Some(sah_build);
    point("tree", "SAH".into(), true, &accel, &base, b, None)?;
    let (mkd, median_build) = median_tree(scene);
    let maccel = Accel::new(&scene.soup, mkd)
        .with_context(|| format!("scene {}: median tree does not fit", scene.name))?;
    let b = Some(median_build);
    point("tree", "median".into(), false, &maccel, &base, b, None)?;
    let intersector = intersectors(scene, &accel, &kd, cfg)?;
    log(&format!(
        "{}: robust {:.3} s, plain {:.3} s, {} of {} rays disagree",
        scene.name,
        intersector.robust_seconds,
        intersector.plain_seconds,
        intersector.disagreements,
        intersector.rays
    ));
    Ok(SceneResult {
        scene: scene.name.clone(),
        triangles: scene.soup.triangles.len(),
        reference_seconds,
        reference_rays,
        points,
        intersector,
    })
}

/// Time closest-hit queries on 4 jittered primary rays per pixel with the robust and the
/// plain intersector (single thread, median of the runs) and count disagreements.
fn intersectors(
    scene: &Scene,
    accel: &Accel,
    kd: &formats::KdFile,
    cfg: &Config,
) -> Result<Intersector> {
    let plain = crate::plain::PlainAccel::new(&scene.soup.triangle_positions(), kd)
        .map_err(anyhow::Error::msg)
        .with_context(|| format!("scene {}: the textbook traversal", scene.name))?;
    let camera = render::CameraModel::new(&scene.soup.camera, cfg.width, cfg.height)
        .with_context(|| format!("scene {}: camera", scene.name))?;
    let mut rays = Vec::with_capacity((cfg.width * cfg.height * 4) as usize);
    for y in 0..cfg.height {
        for x in 0..cfg.width {
            for (sx, sy) in [(0.25, 0.25), (0.75, 0.25), (0.25, 0.75), (0.75, 0.75)] {
                rays.push(camera.ray(x as f32 + sx, y as f32 + sy));
            }
        }
    }
    let time = |f: &dyn Fn(&kdtree::Ray) -> Option<formats::Hit>| -> (f64, Vec<Option<u32>>) {
        let mut times = vec![];
        let mut hits = vec![];
        for _ in 0..cfg.runs.max(1) {
            let t = Instant::now();
            hits = rays.iter().map(|r| f(r).map(|h| h.prim)).collect();
            times.push(t.elapsed().as_secs_f64());
        }
        (median(times), hits)
    };
    let (robust_seconds, a) = time(&|r| accel.intersect(r));
    let (plain_seconds, b) = time(&|r| plain.intersect(r));
    Ok(Intersector {
        scene: scene.name.clone(),
        rays: rays.len(),
        robust_seconds,
        plain_seconds,
        disagreements: a.iter().zip(&b).filter(|(x, y)| x != y).count(),
    })
}
