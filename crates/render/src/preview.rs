//! The PNG preview: exposure, sRGB encoding, 8 bits.

use crate::{Frame, RenderError};
use glam::Vec3;
use std::path::Path;

/// The sRGB opto-electronic transfer function (IEC 61966-2-1) on a linear value in [0, 1].
pub fn srgb_oetf(c: f32) -> f32 {
    if c <= 0.003_130_8 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}

/// One linear channel to an 8-bit sRGB value: scale by 2^exposure, clamp to [0, 1],
/// encode, round.
pub fn to_8bit(linear: f32, exposure: f32) -> u8 {
    Srgb8::get().encode(linear * exposure.exp2())
}

/// [`to_8bit`] through the transfer function itself, on a value in [0, 1]: what
/// [`Srgb8`] is built from, and gives back exactly.
fn encode_8bit(v: f32) -> u8 {
    (srgb_oetf(v) * 255.0 + 0.5) as u8
}

/// Buckets of [`Srgb8`]: [0, 1] in equal steps, few enough that a bucket's table stays in
/// the L1 cache, many enough that no bucket holds more than one threshold (the steepest
/// slope, 12.92 × 255 below the linear segment's end, crosses 0.8 bytes per bucket).
const BUCKETS: usize = 4096;

/// [`to_8bit`] without `powf`, which was most of what the preview cost. `encode_8bit` is
/// non-decreasing on [0, 1], so its byte is the count of thresholds at or below the
/// value, where threshold k is the least value it takes to k or more. That holds on every
/// f32 there: `cargo test --release -p render -- --ignored
/// every_f32_in_0_1_encodes_to_a_non_decreasing_byte` evaluates it on all 1 065 353 217
/// bit patterns from 0 to 1.0, each against the one before, and finds no decrease (x86-64,
/// glibc 2.36's `powf`). The thresholds are found with the platform's own `powf` when
/// first needed.
struct Srgb8 {
    /// Entry k, from 1 to 255, is threshold k; entry 0 is never read, and entries past
    /// 255 are infinite, so that a count can look two further without a bounds check.
    thresholds: [f32; 258],
    /// The count at each bucket's least value.
    buckets: [u8; BUCKETS + 1],
}

impl Srgb8 {
    fn get() -> &'static Srgb8 {
        static TABLE: std::sync::OnceLock<Srgb8> = std::sync::OnceLock::new();
        TABLE.get_or_init(Srgb8::new)
    }

    fn new() -> Srgb8 {
        let mut thresholds = [f32::INFINITY; 258];
        for (k, threshold) in thresholds.iter_mut().enumerate().take(256).skip(1) {
            // Bisection over bit patterns, which order non-negative floats as their
            // values: the least pattern in [0, 1.0] whose byte is at least k.
            let (mut lo, mut hi) = (0u32, 1.0f32.to_bits());
            while lo < hi {
                let mid = lo + (hi - lo) / 2;
                if encode_8bit(f32::from_bits(mid)) as usize >= k {
                    hi = mid;
                } else {
                    lo = mid + 1;
                }
            }
            let v = f32::from_bits(lo);
            // A byte that 1.0 does not reach is reached by no value.
            if encode_8bit(v) as usize >= k {
                *threshold = v;
            }
        }
        let mut buckets = [0; BUCKETS + 1];
        for (i, bucket) in buckets.iter_mut().enumerate() {
            let least = i as f32 / BUCKETS as f32;
            let count = thresholds[1..256].partition_point(|&t| t <= least);
            *bucket = count as u8;
            // The lookup counts at most two thresholds past the bucket's least value.
            let next = (i + 1) as f32 / BUCKETS as f32;
            assert!(
                thresholds.get(count + 3).is_none_or(|&t| t >= next),
                "bucket {i} holds more than two sRGB thresholds"
            );
        }
        Srgb8 {
            thresholds,
            buckets,
        }
    }

    /// The byte of a value already scaled by 2^exposure.
    fn encode(&self, v: f32) -> u8 {
        let v = if v.is_finite() {
            v.clamp(0.0, 1.0)
        } else {
            0.0
        };
        // Exact: the scale is a power of two, and v at most 1.
        let k = self.buckets[(v * BUCKETS as f32) as usize] as usize;
        let above = |j: usize| (v >= self.thresholds[j]) as usize;
        (k + above(k + 1) + above(k + 2)) as u8
    }
}

/// Encode the frame's window as an 8-bit sRGB PNG.
pub fn encode_png(frame: &Frame, exposure: f32) -> Result<Vec<u8>, String> {
    let (w, h) = (frame.window.width(), frame.window.height());
    encode_rgb_png(w, h, &frame.color, exposure)
}

