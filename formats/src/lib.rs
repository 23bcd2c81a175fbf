//! The artifacts that join unitrace's pipeline stages.
//!
//! Every artifact is an [`envelope`]: magic, version, payload length, payload checksum,
//! then a bincode payload. The field-by-field specification is in `SOUP.md`, `KD.md` and
//! `RAYS.md` next to this crate, so that programs in other languages can read the files.

pub mod camera;
pub mod envelope;
pub mod error;
pub mod kd;
pub mod rays;
pub mod sky;
pub mod soup;
pub mod srgb;
pub mod texture;
pub mod threads;

pub use camera::{Camera, Frustum, GateFit, Projection};
pub use envelope::write_atomic;
pub use error::FormatError;
pub use kd::{BuildParams, KdFile, KdHeader, KdNode, TreeStats};
pub use rays::{Hit, RayRecord};
pub use sky::{Panorama, ProceduralSky, Sky, SkyImage, SkyLayout, SunDisk, TexturedSky};
pub use soup::{
    Alpha, Ambient, AmbientMode, Attenuation, CastShadows, ClearFlags, ColorSpace, Cull,
    Environment, Fog, FogMode, Light, LightKind, Material, MetallicMap, NormalMap, Object,
    OcclusionMap, ShadowDistance, Shadows, Soup, SoupGeometry, SoupKey,
};
pub use texture::{Texture, TextureRef, Tiling};

/// BLAKE3 digest, used for geometry hashes and payload checksums.
pub type Digest = [u8; 32];

/// Index of the first item of `items` that is `bad` (given its index and itself), if any.
/// Large arrays (a soup's or a tree's millions of entries) are scanned on all cores; the
/// answer is the lowest such index whichever thread finds it.
pub(crate) fn first_bad<T: Sync>(
    items: &[T],
    bad: impl Fn(usize, &T) -> bool + Sync + Send,
) -> Option<usize> {
    use rayon::prelude::*;
    // Whole blocks per task: rayon's per-item short-circuit checks cost more than the
    // checks themselves.
    const BLOCK: usize = 1 << 16;
    let in_block = |b: usize, block: &[T]| {
        let base = b * BLOCK;
        (0..block.len())
            .find(|&j| bad(base + j, &block[j]))
            .map(|j| base + j)
    };
    if items.len() <= BLOCK {
        return in_block(0, items);
    }
    items
        .par_chunks(BLOCK)
        .enumerate()
        .find_map_first(|(b, block)| in_block(b, block))
}

/// Lower-case hex of a digest (what cache file names and headers carry).
pub fn hex(d: &Digest) -> String {
    blake3::Hash::from_bytes(*d).to_hex().to_string()
}
