//! The rendered pixels of one window of the image, plus its AOVs.

use crate::integrator::Primary;
use crate::{Aov, AovSet, Window};
use glam::Vec3;

/// One channel of a [`Frame`] where it lies: a plane of its own, one component of the
/// pixels' triples, or 1 everywhere.
#[derive(Clone, Copy, Debug)]
pub enum ChannelView<'a> {
    Plane(&'a [f32]),
    /// Component 0, 1 or 2.
    Component(&'a [Vec3], usize),
    One,
}

impl ChannelView<'_> {
    /// The channel's first `n` values (`n` is the frame's pixel count).
    pub fn to_vec(self, n: usize) -> Vec<f32> {
        match self {
            ChannelView::Plane(v) => v.to_vec(),
            ChannelView::Component(v, c) => v.iter().map(|p| p[c]).collect(),
            ChannelView::One => vec![1.0; n],
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Frame {
    /// Full image size (the EXR display window).
    pub width: u32,
    pub height: u32,
    /// The rendered window (the EXR data window).
    pub window: Window,
    /// Linear RGB, row-major over the window.
    pub color: Vec<Vec3>,
    pub aovs: AovSet,
    /// Each AOV buffer is empty unless requested.
    pub depth: Vec<f32>,
    pub normal: Vec<Vec3>,
    pub albedo: Vec<Vec3>,
    pub object: Vec<f32>,
}

impl Frame {
    pub fn new(width: u32, height: u32, window: Window, aovs: AovSet) -> Self {
        let n = window.pixels() as usize;
        let sized = |on: bool| if on { n } else { 0 };
        Frame {
            width,
            height,
            window,
            color: vec![Vec3::ZERO; n],
            aovs,
            depth: vec![0.0; sized(aovs.depth)],
            normal: vec![Vec3::ZERO; sized(aovs.normal)],
            albedo: vec![Vec3::ZERO; sized(aovs.albedo)],
            object: vec![0.0; sized(aovs.object)],
        }
    }

    /// Index into the buffers of full-image pixel (x, y), if it is inside the window.
    pub fn index(&self, x: u32, y: u32) -> Option<usize> {
        let w = self.window;
        (x >= w.x0 && x < w.x1 && y >= w.y0 && y < w.y1)
            .then(|| (y - w.y0) as usize * w.width() as usize + (x - w.x0) as usize)
    }

    /// Colour of full-image pixel (x, y). Panics outside the window (a test helper).
    pub fn pixel(&self, x: u32, y: u32) -> Vec3 {
        self.color[self.index(x, y).expect("pixel inside the rendered window")]
    }

    pub(crate) fn set(&mut self, i: usize, color: Vec3, p: &Primary) {
        self.color[i] = color;
        if self.aovs.depth {
            self.depth[i] = p.depth;
        }
        if self.aovs.normal {
            self.normal[i] = p.normal;
        }
        if self.aovs.albedo {
            self.albedo[i] = p.albedo;
        }
        if self.aovs.object {
            self.object[i] = p.object;
        }
    }

    /// Every channel where it lies in the frame's buffers, named as in the EXR: R, G, B, A
    /// (1: the image is opaque, background included), then the AOVs' channels.
    pub fn channel_views(&self) -> Vec<(&'static str, ChannelView<'_>)> {
        let mut out = vec![
            ("R", ChannelView::Component(&self.color, 0)),
            ("G", ChannelView::Component(&self.color, 1)),
            ("B", ChannelView::Component(&self.color, 2)),
            ("A", ChannelView::One),
        ];
        for aov in self.aovs.list() {
            let names = aov.channels();
            match aov {
                Aov::Depth => out.push((names[0], ChannelView::Plane(&self.depth))),
                Aov::Object => out.push((names[0], ChannelView::Plane(&self.object))),
                Aov::Normal => (0..3)
                    .for_each(|c| out.push((names[c], ChannelView::Component(&self.normal, c)))),
                Aov::Albedo => (0..3)
                    .for_each(|c| out.push((names[c], ChannelView::Component(&self.albedo, c)))),
            }
        }
        out
    }

    /// Number of NaN or infinite values in all buffers (always 0 for a rendered frame).
    pub fn non_finite(&self) -> usize {
        let v = |b: &[Vec3]| b.iter().filter(|p| !p.is_finite()).count();
        let f = |b: &[f32]| b.iter().filter(|p| !p.is_finite()).count();
        v(&self.color) + v(&self.normal) + v(&self.albedo) + f(&self.depth) + f(&self.object)
    }
}
