//! Skies drawn from images, as Unity's Skybox/Panoramic, Skybox/Cubemap and Skybox/6 Sided
//! shaders draw them: the direction turned by the material's rotation, looked up in a
//! latitude-longitude image or on a cube's faces, times the material's tint and exposure.
//!
//! A lookup is filtered over the ray cone's footprint, as the GPU filters a mip-mapped
//! texture: bilinearly in the full-size image while a pixel covers at most a texel,
//! trilinearly between box-filtered halvings of it once the cone spreads over more
//! (Unity imports sky textures with mip maps). The halvings are built at the first such
//! lookup, so a sky seen magnified, as most are, costs none.

use crate::sky::{add_sample, SkyAmbient};
use formats::{Panorama, SkyImage, SkyLayout, TexturedSky};
use glam::Vec3;
use rayon::prelude::*;
use std::f32::consts::PI;
use std::sync::OnceLock;

/// An image sky with its rotation worked out once.
pub struct ImageSky<'a> {
    sky: &'a TexturedSky,
    cos: f32,
    sin: f32,
    /// Per image (one, or six faces), its halvings below the full size.
    mips: Vec<OnceLock<Vec<Level>>>,
}

/// One box-filtered halving of a sky image, linear RGB, rows bottom up.
struct Level {
    width: u32,
    height: u32,
    texels: Vec<Vec3>,
}

impl Level {
    /// The next halving: each texel the mean of the 2×2 block above it (a last odd row or
    /// column folds into the block before it), down to one texel.
    fn halve(width: u32, height: u32, texel: impl Fn(u32, u32) -> Vec3) -> Level {
        let (w, h) = ((width / 2).max(1), (height / 2).max(1));
        let span = |i: u32, n: u32, out: u32| {
            let lo = i * n / out;
            (lo, ((i + 1) * n / out).max(lo + 1))
        };
        let texels = (0..h)
            .flat_map(|y| (0..w).map(move |x| (x, y)))
            .map(|(x, y)| {
                let ((x0, x1), (y0, y1)) = (span(x, width, w), span(y, height, h));
                let mut sum = Vec3::ZERO;
                for j in y0..y1 {
                    for i in x0..x1 {
                        sum += texel(i, j);
                    }
                }
                sum / ((x1 - x0) * (y1 - y0)) as f32
            })
            .collect();
        Level {
            width: w,
            height: h,
            texels,
        }
    }

    fn texel(&self, x: u32, y: u32) -> Vec3 {
        self.texels[(y * self.width + x) as usize]
    }
}

/// Every halving of `image`, down to one texel.
fn mip_levels(image: &SkyImage) -> Vec<Level> {
    let mut levels = vec![Level::halve(image.width, image.height, |x, y| {
        image.texel(x, y)
    })];
    while let Some(l) = levels.last().filter(|l| l.width > 1 || l.height > 1) {
        let next = Level::halve(l.width, l.height, |x, y| l.texel(x, y));
        levels.push(next);
    }
    levels
}

impl<'a> ImageSky<'a> {
    pub fn new(sky: &'a TexturedSky) -> Self {
        let (sin, cos) = sky.rotation.to_radians().sin_cos();
        let images = match &sky.layout {
            SkyLayout::LatLong { .. } => 1,
            SkyLayout::Cube { faces } => faces.len(),
        };
        ImageSky {
            sky,
            cos,
            sin,
            mips: (0..images).map(|_| OnceLock::new()).collect(),
        }
    }

    /// Radiance along unit soup direction `dir`, read in the full-size image.
    pub fn radiance(&self, dir: Vec3) -> Vec3 {
        self.radiance_in_cone(dir, 0.0)
    }

    /// Radiance along unit soup direction `dir` seen by a ray cone `spread` radians wide.
    pub fn radiance_in_cone(&self, dir: Vec3, spread: f32) -> Vec3 {
        self.unscaled(self.unity_direction(dir), spread) * self.sky.scale
    }