/// Encode `w`×`h` linear RGB pixels (row-major) as an 8-bit sRGB PNG.
pub fn encode_rgb_png(w: u32, h: u32, color: &[Vec3], exposure: f32) -> Result<Vec<u8>, String> {
    let (scale, srgb) = (exposure.exp2(), Srgb8::get());
    let mut rgb = vec![0; color.len() * 3];
    for (px, c) in rgb.chunks_exact_mut(3).zip(color) {
        for (byte, v) in px.iter_mut().zip(c.to_array()) {
            *byte = srgb.encode(v * scale);
        }
    }
    let mut out = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut out, w, h);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        enc.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
        let mut writer = enc.write_header().map_err(|e| e.to_string())?;
        writer.write_image_data(&rgb).map_err(|e| e.to_string())?;
    }
    Ok(out)
}

/// Write the preview atomically (temp file + rename).
pub fn write_png(path: &Path, frame: &Frame, exposure: f32) -> Result<(), RenderError> {
    let (w, h) = (frame.window.width(), frame.window.height());
    write_rgb_png(path, w, h, &frame.color, exposure)
}

/// Write `w`×`h` linear RGB pixels as a preview, atomically.
pub fn write_rgb_png(
    path: &Path,
    w: u32,
    h: u32,
    color: &[Vec3],
    exposure: f32,
) -> Result<(), RenderError> {
    let bytes = encode_rgb_png(w, h, color, exposure).map_err(|detail| RenderError::PngWrite {
        path: path.to_path_buf(),
        detail,
    })?;
    formats::write_atomic(path, &bytes)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// [`to_8bit`] as it was, through `powf` on every value.
    fn reference(linear: f32, exposure: f32) -> u8 {
        let v = linear * exposure.exp2();
        let v = if v.is_finite() {
            v.clamp(0.0, 1.0)
        } else {
            0.0
        };
        encode_8bit(v)
    }

    #[test]
    fn srgb_encoding_of_known_values() {
        assert_eq!(to_8bit(0.0, 0.0), 0);
        assert_eq!(to_8bit(1.0, 0.0), 255);
        assert_eq!(to_8bit(0.5, 1.0), 255);
        // Linear 0.2142 is just above sRGB 0.5 (127.5 rounds to 128); 0.05 is sRGB 0.2474 (63).
        assert_eq!(to_8bit(0.2142, 0.0), 128);
        assert_eq!(to_8bit(0.05, 0.0), 63);
        assert_eq!(to_8bit(f32::NAN, 0.0), 0);
        assert_eq!(to_8bit(5.0, 0.0), 255);
    }

    #[test]
    fn thresholds_give_the_bytes_of_the_transfer_function() {
        let t = &Srgb8::get().thresholds;
        assert!(t[1..].windows(2).all(|w| w[0] <= w[1]));
        let exposures = [0.0, -2.5, 1.0, 3.7];
        let mut checked = 0u64;
        let mut check = |linear: f32| {
            for e in exposures {
                assert_eq!(
                    to_8bit(linear, e),
                    reference(linear, e),
                    "{linear:e} at {e}"
                );
            }
            checked += 1;
        };
        // Every f32 within 2000 ulps of each threshold, where a wrong byte would show.
        for &threshold in &t[1..256] {
            let bits = threshold.to_bits();
            for b in bits.saturating_sub(2000)..=bits + 2000 {
                check(f32::from_bits(b));
            }
        }
        // Every 4093rd bit pattern: both signs, subnormals, above 1, infinities, NaNs.
        for b in (0..=u32::MAX).step_by(4093) {
            check(f32::from_bits(b));
        }
        for v in [
            f32::NAN,
            -f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            -0.0,
            -1e-30,
            -1.0,
            f32::MIN,
            f32::MAX,
            1.0,
            1.0 + f32::EPSILON,
            1e30,
            f32::MIN_POSITIVE,
            f32::from_bits(1),
        ] {
            check(v);
        }
        assert!(checked > 2_000_000, "{checked}");
    }

    /// Why the thresholds are exact, and that the table gives every byte in [0, 1]: slow
    /// (10^9 `powf`), so run on demand.
    #[test]
    #[ignore]
    fn every_f32_in_0_1_encodes_to_a_non_decreasing_byte() {
        let mut prev = 0;
        for b in 0..=1.0f32.to_bits() {
            let v = f32::from_bits(b);
            let byte = encode_8bit(v);
            assert!(byte >= prev, "{v:e}");
            assert_eq!(to_8bit(v, 0.0), byte, "{v:e}");
            prev = byte;
        }
        assert_eq!(prev, 255);
    }
}
