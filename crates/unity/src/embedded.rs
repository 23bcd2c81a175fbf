//! Meshes stored inside a scene (class 43 documents): `m_VertexData` (channels over
//! hex-encoded streams) and `m_IndexBuffer` (hex, 16- or 32-bit little-endian indices).
//! The data is already in Unity space with Unity's winding.

use crate::mesh::{smooth_normals, Mesh};
use crate::yaml::Node;
use glam::{Vec2, Vec3};

fn hex(s: &str) -> Result<Vec<u8>, String> {
    let s = s.trim();
    if !s.len().is_multiple_of(2) || !s.bytes().all(|b| b.is_ascii_hexdigit()) {
        return Err("malformed hex data".into());
    }
    (0..s.len())
        .step_by(2)
        .map(|i| u8::from_str_radix(&s[i..i + 2], 16).map_err(|_| "bad hex data".to_string()))
        .collect()
}

/// Bytes per component of a vertex format code (the same codes cover Unity 2017's
/// float/half/byte and 2019+'s VertexFormat enum).
fn format_size(f: i64) -> Option<usize> {
    [4, 2, 1, 1, 2, 2, 1, 1, 2, 2, 4, 4]
        .get(usize::try_from(f).ok()?)
        .copied()
}

struct Channel {
    stream: usize,
    offset: usize,
    format: i64,
    dim: usize,
}

