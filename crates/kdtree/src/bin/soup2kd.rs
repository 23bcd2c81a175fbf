//! soup2kd: compile a soup's triangles into a SAH k-d tree, optionally through a cache.

use anyhow::{bail, Context, Result};
use clap::{CommandFactory, Parser};
use formats::{envelope::Checked, BuildParams, KdFile, Soup, TreeStats};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Compile a soup's geometry into a k-d tree (.kd). The tree depends only on the triangle
/// positions and the build parameters, so a cache folder lets renders reuse it.
#[derive(Parser, Debug)]
#[command(name = "soup2kd", version)]
struct Cli {
    /// The soup to compile (from unity2soup).
    soup: Option<PathBuf>,
    /// Write the tree to this file.
    #[arg(short, long, conflicts_with = "cache")]
    output: Option<PathBuf>,
    /// Cache folder: reuse `DIR/<geometry hash>-<params hash>.kd` when valid, else build it.
    #[arg(long, value_name = "DIR")]
    cache: Option<PathBuf>,
    /// Print one JSON object on stdout instead of a summary on stderr.
    #[arg(long)]
    json: bool,
    /// SAH cost of one traversal step (relative to --intersect-cost; see docs/PERFORMANCE.md
    /// for the sweep behind the default).
    #[arg(long, default_value_t = BuildParams::default().traversal_cost)]
    traversal_cost: f32,
    /// SAH cost of one ray/triangle test.
    #[arg(long, default_value_t = BuildParams::default().intersect_cost)]
    intersect_cost: f32,
    /// Fraction of the cost forgiven for splits that cut off empty space (0–1).
    #[arg(long, default_value_t = BuildParams::default().empty_bonus)]
    empty_bonus: f32,
    /// Depth bound (0: 8 + 1.3·log2 N; at most 60).
    #[arg(long, default_value_t = BuildParams::default().max_depth)]
    max_depth: u32,
    /// Make a leaf at or below this many triangles.
    #[arg(long, default_value_t = BuildParams::default().leaf_size)]
    leaf_size: u32,
    /// Worker threads (default: all cores).
    #[arg(long)]
    threads: Option<usize>,
    /// Print the statistics of an existing tree and exit.
    #[arg(long, value_name = "FILE.kd", conflicts_with_all = ["soup", "output", "cache"])]
    stats: Option<PathBuf>,
}

fn usage_error(msg: &str) -> ! {
    Cli::command()
        .error(clap::error::ErrorKind::MissingRequiredArgument, msg)
        .exit()
}

fn params(cli: &Cli) -> Result<BuildParams> {
    let p = BuildParams {
        traversal_cost: cli.traversal_cost,
        intersect_cost: cli.intersect_cost,
        empty_bonus: cli.empty_bonus,
        max_depth: cli.max_depth,
        leaf_size: cli.leaf_size,
    };
    if !(p.traversal_cost >= 0.0 && p.traversal_cost.is_finite()) {
        bail!("--traversal-cost must be a finite number ≥ 0");
    }
    if !(p.intersect_cost > 0.0 && p.intersect_cost.is_finite()) {
        bail!("--intersect-cost must be a finite number > 0");
    }
    if !(0.0..=1.0).contains(&p.empty_bonus) {
        bail!("--empty-bonus must be between 0 and 1");
    }
    if p.max_depth > kdtree::build::MAX_DEPTH_LIMIT {
        bail!(
            "--max-depth {} is above the traversal's limit of {}",
            p.max_depth,
            kdtree::build::MAX_DEPTH_LIMIT
        );
    }
    if p.leaf_size == 0 {
        bail!("--leaf-size must be at least 1");
    }
    Ok(p)
}

/// Bytes a query structure holds per input triangle: 8-byte nodes, 4-byte leaf
/// references and 36 bytes of vertices per triangle (see `Accel::memory_bytes`).
fn bytes_per_triangle(s: &TreeStats) -> f64 {
    kdtree::query_bytes(s) as f64 / s.triangles.max(1) as f64
}

