//! Parallel rendering over tiles with rayon's work stealing.

use crate::cone::RayCone;
use crate::counters::{RayCounts, SharedCounts};
use crate::integrator::{Integrator, Primary};
use crate::sampling::{pixel_samples, Rng};
use crate::{CameraModel, Frame, Plan, RenderError, RenderOptions, Window};
use formats::{ColorSpace, KdFile, Soup};
use glam::Vec3;
use kdtree::{Accel, LANES};
use rayon::prelude::*;
use std::time::Instant;

/// A finished render.
#[derive(Debug)]
pub struct Rendered {
    pub frame: Frame,
    pub counts: RayCounts,
    /// Wall-clock time of the tracing itself (not loading or writing).
    pub seconds: f64,
    /// Wall-clock time of what the tracing needs first: the textures' mip levels and the
    /// per-triangle tables the plan calls for.
    pub setup_seconds: f64,
}

/// Tiles of at most `edge`×`edge` pixels covering the window, row by row.
pub fn tiles(window: Window, edge: u32) -> Vec<Window> {
    let mut out = Vec::new();
    let mut y = window.y0;
    while y < window.y1 {
        let y1 = (y + edge).min(window.y1);
        let mut x = window.x0;
        while x < window.x1 {
            let x1 = (x + edge).min(window.x1);
            out.push(Window {
                x0: x,
                y0: y,
                x1,
                y1,
            });
            x = x1;
        }
        y = y1;
    }
    out
}

/// Validate, derive the plan, build the accelerator and render: the all-in-one entry
/// point used by tests. `kd2exr` does the same steps one at a time to report on each.
pub fn render_scene(
    soup: &Soup,
    kd: &KdFile,
    opts: &RenderOptions,
) -> Result<(Rendered, Plan), RenderError> {
    opts.validate()?;
    let accel = Accel::new(soup, kd.clone())?;
    let plan = Plan::derive(soup, opts);
    let out = render(soup, &accel, &plan, opts, None)?;
    Ok((out, plan))
}

/// Render `opts.window()` of the image. `progress` is called after each tile with
/// (tiles done, tiles in all).
pub fn render(
    soup: &Soup,
    accel: &Accel,
    plan: &Plan,
    opts: &RenderOptions,
    progress: Option<&(dyn Fn(u64, u64) + Sync)>,
) -> Result<Rendered, RenderError> {
    opts.validate()?;
    let camera = CameraModel::new(&soup.camera, opts.width, opts.height)?;
    let window = opts.window();
    // The samplers are built on the render's own threads too.
    let run = || {
        let setup = Instant::now();
        let integrator = Integrator::new(soup, accel, plan, opts);
        let setup_seconds = setup.elapsed().as_secs_f64();
        let start = Instant::now();
        let gamma = soup.environment.color_space == ColorSpace::Gamma;
        let (frame, counts) = render_tiles(&camera, &integrator, opts, window, gamma, progress);
        Rendered {
            frame,
            counts,
            seconds: start.elapsed().as_secs_f64(),
            setup_seconds,
        }
    };
    Ok(match opts.threads {
        Some(n) => rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .map_err(|e| RenderError::Threads {
                threads: n,
                detail: e.to_string(),
            })?
            .install(run),
        None => run(),
    })
}

