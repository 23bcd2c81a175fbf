//! Bad input never crashes a stage or loses data (issue 8; the table is docs/RELIABILITY.md).
//!
//! Every case runs a real binary on one bad input made in a temporary folder and checks
//! the exit code (1 for bad input, 2 for bad usage, 0 where the stage converts the rest
//! with a warning), that stderr names the input (file path, object name or byte offset),
//! that nothing panicked, and what happened to the output: not written, the previous file
//! left byte for byte, or (for warnings) written.
//!
//! Cases are tables; a table reports every failing case at once.

use formats::{soup::geometry_hash, KdFile, Soup};
use glam::Vec3;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};
use unitrace::{bin, run};

/// What must be true of the output file after the run.
enum Out {
    /// Not created.
    Absent(PathBuf),
    /// Held these bytes before the run and still does.
    Intact(PathBuf, Vec<u8>),
    /// Written (the stage converted what it could).
    Written(PathBuf),
    /// The stage writes nothing on this path (a usage error before any output exists).
    None,
}

struct Case {
    what: String,
    bin: &'static str,
    args: Vec<String>,
    code: i32,
    /// Stderr must contain each of these (the input's name, the object, the problem).
    names: Vec<String>,
    out: Out,
}

fn case(what: &str, bin: &'static str, args: &[&str], code: i32, names: &[&str], out: Out) -> Case {
    Case {
        what: what.to_string(),
        bin,
        args: args.iter().map(|s| s.to_string()).collect(),
        code,
        names: names.iter().map(|s| s.to_string()).collect(),
        out,
    }
}

/// Run every case, then fail once listing every case that did not hold. Each case also
/// prints a row (`--nocapture`) in the shape of the RELIABILITY.md table.
fn check(cases: Vec<Case>) {
    let mut failures = Vec::new();
    for c in &cases {
        let r = run(c.bin, &c.args);
        let first = r
            .stderr
            .lines()
            .find(|l| !l.trim().is_empty())
            .unwrap_or("");
        println!("| {} | {} | {} | {} |", c.what, c.bin, r.code, first);
        let mut bad = Vec::new();
        if r.code != c.code {
            bad.push(format!("exit code {} (want {})", r.code, c.code));
        }
        for n in &c.names {
            if !r.stderr.contains(n.as_str()) {
                bad.push(format!("stderr does not name `{n}`"));
            }
        }
        if c.code != 0 && r.stderr.lines().filter(|l| !l.is_empty()).count() == 0 {
            bad.push("no message".into());
        }
        match &c.out {
            Out::Absent(p) if p.exists() => bad.push(format!("{} was written", p.display())),
            Out::Intact(p, before) => match std::fs::read(p) {
                Ok(now) if &now == before => {}
                _ => bad.push(format!("{} changed", p.display())),
            },
            Out::Written(p) if !p.exists() => bad.push(format!("{} missing", p.display())),
            _ => {}
        }
        if !bad.is_empty() {
            failures.push(format!(
                "{} ({} {}): {}\n  stderr: {}",
                c.what,
                c.bin,
                c.args.join(" "),
                bad.join("; "),
                r.stderr.trim().replace('\n', "\n          ")
            ));
        }
    }
    assert!(
        failures.is_empty(),
        "{} of {} cases failed:\n{}",
        failures.len(),
        cases.len(),
        failures.join("\n")
    );
}

fn s(p: &Path) -> String {
    p.display().to_string()
}

// ---------------------------------------------------------------------------------------
// A tiny Unity project: YAML written the way Unity writes it.

const HEADER: &str = "%YAML 1.1\n%TAG !u! tag:unity3d.com,2011:\n";
const BUILTIN_MESH: &str = "0000000000000000e000000000000000";
const BUILTIN_EXTRA: &str = "0000000000000000f000000000000000";

/// GameObject `go` with Transform `go+1` at `pos` (a YAML flow map) under `father`.
fn object(go: i64, name: &str, pos: &str, father: i64, comps: &[i64]) -> String {
    let t = go + 1;
    let mut s = format!(
        "--- !u!1 &{go}\nGameObject:\n  m_ObjectHideFlags: 0\n  serializedVersion: 6\n  m_Component:\n  - component: {{fileID: {t}}}\n"
    );
    for c in comps {
        s += &format!("  - component: {{fileID: {c}}}\n");
    }
    s += &format!(
        "  m_Layer: 0\n  m_Name: {name}\n  m_IsActive: 1\n--- !u!4 &{t}\nTransform:\n  m_ObjectHideFlags: 0\n  m_GameObject: {{fileID: {go}}}\n  m_LocalRotation: {{x: 0, y: 0, z: 0, w: 1}}\n  m_LocalPosition: {pos}\n  m_LocalScale: {{x: 1, y: 1, z: 1}}\n  m_Children: []\n  m_Father: {{fileID: {father}}}\n"
    );
    s
}

/// A mesh object: GameObject `go`, Transform `go+1`, MeshFilter `go+2` (mesh `mesh`),
/// MeshRenderer `go+3` (material `mat`).
fn mesh_object(go: i64, name: &str, pos: &str, father: i64, mesh: &str, mat: &str) -> String {
    let (mf, mr) = (go + 2, go + 3);
    object(go, name, pos, father, &[mf, mr])
        + &format!(
            "--- !u!33 &{mf}\nMeshFilter:\n  m_GameObject: {{fileID: {go}}}\n  m_Mesh: {mesh}\n--- !u!23 &{mr}\nMeshRenderer:\n  m_GameObject: {{fileID: {go}}}\n  m_Enabled: 1\n  m_Materials:\n  - {mat}\n"
        )
}

