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
use std::io::{Seek, SeekFrom, Write};
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

/// An artifact type: its frame constants and how its payload is written and read.
///
/// Payloads are bincode (little-endian, fixed-width integers), but their bulk — per-triangle
/// arrays, tree nodes — goes through [`PayloadWriter::array`] and [`PayloadReader::array`],
/// which write and read the very bytes bincode would (a u64 count, then the elements
/// little-endian) as one block instead of one call per number. A two-million-triangle soup
/// is 168 MB; serialising it float by float was the largest part of writing it.
pub trait Artifact: Sized {
    const MAGIC: &'static [u8; 8];
    const VERSION: u32;
    /// What error messages call it ("soup", "k-d tree").
    const KIND: &'static str;
    fn write_payload<W: Write + Send>(&self, p: &mut PayloadWriter<W>) -> Result<(), FormatError>;
    /// The payload's fields in order; an error says what does not decode, and where.
    fn read_payload(r: &mut PayloadReader) -> Result<Self, String>;
    /// Cross-references a reader relies on, checked after decoding.
    fn validate(&self) -> Result<(), String>;
}

/// The whole artifact file as bytes: what [`write()`] puts in the file.
pub fn encode<A: Artifact>(value: &A, path: &Path) -> Result<Vec<u8>, FormatError> {
    let mut out = vec![0u8; HEADER_LEN];
    let mut p = PayloadWriter::new(&mut out, path);
    value.write_payload(&mut p)?;
    let (len, hash) = p.finish()?;
    out[..HEADER_LEN].copy_from_slice(&header::<A>(len, hash));
    Ok(out)
}

fn header<A: Artifact>(len: u64, hash: blake3::Hash) -> [u8; HEADER_LEN] {
    let mut header = [0u8; HEADER_LEN];
    header[..8].copy_from_slice(A::MAGIC);
    header[8..12].copy_from_slice(&A::VERSION.to_le_bytes());
    header[12..20].copy_from_slice(&len.to_le_bytes());
    header[20..].copy_from_slice(hash.as_bytes());
    header
}

/// Validate the frame of `bytes` (read from `path`), decode its payload and check the
/// result's cross-references.
pub fn decode<A: Artifact>(bytes: &[u8], path: &Path) -> Result<A, FormatError> {
    let payload = checked_payload(bytes, A::MAGIC, A::KIND, A::VERSION, path)?;
    let corrupt = |detail| FormatError::Corrupt {
        path: path.to_path_buf(),
        detail,
    };
    let mut r = PayloadReader {
        bytes: payload,
        pos: 0,
    };
    let value = A::read_payload(&mut r).map_err(corrupt)?;
    if r.pos != payload.len() {
        return Err(corrupt(format!(
            "payload decoded from {} of {} bytes",
            r.pos,
            payload.len()
        )));
    }
    value.validate().map_err(corrupt)?;
    Ok(value)
}

/// An artifact file whose frame and payload checksum are verified, its fields read on
/// demand without decoding the rest or checking its cross-references: `soup2kd` reads a
/// soup's key and then, on a cache miss, its geometry, with one pass of the checksum.
pub struct Checked<A> {
    bytes: FileBytes,
    path: std::path::PathBuf,
    kind: std::marker::PhantomData<A>,
}

impl<A: Artifact> Checked<A> {
    pub fn open(path: &Path) -> Result<Checked<A>, FormatError> {
        Self::verify(read_file(path)?, path)
    }

    /// A file's bytes already in memory, `path` naming it in errors.
    pub fn from_bytes(bytes: Vec<u8>, path: &Path) -> Result<Checked<A>, FormatError> {
        Self::verify(FileBytes::Read(bytes), path)
    }

    fn verify(bytes: FileBytes, path: &Path) -> Result<Checked<A>, FormatError> {
        checked_payload(&bytes, A::MAGIC, A::KIND, A::VERSION, path)?;
        Ok(Checked {
            bytes,
            path: path.to_path_buf(),
            kind: std::marker::PhantomData,
        })
    }