    /// The direction the shader samples for soup direction `dir`: X negated into Unity's
    /// axes, then turned back by the rotation Unity gives the sky mesh.
    fn unity_direction(&self, dir: Vec3) -> Vec3 {
        let (x, z) = (-dir.x, dir.z);
        Vec3::new(
            self.cos * x + self.sin * z,
            dir.y,
            -self.sin * x + self.cos * z,
        )
    }

    /// [`ImageSky::unity_direction`] undone: the soup direction whose lookup is Unity
    /// direction `d`.
    fn soup_direction(&self, d: Vec3) -> Vec3 {
        let x = self.cos * d.x - self.sin * d.z;
        Vec3::new(-x, d.y, self.sin * d.x + self.cos * d.z)
    }

    /// The texels' radiance along Unity direction `d` (not normalised), before the
    /// material's scale, over a cone `spread` radians wide.
    fn unscaled(&self, d: Vec3, spread: f32) -> Vec3 {
        match &self.sky.layout {
            SkyLayout::LatLong { image, panorama } => {
                let d = d.normalize_or_zero();
                let [mut u, v] = lat_long(d);
                let mut columns = image.width as f32;
                match panorama {
                    Panorama::Full => {}
                    Panorama::Half if u > 0.5 => return Vec3::ZERO,
                    // The shader takes u·2 modulo 1: the back half repeats the front.
                    Panorama::Half | Panorama::HalfMirrored => {
                        u = (u * 2.0).fract();
                        columns *= 2.0;
                    }
                }
                // Texels per radian: along a meridian, and along the parallel, where they
                // crowd towards the poles; the denser decides, as on the GPU.
                let ring = (1.0 - d.y * d.y).max(0.0).sqrt().max(1e-3);
                let density = (image.height as f32 / PI).max(columns / (2.0 * PI) / ring);
                self.filtered(0, image, u, v, true, spread * density)
            }
            SkyLayout::Cube { faces } => {
                let (face, u, v) = cube_face(d);
                // Half a face's texels per unit of the face's tangent plane, which a
                // radian stretches by up to 1 + a² + b² away from the face's centre.
                let (a, b) = (2.0 * u - 1.0, 2.0 * v - 1.0);
                let image = &faces[face];
                let density = image.width.max(image.height) as f32 / 2.0 * (1.0 + a * a + b * b);
                self.filtered(face, image, u, v, false, spread * density)
            }
        }
    }

    /// Image `i` at (u, v) over a footprint `texels` wide in the full-size image:
    /// bilinear there up to one texel, else trilinear between the two halvings whose
    /// texels are nearest the footprint's size.
    fn filtered(
        &self,
        i: usize,
        image: &SkyImage,
        u: f32,
        v: f32,
        wrap: bool,
        texels: f32,
    ) -> Vec3 {
        let full = |u, v| {
            bilinear(image.width, image.height, u, v, wrap, |x, y| {
                image.texel(x, y)
            })
        };
        // NaN (no cone) reads the full-size image too.
        if texels.is_nan() || texels <= 1.0 {
            return full(u, v);
        }
        let levels = self.mips[i].get_or_init(|| mip_levels(image));
        let lod = texels.log2().min(levels.len() as f32);
        let at = |k: usize| match k {
            0 => full(u, v),
            k => {
                let l = &levels[k.min(levels.len()) - 1];
                bilinear(l.width, l.height, u, v, wrap, |x, y| l.texel(x, y))
            }
        };
        let k = lod.floor();
        at(k as usize).lerp(at(k as usize + 1), lod - k)
    }

