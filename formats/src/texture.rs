//! One albedo texture as the soup stores it, and how a material uses it.
//!
//! Texels are RGBA, 8 bits per channel, rows bottom to top (texel (0, 0) is the image's
//! bottom-left corner, Unity's UV origin). Colour channels are sRGB-encoded when
//! [`Texture::srgb`] is set (Unity's `sRGBTexture`), otherwise linear; alpha is always
//! linear. Eight bits are what Unity's importer keeps of an albedo map anyway, so the soup
//! holds exactly the values Unity samples, at a quarter of the size of linear `f32`, and
//! the lookup through [`decode_u8`] is exact (a table, not a re-quantisation).
//!
//! Mip levels are not stored: they follow from the texels, so the renderer builds the
//! levels below the full-size image once before tracing ([`Texture::halvings`]). Each is
//! averaged in linear `f32`, so averaging conserves energy, and kept in the image's own
//! 8-bit encoding, as Unity keeps a texture's mip maps: a quarter of the memory of linear
//! `f32`, and one way of reading every level.

use glam::Vec4;
use serde::{Deserialize, Serialize};

/// Largest width or height accepted (Unity's own import limit).
pub const MAX_SIDE: u32 = 16384;

/// Texture address mode per axis (TextureImporter `wrapU`/`wrapV`: 0, 1, 2).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum Wrap {
    #[default]
    Repeat,
    Clamp,
    Mirror,
}

/// TextureImporter `filterMode`: 0 point, 1 bilinear, 2 trilinear.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum Filter {
    Point,
    #[default]
    Bilinear,
    Trilinear,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Texture {
    /// Asset path relative to the project (for messages).
    pub source: String,
    pub width: u32,
    pub height: u32,
    /// `width · height · 4` bytes, RGBA, bottom row first. (Encoded as bytes: the same
    /// bincode layout as a `Vec<u8>`, written and read as one block.)
    #[serde(with = "serde_bytes")]
    pub texels: Vec<u8>,
    /// Colour channels are sRGB-encoded (alpha never is).
    pub srgb: bool,
    pub wrap_u: Wrap,
    pub wrap_v: Wrap,
    pub filter: Filter,
    /// TextureImporter `enableMipMap`: without it every lookup reads level 0.
    pub mipmaps: bool,
}

/// How a material maps its albedo texture: uv' = uv · scale + offset (`m_Scale`,
/// `m_Offset`; negative scales occur).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Tiling {
    pub scale: [f32; 2],
    pub offset: [f32; 2],
}

/// A material's use of one of the soup's textures.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct TextureRef {
    /// Index into `Soup::textures`.
    pub texture: u32,
    pub tiling: Tiling,
}

impl Default for Tiling {
    fn default() -> Self {
        Tiling {
            scale: [1.0, 1.0],
            offset: [0.0, 0.0],
        }
    }
}

impl Tiling {
    pub fn is_finite(&self) -> bool {
        self.scale.iter().chain(&self.offset).all(|c| c.is_finite())
    }

    pub fn apply(&self, uv: [f32; 2]) -> [f32; 2] {
        [
            uv[0] * self.scale[0] + self.offset[0],
            uv[1] * self.scale[1] + self.offset[1],
        ]
    }

    /// A footprint width in uv becomes one in uv' (the larger axis scale, so tiling never
    /// under-filters).
    pub fn footprint(&self, width: f32) -> f32 {
        width * self.scale[0].abs().max(self.scale[1].abs())
    }
}

/// One mip level: RGBA, 8 bits per channel in its texture's encoding ([`Texture::srgb`]
/// for the colour channels, alpha linear), bottom row first, as [`Texture::texels`].
#[derive(Clone, Debug, PartialEq)]
pub struct Level {
    pub width: u32,
    pub height: u32,
    pub texels: Vec<u8>,
}

/// sRGB → linear for every 8-bit code, computed once.
fn srgb_table() -> &'static [f32; 256] {
    static TABLE: std::sync::OnceLock<[f32; 256]> = std::sync::OnceLock::new();
    TABLE.get_or_init(|| {
        let mut t = [0.0; 256];
        for (i, v) in t.iter_mut().enumerate() {
            let c = i as f64 / 255.0;
            *v = if c <= 0.04045 {
                c / 12.92
            } else {
                ((c + 0.055) / 1.055).powf(2.4)
            } as f32;
        }
        t
    })
}

/// 8-bit code → code / 255, computed once (a table read instead of a division per texel).
fn linear_table() -> &'static [f32; 256] {
    static TABLE: std::sync::OnceLock<[f32; 256]> = std::sync::OnceLock::new();
    TABLE.get_or_init(|| std::array::from_fn(|i| i as f32 / 255.0))
}

