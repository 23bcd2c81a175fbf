//! The compiled k-d tree. Its content depends only on the soup's triangle positions and
//! the build parameters, so it is cached by `<geometry hash>-<params hash>.kd`.

use crate::{envelope, Digest, FormatError};
use glam::Vec3;
use serde::{Deserialize, Serialize};
use std::path::Path;

pub const MAGIC: &[u8; 8] = b"UTKD\0\0\0\0";
pub const VERSION: u32 = 1;

/// SAH build parameters. They change the tree, so they are part of the cache key.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct BuildParams {
    /// Cost of one traversal step, relative to `intersect_cost`. Default 5 (with 1.5 per
    /// triangle): our node steps, each a dependent load and an unpredictable branch, cost
    /// more than a (four-wide) triangle test. Swept with the empty bonus over eleven
    /// scenes: fewer, fuller leaves keep every scene under 58 bytes per triangle and the
    /// build fast, and rays got faster, not slower (docs/PERFORMANCE.md).
    pub traversal_cost: f32,
    /// Cost of one ray/triangle test.
    pub intersect_cost: f32,
    /// Fraction of the SAH cost forgiven when a split cuts off empty space (0–1): the cost
    /// is multiplied by 1 − empty_bonus. Default 0.1 (Wald & Havran's λ = 0.8 is 0.2 here,
    /// pbrt-v3's 0.5): a larger bonus cuts empty slivers off thin surface cells, each a
    /// step every ray through them pays (docs/PERFORMANCE.md has the sweep).
    pub empty_bonus: f32,
    /// Depth bound; 0 means the default 8 + 1.3·log2(N).
    pub max_depth: u32,
    /// Make a leaf without trying to split at or below this many triangles.
    pub leaf_size: u32,
}

impl Default for BuildParams {
    fn default() -> Self {
        BuildParams {
            traversal_cost: 5.0,
            intersect_cost: 1.5,
            empty_bonus: 0.1,
            max_depth: 0,
            leaf_size: 1,
        }
    }
}

impl BuildParams {
    /// First 8 bytes (16 hex digits) of BLAKE3 over the parameters' encoding: the second
    /// half of a cache file name.
    pub fn short_hash(&self) -> String {
        let mut h = blake3::Hasher::new();
        h.update(&VERSION.to_le_bytes());
        h.update(&self.traversal_cost.to_le_bytes());
        h.update(&self.intersect_cost.to_le_bytes());
        h.update(&self.empty_bonus.to_le_bytes());
        h.update(&self.max_depth.to_le_bytes());
        h.update(&self.leaf_size.to_le_bytes());
        h.finalize().to_hex()[..16].to_string()
    }

    /// Cache file name for a soup with this geometry hash.
    pub fn cache_name(&self, geometry_hash: &Digest) -> String {
        format!("{}-{}.kd", crate::hex(geometry_hash), self.short_hash())
    }
}

/// Statistics measured on the built tree.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct TreeStats {
    pub triangles: u64,
    pub nodes: u64,
    pub leaves: u64,
    pub empty_leaves: u64,
    pub max_depth: u32,
    /// Triangle references in leaves (a triangle straddling a split is counted per leaf).
    pub references: u64,
    pub max_leaf_triangles: u32,
    /// Expected cost of a random ray, in units of `intersect_cost` (SAH).
    pub sah_cost: f64,
    pub build_seconds: f64,
}

/// One 8-byte node, laid out as in pbrt-v3's KdTreeAccel.
///
/// * `flags & 3` is 0, 1, 2 for an interior node split on x, y, z, and 3 for a leaf.
/// * Interior: `data` is the split coordinate (f32 bits); `flags >> 2` is the index of
///   the child above the split; the child below is the next node in the array.
/// * Leaf: `flags >> 2` is the number of triangles; `data` is the offset of its first
///   triangle index in [`KdFile::leaf_tris`].
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, bytemuck::Pod, bytemuck::Zeroable,
)]
#[repr(C)]
pub struct KdNode {
    pub flags: u32,
    pub data: u32,
}

impl KdNode {
    pub const LEAF: u32 = 3;

