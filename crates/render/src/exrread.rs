//! Reading OpenEXR files back, for `kd2exr merge` and the tools that compare images: the
//! header is checked before any pixel is read or any plane allocated, because a crop is a
//! file anybody may hand in, and the `exr` crate sizes its buffers by what a header says.

use crate::exrio::{ExrImage, ATTR_PREFIX};
use crate::{memory, RenderError, Window};
use exr::block::reader::ChunksReader;
use exr::block::UncompressedBlock;
use exr::meta::header::Header;
use exr::prelude::*;
use std::collections::BTreeMap;
use std::io::Cursor;
use std::path::Path;

impl ExrImage {
    /// Read an EXR file: one part of flat samples (not deep), its full-resolution level.
    /// The header is checked before any pixel is read or any plane allocated: the display
    /// window must start at (0, 0) with edges of at most [`MAX_EDGE`](crate::options::MAX_EDGE)
    /// pixels and hold the data window; the file must be large enough for the blocks its
    /// header describes; and the data window's planes must fit in the memory available.
    /// Every block of the data window must then be in the file exactly once: a damaged
    /// offset table that names one block twice would otherwise leave another as zeros.
    pub fn read(path: &Path) -> std::result::Result<Self, RenderError> {
        Self::decode_with(&file_bytes(path)?, path, |_, _| Ok(()))
    }

    /// [`ExrImage::read`] of a crop for `kd2exr merge`, which also refuses, before any
    /// pixel is read, a file kd2exr did not write (no `unitrace.version` attribute) and one
    /// stored with a lossy compression (re-encoded since: its pixels are no longer the
    /// rendered ones, and merging promises the pixels of a one-shot render).
    pub fn read_crop(path: &Path) -> std::result::Result<Self, RenderError> {
        Self::decode_with(&file_bytes(path)?, path, |header, attributes| {
            let name = path.display();
            if !attributes.contains_key(&format!("{ATTR_PREFIX}version")) {
                return Err(RenderError::Merge(format!(
                    "{name} was not written by kd2exr (it has no {ATTR_PREFIX}version \
                     attribute): merge joins the crops of one kd2exr render"
                )));
            }
            if header.compression.may_loose_data() {
                return Err(RenderError::Merge(format!(
                    "{name} is stored with {}, which is lossy: kd2exr writes lossless ZIP, \
                     so the crop was re-encoded and its pixels are not the rendered ones",
                    header.compression
                )));
            }
            Ok(())
        })
    }

