//! Damaged `.soup`, `.kd` and rays files: every reader refuses them and names the file.

use super::cases::*;
use super::project::*;
use formats::{KdFile, Soup};
use std::path::PathBuf;

/// The artifact frame around `payload` with a correct checksum and `good`'s magic and
/// version: only the decoder stands between a damaged payload and the reader.
fn frame(good: &[u8], payload: &[u8]) -> Vec<u8> {
    let mut out = good[..12].to_vec();
    out.extend_from_slice(&(payload.len() as u64).to_le_bytes());
    out.extend_from_slice(blake3::hash(payload).as_bytes());
    out.extend_from_slice(payload);
    out
}

/// Bad variants of one artifact file: (label, bytes). `len_at` is the payload offset of a
/// u64 element count to replace by 10¹².
fn bad_variants(good: &[u8], len_at: usize) -> Vec<(&'static str, Vec<u8>)> {
    let mut old = good.to_vec();
    old[8..12].copy_from_slice(&0u32.to_le_bytes());
    let mut newer = good.to_vec();
    newer[8..12].copy_from_slice(&99u32.to_le_bytes());
    let mut flipped = good.to_vec();
    let mid = flipped.len() / 2;
    for b in &mut flipped[mid..mid + 4] {
        *b ^= 0xA5;
    }
    let mut huge = good[52..].to_vec();
    huge[len_at..len_at + 8].copy_from_slice(&1_000_000_000_000u64.to_le_bytes());
    let mut lying_header = good.to_vec();
    lying_header[12..20].copy_from_slice(&1_000_000_000_000u64.to_le_bytes());
    vec![
        ("empty", vec![]),
        ("truncated (half)", good[..good.len() / 2].to_vec()),
        ("truncated header", good[..30].to_vec()),
        (
            "foreign (text)",
            b"solid cube\nfacet normal 0 0 1\n".to_vec(),
        ),
        ("foreign (PNG)", b"\x89PNG\r\n\x1a\n\0\0\0\rIHDR".to_vec()),
        ("old version 0", old),
        ("newer version 99", newer),
        ("4 bytes flipped mid-file", flipped),
        ("stray bytes after payload", [good, b"xx"].concat()),
        ("header length 10^12", lying_header),
        ("element count 10^12 (valid checksum)", frame(good, &huge)),
    ]
}

