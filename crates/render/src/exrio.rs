//! OpenEXR output: RGBA (f32, or f16 with `--half`) plus AOV channels in one single-part
//! scan-line file, the data window set to the rendered crop and the display window to the
//! full image; and merging crops into the full image. Reading back is [`crate::exrread`].

use crate::frame::ChannelView;
use crate::{Frame, RenderError, Window};
use exr::block::chunk::{Chunk, CompressedBlock, CompressedScanLineBlock};
use exr::block::writer::ChunksWriter;
use exr::block::{BlockIndex, UncompressedBlock};
use exr::image::write::layers::{LayersWriter, WritableLayers};
use exr::meta::header::Header;
use exr::prelude::*;
use libdeflater::{CompressionLvl, Compressor};
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::io::Cursor;
use std::path::Path;

/// Prefix of unitrace's own header attributes.
pub const ATTR_PREFIX: &str = "unitrace.";

/// Channels stored as f16 with `--half` (colour and albedo). Depth, normals and object
/// ids stay f32: halves would lose depth precision and object ids above 2048.
fn halvable(name: &str) -> bool {
    matches!(name, "R" | "G" | "B" | "A") || name.starts_with("albedo.")
}

/// JSON with every non-ASCII character escaped (`\uXXXX`), because EXR text attributes
/// are bytes: light and object names may hold any Unicode.
pub fn ascii_json(v: &serde_json::Value) -> String {
    let s = v.to_string();
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        if c.is_ascii() {
            out.push(c);
        } else {
            let mut buf = [0u16; 2];
            for unit in c.encode_utf16(&mut buf) {
                out.push_str(&format!("\\u{unit:04x}"));
            }
        }
    }
    out
}

/// An EXR image as unitrace reads and writes it.
#[derive(Clone, Debug, PartialEq)]
pub struct ExrImage {
    pub width: u32,
    pub height: u32,
    pub window: Window,
    /// Sorted by name (the EXR order).
    pub channels: Vec<(String, FlatSamples)>,
    /// Text attributes (unitrace's and any other text attribute in the header).
    pub attributes: BTreeMap<String, String>,
}

impl ExrImage {
    pub fn from_frame(frame: &Frame, half: bool, attributes: BTreeMap<String, String>) -> Self {
        let n = frame.window.pixels() as usize;
        let channels = frame_layout(frame, half)
            .into_iter()
            .map(|(name, view, halved)| {
                let plane = view.to_vec(n);
                let samples = if halved {
                    FlatSamples::F16(plane.into_iter().map(f16::from_f32).collect())
                } else {
                    FlatSamples::F32(plane)
                };
                (name.to_string(), samples)
            })
            .collect();
        ExrImage {
            width: frame.width,
            height: frame.height,
            window: frame.window,
            channels,
            attributes,
        }
    }

    pub fn channel(&self, name: &str) -> Option<&FlatSamples> {
        self.channels.iter().find(|c| c.0 == name).map(|c| &c.1)
    }

    pub fn channel_names(&self) -> Vec<&str> {
        self.channels.iter().map(|c| c.0.as_str()).collect()
    }

    /// Linear RGB of the data window, row-major, as the preview encodes it; None without
    /// R, G and B channels.
    pub fn color(&self) -> Option<Vec<glam::Vec3>> {
        let [r, g, b] = ["R", "G", "B"].map(|n| self.channel(n));
        let (r, g, b) = (r?, g?, b?);
        Some(
            (0..self.window.pixels() as usize)
                .map(|i| {
                    glam::Vec3::new(
                        r.value_by_flat_index(i).to_f32(),
                        g.value_by_flat_index(i).to_f32(),
                        b.value_by_flat_index(i).to_f32(),
                    )
                })
                .collect(),
        )
    }

    /// Value of channel `name` at full-image pixel (x, y), as f32.
    pub fn value(&self, name: &str, x: u32, y: u32) -> Option<f32> {
        let w = self.window;
        if x < w.x0 || x >= w.x1 || y < w.y0 || y >= w.y1 {
            return None;
        }
        let i = (y - w.y0) as usize * w.width() as usize + (x - w.x0) as usize;
        Some(self.channel(name)?.value_by_flat_index(i).to_f32())
    }

    /// Encode as an EXR file in memory: ZIP in blocks of 16 scan lines, as OpenEXR's own
    /// tools write by default, each block deflated by libdeflate at level 1 on rayon's
    /// threads. The `exr` crate deflates with miniz at level 4, which on a rendered frame
    /// takes 3× as long for a file of the same size (see `exrwrite`).
    pub fn encode(&self) -> std::result::Result<Vec<u8>, String> {
        let n = self.window.pixels() as usize;
        if let Some((name, _)) = self.channels.iter().find(|(_, s)| s.len() != n) {
            return Err(format!(
                "channel {name} does not hold one sample per pixel of the {}×{} window",
                self.window.width(),
                self.window.height()
            ));
        }
        self.encode_planes(|name| self.channel(name).map(Plane::Samples))
    }