fn render_tiles(
    camera: &CameraModel,
    integrator: &Integrator,
    opts: &RenderOptions,
    window: Window,
    gamma: bool,
    progress: Option<&(dyn Fn(u64, u64) + Sync)>,
) -> (Frame, RayCounts) {
    // One pixel's cone shared by its samples, the same for every pixel.
    let cone = camera.cone().per_sample(opts.spp);
    let list = tiles(window, opts.tile);
    let total = list.len() as u64;
    let shared = SharedCounts::default();
    let done = std::sync::atomic::AtomicU64::new(0);
    let results: Vec<(Window, Vec<(Vec3, Primary)>)> = list
        .into_par_iter()
        .map(|tile| {
            let mut counts = RayCounts::default();
            let pixels = render_tile(camera, cone, integrator, opts, tile, &mut counts);
            shared.add(&counts);
            if let Some(report) = progress {
                let n = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
                report(n, total);
            }
            (tile, pixels)
        })
        .collect();
    let mut frame = Frame::new(opts.width, opts.height, window, opts.aovs);
    for (tile, pixels) in results {
        let mut it = pixels.iter();
        for y in tile.y0..tile.y1 {
            for x in tile.x0..tile.x1 {
                let (c, p) = it.next().expect("one result per tile pixel");
                let i = frame.index(x, y).expect("tiles lie inside the window");
                if gamma {
                    frame.set(
                        i,
                        decode(*c),
                        &Primary {
                            albedo: decode(p.albedo),
                            ..*p
                        },
                    );
                } else {
                    frame.set(i, *c, p);
                }
            }
        }
    }
    (frame, shared.load())
}

/// A gamma-space project's pixel as the display shows it, in linear RGB: its frame holds
/// sRGB-encoded values (Unity's gamma-to-linear conversion; negative values, which no
/// colour has, as 0).
fn decode(c: Vec3) -> Vec3 {
    c.map(|v| {
        if v <= 0.0 {
            0.0
        } else {
            formats::srgb::gamma_to_linear(v)
        }
    })
}

/// A tile's pixels, row by row. The pixels of each 2×2 block are traced together, sample by
/// sample ([`render_block`]); an odd last row or column goes through [`render_pixel`].
/// Either way each pixel gets the same value to the bit.
fn render_tile(
    camera: &CameraModel,
    cone: RayCone,
    integrator: &Integrator,
    opts: &RenderOptions,
    tile: Window,
    counts: &mut RayCounts,
) -> Vec<(Vec3, Primary)> {
    let width = (tile.x1 - tile.x0) as usize;
    let at = |x: u32, y: u32| (y - tile.y0) as usize * width + (x - tile.x0) as usize;
    let mut pixels = vec![(Vec3::ZERO, Primary::MISS); tile.pixels() as usize];
    // The blocks cover [x0, x_end) × [y0, y_end).
    let x_end = tile.x1 - (tile.x1 - tile.x0) % 2;
    let y_end = tile.y1 - (tile.y1 - tile.y0) % 2;
    for y in (tile.y0..y_end).step_by(2) {
        for x in (tile.x0..x_end).step_by(2) {
            let block = [(x, y), (x + 1, y), (x, y + 1), (x + 1, y + 1)];
            let values = render_block(camera, cone, integrator, opts, block, counts);
            for ((x, y), value) in block.into_iter().zip(values) {
                pixels[at(x, y)] = value;
            }
        }
    }
    for y in tile.y0..tile.y1 {
        for x in tile.x0..tile.x1 {
            if x >= x_end || y >= y_end {
                pixels[at(x, y)] = render_pixel(camera, cone, integrator, opts, x, y, counts);
            }
        }
    }
    pixels
}

