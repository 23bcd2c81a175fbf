//! Sampling an albedo texture: wrap modes, point / bilinear / trilinear filtering over the
//! mip chain, and the uv footprint of a ray cone at a hit.
//!
//! Conventions follow the GPU's: texel (i, j) has its centre at ((i + ½)/w, (j + ½)/h),
//! v = 0 is the bottom row, and wrap modes act on integer texel coordinates, so a bilinear
//! lookup at a border blends the two texels the wrap mode makes neighbours.

use crate::options::TextureFilter;
use formats::texture::{decode_texel, Filter, Level, Texture, Tiling, Wrap};
use glam::{Vec2, Vec3, Vec4};

/// A texture ready to sample: level 0 is the soup's own 8-bit image, the smaller levels
/// are built once in the same encoding ([`Texture::halvings`]); every level is decoded
/// texel by texel as it is read (a table read per channel).
pub struct Sampler<'a> {
    image: &'a Texture,
    mips: Vec<Level>,
    wrap_u: Wrap,
    wrap_v: Wrap,
    filter: Filter,
}

/// One level of a [`Sampler`]'s chain: RGBA bytes in the image's encoding.
#[derive(Clone, Copy)]
struct LevelRef<'a> {
    width: u32,
    height: u32,
    texels: &'a [u8],
    srgb: bool,
}

impl LevelRef<'_> {
    #[inline(always)]
    fn size(self) -> (u32, u32) {
        (self.width, self.height)
    }

    #[inline(always)]
    fn texel(self, x: u32, y: u32) -> Vec4 {
        Vec4::from_array(decode_texel(self.texels, self.width, x, y, self.srgb))
    }
}

/// `a + (b − a)·f`: unlike `Vec4::lerp`'s `a(1 − f) + bf`, exactly `a` when `a == b`, so a
/// flat texture filters to itself.
fn mix(a: Vec4, b: Vec4, f: f32) -> Vec4 {
    a + (b - a) * f
}

/// Integer texel coordinate `i` wrapped into [0, n).
fn wrap(i: i64, n: u32, mode: Wrap) -> u32 {
    let n = n as i64;
    // Inside the image every mode is the identity; the division below is the slow part of
    // a lookup, and the neighbours of a wrapped texel are almost always inside.
    if (0..n).contains(&i) {
        return i as u32;
    }
    (match mode {
        Wrap::Repeat => i.rem_euclid(n),
        Wrap::Clamp => i.clamp(0, n - 1),
        Wrap::Mirror => {
            let t = i.rem_euclid(2 * n);
            if t < n {
                t
            } else {
                2 * n - 1 - t
            }
        }
    }) as u32
}

impl<'a> Sampler<'a> {
    pub fn new(texture: &'a Texture) -> Sampler<'a> {
        Sampler {
            image: texture,
            mips: texture.halvings(),
            wrap_u: texture.wrap_u,
            wrap_v: texture.wrap_v,
            filter: texture.filter,
        }
    }

    pub fn levels(&self) -> usize {
        1 + self.mips.len()
    }

    fn level(&self, k: usize) -> LevelRef<'_> {
        let (width, height, texels) = match k {
            0 => (self.image.width, self.image.height, &self.image.texels),
            _ => {
                let l = &self.mips[k - 1];
                (l.width, l.height, &l.texels)
            }
        };
        LevelRef {
            width,
            height,
            texels,
            srgb: self.image.srgb,
        }
    }

    /// The continuous mip level for a footprint `width` in uv units: log2 of the footprint
    /// in level-0 texels along the larger side, clamped to the chain.
    pub fn lod(&self, width: f32) -> f32 {
        let texels = width * self.image.width.max(self.image.height) as f32;
        let max = self.mips.len() as f32;
        if texels.is_nan() || texels <= 1.0 {
            0.0
        } else {
            texels.log2().min(max)
        }
    }

    /// Linear RGBA at `uv` (already tiled) for a pixel footprint `width` in uv units.
    /// Point and bilinear read the nearest mip level; trilinear blends the two around it.
    pub fn sample(&self, uv: Vec2, width: f32) -> Vec4 {
        let lod = self.lod(width);
        match self.filter {
            Filter::Point => self.point(self.nearest(lod), uv),
            Filter::Bilinear => self.bilinear(self.nearest(lod), uv),
            Filter::Trilinear => {
                let lo = lod.floor() as usize;
                let f = lod - lo as f32;
                let a = self.bilinear(lo, uv);
                if f == 0.0 || lo + 1 >= self.levels() {
                    a
                } else {
                    mix(a, self.bilinear(lo + 1, uv), f)
                }
            }
        }
    }

