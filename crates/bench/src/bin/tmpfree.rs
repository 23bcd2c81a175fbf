use bench::{rays, scenes};
use formats::BuildParams;
use kdtree::{Accel, Ray};
use std::path::Path;
fn main() {
    let reps: usize = std::env::var("REPS").map_or(5, |v| v.parse().unwrap());
    let arg = std::env::args().nth(1).unwrap();
    let path = Path::new(&arg);
    let s = if path.extension().is_some_and(|e| e == "soup") {
        scenes::load_soup(path).unwrap()
    } else {
        scenes::load_obj(path).unwrap()
    };
    let tris = &s.triangles;
    let kd = kdtree::build(
        tris,
        &BuildParams::default(),
        formats::soup::geometry_hash(tris),
    );
    let a = Accel::from_triangles(tris, &kd).unwrap();
    let b = scenes::bounds(tris);
    let prim = rays::primary(&s.view.unwrap_or(rays::framing(b)), 512);
    let hits: Vec<_> = prim
        .iter()
        .map(|r| a.intersect(r).map(|h| (h.prim, h.u, h.v)))
        .collect();
    let sh = rays::shadow(tris, &hits, rays::light_above(b), b);
    let free: Vec<Ray> = sh.iter().filter(|r| !a.occluded(r)).copied().collect();
    let mut best = f64::MAX;
    for _ in 0..reps {
        let t = std::time::Instant::now();
        let n = free.iter().filter(|r| a.occluded(r)).count();
        std::hint::black_box(n);
        best = best.min(t.elapsed().as_secs_f64());
    }
    println!(
        "{} free {:.2} Mr/s",
        free.len(),
        free.len() as f64 / best / 1e6
    );
}