/// Every 8-bit code's linear value, for sRGB-encoded or linear channels.
fn table(srgb: bool) -> &'static [f32; 256] {
    if srgb {
        srgb_table()
    } else {
        linear_table()
    }
}

/// An 8-bit channel as a linear value.
pub fn decode_u8(code: u8, srgb: bool) -> f32 {
    table(srgb)[code as usize]
}

/// A linear value in [0, 1] as an 8-bit channel (clamped, NaN to 0): the nearest code
/// of linear channels, the transfer function's rounded code of sRGB ones. Every code
/// comes back from [`decode_u8`] as itself.
pub fn encode_u8(linear: f32, srgb: bool) -> u8 {
    encode_with(crate::srgb::Encoder::get(), linear, srgb)
}

/// [`encode_u8`] with the sRGB tables looked up once for many values.
#[inline]
fn encode_with(sr: &crate::srgb::Encoder, linear: f32, srgb: bool) -> u8 {
    if srgb {
        sr.encode(linear)
    } else if linear.is_nan() {
        0
    } else {
        (linear.clamp(0.0, 1.0) * 255.0 + 0.5) as u8
    }
}

/// Texel (x, y) of RGBA bytes `width` texels wide, as linear RGBA.
#[inline]
pub fn decode_texel(texels: &[u8], width: u32, x: u32, y: u32, srgb: bool) -> [f32; 4] {
    let i = ((y as usize) * (width as usize) + x as usize) * 4;
    decode_rgba(&texels[i..i + 4], table(srgb), table(false))
}

impl Texture {
    pub fn validate(&self) -> Result<(), String> {
        if self.width == 0 || self.height == 0 {
            return Err(format!(
                "texture {}: empty ({}x{})",
                self.source, self.width, self.height
            ));
        }
        if self.width > MAX_SIDE || self.height > MAX_SIDE {
            return Err(format!(
                "texture {}: {}x{} is larger than {MAX_SIDE} on a side",
                self.source, self.width, self.height
            ));
        }
        let want = self.width as usize * self.height as usize * 4;
        if self.texels.len() != want {
            return Err(format!(
                "texture {}: {} texel bytes for {}x{} (want {want})",
                self.source,
                self.texels.len(),
                self.width,
                self.height
            ));
        }
        Ok(())
    }

    /// Texel (x, y) as linear RGBA (y = 0 is the bottom row).
    #[inline]
    pub fn texel(&self, x: u32, y: u32) -> [f32; 4] {
        decode_texel(&self.texels, self.width, x, y, self.srgb)
    }

    /// When mip-mapped, every halving of the image down to 1×1 (level 1 first; level 0 is
    /// the image itself, read through [`Texture::texel`]). Each texel of a level is the
    /// mean of the (2×2, or 3 wide/high where a side is odd) linear texels it covers in the
    /// level above, summed in f32 row by row, then encoded to 8 bits ([`encode_u8`]). The
    /// means are taken before the level above is encoded, so rounding never compounds down
    /// the chain; a constant texture's means are within a few ulps of its value, far from
    /// any rounding boundary, so it stays exactly constant at every level.
    pub fn halvings(&self) -> Vec<Level> {
        let mut chain: Vec<Halving> = Vec::new();
        let (mut w, mut h) = (self.width, self.height);
        while self.mipmaps && (w > 1 || h > 1) {
            chain.push(Halving::new(w, h));
            (w, h) = ((w / 2).max(1), (h / 2).max(1));
        }
        // The image's rows go in one by one; each row a level completes goes on into the
        // next, so no level is ever held whole in f32, only its last two or three rows.
        let (colour, alpha) = (table(self.srgb), table(false));
        let row_bytes = self.width as usize * 4;
        for y in 0..self.height as usize {
            let Some((first, rest)) = chain.split_first_mut() else {
                break;
            };
            let bytes = &self.texels[y * row_bytes..][..row_bytes];
            for (t, b) in first.next_row().iter_mut().zip(bytes.chunks_exact(4)) {
                *t = Vec4::from_array(decode_rgba(b, colour, alpha));
            }
            let mut done = first.row_filled(self.srgb);
            for next in rest.iter_mut() {
                let Some(row) = done else { break };
                next.next_row().copy_from_slice(row);
                done = next.row_filled(self.srgb);
            }
        }
        chain.into_iter().map(|h| h.level).collect()
    }
}

/// One halving while the chain is built: the rows of the level above arrive one by one
/// (linear RGBA), and each destination row is averaged as soon as its two (or, for an odd
/// height's last, three) source rows are in, then kept linear for the next halving and
/// encoded into the level.
struct Halving {
    /// Size of the level above.
    src: (u32, u32),
    /// The source rows of the destination row in progress, and how many have arrived.
    rows: [Vec<Vec4>; 3],
    arrived: usize,
    /// The last destination row, linear, and how many rows are done.
    row: Vec<Vec4>,
    done: u32,
    level: Level,
}

