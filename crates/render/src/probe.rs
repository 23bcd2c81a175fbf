//! Unity's default reflection probe: what a physically based surface reflects of the
//! skybox. Unity renders the skybox into a cube map 128 texels a side and fills its smaller
//! mip levels with the sky blurred for rougher surfaces; its shaders read level
//! p·(1.7 − 0.7·p)·6 (p the perceptual roughness, 1 − smoothness) along the view direction
//! mirrored about the normal, trilinearly.
//!
//! Here level 0 holds the sky at each texel's centre, filtered over the texel; level 1,
//! whose lobe is narrower than its texels, level 0 halved; and each level m ≥ 2 the sky
//! convolved with the GGX lobe of the roughness that reads level m, with normal, view and
//! reflection along the texel's direction (as split-sum prefiltering assumes). The lobe is
//! importance-sampled from box-filtered halvings of level 0, each sample read at the
//! halving whose texels are as large as the solid angle it stands for (filtered importance
//! sampling), so 32 samples give a smooth result. Only the levels the scene's materials
//! read are built. Lookups across a face's edge read the neighbouring face, as a GPU's
//! seamless cube filtering does.

use glam::Vec3;
use rayon::prelude::*;
use std::f32::consts::PI;

/// Texels along a face's side at level 0 (RenderSettings' default resolution).
pub const RESOLUTION: usize = 128;
/// The level the roughest surface reads (`UNITY_SPECCUBE_LOD_STEPS`).
const LOD_STEPS: usize = 6;
/// Levels a surface reads.
pub const LEVELS: usize = LOD_STEPS + 1;
/// GGX samples per texel of a prefiltered level.
const SAMPLES: u32 = 32;

/// The skybox as Unity's default reflection probe holds it, times the scene's reflection
/// intensity.
pub struct Probe {
    /// Levels 0 ..= [`LOD_STEPS`], each prefiltered for the roughness that reads it.
    levels: Vec<Cube>,
    /// The sky's mean radiance over all directions: what a material with its Reflections
    /// switch off reflects instead.
    pub mean: Vec3,
}

/// One level of a cube map: six faces of `size`² texels, face-major, row-major. Face
/// 2a + 0 looks along +axis a, 2a + 1 along −axis a; a face's u runs along axis (a + 1) % 3
/// and v along (a + 2) % 3, each from −1 to 1 over the face.
struct Cube {
    size: usize,
    texels: Vec<Vec3>,
    /// Each face again with a border of one texel from its neighbours ((size + 2)² a face),
    /// so that a bilinear lookup never leaves its face.
    bordered: Vec<Vec3>,
}

/// The face a direction leaves the cube through, and its (u, v) on that face.
#[inline(always)]
fn locate(d: Vec3) -> (usize, f32, f32) {
    let a = d.abs();
    // (axis, the component along it, then those along axis + 1 and axis + 2, mod 3)
    let (axis, major, u, v) = if a.x >= a.y && a.x >= a.z {
        (0, d.x, d.y, d.z)
    } else if a.y >= a.z {
        (1, d.y, d.z, d.x)
    } else {
        (2, d.z, d.x, d.y)
    };
    let inv = 1.0 / major.abs();
    (2 * axis + (major < 0.0) as usize, u * inv, v * inv)
}

/// The (unnormalised) direction through (u, v) of `face`; u and v may lie beyond ±1.
fn direction(face: usize, u: f32, v: f32) -> Vec3 {
    let major = if face.is_multiple_of(2) { 1.0 } else { -1.0 };
    match face / 2 {
        0 => Vec3::new(major, u, v),
        1 => Vec3::new(v, major, u),
        _ => Vec3::new(u, v, major),
    }
}

impl Cube {
    /// A level whose texel at each centre direction (unit) is `texel(direction)`.
    fn from_fn(size: usize, texel: impl Fn(Vec3) -> Vec3 + Sync) -> Cube {
        let mut texels = vec![Vec3::ZERO; 6 * size * size];
        texels
            .par_chunks_mut(size)
            .enumerate()
            .for_each(|(row, out)| {
                let (face, j) = (row / size, row % size);
                let v = centre(j, size);
                for (i, t) in out.iter_mut().enumerate() {
                    *t = texel(direction(face, centre(i, size), v).normalize());
                }
            });
        Cube::new(size, texels)
    }

