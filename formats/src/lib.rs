//! The artifacts that join unitrace's pipeline stages.
//!
//! Every artifact is an [`envelope`]: magic, version, payload length, payload checksum,
//! then a bincode payload. The field-by-field specification is in `SOUP.md`, `KD.md` and
//! `RAYS.md` next to this crate, so that programs in other languages can read the files.

pub mod envelope;
pub mod error;
pub mod kd;
pub mod rays;
pub mod soup;
pub mod srgb;
pub mod texture;

pub use envelope::write_atomic;
pub use error::FormatError;
pub use kd::{BuildParams, KdFile, KdNode, TreeStats};
pub use rays::{Hit, RayRecord};
pub use soup::{
    Alpha, Ambient, AmbientMode, Camera, CastShadows, ClearFlags, Cull, Environment, Light,
    LightKind, Material, Object, Projection, Shadows, Soup,
};
pub use texture::{Texture, TextureRef, Tiling};

/// BLAKE3 digest, used for geometry hashes and payload checksums.
pub type Digest = [u8; 32];

/// Lower-case hex of a digest (what cache file names and headers carry).
pub fn hex(d: &Digest) -> String {
    blake3::Hash::from_bytes(*d).to_hex().to_string()
}