    /// Its ambient light, `intensity` times, on nine spherical harmonics: each texel's
    /// radiance weighted by the solid angle it covers, so a small bright sun in an HDR
    /// image counts with all of its energy however few texels it has. Rows are summed on
    /// every core, then added in row order, so the sums are the same on any thread count.
    pub fn ambient(&self, intensity: f32) -> SkyAmbient {
        let (images, columns): (Vec<&SkyImage>, Columns) = match &self.sky.layout {
            SkyLayout::LatLong { image, panorama } => {
                (vec![image], Columns::new(image.width, *panorama))
            }
            SkyLayout::Cube { faces } => (faces.iter().collect(), Columns::default()),
        };
        let rows: Vec<(usize, u32)> = images
            .iter()
            .enumerate()
            .flat_map(|(i, image)| (0..image.height).map(move |y| (i, y)))
            .collect();
        let sums: Vec<[Vec3; 9]> = rows
            .par_iter()
            .map(|&(i, y)| {
                let mut sums = [Vec3::ZERO; 9];
                match &self.sky.layout {
                    SkyLayout::LatLong { .. } => {
                        self.lat_long_row(images[i], &columns, y, &mut sums)
                    }
                    SkyLayout::Cube { .. } => self.face_row(i, images[i], y, &mut sums),
                }
                sums
            })
            .collect();
        let total = sums.iter().fold([Vec3::ZERO; 9], |mut t, s| {
            t.iter_mut().zip(s).for_each(|(t, s)| *t += *s);
            t
        });
        SkyAmbient::from_sums(total, intensity)
    }

    /// Add texel (x, y)'s radiance, as seen along Unity direction `d` over solid angle
    /// `area`, to harmonic `sums` (whose directions are the soup's).
    fn add_texel(
        &self,
        sums: &mut [Vec3; 9],
        image: &SkyImage,
        x: u32,
        y: u32,
        d: Vec3,
        area: f32,
    ) {
        let l = image.texel(x, y) * self.sky.scale;
        add_sample(sums, self.soup_direction(d).normalize(), l * area);
    }

    /// One row of a latitude-longitude image, its texels' azimuths from `columns`.
    fn lat_long_row(&self, image: &SkyImage, columns: &Columns, y: u32, sums: &mut [Vec3; 9]) {
        let v = (y as f32 + 0.5) / image.height as f32;
        let (ring, height) = (PI * (1.0 - v)).sin_cos();
        let area = columns.area * (PI / image.height as f32) * ring;
        for &(x, cos, sin) in &columns.texels {
            let d = Vec3::new(ring * cos, height, ring * sin);
            self.add_texel(sums, image, x, y, d, area);
        }
    }

    /// One row of cube face `f`: a texel at face coordinates (a, b) covers
    /// da·db / (1 + a² + b²)^(3/2) steradians.
    fn face_row(&self, f: usize, face: &SkyImage, y: u32, sums: &mut [Vec3; 9]) {
        let (w, h) = (face.width, face.height);
        let (du, dv) = (2.0 / w as f32, 2.0 / h as f32);
        let b = (y as f32 + 0.5) * dv - 1.0;
        for x in 0..w {
            let a = (x as f32 + 0.5) * du - 1.0;
            let area = du * dv / (1.0 + a * a + b * b).powf(1.5);
            self.add_texel(sums, face, x, y, from_cube_face(f, a, b), area);
        }
    }
}

/// A latitude-longitude image's columns as the azimuths they cover: each texel's column
/// and the cosine and sine of its longitude, and the azimuth one texel spans. A half
/// panorama stretches the image over half the turn: each texel covers half the azimuth,
/// once or (mirrored) twice.
#[derive(Default)]
struct Columns {
    texels: Vec<(u32, f32, f32)>,
    area: f32,
}

impl Columns {
    fn new(width: u32, panorama: Panorama) -> Self {
        let (copies, span): (&[f32], f32) = match panorama {
            Panorama::Full => (&[0.0], 1.0),
            Panorama::Half => (&[0.0], 0.5),
            Panorama::HalfMirrored => (&[0.0, 1.0], 0.5),
        };
        let texels = (0..width)
            .flat_map(|x| {
                copies.iter().map(move |c| {
                    let u = ((x as f32 + 0.5) / width as f32 + c) * span;
                    let (sin, cos) = ((0.5 - u) * 2.0 * PI).sin_cos();
                    (x, cos, sin)
                })
            })
            .collect();
        Columns {
            texels,
            area: 2.0 * PI * span / width as f32,
        }
    }
}