    /// A lookup at a mesh uv through a material's tiling, filtered as `filter` says:
    /// [`TextureFilter::Cone`] is [`Sampler::sample_tiled`] (the texture's own filter mode
    /// and mip maps, the level from the footprint `width`); `Point` and `Bilinear` read the
    /// full-size image whatever the import settings, ignoring `width`.
    pub fn lookup(&self, filter: TextureFilter, tiling: &Tiling, uv: Vec2, width: f32) -> Vec4 {
        match filter {
            TextureFilter::Cone => self.sample_tiled(tiling, uv, width),
            TextureFilter::Point => self.point(0, Vec2::from_array(tiling.apply(uv.to_array()))),
            TextureFilter::Bilinear => {
                self.bilinear(0, Vec2::from_array(tiling.apply(uv.to_array())))
            }
        }
    }

    /// Bytes the mip levels below the image hold (four per texel).
    pub fn bytes(&self) -> u64 {
        self.mips.iter().map(|l| l.texels.len() as u64).sum()
    }

    /// [`Sampler::sample`] at a mesh uv through a material's tiling.
    pub fn sample_tiled(&self, tiling: &Tiling, uv: Vec2, width: f32) -> Vec4 {
        let t = tiling.apply(uv.to_array());
        self.sample(Vec2::from_array(t), tiling.footprint(width))
    }

    fn nearest(&self, lod: f32) -> usize {
        ((lod + 0.5).floor() as usize).min(self.mips.len())
    }

    fn point(&self, level: usize, uv: Vec2) -> Vec4 {
        let l = self.level(level);
        let (w, h) = l.size();
        let x = (uv.x as f64 * w as f64).floor() as i64;
        let y = (uv.y as f64 * h as f64).floor() as i64;
        l.texel(wrap(x, w, self.wrap_u), wrap(y, h, self.wrap_v))
    }

    fn bilinear(&self, level: usize, uv: Vec2) -> Vec4 {
        let l = self.level(level);
        let (w, h) = l.size();
        let x = uv.x as f64 * w as f64 - 0.5;
        let y = uv.y as f64 * h as f64 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = ((x - x0) as f32, (y - y0) as f32);
        let (x0, y0) = (x0 as i64, y0 as i64);
        // Each of the four coordinates wrapped once, not once per texel read.
        let (xa, xb) = (wrap(x0, w, self.wrap_u), wrap(x0 + 1, w, self.wrap_u));
        let (ya, yb) = (wrap(y0, h, self.wrap_v), wrap(y0 + 1, h, self.wrap_v));
        let bottom = mix(l.texel(xa, ya), l.texel(xb, ya), fx);
        let top = mix(l.texel(xa, yb), l.texel(xb, yb), fx);
        mix(bottom, top, fy)
    }
}

/// Bytes a [`Sampler`] of `t` will hold beside the soup's image, without building it:
/// when mip-mapped, every halving down to 1×1, four bytes per texel.
pub fn sampler_bytes(t: &Texture) -> u64 {
    let (mut w, mut h) = (t.width.max(1) as u64, t.height.max(1) as u64);
    let mut texels = 0;
    while t.mipmaps && (w > 1 || h > 1) {
        (w, h) = ((w / 2).max(1), (h / 2).max(1));
        texels += w * h;
    }
    texels * 4
}

/// The smallest alpha of any texel of `t` (0–1): a material whose opacity times this
/// reaches its cut-off, or 1 for a blend, never shows a hole.
pub fn min_alpha(t: &Texture) -> f32 {
    let code = t.texels.chunks_exact(4).map(|c| c[3]).min().unwrap_or(255);
    formats::texture::decode_u8(code, false)
}

