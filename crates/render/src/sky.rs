//! Unity's procedural sky (the Skybox/Procedural shader behind Default-Skybox): Rayleigh
//! and Mie scattering through a thin shell of atmosphere around a unit planet, sampled
//! twice along the view ray (O'Neil's single-scattering model, with that shader's
//! constants), the ground below the horizon, and the sun's disk. Unity evaluates the
//! scattering at the sky mesh's vertices and interpolates; here each ray gets its own.
//!
//! Also what every skybox shares: [`Skybox`], the procedural sky or an image sky
//! (`sky_image.rs`) behind one lookup, and [`SkyAmbient`], a sky's light on nine spherical
//! harmonics as Unity's ambient probe holds it.

use crate::sky_image::ImageSky;
use formats::{ColorSpace, ProceduralSky, Sky, SunDisk};
use glam::Vec3;
use std::f32::consts::PI;

const OUTER_RADIUS: f32 = 1.025;
const CAMERA_HEIGHT: f32 = 0.0001;
const MIE: f32 = 0.0010;
const SUN_BRIGHTNESS: f32 = 20.0;
const MAX_SCATTER: f32 = 50.0;
const HQ_SUN_FACTOR: f32 = 15.0;
const SIMPLE_SUN_FACTOR: f32 = 27.0;
const SUN_SCALE: f32 = 400.0 * SUN_BRIGHTNESS;
const KM_ESUN: f32 = MIE * SUN_BRIGHTNESS;
const KM_4PI: f32 = MIE * 4.0 * PI;
/// 1 / atmosphere thickness (of a unit planet).
const SCALE: f32 = 1.0 / (OUTER_RADIUS - 1.0);
const SCALE_DEPTH: f32 = 0.25;
const SCALE_OVER_SCALE_DEPTH: f32 = SCALE / SCALE_DEPTH;
const MIE_G: f32 = -0.990;
const MIE_G2: f32 = 0.9801;
/// How far below the horizon (in ray y) the sky fades into the ground.
const SKY_GROUND_THRESHOLD: f32 = 0.02;

/// A procedural sky with its per-scene constants worked out once.
#[derive(Clone, Copy, Debug)]
pub struct SkyModel {
    sky: ProceduralSky,
    /// 1 / λ⁴ of the scattered wavelengths the tint picks.
    inv_wavelength: Vec3,
    kr_esun: f32,
    kr_4pi: f32,
    /// The sun light's colour, normalised so that a dim sun still draws a bright disk.
    sun_light: Vec3,
    /// A gamma-space project's sky: Unity's shader outputs the square root of its light.
    gamma: bool,
}

/// The optical depth scale along a ray at angle `cos` to the vertical (O'Neil's fit).
fn scale(cos: f32) -> f32 {
    let x = 1.0 - cos;
    0.25 * (-0.00287 + x * (0.459 + x * (3.83 + x * (-6.80 + x * 5.25)))).exp()
}

impl SkyModel {
    pub fn new(sky: ProceduralSky) -> Self {
        // The tint is read in gamma space, so that 0.5 is the default wavelengths.
        let tint = sky.sky_tint.powf(1.0 / 2.2);
        let base = Vec3::new(0.65, 0.57, 0.475);
        let wavelength = (base - 0.15) + (Vec3::ONE - tint) * 0.3;
        let inv_wavelength = Vec3::ONE / wavelength.powf(4.0);
        let rayleigh = 0.0025 * sky.atmosphere_thickness.max(0.0).powf(2.5);
        let brightness = sky.sun_colour.length().clamp(0.25, 1.0);
        SkyModel {
            sky,
            inv_wavelength,
            kr_esun: rayleigh * SUN_BRIGHTNESS,
            kr_4pi: rayleigh * 4.0 * PI,
            sun_light: sky.sun_colour / brightness,
            gamma: false,
        }
    }

    /// The sky as a project in colour space `space` draws it.
    pub fn in_space(self, space: ColorSpace) -> Self {
        SkyModel {
            gamma: space == ColorSpace::Gamma,
            ..self
        }
    }

    /// What the shader writes for light `l`.
    fn output(&self, l: Vec3) -> Vec3 {
        if self.gamma {
            l.max(Vec3::ZERO).map(f32::sqrt)
        } else {
            l
        }
    }

    fn attenuation(&self, scatter: f32) -> Vec3 {
        let k = self.inv_wavelength * self.kr_4pi + KM_4PI;
        (-(scatter.clamp(0.0, MAX_SCATTER)) * k).exp()
    }

    /// The sky's radiance along unit direction `eye` (linear RGB; in a gamma-space project
    /// the value its shader writes).
    pub fn radiance(&self, eye: Vec3) -> Vec3 {
        let (col, c_out) = self.scattered(eye);
        self.output(if eye.y > 0.0 {
            col + self.sun(c_out, self.sky.sun_direction, eye)
        } else {
            col
        })
    }