pub fn decode(body: &Node) -> Result<Mesh, String> {
    if body.i64_at("m_MeshCompression").unwrap_or(0) != 0 {
        return Err("the mesh is compressed (m_MeshCompression), which is not decoded".into());
    }
    let vd = body.get("m_VertexData").ok_or("no m_VertexData")?;
    let count = vd.i64_at("m_VertexCount").unwrap_or(0).max(0) as usize;
    let data = hex(vd.str_at("_typelessdata").unwrap_or(""))?;
    let channels: Vec<Channel> = vd
        .get("m_Channels")
        .map(Node::as_seq)
        .unwrap_or(&[])
        .iter()
        .map(|c| Channel {
            stream: c.i64_at("stream").unwrap_or(0).max(0) as usize,
            offset: c.i64_at("offset").unwrap_or(0).max(0) as usize,
            format: c.i64_at("format").unwrap_or(0),
            dim: (c.i64_at("dimension").unwrap_or(0) & 0xF) as usize,
        })
        .collect();
    if channels.first().is_none_or(|c| c.dim < 3) {
        return Err("no position channel".into());
    }
    // Every size below comes from the file: bound them before any arithmetic or
    // allocation (a stream number of 8·10¹⁷ made a vector of that length; fuzzer find).
    // Unity has at most 4 vertex streams and strides under 256 bytes.
    for c in channels.iter().filter(|c| c.dim > 0) {
        if c.stream > 3 || c.offset > 255 {
            return Err(format!(
                "vertex channel at stream {} offset {} is outside Unity's 4 streams of at most 256 bytes",
                c.stream, c.offset
            ));
        }
    }
    // Positions alone take 12 bytes a vertex.
    if count > data.len() / 12 {
        return Err(format!(
            "m_VertexCount {count} needs more than the {} bytes of vertex data",
            data.len()
        ));
    }
    // Streams follow each other, each `stride × count` bytes, aligned to 16.
    let n_streams = channels
        .iter()
        .filter(|c| c.dim > 0)
        .map(|c| c.stream + 1)
        .max()
        .unwrap_or(1);
    let mut stride = vec![0usize; n_streams];
    for c in channels.iter().filter(|c| c.dim > 0) {
        let size = format_size(c.format).ok_or(format!("unknown vertex format {}", c.format))?;
        stride[c.stream] = stride[c.stream].max(c.offset + size * c.dim);
    }
    let mut start = vec![0usize; n_streams];
    let mut at = 0usize;
    for s in 0..n_streams {
        start[s] = at;
        at = (at + stride[s] * count).div_ceil(16) * 16;
    }
    let read_vec3 = |c: &Channel, i: usize| -> Result<Vec3, String> {
        if c.format != 0 {
            return Err(format!(
                "vertex format {} for positions/normals is not decoded",
                c.format
            ));
        }
        let base = start[c.stream] + stride[c.stream] * i + c.offset;
        let f = |k: usize| -> Result<f32, String> {
            let b = data
                .get(base + 4 * k..base + 4 * k + 4)
                .ok_or("vertex data is shorter than its channels say")?;
            Ok(f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        };
        Ok(Vec3::new(f(0)?, f(1)?, f(2)?))
    };
    let positions: Vec<Vec3> = (0..count)
        .map(|i| read_vec3(&channels[0], i))
        .collect::<Result<_, _>>()?;
    let file_normals: Option<Vec<Vec3>> = match channels.get(1).filter(|c| c.dim >= 3) {
        Some(c) => Some(
            (0..count)
                .map(|i| read_vec3(c, i))
                .collect::<Result<_, _>>()?,
        ),
        None => None,
    };

    // UV0 is channel 3 in Unity ≤ 2018's 8-channel layout (position, normal, colour, UV0…)
    // and channel 4 in 2019+'s 14 (position, normal, tangent, colour, UV0…). Only float
    // and half UVs are read; any other encoding, or a short stream, leaves the mesh
    // without UVs rather than refusing geometry that converts without them.
    let uv_channel = if channels.len() >= 14 { 4 } else { 3 };
    let uvs: Vec<Vec2> = channels
        .get(uv_channel)
        .filter(|c| c.dim >= 2 && (c.format == 0 || c.format == 1))
        .and_then(|c| {
            let size = if c.format == 0 { 4 } else { 2 };
            (0..count)
                .map(|i| {
                    let base = start[c.stream] + stride[c.stream] * i + c.offset;
                    let f = |k: usize| -> Option<f32> {
                        let b = data.get(base + size * k..base + size * (k + 1))?;
                        Some(if size == 4 {
                            f32::from_le_bytes([b[0], b[1], b[2], b[3]])
                        } else {
                            f16_to_f32(u16::from_le_bytes([b[0], b[1]]))
                        })
                    };
                    Some(Vec2::new(f(0)?, f(1)?))
                })
                .collect()
        })
        .unwrap_or_default();

    let ib = hex(body.str_at("m_IndexBuffer").unwrap_or(""))?;
    let wide = body.i64_at("m_IndexFormat") == Some(1);
    let index = |k: usize| -> Option<u32> {
        if wide {
            ib.get(4 * k..4 * k + 4)
                .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        } else {
            ib.get(2 * k..2 * k + 2)
                .map(|b| u16::from_le_bytes([b[0], b[1]]) as u32)
        }
    };
    let isize_ = if wide { 4 } else { 2 };
    let mut submeshes = Vec::new();
    for sm in body.get("m_SubMeshes").map(Node::as_seq).unwrap_or(&[]) {
        if sm.i64_at("topology").unwrap_or(0) != 0 {
            submeshes.push(vec![]); // lines/points draw no surface
            continue;
        }
        let first = sm.i64_at("firstByte").unwrap_or(0).max(0) as usize / isize_;
        let n = sm.i64_at("indexCount").unwrap_or(0).max(0) as usize;
        let base = sm.i64_at("baseVertex").unwrap_or(0);
        if first.saturating_add(n) > ib.len() / isize_ {
            return Err("index buffer is shorter than its sub-meshes say".into());
        }
        let mut tris = Vec::with_capacity(n / 3);
        for t in 0..n / 3 {
            let mut tri = [0u32; 3];
            for (j, v) in tri.iter_mut().enumerate() {
                let i = index(first + 3 * t + j)
                    .ok_or("index buffer is shorter than its sub-meshes say")?
                    as i64
                    + base;
                if i < 0 || i as usize >= count {
                    return Err(format!("index {i} out of range of {count} vertices"));
                }
                *v = i as u32;
            }
            tris.push(tri);
        }
        submeshes.push(tris);
    }
    let normals = match file_normals {
        Some(n) => n.into_iter().map(|v| v.normalize_or_zero()).collect(),
        None => {
            // Per-vertex average of the smoothed corner normals.
            let all: Vec<[u32; 3]> = submeshes.iter().flatten().copied().collect();
            let corner = smooth_normals(&positions, &all, 180.0);
            let mut acc = vec![Vec3::ZERO; count];
            for (t, ns) in all.iter().zip(corner) {
                for k in 0..3 {
                    acc[t[k] as usize] += ns[k];
                }
            }
            acc.into_iter().map(|v| v.normalize_or_zero()).collect()
        }
    };
    Ok(Mesh {
        positions,
        normals,
        submeshes,
        uvs,
    })
}

/// IEEE half → single (Unity's Float16 vertex format).
fn f16_to_f32(h: u16) -> f32 {
    let sign = if h & 0x8000 != 0 { -1.0 } else { 1.0 };
    let exp = ((h >> 10) & 0x1f) as i32;
    let frac = (h & 0x3ff) as f32;
    sign * match exp {
        0 => frac * 2f32.powi(-24),
        31 if frac == 0.0 => f32::INFINITY,
        31 => f32::NAN,
        _ => (1.0 + frac / 1024.0) * 2f32.powi(exp - 15),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::yaml::parse;

    #[test]
    fn decodes_positions_normals_and_indices() {
        // Three vertices, position + normal (stride 24), one triangle 0-1-2.
        let mut data = String::new();
        for (p, n) in [
            ([0.0f32, 0.0, 0.0], [0.0f32, 0.0, -1.0]),
            ([0.0, 1.0, 0.0], [0.0, 0.0, -1.0]),
            ([1.0, 0.0, 0.0], [0.0, 0.0, -1.0]),
        ] {
            for v in p.iter().chain(&n) {
                for b in v.to_le_bytes() {
                    data += &format!("{b:02x}");
                }
            }
        }
        let text = format!("Mesh:\n  m_SubMeshes:\n  - serializedVersion: 2\n    firstByte: 0\n    indexCount: 3\n    topology: 0\n    baseVertex: 0\n  m_IndexFormat: 0\n  m_IndexBuffer: 000001000200\n  m_VertexData:\n    m_VertexCount: 3\n    m_Channels:\n    - stream: 0\n      offset: 0\n      format: 0\n      dimension: 3\n    - stream: 0\n      offset: 12\n      format: 0\n      dimension: 3\n    m_DataSize: 72\n    _typelessdata: {data}\n");
        let m = decode(parse(&text).get("Mesh").unwrap()).unwrap();
        assert_eq!(m.positions[1], Vec3::Y);
        assert_eq!(m.normals[2], Vec3::NEG_Z);
        assert_eq!(m.submeshes, vec![vec![[0, 1, 2]]]);
        assert!(m.uvs.is_empty());

        // Fuzzer find: a stream number of 8·10¹⁷ asked for a vector that long; absurd
        // streams, offsets and counts are errors before anything is allocated.
        for (from, to) in [
            (
                "- stream: 0\n      offset: 12",
                "- stream: 800000000000000000\n      offset: 12",
            ),
            (
                "- stream: 0\n      offset: 12",
                "- stream: 0\n      offset: 9223372036854775807",
            ),
            ("m_VertexCount: 3", "m_VertexCount: 9223372036854775807"),
            ("m_VertexCount: 3", "m_VertexCount: 7"),
        ] {
            let bad = text.replace(from, to);
            let e = decode(parse(&bad).get("Mesh").unwrap()).unwrap_err();
            assert!(e.contains("stream") || e.contains("m_VertexCount"), "{e}");
        }
    }

    #[test]
    fn reads_uv0_in_both_channel_layouts() {
        // Position (12 bytes) then UV0 (8 bytes float, or 4 bytes half) per vertex.
        let build = |channels: usize, uv_at: usize, half: bool| {
            let mut data = String::new();
            for (p, uv) in [
                ([0.0f32, 0.0, 0.0], [0.0f32, 0.0]),
                ([0.0, 1.0, 0.0], [0.0, 1.0]),
                ([1.0, 0.0, 0.0], [0.5, -2.0]),
            ] {
                for v in p {
                    for b in v.to_le_bytes() {
                        data += &format!("{b:02x}");
                    }
                }
                for v in uv {
                    if half {
                        // 0 → 0x0000, 0.5 → 0x3800, 1 → 0x3c00, −2 → 0xc000.
                        let h: u16 = match v {
                            0.0 => 0,
                            0.5 => 0x3800,
                            1.0 => 0x3c00,
                            _ => 0xc000,
                        };
                        data += &format!("{:02x}{:02x}", h & 0xff, h >> 8);
                    } else {
                        for b in v.to_le_bytes() {
                            data += &format!("{b:02x}");
                        }
                    }
                }
            }
            let mut ch = String::new();
            for i in 0..channels {
                let (offset, format, dim) = match i {
                    0 => (0, 0, 3),
                    i if i == uv_at => (12, half as i32, 2),
                    _ => (0, 0, 0),
                };
                ch += &format!("    - stream: 0\n      offset: {offset}\n      format: {format}\n      dimension: {dim}\n");
            }
            format!("Mesh:\n  m_SubMeshes:\n  - serializedVersion: 2\n    firstByte: 0\n    indexCount: 3\n    topology: 0\n    baseVertex: 0\n  m_IndexFormat: 0\n  m_IndexBuffer: 000001000200\n  m_VertexData:\n    m_VertexCount: 3\n    m_Channels:\n{ch}    _typelessdata: {data}\n")
        };
        for (channels, uv_at, half) in [(8, 3, false), (14, 4, false), (14, 4, true)] {
            let text = build(channels, uv_at, half);
            let m = decode(parse(&text).get("Mesh").unwrap()).unwrap();
            assert_eq!(
                m.uvs,
                vec![Vec2::ZERO, Vec2::Y, Vec2::new(0.5, -2.0)],
                "{channels} channels, half {half}"
            );
        }
    }
}