/// The uv-space footprint of a ray cone of `cone_width` (world units, at the hit) on a
/// triangle with corners `p` and uvs `uv`, hit along unit direction `dir`: the cone's width
/// scaled by the triangle's uv-per-world ratio (square root of the area ratio) and
/// stretched by the incidence angle. Zero for a triangle with no area in either space.
pub fn cone_footprint(cone_width: f32, dir: Vec3, p: [Vec3; 3], uv: [Vec2; 3]) -> f32 {
    let n = (p[1] - p[0]).cross(p[2] - p[0]);
    let world_area = n.length();
    let uv_area = (uv[1] - uv[0]).perp_dot(uv[2] - uv[0]).abs();
    if world_area <= 0.0 || uv_area <= 0.0 || !world_area.is_finite() {
        return 0.0;
    }
    // Grazing hits would give an unbounded footprint: cap the stretch at 1/0.01.
    let cos = (n.dot(dir).abs() / world_area).max(0.01);
    cone_width * (uv_area / world_area).sqrt() / cos
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Linear values that 8-bit codes hit exactly (no sRGB curve).
    fn texture(w: u32, h: u32, rgba: &[[u8; 4]], filter: Filter, wrap: Wrap) -> Texture {
        Texture {
            source: "t".into(),
            width: w,
            height: h,
            texels: rgba.concat(),
            srgb: false,
            wrap_u: wrap,
            wrap_v: wrap,
            filter,
            mipmaps: true,
        }
    }

    /// A sampler of a texture that lives as long as the test.
    fn sampler(t: Texture) -> Sampler<'static> {
        Sampler::new(Box::leak(Box::new(t)))
    }

    /// Bottom row: red, green; top row: blue, white.
    fn two_by_two(filter: Filter, wrap: Wrap) -> Sampler<'static> {
        sampler(texture(
            2,
            2,
            &[
                [255, 0, 0, 255],
                [0, 255, 0, 255],
                [0, 0, 255, 255],
                [255, 255, 255, 255],
            ],
            filter,
            wrap,
        ))
    }

    const RED: Vec4 = Vec4::new(1.0, 0.0, 0.0, 1.0);
    const GREEN: Vec4 = Vec4::new(0.0, 1.0, 0.0, 1.0);
    const BLUE: Vec4 = Vec4::new(0.0, 0.0, 1.0, 1.0);
    const WHITE: Vec4 = Vec4::ONE;

    #[test]
    fn corners() {
        for f in [Filter::Point, Filter::Bilinear, Filter::Trilinear] {
            let s = two_by_two(f, Wrap::Clamp);
            assert_eq!(s.sample(Vec2::new(0.25, 0.25), 0.0), RED, "{f:?}");
            assert_eq!(s.sample(Vec2::new(0.75, 0.25), 0.0), GREEN, "{f:?}");
            assert_eq!(s.sample(Vec2::new(0.25, 0.75), 0.0), BLUE, "{f:?}");
            assert_eq!(s.sample(Vec2::new(0.75, 0.75), 0.0), WHITE, "{f:?}");
            // Clamped, the outer corners are the corner texels too.
            assert_eq!(s.sample(Vec2::new(0.0, 0.0), 0.0), RED, "{f:?}");
            assert_eq!(s.sample(Vec2::new(1.0, 1.0), 0.0), WHITE, "{f:?}");
        }
    }

    #[test]
    fn bilinear_midpoints() {
        let s = two_by_two(Filter::Bilinear, Wrap::Clamp);
        assert_eq!(
            s.sample(Vec2::new(0.5, 0.25), 0.0),
            Vec4::new(0.5, 0.5, 0.0, 1.0)
        );
        assert_eq!(
            s.sample(Vec2::new(0.25, 0.5), 0.0),
            Vec4::new(0.5, 0.0, 0.5, 1.0)
        );
        assert_eq!(
            s.sample(Vec2::new(0.5, 0.5), 0.0),
            Vec4::new(0.5, 0.5, 0.5, 1.0)
        );
    }

    #[test]
    fn wrap_modes_outside_the_unit_square() {
        // Point sampling the bottom row at u = −0.25 (texel −1) and u = 1.25 (texel 2).
        let at = |wrap, u| two_by_two(Filter::Point, wrap).sample(Vec2::new(u, 0.25), 0.0);
        assert_eq!(at(Wrap::Repeat, -0.25), GREEN);
        assert_eq!(at(Wrap::Repeat, 1.25), RED);
        assert_eq!(at(Wrap::Clamp, -0.25), RED);
        assert_eq!(at(Wrap::Clamp, 1.25), GREEN);
        assert_eq!(at(Wrap::Mirror, -0.25), RED);
        assert_eq!(at(Wrap::Mirror, 1.25), GREEN);
        // Bilinear at u = 0: repeat blends the two edge texels, clamp does not.
        let b = |wrap| two_by_two(Filter::Bilinear, wrap).sample(Vec2::new(0.0, 0.25), 0.0);
        assert_eq!(b(Wrap::Repeat), Vec4::new(0.5, 0.5, 0.0, 1.0));
        assert_eq!(b(Wrap::Clamp), RED);
        assert_eq!(b(Wrap::Mirror), RED);
    }

    #[test]
    fn negative_tiling_mirrors_the_image() {
        let s = two_by_two(Filter::Point, Wrap::Repeat);
        let flip = Tiling {
            scale: [-1.0, 1.0],
            offset: [0.0, 0.0],
        };
        assert_eq!(s.sample_tiled(&flip, Vec2::new(0.25, 0.25), 0.0), GREEN);
    }

    #[test]
    fn mip_level_for_footprint() {
        let s = sampler(texture(
            16,
            16,
            &vec![[9, 9, 9, 9]; 256],
            Filter::Trilinear,
            Wrap::Repeat,
        ));
        assert_eq!(s.levels(), 5);
        assert_eq!(s.lod(0.25 / 16.0), 0.0);
        assert_eq!(s.lod(4.0 / 16.0), 2.0);
        assert_eq!(s.lod(100.0), 4.0);
        assert_eq!(s.nearest(s.lod(4.0 / 16.0)), 2);
    }

    #[test]
    fn constant_texture_is_constant_at_every_level() {
        let c = [200, 17, 99, 128];
        for filter in [Filter::Point, Filter::Bilinear, Filter::Trilinear] {
            let mut t = texture(7, 5, &[c; 35], filter, Wrap::Mirror);
            t.srgb = true;
            let want = Vec4::from_array(t.texel(0, 0));
            let s = Sampler::new(&t);
            for k in 0..40 {
                let width = 2f32.powf(k as f32 * 0.25 - 6.0);
                let uv = Vec2::new(k as f32 * 0.37 - 3.0, k as f32 * -0.61 + 1.0);
                assert_eq!(s.sample(uv, width), want, "{filter:?} width {width}");
            }
        }
    }

    #[test]
    fn knob_overrides_and_sizes() {
        let s = two_by_two(Filter::Trilinear, Wrap::Clamp);
        let t = Tiling::default();
        // Half-way between texel centres: point picks one, bilinear blends, and a footprint
        // of the whole texture reads the 1×1 level, the mean 0.5 kept as the code 128.
        let uv = Vec2::new(0.5, 0.25);
        assert_eq!(s.lookup(TextureFilter::Point, &t, uv, 1.0), GREEN);
        assert_eq!(
            s.lookup(TextureFilter::Bilinear, &t, uv, 1.0),
            Vec4::new(0.5, 0.5, 0.0, 1.0)
        );
        assert_eq!(
            s.lookup(TextureFilter::Cone, &t, uv, 2.0),
            Vec4::new(128.0 / 255.0, 128.0 / 255.0, 128.0 / 255.0, 1.0)
        );
        let tex = texture(5, 3, &[[0, 0, 0, 7]; 15], Filter::Bilinear, Wrap::Repeat);
        assert_eq!(sampler_bytes(&tex), Sampler::new(&tex).bytes());
        assert_eq!(sampler_bytes(&tex), (2 + 1) * 4);
        assert_eq!(min_alpha(&tex), 7.0 / 255.0);
    }

    #[test]
    fn footprint_of_a_cone() {
        // A 2 m square in XY mapped to the unit uv square: 0.5 uv per metre.
        let p = [
            Vec3::ZERO,
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(0.0, 2.0, 0.0),
        ];
        let uv = [Vec2::ZERO, Vec2::new(1.0, 0.0), Vec2::new(0.0, 1.0)];
        let head_on = cone_footprint(0.1, Vec3::new(0.0, 0.0, -1.0), p, uv);
        assert!((head_on - 0.05).abs() < 1e-7, "{head_on}");
        // At 60° from the normal the cone's section stretches by 1/cos = 2.
        let d = Vec3::new(0.0, 60f32.to_radians().sin(), -(60f32.to_radians().cos()));
        let slanted = cone_footprint(0.1, d, p, uv);
        assert!((slanted - 0.1).abs() < 1e-6, "{slanted}");
        // No uv area: nothing to filter.
        assert_eq!(cone_footprint(0.1, d, p, [Vec2::ZERO; 3]), 0.0);
    }
}