fn cube(go: i64, name: &str, pos: &str, father: i64) -> String {
    mesh_object(
        go,
        name,
        pos,
        father,
        &format!("{{fileID: 10202, guid: {BUILTIN_MESH}, type: 0}}"),
        &format!("{{fileID: 10303, guid: {BUILTIN_EXTRA}, type: 0}}"),
    )
}

fn camera_and_light() -> String {
    object(10, "Main Camera", "{x: 0, y: 1, z: -10}", 0, &[12])
        + "--- !u!20 &12\nCamera:\n  m_GameObject: {fileID: 10}\n  m_Enabled: 1\n  m_ClearFlags: 2\n  m_BackGroundColor: {r: 0.2, g: 0.3, b: 0.5, a: 0}\n  near clip plane: 0.3\n  field of view: 60\n  orthographic: 0\n  orthographic size: 5\n  m_Depth: -1\n"
        + &object(20, "Sun", "{x: 0, y: 3, z: 0}", 0, &[22])
        + "--- !u!108 &22\nLight:\n  m_GameObject: {fileID: 20}\n  m_Enabled: 1\n  serializedVersion: 8\n  m_Type: 1\n  m_Color: {r: 1, g: 1, b: 1, a: 1}\n  m_Intensity: 1\n  m_Range: 10\n  m_SpotAngle: 30\n  m_Shadows:\n    m_Type: 0\n"
}

fn pos(x: f32, y: f32, z: f32) -> String {
    format!("{{x: {x}, y: {y}, z: {z}}}")
}

/// A PrefabInstance of the model (or prefab) with `guid`.
fn instance(id: i64, guid: &str) -> String {
    format!("--- !u!1001 &{id}\nPrefabInstance:\n  m_ObjectHideFlags: 0\n  serializedVersion: 2\n  m_Modification:\n    m_TransformParent: {{fileID: 0}}\n    m_Modifications: []\n    m_RemovedComponents: []\n  m_SourcePrefab: {{fileID: 100100000, guid: {guid}, type: 3}}\n")
}

fn meta(guid: &str) -> String {
    format!("fileFormatVersion: 2\nguid: {guid}\nModelImporter:\n  serializedVersion: 22\n  meshes:\n    globalScale: 1\n")
}

struct Project {
    _dir: tempfile::TempDir,
    root: PathBuf,
}

impl Project {
    fn new() -> Project {
        let dir = tempfile::tempdir().expect("tempdir");
        let root = dir.path().join("Proj");
        std::fs::create_dir_all(root.join("Assets")).expect("Assets");
        Project { _dir: dir, root }
    }
    /// Write `bytes` at `rel` (relative to the project root); returns the full path.
    fn file(&self, rel: &str, bytes: impl AsRef<[u8]>) -> PathBuf {
        let p = self.root.join(rel);
        std::fs::create_dir_all(p.parent().expect("parent")).expect("mkdir");
        std::fs::write(&p, bytes).expect("write");
        p
    }
    fn scene(&self, name: &str, body: &str) -> PathBuf {
        self.file(&format!("Assets/{name}.unity"), format!("{HEADER}{body}"))
    }
    fn out(&self, name: &str) -> PathBuf {
        self.root.join(name)
    }
}

/// Convert `scene` (must succeed) and return the soup.
fn convert(scene: &Path, out: &Path) -> Soup {
    let r = run("unity2soup", [s(scene), "-o".into(), s(out)]);
    assert_eq!(r.code, 0, "unity2soup {}:\n{}", scene.display(), r.stderr);
    Soup::read(out).expect("soup")
}

/// A project with one good scene converted to `good.soup` and built into `good.kd`, and a
/// second scene (`other.soup`, `other.kd`) with different geometry.
struct Artifacts {
    p: Project,
    soup: PathBuf,
    kd: PathBuf,
    other_soup: PathBuf,
    other_kd: PathBuf,
}

fn artifacts() -> Artifacts {
    let p = Project::new();
    let a = p.scene(
        "A",
        &(camera_and_light() + &cube(100, "Box", &pos(0.0, 0.0, 0.0), 0)),
    );
    let b = p.scene(
        "B",
        &(camera_and_light()
            + &cube(100, "Box", &pos(0.0, 0.0, 0.0), 0)
            + &cube(200, "Box2", &pos(2.0, 0.0, 0.0), 0)),
    );
    let (soup, other_soup) = (p.out("good.soup"), p.out("other.soup"));
    let (kd, other_kd) = (p.out("good.kd"), p.out("other.kd"));
    assert_eq!(convert(&a, &soup).triangles.len(), 12);
    assert_eq!(convert(&b, &other_soup).triangles.len(), 24);
    for (s_, k) in [(&soup, &kd), (&other_soup, &other_kd)] {
        let r = run("soup2kd", [s(s_), "-o".into(), s(k)]);
        assert_eq!(r.code, 0, "soup2kd:\n{}", r.stderr);
    }
    Artifacts {
        p,
        soup,
        kd,
        other_soup,
        other_kd,
    }
}

