//! `fbxload`: the FBX reader alone on every `.fbx` under the given folders (or files),
//! the files loaded in parallel as the converter loads a scene's models, each with the
//! import settings of its `.meta`.
//!
//! The files are read into memory before the clock starts, so the time is the reader's
//! (ufbx's parse and our conversion to Unity's meshes), not the disk's. Each run prints
//! one line; the best run is the last line, with the CPU time the runs took on average
//! (all threads, user and system, from `/proc/self/stat`): on a shared machine the wall
//! time depends on the load, the CPU time much less.

use anyhow::{bail, Context, Result};
use clap::Parser;
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use std::time::Instant;
use unity::meta::ModelMeta;

#[derive(Parser)]
#[command(about = "Time the FBX reader on every .fbx under the given folders")]
struct Args {
    /// Folders (searched recursively) or `.fbx` files.
    #[arg(required = true)]
    paths: Vec<PathBuf>,
    /// Timed runs; the best is reported last.
    #[arg(long, default_value_t = 5)]
    runs: usize,
    /// Print one line per file (triangles, milliseconds) after the runs.
    #[arg(long)]
    per_file: bool,
}

fn main() {
    if let Err(e) = run() {
        eprintln!("fbxload: {e:#}");
        std::process::exit(1);
    }
}

fn is_fbx(p: &Path) -> bool {
    p.extension()
        .is_some_and(|e| e.to_string_lossy().eq_ignore_ascii_case("fbx"))
}

fn collect(path: &Path, out: &mut Vec<PathBuf>) -> Result<()> {
    if path.is_file() {
        out.push(path.to_path_buf());
        return Ok(());
    }
    let entries = std::fs::read_dir(path).with_context(|| format!("{}", path.display()))?;
    for e in entries {
        let p = e?.path();
        if p.is_dir() {
            collect(&p, out)?;
        } else if is_fbx(&p) {
            out.push(p);
        }
    }
    Ok(())
}

/// User plus system time of the whole process so far (Linux; `None` elsewhere).
fn cpu_seconds() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    // Fields after the parenthesised command name; utime and stime are the 12th and
    // 13th of those, in clock ticks (100 per second on Linux).
    let rest = stat.rsplit_once(')')?.1;
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks: f64 = f.get(11)?.parse::<f64>().ok()? + f.get(12)?.parse::<f64>().ok()?;
    Some(ticks / 100.0)
}

struct Input {
    path: PathBuf,
    bytes: Vec<u8>,
    meta: ModelMeta,
}

fn run() -> Result<()> {
    let args = Args::parse();
    let mut files = Vec::new();
    for p in &args.paths {
        collect(p, &mut files)?;
    }
    files.sort();
    if files.is_empty() {
        bail!("no .fbx file under {:?}", args.paths);
    }
    let inputs: Vec<Input> = files
        .into_iter()
        .map(|path| {
            let bytes =
                std::fs::read(&path).with_context(|| format!("reading {}", path.display()))?;
            let meta = ModelMeta::read(&path);
            Ok(Input { path, bytes, meta })
        })
        .collect::<Result<_>>()?;
    let mb = inputs.iter().map(|i| i.bytes.len()).sum::<usize>() as f64 / 1e6;
    let mut best = f64::INFINITY;
    let mut summary = (0, 0, 0);
    let mut per_file = Vec::new();
    let runs = args.runs.max(1);
    let cpu_start = cpu_seconds();
    for run in 0..runs {
        let start = Instant::now();
        let results: Vec<(usize, usize, f64)> = inputs
            .par_iter()
            .map(|i| {
                let t = Instant::now();
                match unity::fbx::load_bytes(&i.bytes, &i.path, &i.meta) {
                    Ok(m) => (m.triangle_count(), 0, t.elapsed().as_secs_f64()),
                    Err(_) => (0, 1, t.elapsed().as_secs_f64()),
                }
            })
            .collect();
        let secs = start.elapsed().as_secs_f64();
        let tris: usize = results.iter().map(|r| r.0).sum();
        let failed: usize = results.iter().map(|r| r.1).sum();
        println!(
            "run {run}: {} files ({mb:.1} MB, {failed} unreadable), {tris} triangles, {secs:.4} s, {:.2} M tri/s",
            inputs.len(),
            tris as f64 / secs / 1e6
        );
        if secs < best {
            best = secs;
            summary = (inputs.len(), tris, failed);
            per_file = results;
        }
    }
    let cpu = cpu_seconds()
        .zip(cpu_start)
        .map(|(b, a)| (b - a) / runs as f64);
    let (n, tris, failed) = summary;
    println!(
        "best: {n} files ({mb:.1} MB, {failed} unreadable), {tris} triangles, {best:.4} s, {:.2} M tri/s, {} threads{}",
        tris as f64 / best / 1e6,
        rayon::current_num_threads(),
        match cpu {
            Some(c) => format!(", {c:.4} CPU s per run ({:.2} M tri per CPU s)", tris as f64 / c / 1e6),
            None => String::new(),
        }
    );
    if args.per_file {
        for (i, r) in inputs.iter().zip(&per_file) {
            println!("{:>9} {:>9.2} ms  {}", r.0, r.2 * 1e3, i.path.display());
        }
    }
    Ok(())
}
