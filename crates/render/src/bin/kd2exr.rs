//! kd2exr: render a soup through its k-d tree into an OpenEXR image.
//!
//! ```text
//! kd2exr scene.soup scene.kd -o image.exr [--preview image.png] [--width 1024] [--height 768]
//!        [--depth 4] [--spp 1] [--seed 0] [--threads N] [--json] [--half]
//!        [--aov depth,normal,albedo,object] [--exposure 0] [--crop x0,y0,x1,y1]
//!        [--soft-samples 16] [--cutoff 0.004] [--texture-filter cone]
//! kd2exr merge a.exr b.exr … -o full.exr [--preview full.png] [--exposure 0]
//! ```

use anyhow::{Context, Result};
use clap::{Args, Parser, Subcommand};
use formats::{KdFile, Soup};
use render::{memory, preview, AovSet, ExrImage, Plan, RenderOptions, TextureFilter, Window};
use std::io::IsTerminal;
use std::path::PathBuf;
use std::time::Instant;

#[derive(Parser)]
#[command(
    name = "kd2exr",
    version,
    about = "Ray-trace a unitrace soup through its k-d tree into an OpenEXR image",
    args_conflicts_with_subcommands = true,
    subcommand_negates_reqs = true
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    #[command(flatten)]
    render: RenderArgs,
}

#[derive(Subcommand)]
enum Command {
    /// Join EXR crops (kd2exr --crop …) of one render into the full image.
    Merge {
        /// The crops, in any order; together they must cover the image.
        #[arg(required = true)]
        inputs: Vec<PathBuf>,
        #[arg(short, long)]
        output: PathBuf,
        /// Also write an 8-bit sRGB PNG preview of the merged image.
        #[arg(long)]
        preview: Option<PathBuf>,
        /// Preview exposure in stops (the PNG is scaled by 2^exposure).
        #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
        exposure: f32,
    },
}

#[derive(Args)]
struct RenderArgs {
    /// The scene (unity2soup output).
    #[arg(required = true)]
    soup: Option<PathBuf>,
    /// Its compiled k-d tree (soup2kd output).
    #[arg(required = true)]
    kd: Option<PathBuf>,
    /// The EXR to write.
    #[arg(short, long, required = true)]
    output: Option<PathBuf>,
    /// Also write an 8-bit sRGB PNG preview.
    #[arg(long)]
    preview: Option<PathBuf>,
    #[arg(long, default_value_t = RenderOptions::default().width)]
    width: u32,
    #[arg(long, default_value_t = RenderOptions::default().height)]
    height: u32,
    /// Maximum mirror bounces.
    #[arg(long, default_value_t = RenderOptions::default().depth)]
    depth: u32,
    /// Samples per pixel (stratified, box filter).
    #[arg(long, default_value_t = RenderOptions::default().spp)]
    spp: u32,
    /// Seed of the per-pixel random numbers.
    #[arg(long, default_value_t = RenderOptions::default().seed)]
    seed: u64,
    /// Threads for loading, tracing and writing (default: one per core).
    #[arg(long)]
    threads: Option<usize>,
    /// Print one JSON object on stdout.
    #[arg(long)]
    json: bool,
    /// Store RGBA (and albedo) as 16-bit floats.
    #[arg(long)]
    half: bool,
    /// Extra channels: any of depth,normal,albedo,object.
    #[arg(long, value_name = "LIST")]
    aov: Option<String>,
    /// Preview exposure in stops (the PNG is scaled by 2^exposure).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    exposure: f32,
    /// Render only the window x0,y0,x1,y1 (x1, y1 exclusive) of the full image.
    #[arg(long, value_name = "x0,y0,x1,y1", value_parser = Window::parse)]
    crop: Option<Window>,
    /// Shadow rays per soft-shadow light per shading point.
    #[arg(long, default_value_t = RenderOptions::default().soft_samples)]
    soft_samples: u32,
    /// Trace every soft-shadow sample, even where four probe rays towards the rim of the
    /// light's extent all let the same share of light through (wholly lit or in shadow).
    #[arg(long)]
    soft_all: bool,
    /// Stop reflection rays when the path weight falls below this.
    #[arg(long, default_value_t = RenderOptions::default().cutoff)]
    cutoff: f32,
    /// Texture lookups: point or bilinear on the full-size image, or cone (as Unity: the
    /// texture's own filter and mip maps, the level from the pixel's footprint).
    #[arg(long, value_name = "point|bilinear|cone", value_parser = TextureFilter::parse,
          default_value_t = RenderOptions::default().texture_filter)]
    texture_filter: TextureFilter,
}