/// Unit Unity direction → the panoramic shader's (u, v).
fn lat_long(d: Vec3) -> [f32; 2] {
    let latitude = d.y.clamp(-1.0, 1.0).acos();
    let longitude = d.z.atan2(d.x);
    [0.5 - longitude / (2.0 * PI), 1.0 - latitude / PI]
}

/// Which face (+X, −X, +Y, −Y, +Z, −Z) a Unity direction meets, and where on it (u, v in
/// [0, 1], v up, as [`SkyLayout::Cube`] orients the faces).
fn cube_face(d: Vec3) -> (usize, f32, f32) {
    let a = d.abs();
    let (face, s, t, m) = if a.x >= a.y && a.x >= a.z {
        if d.x > 0.0 {
            (0, -d.z, d.y, a.x)
        } else {
            (1, d.z, d.y, a.x)
        }
    } else if a.y >= a.z {
        if d.y > 0.0 {
            (2, d.x, -d.z, a.y)
        } else {
            (3, d.x, d.z, a.y)
        }
    } else if d.z > 0.0 {
        (4, d.x, d.y, a.z)
    } else {
        (5, -d.x, d.y, a.z)
    };
    if m <= 0.0 {
        return (4, 0.5, 0.5);
    }
    (face, 0.5 * (s / m + 1.0), 0.5 * (t / m + 1.0))
}

/// The Unity direction through face coordinates (a, b) in [−1, 1] of face `f`.
fn from_cube_face(f: usize, a: f32, b: f32) -> Vec3 {
    match f {
        0 => Vec3::new(1.0, b, -a),
        1 => Vec3::new(-1.0, b, a),
        2 => Vec3::new(a, 1.0, -b),
        3 => Vec3::new(a, -1.0, b),
        4 => Vec3::new(a, b, 1.0),
        _ => Vec3::new(-a, b, -1.0),
    }
}

