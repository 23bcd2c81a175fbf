//! raycast: answer a file of rays against a soup and its k-d tree (formats/RAYS.md).

use anyhow::{Context, Result};
use clap::Parser;
use formats::{rays, Hit, KdFile, Soup};
use kdtree::{Accel, Ray};
use rayon::prelude::*;
use std::path::PathBuf;
use std::time::Instant;

/// Trace a rays file against a soup + tree and write a hits file: per ray the closest hit
/// (t, triangle index in soup order, barycentrics u, v), or a miss (t = +inf,
/// prim = 0xFFFFFFFF). With --any-hit an occluded ray gets t = 0, prim = 0.
#[derive(Parser, Debug)]
#[command(name = "raycast", version)]
struct Cli {
    soup: PathBuf,
    kd: PathBuf,
    rays: PathBuf,
    /// Hits file to write.
    #[arg(short, long)]
    output: PathBuf,
    /// Occlusion queries (stop at the first blocker) instead of closest hits.
    #[arg(long)]
    any_hit: bool,
    /// Worker threads (default: all cores).
    #[arg(long)]
    threads: Option<usize>,
    /// Print one JSON object on stdout instead of a summary on stderr.
    #[arg(long)]
    json: bool,
}

fn run(cli: Cli) -> Result<()> {
    formats::threads::start(cli.threads).map_err(anyhow::Error::msg)?;
    let soup = Soup::read(&cli.soup)?;
    let kd = KdFile::read(&cli.kd)?;
    let accel = Accel::new(&soup, kd)
        .with_context(|| format!("{} does not fit {}", cli.kd.display(), cli.soup.display()))?;
    let input = rays::read_rays(&cli.rays)?;
    let start = Instant::now();
    let hits: Vec<Hit> = input
        .par_iter()
        .with_min_len(1024)
        .map(|r| {
            let ray = Ray::new(r.origin, r.dir, r.tmin, r.tmax);
            if cli.any_hit {
                if accel.occluded(&ray) {
                    Hit {
                        t: 0.0,
                        prim: 0,
                        u: 0.0,
                        v: 0.0,
                    }
                } else {
                    Hit::MISS
                }
            } else {
                accel.intersect(&ray).unwrap_or(Hit::MISS)
            }
        })
        .collect();
    let seconds = start.elapsed().as_secs_f64();
    rays::write_hits(&cli.output, &hits)?;
    let n_hits = hits.iter().filter(|h| !h.is_miss()).count();
    let mrays = input.len() as f64 / seconds.max(1e-9) / 1e6;
    if cli.json {
        let v = serde_json::json!({
            "rays": input.len(), "hits": n_hits, "seconds": seconds, "mrays_per_s": mrays,
        });
        println!("{v}");
    } else {
        eprintln!(
            "raycast: {} rays, {} hits{} in {:.3} s ({:.2} Mrays/s); wrote {}",
            input.len(),
            n_hits,
            if cli.any_hit { " (any-hit)" } else { "" },
            seconds,
            mrays,
            cli.output.display()
        );
    }
    Ok(())
}

fn main() {
    let cli = Cli::parse();
    if let Err(e) = run(cli) {
        eprintln!("raycast: {e:#}");
        std::process::exit(1);
    }
}