    /// Decode the bytes of an EXR file as [`ExrImage::read`] does, errors naming `path`,
    /// with `check` run on the header and its text attributes before any pixel is read.
    fn decode_with(
        bytes: &[u8],
        path: &Path,
        check: impl FnOnce(&Header, &BTreeMap<String, String>) -> std::result::Result<(), RenderError>,
    ) -> std::result::Result<Self, RenderError> {
        let err = |detail: String| RenderError::ExrRead {
            path: path.to_path_buf(),
            detail,
        };
        if bytes.is_empty() {
            return Err(err("the file is empty (0 bytes)".into()));
        }
        if bytes.len() < EXR_MAGIC.len() && EXR_MAGIC.starts_with(bytes) {
            return Err(err(format!(
                "truncated: {} bytes, the start of an OpenEXR file",
                bytes.len()
            )));
        }
        if !bytes.starts_with(&EXR_MAGIC) {
            return Err(err(format!(
                "not an OpenEXR file (its first bytes are \"{}\")",
                bytes[..bytes.len().min(8)].escape_ascii()
            )));
        }
        let reader = exr::block::read(Cursor::new(bytes), false).map_err(|e| err(exr_error(e)))?;
        let headers = reader.headers();
        if headers.len() != 1 {
            return Err(err(format!(
                "holds {} parts; only single-part images are read (kd2exr writes one part)",
                headers.len()
            )));
        }
        let header = headers[0].clone();
        if header.deep {
            return Err(err(
                "holds deep data (any number of samples per pixel); only flat images are read"
                    .into(),
            ));
        }
        let mut attributes = BTreeMap::new();
        let others = header
            .shared_attributes
            .other
            .iter()
            .chain(header.own_attributes.other.iter());
        for (k, v) in others {
            if let AttributeValue::Text(t) = v {
                attributes.insert(k.to_string(), t.to_string());
            }
        }
        check(&header, &attributes)?;

        let display = header.shared_attributes.display_window;
        if display.position != Vec2(0, 0) {
            return Err(err(format!(
                "display window starts at ({}, {}); unitrace images start at (0, 0)",
                display.position.0, display.position.1
            )));
        }
        let pos = header.own_attributes.layer_position;
        if pos.0 < 0 || pos.1 < 0 {
            return Err(err(format!(
                "data window starts at ({}, {}), outside the image",
                pos.0, pos.1
            )));
        }
        let (width, height) = (display.size.0 as u64, display.size.1 as u64);
        let max = crate::options::MAX_EDGE as u64;
        if width > max || height > max {
            return Err(err(format!(
                "display window {width}×{height}: edges above {max} pixels are not supported"
            )));
        }
        let size = header.layer_size;
        let (x1, y1) = (pos.0 as u64 + size.0 as u64, pos.1 as u64 + size.1 as u64);
        // Merging places each crop's pixels by its data window: one reaching past the
        // image would write outside it.
        if x1 > width || y1 > height {
            return Err(err(format!(
                "the {}×{} data window at ({}, {}) reaches past the {width}×{height} image",
                size.0, size.1, pos.0, pos.1
            )));
        }
        if let Some(c) = header
            .channels
            .list
            .iter()
            .find(|c| c.sampling != Vec2(1, 1))
        {
            return Err(err(format!(
                "channel {} is subsampled ({}×{}); only channels with a sample per pixel are \
                 read",
                c.name, c.sampling.0, c.sampling.1
            )));
        }
        // Each block has an 8-byte entry in the offset table and at least 8 bytes of its
        // own: a header describing more blocks than that is of a truncated or forged file.
        let blocks = header.chunk_count as u64;
        if blocks.saturating_mul(16) > bytes.len() as u64 {
            return Err(err(format!(
                "truncated or damaged: the header describes {blocks} blocks of pixels, which \
                 take at least {} bytes; the file has {}",
                blocks.saturating_mul(16),
                bytes.len()
            )));
        }
        let pixels = size.0 as u64 * size.1 as u64;
        let per_pixel: u64 = header
            .channels
            .list
            .iter()
            .map(|c| c.sample_type.bytes_per_sample() as u64)
            .sum();
        // The planes, the file, and the blocks being decompressed at once (each thread's
        // and two waiting), each decompressed into a buffer of its full size.
        let Vec2(bw, bh) = header.max_block_pixel_size();
        let block_bytes = (bw.min(size.0) as u64 * bh.min(size.1) as u64).saturating_mul(per_pixel);
        let threads = std::thread::available_parallelism().map_or(1, |n| n.get()) as u64;
        let in_flight = blocks.min(threads + 2);
        let need = pixels
            .saturating_mul(per_pixel)
            .saturating_add(block_bytes.saturating_mul(in_flight))
            .saturating_add(bytes.len() as u64);
        if let Some((need, avail)) = memory::short_of(need, memory::available_bytes()) {
            return Err(err(format!(
                "its {}×{} data window with {} channels needs about {need:.1} GiB to read, \
                 only {avail:.1} GiB of memory is available",
                size.0,
                size.1,
                header.channels.list.len(),
            )));
        }

        let n = pixels as usize;
        let mut planes: Vec<FlatSamples> = header
            .channels
            .list
            .iter()
            .map(|c| match c.sample_type {
                SampleType::F16 => FlatSamples::F16(vec![f16::ZERO; n]),
                SampleType::F32 => FlatSamples::F32(vec![0.0; n]),
                SampleType::U32 => FlatSamples::U32(vec![0; n]),
            })
            .collect();
        let mut grid = BlockGrid::new(&header);
        let mut problem = None;
        let decoded = reader
            .filter_chunks(false, |_, tile, _| tile.level_index == Vec2(0, 0))
            .and_then(|chunks| {
                chunks.decompress_parallel(false, |_, block| {
                    grid.place(&header, &block, &mut planes).map_err(|p| {
                        problem = Some(p);
                        exr::error::Error::Aborted
                    })
                })
            });
        if let Some(p) = problem {
            return Err(err(p));
        }
        decoded.map_err(|e| err(exr_error(e)))?;
        if let Some((x, y)) = grid.first_missing() {
            return Err(err(format!(
                "damaged: the block of pixels at ({x}, {y}) is not in the file (the offset \
                 table does not lead to it)"
            )));
        }
        let window = Window {
            x0: pos.0 as u32,
            y0: pos.1 as u32,
            x1: x1 as u32,
            y1: y1 as u32,
        };
        let channels = header
            .channels
            .list
            .iter()
            .map(|c| c.name.to_string())
            .zip(planes)
            .collect();
        Ok(ExrImage {
            width: width as u32,
            height: height as u32,
            window,
            channels,
            attributes,
        })
    }
}