    /// A level of these texels, with its faces' borders.
    fn new(size: usize, texels: Vec<Vec3>) -> Cube {
        let mut cube = Cube {
            size,
            texels,
            bordered: Vec::new(),
        };
        let n = size as isize;
        cube.bordered = (0..6)
            .flat_map(|face| (-1..=n).flat_map(move |j| (-1..=n).map(move |i| (face, i, j))))
            .map(|(face, i, j)| cube.fetch(face, i, j))
            .collect();
        cube
    }

    /// No level: one no surface reads.
    fn none() -> Cube {
        Cube {
            size: 0,
            texels: Vec::new(),
            bordered: Vec::new(),
        }
    }

    /// The next box-filtered halving.
    fn halve(&self) -> Cube {
        let (n, h) = (self.size, self.size / 2);
        let mut texels = Vec::with_capacity(6 * h * h);
        for face in 0..6 {
            for j in 0..h {
                for i in 0..h {
                    let at = |di: usize, dj: usize| {
                        self.texels[face * n * n + (2 * j + dj) * n + 2 * i + di]
                    };
                    texels.push((at(0, 0) + at(1, 0) + at(0, 1) + at(1, 1)) * 0.25);
                }
            }
        }
        Cube::new(h, texels)
    }

    /// Texel (i, j) of `face`, where i or j may lie one beyond the face: then the texel of
    /// the neighbouring face that direction falls in.
    fn fetch(&self, face: usize, i: isize, j: isize) -> Vec3 {
        let n = self.size as isize;
        if (0..n).contains(&i) && (0..n).contains(&j) {
            return self.texels[face * self.size * self.size + (j * n + i) as usize];
        }
        let d = direction(face, centre_f(i, self.size), centre_f(j, self.size));
        let (f, u, v) = locate(d);
        let texel = |x: f32| (((x + 1.0) * 0.5 * n as f32) as isize).clamp(0, n - 1) as usize;
        self.texels[f * self.size * self.size + texel(v) * self.size + texel(u)]
    }

    /// The level's bilinear value along `d` (any length but zero).
    #[inline]
    fn bilinear(&self, d: Vec3) -> Vec3 {
        let (face, u, v) = locate(d);
        let n = self.size as f32;
        let x = ((u + 1.0) * 0.5 * n - 0.5).clamp(-0.5, n - 0.5);
        let y = ((v + 1.0) * 0.5 * n - 0.5).clamp(-0.5, n - 0.5);
        // Floors by truncation: x and y are at least −0.5, so i and j at least −1, which
        // is the border's first texel.
        let (i, j) = ((x + 1.0) as usize, (y + 1.0) as usize);
        let (fx, fy) = (x + 1.0 - i as f32, y + 1.0 - j as f32);
        let side = self.size + 2;
        let at = face * side * side + j * side + i;
        let t = &self.bordered;
        let [a, b, c, d] = [t[at], t[at + 1], t[at + side], t[at + side + 1]];
        a.lerp(b, fx).lerp(c.lerp(d, fx), fy)
    }
}

/// The face coordinate of texel `i`'s centre on a face `size` texels wide.
fn centre(i: usize, size: usize) -> f32 {
    centre_f(i as isize, size)
}

fn centre_f(i: isize, size: usize) -> f32 {
    (i as f32 + 0.5) / size as f32 * 2.0 - 1.0
}

/// The level a surface of `smoothness` reads (`perceptualRoughnessToMipmapLevel` after
/// Unity's remapping of the roughness).
pub fn level_of(smoothness: f32) -> f32 {
    let p = 1.0 - smoothness.clamp(0.0, 1.0);
    p * (1.7 - 0.7 * p) * LOD_STEPS as f32
}

/// The GGX roughness α (perceptual roughness squared) of the surfaces that read level `m`
/// alone: the inverse of [`level_of`].
fn alpha_of_level(m: usize) -> f32 {
    let x = m as f32 / LOD_STEPS as f32;
    let p = (1.7 - (1.7f32 * 1.7 - 2.8 * x).max(0.0).sqrt()) / 1.4;
    p * p
}

