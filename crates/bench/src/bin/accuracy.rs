//! `accuracy`: what each render knob buys in accuracy and costs in time. Writes
//! reports/accuracy.md and reports/accuracy.svg.

use anyhow::{Context, Result};
use bench::accuracy::{plot, report, scenes, sweep, Config};
use clap::Parser;
use std::path::PathBuf;

#[derive(Parser)]
#[command(about = "Sweep each render knob alone against a converged reference")]
struct Args {
    /// Repository root (holds scenes/); the corpus is looked for in its sibling shared/.
    #[arg(long, default_value = ".")]
    root: PathBuf,
    #[arg(long, default_value = "reports/accuracy.md")]
    out: PathBuf,
    #[arg(long, default_value = "reports/accuracy.svg")]
    svg: PathBuf,
    #[arg(long, default_value_t = 160)]
    width: u32,
    #[arg(long, default_value_t = 120)]
    height: u32,
    /// Timed runs per point (the median is reported).
    #[arg(long, default_value_t = 3)]
    runs: usize,
    #[arg(long, default_value_t = 256)]
    reference_spp: u32,
    /// Also write each scene's soup to DIR/NAME.soup, and for a textured scene the same
    /// soup with its maps removed (DIR/NAME-no-maps.soup), to time with kd2exr what the
    /// textures cost; the baseline is also written with a checker on every material
    /// (baseline-textured).
    #[arg(long, value_name = "DIR")]
    export: Option<PathBuf>,
    /// Sweep only these scenes (comma-separated names: baseline, shadows-soft, sun-soft,
    /// spot-on-mirror, checkerboard).
    #[arg(long, value_delimiter = ',')]
    only: Vec<String>,
}

fn main() {
    if let Err(e) = run() {
        eprintln!("accuracy: {e:#}");
        std::process::exit(1);
    }
}

fn run() -> Result<()> {
    let a = Args::parse();
    let cfg = Config {
        width: a.width,
        height: a.height,
        runs: a.runs,
        reference_spp: a.reference_spp,
        ..Config::default()
    };
    let mut notes = vec![];
    let mut list = vec![
        scenes::unity_scene(
            "baseline",
            &a.root.join("scenes/baseline/Assets/Scenes/Baseline.unity"),
        )?,
        scenes::unity_scene(
            "shadows-soft",
            &a.root
                .join("scenes/shadows-soft/Assets/Scenes/ShadowsSoft.unity"),
        )?,
    ];
    list.push(scenes::with_sun(&list[1], "sun-soft", 4.0));
    let spot = a.root.join("../shared/corpus/meshes/spot.obj");
    if spot.exists() {
        list.push(scenes::mesh_on_mirror(&spot)?);
    } else {
        let line = format!(
            "SKIPPED: the spot-on-mirror scene because {} is absent",
            spot.display()
        );
        eprintln!("{line}");
        notes.push(line);
    }
    list.push(scenes::checkerboard());
    if let Some(dir) = &a.export {
        for s in &list {
            export(dir, s)?;
        }
        if let Some(b) = list.iter().find(|s| s.name == "baseline") {
            export(dir, &scenes::with_checker(b))?;
        }
    }
    if !a.only.is_empty() {
        list.retain(|s| a.only.contains(&s.name));
        if list.is_empty() {
            anyhow::bail!("--only {}: no such scene", a.only.join(","));
        }
    }
    let start = std::time::Instant::now();
    let log = |l: &str| eprintln!("[{:6.1} s] {l}", start.elapsed().as_secs_f64());
    let mut results = vec![];
    for s in &list {
        results.push(sweep::measure(s, &cfg, &log)?);
    }
    notes.push(format!(
        "Whole run: {:.0} s on {} threads.",
        start.elapsed().as_secs_f64(),
        rayon::current_num_threads()
    ));
    // The report names the command that made it: `just accuracy` runs it bare.
    let args: Vec<String> = std::env::args().skip(1).collect();
    let command = if args.is_empty() {
        "just accuracy".to_string()
    } else {
        format!(
            "cargo run --release -p bench --bin accuracy -- {}",
            args.join(" ")
        )
    };
    let md = report::markdown(&results, &cfg, &command, &notes);
    formats::write_atomic(&a.out, md.as_bytes())
        .with_context(|| format!("{}: cannot write the report", a.out.display()))?;
    let svg = plot::svg(&results).map_err(|e| anyhow::anyhow!("plotting: {e}"))?;
    formats::write_atomic(&a.svg, svg.as_bytes())
        .with_context(|| format!("{}: cannot write the plot", a.svg.display()))?;
    eprintln!("wrote {} and {}", a.out.display(), a.svg.display());
    Ok(())
}

fn export(dir: &std::path::Path, scene: &scenes::Scene) -> Result<()> {
    let write = |name: &str, soup: &formats::Soup| {
        let path = dir.join(format!("{name}.soup"));
        soup.write(&path)
            .with_context(|| format!("{}: cannot write", path.display()))?;
        eprintln!("wrote {}", path.display());
        Ok::<_, anyhow::Error>(())
    };
    write(&scene.name, &scene.soup)?;
    if scene.soup.materials.iter().any(|m| m.albedo_map.is_some()) {
        let mut plain = scene.soup.clone();
        for m in &mut plain.materials {
            m.albedo_map = None;
        }
        plain.textures.clear();
        plain.uvs.clear();
        write(&format!("{}-no-maps", scene.name), &plain)?;
    }
    Ok(())
}
