//! Timing: wall-clock medians over repeated runs, inside rayon pools of a fixed size.

use crate::error::BenchError;
use rayon::prelude::*;
use std::time::Instant;

/// A rayon pool of exactly `threads` workers. Builds and traversals run inside
/// `pool.install`, so the k-d tree's own rayon calls use it too.
pub fn pool(threads: usize) -> Result<rayon::ThreadPool, BenchError> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .thread_name(move |i| format!("bench-{threads}t-{i}"))
        .build()
        .map_err(|e| BenchError::Pool {
            threads,
            detail: e.to_string(),
        })
}

/// Median of a non-empty list (the mean of the middle two for an even count).
pub fn median(mut xs: Vec<f64>) -> f64 {
    xs.sort_by(f64::total_cmp);
    let n = xs.len();
    match n {
        0 => f64::NAN,
        _ if n % 2 == 1 => xs[n / 2],
        _ => 0.5 * (xs[n / 2 - 1] + xs[n / 2]),
    }
}

/// Run `f` `runs` times (at least once); return the median wall time in seconds and the
/// last run's result.
pub fn timed<T>(runs: usize, mut f: impl FnMut() -> T) -> (f64, T) {
    let mut times = Vec::with_capacity(runs);
    let mut last = None;
    for _ in 0..runs.max(1) {
        let start = Instant::now();
        let out = f();
        times.push(start.elapsed().as_secs_f64());
        // Drop the previous result outside the timed region.
        drop(last.replace(out));
    }
    (median(times), last.expect("ran at least once"))
}

/// CPU seconds (user + system, all threads) this process has used so far, from
/// /proc/self/stat in clock ticks (USER_HZ, 100 on Linux); None elsewhere.
pub fn process_cpu_seconds() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    // Fields after the command name, which is in parentheses and may hold spaces.
    let rest = stat.rsplit_once(')')?.1;
    let f: Vec<&str> = rest.split_whitespace().collect();
    let utime: f64 = f.get(11)?.parse().ok()?;
    let stime: f64 = f.get(12)?.parse().ok()?;
    Some((utime + stime) / 100.0)
}

/// Rays per parallel task: small enough for work stealing to balance the two cores,
/// large enough that task overhead is noise.
const CHUNK: usize = 256;

/// Answer every ray with `f` on `pool`'s threads, results in ray order. Each chunk of rays
/// runs inside `around` (a contender's floating-point mode, see `Tracer::in_mode`).
pub fn trace<R, T>(
    pool: &rayon::ThreadPool,
    rays: &[R],
    around: impl Fn(&mut dyn FnMut()) + Sync,
    f: impl Fn(&R) -> T + Sync,
) -> Vec<T>
where
    R: Sync,
    T: Send + Copy + Default,
{
    let mut out = vec![T::default(); rays.len()];
    pool.install(|| {
        out.par_chunks_mut(CHUNK)
            .zip(rays.par_chunks(CHUNK))
            .for_each(|(o, r)| {
                around(&mut || {
                    for (slot, ray) in o.iter_mut().zip(r.iter()) {
                        *slot = f(ray);
                    }
                })
            })
    });
    out
}

/// [`trace`] `packet` rays per call: `many` on each run of `packet` consecutive rays
/// (and on the shorter run left at the end), answers into its slice, in ray order.
pub fn trace_packets<R, T>(
    pool: &rayon::ThreadPool,
    rays: &[R],
    packet: usize,
    around: impl Fn(&mut dyn FnMut()) + Sync,
    many: impl Fn(&[R], &mut [T]) + Sync,
) -> Vec<T>
where
    R: Sync,
    T: Send + Copy + Default,
{
    let packet = packet.max(1);
    // Whole packets per parallel task, so no packet is split between two.
    let chunk = CHUNK.next_multiple_of(packet);
    let mut out = vec![T::default(); rays.len()];
    pool.install(|| {
        out.par_chunks_mut(chunk)
            .zip(rays.par_chunks(chunk))
            .for_each(|(o, r)| {
                around(&mut || {
                    for (o, r) in o.chunks_mut(packet).zip(r.chunks(packet)) {
                        many(r, o);
                    }
                })
            })
    });
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn median_of_odd_and_even_lists() {
        assert_eq!(median(vec![3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(vec![4.0, 1.0, 3.0, 2.0]), 2.5);
    }

    #[test]
    fn trace_keeps_ray_order_on_two_threads() {
        let p = pool(2).unwrap();
        let input: Vec<u32> = (0..10_000).collect();
        let out = trace(&p, &input, |run| run(), |x| x * 2);
        assert!(out.iter().enumerate().all(|(i, &v)| v == 2 * i as u32));
    }

    #[test]
    fn packets_keep_ray_order_and_hand_over_whole_runs() {
        let p = pool(2).unwrap();
        let input: Vec<u32> = (0..1000).collect();
        for packet in [4, 8, 16] {
            let out = trace_packets(
                &p,
                &input,
                packet,
                |run| run(),
                |r, o| {
                    // Every run but the last has exactly `packet` rays and starts at a multiple.
                    assert!(r.len() == packet || r[0] as usize == 1000 / packet * packet);
                    assert_eq!(r[0] as usize % packet, 0);
                    for (o, x) in o.iter_mut().zip(r) {
                        *o = x * 3;
                    }
                },
            );
            assert!(out.iter().enumerate().all(|(i, &v)| v == 3 * i as u32));
        }
    }

    #[test]
    fn process_cpu_time_grows_with_work() {
        // Spin until the clock-tick counter moves (10 ms of CPU); give up after 5 s.
        let a = process_cpu_seconds().unwrap();
        let start = Instant::now();
        let mut x = 0u64;
        let mut b = a;
        while b == a && start.elapsed().as_secs() < 5 {
            for _ in 0..100_000 {
                x = std::hint::black_box(x.wrapping_mul(6364136223846793005).wrapping_add(1));
            }
            b = process_cpu_seconds().unwrap();
        }
        assert!(b > a, "CPU time stayed at {a} s");
        assert!(b - a < 5.0 * std::thread::available_parallelism().map_or(1, |n| n.get()) as f64);
    }

    #[test]
    fn timed_returns_the_last_result() {
        let mut n = 0;
        let (secs, last) = timed(3, || {
            n += 1;
            n
        });
        assert_eq!(last, 3);
        assert!(secs >= 0.0);
    }
}