/// Point k of an n-point Hammersley set in the unit square.
fn hammersley(k: u32, n: u32) -> (f32, f32) {
    (
        (k as f32 + 0.5) / n as f32,
        k.reverse_bits() as f32 * (1.0 / 4_294_967_296.0),
    )
}

/// One sample of a GGX lobe: the direction it reads in the lobe's frame (z along the
/// lobe's axis, which is the cosine it is weighted by) and the halving it reads.
struct Tap {
    l: Vec3,
    mip: f32,
}

/// The taps that prefilter for roughness `alpha` from halvings of a level `full` texels a
/// side, the last `top`: `SAMPLES` GGX-distributed half vectors about the axis, with normal,
/// view and reflection along it, each read where the halving's texels cover the solid
/// angle it stands for. Below the horizon they are dropped.
fn taps(alpha: f32, full: usize, top: f32) -> Vec<Tap> {
    let a2 = alpha * alpha;
    let texel_angle = 4.0 * PI / (6.0 * (full * full) as f32);
    (0..SAMPLES)
        .filter_map(|k| {
            let (x1, x2) = hammersley(k, SAMPLES);
            let cos2 = (1.0 - x1) / (1.0 + (a2 - 1.0) * x1);
            let (cos, sin) = (cos2.sqrt(), (1.0 - cos2).max(0.0).sqrt());
            let phi = 2.0 * PI * x2;
            let h = Vec3::new(sin * phi.cos(), sin * phi.sin(), cos);
            let l = h * (2.0 * cos) - Vec3::Z;
            if l.z <= 0.0 {
                return None;
            }
            // With n = v, the pdf of l is D(h)/4.
            let denom = (a2 - 1.0) * cos2 + 1.0;
            let pdf = a2 / (PI * denom * denom) * 0.25;
            let solid_angle = 1.0 / (SAMPLES as f32 * pdf);
            let mip = (0.5 * (solid_angle / texel_angle).log2() + 1.0).clamp(0.0, top);
            Some(Tap { l, mip })
        })
        .collect()
}

/// A prefiltered texel along unit `n`: the `taps` turned about `n`, each read from the
/// box-filtered `halvings` and weighted by its cosine.
fn prefiltered(halvings: &[Cube], n: Vec3, taps: &[Tap]) -> Vec3 {
    let (t, b) = n.any_orthonormal_pair();
    let (mut sum, mut weight) = (Vec3::ZERO, 0.0f32);
    for tap in taps {
        let l = t * tap.l.x + b * tap.l.y + n * tap.l.z;
        let lo = tap.mip.floor();
        let mut value = halvings[lo as usize].bilinear(l);
        if tap.mip > lo {
            value = value.lerp(halvings[lo as usize + 1].bilinear(l), tap.mip - lo);
        }
        sum += value * tap.l.z;
        weight += tap.l.z;
    }
    if weight > 0.0 {
        sum / weight
    } else {
        halvings[0].bilinear(n)
    }
}

impl Probe {
    /// The probe of a sky whose radiance along a unit direction, seen by a cone `spread`
    /// radians wide, is `sky(direction, spread)`, times `intensity`, holding the levels
    /// `needed` says a surface reads (a lookup between levels reads both).
    pub fn new(
        sky: impl Fn(Vec3, f32) -> Vec3 + Sync,
        intensity: f32,
        needed: [bool; LEVELS],
    ) -> Probe {
        // Where neither of the two sharpest levels is read, the sky at half the size is
        // fine enough for the lobes of the others.
        let source = if needed[0] || needed[1] {
            RESOLUTION
        } else {
            RESOLUTION / 2
        };
        let spread = 0.5 * PI / source as f32;
        let full = Cube::from_fn(source, |d| sky(d, spread) * intensity);
        let mut halvings = vec![full];
        while halvings.last().is_some_and(|c| c.size > 1) {
            let next = halvings.last().map(Cube::halve);
            halvings.extend(next);
        }
        let mean = mean(&halvings[0]);
        let top = (halvings.len() - 1) as f32;
        let mut levels: Vec<Cube> = (0..LEVELS)
            .map(|m| {
                if needed[m] && m >= 2 {
                    let taps = taps(alpha_of_level(m), source, top);
                    Cube::from_fn(RESOLUTION >> m, |n| prefiltered(&halvings, n, &taps))
                } else {
                    Cube::none()
                }
            })
            .collect();
        // Levels 0 and 1 are the sky and its first halving: level 1's lobe (α ≈ 0.01,
        // about 1.2° wide) is narrower than its texels (1.4°), so the halving is the
        // convolution, within its texels.
        for m in 0..2 {
            if needed[m] {
                levels[m] = std::mem::replace(&mut halvings[m], Cube::none());
            }
        }
        // Lookups read the bordered faces alone.
        for level in &mut levels {
            level.texels = Vec::new();
        }
        Probe { levels, mean }
    }