    /// What `read` takes from the payload (its leading fields, any fixed-size last one),
    /// its errors named as corruption of this file.
    pub fn read<T>(
        &self,
        read: impl FnOnce(&mut PayloadReader) -> Result<T, String>,
    ) -> Result<T, FormatError> {
        read(&mut PayloadReader {
            bytes: &self.bytes[HEADER_LEN..],
            pos: 0,
        })
        .map_err(|detail| FormatError::Corrupt {
            path: self.path.clone(),
            detail,
        })
    }
}

/// The payload of `bytes` once magic, version, length and checksum are right.
fn checked_payload<'a>(
    bytes: &'a [u8],
    magic: &[u8; 8],
    kind: &'static str,
    version: u32,
    path: &Path,
) -> Result<&'a [u8], FormatError> {
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
    let mut hasher = blake3::Hasher::new();
    hash_into(&mut hasher, payload);
    if hasher.finalize().as_bytes() != &bytes[20..52] {
        return Err(FormatError::Corrupt {
            path: p(),
            detail: "payload checksum mismatch (bytes changed after writing)".into(),
        });
    }
    Ok(payload)
}

/// Below this many bytes one thread hashes faster than the pool starts (BLAKE3's own advice
/// is 128 KiB and up).
pub(crate) const PARALLEL_HASH_MIN: usize = 1 << 20;

/// BLAKE3 of large blocks on all cores; the digest is the same however it is split.
pub(crate) fn hash_into(h: &mut blake3::Hasher, bytes: &[u8]) {
    if bytes.len() < PARALLEL_HASH_MIN {
        h.update(bytes);
    } else {
        h.update_rayon(bytes);
    }
}

/// Where a payload's bytes go, hashed on their way. Small writes (bincode writes field by
/// field) are gathered in a buffer; blocks of 64 KiB or more go straight
/// from the caller's memory to the hash and the file.
pub struct PayloadWriter<'p, W> {
    out: W,
    buf: Vec<u8>,
    hasher: blake3::Hasher,
    len: u64,
    path: &'p Path,
}

/// Writes at least this large bypass the buffer (and its copy).
const PASS_THROUGH: usize = 64 << 10;

impl<'p, W: Write + Send> PayloadWriter<'p, W> {
    fn new(out: W, path: &'p Path) -> Self {
        PayloadWriter {
            out,
            buf: Vec::with_capacity(PASS_THROUGH),
            hasher: blake3::Hasher::new(),
            len: 0,
            path,
        }
    }

    /// A `Vec<T>` of plain numbers, encoded as bincode encodes it: the element count as u64,
    /// then the elements, little-endian, as one block.
    pub fn array<T: bytemuck::Pod + Serialize>(&mut self, items: &[T]) -> Result<(), FormatError> {
        #[cfg(target_endian = "little")]
        {
            self.write_all(&(items.len() as u64).to_le_bytes())
                .and_then(|()| self.write_all(bytemuck::cast_slice(items)))
                .map_err(|e| FormatError::io(self.path, e))
        }
        #[cfg(not(target_endian = "little"))]
        self.value(&items)
    }

    /// Anything else, through bincode's serde route.
    pub fn value<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<(), FormatError> {
        let path = self.path;
        bincode::serde::encode_into_std_write(value, self, config()).map_err(|e| {
            FormatError::Encode {
                path: path.to_path_buf(),
                detail: e.to_string(),
            }
        })?;
        Ok(())
    }

    /// The payload's length and BLAKE3, once everything is written.
    fn finish(mut self) -> Result<(u64, blake3::Hash), FormatError> {
        self.flush().map_err(|e| FormatError::io(self.path, e))?;
        Ok((self.len, self.hasher.finalize()))
    }

    /// Large blocks are hashed (on all cores) while the kernel copies them into the file.
    fn pass(&mut self, bytes: &[u8]) -> std::io::Result<()> {
        if bytes.len() < PARALLEL_HASH_MIN {
            self.hasher.update(bytes);
            self.out.write_all(bytes)?;
        } else {
            let (hasher, out) = (&mut self.hasher, &mut self.out);
            rayon::join(|| hasher.update_rayon(bytes), || out.write_all(bytes)).1?;
        }
        self.len += bytes.len() as u64;
        Ok(())
    }
}

