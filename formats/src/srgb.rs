//! The sRGB transfer functions on floats, both ways, and Unity's gamma-to-linear conversion
//! (the converter's colours, the renderer's gamma-space frames); and linear values to 8-bit
//! sRGB codes, exactly as the transfer function rounds them, without calling `powf` per
//! value: the preview's bytes and the 8-bit mip levels of sRGB textures. (8-bit codes to
//! linear are a 256-entry table: [`crate::texture::decode_u8`].)

/// The sRGB opto-electronic transfer function (IEC 61966-2-1), linear to encoded; above 1
/// it follows the same curve (Unity's HDR colours are encoded so).
pub fn linear_to_srgb(c: f32) -> f32 {
    if c <= 0.003_130_8 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}

/// The sRGB electro-optical transfer function, encoded to linear: the inverse of
/// [`linear_to_srgb`], above 1 too.
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// Unity's gamma-to-linear conversion of a value that may exceed 1 (a `[Gamma]` float, a
/// light's colour times its intensity, a gamma-space frame's pixel): the sRGB curve up to
/// 1, x^2.2 above.
pub fn gamma_to_linear(x: f32) -> f32 {
    if x <= 1.0 {
        srgb_to_linear(x)
    } else {
        x.powf(2.2)
    }
}

/// A linear value's 8-bit sRGB code: clamped to [0, 1] (infinities too; NaN to 0),
/// encoded, rounded.
pub fn encode(linear: f32) -> u8 {
    Encoder::get().encode(linear)
}

/// [`encode`] through the transfer function itself, on a value in [0, 1]: what [`Encoder`]
/// is built from, and gives back exactly.
fn encode_by_powf(v: f32) -> u8 {
    (linear_to_srgb(v) * 255.0 + 0.5) as u8
}

/// Buckets of [`Encoder`]: [0, 1] in equal steps, few enough that a bucket's table stays in
/// the L1 cache, many enough that no bucket holds more than one threshold (the steepest
/// slope, 12.92 × 255 below the linear segment's end, crosses 0.8 bytes per bucket).
const BUCKETS: usize = 4096;

/// [`encode`] without `powf`, which was most of what the preview cost. `encode_by_powf` is
/// non-decreasing on [0, 1], so its byte is the count of thresholds at or below the
/// value, where threshold k is the least value it takes to k or more. That holds on every
/// f32 there: `cargo test --release -p formats -- --ignored
/// every_f32_in_0_1_encodes_to_a_non_decreasing_byte` evaluates it on all 1 065 353 217
/// bit patterns from 0 to 1.0, each against the one before, and finds no decrease (x86-64,
/// glibc 2.36's `powf`). The thresholds are found with the platform's own `powf` when
/// first needed.
pub struct Encoder {
    /// Entry k, from 1 to 255, is threshold k; entry 0 is never read, and entries past
    /// 255 are infinite, so that a count can look two further without a bounds check.
    thresholds: [f32; 258],
    /// The count at each bucket's least value.
    buckets: [u8; BUCKETS + 1],
}

impl Encoder {
    /// The tables, built on first use.
    pub fn get() -> &'static Encoder {
        static TABLE: std::sync::OnceLock<Encoder> = std::sync::OnceLock::new();
        TABLE.get_or_init(Encoder::new)
    }

    fn new() -> Encoder {
        let mut thresholds = [f32::INFINITY; 258];
        for (k, threshold) in thresholds.iter_mut().enumerate().take(256).skip(1) {
            // Bisection over bit patterns, which order non-negative floats as their
            // values: the least pattern in [0, 1.0] whose byte is at least k.
            let (mut lo, mut hi) = (0u32, 1.0f32.to_bits());
            while lo < hi {
                let mid = lo + (hi - lo) / 2;
                if encode_by_powf(f32::from_bits(mid)) as usize >= k {
                    hi = mid;
                } else {
                    lo = mid + 1;
                }
            }
            let v = f32::from_bits(lo);
            // A byte that 1.0 does not reach is reached by no value.
            if encode_by_powf(v) as usize >= k {
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
        Encoder {
            thresholds,
            buckets,
        }
    }

    /// [`encode`] without looking the tables up: for many values in a row.
    #[inline]
    pub fn encode(&self, v: f32) -> u8 {
        // A NaN stays NaN: its index below is 0 and it passes no threshold, so it gives 0.
        let v = v.clamp(0.0, 1.0);
        // Exact: the bucket count is a power of two, and v at most 1. Through i32 and
        // clamped, the index needs neither a 64-bit conversion's fix-ups nor a bounds check.
        let i = ((v * BUCKETS as f32) as i32).clamp(0, BUCKETS as i32) as usize;
        let k = self.buckets[i] as usize;
        let above = |j: usize| (v >= self.thresholds[j]) as usize;
        (k + above(k + 1) + above(k + 2)) as u8
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// [`encode`] through `powf` on every value.
    fn reference(v: f32) -> u8 {
        if v.is_nan() {
            0
        } else {
            encode_by_powf(v.clamp(0.0, 1.0))
        }
    }

    #[test]
    fn known_values() {
        assert_eq!(encode(0.0), 0);
        assert_eq!(encode(1.0), 255);
        // Linear 0.2142 is just above sRGB 0.5 (127.5 rounds to 128); 0.05 is sRGB 0.2474 (63).
        assert_eq!(encode(0.2142), 128);
        assert_eq!(encode(0.05), 63);
        assert_eq!(encode(f32::NAN), 0);
        assert_eq!(encode(5.0), 255);
        assert_eq!(encode(f32::INFINITY), 255);
        assert_eq!(encode(f32::NEG_INFINITY), 0);
    }

    #[test]
    fn every_code_survives_decoding_and_encoding() {
        for code in 0..=255u8 {
            assert_eq!(encode(crate::texture::decode_u8(code, true)), code);
        }
    }

    #[test]
    fn thresholds_give_the_bytes_of_the_transfer_function() {
        let t = &Encoder::get().thresholds;
        assert!(t[1..].windows(2).all(|w| w[0] <= w[1]));
        let mut checked = 0u64;
        let mut check = |v: f32| {
            assert_eq!(encode(v), reference(v), "{v:e}");
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
        assert!(checked > 1_000_000, "{checked}");
    }

    /// Why the thresholds are exact, and that the table gives every byte in [0, 1]: slow
    /// (10^9 `powf`), so run on demand.
    #[test]
    #[ignore]
    fn every_f32_in_0_1_encodes_to_a_non_decreasing_byte() {
        let mut prev = 0;
        for b in 0..=1.0f32.to_bits() {
            let v = f32::from_bits(b);
            let byte = encode_by_powf(v);
            assert!(byte >= prev, "{v:e}");
            assert_eq!(encode(v), byte, "{v:e}");
            prev = byte;
        }
        assert_eq!(prev, 255);
    }
}
