//! What a Skybox camera sees where no surface is: Unity's procedural sky, or a sky drawn
//! from images (the Skybox/Panoramic, Skybox/Cubemap and Skybox/6 Sided shaders).
//!
//! Image skies keep their texels in Ward's RGBE encoding (three 8-bit mantissas sharing
//! one exponent, 4 bytes per texel): HDR images (the usual skybox) keep their range at
//! the size of an 8-bit RGBA albedo map. Each channel is kept to within 1/256 of its
//! texel's brightest channel: the brightest to under 0.4 %, a dim channel beside a bright
//! one less well (a red of 0.021 beside a blue of 1 reads 0.023).

use glam::Vec3;
use serde::{Deserialize, Serialize};

use crate::texture::MAX_SIDE;

/// RenderSettings' skybox material, as the renderer draws it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum Sky {
    Procedural(ProceduralSky),
    Textured(TexturedSky),
}

impl Sky {
    pub(crate) fn validate(&self) -> Result<(), String> {
        match self {
            Sky::Procedural(p) => p.validate(),
            Sky::Textured(t) => t.validate(),
        }
    }
}

/// Which sun disk Unity's procedural sky draws (its `_SUNDISK_*` keyword).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum SunDisk {
    None,
    Simple,
    HighQuality,
}

/// A Skybox/Procedural material's settings and the sun it shows.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ProceduralSky {
    pub sun_disk: SunDisk,
    /// `_SunSize`, `_SunSizeConvergence`, `_AtmosphereThickness`, `_Exposure`.
    pub sun_size: f32,
    pub sun_size_convergence: f32,
    pub atmosphere_thickness: f32,
    pub exposure: f32,
    /// `_SkyTint` and `_GroundColor`, linear RGB.
    pub sky_tint: Vec3,
    pub ground: Vec3,
    /// Unit vector towards the sun light (Unity's `_WorldSpaceLightPos0`).
    pub sun_direction: Vec3,
    /// The sun light's colour × intensity, linear RGB; black without a sun.
    pub sun_colour: Vec3,
}

impl ProceduralSky {
    fn validate(&self) -> Result<(), String> {
        let numbers = [
            self.sun_size,
            self.sun_size_convergence,
            self.atmosphere_thickness,
            self.exposure,
        ];
        let colours = [
            self.sky_tint,
            self.ground,
            self.sun_direction,
            self.sun_colour,
        ];
        if numbers.iter().all(|x| x.is_finite()) && colours.iter().all(|c| c.is_finite()) {
            Ok(())
        } else {
            Err(format!("procedural sky {self:?} holds a non-finite number"))
        }
    }
}

/// A sky drawn from images. Directions are Unity's (left-handed): a soup direction
/// (x, y, z) looks up (−x, y, z), turned by −`rotation` about +Y first, as Unity turns the
/// sky mesh by `_Rotation` and samples with the unturned vertex.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TexturedSky {
    /// The shader's factor on every texel: `_Tint` (linear) × `unity_ColorSpaceDouble`
    /// (4.59479, so the default grey tint is 0.98) × `_Exposure`.
    pub scale: Vec3,
    /// `_Rotation`, degrees about +Y.
    pub rotation: f32,
    pub layout: SkyLayout,
}

/// How a direction finds its texel.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum SkyLayout {
    /// One equirectangular image (Skybox/Panoramic's latitude-longitude mapping, or a
    /// cubemap imported from one): u = 0.5 − atan2(z, x)/2π, v = 1 − acos(y)/π, u wrapping
    /// around, v clamped.
    LatLong { image: SkyImage, panorama: Panorama },
    /// Six faces in the order +X, −X, +Y, −Y, +Z, −Z, each upright as seen from inside
    /// the cube: u grows towards −Z, +Z, +X, +X, +X, −X and v (up) towards +Y on the four
    /// sides, −Z on +Y's face and +Z on −Y's. Each face is clamped at its edges.
    Cube { faces: Vec<SkyImage> },
}

/// How much of the sphere a latitude-longitude image covers (`_ImageType`,
/// `_MirrorOnBack`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Panorama {
    /// The whole sphere.
    Full,
    /// The front half (u < 0.5 of the sphere, the image stretched over it); black behind.
    Half,
    /// The front half, mirrored onto the back.
    HalfMirrored,
}

/// One image of a textured sky: RGBE texels (R, G, B mantissas, then the exponent + 128;
/// an exponent byte of 0 is black), bottom row first, like the soup's textures.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SkyImage {
    /// Asset path relative to the project (for messages).
    pub source: String,
    pub width: u32,
    pub height: u32,
    #[serde(with = "serde_bytes")]
    pub texels: Vec<u8>,
}

