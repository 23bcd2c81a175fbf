//! unity2soup SCENE.unity -o scene.soup [--assets DIR] [--json] [--strict]
use anyhow::Context;
use clap::Parser;
use std::path::PathBuf;
use std::time::Instant;

#[derive(Parser)]
#[command(about = "Convert a text-serialized Unity scene into a unitrace triangle soup")]
struct Args {
    /// The scene (.unity, text serialization).
    scene: PathBuf,
    /// Output soup file.
    #[arg(short, long)]
    output: PathBuf,
    /// Unity project root (the folder holding Assets/); default: found above the scene.
    #[arg(long)]
    assets: Option<PathBuf>,
    /// Print one JSON object with the summary on stdout.
    #[arg(long)]
    json: bool,
    /// Treat every warning as an error.
    #[arg(long)]
    strict: bool,
}

fn main() {
    let args = Args::parse();
    if let Err(e) = run(&args) {
        eprintln!("unity2soup: {e:#}");
        std::process::exit(1);
    }
}

fn run(args: &Args) -> anyhow::Result<()> {
    let t0 = Instant::now();
    let opts = unity::Options {
        project: args.assets.clone(),
        strict: args.strict,
    };
    let soup = unity::convert(&args.scene, &opts)?;
    soup.write(&args.output)
        .with_context(|| format!("writing {}", args.output.display()))?;
    let secs = t0.elapsed().as_secs_f64();
    for w in &soup.warnings {
        eprintln!("warning: {w}");
    }
    eprintln!(
        "{}: {} objects, {} triangles, {} lights, {} materials, {} warnings, {} degenerate dropped, {:.3} s",
        args.scene.display(),
        soup.objects.len(),
        soup.triangles.len(),
        soup.lights.len(),
        soup.materials.len(),
        soup.warnings.len(),
        soup.dropped_degenerate,
        secs
    );
    if args.json {
        let j = serde_json::json!({
            "objects": soup.objects.len(),
            "triangles": soup.triangles.len(),
            "lights": soup.lights.len(),
            "materials": soup.materials.len(),
            "warnings": soup.warnings,
            "dropped_degenerate": soup.dropped_degenerate,
            "seconds": secs,
        });
        println!("{j}");
    }
    Ok(())
}
