//! kdbench: the k-d tree side by side with brute force and (feature `embree`) Embree 3.
//!
//! ```text
//! kdbench [--baseline out/baseline.soup] [--meshes DIR] [--out reports/bench.md] [--quick]
//!         [--packet 4|8|16]
//! ```

use anyhow::{Context, Result};
use bench::{report, run, Config};
use clap::builder::TypedValueParser;
use clap::Parser;
use std::path::PathBuf;

#[derive(Parser)]
#[command(about = "Benchmark the k-d tree build and traversal against brute force and Embree")]
struct Args {
    /// Baseline soup (from unity2soup); skipped with a message when absent.
    #[arg(long)]
    baseline: Option<PathBuf>,
    /// Folder of OBJ meshes [default: ../shared/corpus/meshes next to the repo].
    #[arg(long)]
    meshes: Option<PathBuf>,
    /// Skip the real meshes.
    #[arg(long)]
    no_meshes: bool,
    /// Triangles in the generated scene (0: none).
    #[arg(long, default_value_t = 5_100_000)]
    generated: usize,
    /// Primary rays: an N×N camera.
    #[arg(long, default_value_t = 512)]
    image: u32,
    /// Number of random rays.
    #[arg(long, default_value_t = 262_144)]
    random_rays: usize,
    /// Rays per packet in the ×N columns: 4, 8 or 16 (Embree's `rtcIntersect4/8/16`; the
    /// k-d tree traces 8 or 16 as two or four packets of 4).
    #[arg(long, default_value_t = 4, value_parser = clap::builder::PossibleValuesParser::new(["4", "8", "16"]).map(packet_size))]
    packet: usize,
    /// Timed runs per measurement (the median is reported).
    #[arg(long, default_value_t = 3)]
    runs: usize,
    /// Write the markdown report here too (atomically).
    #[arg(long)]
    out: Option<PathBuf>,
    /// A line for the report's header (repeatable), e.g. "kdtree at commit 1c08420".
    #[arg(long)]
    note: Vec<String>,
    /// Smoke test: one small generated scene and few rays; finishes in seconds.
    #[arg(long)]
    quick: bool,
    /// Embree build quality: low, medium or high.
    #[cfg(feature = "embree")]
    #[arg(long, default_value = "high", value_parser = ["low", "medium", "high"])]
    embree_quality: String,
}

/// A `--packet` value clap has already checked to be 4, 8 or 16.
fn packet_size(s: String) -> usize {
    match s.as_str() {
        "8" => 8,
        "16" => 16,
        _ => 4,
    }
}

/// The corpus meshes next to the repository (`<repo>/../shared/corpus/meshes`).
fn default_meshes() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/corpus/meshes")
}

fn main() {
    let args = Args::parse();
    if let Err(e) = real_main(args) {
        eprintln!("kdbench: {e:#}");
        std::process::exit(1);
    }
}

fn real_main(args: Args) -> Result<()> {
    let mut cfg = if args.quick {
        Config::quick()
    } else {
        Config {
            baseline: args.baseline.clone(),
            meshes: if args.no_meshes {
                None
            } else {
                Some(args.meshes.clone().unwrap_or_else(default_meshes))
            },
            generated: args.generated,
            image: args.image,
            random_rays: args.random_rays,
            packet: args.packet,
            runs: args.runs,
            ..Config::full()
        }
    };
    #[cfg(feature = "embree")]
    {
        use bench::embree::Quality;
        cfg.embree_quality = match args.embree_quality.as_str() {
            "low" => Quality::Low,
            "medium" => Quality::Medium,
            _ => Quality::High,
        };
    }
    cfg.command = std::env::args().collect::<Vec<_>>().join(" ");
    cfg.remarks = args.note.clone();
    let report = run(&cfg, &mut |line| eprintln!("{line}"))?;
    let md = report::markdown(&report);
    print!("{md}");
    if let Some(path) = &args.out {
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir)
                .with_context(|| format!("cannot create the folder {}", dir.display()))?;
        }
        formats::write_atomic(path, md.as_bytes())
            .with_context(|| format!("cannot write the report {}", path.display()))?;
        eprintln!("report written to {}", path.display());
    }
    if !report.all_agree() {
        anyhow::bail!(
            "the contenders disagree on more than 0.01% of rays (see the agreement table)"
        );
    }
    Ok(())
}
