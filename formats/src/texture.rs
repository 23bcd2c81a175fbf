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
//! levels below the full-size image once before tracing ([`Texture::halvings`]), in linear
//! `f32` so averaging conserves energy, and reads the full-size image from these bytes.

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

/// One mip level: linear RGBA, bottom row first.
#[derive(Clone, Debug, PartialEq)]
pub struct Level {
    pub width: u32,
    pub height: u32,
    pub texels: Vec<[f32; 4]>,
}

impl Level {
    pub fn texel(&self, x: u32, y: u32) -> [f32; 4] {
        self.texels[(y as usize) * (self.width as usize) + x as usize]
    }
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
        let i = ((y as usize) * (self.width as usize) + x as usize) * 4;
        decode_rgba(&self.texels[i..i + 4], table(self.srgb), table(false))
    }

    /// When mip-mapped, every halving of the image down to 1×1 (level 1 first; level 0 is
    /// the image itself, read through [`Texture::texel`]). Each texel of a level is the
    /// mean of the (2×2, or 3 wide/high where a side is odd) texels it covers, summed in
    /// f64 so that a constant texture stays exactly constant at every level.
    pub fn halvings(&self) -> Vec<Level> {
        let mut levels: Vec<Level> = Vec::new();
        if !self.mipmaps || (self.width == 1 && self.height == 1) {
            return levels;
        }
        let (colour, alpha) = (table(self.srgb), table(false));
        let row_bytes = self.width as usize * 4;
        levels.push(halve(self.width, self.height, |y, row| {
            let bytes = &self.texels[y as usize * row_bytes..][..row_bytes];
            for (t, b) in row.iter_mut().zip(bytes.chunks_exact(4)) {
                *t = decode_rgba(b, colour, alpha);
            }
        }));
        while let Some(prev) = levels.last().filter(|l| l.width > 1 || l.height > 1) {
            let w = prev.width as usize;
            levels.push(halve(prev.width, prev.height, |y, row| {
                row.copy_from_slice(&prev.texels[y as usize * w..][..w]);
            }));
        }
        levels
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

/// The halving of a `width`×`height` level whose rows `fill_row(y, row)` writes as linear
/// RGBA. Each destination texel sums its source texels row by row, left to right, in f64.
fn halve(width: u32, height: u32, mut fill_row: impl FnMut(u32, &mut [[f32; 4]])) -> Level {
    let (w, h) = ((width / 2).max(1), (height / 2).max(1));
    let mut texels = Vec::with_capacity(w as usize * h as usize);
    // At most three source rows feed a destination row (an odd height's last one).
    let mut rows = vec![vec![[0f32; 4]; width as usize]; 3.min(height as usize)];
    for y in 0..h {
        let (y0, y1) = span(y, height, h);
        let rows = &mut rows[..(y1 - y0 + 1) as usize];
        for (sy, row) in (y0..=y1).zip(rows.iter_mut()) {
            fill_row(sy, row);
        }
        // Most texels cover a 2×2 block: summed straight from two row pairs, in the order
        // the general loop below sums them.
        let pairs = match &*rows {
            [upper, lower] if width > 1 => {
                let pairs = (width / 2 - width % 2) as usize;
                let blocks = upper.chunks_exact(2).zip(lower.chunks_exact(2));
                for (a, b) in blocks.take(pairs) {
                    texels.push(std::array::from_fn(|c| {
                        let sum =
                            0.0 + a[0][c] as f64 + a[1][c] as f64 + b[0][c] as f64 + b[1][c] as f64;
                        (sum / 4.0) as f32
                    }));
                }
                pairs
            }
            _ => 0,
        };
        for x in pairs as u32..w {
            let (x0, x1) = span(x, width, w);
            let mut sum = [0f64; 4];
            for row in rows.iter() {
                for t in &row[x0 as usize..=x1 as usize] {
                    for c in 0..4 {
                        sum[c] += t[c] as f64;
                    }
                }
            }
            let n = ((x1 - x0 + 1) * (y1 - y0 + 1)) as f64;
            texels.push(sum.map(|s| (s / n) as f32));
        }
    }
    Level {
        width: w,
        height: h,
        texels,
    }
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
        let c = t.texel(0, 0);
        for l in &mips {
            assert!(l.texels.iter().all(|&x| x == c), "{}x{}", l.width, l.height);
        }
    }

    #[test]
    fn mip_averages_in_linear() {
        let mut t = tex(2, 1, vec![255, 255, 255, 255, 0, 0, 0, 0]);
        t.srgb = true;
        let m = t.halvings();
        assert_eq!(m[0].texels, vec![[0.5, 0.5, 0.5, 0.5]]);
        t.mipmaps = false;
        assert!(t.halvings().is_empty());
    }

    /// Each level's texel is the mean, summed in f64 row by row, of the texels of the level
    /// above that it covers: two per axis, three where that axis's side is odd and the
    /// texel is the last. Checked bit for bit on odd and even sides, both encodings.
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
                let mut prev: Option<&Level> = None;
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
                    for y in 0..l.height {
                        for x in 0..l.width {
                            let (xs, ys) = (cover(x, pw, l.width), cover(y, ph, l.height));
                            let n = (xs.clone().count() * ys.clone().count()) as f64;
                            let mut sum = [0f64; 4];
                            for sy in ys.clone() {
                                for sx in xs.clone() {
                                    let v = match prev {
                                        Some(p) => p.texel(sx, sy),
                                        None => t.texel(sx, sy),
                                    };
                                    for c in 0..4 {
                                        sum[c] += v[c] as f64;
                                    }
                                }
                            }
                            let want = sum.map(|s| (s / n) as f32);
                            assert_eq!(l.texel(x, y), want, "{w}x{h} srgb {srgb}: ({x}, {y})");
                        }
                    }
                    (pw, ph) = (l.width, l.height);
                    prev = Some(l);
                }
                assert_eq!((pw, ph), (1, 1));
            }
        }
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