/// The artifact frame around `payload` with a correct checksum. The test package has no
/// BLAKE3 of its own; `geometry_hash` is BLAKE3 over f32 little-endian bytes, so the
/// payload (zero-padded to whole triangles, which the decoder never reaches) is handed
/// to it as triangles whose bits are the payload bytes.
fn frame(magic: &[u8; 8], version: u32, payload: &[u8]) -> Vec<u8> {
    let mut payload = payload.to_vec();
    payload.resize(payload.len().div_ceil(36) * 36, 0);
    let f = |b: &[u8]| f32::from_bits(u32::from_le_bytes(b.try_into().expect("4")));
    let tris: Vec<[Vec3; 3]> = payload
        .chunks_exact(36)
        .map(|t| {
            let v =
                |k: usize| Vec3::new(f(&t[k..k + 4]), f(&t[k + 4..k + 8]), f(&t[k + 8..k + 12]));
            [v(0), v(12), v(24)]
        })
        .collect();
    let mut out = magic.to_vec();
    out.extend_from_slice(&version.to_le_bytes());
    out.extend_from_slice(&(payload.len() as u64).to_le_bytes());
    out.extend_from_slice(&geometry_hash(&tris));
    out.extend_from_slice(&payload);
    out
}

/// Bad variants of one artifact file: (label, bytes). `len_at` is the payload offset of a
/// u64 element count to replace by 10¹².
fn bad_variants(good: &[u8], magic: &[u8; 8], len_at: usize) -> Vec<(&'static str, Vec<u8>)> {
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
        (
            "element count 10^12 (valid checksum)",
            frame(magic, 1, &huge),
        ),
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
    for (label, bytes) in bad_variants(&good_soup, formats::soup::MAGIC, 0) {
        n += 1;
        let p = dir.join(format!("bad{n}.soup"));
        std::fs::write(&p, bytes).unwrap();
        soup_inputs.push((label.to_string(), p));
    }
    // A string length of 2·10¹⁸ behind a valid checksum (the object name "Box"): bincode
    // used to allocate it before reading (found by cargo fuzz).
    let mut payload = good_soup[52..].to_vec();
    let at = payload.windows(3).position(|w| w == b"Box").unwrap() - 8;
    payload[at..at + 8].copy_from_slice(&0x2074_6c75_6166_6544u64.to_le_bytes());
    let p = dir.join("huge-name.soup");
    std::fs::write(&p, frame(formats::soup::MAGIC, 1, &payload)).unwrap();
    soup_inputs.push(("string length 2·10^18 (valid checksum)".into(), p));
    for (label, p) in &soup_inputs {
        let what = format!(".soup {label}");
        let ps = s(p);
        let o = dir.join(format!("o{n}"));
        n += 1;
        std::fs::write(&o, &prev).unwrap();
        cases.push(case(
            &what,
            "soup2kd",
            &[&ps, "-o", &s(&o)],
            1,
            &[&ps],
            Out::Intact(o.clone(), prev.clone()),
        ));
        cases.push(case(
            &what,
            "soup2obj",
            &[&ps, "-o", &s(&o)],
            1,
            &[&ps],
            Out::Intact(o.clone(), prev.clone()),
        ));
        cases.push(case(
            &what,
            "raycast",
            &[&ps, &s(&a.kd), &s(&rays), "-o", &s(&o)],
            1,
            &[&ps],
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
            &[&ps],
            Out::Intact(o.clone(), prev.clone()),
        ));
        let cache = dir.join(format!("cache{n}"));
        cases.push(case(
            &what,
            "soup2kd",
            &[&ps, "--cache", &s(&cache)],
            1,
            &[&ps],
            Out::None,
        ));
    }
    let mut kd_inputs: Vec<(String, PathBuf)> = vec![
        ("missing".into(), dir.join("nope.kd")),
        ("a directory (unreadable)".into(), dir.join("Assets")),
    ];
    for (label, bytes) in bad_variants(&good_kd, formats::kd::MAGIC, nodes_at) {
        n += 1;
        let p = dir.join(format!("bad{n}.kd"));
        std::fs::write(&p, bytes).unwrap();
        kd_inputs.push((label.to_string(), p));
    }
    kd_inputs.push(("a soup given as the tree".into(), a.soup.clone()));
    for (label, p) in &kd_inputs {
        let what = format!(".kd {label}");
        let ps = s(p);
        let o = dir.join(format!("o{n}"));
        n += 1;
        std::fs::write(&o, &prev).unwrap();
        cases.push(case(
            &what,
            "raycast",
            &[&s(&a.soup), &ps, &s(&rays), "-o", &s(&o)],
            1,
            &[&ps],
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
            &[&ps],
            Out::Intact(o.clone(), prev.clone()),
        ));
        cases.push(case(
            &what,
            "soup2kd",
            &["--stats", &ps],
            1,
            &[&ps],
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

#[test]
fn bad_usage_exits_2() {
    let a = artifacts();
    let o = a.p.out("x");
    let so = s(&a.soup);
    let k = s(&a.kd);
    let os = s(&o);
    check(vec![
        case("no arguments", "unity2soup", &[], 2, &["Usage"], Out::None),
        case(
            "unknown flag",
            "unity2soup",
            &["--frobnicate"],
            2,
            &["--frobnicate"],
            Out::None,
        ),
        case(
            "no output",
            "soup2kd",
            &[&so],
            2,
            &["-o"],
            Out::Absent(o.clone()),
        ),
        case(
            "-o and --cache",
            "soup2kd",
            &[&so, "-o", &os, "--cache", &os],
            2,
            &["--cache"],
            Out::Absent(o.clone()),
        ),
        case("no output", "soup2obj", &[&so], 2, &["--output"], Out::None),
        case(
            "missing rays argument",
            "raycast",
            &[&so, &k, "-o", &os],
            2,
            &["RAYS"],
            Out::Absent(o.clone()),
        ),
        case(
            "--width not a number",
            "kd2exr",
            &[&so, &k, "-o", &os, "--width", "wide"],
            2,
            &["wide"],
            Out::Absent(o.clone()),
        ),
        case(
            "--width -5",
            "kd2exr",
            &[&so, &k, "-o", &os, "--width", "-5"],
            2,
            &["-5"],
            Out::Absent(o.clone()),
        ),
    ]);
}

// ---------------------------------------------------------------------------------------
// Unity input.

#[test]
fn bad_unity_input_is_named_and_the_rest_converts() {
    let p = Project::new();
    let good = camera_and_light() + &cube(100, "Box", &pos(0.0, 0.0, 0.0), 0);
    let mut cases = Vec::new();
    let mut n = 0;
    let mut add = |cases: &mut Vec<Case>,
                   what: &str,
                   scene: &Path,
                   extra: &[&str],
                   code: i32,
                   names: &[&str]| {
        n += 1;
        let o = p.out(&format!("u{n}.soup"));
        let mut args = vec![s(scene), "-o".into(), s(&o)];
        args.extend(extra.iter().map(|s| s.to_string()));
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let out = if code == 0 {
            Out::Written(o.clone())
        } else {
            Out::Absent(o.clone())
        };
        cases.push(case(what, "unity2soup", &args, code, names, out));
    };

    // One document's YAML is broken (an unclosed flow map swallows its lines): the other
    // objects convert, and a warning names the document.
    let broken = p.scene(
        "Broken",
        &(good.clone()
            + "--- !u!1 &300\nGameObject:\n  m_Component:\n  - component: {fileID: 301\n  m_Name: [Half\n  m_IsActive: 1\n--- !u!4 &301\nTransform:\n  m_GameObject: {fileID: 300}\n  m_LocalPosition: {x: 1, y: 2, z:: }}}\n  m_Father: {fileID: 0}\n"
            + &cube(400, "After", &pos(3.0, 0.0, 0.0), 0)),
    );
    add(
        &mut cases,
        "malformed YAML in one document",
        &broken,
        &[],
        0,
        &["warning:", "Broken.unity", "fileID 300"],
    );
    add(
        &mut cases,
        "malformed YAML in one document, --strict",
        &broken,
        &["--strict"],
        1,
        &["--strict", "Broken.unity"],
    );

    let unknown = p.scene(
        "Unknown",
        &(good.clone()
            + "--- !u!987654 &500\nNoSuchClass:\n  m_GameObject: {fileID: 100}\n  weird: [1, 2, {a: b}]\n--- !u!114 &501\nMonoBehaviour:\n  m_GameObject: {fileID: 100}\n  m_Script: {fileID: 11500000, guid: 0123456789abcdef0123456789abcdef, type: 3}\n"),
    );
    add(
        &mut cases,
        "unknown classes (987654, MonoBehaviour)",
        &unknown,
        &[],
        0,
        &["12 triangles"],
    );

    let missing_ids = p.scene(
        "MissingIds",
        &(good.clone()
            + &cube(600, "Orphan", &pos(0.0, 2.0, 0.0), 4242)
            + &mesh_object(
                700,
                "NoSuchMesh",
                &pos(0.0, 4.0, 0.0),
                0,
                "{fileID: 10299, guid: 0000000000000000e000000000000000, type: 0}",
                "{fileID: 10303, guid: 0000000000000000f000000000000000, type: 0}",
            )),
    );
    add(
        &mut cases,
        "missing fileIDs (m_Father, builtin mesh)",
        &missing_ids,
        &[],
        0,
        &["warning:", "Orphan", "4242", "NoSuchMesh"],
    );

    let missing_guids = p.scene(
        "MissingGuids",
        &(good.clone()
            + &mesh_object(
                800,
                "LostMesh",
                &pos(0.0, 2.0, 0.0),
                0,
                "{fileID: 4300000, guid: 11111111111111111111111111111111, type: 3}",
                "{fileID: 2100000, guid: 22222222222222222222222222222222, type: 2}",
            )
            + &mesh_object(
                900,
                "LostMat",
                &pos(0.0, 4.0, 0.0),
                0,
                "{fileID: 10202, guid: 0000000000000000e000000000000000, type: 0}",
                "{fileID: 2100000, guid: 22222222222222222222222222222222, type: 2}",
            )
            + &instance(950, "33333333333333333333333333333333")),
    );
    add(
        &mut cases,
        "missing GUIDs (mesh, material, prefab)",
        &missing_guids,
        &[],
        0,
        &[
            "warning:",
            "11111111111111111111111111111111",
            "33333333333333333333333333333333",
            "LostMesh",
        ],
    );

    let cycle = p.scene(
        "Cycle",
        &(good.clone()
            + &cube(1000, "LoopA", &pos(0.0, 2.0, 0.0), 1101)
            + &cube(1100, "LoopB", &pos(0.0, 4.0, 0.0), 1001)
            + &cube(1200, "Self", &pos(0.0, 6.0, 0.0), 1201)),
    );
    add(
        &mut cases,
        "parent cycles (m_Father loops)",
        &cycle,
        &[],
        0,
        &["warning:", "LoopA", "Self", "cycle"],
    );

    for (label, v) in [
        ("NaN", "NaN"),
        ("Infinity", "Infinity"),
        ("-Infinity", "-Infinity"),
        ("hex NaN bits", "0x7fc00000(nan)"),
    ] {
        let sc = p.scene(
            &format!("NonFinite{}", label.replace(' ', "")),
            &(good.clone() + &cube(1300, "Bad", &format!("{{x: 0, y: {v}, z: 0}}"), 0)),
        );
        add(
            &mut cases,
            &format!("{label} in a position"),
            &sc,
            &[],
            1,
            &["Bad", "fileID 1300", "NaN or infinite"],
        );
    }
    // 1e38 is finite, but a parent scaled by 1e38 makes the child's world matrix overflow.
    let overflow = p.scene(
        "Overflow",
        &(good.clone()
            + &object(1400, "Big", &pos(0.0, 0.0, 0.0), 0, &[]).replace(
                "m_LocalScale: {x: 1, y: 1, z: 1}",
                "m_LocalScale: {x: 1e38, y: 1e38, z: 1e38}",
            )
            + &cube(1500, "Child", "{x: 1e38, y: 0, z: 0}", 1401)),
    );
    add(
        &mut cases,
        "1e38 position under a 1e38 scale (overflows)",
        &overflow,
        &[],
        1,
        &["Child", "NaN or infinite"],
    );
    let far = p.scene(
        "Far",
        &(good.clone() + &cube(1600, "Far", "{x: 1e38, y: 0, z: 0}", 0)),
    );
    add(
        &mut cases,
        "1e38 position (finite; 8 of 12 cube triangles collapse)",
        &far,
        &[],
        0,
        &["16 triangles", "8 degenerate dropped"],
    );

    let empty = p.scene("Empty", "");
    std::fs::write(&empty, b"").unwrap();
    add(
        &mut cases,
        "zero-byte scene",
        &empty,
        &[],
        1,
        &[&s(&empty), "empty"],
    );
    let latin1 = p.scene(
        "Latin1",
        &(good.clone() + &cube(1700, "Caf\u{e9}", &pos(0.0, 2.0, 0.0), 0)),
    );
    let mut bytes = std::fs::read(&latin1).unwrap();
    let at = bytes
        .windows(2)
        .position(|w| w == "\u{e9}".as_bytes())
        .unwrap();
    bytes.splice(at..at + 2, [0xE9]); // Latin-1 é: not UTF-8
    std::fs::write(&latin1, &bytes).unwrap();
    add(
        &mut cases,
        "non-UTF-8 bytes in a name",
        &latin1,
        &[],
        0,
        &["24 triangles"],
    );
    let utf16 = p.out("Assets/Utf16.unity");
    let wide: Vec<u8> = [0xFF, 0xFE]
        .into_iter()
        .chain(
            format!("{HEADER}{good}")
                .encode_utf16()
                .flat_map(u16::to_le_bytes),
        )
        .collect();
    std::fs::write(&utf16, wide).unwrap();
    add(
        &mut cases,
        "UTF-16 scene (not UTF-8)",
        &utf16,
        &[],
        1,
        &[&s(&utf16)],
    );
    let garbage = p.out("Assets/Garbage.unity");
    std::fs::write(&garbage, noise(4096, 7)).unwrap();
    add(
        &mut cases,
        "binary garbage as a scene",
        &garbage,
        &[],
        1,
        &[&s(&garbage)],
    );
    let missing = p.out("Assets/NotThere.unity");
    add(
        &mut cases,
        "missing scene",
        &missing,
        &[],
        1,
        &[&s(&missing)],
    );
    let dir_scene = p.root.join("Assets");
    add(
        &mut cases,
        "a directory as the scene",
        &dir_scene,
        &[],
        1,
        &[&s(&dir_scene)],
    );

    check(cases);

    // Two .meta files claim one GUID: one wins, with a warning naming both (its own
    // project, so the warning does not reach the cases above).
    let p = Project::new();
    let g = "44444444444444444444444444444444";
    p.file("Assets/A/one.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    p.file("Assets/A/one.obj.meta", meta(g));
    p.file(
        "Assets/B/two.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4 3\n",
    );
    p.file("Assets/B/two.obj.meta", meta(g));
    let collide = p.scene("Collide", &(good.clone() + &instance(1800, g)));
    let o = p.out("collide.soup");
    // The walk meets B/ before A/; the message names the one used first.
    check(vec![case(
        ".meta GUID collision",
        "unity2soup",
        &[&s(&collide), "-o", &s(&o)],
        0,
        &[
            "duplicate GUID",
            g,
            "B/two.obj and",
            "A/one.obj; using the first",
            "14 triangles",
        ],
        Out::Written(o),
    )]);
}

/// Deterministic noise (xorshift), so a failing case can be reproduced.
fn noise(len: usize, seed: u64) -> Vec<u8> {
    let mut x = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
    (0..len)
        .map(|_| {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x >> 24) as u8
        })
        .collect()
}

#[test]
fn asset_paths_never_escape_the_project() {
    let p = Project::new();
    // A material library and a model outside the project, reachable by `..` and by a
    // symlink inside Assets/.
    let outside = p.root.parent().unwrap().join("outside");
    std::fs::create_dir_all(&outside).unwrap();
    std::fs::write(
        outside.join("secret.mtl"),
        "newmtl red\nKd 0.123 0.456 0.789\n",
    )
    .unwrap();
    let g_out = "55555555555555555555555555555555";
    std::fs::write(
        outside.join("far.obj"),
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    )
    .unwrap();
    std::fs::write(outside.join("far.obj.meta"), meta(g_out)).unwrap();
    std::os::unix::fs::symlink(&outside, p.root.join("Assets/linked")).unwrap();
    // A symlink loop inside Assets/ must not hang the GUID index.
    std::os::unix::fs::symlink(p.root.join("Assets"), p.root.join("Assets/loop")).unwrap();
    let g = "66666666666666666666666666666666";
    p.file(
        "Assets/m/model.obj",
        "mtllib ../../../outside/secret.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\n",
    );
    p.file("Assets/m/model.obj.meta", meta(g));
    let scene = p.scene(
        "Escape",
        &(camera_and_light() + &instance(100, g) + &instance(200, g_out)),
    );
    let o = p.out("escape.soup");
    let r = run(
        "unity2soup",
        [s(&scene), "-o".into(), s(&o), "--list".into()],
    );
    assert_eq!(r.code, 0, "{}", r.stderr);
    let soup = Soup::read(&o).unwrap();
    // Only the model inside the project converts; the outside .mtl colour is not used.
    assert_eq!(soup.triangles.len(), 1, "{}", r.stderr);
    assert!(
        soup.materials
            .iter()
            .all(|m| (m.color - Vec3::new(0.123, 0.456, 0.789)).length() > 1e-3),
        "a colour was read from outside the project: {:?}",
        soup.materials
    );
    for want in ["secret.mtl", "outside the project", g_out] {
        assert!(
            r.stderr.contains(want),
            "stderr lacks `{want}`:\n{}",
            r.stderr
        );
    }
}

// ---------------------------------------------------------------------------------------
// OBJ models.

#[test]
fn bad_obj_models_are_named_by_file_and_line() {
    let p = Project::new();
    let good = camera_and_light() + &cube(100, "Box", &pos(0.0, 0.0, 0.0), 0);
    let tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
    let models: Vec<(&str, Vec<u8>, &[&str])> = vec![
        (
            "out-of-range index",
            format!("{tri}f 1 2 9\n").into_bytes(),
            &[":4:", "vertex index 9 out of range"],
        ),
        (
            "zero index",
            format!("{tri}f 0 1 2\n").into_bytes(),
            &[":4:", "vertex index 0 out of range"],
        ),
        (
            "negative index past the start",
            format!("{tri}f -1 -2 -4\n").into_bytes(),
            &[":4:", "vertex index -4 out of range"],
        ),
        (
            "normal index out of range",
            format!("{tri}vn 0 0 1\nf 1//1 2//2 3//1\n").into_bytes(),
            &[":5:", "normal index 2 out of range"],
        ),
        (
            "index past i64",
            format!("{tri}f 1 2 99999999999999999999\n").into_bytes(),
            &[":4:", "99999999999999999999"],
        ),
        (
            "bad number",
            format!("{tri}v 1 2 x\nf 1 2 3\n").into_bytes(),
            &[":4:", "bad number"],
        ),
        (
            "binary garbage",
            [b"v ".as_slice(), &noise(2048, 3)].concat(),
            &[":1:"],
        ),
        (
            "Git LFS pointer",
            b"version https://git-lfs.github.com/spec/v1\noid sha256:ab\nsize 9\n".to_vec(),
            &["git lfs pull"],
        ),
        ("zero-byte file (no faces)", vec![], &["no faces"]),
    ];
    let mut cases = Vec::new();
    for (i, (label, bytes, names)) in models.into_iter().enumerate() {
        let guid = format!("{:032x}", 0xabc000 + i);
        let rel = format!("Assets/bad{i}.obj");
        p.file(&rel, &bytes);
        p.file(&format!("{rel}.meta"), meta(&guid));
        let scene = p.scene(
            &format!("Obj{i}"),
            &(good.clone() + &instance(100_000, &guid)),
        );
        let mut names: Vec<&str> = names.to_vec();
        names.push(&rel);
        names.push("warning:");
        let o = p.out(&format!("obj{i}.soup"));
        // The model is skipped with a warning naming file and line; the scene converts.
        cases.push(case(
            &format!("OBJ: {label}"),
            "unity2soup",
            &[&s(&scene), "-o", &s(&o)],
            0,
            &names,
            Out::Written(o.clone()),
        ));
        let o = p.out(&format!("obj{i}-strict.soup"));
        cases.push(case(
            &format!("OBJ: {label}, --strict"),
            "unity2soup",
            &[&s(&scene), "-o", &s(&o), "--strict"],
            1,
            &[&rel],
            Out::Absent(o),
        ));
    }
    // Faces with fewer than 3 corners are skipped with a warning; the rest converts.
    let g = "77777777777777777777777777777777";
    p.file(
        "Assets/short.obj",
        format!("{tri}v 1 1 0\nf 1 2\nf 3\nf 1 2 3\nf 2 4 3\n"),
    );
    p.file("Assets/short.obj.meta", meta(g));
    let scene = p.scene("Short", &(good.clone() + &instance(100_000, g)));
    let o = p.out("short.soup");
    cases.push(case(
        "OBJ: faces with 2 and 1 corners",
        "unity2soup",
        &[&s(&scene), "-o", &s(&o)],
        0,
        &[
            "Assets/short.obj",
            "2 faces with fewer than 3 corners",
            "14 triangles",
        ],
        Out::Written(o),
    ));
    // A NaN vertex is an error naming the object that uses the model.
    let g = "88888888888888888888888888888888";
    p.file("Assets/nan.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n");
    p.file("Assets/nan.obj.meta", meta(g));
    let scene = p.scene("Nan", &(good.clone() + &instance(100_000, g)));
    let o = p.out("nan.soup");
    cases.push(case(
        "OBJ: NaN vertex",
        "unity2soup",
        &[&s(&scene), "-o", &s(&o)],
        1,
        &["nan.obj", "NaN or infinite"],
        Out::Absent(o),
    ));
    check(cases);
}

#[test]
fn absurd_obj_polygons_convert_in_bounded_time() {
    // One 20 000-corner non-convex (star) face: ear clipping is cubic in the corner
    // count, so a face this large must take the bounded path.
    let p = Project::new();
    let n = 20_000;
    let mut text = String::new();
    for i in 0..n {
        let a = i as f32 / n as f32 * std::f32::consts::TAU;
        let r = if i % 2 == 0 { 1.0 } else { 0.5 };
        text += &format!("v {} {} 0\n", r * a.cos(), r * a.sin());
    }
    text += "f";
    for i in 1..=n {
        text += &format!(" {i}");
    }
    text += "\n";
    let g = "99999999999999999999999999999999";
    p.file("Assets/star.obj", text);
    p.file("Assets/star.obj.meta", meta(g));
    let scene = p.scene("Star", &(camera_and_light() + &instance(100, g)));
    let o = p.out("star.soup");
    let soup = convert(&scene, &o);
    // A polygon of n corners makes n − 2 triangles (none are degenerate here).
    assert_eq!(
        soup.triangles.len() as u64 + soup.dropped_degenerate,
        n as u64 - 2
    );
}

// ---------------------------------------------------------------------------------------
// Renderer options.

#[test]
fn absurd_render_options_are_refused_before_work() {
    let a = artifacts();
    let o = a.p.out("r.exr");
    let (so, k, os) = (s(&a.soup), s(&a.kd), s(&o));
    let r = |extra: &[&str]| -> Vec<String> {
        let mut v: Vec<String> = [so.as_str(), k.as_str(), "-o", os.as_str()]
            .iter()
            .map(|s| s.to_string())
            .collect();
        v.extend(extra.iter().map(|s| s.to_string()));
        v
    };
    let mk = |what: &str, extra: &[&str], names: &[&str]| {
        let args = r(extra);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        case(what, "kd2exr", &args, 1, names, Out::Absent(o.clone()))
    };
    check(vec![
        mk("--width 0", &["--width", "0"], &["--width"]),
        mk("--height 0", &["--height", "0"], &["--height"]),
        mk("--spp 0", &["--spp", "0"], &["--spp"]),
        mk(
            "absurd resolution 10^6 × 10^6",
            &["--width", "1000000", "--height", "1000000"],
            &["1000000"],
        ),
        mk(
            "crop outside the image",
            &[
                "--width",
                "64",
                "--height",
                "64",
                "--crop",
                "100,100,120,120",
            ],
            &["--crop"],
        ),
        mk(
            "crop x1 < x0",
            &["--width", "64", "--height", "64", "--crop", "40,0,20,10"],
            &["--crop"],
        ),
        mk("unknown AOV", &["--aov", "depth,colour"], &["colour"]),
        mk("NaN exposure", &["--exposure", "NaN"], &["--exposure"]),
    ]);
    // 16k × 16k with every AOV: either refused before any work (naming the memory it
    // needs and has), or it fits and starts; never killed by the OOM killer or a failed
    // allocation. A render that fits is stopped after 20 s: only the decision is tested.
    let all = "depth,normal,albedo,object";
    let mut child = Command::new(bin("kd2exr"))
        .args(r(&["--width", "16384", "--height", "16384", "--aov", all]))
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn kd2exr");
    let t = Instant::now();
    let status = loop {
        if let Some(st) = child.try_wait().expect("try_wait") {
            break Some(st);
        }
        if t.elapsed() > Duration::from_secs(20) {
            let _ = child.kill();
            let _ = child.wait();
            break None;
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    let mut err = String::new();
    if let Some(mut e) = child.stderr.take() {
        use std::io::Read;
        let _ = e.read_to_string(&mut err);
    }
    assert!(!err.contains("panicked"), "{err}");
    match status {
        Some(st) => {
            println!("16k×16k with AOVs: exit {:?} after {:?}: {}", st.code(), t.elapsed(), err.lines().next().unwrap_or(""));
            assert_eq!(st.code(), Some(1), "{err}");
            assert!(err.contains("16384×16384") && err.contains("GiB"), "{err}");
            assert!(!o.exists());
        }
        None => println!("16k×16k with AOVs fits in this machine's memory: rendering started (stopped after 20 s)"),
    }
    // The same size rendered as a 16×16 crop needs only the crop's memory.
    let crop = run(
        "kd2exr",
        r(&[
            "--width",
            "16384",
            "--height",
            "16384",
            "--aov",
            all,
            "--crop",
            "0,0,16,16",
        ]),
    );
    assert_eq!(crop.code, 0, "{}", crop.stderr);
}

// ---------------------------------------------------------------------------------------
// Atomic outputs.

/// A soup of `n` random small triangles in a 100 m cube.
fn big_soup(path: &Path, n: usize) {
    let mut soup = Soup::empty();
    let bytes = noise(n * 12, 11);
    let f = |i: usize| bytes[i] as f32 / 255.0;
    for t in 0..n {
        let c = Vec3::new(f(t * 12), f(t * 12 + 1), f(t * 12 + 2)) * 100.0;
        let v = |k: usize| c + Vec3::new(f(t * 12 + k), f(t * 12 + k + 1), f(t * 12 + k + 2)) - 0.5;
        soup.triangles.push([v(3), v(6), v(9)]);
        soup.normals.push([Vec3::Z; 3]);
        soup.tri_material.push(0);
        soup.tri_object.push(0);
    }
    soup.objects.push(formats::Object {
        name: "noise".into(),
        source: "test".into(),
    });
    soup.materials.push(formats::Material::unity_default());
    soup.camera.position = Vec3::new(50.0, 50.0, -150.0);
    soup.seal();
    soup.write(path).unwrap();
}

/// Start `name args`, let it run `after`, kill -9 it; returns whether it was still
/// running when killed (so the kill really landed mid-run).
fn kill_mid_run(name: &str, args: &[String], after: Duration) -> bool {
    let mut child = Command::new(bin(name))
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("spawn");
    std::thread::sleep(after);
    let running = child.try_wait().expect("try_wait").is_none();
    let _ = child.kill(); // SIGKILL
    let _ = child.wait();
    running
}

/// Files in `dir` apart from `keep` that a user or a later stage could mistake for
/// output: anything but the writers' hidden `.unitrace-*.tmp` temporaries.
fn litter(dir: &Path, keep: &[&Path]) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .filter_map(Result::ok)
        .map(|e| e.path())
        .filter(|p| !keep.contains(&p.as_path()))
        .filter_map(|p| p.file_name().map(|n| n.to_string_lossy().into_owned()))
        .filter(|n| !(n.starts_with(".unitrace-") && n.ends_with(".tmp")))
        .collect()
}

#[test]
fn killed_stages_leave_the_previous_output_intact() {
    let dir = tempfile::tempdir().unwrap();
    let soup = dir.path().join("big.soup");
    big_soup(&soup, 300_000);
    let out = dir.path().join("out");
    std::fs::create_dir_all(&out).unwrap();
    let kd = out.join("big.kd");
    // A previous, complete tree at the output path.
    let r = run("soup2kd", [s(&soup), "-o".into(), s(&kd)]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    let mut before = std::fs::read(&kd).unwrap();
    // Other parameters than the first tree's (so a run that lands is seen), and slow ones
    // (a low traversal cost and a deep bound make a big tree).
    let args = vec![
        s(&soup),
        "-o".into(),
        s(&kd),
        "--traversal-cost".into(),
        "1".into(),
        "--max-depth".into(),
        "40".into(),
    ];
    let mut landed = 0;
    for ms in [150, 400, 700] {
        let killed = kill_mid_run("soup2kd", &args, Duration::from_millis(ms));
        let now = std::fs::read(&kd).unwrap();
        if killed {
            landed += 1;
            assert_eq!(
                now,
                before,
                "soup2kd killed after {ms} ms changed {}",
                kd.display()
            );
        } else {
            // It finished before the kill: its whole tree, nothing half-written.
            KdFile::read(&kd).expect("a finished run leaves a complete tree");
            before = now;
        }
        assert_eq!(litter(&out, &[&kd]), Vec::<String>::new());
    }
    assert!(
        landed > 0,
        "soup2kd finished before every kill: make the input bigger"
    );
    KdFile::read(&kd).expect("the previous tree still reads");

    // kd2exr: a previous image, then a render killed mid-way.
    let exr = out.join("img.exr");
    let small = ["--width", "32", "--height", "24"].map(String::from);
    let mut a = vec![s(&soup), s(&kd), "-o".into(), s(&exr)];
    a.extend(small);
    let r = run("kd2exr", &a);
    assert_eq!(r.code, 0, "{}", r.stderr);
    let before = std::fs::read(&exr).unwrap();
    let mut a = vec![s(&soup), s(&kd), "-o".into(), s(&exr)];
    a.extend(
        [
            "--width",
            "3000",
            "--height",
            "3000",
            "--spp",
            "16",
            "--threads",
            "1",
        ]
        .map(String::from),
    );
    assert!(
        kill_mid_run("kd2exr", &a, Duration::from_millis(1500)),
        "kd2exr finished before the kill"
    );
    assert_eq!(
        std::fs::read(&exr).unwrap(),
        before,
        "kd2exr killed mid-render changed {}",
        exr.display()
    );
    assert_eq!(litter(&out, &[&kd, &exr]), Vec::<String>::new());
}

#[test]
fn concurrent_cache_builds_both_succeed() {
    let dir = tempfile::tempdir().unwrap();
    let soup = dir.path().join("s.soup");
    big_soup(&soup, 60_000);
    let cache = dir.path().join("cache");
    let spawn = || {
        Command::new(bin("soup2kd"))
            .args([s(&soup), "--cache".into(), s(&cache), "--json".into()])
            .output()
            .expect("spawn")
    };
    let (a, b) = std::thread::scope(|sc| {
        let a = sc.spawn(spawn);
        let b = sc.spawn(spawn);
        (a.join().unwrap(), b.join().unwrap())
    });
    for o in [&a, &b] {
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(o.status.success(), "{err}");
        assert!(!err.contains("panicked"), "{err}");
    }
    let entries: Vec<PathBuf> = std::fs::read_dir(&cache)
        .unwrap()
        .filter_map(Result::ok)
        .map(|e| e.path())
        .collect();
    assert_eq!(entries.len(), 1, "{entries:?}");
    let kd = KdFile::read(&entries[0]).unwrap();
    assert_eq!(kd.geometry_hash, Soup::read(&soup).unwrap().geometry_hash);
    // A third run is a cache hit on the same entry.
    let r = run(
        "soup2kd",
        [s(&soup), "--cache".into(), s(&cache), "--json".into()],
    );
    assert_eq!(r.json()["cache"], "hit");
}
