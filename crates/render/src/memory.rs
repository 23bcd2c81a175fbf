//! Refuse a render that cannot fit in memory before any work starts.

use crate::{RenderError, RenderOptions};

/// Bytes per rendered pixel besides the AOVs: the frame's colour (12), the tiles' results
/// before they are gathered (colour + first-hit record, 44), the RGBA planes handed to the
/// EXR encoder (16) and the encoded file, at worst as large as its planes (16).
const BASE_BYTES_PER_PIXEL: u64 = 12 + 44 + 16 + 16;

/// Estimated peak memory of a render of `opts` (the soup and tree not included).
pub fn estimate_bytes(opts: &RenderOptions) -> u64 {
    let aov_channels = opts.aovs.channel_count() as u64;
    // Each AOV channel: its frame buffer, its plane and its share of the encoded file.
    let per_pixel = BASE_BYTES_PER_PIXEL + aov_channels * (4 + 4 + 4);
    opts.window().pixels().saturating_mul(per_pixel)
}

/// Memory this process may still use, in bytes: Linux's MemAvailable, lowered to the
/// cgroup's remaining allowance when one is set. None where neither can be read.
pub fn available_bytes() -> Option<u64> {
    let meminfo = std::fs::read_to_string("/proc/meminfo").ok()?;
    let avail_kib: u64 = meminfo
        .lines()
        .find_map(|l| l.strip_prefix("MemAvailable:"))?
        .trim()
        .trim_end_matches("kB")
        .trim()
        .parse()
        .ok()?;
    let mut avail = avail_kib * 1024;
    let read = |p: &str| -> Option<u64> { std::fs::read_to_string(p).ok()?.trim().parse().ok() };
    if let (Some(max), Some(cur)) = (
        read("/sys/fs/cgroup/memory.max"),
        read("/sys/fs/cgroup/memory.current"),
    ) {
        avail = avail.min(max.saturating_sub(cur));
    }
    Some(avail)
}

/// `need` and `available` bytes in GiB when `need` exceeds `available` (never when the
/// available memory is unknown): what every refusal for memory reports.
pub fn short_of(need: u64, available: Option<u64>) -> Option<(f64, f64)> {
    let gib = |b: u64| b as f64 / (1u64 << 30) as f64;
    available
        .filter(|&avail| need > avail)
        .map(|avail| (gib(need), gib(avail)))
}

/// Err when the render's estimate exceeds `available` bytes (no check when None).
pub fn check(opts: &RenderOptions, available: Option<u64>) -> Result<(), RenderError> {
    match short_of(estimate_bytes(opts), available) {
        Some((need_gib, available_gib)) => Err(RenderError::OutOfMemory {
            width: opts.window().width(),
            height: opts.window().height(),
            channels: 4 + opts.aovs.channel_count(),
            need_gib,
            available_gib,
        }),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::AovSet;

    const GIB: u64 = 1 << 30;

    #[test]
    fn a_16k_render_with_aovs_needs_more_than_32_gib() {
        let opts = RenderOptions {
            width: 16384,
            height: 16384,
            aovs: AovSet::all(),
            ..Default::default()
        };
        assert!(estimate_bytes(&opts) > 32 * GIB);
        assert!(matches!(
            check(&opts, Some(32 * GIB)),
            Err(RenderError::OutOfMemory { .. })
        ));
        assert!(check(&opts, Some(128 * GIB)).is_ok());
    }

    #[test]
    fn a_crop_needs_only_its_window() {
        let opts = RenderOptions {
            width: 16384,
            height: 16384,
            aovs: AovSet::all(),
            crop: Some(crate::Window {
                x0: 0,
                y0: 0,
                x1: 1024,
                y1: 1024,
            }),
            ..Default::default()
        };
        assert!(estimate_bytes(&opts) < GIB);
        assert!(check(&opts, Some(GIB)).is_ok());
    }

    #[test]
    fn this_machine_reports_its_memory() {
        let a = available_bytes().expect("Linux has /proc/meminfo");
        assert!(a > 0);
    }
}