    /// The levels surfaces whose smoothness lies in each of `ranges` (lowest, highest)
    /// read.
    pub fn levels_read(ranges: impl IntoIterator<Item = (f32, f32)>) -> [bool; LEVELS] {
        let mut needed = [false; LEVELS];
        for (lo, hi) in ranges {
            let (sharpest, roughest) = (level_of(hi), level_of(lo));
            let first = sharpest.floor() as usize;
            let last = (roughest.ceil() as usize).min(LOD_STEPS);
            for n in needed.iter_mut().take(last + 1).skip(first) {
                *n = true;
            }
        }
        needed
    }

    /// What a surface of `smoothness` reflects along unit `r`, the view direction mirrored
    /// about its normal.
    pub fn at(&self, r: Vec3, smoothness: f32) -> Vec3 {
        let mip = level_of(smoothness).clamp(0.0, LOD_STEPS as f32);
        let lo = mip.floor();
        let value = self.level(lo as usize).bilinear(r);
        if mip > lo {
            value.lerp(self.level(lo as usize + 1).bilinear(r), mip - lo)
        } else {
            value
        }
    }

    /// Level `m`, or where it was not built (no surface was to read it) the nearest one
    /// that was.
    fn level(&self, m: usize) -> &Cube {
        let built = |k: &usize| self.levels[*k].size > 0;
        (m..LEVELS)
            .find(built)
            .or_else(|| (0..m).rev().find(built))
            .map_or(&self.levels[0], |k| &self.levels[k])
    }
}

