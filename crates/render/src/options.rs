//! What a render is asked to do: image size, window, sampling and effect limits.

use crate::{AovSet, RenderError};
use serde::Serialize;

/// How albedo and alpha lookups filter a texture (`--texture-filter`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum TextureFilter {
    /// The texel under the hit on the full-size image, whatever the import settings: the
    /// cheapest lookup, and it aliases wherever a pixel covers many texels.
    Point,
    /// Bilinear on the full-size image, whatever the import settings: smooth up close,
    /// aliases like point when minified.
    Bilinear,
    /// What Unity does: the texture's own filter mode (point, bilinear, trilinear) and mip
    /// maps, the level chosen by the ray cone's footprint at the hit.
    #[default]
    Cone,
}

impl TextureFilter {
    pub const ALL: [TextureFilter; 3] = [
        TextureFilter::Point,
        TextureFilter::Bilinear,
        TextureFilter::Cone,
    ];

    pub fn name(self) -> &'static str {
        match self {
            TextureFilter::Point => "point",
            TextureFilter::Bilinear => "bilinear",
            TextureFilter::Cone => "cone",
        }
    }

    pub fn parse(s: &str) -> Result<Self, String> {
        Self::ALL
            .into_iter()
            .find(|f| f.name() == s)
            .ok_or_else(|| format!("--texture-filter {s:?}: choose from point, bilinear, cone"))
    }
}

impl std::fmt::Display for TextureFilter {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// A half-open pixel rectangle [x0, x1) × [y0, y1) of the full image, y = 0 at the top.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Window {
    pub x0: u32,
    pub y0: u32,
    pub x1: u32,
    pub y1: u32,
}

impl Window {
    pub fn full(width: u32, height: u32) -> Self {
        Window {
            x0: 0,
            y0: 0,
            x1: width,
            y1: height,
        }
    }
    pub fn width(&self) -> u32 {
        self.x1 - self.x0
    }
    pub fn height(&self) -> u32 {
        self.y1 - self.y0
    }
    pub fn pixels(&self) -> u64 {
        self.width() as u64 * self.height() as u64
    }

    /// Parse `x0,y0,x1,y1` (x1, y1 exclusive).
    pub fn parse(s: &str) -> Result<Self, String> {
        let v: Vec<u32> = s
            .split(',')
            .map(|p| p.trim().parse::<u32>())
            .collect::<Result<_, _>>()
            .map_err(|e| format!("crop {s:?}: {e}; expected x0,y0,x1,y1"))?;
        match v[..] {
            [x0, y0, x1, y1] => Ok(Window { x0, y0, x1, y1 }),
            _ => Err(format!(
                "crop {s:?} has {} numbers; expected x0,y0,x1,y1",
                v.len()
            )),
        }
    }
}

impl std::fmt::Display for Window {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{},{},{},{}", self.x0, self.y0, self.x1, self.y1)
    }
}

#[derive(Clone, Debug)]
pub struct RenderOptions {
    pub width: u32,
    pub height: u32,
    /// Maximum number of mirror bounces along a path (0: no reflection rays).
    pub depth: u32,
    /// Samples per pixel.
    pub spp: u32,
    pub seed: u64,
    /// Shadow rays per soft-shadow light per shading point.
    pub soft_samples: u32,
    /// Ask four rays towards the rim of a soft-shadow light's extent first, and take their
    /// answer when all four let the same share of light through.
    pub soft_probe: bool,
    /// Reflection rays are traced only while the path weight (the product of the
    /// reflectances met so far, largest channel) is at least this.
    pub cutoff: f32,
    /// Render only this window of the full image (None: the whole image).
    pub crop: Option<Window>,
    pub aovs: AovSet,
    /// Worker threads (None: rayon's default, one per core).
    pub threads: Option<usize>,
    /// Tile edge in pixels.
    pub tile: u32,
    pub texture_filter: TextureFilter,
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions {
            width: 1024,
            height: 768,
            // Depth, soft samples and cut-off are what reports/accuracy.md recommends: the
            // cheapest settings whose bias adds at most 1 % to the 1-spp error.
            depth: 4,
            spp: 1,
            seed: 0,
            soft_samples: 16,
            soft_probe: true,
            cutoff: 0.004,
            crop: None,
            aovs: AovSet::default(),
            threads: None,
            tile: 32,
            texture_filter: TextureFilter::default(),
        }
    }
}

/// Largest image edge: EXR windows are i32 and a pixel index must fit comfortably.
pub const MAX_EDGE: u32 = 1 << 20;

/// Deepest mirror recursion: each bounce is a stack frame, and a room of perfect mirrors
/// (whose path weight never falls below the cut-off) overflowed the stack at about 5,000.
pub const MAX_DEPTH: u32 = 256;

/// Most samples per pixel: a pixel's sample positions are held at once, and its error has
/// long stopped falling (as 1/√spp) at this count.
pub const MAX_SPP: u32 = 1 << 16;

impl RenderOptions {
    /// Refuse options that cannot make an image, naming the option.
    pub fn validate(&self) -> Result<(), RenderError> {
        let bad = |s: String| Err(RenderError::Option(s));
        if self.width == 0 || self.height == 0 {
            return bad(format!(
                "--width {} --height {}: the image needs at least one pixel",
                self.width, self.height
            ));
        }
        if self.width > MAX_EDGE || self.height > MAX_EDGE {
            return bad(format!(
                "--width {} --height {}: edges above {MAX_EDGE} pixels are not supported",
                self.width, self.height
            ));
        }
        if self.spp == 0 {
            return bad("--spp 0: at least one sample per pixel is needed".into());
        }
        if self.spp > MAX_SPP {
            return bad(format!("--spp {}: at most {MAX_SPP}", self.spp));
        }
        if self.depth > MAX_DEPTH {
            return bad(format!("--depth {}: at most {MAX_DEPTH}", self.depth));
        }
        if self.soft_samples == 0 {
            return bad("--soft-samples 0: at least one shadow sample is needed".into());
        }
        if !(self.cutoff.is_finite() && self.cutoff >= 0.0) {
            return bad(format!(
                "--cutoff {}: must be a finite number ≥ 0",
                self.cutoff
            ));
        }
        formats::threads::requested(self.threads, None).map_err(RenderError::Option)?;
        if self.tile == 0 {
            return bad("tile size 0".into());
        }
        if let Some(c) = self.crop {
            if c.x0 >= c.x1 || c.y0 >= c.y1 || c.x1 > self.width || c.y1 > self.height {
                return bad(format!(
                    "--crop {c}: must be a non-empty window inside the {}×{} image \
                     (x0 < x1 ≤ width, y0 < y1 ≤ height; x1 and y1 are exclusive)",
                    self.width, self.height
                ));
            }
        }
        Ok(())
    }

    pub fn window(&self) -> Window {
        self.crop.unwrap_or(Window::full(self.width, self.height))
    }
}
