//! OpenEXR output: RGBA (f32, or f16 with `--half`) plus AOV channels in one single-part
//! scan-line file, the data window set to the rendered crop and the display window to the
//! full image; reading back; and merging crops into the full image.

use crate::{Frame, RenderError, Window};
use exr::block::chunk::{Chunk, CompressedBlock, CompressedScanLineBlock};
use exr::block::writer::ChunksWriter;
use exr::block::UncompressedBlock;
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
        let mut channels: Vec<(String, FlatSamples)> = frame
            .channels()
            .into_iter()
            .map(|(name, plane)| {
                let samples = if half && halvable(name) {
                    FlatSamples::F16(plane.into_iter().map(f16::from_f32).collect())
                } else {
                    FlatSamples::F32(plane)
                };
                (name.to_string(), samples)
            })
            .collect();
        channels.sort_by(|a, b| a.0.cmp(&b.0));
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
        let image = self.exr_image(Encoding::SMALL_LOSSLESS)?;
        let headers = image.write().infer_meta_data();
        let layers = image.layer_data.create_writer(&headers);
        let mut out = Cursor::new(Vec::new());
        exr::block::write(&mut out, headers, true, |meta, writer| {
            let blocks: Vec<_> = meta.enumerate_ordered_header_block_indices().collect();
            let chunks = blocks
                .into_par_iter()
                .map_init(
                    || Compressor::new(CompressionLvl::new(1).expect("level 1 exists")),
                    |deflate, (i, index)| {
                        let raw = layers.extract_uncompressed_block(&meta.headers, index);
                        let block = UncompressedBlock { index, data: raw };
                        zip_chunk(deflate, &meta.headers, block).map(|c| (i, c))
                    },
                )
                .collect::<exr::error::Result<Vec<_>>>()?;
            for (i, chunk) in chunks {
                writer.write_chunk(i, chunk)?;
            }
            Ok(())
        })
        .map_err(|e| e.to_string())?;
        Ok(out.into_inner())
    }

    /// Encode with the `exr` crate's own compressors (what `exrwrite` compares).
    pub fn encode_with(&self, encoding: Encoding) -> std::result::Result<Vec<u8>, String> {
        let mut out = Cursor::new(Vec::new());
        self.exr_image(encoding)?
            .write()
            .to_buffered(&mut out)
            .map_err(|e| e.to_string())?;
        Ok(out.into_inner())
    }

    /// The `exr` crate's image of this one: one layer, its channels and attributes.
    fn exr_image(
        &self,
        encoding: Encoding,
    ) -> std::result::Result<Image<Layer<AnyChannels<FlatSamples>>>, String> {
        let list: SmallVec<[AnyChannel<FlatSamples>; 4]> = self
            .channels
            .iter()
            .map(|(name, s)| {
                let text =
                    Text::new_or_none(name).ok_or(format!("channel name {name:?} is not ASCII"))?;
                Ok(AnyChannel::new(text, s.clone()))
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
        let bytes = self.encode().map_err(|detail| RenderError::ExrWrite {
            path: path.to_path_buf(),
            detail,
        })?;
        formats::write_atomic(path, &bytes)?;
        Ok(())
    }

    pub fn read(path: &Path) -> std::result::Result<Self, RenderError> {
        let err = |detail: String| RenderError::ExrRead {
            path: path.to_path_buf(),
            detail,
        };
        let bytes = std::fs::read(path).map_err(|e| err(e.to_string()))?;
        let image = read()
            .no_deep_data()
            .largest_resolution_level()
            .all_channels()
            .first_valid_layer()
            .all_attributes()
            .from_buffered(Cursor::new(bytes))
            .map_err(|e| err(e.to_string()))?;
        let display = image.attributes.display_window;
        if display.position != Vec2(0, 0) {
            return Err(err(format!(
                "display window starts at {:?}; unitrace images start at (0, 0)",
                display.position
            )));
        }
        let layer = image.layer_data;
        let pos = layer.attributes.layer_position;
        if pos.0 < 0 || pos.1 < 0 {
            return Err(err(format!(
                "data window starts at {pos:?}, outside the image"
            )));
        }
        let window = Window {
            x0: pos.0 as u32,
            y0: pos.1 as u32,
            x1: pos.0 as u32 + layer.size.0 as u32,
            y1: pos.1 as u32 + layer.size.1 as u32,
        };
        let mut attributes = BTreeMap::new();
        let others = image
            .attributes
            .other
            .iter()
            .chain(layer.attributes.other.iter());
        for (k, v) in others {
            if let AttributeValue::Text(t) = v {
                attributes.insert(k.to_string(), t.to_string());
            }
        }
        let channels = layer
            .channel_data
            .list
            .into_iter()
            .map(|c| (c.name.to_string(), c.sample_data))
            .collect();
        Ok(ExrImage {
            width: display.size.0 as u32,
            height: display.size.1 as u32,
            window,
            channels,
            attributes,
        })
    }
}

/// One scan-line block as OpenEXR's ZIP compressor stores it: the block's little-endian
/// bytes split into the even-indexed then the odd-indexed ones, each byte replaced by its
/// difference to the one before plus 128, then zlib; a block that would not shrink is
/// stored as it is, which readers recognise by its size.
fn zip_chunk(
    deflate: &mut Compressor,
    headers: &[Header],
    block: UncompressedBlock,
) -> exr::error::Result<Chunk> {
    if cfg!(target_endian = "big") {
        // The samples must be swapped to little-endian first: leave that to the crate.
        return block.compress_to_chunk(headers);
    }
    let raw = &block.data;
    let n = raw.len();
    let mut split = vec![0u8; n];
    let (evens, odds) = split.split_at_mut(n.div_ceil(2));
    for (i, pair) in raw.chunks(2).enumerate() {
        evens[i] = pair[0];
        if let Some(&b) = pair.get(1) {
            odds[i] = b;
        }
    }
    for i in (1..n).rev() {
        split[i] = split[i].wrapping_sub(split[i - 1]).wrapping_add(128);
    }
    let mut packed = vec![0u8; deflate.zlib_compress_bound(n)];
    // The only failure is a too small buffer, which the bound rules out; it would store
    // the block as it is.
    let size = deflate.zlib_compress(&split, &mut packed).unwrap_or(n);
    packed.truncate(size);
    let header = &headers[block.index.layer];
    let y = block.index.pixel_position.y() as i32 + header.own_attributes.layer_position.y();
    Ok(Chunk {
        layer_index: block.index.layer,
        compressed_block: CompressedBlock::ScanLine(CompressedScanLineBlock {
            y_coordinate: y,
            compressed_pixels_le: if size < n { packed } else { block.data },
        }),
    })
}

/// Attributes that must agree between the crops of one image: the settings that change
/// pixels, the scene (its geometry, and the soup's checksum, which also covers materials,
/// lights and camera), the tree's build parameters and the renderer's version. Crops that
/// differ in any of them may still cover the image without a gap or a disagreeing overlap.
const SAME_RENDER: [&str; 10] = [
    "spp",
    "depth",
    "seed",
    "geometryHash",
    "softSamples",
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
                return Err(bad(format!(
                    "{label} was rendered with {key} {:?}, {first_label} with {:?}: \
                     they are not crops of one render",
                    p.attributes.get(&k),
                    first.attributes.get(&k)
                )));
            }
        }
    }
    let (w, h) = (first.width as usize, first.height as usize);
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
mod tests {
    use super::*;

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

