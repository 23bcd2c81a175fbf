//! Build-parameter experiments:
//! `cargo run --release -p bench --bin kdtune -- [--bins B] KT KI BONUS MAX_DEPTH LEAF_SIZE FILE…`
//! builds each soup or OBJ (or `gen:N`, kdbench's generated scene of N triangles) with
//! those parameters and prints build time (best of up to 9 builds, all threads), primary,
//! shadow, random and surface-origin (closest/any hit) Mrays/s (best of 15, 1 thread), the tree's statistics and a
//! digest of its nodes (equal digests, identical trees). With `--bins B` the tree comes from
//! the approximate builder that prices only B slab boundaries per axis
//! ([`bench::binned_build`]) instead of the product's exact plane search. Only ratios within one run mean
//! anything on a noisy machine.

use anyhow::{bail, Context, Result};
use bench::{rays, scenes};
use formats::BuildParams;
use kdtree::Accel;
use std::path::Path;
use std::time::Instant;

fn main() {
    if let Err(e) = run() {
        eprintln!("kdtune: {e:#}");
        std::process::exit(1);
    }
}

/// Fastest of `runs` timed calls (at least one), and the last call's result.
fn best_of<T>(runs: usize, mut f: impl FnMut() -> T) -> (f64, T) {
    let t = Instant::now();
    let mut out = f();
    let mut best = t.elapsed().as_secs_f64();
    for _ in 1..runs {
        let t = Instant::now();
        out = f();
        best = best.min(t.elapsed().as_secs_f64());
    }
    (best, out)
}

fn run() -> Result<()> {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let bins = match args.iter().position(|a| a == "--bins") {
        Some(i) if i + 1 < args.len() => {
            let b: usize = args[i + 1]
                .parse()
                .with_context(|| format!("--bins {:?} is not a count", args[i + 1]))?;
            if b < 2 {
                bail!("--bins {b}: at least 2 slabs");
            }
            args.drain(i..i + 2);
            Some(b)
        }
        Some(_) => bail!("--bins needs a count"),
        None => None,
    };
    if args.len() < 6 {
        bail!("usage: kdtune [--bins B] KT KI BONUS MAX_DEPTH LEAF_SIZE FILE…");
    }
    let num = |i: usize| -> Result<f32> {
        args[i]
            .parse()
            .with_context(|| format!("argument {}: {:?} is not a number", i + 1, args[i]))
    };
    let p = BuildParams {
        traversal_cost: num(0)?,
        intersect_cost: num(1)?,
        empty_bonus: num(2)?,
        max_depth: num(3)? as u32,
        leaf_size: num(4)? as u32,
    };
    for arg in &args[5..] {
        let path = Path::new(arg);
        let s = if let Some(n) = arg.strip_prefix("gen:") {
            let n = n
                .parse()
                .with_context(|| format!("{arg}: not gen:TRIANGLES"))?;
            scenes::generated(n)
        } else if path.extension().is_some_and(|e| e == "soup") {
            scenes::load_soup(path)?
        } else {
            scenes::load_obj(path)?
        };
        let tris = &s.triangles;
        let hash = formats::soup::geometry_hash(tris);
        let builds = (3_000_000 / tris.len().max(1)).clamp(1, 9);
        let (build, kd) = best_of(builds, || match bins {
            Some(b) => bench::binned_build::build_binned(tris, &p, b, hash),
            None => kdtree::build(tris, &p, hash),
        });
        let a = Accel::from_triangles(tris, &kd)?;
        let b = scenes::bounds(tris);
        let prim = rays::primary(&s.view.unwrap_or(rays::framing(b)), 512);
        let (tp, hits) = best_of(15, || {
            prim.iter()
                .map(|r| a.intersect(r).map(|h| (h.prim, h.u, h.v)))
                .collect::<Vec<_>>()
        });
        let sh = rays::shadow(tris, &hits, rays::light_above(b), b);
        let (ts, occluded) = best_of(15, || sh.iter().filter(|r| a.occluded(r)).count());
        let random = rays::random(b, 1 << 16, 7);
        let (tr, _) = best_of(15, || random.iter().filter_map(|r| a.intersect(r)).count());
        let light = rays::light_above(b);
        let sl = rays::surface(tris, 1 << 16, 11, |_, _| rays::Toward::Point(light));
        let (tsl, _) = best_of(15, || sl.iter().filter_map(|r| a.intersect(r)).count());
        let (tsla, _) = best_of(15, || sl.iter().filter(|r| a.occluded(r)).count());
        let sh2 = rays::surface(tris, 1 << 16, 12, |rng, n| {
            rays::Toward::Direction(rays::hemisphere(rng, n))
        });
        let (tsh, _) = best_of(15, || sh2.iter().filter_map(|r| a.intersect(r)).count());
        let (tsha, _) = best_of(15, || sh2.iter().filter(|r| a.occluded(r)).count());
        let mr = |n: usize, t: f64| n as f64 / t / 1e6;
        let st = &kd.stats;
        // FNV-1a over the nodes and leaf lists: equal digests mean an identical tree.
        let digest = kd
            .nodes
            .iter()
            .flat_map(|n| [n.flags, n.data])
            .chain(kd.leaf_tris.iter().copied())
            .fold(0xcbf2_9ce4_8422_2325u64, |h, w| {
                (h ^ w as u64).wrapping_mul(0x100_0000_01b3)
            });
        println!(
            "{}: {} triangles, build {:.1} ms, primary {:.3} Mrays/s, shadow {:.3} Mrays/s \
             ({occluded} occluded), random {:.3} Mrays/s, surface→light {:.3}/{:.3} any, \
             surface→hemisphere {:.3}/{:.3} any Mrays/s, nodes {}, leaves {}, max leaf {}, \
             depth {}, refs/tri {:.2}, SAH {:.1}, bytes/tri {:.1}, tree {digest:016x}",
            s.name,
            tris.len(),
            build * 1e3,
            prim.len() as f64 / tp / 1e6,
            sh.len() as f64 / ts / 1e6,
            random.len() as f64 / tr / 1e6,
            mr(sl.len(), tsl),
            mr(sl.len(), tsla),
            mr(sh2.len(), tsh),
            mr(sh2.len(), tsha),
            st.nodes,
            st.leaves,
            st.max_leaf_triangles,
            st.max_depth,
            st.references as f64 / st.triangles.max(1) as f64,
            st.sah_cost,
            a.bytes_per_triangle()
        );
    }
    Ok(())
}
