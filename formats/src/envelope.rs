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
use std::fs::File;
use std::io::{Seek, SeekFrom, Write};
use std::path::Path;
use std::sync::mpsc;

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
    let mut tmp = temp_beside(path)?;
    tmp.write_all(bytes).map_err(|e| FormatError::io(path, e))?;
    persist(tmp, path)
}

/// Serialise `value` as an artifact straight into `path`: the bytes of [`encode`], written
/// atomically as by [`write_atomic`], without the payload ever being whole in memory.
///
/// The file is not synced to disk (see the comment at the rename for why that is safe).
///
/// A soup of two million triangles is 168 MB; building it in memory first cost a fresh
/// allocation (page faults), a copy into the framed buffer and a serial hash before the
/// first byte reached the file. Here the serialiser fills `CHUNK`-sized buffers that a
/// second thread hashes and writes while the next one fills. The header's length and
/// checksum are known only at the end, so the header is written zeroed and overwritten in
/// place before the rename: a reader never sees the file until it is complete.
pub fn write_encoded<T: Serialize>(
    value: &T,
    magic: &[u8; 8],
    version: u32,
    path: &Path,
) -> Result<(), FormatError> {
    let mut tmp = temp_beside(path)?;
    let file = tmp.as_file_mut();
    file.write_all(&[0; HEADER_LEN])
        .map_err(|e| FormatError::io(path, e))?;
    let (len, hash) = stream_payload(value, file, path)?;
    let mut header = [0u8; HEADER_LEN];
    header[..8].copy_from_slice(magic);
    header[8..12].copy_from_slice(&version.to_le_bytes());
    header[12..20].copy_from_slice(&len.to_le_bytes());
    header[20..].copy_from_slice(hash.as_bytes());
    file.seek(SeekFrom::Start(0))
        .and_then(|_| file.write_all(&header))
        .map_err(|e| FormatError::io(path, e))?;
    // Not synced, unlike `write_atomic`'s files: the rename after the complete write is what
    // keeps a killed process from leaving a torn artifact, and `fsync` adds only safety
    // against power loss, at the price of waiting for the disk (55–65 ms for a 168 MB soup,
    // a fifth of the conversion). After a power cut an unsynced artifact can come back
    // empty or with zeroed blocks; its header's length and BLAKE3 then fail, so every
    // reader rejects it with an error naming the file and it is rebuilt, never used.
    tmp.persist(path)
        .map_err(|e| FormatError::io(path, e.error))?;
    Ok(())
}

/// Size of the buffers between the serialiser and the writing thread: large enough that a
/// `write` call costs little against its copy, small enough to stay in the cache.
const CHUNK: usize = 1 << 20;

/// Serialise `value` into `file` at its current position; the payload's length and BLAKE3.
fn stream_payload<T: Serialize>(
    value: &T,
    file: &mut File,
    path: &Path,
) -> Result<(u64, blake3::Hash), FormatError> {
    // Two full buffers in flight let the serialiser run ahead of one slow write without
    // the memory growing; emptied buffers come back so no chunk faults in fresh pages.
    let (full_tx, full_rx) = mpsc::sync_channel::<Vec<u8>>(2);
    let (free_tx, free_rx) = mpsc::channel::<Vec<u8>>();
    std::thread::scope(|s| {
        let sink = s.spawn(move || -> std::io::Result<(u64, blake3::Hash)> {
            let mut hasher = blake3::Hasher::new();
            let mut len = 0u64;
            for mut chunk in full_rx {
                hasher.update(&chunk);
                file.write_all(&chunk)?;
                len += chunk.len() as u64;
                chunk.clear();
                // The serialiser may already be done and gone; the buffer is then dropped.
                let _ = free_tx.send(chunk);
            }
            Ok((len, hasher.finalize()))
        });
        let mut w = ChunkWriter {
            buf: Vec::with_capacity(CHUNK),
            full: full_tx,
            free: free_rx,
        };
        let encoded = bincode::serde::encode_into_std_write(value, &mut w, config());
        let sent = w.send();
        // Closing the channel ends the sink's loop.
        drop(w);
        let sunk = match sink.join() {
            Ok(r) => r,
            Err(panic) => std::panic::resume_unwind(panic),
        };
        // A failed write stops the sink, which makes the serialiser's next send fail too:
        // the write's own error is the one worth reporting.
        let (len, hash) = sunk.map_err(|e| FormatError::io(path, e))?;
        encoded.map_err(|e| FormatError::Encode {
            path: path.to_path_buf(),
            detail: e.to_string(),
        })?;
        sent.map_err(|e| FormatError::io(path, e))?;
        Ok((len, hash))
    })
}

/// The serialiser's end of the pipe to the writing thread.
struct ChunkWriter {
    buf: Vec<u8>,
    full: mpsc::SyncSender<Vec<u8>>,
    free: mpsc::Receiver<Vec<u8>>,
}

impl ChunkWriter {
    /// Hand the filled buffer to the writing thread and continue in an emptied one.
    #[cold]
    #[inline(never)]
    fn send(&mut self) -> std::io::Result<()> {
        if self.buf.is_empty() {
            return Ok(());
        }
        let next = self
            .free
            .try_recv()
            .unwrap_or_else(|_| Vec::with_capacity(CHUNK));
        let full = std::mem::replace(&mut self.buf, next);
        self.full.send(full).map_err(|_| {
            std::io::Error::new(std::io::ErrorKind::BrokenPipe, "the writing thread stopped")
        })
    }
}

// bincode writes each number through `write_all`: the default's retry loop around `write`
// made the four-byte appends a third of the whole conversion, hence both inlined here.
impl Write for ChunkWriter {
    #[inline]
    fn write(&mut self, data: &[u8]) -> std::io::Result<usize> {
        self.write_all(data)?;
        Ok(data.len())
    }

    #[inline]
    fn write_all(&mut self, data: &[u8]) -> std::io::Result<()> {
        if self.buf.len() + data.len() > CHUNK {
            self.send()?;
        }
        self.buf.extend_from_slice(data);
        Ok(())
    }

    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

/// A temporary file in `path`'s folder, so that the final rename stays on one file system.
fn temp_beside(path: &Path) -> Result<tempfile::NamedTempFile, FormatError> {
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
    builder
        .tempfile_in(dir)
        .map_err(|e| FormatError::io(path, e))
}

/// Sync the complete temporary file and rename it over `path`.
fn persist(tmp: tempfile::NamedTempFile, path: &Path) -> Result<(), FormatError> {
    tmp.as_file()
        .sync_all()
        .map_err(|e| FormatError::io(path, e))?;
    tmp.persist(path)
        .map_err(|e| FormatError::io(path, e.error))?;
    Ok(())
}