impl<W: Write + Send> Write for PayloadWriter<'_, W> {
    fn write(&mut self, data: &[u8]) -> std::io::Result<usize> {
        self.write_all(data)?;
        Ok(data.len())
    }

    // bincode writes every number through `write_all`: inlined, a four-byte append is a
    // few instructions rather than the default retry loop around `write`.
    #[inline]
    fn write_all(&mut self, data: &[u8]) -> std::io::Result<()> {
        if self.buf.len() + data.len() > PASS_THROUGH {
            self.flush()?;
        }
        if data.len() >= PASS_THROUGH {
            self.pass(data)
        } else {
            self.buf.extend_from_slice(data);
            Ok(())
        }
    }

    #[cold]
    fn flush(&mut self) -> std::io::Result<()> {
        let buf = std::mem::take(&mut self.buf);
        let passed = self.pass(&buf);
        self.buf = buf;
        self.buf.clear();
        passed
    }
}

/// The decoding side of [`PayloadWriter`]: a cursor over a payload whose checksum is good.
pub struct PayloadReader<'a> {
    bytes: &'a [u8],
    pos: usize,
}

impl PayloadReader<'_> {
    /// What [`PayloadWriter::array`] wrote, named `what` in errors. The count is checked
    /// against the bytes left before anything is allocated.
    pub fn array<T: bytemuck::Pod + DeserializeOwned>(
        &mut self,
        what: &str,
    ) -> Result<Vec<T>, String> {
        #[cfg(target_endian = "little")]
        {
            let bytes = self.array_bytes::<T>(what)?;
            Ok(copy_out(bytes))
        }
        #[cfg(not(target_endian = "little"))]
        self.value(what)
    }

    /// Steps over what [`PayloadWriter::array`] wrote, returning its length.
    pub fn skip_array<T: bytemuck::Pod>(&mut self, what: &str) -> Result<usize, String> {
        Ok(self.array_bytes::<T>(what)?.len() / std::mem::size_of::<T>())
    }

    /// The elements' bytes of the array at the reader's position (a little-endian u64
    /// count, then the elements), the reader moved past them.
    fn array_bytes<T: bytemuck::Pod>(&mut self, what: &str) -> Result<&[u8], String> {
        let at = self.pos;
        let rest = &self.bytes[at..];
        let Some(count) = rest.get(..8) else {
            return Err(format!(
                "payload does not decode: it ends at byte {at}, inside the count of {what}"
            ));
        };
        let count = u64::from_le_bytes(count.try_into().expect("8 bytes"));
        let size = usize::try_from(count)
            .ok()
            .and_then(|n| n.checked_mul(std::mem::size_of::<T>()))
            .filter(|&size| size <= rest.len() - 8)
            .ok_or_else(|| {
                format!(
                    "payload does not decode: {count} {what} at byte {at} need more than the {} bytes left",
                    rest.len() - 8
                )
            })?;
        self.pos += 8 + size;
        Ok(&rest[8..8 + size])
    }

    /// The payload's last `N` bytes, a fixed-size last field, named `what` in errors; they
    /// must lie beyond the reader's position.
    pub fn last<const N: usize>(&self, what: &str) -> Result<[u8; N], String> {
        let len = self.bytes.len();
        if len < self.pos + N {
            return Err(format!(
                "payload does not decode: {len} bytes end before {what}, {N} bytes after byte {}",
                self.pos
            ));
        }
        Ok(self.bytes[len - N..].try_into().expect("N bytes"))
    }

    /// A value bincode's serde route wrote, named `what` in errors.
    pub fn value<T: DeserializeOwned>(&mut self, what: &str) -> Result<T, String> {
        let (value, used) = decode_payload(&self.bytes[self.pos..])
            .map_err(|e| format!("payload does not decode: {what} at byte {}: {e}", self.pos))?;
        self.pos += used;
        Ok(value)
    }
}

/// Below this many bytes an array is copied out on one thread.
const PARALLEL_COPY_MIN: usize = 1 << 20;