    /// [`ExrImage::from_frame`] encoded, the same bytes, but each block read straight from
    /// the frame's buffers: gathering the planes first costs more than the blocks' copying,
    /// most of it in page faults on the fresh memory.
    pub fn encode_frame(
        frame: &Frame,
        half: bool,
        attributes: BTreeMap<String, String>,
    ) -> std::result::Result<Vec<u8>, String> {
        if cfg!(target_endian = "big") {
            // The crate writes the blocks there, from samples of its own.
            return Self::from_frame(frame, half, attributes).encode();
        }
        let n = frame.window.pixels() as usize;
        for (name, view) in frame.channel_views() {
            let len = match view {
                ChannelView::Plane(v) => v.len(),
                ChannelView::Component(v, _) => v.len(),
                ChannelView::One => n,
            };
            if len != n {
                return Err(format!(
                    "channel {name} of the frame holds {len} of {n} pixels"
                ));
            }
        }
        let layout = frame_layout(frame, half);
        // The header's image: each channel's type, no samples.
        let channels = layout
            .iter()
            .map(|&(name, _, halved)| {
                let samples = match halved {
                    true => FlatSamples::F16(Vec::new()),
                    false => FlatSamples::F32(Vec::new()),
                };
                (name.to_string(), samples)
            })
            .collect();
        let header = ExrImage {
            width: frame.width,
            height: frame.height,
            window: frame.window,
            channels,
            attributes,
        };
        header.encode_planes(|name| {
            let &(_, view, halved) = layout.iter().find(|c| c.0 == name)?;
            Some(Plane::Frame(view, halved))
        })
    }

    /// Encode with each block's samples from `plane` (by channel name) and the header
    /// from this image. On big-endian machines the crate builds the blocks, from this
    /// image's samples.
    fn encode_planes<'a>(
        &self,
        plane: impl Fn(&str) -> Option<Plane<'a>>,
    ) -> std::result::Result<Vec<u8>, String> {
        // On little-endian machines the blocks are built here from the channels, and the
        // crate's image only describes the header: it need not copy the samples.
        let big_endian = cfg!(target_endian = "big");
        let image = self.exr_image(Encoding::SMALL_LOSSLESS, big_endian)?;
        let headers = image.write().infer_meta_data();
        // The header's channel order, which is what a block's lines follow.
        let planes = headers[0]
            .channels
            .list
            .iter()
            .map(|c| {
                let name = c.name.to_string();
                plane(&name).ok_or(format!(
                    "channel {name} is in the header but not in the image"
                ))
            })
            .collect::<std::result::Result<Vec<_>, _>>()?;
        let layers = image.layer_data.create_writer(&headers);
        let mut out = Cursor::new(Vec::new());
        exr::block::write(&mut out, headers, true, |meta, writer| {
            let blocks: Vec<_> = meta.enumerate_ordered_header_block_indices().collect();
            let chunks = blocks
                .into_par_iter()
                .map_init(ZipScratch::new, |scratch, (i, index)| {
                    let chunk = if big_endian {
                        // The samples must be swapped to little-endian first: leave that to
                        // the crate.
                        let data = layers.extract_uncompressed_block(&meta.headers, index);
                        UncompressedBlock { index, data }.compress_to_chunk(&meta.headers)
                    } else {
                        block_bytes(
                            &planes,
                            self.window.width() as usize,
                            index,
                            &mut scratch.raw,
                        );
                        Ok(zip_chunk(scratch, &meta.headers, index))
                    };
                    chunk.map(|c| (i, c))
                })
                .collect::<exr::error::Result<Vec<_>>>()?;
            for (i, chunk) in chunks {
                writer.write_chunk(i, chunk)?;
            }
            Ok(())
        })
        .map_err(|e| e.to_string())?;
        sorted_header(out.into_inner())
    }

    /// Encode with the `exr` crate's own compressors (what `exrwrite` compares).
    pub fn encode_with(&self, encoding: Encoding) -> std::result::Result<Vec<u8>, String> {
        let mut out = Cursor::new(Vec::new());
        self.exr_image(encoding, true)?
            .write()
            .to_buffered(&mut out)
            .map_err(|e| e.to_string())?;
        sorted_header(out.into_inner())
    }

    /// The `exr` crate's image of this one: one layer, its channels and attributes; without
    /// `samples`, each channel's sample type but none of its samples, which is enough for
    /// the header.
    fn exr_image(
        &self,
        encoding: Encoding,
        samples: bool,
    ) -> std::result::Result<Image<Layer<AnyChannels<FlatSamples>>>, String> {
        let list: SmallVec<[AnyChannel<FlatSamples>; 4]> = self
            .channels
            .iter()
            .map(|(name, s)| {
                let text =
                    Text::new_or_none(name).ok_or(format!("channel name {name:?} is not ASCII"))?;
                let s = match s {
                    _ if samples => s.clone(),
                    FlatSamples::F16(_) => FlatSamples::F16(Vec::new()),
                    FlatSamples::F32(_) => FlatSamples::F32(Vec::new()),
                    FlatSamples::U32(_) => FlatSamples::U32(Vec::new()),
                };
                Ok(AnyChannel::new(text, s))
            })
            .collect::<std::result::Result<_, String>>()?;
        let size = (self.window.width() as usize, self.window.height() as usize);
        let mut attrs = LayerAttributes {
            layer_position: Vec2(self.window.x0 as i32, self.window.y0 as i32),
            software_name: Some(Text::from(concat!(
                "unitrace kd2exr ",
                env!("CARGO_PKG_VERSION")
            ))),
            ..LayerAttributes::default()
        };
        for (k, v) in &self.attributes {
            let (Some(k), Some(v)) = (Text::new_or_none(k), Text::new_or_none(v)) else {
                return Err(format!("attribute {k:?} is not Latin-1 text"));
            };
            attrs.other.insert(k, AttributeValue::Text(v));
        }
        let layer = Layer::new(size, attrs, encoding, AnyChannels::sort(list));
        let display = IntegerBounds::new((0, 0), (self.width as usize, self.height as usize));
        Ok(Image::new(ImageAttributes::new(display), layer))
    }

    /// Write atomically (temp file in the same folder + rename).
    pub fn write(&self, path: &Path) -> std::result::Result<(), RenderError> {
        write_encoded(path, self.encode())
    }

    /// [`ExrImage::encode_frame`] written atomically.
    pub fn write_frame(
        frame: &Frame,
        half: bool,
        attributes: BTreeMap<String, String>,
        path: &Path,
    ) -> std::result::Result<(), RenderError> {
        write_encoded(path, Self::encode_frame(frame, half, attributes))
    }
}