    /// The light the sky sends down unit direction `eye` without the sun's disk, and the
    /// Mie colour that scales that disk.
    fn scattered(&self, eye: Vec3) -> (Vec3, Vec3) {
        let light = self.sky.sun_direction;
        let camera = Vec3::new(0.0, 1.0 + CAMERA_HEIGHT, 0.0);
        let (c_in, c_out) = if eye.y >= 0.0 {
            // Up to the outer shell, two samples.
            let far = (OUTER_RADIUS * OUTER_RADIUS + eye.y * eye.y - 1.0).sqrt() - eye.y;
            let height = 1.0 + CAMERA_HEIGHT;
            let start_depth = (SCALE_OVER_SCALE_DEPTH * -CAMERA_HEIGHT).exp();
            let start_offset = start_depth * scale(eye.dot(camera) / height);
            let step = far / 2.0;
            let mut p = camera + eye * (step * 0.5);
            let mut front = Vec3::ZERO;
            for _ in 0..2 {
                let h = p.length();
                let depth = (SCALE_OVER_SCALE_DEPTH * (1.0 - h)).exp();
                let scatter =
                    start_offset + depth * (scale(light.dot(p) / h) - scale(eye.dot(p) / h));
                front += self.attenuation(scatter) * (depth * step * SCALE);
                p += eye * step;
            }
            (
                front * (self.inv_wavelength * self.kr_esun),
                front * KM_ESUN,
            )
        } else {
            // Down to the ground, one sample.
            let far = -CAMERA_HEIGHT / eye.y.min(-0.001);
            let pos = camera + eye * far;
            let depth0 = (-CAMERA_HEIGHT / SCALE_DEPTH).exp();
            let camera_scale = scale((-eye).dot(pos));
            let both = scale(light.dot(pos)) + camera_scale;
            let step = far / 2.0;
            let p = camera + eye * (step * 0.5);
            let depth = (SCALE_OVER_SCALE_DEPTH * (1.0 - p.length())).exp();
            let attenuate = self.attenuation(depth * both - depth0 * camera_scale);
            let front = attenuate * (depth * step * SCALE);
            (
                front * (self.inv_wavelength * self.kr_esun + KM_ESUN),
                attenuate.clamp(Vec3::ZERO, Vec3::ONE),
            )
        };
        let exposure = self.sky.exposure;
        let ground = exposure * (c_in + self.sky.ground * c_out);
        let cos = light.dot(eye);
        let sky = exposure * c_in * (0.75 + 0.75 * cos * cos);
        // Below the horizon the sky fades into the ground within SKY_GROUND_THRESHOLD.
        let y = -eye.y / SKY_GROUND_THRESHOLD;
        (sky.lerp(ground, y.clamp(0.0, 1.0)), c_out)
    }

    /// The ambient light this sky gives a surface, `intensity` times, as Unity's ambient
    /// probe holds it: the sky (without the sun's disk, which a few thousand directions
    /// would alias) projected onto the nine spherical harmonics of bands 0–2 and convolved
    /// with the cosine lobe.
    pub fn ambient(&self, intensity: f32) -> SkyAmbient {
        const ROWS: usize = 64;
        const COLUMNS: usize = 128;
        // Equal-area cells: uniform in height (y) and in azimuth.
        let area = 4.0 * PI / (ROWS * COLUMNS) as f32;
        SkyAmbient::project(intensity, |add| {
            for r in 0..ROWS {
                let y = 1.0 - 2.0 * (r as f32 + 0.5) / ROWS as f32;
                let ring = (1.0 - y * y).max(0.0).sqrt();
                for c in 0..COLUMNS {
                    let phi = 2.0 * PI * (c as f32 + 0.5) / COLUMNS as f32;
                    let dir = Vec3::new(ring * phi.cos(), y, ring * phi.sin());
                    add(dir, self.output(self.scattered(dir).0) * area);
                }
            }
        })
    }
}

/// The real spherical harmonics of bands 0–2 at unit `d`.
fn basis(d: Vec3) -> [f32; 9] {
    [
        0.282_095,
        0.488_603 * d.y,
        0.488_603 * d.z,
        0.488_603 * d.x,
        1.092_548 * d.x * d.y,
        1.092_548 * d.y * d.z,
        0.315_392 * (3.0 * d.z * d.z - 1.0),
        1.092_548 * d.x * d.z,
        0.546_274 * (d.x * d.x - d.y * d.y),
    ]
}

