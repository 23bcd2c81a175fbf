//! The report's header: when and where it ran (machine facts, load) and what it measured.

use crate::config::Config;

/// Machine and run description for the report's header.
pub fn header(cfg: &Config) -> Vec<String> {
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split_once(':'))
                .map(|(_, v)| v.trim().to_string())
        })
        .unwrap_or_else(|| "unknown".into());
    let nproc = std::thread::available_parallelism().map_or(0, |n| n.get());
    let p = &cfg.params;
    let mut h = vec![
        format!("date: {}", utc_now()),
        format!(
            "machine: nproc {nproc}, CPU {cpu}; load average at start {} (other processes share the cores: compare contenders within a run, not across runs)",
            load_average()
        ),
        format!("command: `{}`", cfg.command),
        format!(
            "kdtree build parameters: traversal cost {}, intersection cost {}, empty bonus {}, max depth {}, leaf size {}",
            p.traversal_cost,
            p.intersect_cost,
            p.empty_bonus,
            if p.max_depth == 0 { "auto".to_string() } else { p.max_depth.to_string() },
            p.leaf_size
        ),
        format!(
            "rays: primary {0}×{0} camera (the soup's when it has one, else a 45° view framing the bounds); \
             primary ×{2}: the same rays in {3} pixel blocks, one packet query per block (k-d tree `intersect4` {4}, Embree `rtcIntersect{2}`); \
             shadow rays from every primary hit of the k-d tree to a light above the scene (any-hit); \
             shadow ×{2}: those of the primary ×{2} hits, in block order, one packet query per block (k-d tree `occluded4` {4}, Embree `rtcOccluded{2}`); \
             soft: from every {2}th primary hit facing the sun (toward that light), {2} soft-shadow samples within a {5}° cone, spawned as the renderer spawns them (any-hit); \
             soft ×{2}: the same, one packet query per hit (k-d tree `occluded4` on each four, Embree `rtcOccluded{2}`); \
             {1} random rays (origins uniform in the bounds, directions uniform on the sphere)",
            cfg.image,
            cfg.random_rays,
            cfg.packet,
            match cfg.packet {
                4 => "2×2",
                8 => "4×2 (two 2×2)",
                _ => "4×4 (four 2×2)",
            },
            match cfg.packet {
                4 => "once per block",
                8 => "on each 2×2 half",
                _ => "on each 2×2 quarter",
            },
            crate::rays::SUN_DEGREES,
        ),
        format!(
            "timing: median of {} runs (traversal runs go round-robin over the contenders); threads {:?} (rayon pools of that size; Embree builds on a device of that many threads); \
             brute force only on scenes ≤ {} triangles, on {} rays of each set",
            cfg.runs.max(1),
            cfg.threads,
            cfg.brute_max_triangles,
            cfg.brute_rays
        ),
    ];
    h.extend(cfg.remarks.iter().cloned());
    #[cfg(feature = "embree")]
    {
        let version = crate::embree::Device::new(1)
            .map(|d| d.version())
            .unwrap_or_else(|e| format!("unavailable ({e})"));
        h.push(format!(
            "Embree {version}: build quality {}, scene flags none, rtcIntersect1 / rtcOccluded1 with the incoherent context flag, rtcIntersect{p} / rtcOccluded{p} with the coherent one for primary ×{p} and shadow ×{p}; \
             build time includes filling its vertex and index buffers; bytes/tri from its memory monitor",
            cfg.embree_quality.name(),
            p = cfg.packet,
        ));
    }
    #[cfg(not(feature = "embree"))]
    h.push("Embree: not measured (build with `--features embree`)".into());
    h
}

/// The 1, 5 and 15 minute load averages from /proc/loadavg ("unknown" elsewhere).
pub fn load_average() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .ok()
        .map(|s| s.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
        .filter(|s| !s.is_empty())
        .unwrap_or_else(|| "unknown".into())
}

/// `YYYY-MM-DD HH:MM UTC` from the system clock (civil-from-days, Howard Hinnant).
pub fn utc_now() -> String {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs()) as i64;
    let (days, rem) = (secs.div_euclid(86400), secs.rem_euclid(86400));
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + i64::from(m <= 2);
    format!(
        "{y:04}-{m:02}-{d:02} {:02}:{:02} UTC",
        rem / 3600,
        (rem % 3600) / 60
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn utc_now_is_well_formed() {
        let s = utc_now();
        assert_eq!(s.len(), "2026-11-22 03:20 UTC".len(), "{s}");
        assert!(s.starts_with("20") && s.ends_with(" UTC"));
    }
}