/// A frame's channels in the EXR's order (by name), each with whether it is stored as f16.
fn frame_layout(frame: &Frame, half: bool) -> Vec<(&'static str, ChannelView<'_>, bool)> {
    let mut layout: Vec<_> = frame
        .channel_views()
        .into_iter()
        .map(|(name, view)| (name, view, half && halvable(name)))
        .collect();
    layout.sort_by_key(|c| c.0);
    layout
}

/// An encoded image written atomically, or its encoding error named with the path.
/// The single-part file `bytes` with its header's attributes in the order of their names.
/// The `exr` crate keeps a layer's other attributes in a hash map, whose order changes from
/// one run to the next: without this the same render would write different bytes each
/// time. The header keeps its length, so the offset table after it stays right.
fn sorted_header(mut bytes: Vec<u8>) -> std::result::Result<Vec<u8>, String> {
    const MULTIPART: u8 = 0x10;
    if bytes.len() < 8 || bytes[5] & MULTIPART != 0 {
        return Err("not a single-part EXR file".into());
    }
    let bad = || "the EXR header ends inside an attribute".to_string();
    let mut attributes: Vec<(&[u8], &[u8])> = Vec::new();
    let mut at = 8;
    loop {
        let name_end = at + bytes[at..].iter().position(|&b| b == 0).ok_or_else(bad)?;
        if name_end == at {
            break;
        }
        let type_end = name_end
            + 1
            + bytes[name_end + 1..]
                .iter()
                .position(|&b| b == 0)
                .ok_or_else(bad)?;
        let size: [u8; 4] = bytes
            .get(type_end + 1..type_end + 5)
            .ok_or_else(bad)?
            .try_into()
            .map_err(|_| bad())?;
        let end = type_end + 5 + u32::from_le_bytes(size) as usize;
        if end > bytes.len() {
            return Err(bad());
        }
        attributes.push((&bytes[at..name_end], &bytes[at..end]));
        at = end;
    }
    attributes.sort_by_key(|&(name, _)| name);
    let header: Vec<u8> = attributes
        .iter()
        .flat_map(|&(_, a)| a.iter().copied())
        .collect();
    bytes[8..8 + header.len()].copy_from_slice(&header);
    Ok(bytes)
}

fn write_encoded(
    path: &Path,
    encoded: std::result::Result<Vec<u8>, String>,
) -> std::result::Result<(), RenderError> {
    let bytes = encoded.map_err(|detail| RenderError::ExrWrite {
        path: path.to_path_buf(),
        detail,
    })?;
    formats::write_atomic(path, &bytes)?;
    Ok(())
}

/// What one thread reuses from block to block: its compressor, and buffers the size of a
/// block, which are too large to allocate cheaply each time.
struct ZipScratch {
    deflate: Compressor,
    raw: Vec<u8>,
    split: Vec<u8>,
    predicted: Vec<u8>,
    packed: Vec<u8>,
}

impl ZipScratch {
    fn new() -> Self {
        ZipScratch {
            deflate: Compressor::new(CompressionLvl::new(1).expect("level 1 exists")),
            raw: Vec::new(),
            split: Vec::new(),
            predicted: Vec::new(),
            packed: Vec::new(),
        }
    }
}

/// A channel's samples as the blocks read them.
#[derive(Clone, Copy)]
enum Plane<'a> {
    Samples(&'a FlatSamples),
    /// A frame's f32 values, converted to f16 on the way when `.1`.
    Frame(ChannelView<'a>, bool),
}

impl Plane<'_> {
    fn sample_bytes(&self) -> usize {
        match self {
            Plane::Samples(FlatSamples::F16(_)) | Plane::Frame(_, true) => 2,
            Plane::Samples(_) | Plane::Frame(_, false) => 4,
        }
    }
}

/// The little-endian bytes of one scan-line block into `out`: for each line, each channel
/// of `planes` (the header's order) with that line's samples. `width` is the data
/// window's.
fn block_bytes(planes: &[Plane], width: usize, index: BlockIndex, out: &mut Vec<u8>) {
    let (x, y) = (index.pixel_position.x(), index.pixel_position.y());
    let (w, h) = (index.pixel_size.width(), index.pixel_size.height());
    let per_pixel: usize = planes.iter().map(Plane::sample_bytes).sum();
    out.resize(w * h * per_pixel, 0);
    let mut at = 0;
    for row in y..y + h {
        let line = row * width + x..row * width + x + w;
        for plane in planes {
            let dst = &mut out[at..at + w * plane.sample_bytes()];
            let line = line.clone();
            let half = |v: f32| f16::from_f32(v).to_le_bytes();
            match *plane {
                Plane::Samples(FlatSamples::F16(v)) => put(dst, &v[line], |s| s.to_le_bytes()),
                Plane::Samples(FlatSamples::F32(v)) => put(dst, &v[line], |s| s.to_le_bytes()),
                Plane::Samples(FlatSamples::U32(v)) => put(dst, &v[line], |s| s.to_le_bytes()),
                Plane::Frame(ChannelView::Plane(v), false) => {
                    put(dst, &v[line], |s| s.to_le_bytes())
                }
                Plane::Frame(ChannelView::Plane(v), true) => put(dst, &v[line], half),
                Plane::Frame(ChannelView::Component(v, c), false) => {
                    put(dst, &v[line], |p| p[c].to_le_bytes())
                }
                Plane::Frame(ChannelView::Component(v, c), true) => {
                    put(dst, &v[line], |p| half(p[c]))
                }
                Plane::Frame(ChannelView::One, false) => fill(dst, 1.0f32.to_le_bytes()),
                Plane::Frame(ChannelView::One, true) => fill(dst, half(1.0)),
            }
            at += dst.len();
        }
    }
}