fn main() {
    let cli = Cli::parse();
    let result = match cli.command {
        Some(Command::Merge {
            inputs,
            output,
            preview,
            exposure,
        }) => merge(&inputs, &output, preview.as_deref(), exposure),
        None => run(cli.render),
    };
    if let Err(e) = result {
        eprintln!("kd2exr: error: {e:#}");
        std::process::exit(1);
    }
}

fn merge(
    inputs: &[PathBuf],
    output: &std::path::Path,
    preview: Option<&std::path::Path>,
    exposure: f32,
) -> Result<()> {
    let start = Instant::now();
    finite_exposure(exposure)?;
    for p in std::iter::once(output).chain(preview) {
        writable_folder(p)?;
    }
    let parts = inputs
        .iter()
        .map(|p| Ok((p.display().to_string(), ExrImage::read_crop(p)?)))
        .collect::<Result<Vec<_>, render::RenderError>>()?;
    let labelled: Vec<(String, &ExrImage)> = parts.iter().map(|(l, p)| (l.clone(), p)).collect();
    let full = render::exrio::merge_labelled(&labelled)?;
    full.write(output)?;
    if let Some(png) = preview {
        let color = full.color().with_context(|| {
            format!(
                "cannot write the preview {}: the crops have no RGB channels",
                png.display()
            )
        })?;
        preview::write_rgb_png(png, full.width, full.height, &color, exposure)?;
    }
    eprintln!(
        "kd2exr: merged {} crops into {} ({}×{}) in {:.2} s",
        parts.len(),
        output.display(),
        full.width,
        full.height,
        start.elapsed().as_secs_f64()
    );
    Ok(())
}

fn finite_exposure(exposure: f32) -> Result<()> {
    if !exposure.is_finite() {
        anyhow::bail!("invalid option: --exposure {exposure} is not a finite number");
    }
    Ok(())
}

/// Fail early, naming the path, when an output's folder does not exist or the output is
/// itself a folder: a render writes the EXR before its preview, and a preview refused only
/// then would leave the EXR of a failed run behind.
fn writable_folder(path: &std::path::Path) -> Result<()> {
    if path.is_dir() {
        anyhow::bail!("cannot write {}: it is a folder", path.display());
    }
    match path.parent() {
        Some(dir) if !dir.as_os_str().is_empty() && !dir.is_dir() => anyhow::bail!(
            "cannot write {}: the folder {} does not exist",
            path.display(),
            dir.display()
        ),
        _ => Ok(()),
    }
}