/// Add radiance `l` (times its solid angle) from unit direction `dir` to harmonic sums.
pub fn add_sample(sums: &mut [Vec3; 9], dir: Vec3, l: Vec3) {
    for (c, b) in sums.iter_mut().zip(basis(dir)) {
        *c += l * b;
    }
}

/// A sky's ambient light as nine spherical-harmonic coefficients.
#[derive(Clone, Copy, Debug)]
pub struct SkyAmbient {
    coeffs: [Vec3; 9],
}

impl SkyAmbient {
    /// The harmonics of the radiance `sample` hands over, each as a unit direction and
    /// its radiance times the solid angle it stands for, convolved with the cosine lobe
    /// and divided by π (irradiance as the radiance of a white surface), `intensity` times.
    pub fn project(intensity: f32, sample: impl FnOnce(&mut dyn FnMut(Vec3, Vec3))) -> Self {
        let mut sums = [Vec3::ZERO; 9];
        sample(&mut |dir, l| add_sample(&mut sums, dir, l));
        SkyAmbient::from_sums(sums, intensity)
    }

    /// [`SkyAmbient::project`] of samples already summed by [`add_sample`].
    pub fn from_sums(mut coeffs: [Vec3; 9], intensity: f32) -> Self {
        const BANDS: [f32; 9] = [
            1.0,
            2.0 / 3.0,
            2.0 / 3.0,
            2.0 / 3.0,
            0.25,
            0.25,
            0.25,
            0.25,
            0.25,
        ];
        for (c, band) in coeffs.iter_mut().zip(BANDS) {
            *c *= band * intensity;
        }
        SkyAmbient { coeffs }
    }

    /// The ambient light on a surface with unit normal `n` (never negative).
    pub fn at(&self, n: Vec3) -> Vec3 {
        let l = basis(n)
            .iter()
            .zip(&self.coeffs)
            .fold(Vec3::ZERO, |l, (b, c)| l + *c * *b);
        l.max(Vec3::ZERO)
    }
}

/// RenderSettings' skybox, ready to draw.
pub enum Skybox<'a> {
    Procedural(SkyModel),
    Image(ImageSky<'a>),
}

impl<'a> Skybox<'a> {
    /// The sky as a project in colour space `space` draws it (an image sky's texels and
    /// scale are already that space's).
    pub fn new(sky: &'a Sky, space: ColorSpace) -> Self {
        match sky {
            Sky::Procedural(p) => Skybox::Procedural(SkyModel::new(*p).in_space(space)),
            Sky::Textured(t) => Skybox::Image(ImageSky::new(t)),
        }
    }

    /// Radiance along unit direction `dir`, seen by a ray cone `spread` radians wide
    /// (an image sky filters over it; the procedural sky is smooth).
    pub fn radiance(&self, dir: Vec3, spread: f32) -> Vec3 {
        match self {
            Skybox::Procedural(p) => p.radiance(dir),
            Skybox::Image(i) => i.radiance_in_cone(dir, spread),
        }
    }

    /// The sky's ambient light, `intensity` times.
    pub fn ambient(&self, intensity: f32) -> SkyAmbient {
        match self {
            Skybox::Procedural(p) => p.ambient(intensity),
            Skybox::Image(i) => i.ambient(intensity),
        }
    }
}