impl Halving {
    fn new(width: u32, height: u32) -> Halving {
        let (w, h) = ((width / 2).max(1), (height / 2).max(1));
        let src_row = || vec![Vec4::ZERO; width as usize];
        Halving {
            src: (width, height),
            rows: [src_row(), src_row(), src_row()],
            arrived: 0,
            row: Vec::with_capacity(w as usize),
            done: 0,
            level: Level {
                width: w,
                height: h,
                texels: vec![0; w as usize * h as usize * 4],
            },
        }
    }

    /// Where the next source row goes.
    fn next_row(&mut self) -> &mut [Vec4] {
        &mut self.rows[self.arrived]
    }

    /// Counts the row written at [`Halving::next_row`]; once a destination row's source rows
    /// are all in, averages it (each texel sums its source texels in f32, row by row, left
    /// to right, and divides by their count), appends it encoded to the level and returns
    /// it linear.
    fn row_filled(&mut self, srgb: bool) -> Option<&[Vec4]> {
        let (
            (width, height),
            Level {
                width: w,
                height: h,
                texels,
            },
        ) = (self.src, &mut self.level);
        let (y0, y1) = span(self.done, height, *h);
        self.arrived += 1;
        if y0 + self.arrived as u32 <= y1 {
            return None;
        }
        let rows = &self.rows[..self.arrived];
        self.arrived = 0;
        self.row.clear();
        // Most texels cover a 2×2 block: summed straight from two row pairs, in the order
        // the general loop below sums them.
        let pairs = match rows {
            [upper, lower] if width > 1 => {
                let pairs = (width / 2 - width % 2) as usize;
                let blocks = upper.chunks_exact(2).zip(lower.chunks_exact(2));
                for (a, b) in blocks.take(pairs) {
                    self.row.push((a[0] + a[1] + b[0] + b[1]) / 4.0);
                }
                pairs
            }
            _ => 0,
        };
        for x in pairs as u32..*w {
            let (x0, x1) = span(x, width, *w);
            let mut sum = Vec4::ZERO;
            for row in rows {
                for t in &row[x0 as usize..=x1 as usize] {
                    sum += *t;
                }
            }
            self.row.push(sum / ((x1 - x0 + 1) * (y1 - y0 + 1)) as f32);
        }
        let row_bytes = *w as usize * 4;
        let out = &mut texels[self.done as usize * row_bytes..][..row_bytes];
        let sr = crate::srgb::Encoder::get();
        for (b, t) in out.chunks_exact_mut(4).zip(&self.row) {
            b.copy_from_slice(&[
                encode_with(sr, t[0], srgb),
                encode_with(sr, t[1], srgb),
                encode_with(sr, t[2], srgb),
                encode_with(sr, t[3], false),
            ]);
        }
        self.done += 1;
        Some(&self.row)
    }
}

/// One texel's four bytes as linear RGBA, through the colour and alpha tables.
#[inline]
fn decode_rgba(b: &[u8], colour: &[f32; 256], alpha: &[f32; 256]) -> [f32; 4] {
    [
        colour[b[0] as usize],
        colour[b[1] as usize],
        colour[b[2] as usize],
        alpha[b[3] as usize],
    ]
}