#[test]
fn damaged_soup_and_kd_files_are_refused_by_every_reader() {
    let a = artifacts();
    let dir = a.p.root.clone();
    let good_soup = std::fs::read(&a.soup).unwrap();
    let good_kd = std::fs::read(&a.kd).unwrap();
    let kd = KdFile::read(&a.kd).unwrap();
    // Payload layout (KD.md): the `nodes` count sits before the nodes and leaf lists.
    let nodes_at = good_kd.len() - 52 - 16 - 8 * kd.nodes.len() - 4 * kd.leaf_tris.len();
    let rays = dir.join("rays.rays");
    std::fs::write(
        &rays,
        [
            &b"RAYS"[..],
            &1u32.to_le_bytes(),
            &1u64.to_le_bytes(),
            &[0u8; 32],
        ]
        .concat(),
    )
    .unwrap();
    let prev = b"previous output".to_vec();
    let mut cases = Vec::new();
    let mut n = 0;
    let mut soup_inputs: Vec<(String, PathBuf)> = vec![
        ("missing".into(), dir.join("nope.soup")),
        ("a directory (unreadable)".into(), dir.join("Assets")),
    ];
    for (label, bytes) in bad_variants(&good_soup, 0) {
        n += 1;
        let p = dir.join(format!("bad{n}.soup"));
        std::fs::write(&p, bytes).unwrap();
        soup_inputs.push((label.to_string(), p));
    }
    // A string length of 2·10¹⁸ behind a valid checksum (the object name "Box"): bincode
    // used to allocate it before reading (found by cargo fuzz). The geometry is intact:
    // soup2kd, which reads only the geometry, builds from it; the other readers refuse it.
    let mut payload = good_soup[52..].to_vec();
    let at = payload.windows(3).position(|w| w == b"Box").unwrap() - 8;
    payload[at..at + 8].copy_from_slice(&0x2074_6c75_6166_6544u64.to_le_bytes());
    let p = dir.join("huge-name.soup");
    std::fs::write(&p, frame(&good_soup, &payload)).unwrap();
    soup_inputs.push(("string length 2·10^18 (valid checksum)".into(), p));
    for (label, p) in &soup_inputs {
        let what = format!(".soup {label}");
        let ps = s(p);
        // A damaged payload behind a valid checksum is named as one that does not decode.
        let names: &[&str] = if label.ends_with("(valid checksum)") {
            &[&ps, "does not decode"]
        } else {
            &[&ps]
        };
        let geometry_intact = label.starts_with("string length");
        let o = dir.join(format!("o{n}"));
        n += 1;
        std::fs::write(&o, &prev).unwrap();
        if geometry_intact {
            let kd_out = dir.join(format!("o{n}.kd"));
            cases.push(case(
                &what,
                "soup2kd",
                &[&ps, "-o", &s(&kd_out)],
                0,
                &["soup2kd:"],
                Out::Written(kd_out),
            ));
        } else {
            cases.push(case(
                &what,
                "soup2kd",
                &[&ps, "-o", &s(&o)],
                1,
                names,
                Out::Intact(o.clone(), prev.clone()),
            ));
        }
        cases.push(case(
            &what,
            "soup2obj",
            &[&ps, "-o", &s(&o)],
            1,
            names,
            Out::Intact(o.clone(), prev.clone()),
        ));
        cases.push(case(
            &what,
            "raycast",
            &[&ps, &s(&a.kd), &s(&rays), "-o", &s(&o)],
            1,
            names,
            Out::Intact(o.clone(), prev.clone()),
        ));
        cases.push(case(
            &what,
            "kd2exr",
            &[
                &ps,
                &s(&a.kd),
                "-o",
                &s(&o),
                "--width",
                "8",
                "--height",
                "8",
            ],
            1,
            names,
            Out::Intact(o.clone(), prev.clone()),
        ));
        let cache = dir.join(format!("cache{n}"));
        cases.push(case(
            &what,
            "soup2kd",
            &[&ps, "--cache", &s(&cache)],
            if geometry_intact { 0 } else { 1 },
            if geometry_intact {
                &["cache miss"]
            } else {
                names
            },
            Out::None,
        ));
    }
    let mut kd_inputs: Vec<(String, PathBuf)> = vec![
        ("missing".into(), dir.join("nope.kd")),
        ("a directory (unreadable)".into(), dir.join("Assets")),
    ];
    for (label, bytes) in bad_variants(&good_kd, nodes_at) {
        n += 1;
        let p = dir.join(format!("bad{n}.kd"));
        std::fs::write(&p, bytes).unwrap();
        kd_inputs.push((label.to_string(), p));
    }
    kd_inputs.push(("a soup given as the tree".into(), a.soup.clone()));
    for (label, p) in &kd_inputs {
        let what = format!(".kd {label}");
        let ps = s(p);
        let names: &[&str] = if label.ends_with("(valid checksum)") {
            &[&ps, "does not decode"]
        } else {
            &[&ps]
        };
        let o = dir.join(format!("o{n}"));
        n += 1;
        std::fs::write(&o, &prev).unwrap();
        cases.push(case(
            &what,
            "raycast",
            &[&s(&a.soup), &ps, &s(&rays), "-o", &s(&o)],
            1,
            names,
            Out::Intact(o.clone(), prev.clone()),
        ));
        cases.push(case(
            &what,
            "kd2exr",
            &[
                &s(&a.soup),
                &ps,
                "-o",
                &s(&o),
                "--width",
                "8",
                "--height",
                "8",
            ],
            1,
            names,
            Out::Intact(o.clone(), prev.clone()),
        ));
        cases.push(case(
            &what,
            "soup2kd",
            &["--stats", &ps],
            1,
            names,
            Out::None,
        ));
    }
    // A tree that belongs to another soup: refused, naming both files.
    let o = dir.join("mismatch.exr");
    cases.push(case(
        ".kd of another soup",
        "kd2exr",
        &[
            &s(&a.soup),
            &s(&a.other_kd),
            "-o",
            &s(&o),
            "--width",
            "8",
            "--height",
            "8",
        ],
        1,
        &[&s(&a.soup), &s(&a.other_kd)],
        Out::Absent(o.clone()),
    ));
    cases.push(case(
        ".kd of another soup",
        "kd2exr",
        &[
            &s(&a.other_soup),
            &s(&a.kd),
            "-o",
            &s(&o),
            "--width",
            "8",
            "--height",
            "8",
        ],
        1,
        &[&s(&a.other_soup), &s(&a.kd)],
        Out::Absent(o.clone()),
    ));
    let o = dir.join("mismatch.hits");
    cases.push(case(
        ".kd of another soup",
        "raycast",
        &[&s(&a.other_soup), &s(&a.kd), &s(&rays), "-o", &s(&o)],
        1,
        &[&s(&a.other_soup), &s(&a.kd)],
        Out::Absent(o.clone()),
    ));
    // A stale cache entry (a tree of another soup under this soup's cache name) is
    // rebuilt, not trusted.
    let cache = dir.join("stale-cache");
    std::fs::create_dir_all(&cache).unwrap();
    let soup = Soup::read(&a.soup).unwrap();
    let entry = cache.join(kd.params.cache_name(&soup.geometry_hash));
    std::fs::copy(&a.other_kd, &entry).unwrap();
    cases.push(case(
        "stale --cache entry (tree of another soup)",
        "soup2kd",
        &[&s(&a.soup), "--cache", &s(&cache)],
        0,
        &["cache miss"],
        Out::Written(entry.clone()),
    ));
    check(cases);
    assert_eq!(
        KdFile::read(&entry).unwrap().geometry_hash,
        soup.geometry_hash
    );
}

