//! `exrwrite IMAGE.exr`: what writing a frame costs with each EXR compression `kd2exr`
//! could use. The image (a `kd2exr` output: colour plus its AOVs) is read once, then
//! encoded in memory with every compression in turn, round-robin, `--runs` times; each
//! line gives the median encoding time (blocks compressed on all cores, as `kd2exr` does),
//! the size, and whether decoding gives back the same samples. The first line is
//! `kd2exr`'s own encoder (ZIP deflated by libdeflate); the others are the `exr` crate's.

use anyhow::{Context, Result};
use clap::Parser;
use exr::prelude::{Blocks, Compression, Encoding, LineOrder, Vec2};
use render::exrio::ExrImage;
use std::path::PathBuf;
use std::time::Instant;

#[derive(Parser)]
#[command(about = "Time EXR encoding of one image with each compression")]
struct Args {
    /// A kd2exr output.
    image: PathBuf,
    /// Rounds; every compression is timed once per round.
    #[arg(long, default_value_t = 9)]
    runs: usize,
}

fn main() {
    if let Err(e) = run() {
        eprintln!("exrwrite: {e:#}");
        std::process::exit(1);
    }
}

fn scan_lines(compression: Compression) -> Encoding {
    Encoding {
        compression,
        blocks: Blocks::ScanLines,
        line_order: LineOrder::Increasing,
    }
}

fn run() -> Result<()> {
    let args = Args::parse();
    let image = ExrImage::read(&args.image)?;
    // `None`: kd2exr's encoder.
    let candidates: Vec<(&str, Option<Encoding>)> = vec![
        ("ZIP, 16 lines, libdeflate level 1 (kd2exr)", None),
        (
            "ZIP, 16 lines, exr crate (miniz level 4)",
            Some(Encoding::SMALL_LOSSLESS),
        ),
        ("ZIPS, 1 line", Some(scan_lines(Compression::ZIP1))),
        ("PIZ, 32 lines", Some(scan_lines(Compression::PIZ))),
        ("RLE, 1 line", Some(scan_lines(Compression::RLE))),
        (
            "RLE, 64×64 tiles",
            Some(Encoding {
                compression: Compression::RLE,
                blocks: Blocks::Tiles(Vec2(64, 64)),
                line_order: LineOrder::Unspecified,
            }),
        ),
        ("none", Some(scan_lines(Compression::Uncompressed))),
    ];
    let encode = |encoding: &Option<Encoding>| match encoding {
        None => image.encode(),
        Some(e) => image.encode_with(*e),
    };
    let mut times = vec![Vec::new(); candidates.len()];
    let mut sizes = vec![0usize; candidates.len()];
    for _ in 0..args.runs {
        for (i, (_, encoding)) in candidates.iter().enumerate() {
            let t = Instant::now();
            let bytes = encode(encoding)
                .map_err(anyhow::Error::msg)
                .context("encoding")?;
            times[i].push(t.elapsed().as_secs_f64());
            sizes[i] = bytes.len();
        }
    }
    println!(
        "{}: {}×{}, {} channels, median of {} rounds",
        args.image.display(),
        image.width,
        image.height,
        image.channels.len(),
        args.runs
    );
    println!("| compression | encode ms | MB | same samples |");
    println!("|---|---:|---:|---|");
    let dir = tempfile::tempdir()?;
    for (i, (name, encoding)) in candidates.iter().enumerate() {
        times[i].sort_by(f64::total_cmp);
        let path = dir.path().join(format!("{i}.exr"));
        std::fs::write(&path, encode(encoding).map_err(anyhow::Error::msg)?)?;
        let back = ExrImage::read(&path)?;
        println!(
            "| {name} | {:.1} | {:.2} | {} |",
            times[i][times[i].len() / 2] * 1e3,
            sizes[i] as f64 / 1e6,
            if back.channels == image.channels {
                "yes"
            } else {
                "NO"
            }
        );
    }
    Ok(())
}