impl TexturedSky {
    fn validate(&self) -> Result<(), String> {
        if !self.scale.is_finite() || self.scale.min_element() < 0.0 {
            return Err(format!("sky scale {} is not a colour", self.scale));
        }
        if !self.rotation.is_finite() {
            return Err(format!("sky rotation {}", self.rotation));
        }
        match &self.layout {
            SkyLayout::LatLong { image, .. } => image.validate(),
            SkyLayout::Cube { faces } if faces.len() != 6 => {
                Err(format!("a cube sky with {} faces", faces.len()))
            }
            SkyLayout::Cube { faces } => faces.iter().try_for_each(SkyImage::validate),
        }
    }
}

impl SkyImage {
    /// An image `width` texels wide from linear RGB rows, bottom row first.
    pub fn from_linear(source: &str, width: u32, height: u32, rgb: &[Vec3]) -> SkyImage {
        SkyImage {
            source: source.to_string(),
            width,
            height,
            texels: rgb.iter().flat_map(|&c| encode_rgbe(c)).collect(),
        }
    }

    fn validate(&self) -> Result<(), String> {
        let (w, h) = (self.width, self.height);
        if w == 0 || h == 0 || w > MAX_SIDE || h > MAX_SIDE {
            return Err(format!("sky image {}: {w}x{h}", self.source));
        }
        let want = w as usize * h as usize * 4;
        if self.texels.len() != want {
            return Err(format!(
                "sky image {}: {} texel bytes for {w}x{h} (want {want})",
                self.source,
                self.texels.len()
            ));
        }
        Ok(())
    }

    /// Texel (x, y) as linear RGB (y = 0 is the bottom row).
    #[inline]
    pub fn texel(&self, x: u32, y: u32) -> Vec3 {
        let i = (y as usize * self.width as usize + x as usize) * 4;
        let t = &self.texels[i..i + 4];
        decode_rgbe([t[0], t[1], t[2], t[3]])
    }
}

/// 2^(e − 136) for every exponent byte e: a mantissa byte's weight.
fn weights() -> &'static [f32; 256] {
    static TABLE: std::sync::OnceLock<[f32; 256]> = std::sync::OnceLock::new();
    TABLE.get_or_init(|| std::array::from_fn(|e| (2f64.powi(e as i32 - 136)) as f32))
}

/// Linear RGB as RGBE: the brightest channel's mantissa rounded to 8 bits (128–255), the
/// others on the same exponent. Negative and NaN channels are black; values beyond 2^127
/// saturate; below 2^−126 is black. Powers of two and their small multiples are exact.
pub fn encode_rgbe(c: Vec3) -> [u8; 4] {
    let c = Vec3::new(clean(c.x), clean(c.y), clean(c.z));
    let v = c.max_element().min(f32::MAX);
    if v < f32::MIN_POSITIVE {
        return [0; 4];
    }
    // frexp: v = m·2^e with m in [0.5, 1).
    let mut e = ((v.to_bits() >> 23) & 0xff) as i32 - 126;
    let quantise = |x: f32, e: i32| (x as f64 * 2f64.powi(8 - e)).round() as u32;
    if quantise(v, e) > 255 {
        e += 1;
    }
    let e = e.min(127);
    let q = |x: f32| quantise(x, e).min(255) as u8;
    [q(c.x), q(c.y), q(c.z), (e + 128) as u8]
}

fn clean(x: f32) -> f32 {
    if x > 0.0 {
        x
    } else {
        0.0
    }
}

/// RGBE as linear RGB.
#[inline]
pub fn decode_rgbe(t: [u8; 4]) -> Vec3 {
    if t[3] == 0 {
        return Vec3::ZERO;
    }
    let w = weights()[t[3] as usize];
    Vec3::new(t[0] as f32, t[1] as f32, t[2] as f32) * w
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rgbe_keeps_powers_of_two_and_the_brightest_channel_to_half_a_percent() {
        for c in [
            Vec3::ONE,
            Vec3::new(0.5, 0.25, 2.0),
            Vec3::new(4096.0, 0.0, 512.0),
        ] {
            assert_eq!(decode_rgbe(encode_rgbe(c)), c);
        }
        assert_eq!(
            decode_rgbe(encode_rgbe(Vec3::new(-1.0, f32::NAN, 0.0))),
            Vec3::ZERO
        );
        let mut x = 1.0e-30f32;
        while x < 1.0e30 {
            let c = Vec3::new(x, 0.3 * x, 0.999 * x);
            let d = decode_rgbe(encode_rgbe(c));
            assert!((d.x - x).abs() <= x / 256.0, "{x}: {d}");
            assert!((d.z - c.z).abs() <= x / 256.0, "{x}: {d}");
            x *= 1.37;
        }
        // Rounding up to 256 moves to the next exponent.
        let d = decode_rgbe(encode_rgbe(Vec3::splat(0.99999)));
        assert_eq!(d, Vec3::ONE);
        assert_eq!(
            decode_rgbe(encode_rgbe(Vec3::splat(f32::INFINITY))).x,
            255.0 * 2f32.powi(119)
        );
    }
}