fn fill<const N: usize>(dst: &mut [u8], bytes: [u8; N]) {
    for d in dst.chunks_exact_mut(N) {
        d.copy_from_slice(&bytes);
    }
}

fn put<T: Copy, const N: usize>(dst: &mut [u8], src: &[T], bytes: impl Fn(T) -> [u8; N]) {
    for (d, &s) in dst.chunks_exact_mut(N).zip(src) {
        d.copy_from_slice(&bytes(s));
    }
}

/// `raw`'s even-indexed bytes into `evens`, its odd-indexed ones into `odds`, each half as
/// long as `raw` (whose length is even, as every sample's is).
fn deinterleave(raw: &[u8], evens: &mut [u8], odds: &mut [u8]) {
    const LOW: u64 = 0x00ff_00ff_00ff_00ff;
    // The low bytes of the four 16-bit lanes of `x` (each 0 to 255) gathered into its low
    // 32 bits: eight bytes a step instead of one, which the compiler does not find itself.
    let gather = |x: u64| {
        let x = (x | x >> 8) & 0x0000_ffff_0000_ffff;
        (x | x >> 16) & 0xffff_ffff
    };
    let (raw16, rest) = raw.split_at(raw.len() / 16 * 16);
    let (evens8, evens_rest) = evens.split_at_mut(raw16.len() / 2);
    let (odds8, odds_rest) = odds.split_at_mut(raw16.len() / 2);
    let words = raw16
        .chunks_exact(16)
        .zip(evens8.chunks_exact_mut(8))
        .zip(odds8.chunks_exact_mut(8));
    for ((src, e), o) in words {
        let [a, b] = [&src[..8], &src[8..]].map(|s| {
            u64::from_le_bytes(
                s.try_into()
                    .expect("a chunk of 16 bytes has two halves of 8"),
            )
        });
        e.copy_from_slice(&(gather(a & LOW) | gather(b & LOW) << 32).to_le_bytes());
        o.copy_from_slice(&(gather(a >> 8 & LOW) | gather(b >> 8 & LOW) << 32).to_le_bytes());
    }
    for ((pair, e), o) in rest.chunks_exact(2).zip(evens_rest).zip(odds_rest) {
        *e = pair[0];
        *o = pair[1];
    }
}

/// One scan-line block, its little-endian bytes in `scratch.raw`, as OpenEXR's ZIP
/// compressor stores it: the even-indexed bytes, then the odd-indexed ones, each byte
/// replaced by its difference to the one before plus 128, then zlib; a block that would
/// not shrink is stored as it is, which readers recognise by its size.
fn zip_chunk(scratch: &mut ZipScratch, headers: &[Header], index: BlockIndex) -> Chunk {
    let ZipScratch {
        deflate,
        raw,
        split,
        predicted,
        packed,
    } = scratch;
    let n = raw.len();
    split.resize(n, 0);
    predicted.resize(n, 0);
    let (evens, odds) = split.split_at_mut(n / 2);
    deinterleave(raw, evens, odds);
    // From a copy, front to back: in place it would have to run backwards, which the
    // compiler does not vectorise.
    if n > 0 {
        predicted[0] = split[0];
        let pairs = predicted[1..]
            .iter_mut()
            .zip(&split[1..])
            .zip(&split[..n - 1]);
        for ((d, &cur), &prev) in pairs {
            *d = cur.wrapping_sub(prev).wrapping_add(128);
        }
    }
    packed.resize(deflate.zlib_compress_bound(n), 0);
    // The only failure is a too small buffer, which the bound rules out; it would store
    // the block as it is.
    let size = deflate.zlib_compress(predicted, packed).unwrap_or(n);
    let header = &headers[index.layer];
    let y = index.pixel_position.y() as i32 + header.own_attributes.layer_position.y();
    Chunk {
        layer_index: index.layer,
        compressed_block: CompressedBlock::ScanLine(CompressedScanLineBlock {
            y_coordinate: y,
            compressed_pixels_le: if size < n {
                packed[..size].to_vec()
            } else {
                raw.clone()
            },
        }),
    }
}

/// Attributes that must agree between the crops of one image: the settings that change
/// pixels, the scene (its geometry, and the soup's checksum, which also covers materials,
/// lights and camera), the tree's build parameters and the renderer's version. Crops that
/// differ in any of them may still cover the image without a gap or a disagreeing overlap.
const SAME_RENDER: [&str; 11] = [
    "spp",
    "depth",
    "seed",
    "geometryHash",
    "softSamples",
    "softProbe",
    "cutoff",
    "textureFilter",
    "soupDigest",
    "treeParams",
    "version",
];

