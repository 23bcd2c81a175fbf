//! Image error against a reference: RMSE and mean relative squared error on the linear
//! HDR colour, and SSIM on the luma of the tone-mapped (8-bit sRGB preview) image.

use glam::Vec3;

/// Errors of one image against the reference.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Errors {
    /// Root mean squared difference over all channels of all pixels (linear HDR).
    pub rmse: f64,
    /// Mean over channels of (a − r)² / (r² + 0.01): the ε keeps black pixels from
    /// dominating (the usual relMSE of the rendering literature).
    pub rel_mse: f64,
    /// Mean SSIM over 8×8 windows of the preview's luma; 1 means identical.
    pub ssim: f64,
}

impl Errors {
    /// 1 − SSIM: a perceptual error that, like the others, is 0 for a perfect image.
    pub fn dssim(&self) -> f64 {
        (1.0 - self.ssim).max(0.0)
    }
}

/// Compare `img` with `reference`, both `width`×`height` row-major linear RGB.
/// Panics if the sizes differ (a programming error: both come from the same options).
pub fn compare(img: &[Vec3], reference: &[Vec3], width: usize, height: usize) -> Errors {
    assert_eq!(img.len(), reference.len(), "images of different sizes");
    assert_eq!(img.len(), width * height, "image size does not match");
    let mut sq = 0.0f64;
    let mut rel = 0.0f64;
    for (a, r) in img.iter().zip(reference) {
        for c in 0..3 {
            let d = (a[c] - r[c]) as f64;
            sq += d * d;
            rel += d * d / ((r[c] as f64).powi(2) + 0.01);
        }
    }
    let n = (img.len() * 3).max(1) as f64;
    Errors {
        rmse: (sq / n).sqrt(),
        rel_mse: rel / n,
        ssim: ssim(&luma(img), &luma(reference), width, height),
    }
}

/// Luma (Rec. 709 weights) of the 8-bit sRGB preview at exposure 0, in [0, 1]: what a
/// viewer of the PNG sees.
pub fn luma(img: &[Vec3]) -> Vec<f64> {
    img.iter()
        .map(|c| {
            let v = |x: f32| render::preview::to_8bit(x, 0.0) as f64 / 255.0;
            0.2126 * v(c.x) + 0.7152 * v(c.y) + 0.0722 * v(c.z)
        })
        .collect()
}

/// Mean SSIM (Wang et al. 2004, dynamic range 1) over 8×8 windows stepped by 4 pixels;
/// images smaller than a window are compared as one window.
pub fn ssim(a: &[f64], b: &[f64], width: usize, height: usize) -> f64 {
    const C1: f64 = 0.01 * 0.01;
    const C2: f64 = 0.03 * 0.03;
    let win = 8.min(width).min(height).max(1);
    let step = 4.min(win);
    let mut sum = 0.0;
    let mut count = 0usize;
    let mut y = 0;
    while y + win <= height {
        let mut x = 0;
        while x + win <= width {
            let (mut ma, mut mb) = (0.0, 0.0);
            for j in y..y + win {
                for i in x..x + win {
                    ma += a[j * width + i];
                    mb += b[j * width + i];
                }
            }
            let n = (win * win) as f64;
            ma /= n;
            mb /= n;
            let (mut va, mut vb, mut cov) = (0.0, 0.0, 0.0);
            for j in y..y + win {
                for i in x..x + win {
                    let da = a[j * width + i] - ma;
                    let db = b[j * width + i] - mb;
                    va += da * da;
                    vb += db * db;
                    cov += da * db;
                }
            }
            // Sample (n − 1) statistics, as in the reference implementation.
            let m = (n - 1.0).max(1.0);
            let (va, vb, cov) = (va / m, vb / m, cov / m);
            sum += ((2.0 * ma * mb + C1) * (2.0 * cov + C2))
                / ((ma * ma + mb * mb + C1) * (va + vb + C2));
            count += 1;
            x += step;
        }
        y += step;
    }
    if count == 0 {
        1.0
    } else {
        sum / count as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn identical_images_have_zero_error() {
        let img: Vec<Vec3> = (0..16 * 12)
            .map(|i| Vec3::new(i as f32 / 200.0, 0.3, 1.5))
            .collect();
        let e = compare(&img, &img, 16, 12);
        assert_eq!(e.rmse, 0.0);
        assert_eq!(e.rel_mse, 0.0);
        assert!((e.ssim - 1.0).abs() < 1e-12, "ssim {}", e.ssim);
    }

    #[test]
    fn known_offset_gives_known_rmse_and_rel_mse() {
        let r = vec![Vec3::splat(0.3); 64];
        let a = vec![Vec3::splat(0.4); 64];
        let e = compare(&a, &r, 8, 8);
        assert!((e.rmse - 0.1).abs() < 1e-6, "rmse {}", e.rmse);
        // 0.01 / (0.09 + 0.01) = 0.1
        assert!((e.rel_mse - 0.1).abs() < 1e-5, "rel {}", e.rel_mse);
        // Flat windows: SSIM is only the luminance term, below 1.
        assert!(e.ssim < 1.0 && e.ssim > 0.9, "ssim {}", e.ssim);
    }

    #[test]
    fn inverted_pattern_has_low_ssim() {
        let a: Vec<f64> = (0..64).map(|i| (i % 2) as f64).collect();
        let b: Vec<f64> = a.iter().map(|v| 1.0 - v).collect();
        assert!(ssim(&a, &b, 8, 8) < 0.0);
    }
}