    /// A 50×40 crop at (3, 37) of a 60×90 image: three blocks of 16 lines, the last one
    /// short. `noise` fills every channel with random bits, which deflate cannot shrink.
    fn encodable(noise: bool) -> ExrImage {
        let window = Window {
            x0: 3,
            y0: 37,
            x1: 53,
            y1: 77,
        };
        let n = window.pixels() as usize;
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut bits = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state as u32
        };
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
                let bits = |s: &FlatSamples| -> Vec<u32> {
                    match s {
                        FlatSamples::F16(v) => v.iter().map(|h| h.to_bits() as u32).collect(),
                        FlatSamples::F32(v) => v.iter().map(|f| f.to_bits()).collect(),
                        FlatSamples::U32(v) => v.clone(),
                    }
                };
                assert_eq!(bits(ours), bits(theirs), "channel {name}, noise {noise}");
            }
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
    fn merge_names_the_input_of_another_soup_tree_or_texture_filter() {
        let (left, right) = halves();
        for key in ["soupDigest", "treeParams", "version", "textureFilter"] {
            let a = crop(left, &[(key, "1")]);
            let b = crop(right, &[(key, "2")]);
            let err = merge_labelled(&[("a.exr".into(), &a), ("b.exr".into(), &b)])
                .unwrap_err()
                .to_string();
            assert!(
                err.contains("b.exr was rendered with") && err.contains(key),
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
