//! `threads`: render speed-up from 1 to N threads on one scene, in one process.
//!
//! The scene is converted and its tree built once; then renders with 1 and N threads
//! alternate (so the machine's drift hits both alike) and the median of the per-pair
//! ratios is reported with its range. The time is `render`'s own (tiles, shading and
//! frame assembly; loading and writing excluded), as `kd2exr --json` reports it.

use anyhow::{ensure, Context, Result};
use bench::measure::median;
use clap::Parser;
use formats::BuildParams;
use kdtree::Accel;
use render::{Plan, RenderOptions};
use std::path::PathBuf;

#[derive(Parser)]
#[command(about = "Render speed-up from 1 to N threads, interleaved pairs in one process")]
struct Args {
    /// Unity scene to render.
    #[arg(default_value = "scenes/baseline/Assets/Scenes/Baseline.unity")]
    scene: PathBuf,
    #[arg(long, default_value_t = 1024)]
    width: u32,
    #[arg(long, default_value_t = 768)]
    height: u32,
    /// Threads of the parallel run (the other run uses 1).
    #[arg(long, default_value_t = 2)]
    threads: usize,
    /// Interleaved (1 thread, N threads) pairs.
    #[arg(long, default_value_t = 15)]
    pairs: usize,
}

fn main() {
    if let Err(e) = run() {
        eprintln!("threads: {e:#}");
        std::process::exit(1);
    }
}

fn run() -> Result<()> {
    let a = Args::parse();
    ensure!(a.pairs > 0, "--pairs must be at least 1");
    let soup = unity::convert(&a.scene, &unity::Options::default())
        .with_context(|| format!("{}: cannot convert the scene", a.scene.display()))?;
    let accel = Accel::build(&soup.triangle_positions(), &BuildParams::default());
    let opts = |threads| RenderOptions {
        width: a.width,
        height: a.height,
        threads: Some(threads),
        ..RenderOptions::default()
    };
    let plan = Plan::derive(&soup, &opts(1));
    let time = |threads| -> Result<f64> {
        Ok(render::render(&soup, &accel, &plan, &opts(threads), None)?.seconds)
    };
    time(a.threads)?; // warm-up: page in the tree and the frame
    let (mut one, mut many, mut ratio) = (vec![], vec![], vec![]);
    for _ in 0..a.pairs {
        let t1 = time(1)?;
        let tn = time(a.threads)?;
        one.push(t1);
        many.push(tn);
        ratio.push(t1 / tn);
    }
    let (lo, hi) = ratio
        .iter()
        .fold((f64::MAX, f64::MIN), |(l, h), &r| (l.min(r), h.max(r)));
    println!(
        "{}×{}, {} pairs: median 1 thread {:.3} s, {} threads {:.3} s; median speed-up {:.2}× (range {:.2}–{:.2})",
        a.width,
        a.height,
        a.pairs,
        median(one),
        a.threads,
        median(many),
        median(ratio),
        lo,
        hi
    );
    Ok(())
}