/// Four pixels, [`render_pixel`]'s values bit for bit: each pixel's generator draws its
/// sample positions first, then the four pixels' k-th samples are traced together
/// ([`Integrator::camera_sample4`], which draws from each pixel's generator in its own
/// order), and each pixel sums its samples in their order.
fn render_block(
    camera: &CameraModel,
    cone: RayCone,
    integrator: &Integrator,
    opts: &RenderOptions,
    block: [(u32, u32); LANES],
    counts: &mut RayCounts,
) -> [(Vec3, Primary); LANES] {
    let mut rngs = block.map(|(x, y)| Rng::for_pixel(opts.seed, x, y));
    let ray = |(x, y): (u32, u32), (sx, sy): (f32, f32)| camera.ray(x as f32 + sx, y as f32 + sy);
    if opts.spp <= 1 {
        let rays = block.map(|p| ray(p, (0.5, 0.5)));
        return integrator
            .camera_sample4(&rays, cone, &mut rngs, counts)
            .map(one_sample);
    }
    let samples: [Vec<(f32, f32)>; LANES] =
        std::array::from_fn(|l| pixel_samples(opts.spp, &mut rngs[l]));
    let mut sum = [Vec3::ZERO; LANES];
    let mut best = [(f32::INFINITY, Primary::MISS); LANES];
    let mut positions = samples.each_ref().map(|s| s.iter().copied());
    // Every pixel draws the same number of positions, `spp`.
    while let [Some(a), Some(b), Some(c), Some(d)] = positions.each_mut().map(Iterator::next) {
        let at = [a, b, c, d];
        let rays = std::array::from_fn(|l| ray(block[l], at[l]));
        let out = integrator.camera_sample4(&rays, cone, &mut rngs, counts);
        for l in 0..LANES {
            let (value, primary) = out[l];
            sum[l] += value;
            let d = centre_distance(at[l]);
            if d < best[l].0 {
                best[l] = (d, primary);
            }
        }
    }
    std::array::from_fn(|l| (sum[l] / samples[l].len() as f32, best[l].1))
}

/// A pixel of one sample: the mean [`render_pixel`] takes of many, which turns −0 into +0.
fn one_sample((l, primary): (Vec3, Primary)) -> (Vec3, Primary) {
    (Vec3::ZERO + l, primary)
}

/// How far a sample position lies from its pixel's centre (squared), to pick the sample
/// whose AOVs the pixel keeps.
fn centre_distance((sx, sy): (f32, f32)) -> f32 {
    (sx - 0.5).powi(2) + (sy - 0.5).powi(2)
}

/// One pixel: the box-filtered mean of its samples. Its generator is seeded from
/// (seed, x, y) only, so its value is independent of tiles, threads and crops. The AOVs
/// come from the sample nearest the pixel centre (averaging depths or object ids across
/// an edge would describe no surface). `cone` is each sample's ray cone
/// ([`CameraModel::cone`] shared by the `opts.spp` samples).
pub fn render_pixel(
    camera: &CameraModel,
    cone: RayCone,
    integrator: &Integrator,
    opts: &RenderOptions,
    x: u32,
    y: u32,
    counts: &mut RayCounts,
) -> (Vec3, Primary) {
    let mut rng = Rng::for_pixel(opts.seed, x, y);
    // The centre (`pixel_samples`' answer for one sample) needs no list: a heap list per
    // pixel was 3.6 % of a 1-spp render's instructions.
    if opts.spp <= 1 {
        let ray = camera.ray(x as f32 + 0.5, y as f32 + 0.5);
        return one_sample(integrator.camera_sample(&ray, cone, &mut rng, counts));
    }
    let samples = pixel_samples(opts.spp, &mut rng);
    let mut sum = Vec3::ZERO;
    let mut best = (f32::INFINITY, Primary::MISS);
    for &(sx, sy) in &samples {
        let ray = camera.ray(x as f32 + sx, y as f32 + sy);
        let (l, primary) = integrator.camera_sample(&ray, cone, &mut rng, counts);
        sum += l;
        let d = centre_distance((sx, sy));
        if d < best.0 {
            best = (d, primary);
        }
    }
    (sum / samples.len() as f32, best.1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tiles_cover_the_window_once() {
        let w = Window {
            x0: 3,
            y0: 5,
            x1: 70,
            y1: 41,
        };
        let t = tiles(w, 32);
        let area: u64 = t.iter().map(|t| t.pixels()).sum();
        assert_eq!(area, w.pixels());
        assert_eq!(t.len(), 3 * 2);
        assert!(t
            .iter()
            .all(|t| t.x0 >= 3 && t.x1 <= 70 && t.y0 >= 5 && t.y1 <= 41));
    }
}