/// An array's bytes copied out of the file into a vector of its own, large ones in
/// blocks on all cores. Most of such a copy's time is the kernel handing out and zeroing
/// the vector's fresh pages, one fault per page, and those faults run side by side on
/// two threads.
fn copy_out<T: bytemuck::Pod>(bytes: &[u8]) -> Vec<T> {
    if bytes.len() < PARALLEL_COPY_MIN {
        return bytemuck::pod_collect_to_vec(bytes);
    }
    use rayon::prelude::*;
    // Zeroed memory this large comes fresh from the kernel, which zeroes it on first touch:
    // the copy below is the only pass over it.
    let mut out: Vec<T> = bytemuck::zeroed_vec(bytes.len() / std::mem::size_of::<T>());
    bytemuck::cast_slice_mut::<T, u8>(&mut out)
        .par_chunks_mut(PARALLEL_COPY_MIN)
        .zip(bytes.par_chunks(PARALLEL_COPY_MIN))
        .for_each(|(to, from)| to.copy_from_slice(from));
    out
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

/// A whole file's bytes: mapped when it is large, read when it is small.
pub enum FileBytes {
    Mapped(memmap2::Mmap),
    Read(Vec<u8>),
}

impl std::ops::Deref for FileBytes {
    type Target = [u8];
    fn deref(&self) -> &[u8] {
        match self {
            FileBytes::Mapped(m) => m,
            FileBytes::Read(v) => v,
        }
    }
}

/// Files from this size on are mapped rather than read.
const MAP_MIN: u64 = 1 << 20;

/// A whole file, naming it in the error.
///
/// A large artifact is mapped instead of read: the checksum and the decoder read the page
/// cache in place, and only the decoded arrays are copied, where reading first copied the
/// whole file into a buffer of its own (on `just large`'s 362 MB soup, that copy and the
/// buffer's page faults took 0.5 s of `kd2exr`'s 1.7 s of loading).
pub fn read_file(path: &Path) -> Result<FileBytes, FormatError> {
    let io = |e| FormatError::io(path, e);
    let file = std::fs::File::open(path).map_err(io)?;
    let len = file.metadata().map_err(io)?.len();
    if len < MAP_MIN {
        let mut bytes = Vec::with_capacity(len as usize);
        std::io::Read::read_to_end(&mut &file, &mut bytes).map_err(io)?;
        return Ok(FileBytes::Read(bytes));
    }
    // SAFETY: a mapping is undefined behaviour if the file changes while it is mapped.
    // unitrace never changes an artifact in place: every writer writes a temporary file
    // and renames (or exchanges) it over the old name, which leaves the mapped file (the
    // old inode) as it was. Another program truncating the very file we map would stop
    // this process with SIGBUS, and one rewriting it in place while it is read could hand
    // the decoder bytes that changed after the checksum was verified; nothing of ours
    // does either.
    let map = unsafe { memmap2::MmapOptions::new().map(&file) }.map_err(io)?;
    Ok(FileBytes::Mapped(map))
}

/// Write `bytes` to `path` through a temporary file in the same folder and a rename, so a
/// crash never leaves half a file and concurrent readers see the old or the new file whole.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), FormatError> {
    let mut tmp = temp_beside(path)?;
    tmp.write_all(bytes).map_err(|e| FormatError::io(path, e))?;
    persist(tmp, path)
}