/// The mean of a level over all directions, each texel weighted by its solid angle.
fn mean(cube: &Cube) -> Vec3 {
    let n = cube.size;
    let (mut sum, mut weight) = (Vec3::ZERO, 0.0f64);
    for (k, t) in cube.texels.iter().enumerate() {
        let (u, v) = (centre(k % n, n), centre(k / n % n, n));
        let w = (1.0 + u * u + v * v).powf(-1.5);
        sum += *t * w;
        weight += w as f64;
    }
    sum / weight as f32
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: Vec3, b: Vec3, tol: f32) -> bool {
        (a - b).abs().max_element() <= tol
    }

    #[test]
    fn faces_cover_every_direction_once() {
        for face in 0..6 {
            for &(u, v) in &[(0.0, 0.0), (0.9, -0.3), (-0.99, 0.99)] {
                let (f, u2, v2) = locate(direction(face, u, v));
                assert_eq!((f, u2, v2), (face, u, v));
            }
        }
    }

    #[test]
    fn levels_map_to_the_roughness_that_reads_them() {
        assert_eq!(level_of(1.0), 0.0);
        assert_eq!(level_of(0.0), 6.0);
        for m in 0..=LOD_STEPS {
            let smoothness = 1.0 - alpha_of_level(m).sqrt();
            assert!((level_of(smoothness) - m as f32).abs() < 1e-4, "level {m}");
        }
    }

    #[test]
    fn only_the_levels_surfaces_read_are_built() {
        // Smoothness 0.5 reads between levels 4 and 5; a map from 0 to 0.85, levels 1–6.
        let half = Probe::levels_read([(0.5, 0.5)]);
        assert_eq!(half, [false, false, false, false, true, true, false]);
        assert_eq!(
            Probe::levels_read([(1.0, 1.0)]),
            [true, false, false, false, false, false, false]
        );
        let mapped = Probe::levels_read([(0.0, 0.85), (0.5, 0.5)]);
        assert_eq!(mapped, [false, true, true, true, true, true, true]);
        // Built from half the sky's resolution, the levels read agree with a full probe's.
        let sky = |d: Vec3, _| Vec3::new(d.y.max(0.0) * 2.0, 0.5 + 0.5 * d.x, 0.25);
        let (full, part) = (
            Probe::new(sky, 1.0, [true; LEVELS]),
            Probe::new(sky, 1.0, half),
        );
        assert!(part.levels[0].bordered.is_empty() && part.levels[6].bordered.is_empty());
        assert!(!part.levels[4].bordered.is_empty());
        for d in [Vec3::Y, Vec3::new(0.3, 0.2, -0.9).normalize(), -Vec3::X] {
            let (a, b) = (full.at(d, 0.5), part.at(d, 0.5));
            assert!(close(a, b, 0.01 * a.max_element()), "{d}: {a} {b}");
            // A level that was not built reads the nearest one that was.
            assert_eq!(part.at(d, 1.0), part.levels[4].bilinear(d));
        }
    }

    #[test]
    fn a_uniform_sky_stays_uniform_at_every_level() {
        let c = Vec3::new(0.25, 0.5, 2.0);
        let probe = Probe::new(|_, _| c, 1.5, [true; LEVELS]);
        assert_eq!(probe.levels.len(), LOD_STEPS + 1);
        assert!(close(probe.mean, c * 1.5, 1e-5), "{}", probe.mean);
        for s in [0.0, 0.3, 0.5, 0.77, 1.0] {
            for d in [
                Vec3::X,
                Vec3::new(1.0, 1.0, 1.0),
                Vec3::new(-0.2, 0.9, -1.0),
            ] {
                let v = probe.at(d.normalize(), s);
                assert!(close(v, c * 1.5, 1e-5), "smoothness {s} along {d}: {v}");
            }
        }
    }

    #[test]
    fn a_smooth_sky_reads_back_across_edges_and_corners() {
        // A sky linear in the direction: level 0's bilinear values follow it closely on
        // face centres, edges and corners alike (a lookup across an edge reads the
        // neighbouring face).
        let sky = |d: Vec3| Vec3::splat(0.5 + 0.25 * d.x + 0.125 * d.y - 0.0625 * d.z);
        let probe = Probe::new(|d, _| sky(d), 1.0, [true; LEVELS]);
        let mut worst = 0.0f32;
        for face in 0..6 {
            for &(u, v) in &[
                (0.0, 0.0),
                (0.999, 0.2),
                (-1.0, -1.0),
                (1.0, 0.999),
                (0.5, -0.998),
            ] {
                let d = direction(face, u, v).normalize();
                worst = worst.max((probe.at(d, 1.0) - sky(d)).abs().max_element());
            }
        }
        assert!(worst < 2e-3, "worst error {worst}");
        // A symmetric lobe keeps the mean and shrinks the slope: opposite directions
        // still average to the constant term at every level.
        for s in [0.0, 0.4, 0.8] {
            let (a, b) = (probe.at(Vec3::X, s), probe.at(-Vec3::X, s));
            assert!(
                ((a + b).x * 0.5 - 0.5).abs() < 2e-3,
                "smoothness {s}: {a} {b}"
            );
            assert!(a.x > 0.5 && a.x <= 0.75 + 1e-3, "smoothness {s}: {a}");
        }
        assert!(probe.at(Vec3::X, 0.0).x < probe.at(Vec3::X, 0.8).x);
    }

    #[test]
    fn a_rough_surface_spreads_a_bright_half_sky() {
        // The upper half bright: a mirror sees it sharply, the roughest surface sees it
        // blurred across the horizon, but still more of it looking up than down.
        let probe = Probe::new(
            |d, _| Vec3::splat((d.y > 0.0) as u8 as f32),
            1.0,
            [true; LEVELS],
        );
        let up = Vec3::new(0.3, 1.0, 0.2).normalize();
        assert!(close(probe.at(up, 1.0), Vec3::ONE, 1e-6));
        assert!(close(probe.at(-up, 1.0), Vec3::ZERO, 1e-6));
        let (rough_up, rough_down) = (probe.at(up, 0.0).x, probe.at(-up, 0.0).x);
        assert!(rough_up < 0.999 && rough_up > 0.6, "{rough_up}");
        assert!(
            (rough_up + rough_down - 1.0).abs() < 0.02,
            "{rough_up} {rough_down}"
        );
        assert!((probe.mean.x - 0.5).abs() < 1e-3, "{}", probe.mean);
    }
}