fn run(a: RenderArgs) -> Result<()> {
    let start = Instant::now();
    let (Some(soup_path), Some(kd_path), Some(out_path)) = (a.soup, a.kd, a.output) else {
        anyhow::bail!("a render needs SOUP KD -o OUTPUT");
    };
    let opts = RenderOptions {
        width: a.width,
        height: a.height,
        depth: a.depth,
        spp: a.spp,
        seed: a.seed,
        soft_samples: a.soft_samples,
        soft_probe: !a.soft_all,
        cutoff: a.cutoff,
        crop: a.crop,
        aovs: match &a.aov {
            Some(list) => AovSet::parse(list)?,
            None => AovSet::default(),
        },
        threads: a.threads,
        texture_filter: a.texture_filter,
        ..RenderOptions::default()
    };
    finite_exposure(a.exposure)?;
    // Everything that can be refused is refused before loading or tracing anything.
    opts.validate()?;
    // Loading and writing run on the same number of threads as the tracing.
    formats::threads::start(opts.threads).map_err(anyhow::Error::msg)?;
    memory::check(&opts, memory::available_bytes())?;
    for p in std::iter::once(&out_path).chain(a.preview.as_ref()) {
        writable_folder(p)?;
    }

    let t_load = Instant::now();
    let soup_bytes = formats::envelope::read_file(&soup_path)?;
    let soup = Soup::from_bytes(&soup_bytes, &soup_path)?;
    // The envelope's payload checksum, verified by the decode, identifies the whole soup.
    let soup_digest: formats::Digest = soup_bytes
        [formats::envelope::HEADER_LEN - 32..formats::envelope::HEADER_LEN]
        .try_into()
        .context("the soup's envelope header")?;
    drop(soup_bytes);
    let kd = KdFile::read(&kd_path)?;
    let params = kd.params;
    let accel = kdtree::Accel::new(&soup, kd)
        .with_context(|| format!("{} and {}", soup_path.display(), kd_path.display()))?;
    let load_seconds = t_load.elapsed().as_secs_f64();

    let plan = Plan::derive(&soup, &opts);
    if !a.json {
        eprintln!("{}", plan.describe());
    }

    let window = opts.window();
    let bar = std::io::stderr().is_terminal().then(|| {
        let total = render::render::tiles(window, opts.tile).len() as u64;
        let bar = indicatif::ProgressBar::new(total);
        bar.set_style(
            indicatif::ProgressStyle::with_template(
                "{bar:40} {pos}/{len} tiles, {elapsed} elapsed, ETA {eta}",
            )
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        bar
    });
    let tick = |done: u64, _total: u64| {
        if let Some(b) = &bar {
            b.set_position(done);
        }
    };
    let out = render::render(&soup, &accel, &plan, &opts, Some(&tick))?;
    if let Some(b) = &bar {
        b.finish_and_clear();
    }

    let mut attrs = render::header_attributes(&plan, &opts, out.seconds, &soup.geometry_hash);
    attrs.extend(render::source_attributes(&soup_digest, &params));
    // The EXR's compression and the PNG's are independent: one thread each (the EXR also
    // spreads its blocks over whatever threads are free).
    let t_write = Instant::now();
    let (exr_written, png_written) = rayon::join(
        || ExrImage::write_frame(&out.frame, a.half, attrs, &out_path),
        || {
            a.preview
                .as_ref()
                .map(|png| preview::write_png(png, &out.frame, a.exposure))
                .transpose()
        },
    );
    exr_written?;
    png_written?;
    let write_seconds = t_write.elapsed().as_secs_f64();

    let c = out.counts;
    let mrays = c.total() as f64 / out.seconds.max(1e-9) / 1e6;
    eprintln!(
        "kd2exr: rendered {}×{} (window {}) at {} spp, depth {} in {:.3} s ({:.2} Mrays/s; loading took {:.3} s, setting up {:.3} s, writing {:.3} s)",
        opts.width, opts.height, window, opts.spp, opts.depth, out.seconds, mrays, load_seconds, out.setup_seconds, write_seconds
    );
    eprintln!(
        "kd2exr: rays: camera {}, shadow {}, soft_shadow {}, reflection {}, blend_continuation {}, pass_through {}, shadow_pass_through {}, shadow_blend {}, shadow_reuse {}, soft_decided {} (total {})",
        c.camera,
        c.shadow,
        c.soft_shadow,
        c.reflection,
        c.blend_continuation,
        c.pass_through,
        c.shadow_pass_through,
        c.shadow_blend,
        c.shadow_reuse,
        c.soft_decided,
        c.total()
    );
    if c.texture_lookups
        + c.normal_lookups
        + c.emission_lookups
        + c.occlusion_lookups
        + c.metallic_lookups
        + c.alpha_lookups
        > 0
    {
        eprintln!(
            "kd2exr: texture lookups {}, normal-map lookups {}, emission-map lookups {}, \
             occlusion-map lookups {}, metallic-map lookups {}, alpha lookups {} \
             ({:.1} MiB of mip levels)",
            c.texture_lookups,
            c.normal_lookups,
            c.emission_lookups,
            c.occlusion_lookups,
            c.metallic_lookups,
            c.alpha_lookups,
            plan.textures.bytes as f64 / (1u64 << 20) as f64
        );
    }
    if c.probe_lookups > 0 {
        eprintln!("kd2exr: reflection probe lookups {}", c.probe_lookups);
    }
    if c.sanitized > 0 {
        eprintln!(
            "kd2exr: warning: {} samples were NaN or infinite and were set to 0 (check the scene's materials and lights)",
            c.sanitized
        );
    }
    eprintln!("kd2exr: wrote {}", out_path.display());
    if a.json {
        let json = serde_json::json!({
            "width": opts.width,
            "height": opts.height,
            "window": [window.x0, window.y0, window.x1, window.y1],
            "spp": opts.spp,
            "depth": opts.depth,
            "texture_filter": opts.texture_filter,
            "seconds": out.seconds,
            "load_seconds": load_seconds,
            "setup_seconds": out.setup_seconds,
            "write_seconds": write_seconds,
            "total_seconds": start.elapsed().as_secs_f64(),
            "rays": c,
            "sanitized": c.sanitized,
            "plan": plan.to_json(),
            "output": out_path,
        });
        println!("{json}");
    }
    Ok(())
}