/// Assemble crops of one render into the full image. Every pixel must be covered; where
/// crops overlap they must agree bit for bit. The result's pixels are bit-identical to a
/// one-shot render; its `renderSeconds` is the sum of the parts'. Errors name the inputs
/// by position ("input 2"); [`merge_labelled`] names them as the caller likes.
pub fn merge(parts: &[ExrImage]) -> std::result::Result<ExrImage, RenderError> {
    let labelled: Vec<(String, &ExrImage)> = parts
        .iter()
        .enumerate()
        .map(|(i, p)| (format!("input {}", i + 1), p))
        .collect();
    merge_labelled(&labelled)
}

/// [`merge`], each error naming the offending input by its label (kd2exr passes the file
/// names, so a refusal says which tile to look at).
pub fn merge_labelled(parts: &[(String, &ExrImage)]) -> std::result::Result<ExrImage, RenderError> {
    let bad = |s: String| RenderError::Merge(s);
    let (first_label, first) = parts.first().ok_or_else(|| bad("no input images".into()))?;
    let first = *first;
    let names = first.channel_names();
    let crop_key = format!("{ATTR_PREFIX}crop");
    for (label, p) in parts {
        if (p.width, p.height) != (first.width, first.height) {
            return Err(bad(format!(
                "{label} is a crop of a {}×{} image, {first_label} of {}×{}",
                p.width, p.height, first.width, first.height
            )));
        }
        // A crop whose header names another window than the one it holds was cut or
        // edited after rendering: its pixels are not where the render put them.
        if let Some(crop) = p.attributes.get(&crop_key) {
            if *crop != p.window.to_string() {
                return Err(bad(format!(
                    "{label} was rendered as the crop {crop} but holds the window {}",
                    p.window
                )));
            }
        }
        if p.channel_names() != names {
            return Err(bad(format!(
                "{label} has channels {:?}, {first_label} has {:?}",
                p.channel_names(),
                names
            )));
        }
        for key in SAME_RENDER {
            let k = format!("{ATTR_PREFIX}{key}");
            if p.attributes.get(&k) != first.attributes.get(&k) {
                let value = |img: &ExrImage| {
                    img.attributes
                        .get(&k)
                        .map_or("unset".to_string(), |v| format!("\"{v}\""))
                };
                return Err(bad(format!(
                    "{label} was rendered with {key} {}, {first_label} with {}: \
                     they are not crops of one render",
                    value(p),
                    value(first)
                )));
            }
        }
    }
    let (w, h) = (first.width as usize, first.height as usize);
    // The full image is assembled in memory: refuse, as a render does, what cannot fit.
    let per_pixel: u64 = 1 + first
        .channels
        .iter()
        .map(|(_, s)| match s {
            FlatSamples::F16(_) => 2,
            FlatSamples::F32(_) | FlatSamples::U32(_) => 4,
        })
        .sum::<u64>();
    let need = w as u64 * h as u64 * per_pixel;
    if let Some((need, avail)) = crate::memory::short_of(need, crate::memory::available_bytes()) {
        return Err(bad(format!(
            "a {w}×{h} image with {} channels needs about {need:.1} GiB to merge, only \
             {avail:.1} GiB of memory is available",
            first.channels.len(),
        )));
    }
    let mut covered = vec![false; w * h];
    let mut channels: Vec<(String, FlatSamples)> = first
        .channels
        .iter()
        .map(|(n, s)| {
            let full = match s {
                FlatSamples::F16(_) => FlatSamples::F16(vec![f16::ZERO; w * h]),
                FlatSamples::F32(_) => FlatSamples::F32(vec![0.0; w * h]),
                FlatSamples::U32(_) => FlatSamples::U32(vec![0; w * h]),
            };
            (n.clone(), full)
        })
        .collect();
    for (label, p) in parts {
        let pw = p.window.width() as usize;
        for (ci, (name, src)) in p.channels.iter().enumerate() {
            let dst = &mut channels[ci].1;
            for row in 0..p.window.height() as usize {
                let y = p.window.y0 as usize + row;
                let from = row * pw;
                let to = y * w + p.window.x0 as usize;
                let ok = match (src, &mut *dst) {
                    (FlatSamples::F16(s), FlatSamples::F16(d)) => copy_row(
                        &s[from..from + pw],
                        &mut d[to..to + pw],
                        &covered[to..to + pw],
                        |a, b| a.to_bits() == b.to_bits(),
                    ),
                    (FlatSamples::F32(s), FlatSamples::F32(d)) => copy_row(
                        &s[from..from + pw],
                        &mut d[to..to + pw],
                        &covered[to..to + pw],
                        |a, b| a.to_bits() == b.to_bits(),
                    ),
                    (FlatSamples::U32(s), FlatSamples::U32(d)) => copy_row(
                        &s[from..from + pw],
                        &mut d[to..to + pw],
                        &covered[to..to + pw],
                        |a, b| a == b,
                    ),
                    _ => {
                        return Err(bad(format!(
                        "channel {name} of {label} has another sample type than in {first_label}"
                    )))
                    }
                };
                if let Err(x) = ok {
                    return Err(bad(format!(
                        "{label} overlaps an earlier input at pixel ({}, {y}) with a \
                         different {name} value: they are not crops of one render",
                        p.window.x0 as usize + x
                    )));
                }
            }
        }
        for row in 0..p.window.height() as usize {
            let to = (p.window.y0 as usize + row) * w + p.window.x0 as usize;
            covered[to..to + pw].iter_mut().for_each(|c| *c = true);
        }
    }
    if let Some(i) = covered.iter().position(|c| !c) {
        let missing = covered.iter().filter(|c| !**c).count();
        return Err(bad(format!(
            "{missing} pixels are in no input, the first at ({}, {})",
            i % w,
            i / w
        )));
    }
    let mut attributes = first.attributes.clone();
    let seconds: f64 = parts
        .iter()
        .filter_map(|(_, p)| {
            p.attributes
                .get(&format!("{ATTR_PREFIX}renderSeconds"))?
                .parse::<f64>()
                .ok()
        })
        .sum();
    attributes.insert(
        format!("{ATTR_PREFIX}renderSeconds"),
        format!("{seconds:.6}"),
    );
    attributes.insert(format!("{ATTR_PREFIX}mergedFrom"), parts.len().to_string());
    attributes.remove(&format!("{ATTR_PREFIX}crop"));
    Ok(ExrImage {
        width: first.width,
        height: first.height,
        window: Window::full(first.width, first.height),
        channels,
        attributes,
    })
}