/// The first bytes of every OpenEXR file.
const EXR_MAGIC: [u8; 4] = [0x76, 0x2f, 0x31, 0x01];

/// The bytes of the file at `path`, refusing before reading what is not a regular file
/// (a FIFO or a device such as /dev/zero would block or never end) and a file larger than
/// the memory available.
fn file_bytes(path: &Path) -> std::result::Result<Vec<u8>, RenderError> {
    let err = |detail: String| RenderError::ExrRead {
        path: path.to_path_buf(),
        detail,
    };
    let meta = std::fs::metadata(path).map_err(|e| err(e.to_string()))?;
    if meta.is_dir() {
        return Err(err("is a folder, not an EXR file".into()));
    }
    if !meta.is_file() {
        return Err(err(
            "is not a regular file (a pipe, socket or device); only EXR files are read".into(),
        ));
    }
    if let Some((size, avail)) = memory::short_of(meta.len(), memory::available_bytes()) {
        return Err(err(format!(
            "the file holds {size:.1} GiB, more than the {avail:.1} GiB of memory available"
        )));
    }
    std::fs::read(path).map_err(|e| err(e.to_string()))
}

/// The `exr` crate's error as a sentence about the file.
fn exr_error(e: exr::error::Error) -> String {
    use exr::error::Error as E;
    match e {
        E::Invalid(m) if m == "reference to missing bytes" => {
            "truncated or damaged: the file ends before data its header or offset table \
             points to"
                .into()
        }
        E::Invalid(m) => format!("damaged or not a valid EXR file: {m}"),
        E::NotSupported(m) => format!("uses an OpenEXR feature this reader does not support: {m}"),
        E::Io(e) => e.to_string(),
        E::Aborted => "reading was stopped".into(),
    }
}

/// Which blocks of the full-resolution level have been read: each must be once.
struct BlockGrid {
    /// A block's size in pixels (the last ones in a row or column may be smaller).
    block: (usize, usize),
    /// The data window's size in pixels.
    size: (usize, usize),
    /// Where the data window starts in the image: errors name image positions.
    origin: (usize, usize),
    columns: usize,
    seen: Vec<bool>,
}

impl BlockGrid {
    fn new(header: &Header) -> Self {
        let Vec2(bw, bh) = header.max_block_pixel_size();
        let block = (bw.max(1), bh.max(1));
        let size = (header.layer_size.0, header.layer_size.1);
        let Vec2(ox, oy) = header.own_attributes.layer_position;
        let origin = (ox.max(0) as usize, oy.max(0) as usize);
        let columns = size.0.div_ceil(block.0);
        // At most the header's block count, which the file's size has bounded.
        let seen = vec![false; columns * size.1.div_ceil(block.1)];
        BlockGrid {
            block,
            size,
            origin,
            columns,
            seen,
        }
    }

