//! Rays spawned the way the renderer spawns them, with tmin = `f32::MIN_POSITIVE`, are
//! traced without computing a single subnormal number: Intel cores produce each one
//! through a microcode assist, and padding that tmin at every node step once made such
//! rays 1.5–2.6× slower there. The test traces them with the processor's underflow
//! exception unmasked, in a child process: any subnormal (tiny) result then traps, and the
//! child dies of SIGFPE. (Comparisons with the subnormal padding constant produce no
//! result, and do not trap.)

#![cfg(target_arch = "x86_64")]

use formats::BuildParams;
use glam::Vec3;
use kdtree::testkit::{grid, sphere, Rng};
use kdtree::{Accel, Ray, LANES};
use std::arch::asm;
use std::process::Command;

/// Set in the child process, which traces with underflow trapping.
const CHILD: &str = "UNITRACE_SUBNORMAL_CHILD";

/// MXCSR's underflow mask bit: clear, a tiny result raises the exception.
const UNDERFLOW_MASK: u32 = 1 << 11;

fn mxcsr() -> u32 {
    let mut m = 0u32;
    // SAFETY: stores the 4-byte control and status word into `m`.
    unsafe { asm!("stmxcsr [{}]", in(reg) &mut m, options(nostack, preserves_flags)) };
    m
}

fn set_mxcsr(m: u32) {
    // SAFETY: loads a control and status word built from the thread's own.
    unsafe { asm!("ldmxcsr [{}]", in(reg) &m, options(nostack, preserves_flags)) };
}

/// Four rays from one point just off a random triangle, into the hemisphere of its
/// outward normal within a narrow cone (as a soft shadow's samples leave a point), as the
/// renderer spawns them: origin moved off the surface, tmin = `f32::MIN_POSITIVE`; every
/// other point's rays end at a light instead of running on.
fn spawned(tris: &[[Vec3; 3]], rng: &mut Rng, light: Vec3) -> [Ray; LANES] {
    let t = tris[(rng.next_u64() % tris.len() as u64) as usize];
    let (mut a, mut b) = (rng.unit(), rng.unit());
    if a + b > 1.0 {
        (a, b) = (1.0 - a, 1.0 - b);
    }
    let p = t[0] + (t[1] - t[0]) * a + (t[2] - t[0]) * b;
    let mut n = (t[1] - t[0]).cross(t[2] - t[0]).normalize();
    if n.dot(p) < 0.0 && n.y <= 0.0 {
        n = -n;
    }
    let o = p + n * 1e-4;
    let toward = if rng.unit() < 0.5 {
        (light - o).normalize()
    } else {
        let d = rng.dir();
        if d.dot(n) < 0.0 {
            -d
        } else {
            d
        }
    };
    let to_light = rng.unit() < 0.5;
    std::array::from_fn(|_| {
        let dir = (toward + rng.dir() * 0.02).normalize();
        let tmax = if to_light {
            (light - o).length()
        } else {
            f32::INFINITY
        };
        Ray::new(o, dir, f32::MIN_POSITIVE, tmax)
    })
}

#[test]
fn spawned_rays_compute_no_subnormal_number() {
    if std::env::var_os(CHILD).is_some() {
        trace_spawned_rays_with_underflow_trapping();
        return;
    }
    let exe = std::env::current_exe().expect("the test binary's path");
    let out = Command::new(exe)
        .args([
            "--exact",
            "subnormals::spawned_rays_compute_no_subnormal_number",
            "--test-threads=1",
        ])
        .env(CHILD, "1")
        .output()
        .expect("the test binary runs again");
    assert!(
        out.status.success(),
        "tracing spawned rays computed a subnormal number (the child ended with {:?}):\n{}",
        out.status,
        String::from_utf8_lossy(&out.stdout)
    );
    let said = String::from_utf8_lossy(&out.stdout);
    assert!(said.contains("1 passed"), "the child ran no test:\n{said}");
}

fn trace_spawned_rays_with_underflow_trapping() {
    let mut tris = sphere(Vec3::new(0.0, 1.0, 0.0), 1.0, 24, 48);
    tris.extend(
        grid(16, 8.0, 0.0)
            .iter()
            .map(|t| t.map(|v| v - Vec3::new(4.0, 0.0, 4.0))),
    );
    let accel = Accel::build(&tris, &BuildParams::default());
    let light = Vec3::new(2.0, 6.0, 1.0);
    let mut rng = Rng(7);
    let sets: Vec<[Ray; LANES]> = (0..2000).map(|_| spawned(&tris, &mut rng, light)).collect();
    let mut answers = 0usize;
    let mode = mxcsr();
    set_mxcsr(mode & !UNDERFLOW_MASK);
    for rays in &sets {
        for ray in rays {
            answers += accel.intersect(ray).is_some() as usize;
            answers += accel.occluded(ray) as usize;
            answers += accel.occluded_filtered_in_order(ray, |_, front| front) as usize;
        }
        answers += accel.intersect4(rays).iter().flatten().count();
        answers += accel.occluded4(rays).iter().filter(|&&b| b).count();
        let in_order = accel.occluded4_filtered_in_order(rays, |_, _, front| front);
        answers += in_order.iter().filter(|&&b| b).count();
    }
    set_mxcsr(mode);
    // The rays do reach things: the floor and the sphere are hit, some rays blocked.
    assert!(answers > 4000 && answers < 6 * 8000, "{answers} answers");
}