#[test]
fn damaged_rays_files_are_refused() {
    let a = artifacts();
    let dir = a.p.root.clone();
    let head = |magic: &[u8], version: u32, count: u64| {
        [magic, &version.to_le_bytes(), &count.to_le_bytes()].concat()
    };
    let one_ray = [0u8; 32];
    let variants: Vec<(&str, Vec<u8>)> = vec![
        ("empty", vec![]),
        (
            "foreign (HITS given as rays)",
            [head(b"HITS", 1, 1), vec![0; 16]].concat(),
        ),
        (
            "old version 0",
            [head(b"RAYS", 0, 1), one_ray.to_vec()].concat(),
        ),
        (
            "truncated (count 2, one ray)",
            [head(b"RAYS", 1, 2), one_ray.to_vec()].concat(),
        ),
        (
            "count 10^12",
            [head(b"RAYS", 1, 1_000_000_000_000), one_ray.to_vec()].concat(),
        ),
        (
            "count 2^61 (count × 32 overflows)",
            [head(b"RAYS", 1, 1 << 61), one_ray.to_vec()].concat(),
        ),
        ("truncated header", b"RAYS\x01\0".to_vec()),
    ];
    let mut cases = Vec::new();
    for (i, (label, bytes)) in variants.into_iter().enumerate() {
        let p = dir.join(format!("bad{i}.rays"));
        std::fs::write(&p, bytes).unwrap();
        let o = dir.join(format!("hits{i}"));
        std::fs::write(&o, b"previous").unwrap();
        cases.push(case(
            &format!(".rays {label}"),
            "raycast",
            &[&s(&a.soup), &s(&a.kd), &s(&p), "-o", &s(&o)],
            1,
            &[&s(&p)],
            Out::Intact(o, b"previous".to_vec()),
        ));
    }
    check(cases);
}
