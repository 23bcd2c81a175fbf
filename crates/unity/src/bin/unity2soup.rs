//! unity2soup SCENE.unity -o scene.soup [--assets DIR] [--camera NAME] [--json] [--strict]
use anyhow::Context;
use clap::Parser;
use formats::TextureRef;
use std::path::PathBuf;
use std::time::Instant;

#[derive(Parser)]
#[command(
    name = "unity2soup",
    version,
    about = "Convert a text-serialized Unity scene into a unitrace triangle soup"
)]
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
    /// Render the enabled camera on this GameObject (its name or hierarchy path,
    /// `Parent/Child`) instead of the Game view's.
    #[arg(long)]
    camera: Option<String>,
    /// List the project settings read (render pipeline, light units, colour space,
    /// quality level), every converted object (triangles, source, materials, layer, shadows), every
    /// material (texture, tiling, opacity, alpha mode), every renderer Unity's draw rules
    /// skip (camera culling mask, LOD levels the camera does not show), light and warning
    /// on stderr.
    #[arg(long)]
    list: bool,
}

fn main() {
    let report = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        if !unity::texture::panic_is_caught_decode() {
            report(info)
        }
    }));
    let args = Args::parse();
    if let Err(e) = run(&args) {
        eprintln!("unity2soup: {e:#}");
        std::process::exit(1);
    }
}

fn run(args: &Args) -> anyhow::Result<()> {
    let t0 = Instant::now();
    formats::threads::start(None).map_err(anyhow::Error::msg)?;
    let opts = unity::Options {
        project: args.assets.clone(),
        strict: args.strict,
        camera: args.camera.clone(),
    };
    let report = unity::convert_report(&args.scene, &opts)?;
    let soup = &report.soup;
    soup.write(&args.output)
        .with_context(|| format!("writing {}", args.output.display()))?;
    let secs = t0.elapsed().as_secs_f64();
    // A real project can have hundreds of warnings: show the first few unless asked.
    let shown = if args.list { soup.warnings.len() } else { 20 };
    for w in soup.warnings.iter().take(shown) {
        eprintln!("warning: {w}");
    }
    if soup.warnings.len() > shown {
        eprintln!(
            "warning: … and {} more (--list or --json shows them all)",
            soup.warnings.len() - shown
        );
    }
    if args.list {
        list(&report);
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
            "textures": soup.textures.len(),
            "warnings": soup.warnings,
            "dropped_degenerate": soup.dropped_degenerate,
            "skipped": report.skipped,
            "seconds": secs,
        });
        println!("{j}");
    }
    Ok(())
}

/// The project's settings, then one line per object, material, skipped renderer and
/// light, for checking a conversion by eye.
fn list(report: &unity::Report) {
    eprintln!("project: {}", report.settings);
    let soup = &report.soup;
    let mut tris = vec![0usize; soup.objects.len()];
    let mut mats: Vec<Vec<u32>> = vec![Vec::new(); soup.objects.len()];
    for (&o, &m) in soup.tri_object.iter().zip(&soup.tri_material) {
        tris[o as usize] += 1;
        if !mats[o as usize].contains(&m) {
            mats[o as usize].push(m);
        }
    }
    for (i, o) in soup.objects.iter().enumerate() {
        let origins = report.material_origins.get(i);
        let names: Vec<String> = mats[i]
            .iter()
            .map(|&mi| {
                let m = &soup.materials[mi as usize];
                let origin = origins
                    .and_then(|os| os.iter().find(|(x, _)| *x == mi))
                    .map(|(_, o)| o.as_str())
                    .unwrap_or("?");
                format!(
                    "{} rgb({:.3},{:.3},{:.3}) cull {:?} from {origin}",
                    m.name, m.color.x, m.color.y, m.color.z, m.cull
                )
            })
            .collect();
        eprintln!(
            "object {:?}: {} triangles from {} [{}], layer {}, shadows {:?}{}",
            o.name,
            tris[i],
            o.source,
            names.join("; "),
            o.layer,
            o.cast_shadows,
            if o.receive_shadows {
                ""
            } else {
                ", receives none"
            }
        );
    }
    // A map's image as the lines name it: its file and imported size.
    let image = |r: &TextureRef| {
        let t = &soup.textures[r.texture as usize];
        format!("{} {}x{}", t.source, t.width, t.height)
    };
    for m in &soup.materials {
        let texture = match &m.albedo_map {
            Some(r) => format!(
                "texture {} scale ({}, {}) offset ({}, {})",
                image(r),
                r.tiling.scale[0],
                r.tiling.scale[1],
                r.tiling.offset[0],
                r.tiling.offset[1]
            ),
            None => "no texture".to_string(),
        };
        let normal = m.normal_map.as_ref().map_or(String::new(), |n| {
            format!(", normal map {} scale {}", image(&n.map), n.scale)
        });
        let glow = m
            .emission_map
            .as_ref()
            .map_or(String::new(), |r| format!(", emission map {}", image(r)));
        let occlusion = m.occlusion_map.as_ref().map_or(String::new(), |o| {
            format!(", occlusion map {} strength {}", image(&o.map), o.strength)
        });
        let metal = m.metallic_map.as_ref().map_or(String::new(), |g| {
            format!(
                ", metallic map {} smoothness {}",
                image(&g.map),
                g.smoothness
            )
        });
        let unlit = if m.unlit { ", unlit" } else { "" };
        eprintln!(
            "material {:?} ({}): {texture}{normal}{glow}{occlusion}{metal}, opacity {}, alpha {:?}{unlit}",
            m.name, m.source, m.opacity, m.alpha
        );
    }
    for s in &report.skipped {
        eprintln!("skipped {s}");
    }
    if !report.skipped.is_empty() {
        eprintln!(
            "skipped {} renderers by Unity's draw rules",
            report.skipped.len()
        );
    }
    for l in &soup.lights {
        eprintln!(
            "light {:?}: {:?} at {} along {}, colour {}, intensity {}, range {}, {:?} attenuation, shadows {:?}, layers {:#010x}",
            l.name, l.kind, l.position, l.direction, l.color, l.intensity, l.range, l.attenuation, l.shadows, l.culling_mask
        );
    }
    let c = &soup.camera;
    eprintln!(
        "camera {:?}: at {} forward {} up {} {:?}",
        c.name, c.position, c.forward, c.up, c.projection
    );
}