    /// Copy `block`'s samples into `planes` (the header's channels, each a plane of the
    /// data window), marking it read; Err when it is outside the data window, read before
    /// or of another size than its place.
    fn place(
        &mut self,
        header: &Header,
        block: &UncompressedBlock,
        planes: &mut [FlatSamples],
    ) -> std::result::Result<(), String> {
        let Vec2(x, y) = block.index.pixel_position;
        let Vec2(w, h) = block.index.pixel_size;
        // The block's top left corner in the image, for the messages.
        let (ix, iy) = (
            x.saturating_add(self.origin.0),
            y.saturating_add(self.origin.1),
        );
        let inside = x % self.block.0 == 0
            && y % self.block.1 == 0
            && x.saturating_add(w) <= self.size.0
            && y.saturating_add(h) <= self.size.1;
        let misfit = || {
            format!(
                "damaged: a {w}×{h} block at ({ix}, {iy}) does not fit the data window's blocks"
            )
        };
        if !inside {
            return Err(misfit());
        }
        let cell = (y / self.block.1) * self.columns + x / self.block.0;
        match self.seen.get_mut(cell) {
            Some(seen) if !*seen => *seen = true,
            Some(_) => {
                return Err(format!(
                    "damaged: the file holds the block of pixels at ({ix}, {iy}) twice"
                ))
            }
            None => return Err(misfit()),
        }
        let expected = header.channels.bytes_per_pixel * w * h;
        if block.data.len() != expected {
            return Err(format!(
                "damaged: the block at ({ix}, {iy}) holds {} bytes of samples, not {expected}",
                block.data.len()
            ));
        }
        let width = self.size.0;
        for line in block.lines(&header.channels) {
            let Vec2(lx, ly) = line.location.position;
            let at = ly * width + lx;
            let range = at..at + line.location.sample_count;
            let read = match planes.get_mut(line.location.channel) {
                Some(FlatSamples::F16(v)) => {
                    v.get_mut(range).map(|s| line.read_samples_into_slice(s))
                }
                Some(FlatSamples::F32(v)) => {
                    v.get_mut(range).map(|s| line.read_samples_into_slice(s))
                }
                Some(FlatSamples::U32(v)) => {
                    v.get_mut(range).map(|s| line.read_samples_into_slice(s))
                }
                None => None,
            };
            match read {
                Some(Ok(())) => {}
                Some(Err(e)) => return Err(exr_error(e)),
                None => {
                    return Err(format!(
                        "damaged: a line of the block at ({ix}, {iy}) lies outside the data \
                         window"
                    ))
                }
            }
        }
        Ok(())
    }

    /// The image position of the first block not read, if any.
    fn first_missing(&self) -> Option<(usize, usize)> {
        let i = self.seen.iter().position(|s| !s)?;
        Some((
            self.origin.0 + i % self.columns * self.block.0,
            self.origin.1 + i / self.columns * self.block.1,
        ))
    }
}
#[cfg(test)]
mod tests {
    use super::*;
    use crate::exrio::tests::{encodable, foreign_exr};

    fn decode(bytes: &[u8], path: &Path) -> std::result::Result<ExrImage, RenderError> {
        ExrImage::decode_with(bytes, path, |_, _| Ok(()))
    }

    /// Where an EXR file's header ends (after its terminating NUL): the offset table follows.
    fn header_end(bytes: &[u8]) -> usize {
        let mut at = 8;
        while bytes[at] != 0 {
            let nul = |from: usize| from + bytes[from..].iter().position(|&b| b == 0).unwrap();
            let type_end = nul(nul(at) + 1);
            let size = i32::from_le_bytes(bytes[type_end + 1..type_end + 5].try_into().unwrap());
            at = type_end + 5 + size as usize;
        }
        at + 1
    }

    /// `bytes` with the attribute `name` of type `kind` set to `values`.
    fn with_ints(mut bytes: Vec<u8>, name: &str, kind: &str, values: &[i32]) -> Vec<u8> {
        let key = format!("{name}\0{kind}\0");
        let at = bytes
            .windows(key.len())
            .position(|w| w == key.as_bytes())
            .unwrap()
            + key.len()
            + 4;
        for (i, v) in values.iter().enumerate() {
            bytes[at + 4 * i..at + 4 * i + 4].copy_from_slice(&v.to_le_bytes());
        }
        bytes
    }