fn print_stats(path: &Path, json: bool) -> Result<()> {
    let kd = KdFile::read(path)?;
    let s = &kd.stats;
    let full = s.leaves - s.empty_leaves;
    let per_leaf = s.references as f64 / full.max(1) as f64;
    let refs = s.references as f64 / s.triangles.max(1) as f64;
    if json {
        let v = serde_json::json!({
            "path": path.display().to_string(),
            "geometry_hash": formats::hex(&kd.geometry_hash),
            "triangles": s.triangles, "nodes": s.nodes, "leaves": s.leaves,
            "empty_leaves": s.empty_leaves, "max_depth": s.max_depth,
            "references": s.references, "references_per_triangle": refs,
            "triangles_per_leaf": per_leaf, "max_leaf_triangles": s.max_leaf_triangles,
            "sah_cost": s.sah_cost, "build_seconds": s.build_seconds,
            "bytes_per_triangle": bytes_per_triangle(&kd.stats),
            "params": {
                "traversal_cost": kd.params.traversal_cost,
                "intersect_cost": kd.params.intersect_cost,
                "empty_bonus": kd.params.empty_bonus,
                "max_depth": kd.params.max_depth,
                "leaf_size": kd.params.leaf_size,
            },
        });
        println!("{v}");
    } else {
        println!("{}", path.display());
        println!("  geometry hash        {}", formats::hex(&kd.geometry_hash));
        println!("  triangles            {}", s.triangles);
        println!("  nodes                {}", s.nodes);
        println!(
            "  leaves               {} ({} empty)",
            s.leaves, s.empty_leaves
        );
        println!("  max depth            {}", s.max_depth);
        println!(
            "  triangles per leaf   {per_leaf:.2} (non-empty leaves; max {})",
            s.max_leaf_triangles
        );
        println!("  references/triangle  {refs:.3}");
        println!("  SAH cost             {:.3}", s.sah_cost);
        println!("  build time           {:.3} s", s.build_seconds);
        println!(
            "  bytes per triangle   {:.1} (nodes + leaf lists + vertices)",
            bytes_per_triangle(&kd.stats)
        );
        println!(
            "  params               traversal {} intersect {} empty bonus {} max depth {} leaf size {}",
            kd.params.traversal_cost,
            kd.params.intersect_cost,
            kd.params.empty_bonus,
            kd.params.max_depth,
            kd.params.leaf_size
        );
    }
    Ok(())
}

fn run(cli: Cli) -> Result<()> {
    formats::threads::start(cli.threads).map_err(anyhow::Error::msg)?;
    if let Some(path) = &cli.stats {
        return print_stats(path, cli.json);
    }
    let Some(soup_path) = &cli.soup else {
        usage_error("a soup file (or --stats FILE.kd) is required");
    };
    if cli.output.is_none() && cli.cache.is_none() {
        usage_error("say where the tree goes: -o FILE.kd or --cache DIR");
    }
    let params = params(&cli)?;
    let start = Instant::now();
    // The soup's checksum is verified once, over the whole file; only what is used is
    // decoded from it.
    let file = Checked::<Soup>::open(soup_path)?;
    let (path, cache) = match (&cli.output, &cli.cache) {
        (Some(out), _) => (out.clone(), "none"),
        (None, Some(dir)) => {
            std::fs::create_dir_all(dir)
                .with_context(|| format!("cannot create cache folder {}", dir.display()))?;
            // A hit reads only what names and matches the tree; both files' checksums are
            // verified, and the renderer checks the rest when it loads them.
            let key = file.key()?;
            let path = dir.join(params.cache_name(&key.geometry_hash));
            let cached = path
                .exists()
                .then(|| KdFile::read_header(&path).ok())
                .flatten();
            if let Some(h) =
                cached.filter(|h| h.geometry_hash == key.geometry_hash && h.params == params)
            {
                return report(&cli, key.triangles, &h.stats, &path, "hit", start);
            }
            (path, "miss")
        }
        (None, None) => unreachable!("checked above"),
    };
    // The build reads only the soup's geometry, and only the corners once they are
    // gathered.
    let soup = file.geometry()?;
    drop(file);
    let (count, geometry_hash) = (soup.triangles.len(), soup.geometry_hash);
    if count >= kdtree::MAX_TRIANGLES {
        bail!(
            "{}: {count} triangles; a tree holds fewer than {} (30-bit indices in nodes and build events)",
            soup_path.display(),
            kdtree::MAX_TRIANGLES
        );
    }
    let corners = soup.triangle_positions();
    drop(soup);
    let kd = kdtree::build(&corners, &params, geometry_hash);
    drop(corners);
    // Atomic (temp file + rename): concurrent builders of one cache entry both succeed.
    kd.write(&path)?;
    report(&cli, count, &kd.stats, &path, cache, start)
}

fn report(
    cli: &Cli,
    triangles: usize,
    s: &TreeStats,
    path: &Path,
    cache: &str,
    start: Instant,
) -> Result<()> {
    let seconds = start.elapsed().as_secs_f64();
    if cli.json {
        let v = serde_json::json!({
            "triangles": triangles, "nodes": s.nodes, "leaves": s.leaves,
            "max_depth": s.max_depth, "sah_cost": s.sah_cost, "seconds": seconds,
            "build_seconds": if cache == "hit" { 0.0 } else { s.build_seconds },
            "bytes_per_triangle": bytes_per_triangle(s),
            "cache": cache, "path": path.display().to_string(),
        });
        println!("{v}");
    } else if cache == "hit" {
        eprintln!("cache hit: {}", path.display());
    } else {
        eprintln!(
            "soup2kd: {} triangles -> {} nodes, {} leaves ({} empty), depth {}, {:.2} refs/triangle, SAH {:.2}, {:.1} bytes/triangle; built in {:.3} s{}",
            triangles,
            s.nodes,
            s.leaves,
            s.empty_leaves,
            s.max_depth,
            s.references as f64 / s.triangles.max(1) as f64,
            s.sah_cost,
            bytes_per_triangle(s),
            s.build_seconds,
            if cache == "miss" { " (cache miss)" } else { "" }
        );
        eprintln!("wrote {}", path.display());
    }
    Ok(())
}

fn main() {
    let cli = Cli::parse();
    if let Err(e) = run(cli) {
        eprintln!("soup2kd: {e:#}");
        std::process::exit(1);
    }
}