    pub fn interior(axis: u32, split: f32, above: u32) -> Self {
        debug_assert!(axis < 3 && above < (1 << 30));
        KdNode {
            flags: axis | (above << 2),
            data: split.to_bits(),
        }
    }
    pub fn leaf(count: u32, offset: u32) -> Self {
        debug_assert!(count < (1 << 30));
        KdNode {
            flags: Self::LEAF | (count << 2),
            data: offset,
        }
    }
    #[inline]
    pub fn is_leaf(self) -> bool {
        self.flags & 3 == Self::LEAF
    }
    #[inline]
    pub fn axis(self) -> usize {
        (self.flags & 3) as usize
    }
    #[inline]
    pub fn split(self) -> f32 {
        f32::from_bits(self.data)
    }
    #[inline]
    pub fn above_child(self) -> u32 {
        self.flags >> 2
    }
    #[inline]
    pub fn count(self) -> u32 {
        self.flags >> 2
    }
    #[inline]
    pub fn offset(self) -> u32 {
        self.data
    }
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct KdFile {
    /// The soup geometry this tree was built from; the renderer refuses any other soup.
    pub geometry_hash: Digest,
    pub params: BuildParams,
    pub stats: TreeStats,
    /// Bounds of all triangles: [min, max].
    pub bounds: [Vec3; 2],
    /// Node 0 is the root.
    pub nodes: Vec<KdNode>,
    /// Triangle indices (soup order) of all leaves, each leaf's run contiguous.
    pub leaf_tris: Vec<u32>,
}

/// A tree file's fields before its nodes ([`KdFile::read_header`]).
#[derive(Clone, Debug, PartialEq)]
pub struct KdHeader {
    pub geometry_hash: Digest,
    pub params: BuildParams,
    pub stats: TreeStats,
    pub bounds: [Vec3; 2],
}

impl KdHeader {
    fn read(r: &mut envelope::PayloadReader) -> Result<KdHeader, String> {
        let (geometry_hash, params, stats, bounds) = r.value("the header fields")?;
        Ok(KdHeader {
            geometry_hash,
            params,
            stats,
            bounds,
        })
    }
}

impl envelope::Checked<KdFile> {
    /// The tree's [`KdHeader`], without decoding or checking its nodes and lists
    /// ([`KdFile::read`] does).
    pub fn header(&self) -> Result<KdHeader, FormatError> {
        self.read(KdHeader::read)
    }
}

/// Where [`KdFile::height`] stops counting.
pub const HEIGHT_CAP: u32 = u8::MAX as u32;

impl KdFile {
    /// Levels of interior nodes above the deepest leaf (0 for a lone leaf). Call it on a
    /// validated tree: children always follow their parent, so one pass from the back
    /// computes it, even for a file whose nodes share children.
    ///
    /// Heights of [`HEIGHT_CAP`] and more are all reported as [`HEIGHT_CAP`]: no tree that
    /// deep can be traversed, and a byte per node is a quarter of the fresh memory (on a
    /// tree of 10 million triangles, 0.03 s of loading).
    pub fn height(&self) -> u32 {
        let mut height = vec![0u8; self.nodes.len()];
        for i in (0..self.nodes.len()).rev() {
            let n = self.nodes[i];
            if !n.is_leaf() {
                let below = height[i + 1].max(height[n.above_child() as usize]);
                height[i] = below.saturating_add(1);
            }
        }
        height.first().map_or(0, |&h| u32::from(h))
    }

    /// Check that every node reference stays inside the arrays, naming the first bad one.
    pub fn validate(&self) -> Result<(), String> {
        let n = self.nodes.len();
        if n == 0 {
            return Err("the tree has no nodes".into());
        }
        let list = self.leaf_tris.len() as u64;
        let bad = |i: usize, node: &KdNode| {
            if node.is_leaf() {
                node.offset() as u64 + node.count() as u64 > list
            } else {
                let above = node.above_child() as usize;
                above <= i + 1 || above >= n || i + 1 >= n
            }
        };
        if let Some(i) = crate::first_bad(&self.nodes, bad) {
            let node = self.nodes[i];
            return Err(if node.is_leaf() {
                format!("leaf {i} reaches past the triangle list")
            } else {
                format!("node {i} points at child {} of {n}", node.above_child())
            });
        }
        if let Some(t) = crate::first_bad(&self.leaf_tris, |_, &t| t as u64 >= self.stats.triangles)
            .map(|i| self.leaf_tris[i])
        {
            return Err(format!(
                "leaf triangle {t} is out of range ({} triangles)",
                self.stats.triangles
            ));
        }
        Ok(())
    }

    pub fn to_bytes(&self, path: &Path) -> Result<Vec<u8>, FormatError> {
        envelope::encode(self, path)
    }

    /// The leading fields of the tree at `path`, the whole payload's checksum verified,
    /// without decoding or checking its nodes and lists ([`KdFile::read`] does).
    pub fn read_header(path: &Path) -> Result<KdHeader, FormatError> {
        envelope::Checked::<KdFile>::open(path)?.header()
    }

    pub fn from_bytes(bytes: &[u8], path: &Path) -> Result<Self, FormatError> {
        envelope::decode(bytes, path)
    }

    /// Write atomically (temp file + rename), the bytes of [`KdFile::to_bytes`] streamed.
    pub fn write(&self, path: &Path) -> Result<(), FormatError> {
        envelope::write(self, path)
    }

    pub fn read(path: &Path) -> Result<Self, FormatError> {
        Self::from_bytes(&envelope::read_file(path)?, path)
    }
}

/// The fields in the order of KD.md (the order of the struct, so the bytes are those of its
/// serde encoding), nodes and leaf lists as blocks.
impl envelope::Artifact for KdFile {
    const MAGIC: &'static [u8; 8] = MAGIC;
    const VERSION: u32 = VERSION;
    const KIND: &'static str = "k-d tree";

    fn write_payload<W: std::io::Write + Send>(
        &self,
        p: &mut envelope::PayloadWriter<W>,
    ) -> Result<(), FormatError> {
        p.value(&(&self.geometry_hash, &self.params, &self.stats, &self.bounds))?;
        p.array(&self.nodes)?;
        p.array(&self.leaf_tris)
    }

    fn read_payload(r: &mut envelope::PayloadReader) -> Result<Self, String> {
        let KdHeader {
            geometry_hash,
            params,
            stats,
            bounds,
        } = KdHeader::read(r)?;
        Ok(KdFile {
            geometry_hash,
            params,
            stats,
            bounds,
            nodes: r.array("nodes")?,
            leaf_tris: r.array("leaf_tris")?,
        })
    }

    fn validate(&self) -> Result<(), String> {
        KdFile::validate(self)
    }
}
