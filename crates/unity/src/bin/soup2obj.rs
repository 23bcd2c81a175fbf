//! soup2obj scene.soup -o scene.obj: world-space OBJ, one `o` per object, faces in soup
//! order, with normals.
use anyhow::Context;
use clap::Parser;
use std::path::PathBuf;

#[derive(Parser)]
#[command(
    name = "soup2obj",
    version,
    about = "Export a unitrace soup as a world-space Wavefront OBJ"
)]
struct Args {
    soup: PathBuf,
    #[arg(short, long)]
    output: PathBuf,
}

fn main() {
    let args = Args::parse();
    if let Err(e) = run(&args) {
        eprintln!("soup2obj: {e:#}");
        std::process::exit(1);
    }
}

fn run(args: &Args) -> anyhow::Result<()> {
    formats::threads::start(None).map_err(anyhow::Error::msg)?;
    let soup = formats::Soup::read(&args.soup)?;
    let text = unity::objexport::to_obj(&soup);
    formats::write_atomic(&args.output, text.as_bytes())
        .with_context(|| format!("writing {}", args.output.display()))?;
    eprintln!(
        "{}: {} objects, {} triangles",
        args.output.display(),
        soup.objects.len(),
        soup.triangles.len()
    );
    Ok(())
}
