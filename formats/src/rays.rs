//! Raw ray and hit files (RAYS.md): plain little-endian records any tool can produce.
//!
//! ```text
//! rays: "RAYS", u32 version 1, u64 count, count × {ox oy oz tmin dx dy dz tmax: f32}
//! hits: "HITS", u32 version 1, u64 count, count × {t: f32, prim: u32, u: f32, v: f32}
//! ```

use crate::{envelope::write_atomic, FormatError};
use glam::Vec3;
use std::path::Path;

pub const RAYS_MAGIC: &[u8; 4] = b"RAYS";
pub const HITS_MAGIC: &[u8; 4] = b"HITS";
pub const VERSION: u32 = 1;
const HEADER: usize = 16;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayRecord {
    pub origin: Vec3,
    pub tmin: f32,
    pub dir: Vec3,
    pub tmax: f32,
}

/// A closest hit (or, for any-hit queries, `t = 0` when occluded). A miss is
/// `t = +inf`, `prim = u32::MAX`. The hit point is (1−u−v)·v0 + u·v1 + v·v2.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    pub t: f32,
    pub prim: u32,
    pub u: f32,
    pub v: f32,
}

impl Hit {
    pub const MISS: Hit = Hit {
        t: f32::INFINITY,
        prim: u32::MAX,
        u: 0.0,
        v: 0.0,
    };
    pub fn is_miss(&self) -> bool {
        self.prim == u32::MAX
    }
}

fn header(magic: &[u8; 4], count: usize) -> Vec<u8> {
    let mut out = Vec::with_capacity(HEADER);
    out.extend_from_slice(magic);
    out.extend_from_slice(&VERSION.to_le_bytes());
    out.extend_from_slice(&(count as u64).to_le_bytes());
    out
}

/// Check magic, version and that the file holds exactly `count` records of `record` bytes.
fn records<'a>(
    bytes: &'a [u8],
    magic: &[u8; 4],
    kind: &'static str,
    record: usize,
    path: &Path,
) -> Result<&'a [u8], FormatError> {
    let p = || path.to_path_buf();
    if bytes.len() < 4 || &bytes[..4] != magic {
        return Err(FormatError::Magic {
            path: p(),
            expected: kind,
            found: String::from_utf8_lossy(&bytes[..bytes.len().min(4)]).into_owned(),
        });
    }
    if bytes.len() < HEADER {
        return Err(FormatError::Truncated {
            path: p(),
            detail: format!("{} bytes, the header alone is {HEADER}", bytes.len()),
        });
    }
    let version = u32::from_le_bytes(bytes[4..8].try_into().expect("4 bytes"));
    if version != VERSION {
        return Err(FormatError::Version {
            path: p(),
            kind,
            found: version,
            supported: VERSION,
        });
    }
    let count = u64::from_le_bytes(bytes[8..16].try_into().expect("8 bytes"));
    let have = (bytes.len() - HEADER) as u64;
    match count.checked_mul(record as u64) {
        Some(need) if need == have => Ok(&bytes[HEADER..]),
        Some(need) if need > have => Err(FormatError::Truncated {
            path: p(),
            detail: format!(
                "header promises {count} records ({need} bytes), the file holds {have}"
            ),
        }),
        _ => Err(FormatError::Corrupt {
            path: p(),
            detail: format!("header promises {count} records but the file holds {have} bytes"),
        }),
    }
}

fn f32_at(b: &[u8], i: usize) -> f32 {
    f32::from_le_bytes(b[i * 4..i * 4 + 4].try_into().expect("4 bytes"))
}

pub fn decode_rays(bytes: &[u8], path: &Path) -> Result<Vec<RayRecord>, FormatError> {
    let body = records(bytes, RAYS_MAGIC, "rays", 32, path)?;
    Ok(body
        .chunks_exact(32)
        .map(|r| RayRecord {
            origin: Vec3::new(f32_at(r, 0), f32_at(r, 1), f32_at(r, 2)),
            tmin: f32_at(r, 3),
            dir: Vec3::new(f32_at(r, 4), f32_at(r, 5), f32_at(r, 6)),
            tmax: f32_at(r, 7),
        })
        .collect())
}

pub fn encode_rays(rays: &[RayRecord]) -> Vec<u8> {
    let mut out = header(RAYS_MAGIC, rays.len());
    out.reserve(rays.len() * 32);
    for r in rays {
        for f in [
            r.origin.x, r.origin.y, r.origin.z, r.tmin, r.dir.x, r.dir.y, r.dir.z, r.tmax,
        ] {
            out.extend_from_slice(&f.to_le_bytes());
        }
    }
    out
}

pub fn decode_hits(bytes: &[u8], path: &Path) -> Result<Vec<Hit>, FormatError> {
    let body = records(bytes, HITS_MAGIC, "hits", 16, path)?;
    Ok(body
        .chunks_exact(16)
        .map(|r| Hit {
            t: f32_at(r, 0),
            prim: u32::from_le_bytes(r[4..8].try_into().expect("4 bytes")),
            u: f32_at(r, 2),
            v: f32_at(r, 3),
        })
        .collect())
}

pub fn encode_hits(hits: &[Hit]) -> Vec<u8> {
    let mut out = header(HITS_MAGIC, hits.len());
    out.reserve(hits.len() * 16);
    for h in hits {
        out.extend_from_slice(&h.t.to_le_bytes());
        out.extend_from_slice(&h.prim.to_le_bytes());
        out.extend_from_slice(&h.u.to_le_bytes());
        out.extend_from_slice(&h.v.to_le_bytes());
    }
    out
}

pub fn read_rays(path: &Path) -> Result<Vec<RayRecord>, FormatError> {
    decode_rays(&crate::envelope::read_file(path)?, path)
}

pub fn write_rays(path: &Path, rays: &[RayRecord]) -> Result<(), FormatError> {
    write_atomic(path, &encode_rays(rays))
}

pub fn read_hits(path: &Path) -> Result<Vec<Hit>, FormatError> {
    decode_hits(&crate::envelope::read_file(path)?, path)
}

pub fn write_hits(path: &Path, hits: &[Hit]) -> Result<(), FormatError> {
    write_atomic(path, &encode_hits(hits))
}
