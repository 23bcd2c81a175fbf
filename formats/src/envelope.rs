//! The common frame of the soup and k-d tree artifacts.
//!
//! ```text
//! offset  size  field
//! 0       8     magic ("UTSOUP\0\0" or "UTKD\0\0\0\0")
//! 8       4     format version, u32 little-endian
//! 12      8     payload length in bytes, u64 little-endian
//! 20      32    BLAKE3 of the payload
//! 52      n     payload: bincode 2 (serde route), fixed-width little-endian integers
//! ```
//!
//! The reader checks magic, version, length and checksum before decoding anything, so a
//! truncated, foreign, old or bit-flipped file is an error that names the file, and no
//! length field inside the payload is trusted before the bytes behind it are known good.

use crate::FormatError;
use serde::{de::DeserializeOwned, Serialize};
use std::io::Write;
use std::path::Path;

pub const HEADER_LEN: usize = 52;

/// bincode configuration of every payload: little-endian, fixed-width integers (so the
/// layout documented in SOUP.md / KD.md is simple to read from any language).
fn config() -> bincode::config::Configuration<bincode::config::LittleEndian, bincode::config::Fixint>
{
    bincode::config::standard()
        .with_little_endian()
        .with_fixed_int_encoding()
}

/// Serialise `value` as an artifact with the given magic and version.
pub fn encode<T: Serialize>(
    value: &T,
    magic: &[u8; 8],
    version: u32,
    path: &Path,
) -> Result<Vec<u8>, FormatError> {
    let payload =
        bincode::serde::encode_to_vec(value, config()).map_err(|e| FormatError::Encode {
            path: path.to_path_buf(),
            detail: e.to_string(),
        })?;
    let mut out = Vec::with_capacity(HEADER_LEN + payload.len());
    out.extend_from_slice(magic);
    out.extend_from_slice(&version.to_le_bytes());
    out.extend_from_slice(&(payload.len() as u64).to_le_bytes());
    out.extend_from_slice(blake3::hash(&payload).as_bytes());
    out.extend_from_slice(&payload);
    Ok(out)
}

/// Validate the frame of `bytes` (read from `path`) and decode its payload.
pub fn decode<T: DeserializeOwned>(
    bytes: &[u8],
    magic: &[u8; 8],
    kind: &'static str,
    version: u32,
    path: &Path,
) -> Result<T, FormatError> {
    let p = || path.to_path_buf();
    if bytes.len() < 8 || &bytes[..8] != magic {
        if bytes.is_empty() {
            return Err(FormatError::Truncated {
                path: p(),
                detail: "the file is empty".into(),
            });
        }
        let n = bytes.len().min(8);
        return Err(FormatError::Magic {
            path: p(),
            expected: kind,
            found: String::from_utf8_lossy(&bytes[..n]).into_owned(),
        });
    }
    if bytes.len() < HEADER_LEN {
        return Err(FormatError::Truncated {
            path: p(),
            detail: format!("{} bytes, the header alone is {HEADER_LEN}", bytes.len()),
        });
    }
    let found = u32::from_le_bytes(bytes[8..12].try_into().expect("4 bytes"));
    if found != version {
        return Err(FormatError::Version {
            path: p(),
            kind,
            found,
            supported: version,
        });
    }
    let len = u64::from_le_bytes(bytes[12..20].try_into().expect("8 bytes"));
    let have = (bytes.len() - HEADER_LEN) as u64;
    if len > have {
        return Err(FormatError::Truncated {
            path: p(),
            detail: format!("header promises {len} payload bytes, the file holds {have}"),
        });
    }
    if len < have {
        return Err(FormatError::Corrupt {
            path: p(),
            detail: format!(
                "{} stray bytes after the payload (offset {})",
                have - len,
                HEADER_LEN as u64 + len
            ),
        });
    }
    let payload = &bytes[HEADER_LEN..];
    if blake3::hash(payload).as_bytes() != &bytes[20..52] {
        return Err(FormatError::Corrupt {
            path: p(),
            detail: "payload checksum mismatch (bytes changed after writing)".into(),
        });
    }
    let (value, used) = decode_payload(payload).map_err(|e| FormatError::Corrupt {
        path: p(),
        detail: format!("payload does not decode: {e}"),
    })?;
    if used != payload.len() {
        return Err(FormatError::Corrupt {
            path: p(),
            detail: format!("payload decoded from {used} of {} bytes", payload.len()),
        });
    }
    Ok(value)
}

/// Decode a payload with a byte limit no smaller than the payload and at most 4× it.
///
/// bincode allocates a string's bytes (`vec![0; len]`) before reading them, trusting the
/// length field; only a configured limit makes it check the length first. Without one a
/// well-framed payload whose string length reads 2·10¹⁸ aborted the process on the
/// allocation (found by `cargo fuzz run soup`). The limit is a const generic, hence the
/// tiers.
fn decode_payload<T: DeserializeOwned>(
    payload: &[u8],
) -> Result<(T, usize), bincode::error::DecodeError> {
    macro_rules! tiers {
        ($($shift:literal)*) => {$(
            if payload.len() <= 1usize << $shift {
                return bincode::serde::decode_from_slice(
                    payload,
                    config().with_limit::<{ 1usize << $shift }>(),
                );
            }
        )*};
    }
    tiers!(12 14 16 18 20 22 24 26 28 30 32 34 36 38 40 42 44 46);
    bincode::serde::decode_from_slice(payload, config().with_limit::<{ usize::MAX }>())
}

/// Read a whole file, naming it in the error.
pub fn read_file(path: &Path) -> Result<Vec<u8>, FormatError> {
    std::fs::read(path).map_err(|e| FormatError::io(path, e))
}

/// Write `bytes` to `path` through a temporary file in the same folder and a rename, so a
/// crash never leaves half a file and concurrent readers see the old or the new file whole.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), FormatError> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let mut builder = tempfile::Builder::new();
    builder.prefix(".unitrace-").suffix(".tmp");
    // A temporary file is private (0600) by default; the output should be what creating it
    // directly gives (0666 less the umask), so that, say, a cluster's merge step running as
    // another user can read the tiles.
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        builder.permissions(std::fs::Permissions::from_mode(0o666));
    }
    let mut tmp = builder
        .tempfile_in(dir)
        .map_err(|e| FormatError::io(path, e))?;
    tmp.write_all(bytes).map_err(|e| FormatError::io(path, e))?;
    tmp.as_file()
        .sync_all()
        .map_err(|e| FormatError::io(path, e))?;
    tmp.persist(path)
        .map_err(|e| FormatError::io(path, e.error))?;
    Ok(())
}