/// Bilinear lookup at (u, v) in a `w` × `h` image whose texels `texel` reads, texel centres
/// at half-integers; u wraps around when `wrap`, else both axes clamp at the edge texels.
fn bilinear(w: u32, h: u32, u: f32, v: f32, wrap: bool, texel: impl Fn(u32, u32) -> Vec3) -> Vec3 {
    let x = u * w as f32 - 0.5;
    let y = v * h as f32 - 0.5;
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = (x - x0, y - y0);
    let column = |i: f32| -> u32 {
        let i = i as i64;
        if wrap {
            i.rem_euclid(w as i64) as u32
        } else {
            i.clamp(0, w as i64 - 1) as u32
        }
    };
    let row = |j: f32| -> u32 { (j as i64).clamp(0, h as i64 - 1) as u32 };
    let (xa, xb, ya, yb) = (column(x0), column(x0 + 1.0), row(y0), row(y0 + 1.0));
    let bottom = texel(xa, ya).lerp(texel(xb, ya), fx);
    let top = texel(xa, yb).lerp(texel(xb, yb), fx);
    bottom.lerp(top, fy)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The Unity direction at (u, v) of a latitude-longitude image.
    fn from_lat_long(u: f32, v: f32) -> Vec3 {
        let latitude = PI * (1.0 - v);
        let longitude = (0.5 - u) * 2.0 * PI;
        let ring = latitude.sin();
        Vec3::new(
            ring * longitude.cos(),
            latitude.cos(),
            ring * longitude.sin(),
        )
    }

    #[test]
    fn lat_long_and_cube_coordinates_invert() {
        for &(u, v) in &[(0.1, 0.2), (0.5, 0.5), (0.75, 0.9), (0.99, 0.01)] {
            let [u2, v2] = lat_long(from_lat_long(u, v));
            assert!((u - u2).abs() < 1e-5 && (v - v2).abs() < 1e-5, "{u} {v}");
        }
        for f in 0..6 {
            for &(a, b) in &[(0.0, 0.0), (0.5, -0.25), (-0.9, 0.8)] {
                let (g, u, v) = cube_face(from_cube_face(f, a, b));
                assert_eq!(g, f);
                assert!((u - 0.5 * (a + 1.0)).abs() < 1e-6 && (v - 0.5 * (b + 1.0)).abs() < 1e-6);
            }
        }
    }

    #[test]
    fn the_panoramic_shader_s_landmarks() {
        // Straight up is the image's top row, Unity's +X its middle column, +Z a quarter
        // to the left of it, −X its seam.
        assert_eq!(lat_long(Vec3::Y)[1], 1.0);
        assert_eq!(lat_long(Vec3::X), [0.5, 0.5]);
        assert_eq!(lat_long(Vec3::Z), [0.25, 0.5]);
        assert_eq!(lat_long(-Vec3::Z), [0.75, 0.5]);
        assert!(lat_long(-Vec3::X)[0].abs() < 1e-6 || lat_long(-Vec3::X)[0] == 1.0);
    }

    fn sky(layout: SkyLayout, rotation: f32) -> TexturedSky {
        TexturedSky {
            scale: Vec3::new(1.0, 0.5, 2.0),
            rotation,
            layout,
        }
    }

    /// An 8×4 image whose columns (or rows) each hold one power of two.
    fn stripes(columns: bool) -> SkyImage {
        let rgb: Vec<Vec3> = (0..32)
            .map(|i| Vec3::splat(2f32.powi(if columns { i % 8 } else { i / 8 })))
            .collect();
        SkyImage::from_linear("stripes", 8, 4, &rgb)
    }

    #[test]
    fn a_lat_long_sky_reads_the_texels_the_shader_reads() {
        let rows = sky(
            SkyLayout::LatLong {
                image: stripes(false),
                panorama: Panorama::Full,
            },
            0.0,
        );
        let s = ImageSky::new(&rows);
        // Up is the top row (clamped), the horizon halfway between rows 1 and 2.
        assert_eq!(s.radiance(Vec3::Y), Vec3::splat(8.0) * rows.scale);
        assert_eq!(s.radiance(Vec3::Z), Vec3::splat(3.0) * rows.scale);
        assert_eq!(s.radiance(-Vec3::Y), rows.scale);

        let columns = sky(
            SkyLayout::LatLong {
                image: stripes(true),
                panorama: Panorama::Full,
            },
            0.0,
        );
        let s = ImageSky::new(&columns);
        // Unity's +X (the soup's −X) is u = 0.5, between columns 3 and 4; +Z is u = 0.25,
        // between columns 1 and 2; −X the seam, between columns 7 and 0 (wrapped).
        let scale = columns.scale;
        assert_eq!(s.radiance(-Vec3::X), Vec3::splat(12.0) * scale);
        assert_eq!(s.radiance(Vec3::Z), Vec3::splat(3.0) * scale);
        assert_eq!(s.radiance(Vec3::X), Vec3::splat(64.5) * scale);
        // Turned by 90°, Unity's +Z shows what was at +X.
        let turned = sky(columns.layout.clone(), 90.0);
        let t = ImageSky::new(&turned);
        let d = t.radiance(Vec3::Z) - s.radiance(-Vec3::X);
        assert!(d.abs().max_element() < 1e-4, "{d}");
    }

    #[test]
    fn a_half_panorama_is_black_or_mirrored_behind() {
        let half = |panorama| {
            sky(
                SkyLayout::LatLong {
                    image: stripes(true),
                    panorama,
                },
                0.0,
            )
        };
        let black = half(Panorama::Half);
        let mirrored = half(Panorama::HalfMirrored);
        // The front half (Unity's +Z side) stretches the image over 180°: +Z is u = 0.25,
        // the image's middle (between columns 3 and 4).
        for s in [&black, &mirrored] {
            assert_eq!(
                ImageSky::new(s).radiance(Vec3::Z),
                Vec3::splat(12.0) * s.scale
            );
        }
        assert_eq!(ImageSky::new(&black).radiance(-Vec3::Z), Vec3::ZERO);
        assert_eq!(
            ImageSky::new(&mirrored).radiance(-Vec3::Z),
            Vec3::splat(12.0) * mirrored.scale
        );
    }

    #[test]
    fn cube_faces_are_met_where_unity_puts_them() {
        // Face f holds 2^f everywhere.
        let faces = (0..6)
            .map(|f| SkyImage::from_linear("f", 2, 2, &[Vec3::splat(2f32.powi(f)); 4]))
            .collect();
        let cube = sky(SkyLayout::Cube { faces }, 0.0);
        let s = ImageSky::new(&cube);
        // Soup directions: X negated from Unity's.
        let unity = [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z];
        for (f, d) in unity.iter().enumerate() {
            let soup = Vec3::new(-d.x, d.y, d.z);
            assert_eq!(
                s.radiance(soup),
                Vec3::splat(2f32.powi(f as i32)) * cube.scale
            );
        }
    }

    #[test]
    fn a_uniform_sky_lights_every_normal_with_its_radiance() {
        let l = Vec3::new(0.25, 0.5, 1.0);
        let uniform_lat_long = sky(
            SkyLayout::LatLong {
                image: SkyImage::from_linear("u", 64, 32, &[l; 64 * 32]),
                panorama: Panorama::Full,
            },
            33.0,
        );
        let uniform_cube = sky(
            SkyLayout::Cube {
                faces: vec![SkyImage::from_linear("u", 16, 16, &[l; 256]); 6],
            },
            0.0,
        );
        for s in [&uniform_lat_long, &uniform_cube] {
            let ambient = ImageSky::new(s).ambient(1.5);
            for n in [Vec3::Y, -Vec3::Y, Vec3::X, Vec3::new(0.6, 0.0, -0.8)] {
                let want = l * s.scale * 1.5;
                let got = ambient.at(n);
                assert!(
                    ((got - want) / want).abs().max_element() < 2e-3,
                    "{n}: {got} against {want}"
                );
            }
        }
        // Black behind a half panorama: the back (Unity's −Z) gets far less light.
        let half = sky(
            SkyLayout::LatLong {
                image: SkyImage::from_linear("u", 64, 32, &[l; 64 * 32]),
                panorama: Panorama::Half,
            },
            0.0,
        );
        let a = ImageSky::new(&half).ambient(1.0);
        let (front, back) = (a.at(Vec3::Z), a.at(-Vec3::Z));
        let full = l * half.scale;
        assert!((a.at(Vec3::X) - full * 0.5).abs().max_element() < 0.01 * full.max_element());
        assert!(
            front.x > 0.9 * full.x && back.x < 0.1 * full.x,
            "{front} {back}"
        );
    }

    #[test]
    fn the_ambient_sums_do_not_depend_on_the_thread_count() {
        let rgb: Vec<Vec3> = (0..64 * 32)
            .map(|i| Vec3::splat((i % 97) as f32 * 0.37))
            .collect();
        let s = sky(
            SkyLayout::LatLong {
                image: SkyImage::from_linear("r", 64, 32, &rgb),
                panorama: Panorama::Full,
            },
            10.0,
        );
        let on = |threads| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| ImageSky::new(&s).ambient(1.0).at(Vec3::new(0.6, 0.0, 0.8)))
        };
        assert_eq!(on(1), on(2));
        assert_eq!(on(1), on(5));
    }

    #[test]
    fn halvings_average_their_blocks_down_to_one_texel() {
        // 5 × 3: odd both ways, so the last column and row fold into the block before.
        let rgb: Vec<Vec3> = (0..15).map(|i| Vec3::splat(i as f32)).collect();
        let image = SkyImage::from_linear("ramp", 5, 3, &rgb);
        let levels = mip_levels(&image);
        let sizes: Vec<_> = levels.iter().map(|l| (l.width, l.height)).collect();
        assert_eq!(sizes, [(2, 1), (1, 1)]);
        // Level 1's left texel: columns 0–1 of all three rows; its right one columns 2–4.
        let mean = |xs: &[u32]| {
            let all: Vec<f32> = (0..3)
                .flat_map(|y| xs.iter().map(move |&x| (y * 5 + x) as f32))
                .collect();
            all.iter().sum::<f32>() / all.len() as f32
        };
        assert_eq!(levels[0].texel(0, 0).x, mean(&[0, 1]));
        assert_eq!(levels[0].texel(1, 0).x, mean(&[2, 3, 4]));
        let top = levels[1].texel(0, 0).x;
        assert_eq!(top, (mean(&[0, 1]) + mean(&[2, 3, 4])) / 2.0);
    }

    /// Columns alternating 0 and 2 around a 256 × 128 panorama: a cone narrower than a
    /// texel reads the column it points at, as before; one spread over several texels
    /// reads their mean, 1, as a mip-mapped texture on the GPU does, and only then are the
    /// halvings built.
    #[test]
    fn a_wide_cone_reads_the_mean_of_the_texels_it_covers() {
        let (w, h) = (256u32, 128u32);
        let rgb: Vec<Vec3> = (0..w * h)
            .map(|i| Vec3::splat(if i % 2 == 0 { 0.0 } else { 2.0 }))
            .collect();
        let striped = TexturedSky {
            scale: Vec3::ONE,
            rotation: 0.0,
            layout: SkyLayout::LatLong {
                image: SkyImage::from_linear("striped", w, h, &rgb),
                panorama: Panorama::Full,
            },
        };
        let s = ImageSky::new(&striped);
        let texel = PI / h as f32;
        // Along the horizon, a column's centre: x = 100 is u = 100.5 / 256.
        let u = 100.5 / w as f32;
        let longitude = (0.5 - u) * 2.0 * PI;
        let unity = Vec3::new(longitude.cos(), 0.0, longitude.sin());
        let soup = Vec3::new(-unity.x, unity.y, unity.z);
        assert_eq!(s.radiance_in_cone(soup, 0.5 * texel), Vec3::ZERO);
        assert_eq!(s.radiance_in_cone(soup, texel), Vec3::ZERO);
        assert!(s.mips[0].get().is_none(), "no halving for a magnified sky");
        for spread in [2.0, 3.0, 8.0, 100.0] {
            let l = s.radiance_in_cone(soup, spread * texel);
            assert!((l - Vec3::ONE).abs().max_element() < 1e-6, "{spread}: {l}");
        }
        assert_eq!(s.mips[0].get().map(Vec::len), Some(8));
        // Between one and two texels the two levels blend: partway from 0 towards 1.
        let l = s.radiance_in_cone(soup, 1.5 * texel).x;
        assert!(l > 0.0 && l < 1.0, "{l}");
    }

    /// A uniform sky keeps its radiance at every footprint, on both layouts.
    #[test]
    fn filtering_keeps_a_uniform_sky_uniform() {
        let grey =
            |w, h| SkyImage::from_linear("grey", w, h, &vec![Vec3::splat(0.25); (w * h) as usize]);
        for layout in [
            SkyLayout::LatLong {
                image: grey(64, 32),
                panorama: Panorama::Full,
            },
            SkyLayout::Cube {
                faces: (0..6).map(|_| grey(16, 16)).collect(),
            },
        ] {
            let uniform = sky(layout, 30.0);
            let s = ImageSky::new(&uniform);
            for d in [
                Vec3::X,
                Vec3::new(0.3, 0.9, -0.2),
                -Vec3::Y,
                Vec3::new(-1.0, 0.1, 0.4),
            ] {
                for spread in [0.0, 0.01, 0.1, 0.5, 3.0] {
                    let l = s.radiance_in_cone(d.normalize(), spread);
                    let want = Vec3::splat(0.25) * uniform.scale;
                    assert!(
                        (l - want).abs().max_element() < 1e-3 * want.max_element(),
                        "{d} {spread}: {l}"
                    );
                }
            }
        }
    }
}
