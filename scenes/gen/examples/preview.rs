//! `cargo run -p scenegen --example preview -- OUT.png`: the baseline models drawn with a
//! z-buffer from the front, the side and above, one row per model, to check by eye that
//! each looks like what it is named after (no renderer needed).

use glam::{Mat3, Vec3};
use scenegen::mesh::Mesh;

const CELL: usize = 220;

fn main() -> anyhow::Result<()> {
    let out = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "models.png".into());
    let models = scenegen::models::all();
    let views = [
        Mat3::IDENTITY, // front (model faces +Z, camera at +Z)
        Mat3::from_rotation_y(-std::f32::consts::FRAC_PI_2), // side
        Mat3::from_rotation_x(std::f32::consts::FRAC_PI_2), // top
        Mat3::from_rotation_x(0.4) * Mat3::from_rotation_y(-0.7), // three-quarter
    ];
    let (w, h) = (CELL * views.len(), CELL * models.len());
    let mut img = vec![30u8; w * h * 3];
    for (row, model) in models.iter().enumerate() {
        for (col, view) in views.iter().enumerate() {
            draw(&model.mesh, *view, &mut img, w, col * CELL, row * CELL);
        }
    }
    let file = std::fs::File::create(&out)?;
    let mut enc = png::Encoder::new(std::io::BufWriter::new(file), w as u32, h as u32);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    enc.write_header()?.write_image_data(&img)?;
    println!("wrote {out}");
    Ok(())
}

fn draw(m: &Mesh, view: Mat3, img: &mut [u8], w: usize, x0: usize, y0: usize) {
    let pts: Vec<Vec3> = m.positions.iter().map(|&p| view * p).collect();
    let (lo, hi) = pts
        .iter()
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(l, h), &p| {
            (l.min(p), h.max(p))
        });
    let size = (hi - lo).max_element().max(1e-6);
    let scale = (CELL as f32 - 20.0) / size;
    let centre = (lo + hi) * 0.5;
    let to_px = |p: Vec3| {
        Vec3::new(
            (p.x - centre.x) * scale + CELL as f32 / 2.0,
            CELL as f32 / 2.0 - (p.y - centre.y) * scale,
            p.z,
        )
    };
    let light = Vec3::new(0.4, 0.6, 0.7).normalize();
    let mut depth = vec![f32::NEG_INFINITY; CELL * CELL];
    for t in &m.triangles {
        let [a, b, c] = t.map(|i| pts[i as usize]);
        let n = (b - a).cross(c - a).normalize_or_zero();
        if n.z <= 0.0 {
            continue; // back face
        }
        let shade = 0.25 + 0.75 * n.dot(light).max(0.0);
        let [pa, pb, pc] = [to_px(a), to_px(b), to_px(c)];
        let min_x = pa.x.min(pb.x).min(pc.x).floor().max(0.0) as usize;
        let max_x = (pa.x.max(pb.x).max(pc.x).ceil() as usize).min(CELL - 1);
        let min_y = pa.y.min(pb.y).min(pc.y).floor().max(0.0) as usize;
        let max_y = (pa.y.max(pb.y).max(pc.y).ceil() as usize).min(CELL - 1);
        let area = (pb.x - pa.x) * (pc.y - pa.y) - (pb.y - pa.y) * (pc.x - pa.x);
        if area.abs() < 1e-9 {
            continue;
        }
        for y in min_y..=max_y {
            for x in min_x..=max_x {
                let (px, py) = (x as f32 + 0.5, y as f32 + 0.5);
                let w0 = ((pb.x - px) * (pc.y - py) - (pb.y - py) * (pc.x - px)) / area;
                let w1 = ((pc.x - px) * (pa.y - py) - (pc.y - py) * (pa.x - px)) / area;
                let w2 = 1.0 - w0 - w1;
                if w0 < 0.0 || w1 < 0.0 || w2 < 0.0 {
                    continue;
                }
                let z = w0 * pa.z + w1 * pb.z + w2 * pc.z;
                let k = y * CELL + x;
                if z > depth[k] {
                    depth[k] = z;
                    let v = (shade * 255.0) as u8;
                    let o = ((y0 + y) * w + x0 + x) * 3;
                    img[o..o + 3].copy_from_slice(&[v, v, v]);
                }
            }
        }
    }
}