impl SkyModel {
    /// The sun's disk seen along `eye`.
    fn sun(&self, c_out: Vec3, light: Vec3, eye: Vec3) -> Vec3 {
        match self.sky.sun_disk {
            SunDisk::None => Vec3::ZERO,
            SunDisk::Simple => {
                let colour = SIMPLE_SUN_FACTOR
                    * (c_out * SUN_SCALE).clamp(Vec3::ZERO, Vec3::ONE)
                    * self.sun_light;
                let size = self.sky.sun_size;
                let t = if size > 0.0 {
                    ((light - eye).length() / size).clamp(0.0, 1.0)
                } else {
                    1.0
                };
                let spot = 1.0 - t * t * (3.0 - 2.0 * t);
                colour * (spot * spot)
            }
            SunDisk::HighQuality => {
                let colour = HQ_SUN_FACTOR * c_out.clamp(Vec3::ZERO, Vec3::ONE) * self.sun_light;
                let focused = light
                    .dot(eye)
                    .clamp(0.0, 1.0)
                    .powf(self.sky.sun_size_convergence);
                // The Mie phase at the focused cosine, narrowed by the sun's size.
                let base = 1.0 + MIE_G2 - 2.0 * MIE_G * -focused;
                let narrowed = base
                    .powf(self.sky.sun_size.max(0.0).powf(0.65) * 10.0)
                    .max(1.0e-4);
                let phase =
                    1.5 * ((1.0 - MIE_G2) / (2.0 + MIE_G2)) * (1.0 + focused * focused) / narrowed;
                colour * phase
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Default-Skybox's settings with a white sun 45° up towards +Z.
    fn default_sky() -> SkyModel {
        let lin = |c: f32| ((c + 0.055) / 1.055).powf(2.4);
        SkyModel::new(ProceduralSky {
            sun_disk: SunDisk::HighQuality,
            sun_size: 0.04,
            sun_size_convergence: 5.0,
            atmosphere_thickness: 1.0,
            exposure: 1.3,
            sky_tint: Vec3::splat(lin(0.5)),
            ground: Vec3::new(lin(0.369), lin(0.349), lin(0.341)),
            sun_direction: Vec3::new(0.0, 1.0, 1.0).normalize(),
            sun_colour: Vec3::ONE,
        })
    }

    /// Nine harmonics ring at the horizon's step: 0.3 % off for a wall, 6 % for the
    /// floor's upward face, 10 % for a ceiling lit by the ground (Unity's probe has the
    /// same nine).
    const TOLERANCE: f32 = 0.11;

    fn close(got: Vec3, want: [f32; 3]) {
        let want = Vec3::from_array(want);
        let err = ((got - want).abs() / want).max_element();
        assert!(err < 1e-3, "got {got}, want {want}");
    }

    /// Values from an independent double-precision transcription of the shader's
    /// arithmetic: a deep blue zenith, a pale horizon, the grey-brown ground and the sun.
    #[test]
    fn the_default_sky_has_unitys_colours() {
        let sky = default_sky();
        let s = 0.5f32.sqrt();
        close(sky.radiance(Vec3::Y), [0.079709, 0.130018, 0.246302]);
        close(
            sky.radiance(Vec3::new(1.0, 0.01, 0.0)),
            [0.631738, 0.819947, 0.860788],
        );
        close(
            sky.radiance(Vec3::new(0.0, -s, s)),
            [0.137867, 0.118595, 0.103105],
        );
        close(
            sky.radiance(Vec3::new(0.0, s, s)),
            [16.481407, 15.91454, 14.516068],
        );
    }

    /// The harmonics hold the sky's light on a surface: against a brute-force cosine
    /// integral of the sky (a 512 × 1024 grid of directions), within what nine harmonics
    /// can hold of a sky with a sharp horizon ([`TOLERANCE`]).
    #[test]
    fn the_ambient_harmonics_hold_the_skys_irradiance() {
        let sky = default_sky();
        let ambient = sky.ambient(1.0);
        let irradiance = |n: Vec3| {
            let (rows, columns) = (512, 1024);
            let area = 4.0 * PI / (rows * columns) as f32;
            let mut e = Vec3::ZERO;
            for r in 0..rows {
                let y = 1.0 - 2.0 * (r as f32 + 0.5) / rows as f32;
                let ring = (1.0 - y * y).sqrt();
                for c in 0..columns {
                    let phi = 2.0 * PI * (c as f32 + 0.5) / columns as f32;
                    let d = Vec3::new(ring * phi.cos(), y, ring * phi.sin());
                    e += sky.scattered(d).0 * (d.dot(n).max(0.0) * area);
                }
            }
            e / PI
        };
        for n in [Vec3::Y, -Vec3::Y, Vec3::X, Vec3::new(0.0, 0.6, 0.8)] {
            let (got, want) = (ambient.at(n), irradiance(n));
            let err = ((got - want).abs() / want).max_element();
            assert!(err < TOLERANCE, "normal {n}: {got} against {want}");
        }
        // Twice the intensity, twice the light.
        assert_eq!(sky.ambient(2.0).at(Vec3::Y), ambient.at(Vec3::Y) * 2.0);
    }

    #[test]
    fn without_a_sun_or_a_disk_no_sun_is_drawn() {
        let s = 0.5f32.sqrt();
        let towards = Vec3::new(0.0, s, s);
        let lit = default_sky();
        let dark = SkyModel::new(ProceduralSky {
            sun_colour: Vec3::ZERO,
            ..lit.sky
        });
        let none = SkyModel::new(ProceduralSky {
            sun_disk: SunDisk::None,
            ..lit.sky
        });
        // The scattered sky stays; only the disk goes.
        let sky_alone = none.radiance(towards);
        assert!(sky_alone.max_element() < 2.0, "{sky_alone}");
        assert_eq!(dark.radiance(towards), sky_alone);
        assert!(lit.radiance(towards).min_element() > 10.0);
        // The simple disk is bright at the sun and gone beyond its size.
        let simple = SkyModel::new(ProceduralSky {
            sun_disk: SunDisk::Simple,
            ..lit.sky
        });
        assert!(simple.radiance(towards).min_element() > 10.0);
        let aside = Vec3::new(0.0, 0.6, 0.8).normalize();
        assert_eq!(simple.radiance(aside), none.radiance(aside));
    }
}