/// Write `value` to `path` atomically (as [`write_atomic`]), the bytes of [`encode`]
/// streamed into the file without the payload ever being whole in memory.
///
/// The file is not synced to disk (see the comment at the rename for why that is safe).
/// The header's length and checksum are known only at the end, so it is written zeroed and
/// overwritten in place before the rename: a reader never sees the file until it is complete.
pub fn write<A: Artifact>(value: &A, path: &Path) -> Result<(), FormatError> {
    let mut tmp = temp_beside(path)?;
    let file = tmp.as_file_mut();
    file.write_all(&[0; HEADER_LEN])
        .map_err(|e| FormatError::io(path, e))?;
    let mut p = PayloadWriter::new(&mut *file, path);
    value.write_payload(&mut p)?;
    let (len, hash) = p.finish()?;
    let header = header::<A>(len, hash);
    file.seek(SeekFrom::Start(0))
        .and_then(|_| file.write_all(&header))
        .map_err(|e| FormatError::io(path, e))?;
    // Not synced, unlike `write_atomic`'s files: the rename after the complete write is what
    // keeps a killed process from leaving a torn artifact, and `fsync` adds only safety
    // against power loss, at the price of waiting for the disk (55–65 ms for a 168 MB soup,
    // a fifth of the conversion). After a power cut an unsynced artifact can come back
    // empty or with zeroed blocks; its header's length and BLAKE3 then fail, so every
    // reader rejects it with an error naming the file and it is rebuilt, never used.
    replace(tmp, path)
}

/// Put the complete temporary file in `path`'s place, atomically for readers.
///
/// Renaming over an existing file makes ext4 (with its default `auto_da_alloc`) write the
/// new file's blocks out before the rename returns, its guard against the empty files that
/// unsynced rename-replacements leave after a crash: about 100 ms for a 168 MB soup, a third
/// of the conversion. The artifacts carry their own guard (length and checksum), so where
/// the target exists the two names are exchanged instead, which the heuristic leaves
/// alone, and the old file, now under the temporary name, is deleted. Readers see the old
/// file or the new one, whole, as with a rename. A file system that cannot exchange gets
/// the plain rename.
fn replace(tmp: tempfile::NamedTempFile, path: &Path) -> Result<(), FormatError> {
    #[cfg(target_os = "linux")]
    {
        use rustix::fs::{renameat_with, RenameFlags, CWD};
        // Only a regular file is exchanged: a folder (or a link) in the way must meet the
        // rename's refusal, not be moved aside under the temporary name.
        let replaces_file = std::fs::symlink_metadata(path).is_ok_and(|m| m.is_file());
        if replaces_file && renameat_with(CWD, tmp.path(), CWD, path, RenameFlags::EXCHANGE).is_ok()
        {
            // Closing the temporary file deletes what its name now holds: the old artifact.
            // The new one is in place either way, so a failed deletion (which leaves a hidden
            // `.unitrace-*.tmp`) is no reason to report the write as failed.
            let _ = tmp.close();
            return Ok(());
        }
    }
    tmp.persist(path)
        .map_err(|e| FormatError::io(path, e.error))?;
    Ok(())
}

/// A temporary file in `path`'s folder, so that the final rename stays on one file system.
fn temp_beside(path: &Path) -> Result<tempfile::NamedTempFile, FormatError> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    remove_stale_temporaries(dir);
    let mut builder = tempfile::Builder::new();
    builder.prefix(TEMP_PREFIX).suffix(TEMP_SUFFIX);
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

const TEMP_PREFIX: &str = ".unitrace-";
const TEMP_SUFFIX: &str = ".tmp";

/// A temporary file untouched for this long belongs to a writer that was killed: a live one
/// writes its file from start to end without pausing, and takes seconds even at 10 million
/// triangles.
pub const STALE_TEMP_SECONDS: u64 = 3600;

/// Delete the hidden temporaries that killed writers left in `dir` (nothing survives a
/// SIGKILL to delete its own). Best effort: a folder that cannot be listed, or a file that
/// cannot be removed, is left as it is, and the write goes on.
fn remove_stale_temporaries(dir: &Path) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    let stale = std::time::Duration::from_secs(STALE_TEMP_SECONDS);
    for entry in entries.flatten() {
        let name = entry.file_name();
        let Some(name) = name.to_str() else { continue };
        if !(name.starts_with(TEMP_PREFIX) && name.ends_with(TEMP_SUFFIX)) {
            continue;
        }
        let old = entry
            .metadata()
            .ok()
            .filter(|m| m.is_file())
            .and_then(|m| m.modified().ok())
            .and_then(|t| t.elapsed().ok())
            .is_some_and(|age| age > stale);
        if old {
            let _ = std::fs::remove_file(entry.path());
        }
    }
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