/// Copy `src` into `dst`; where `covered` already, the values must be equal. Err(x) is
/// the first disagreeing position.
fn copy_row<T: Copy>(
    src: &[T],
    dst: &mut [T],
    covered: &[bool],
    same: impl Fn(T, T) -> bool,
) -> std::result::Result<(), usize> {
    for (x, ((s, d), c)) in src.iter().zip(dst.iter_mut()).zip(covered).enumerate() {
        if *c && !same(*s, *d) {
            return Err(x);
        }
        *d = *s;
    }
    Ok(())
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::AovSet;

    /// An EXR file of RGB whose display window is `display` and data window `data` at the
    /// origin, as another program might write it.
    pub(crate) fn foreign_exr(path: &Path, display: (usize, usize), data: (usize, usize)) {
        let n = data.0 * data.1;
        let ch = |name: &str| AnyChannel::new(name, FlatSamples::F32(vec![0.5; n]));
        let channels = AnyChannels::sort(vec![ch("R"), ch("G"), ch("B")].into());
        let layer = Layer::new(
            data,
            LayerAttributes::default(),
            Encoding::UNCOMPRESSED,
            channels,
        );
        let mut image = Image::from_layer(layer);
        image.attributes.display_window = IntegerBounds::new((0, 0), display);
        image.write().to_file(path).unwrap();
    }

    #[test]
    fn crops_past_their_image_or_too_large_to_merge_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let past = dir.path().join("past.exr");
        foreign_exr(&past, (1, 1), (10, 10));
        let err = ExrImage::read(&past).unwrap_err().to_string();
        assert!(
            err.contains("past.exr") && err.contains("reaches past the 1×1 image"),
            "{err}"
        );

        // A 400-byte file describing a 200,000² image: merging it would need about 480 GiB.
        let huge = dir.path().join("huge.exr");
        foreign_exr(&huge, (200_000, 200_000), (1, 1));
        let img = ExrImage::read(&huge).unwrap();
        let err = merge(&[img]).unwrap_err().to_string();
        assert!(
            err.contains("a 200000×200000 image with 3 channels needs about"),
            "{err}"
        );
    }

    fn crop(window: Window, attrs: &[(&str, &str)]) -> ExrImage {
        let n = window.pixels() as usize;
        ExrImage {
            width: 4,
            height: 2,
            window,
            channels: vec![("R".into(), FlatSamples::F32(vec![0.5; n]))],
            attributes: attrs
                .iter()
                .map(|(k, v)| (format!("{ATTR_PREFIX}{k}"), v.to_string()))
                .collect(),
        }
    }

    /// The left and right 2×2 halves of a 4×2 image.
    fn halves() -> (Window, Window) {
        let w = |x0| Window {
            x0,
            y0: 0,
            x1: x0 + 2,
            y1: 2,
        };
        (w(0), w(2))
    }

    /// Random bits, repeatable from `seed` (xorshift64).
    fn xorshift(mut state: u64) -> impl FnMut() -> u32 {
        move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state as u32
        }
    }

    /// A 50×40 crop at (3, 37) of a 60×90 image: three blocks of 16 lines, the last one
    /// short. `noise` fills every channel with random bits, which deflate cannot shrink.
    pub(crate) fn encodable(noise: bool) -> ExrImage {
        let window = Window {
            x0: 3,
            y0: 37,
            x1: 53,
            y1: 77,
        };
        let n = window.pixels() as usize;
        let mut bits = xorshift(0x9e37_79b9_7f4a_7c15);
        let mut f32s = |f: fn(usize) -> f32| -> Vec<f32> {
            (0..n)
                .map(|i| if noise { f32::from_bits(bits()) } else { f(i) })
                .collect()
        };
        let red = f32s(|i| (i % 50) as f32 / 50.0);
        let depth = f32s(|i| 10.0 + (i / 50) as f32 * 0.25);
        let alpha = (0..n)
            .map(|_| match noise {
                true => f16::from_bits(bits() as u16),
                false => f16::ONE,
            })
            .collect();
        ExrImage {
            width: 60,
            height: 90,
            window,
            channels: vec![
                ("A".into(), FlatSamples::F16(alpha)),
                ("R".into(), FlatSamples::F32(red)),
                ("Z".into(), FlatSamples::F32(depth)),
            ],
            attributes: BTreeMap::from([(format!("{ATTR_PREFIX}spp"), "1".to_string())]),
        }
    }

    /// The same image gives the same bytes every time, its attributes in name order,
    /// whatever order the `exr` crate's map hands them out in; and it reads back whole.
    #[test]
    fn encoding_is_deterministic_with_the_attributes_in_name_order() {
        let mut image = encodable(false);
        image.attributes = (0..24)
            .map(|i| (format!("{ATTR_PREFIX}k{:02}", 23 - i), "v".repeat(i)))
            .collect();
        let first = image.encode().unwrap();
        for _ in 0..4 {
            assert!(image.encode().unwrap() == first);
            assert!(image.encode_with(Encoding::SMALL_LOSSLESS).unwrap()[..200] == first[..200]);
        }
        let text = String::from_utf8_lossy(&first);
        let at: Vec<usize> = (0..24)
            .map(|i| text.find(&format!("{ATTR_PREFIX}k{i:02}")).unwrap())
            .collect();
        assert!(at.windows(2).all(|w| w[0] < w[1]), "{at:?}");
        for name in ["channels", "compression", "dataWindow", "software"] {
            assert!(
                text.find(name).unwrap() < at[0],
                "{name} before unitrace.k00"
            );
        }
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("sorted.exr");
        std::fs::write(&path, &first).unwrap();
        let back = ExrImage::read(&path).unwrap();
        assert_eq!(back.attributes, image.attributes);
        assert_eq!(back.channels, image.channels);
        assert!(sorted_header(vec![0x76, 0x2f, 0x31, 0x01, 2, 0x10, 0, 0]).is_err());
        assert!(sorted_header(first[..60].to_vec()).is_err());
    }

    #[test]
    fn encoded_images_give_back_every_sample_bit_for_bit() {
        let dir = tempfile::tempdir().unwrap();
        for noise in [false, true] {
            let image = encodable(noise);
            let bytes = image.encode().unwrap();
            // Samples: 50×40 pixels of 4 + 4 + 2 bytes.
            let raw = 50 * 40 * 10;
            if noise {
                // Every block stored as it is: the samples plus header, offsets and the
                // 8-byte prefix of each of the three blocks.
                assert!(
                    bytes.len() > raw && bytes.len() < raw + 2_000,
                    "{}",
                    bytes.len()
                );
            } else {
                assert!(bytes.len() < raw / 4, "{} bytes", bytes.len());
            }
            let path = dir.path().join(format!("{noise}.exr"));
            std::fs::write(&path, &bytes).unwrap();
            let back = ExrImage::read(&path).unwrap();
            assert_eq!(
                (back.width, back.height, back.window),
                (60, 90, image.window)
            );
            assert_eq!(back.attributes[&format!("{ATTR_PREFIX}spp")], "1");
            assert_eq!(back.channel_names(), ["A", "R", "Z"]);
            for ((name, ours), (_, theirs)) in back.channels.iter().zip(&image.channels) {
                assert_eq!(
                    sample_bits(ours),
                    sample_bits(theirs),
                    "channel {name}, noise {noise}"
                );
            }
        }
    }

    /// A 37×21 crop at (5, 11) of a 64×40 image with every sample type, each channel
    /// filled with random bits.
    fn odd_crop() -> ExrImage {
        let window = Window {
            x0: 5,
            y0: 11,
            x1: 42,
            y1: 32,
        };
        let n = window.pixels() as usize;
        let mut bits = xorshift(0x2545_f491_4f6c_dd1d);
        let mut f32s = || (0..n).map(|_| f32::from_bits(bits())).collect::<Vec<_>>();
        let (red, depth) = (f32s(), f32s());
        let alpha = (0..n).map(|_| f16::from_bits(bits() as u16)).collect();
        let object = (0..n).map(|_| bits()).collect();
        ExrImage {
            width: 64,
            height: 40,
            window,
            // Out of name order: the blocks follow the header's order.
            channels: vec![
                ("Z".into(), FlatSamples::F32(depth)),
                ("A".into(), FlatSamples::F16(alpha)),
                ("object".into(), FlatSamples::U32(object)),
                ("R".into(), FlatSamples::F32(red)),
            ],
            attributes: BTreeMap::new(),
        }
    }

    /// The samples as bits: NaNs compare equal to themselves.
    fn sample_bits(s: &FlatSamples) -> Vec<u32> {
        match s {
            FlatSamples::F16(v) => v.iter().map(|h| h.to_bits() as u32).collect(),
            FlatSamples::F32(v) => v.iter().map(|f| f.to_bits()).collect(),
            FlatSamples::U32(v) => v.clone(),
        }
    }

    fn block_indices(headers: &[Header]) -> Vec<BlockIndex> {
        exr::block::enumerate_ordered_header_block_indices(headers)
            .map(|(_, index)| index)
            .collect()
    }

    #[test]
    fn blocks_hold_the_bytes_the_exr_crate_extracts() {
        for image in [odd_crop(), encodable(false), encodable(true)] {
            let crate_image = image.exr_image(Encoding::SMALL_LOSSLESS, true).unwrap();
            let headers = crate_image.write().infer_meta_data();
            let layers = crate_image.layer_data.create_writer(&headers);
            let planes: Vec<_> = headers[0]
                .channels
                .list
                .iter()
                .map(|c| Plane::Samples(image.channel(&c.name.to_string()).unwrap()))
                .collect();
            let mut ours = Vec::new();
            let blocks = block_indices(&headers);
            assert!(blocks.len() >= 2);
            for index in blocks {
                block_bytes(&planes, image.window.width() as usize, index, &mut ours);
                let theirs = layers.extract_uncompressed_block(&headers, index);
                assert_eq!(ours, theirs, "block at line {}", index.pixel_position.y());
            }
        }
    }

    #[test]
    fn an_odd_crop_of_every_sample_type_gives_back_every_sample() {
        let image = odd_crop();
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("odd.exr");
        std::fs::write(&path, image.encode().unwrap()).unwrap();
        let back = ExrImage::read(&path).unwrap();
        assert_eq!(back.window, image.window);
        assert_eq!(back.channel_names(), ["A", "R", "Z", "object"]);
        for (name, samples) in &image.channels {
            let back = back.channel(name).unwrap();
            assert_eq!(sample_bits(back), sample_bits(samples), "channel {name}");
        }
    }

    #[test]
    fn zip_chunks_hold_the_split_and_predicted_bytes() {
        // The definition, a byte at a time.
        let reference = |raw: &[u8]| {
            let evens = raw.iter().step_by(2);
            let split: Vec<u8> = evens
                .chain(raw.iter().skip(1).step_by(2))
                .copied()
                .collect();
            let mut predicted = split.clone();
            for i in 1..split.len() {
                predicted[i] = split[i].wrapping_sub(split[i - 1]).wrapping_add(128);
            }
            predicted
        };
        let image = odd_crop();
        let headers = image
            .exr_image(Encoding::SMALL_LOSSLESS, false)
            .unwrap()
            .write()
            .infer_meta_data();
        let index = block_indices(&headers)[0];
        let mut scratch = ZipScratch::new();
        let mut inflate = libdeflater::Decompressor::new();
        // Lengths on either side of the 16 bytes deinterleaved at a time; smooth bytes,
        // which deflate shrinks.
        for n in [2, 4, 14, 16, 18, 30, 32, 34, 250, 4096 + 6] {
            scratch.raw = (0..n).map(|i| (i / 7 + i % 2 * 40) as u8).collect();
            let chunk = zip_chunk(&mut scratch, &headers, index);
            let CompressedBlock::ScanLine(block) = chunk.compressed_block else {
                panic!("a scan-line block");
            };
            let mut back = vec![0; n];
            let bytes = block.compressed_pixels_le;
            let got = match inflate.zlib_decompress(&bytes, &mut back) {
                Ok(size) if size == n => back,
                // Stored as it is.
                _ => bytes.clone(),
            };
            assert!(n < 250 || bytes.len() < n, "{n} bytes did not shrink");
            if bytes.len() < n {
                assert_eq!(got, reference(&scratch.raw), "{n} bytes");
            } else {
                assert_eq!(bytes, scratch.raw, "{n} bytes stored");
            }
        }
    }

    #[test]
    fn encoding_refuses_a_channel_of_another_size() {
        let mut image = odd_crop();
        image.channels[1].1 = FlatSamples::F16(vec![f16::ONE; 3]);
        let err = image.encode().unwrap_err();
        assert!(err.contains("channel A"), "{err}");
    }

    #[test]
    fn frames_encode_to_the_bytes_of_their_images() {
        let window = Window {
            x0: 7,
            y0: 3,
            x1: 50,
            y1: 40,
        };
        for (aovs, half) in [
            (AovSet::default(), false),
            (AovSet::all(), false),
            (AovSet::all(), true),
        ] {
            let mut frame = Frame::new(64, 48, window, aovs);
            let mut bits = xorshift(0x9e37_79b9);
            // Spread over many binades, with bits that f16 must round.
            let mut value = move || (bits() % 100_000) as f32 / 997.0 - 3.0;
            let mut vec3 = || glam::Vec3::new(value(), value(), value());
            frame.color.iter_mut().for_each(|p| *p = vec3());
            frame.normal.iter_mut().for_each(|p| *p = vec3());
            frame.albedo.iter_mut().for_each(|p| *p = vec3());
            frame.depth.iter_mut().for_each(|d| *d = vec3().x);
            frame
                .object
                .iter_mut()
                .for_each(|o| *o = vec3().y.abs().floor());
            // One attribute: the crate writes them in hash order.
            let attrs = BTreeMap::from([(format!("{ATTR_PREFIX}spp"), "1".to_string())]);
            let direct = ExrImage::encode_frame(&frame, half, attrs.clone()).unwrap();
            let planes = ExrImage::from_frame(&frame, half, attrs).encode().unwrap();
            assert!(direct == planes, "aovs {aovs:?}, half {half}");
        }
    }

    #[test]
    fn merge_refuses_a_crop_that_holds_another_window_than_it_names() {
        let (left, right) = halves();
        let a = crop(left, &[("crop", "0,0,2,2")]);
        let b = crop(right, &[("crop", "0,0,2,2")]);
        let err = merge_labelled(&[("a.exr".into(), &a), ("b.exr".into(), &b)])
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("b.exr was rendered as the crop 0,0,2,2 but holds the window 2,0,4,2"),
            "{err}"
        );
        let b = crop(right, &[("crop", "2,0,4,2")]);
        assert!(merge(&[a, b]).is_ok());
    }

    #[test]
    fn merge_names_the_input_of_another_soup_tree_texture_filter_or_probe() {
        let (left, right) = halves();
        for key in [
            "soupDigest",
            "treeParams",
            "version",
            "textureFilter",
            "softProbe",
        ] {
            let a = crop(left, &[(key, "1")]);
            let b = crop(right, &[(key, "2")]);
            let err = merge_labelled(&[("a.exr".into(), &a), ("b.exr".into(), &b)])
                .unwrap_err()
                .to_string();
            assert!(
                err.contains(&format!(
                    "b.exr was rendered with {key} \"2\", a.exr with \"1\""
                )),
                "{err}"
            );
        }
    }

    #[test]
    fn ascii_json_escapes_unicode() {
        let v = serde_json::json!({"name": "Lampe à 🌞"});
        let s = ascii_json(&v);
        assert!(s.is_ascii());
        let back: serde_json::Value = serde_json::from_str(&s).unwrap();
        assert_eq!(back, v);
    }
}
