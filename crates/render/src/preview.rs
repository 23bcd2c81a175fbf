//! The PNG preview: exposure, sRGB encoding, 8 bits.

use crate::{Frame, RenderError};
use glam::Vec3;
use std::path::Path;

/// One linear channel to an 8-bit sRGB value: scale by 2^exposure, clamp to [0, 1],
/// encode, round ([`formats::srgb::encode`]).
pub fn to_8bit(linear: f32, exposure: f32) -> u8 {
    formats::srgb::encode(linear * exposure.exp2())
}

/// Encode the frame's window as an 8-bit sRGB PNG.
pub fn encode_png(frame: &Frame, exposure: f32) -> Result<Vec<u8>, String> {
    let (w, h) = (frame.window.width(), frame.window.height());
    encode_rgb_png(w, h, &frame.color, exposure)
}

/// Encode `w`×`h` linear RGB pixels (row-major) as an 8-bit sRGB PNG.
pub fn encode_rgb_png(w: u32, h: u32, color: &[Vec3], exposure: f32) -> Result<Vec<u8>, String> {
    let scale = exposure.exp2();
    let mut rgb = vec![0; color.len() * 3];
    for (px, c) in rgb.chunks_exact_mut(3).zip(color) {
        for (byte, v) in px.iter_mut().zip(c.to_array()) {
            *byte = formats::srgb::encode(v * scale);
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

    #[test]
    fn exposure_scales_before_encoding() {
        assert_eq!(to_8bit(0.0, 0.0), 0);
        assert_eq!(to_8bit(1.0, 0.0), 255);
        assert_eq!(to_8bit(0.5, 1.0), 255);
        assert_eq!(to_8bit(0.2142 * 4.0, -2.0), 128);
        assert_eq!(to_8bit(0.05 / 8.0, 3.0), 63);
        assert_eq!(to_8bit(f32::NAN, 0.0), 0);
    }
}