/// Source index range [first, last] that destination index `i` covers along one axis.
fn span(i: u32, src: u32, dst: u32) -> (u32, u32) {
    if src == 1 {
        return (0, 0);
    }
    let first = 2 * i;
    // An odd side folds its last texel into the last destination texel.
    let last = if i + 1 == dst && src % 2 == 1 {
        src - 1
    } else {
        first + 1
    };
    (first, last)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tex(w: u32, h: u32, texels: Vec<u8>) -> Texture {
        Texture {
            source: "t.png".into(),
            width: w,
            height: h,
            texels,
            srgb: true,
            wrap_u: Wrap::Repeat,
            wrap_v: Wrap::Repeat,
            filter: Filter::Trilinear,
            mipmaps: true,
        }
    }

    #[test]
    fn validation() {
        assert!(tex(2, 1, vec![0; 8]).validate().is_ok());
        assert!(tex(2, 1, vec![0; 7]).validate().is_err());
        assert!(tex(0, 1, vec![]).validate().is_err());
        assert!(tex(MAX_SIDE + 1, 1, vec![0; (MAX_SIDE as usize + 1) * 4])
            .validate()
            .is_err());
    }

    #[test]
    fn srgb_mid_grey_is_0_2158_linear() {
        assert!((decode_u8(128, true) - 0.2158).abs() < 1e-4);
        assert_eq!(decode_u8(255, true), 1.0);
        assert_eq!(decode_u8(0, true), 0.0);
        assert_eq!(decode_u8(51, false), 51.0 / 255.0);
    }

    #[test]
    fn mip_chain_sizes_and_constant_levels() {
        let t = tex(5, 3, [200, 10, 77, 255].repeat(15));
        let mips = t.halvings();
        let sizes: Vec<_> = mips.iter().map(|l| (l.width, l.height)).collect();
        assert_eq!(sizes, vec![(2, 1), (1, 1)]);
        for l in &mips {
            assert!(
                l.texels.chunks(4).all(|x| x == [200, 10, 77, 255]),
                "{}x{}",
                l.width,
                l.height
            );
        }
    }

    #[test]
    fn mip_averages_in_linear() {
        let mut t = tex(2, 1, vec![255, 255, 255, 255, 0, 0, 0, 0]);
        t.srgb = true;
        let m = t.halvings();
        // Linear 0.5 is sRGB 0.7354 (187.5 rounds to 188); alpha is linear.
        assert_eq!(m[0].texels, vec![188, 188, 188, 128]);
        assert_eq!(decode_u8(188, true), 0.5028865);
        t.mipmaps = false;
        assert!(t.halvings().is_empty());
    }

    /// Each level's texel is the mean, summed in f32 row by row, of the linear texels of the
    /// level above that it covers (two per axis, three where that axis's side is odd and
    /// the texel is the last) before that level was encoded, then encoded to 8 bits.
    /// Checked bit for bit on odd and even sides, both encodings.
    #[test]
    fn every_mip_texel_is_the_mean_of_the_texels_it_covers() {
        let mut seed = 0x9e37_79b9u32;
        let mut byte = || {
            seed ^= seed << 13;
            seed ^= seed >> 17;
            seed ^= seed << 5;
            (seed >> 24) as u8
        };
        for (w, h) in [(7, 5), (6, 4), (1, 9), (9, 1), (3, 3), (16, 2), (5, 8)] {
            for srgb in [false, true] {
                let mut t = tex(w, h, (0..w * h * 4).map(|_| byte()).collect());
                t.srgb = srgb;
                let levels = t.halvings();
                let (mut pw, mut ph) = (w, h);
                // The level above, linear and unrounded.
                let mut prev: Vec<[f32; 4]> = (0..h)
                    .flat_map(|y| (0..w).map(move |x| (x, y)))
                    .map(|(x, y)| t.texel(x, y))
                    .collect();
                for l in &levels {
                    assert_eq!((l.width, l.height), ((pw / 2).max(1), (ph / 2).max(1)));
                    let cover = |i: u32, src: u32, dst: u32| -> std::ops::RangeInclusive<u32> {
                        if src == 1 {
                            0..=0
                        } else if i + 1 == dst && src % 2 == 1 {
                            2 * i..=src - 1
                        } else {
                            2 * i..=2 * i + 1
                        }
                    };
                    let mut means = Vec::new();
                    for y in 0..l.height {
                        for x in 0..l.width {
                            let (xs, ys) = (cover(x, pw, l.width), cover(y, ph, l.height));
                            let n = (xs.clone().count() * ys.clone().count()) as f32;
                            let mut sum = [0f32; 4];
                            for sy in ys.clone() {
                                for sx in xs.clone() {
                                    let v = prev[(sy * pw + sx) as usize];
                                    for c in 0..4 {
                                        sum[c] += v[c];
                                    }
                                }
                            }
                            let mean = sum.map(|s| s / n);
                            let want = [
                                encode_u8(mean[0], srgb),
                                encode_u8(mean[1], srgb),
                                encode_u8(mean[2], srgb),
                                encode_u8(mean[3], false),
                            ];
                            let i = ((y * l.width + x) * 4) as usize;
                            assert_eq!(l.texels[i..i + 4], want, "{w}x{h} srgb {srgb}: ({x}, {y})");
                            means.push(mean);
                        }
                    }
                    (pw, ph) = (l.width, l.height);
                    prev = means;
                }
                assert_eq!((pw, ph), (1, 1));
            }
        }
    }

    #[test]
    fn every_linear_code_survives_decoding_and_encoding() {
        for code in 0..=255u8 {
            assert_eq!(encode_u8(decode_u8(code, false), false), code);
            assert_eq!(encode_u8(decode_u8(code, true), true), code);
        }
        assert_eq!(encode_u8(f32::NAN, false), 0);
        assert_eq!(encode_u8(-1.0, false), 0);
        assert_eq!(encode_u8(2.0, false), 255);
    }

    #[test]
    fn tiling() {
        let t = Tiling {
            scale: [-2.0, 0.5],
            offset: [1.0, 0.25],
        };
        assert_eq!(t.apply([0.25, 0.5]), [0.5, 0.5]);
        assert_eq!(t.footprint(0.1), 0.2);
    }
}
