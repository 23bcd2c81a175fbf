//! `scenegen [SCENES_DIR] [--only NAME]`: (re)write the bundled Unity projects;
//! `scenegen DIR --large SIDE`: write the scale-test project instead;
//! `scenegen DIR --fbx MODELS`: write the FBX scale-test project instead.

use anyhow::{bail, Context, Result};
use clap::Parser;
use std::path::PathBuf;

#[derive(Parser)]
#[command(
    version,
    about = "Write the bundled Unity projects (baseline and effect scenes)"
)]
struct Args {
    /// Folder that holds the projects (one sub-folder each).
    #[arg(default_value = "scenes")]
    dir: PathBuf,
    /// Only this project (e.g. `baseline`, `spot`).
    #[arg(long)]
    only: Option<String>,
    /// Write only the scale-test project `large`: the baseline's props on a SIDE×SIDE
    /// grid (41,821·SIDE² + 12 triangles; 16 gives 10.7 million).
    #[arg(long, value_name = "SIDE", conflicts_with = "only")]
    large: Option<usize>,
    /// Write only the FBX scale-test project `fbxlarge`: MODELS distinct binary FBX
    /// models of 65,536 triangles, each placed twice unless `--instances` says otherwise
    /// (16 gives 1,048,576 triangles in the files).
    #[arg(long, value_name = "MODELS", conflicts_with_all = ["only", "large"])]
    fbx: Option<usize>,
    /// With `--fbx`: deflate the models' arrays, as exporters write them.
    #[arg(long, requires = "fbx")]
    deflate: bool,
    /// With `--fbx`: place each model this many times (1: every triangle of the scene is
    /// read from a file).
    #[arg(long, requires = "fbx", default_value_t = scenegen::fbx_scene::INSTANCES)]
    instances: usize,
}

fn main() {
    if let Err(e) = run() {
        eprintln!("scenegen: {e:#}");
        std::process::exit(1);
    }
}

fn run() -> Result<()> {
    let args = Args::parse();
    let projects: Vec<_> = match (args.large, args.fbx) {
        (Some(side), _) => vec![scenegen::baseline::large(side)],
        (None, Some(models)) => vec![scenegen::fbx_scene::project(
            models,
            args.instances,
            args.deflate,
        )],
        (None, None) => scenegen::all_projects()
            .into_iter()
            .filter(|p| args.only.as_deref().is_none_or(|o| o == p.name))
            .collect(),
    };
    if projects.is_empty() {
        bail!("no project named {:?}", args.only.unwrap_or_default());
    }
    for p in &projects {
        let stale = p
            .write(&args.dir)
            .with_context(|| format!("writing {}", args.dir.join(&p.name).display()))?;
        for s in stale {
            eprintln!("removed stale {}/{}/{s}", args.dir.display(), p.name);
        }
        println!(
            "{}: {} files",
            args.dir.join(&p.name).display(),
            p.files.len()
        );
    }
    Ok(())
}