    #[test]
    fn headers_describing_more_than_the_file_or_memory_holds_are_refused_before_reading() {
        // The 50×40 crop's header made to describe a 2²⁰-pixel square (the largest edge):
        // 65,536 blocks of 16 lines, 10 TiB of samples. Both aborted the process on the
        // allocation of the samples.
        let bytes = encodable(false).encode().unwrap();
        let end = header_end(&bytes);
        let edge = [0, 0, (1 << 20) - 1, (1 << 20) - 1];
        let huge = with_ints(bytes, "dataWindow", "box2i", &edge);
        let huge = with_ints(huge, "displayWindow", "box2i", &edge);
        let mut huge = with_ints(huge, "chunkCount", "int", &[1 << 16]);
        huge.truncate(end);
        let path = Path::new("huge.exr");
        let err = decode(&huge, path).unwrap_err().to_string();
        assert!(
            err.contains("huge.exr")
                && err.contains("the header describes 65536 blocks of pixels, which take at least 1048576 bytes"),
            "{err}"
        );
        // Long enough for its blocks: refused by the memory its planes would take.
        huge.resize(1 << 20, 0);
        let err = decode(&huge, path).unwrap_err().to_string();
        assert!(
            err.contains("its 1048576×1048576 data window with 3 channels needs about 102")
                && err.contains("GiB to read"),
            "{err}"
        );
    }

    #[test]
    fn an_offset_table_leading_to_one_block_twice_is_refused() {
        // Three blocks; the second's entry made to lead to the first. The block it no longer
        // leads to was left as zeros.
        let image = encodable(false);
        let bytes = image.encode().unwrap();
        let end = header_end(&bytes);
        let mut twice = bytes.clone();
        twice.copy_within(end..end + 8, end + 8);
        let err = decode(&twice, Path::new("twice.exr"))
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("twice.exr") && err.contains("holds the block of pixels at (3, 37) twice"),
            "{err}"
        );
        // The table in another order leads to every block once: the image is the same.
        let mut swapped = bytes;
        let table = &mut swapped[end..end + 24];
        let entries: Vec<[u8; 8]> = table.chunks(8).map(|e| e.try_into().unwrap()).collect();
        for (slot, from) in table.chunks_mut(8).zip([2, 0, 1]) {
            slot.copy_from_slice(&entries[from]);
        }
        let back = decode(&swapped, Path::new("swapped.exr")).unwrap();
        assert_eq!(back.channels, image.channels);
    }

    #[test]
    fn merge_reads_only_what_kd2exr_wrote() {
        let dir = tempfile::tempdir().unwrap();
        let foreign = dir.path().join("foreign.exr");
        foreign_exr(&foreign, (4, 4), (4, 4));
        assert!(ExrImage::read(&foreign).is_ok());
        let err = ExrImage::read_crop(&foreign).unwrap_err().to_string();
        assert!(
            err.contains("foreign.exr was not written by kd2exr (it has no unitrace.version"),
            "{err}"
        );
        let mut image = encodable(false);
        image
            .attributes
            .insert(format!("{ATTR_PREFIX}version"), "0.1.0".into());
        let lossy = dir.path().join("lossy.exr");
        let encoding = Encoding {
            compression: Compression::PXR24,
            ..Encoding::SMALL_LOSSLESS
        };
        std::fs::write(&lossy, image.encode_with(encoding).unwrap()).unwrap();
        let err = ExrImage::read_crop(&lossy).unwrap_err().to_string();
        assert!(
            err.contains("lossy.exr is stored with pxr24 compression, which is lossy"),
            "{err}"
        );
        let ours = dir.path().join("ours.exr");
        image.write(&ours).unwrap();
        assert_eq!(ExrImage::read_crop(&ours).unwrap(), image);
    }
}
