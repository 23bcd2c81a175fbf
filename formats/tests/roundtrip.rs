use formats::texture::{Filter, Wrap};
use formats::*;
use glam::{Vec2, Vec3};
use std::path::Path;

fn sample_soup() -> Soup {
    let mut s = Soup::empty();
    // Two triangles sharing vertex 1 (X).
    s.positions = vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z, Vec3::ONE];
    s.triangles = vec![[0, 1, 2], [3, 1, 4]];
    s.normals = vec![Vec3::Z, Vec3::Z, Vec3::Z, Vec3::Y, Vec3::Y];
    s.tri_material = vec![0, 0];
    s.tri_object = vec![0, 0];
    s.objects = vec![Object {
        layer: 9,
        cast_shadows: CastShadows::ShadowsOnly,
        receive_shadows: false,
        ..Object::new("Cube", "builtin:Cube")
    }];
    s.uvs = vec![
        Vec2::ZERO,
        Vec2::X,
        Vec2::Y,
        Vec2::ONE,
        Vec2::new(-1.0, 2.0),
    ];
    s.materials = vec![Material {
        normal_map: Some(NormalMap {
            map: TextureRef {
                texture: 0,
                tiling: Tiling::default(),
            },
            scale: 0.5,
        }),
        emission: Vec3::new(0.5, 2.0, 0.0),
        occlusion_map: Some(OcclusionMap {
            map: TextureRef {
                texture: 0,
                tiling: Tiling::default(),
            },
            strength: 0.6,
        }),
        metallic_map: Some(MetallicMap {
            map: TextureRef {
                texture: 0,
                tiling: Tiling::default(),
            },
            smoothness: 0.8,
        }),
        emission_map: Some(TextureRef {
            texture: 0,
            tiling: Tiling {
                scale: [1.0, 3.0],
                offset: [0.0, 0.25],
            },
        }),
        albedo_map: Some(TextureRef {
            texture: 0,
            tiling: Tiling {
                scale: [2.0, -1.0],
                offset: [0.5, 0.0],
            },
        }),
        opacity: 0.75,
        alpha: Alpha::Cutout { cutoff: 0.5 },
        ..Material::unity_default()
    }];
    s.textures = vec![Texture {
        source: "Assets/T.png".into(),
        width: 2,
        height: 1,
        texels: vec![255, 0, 0, 255, 0, 128, 0, 64],
        srgb: true,
        wrap_u: Wrap::Mirror,
        wrap_v: Wrap::Clamp,
        filter: Filter::Point,
        mipmaps: false,
    }];
    s.lights = vec![Light {
        name: "Point Light".into(),
        kind: LightKind::Spot {
            angle: 30.0,
            inner_angle: 20.0,
        },
        position: Vec3::new(1.0, 2.0, 3.0),
        direction: -Vec3::Y,
        color: Vec3::ONE,
        intensity: 1.5,
        range: 10.0,
        attenuation: Attenuation::Universal,
        shadows: Shadows::Soft,
        shadow_radius: 0.1,
        shadow_strength: 0.75,
        culling_mask: 0xffff_fdff,
    }];
    s.environment.fog = Some(Fog {
        mode: FogMode::Linear {
            start: 2.0,
            end: 30.0,
        },
        colour: Vec3::new(0.3, 0.4, 0.5),
    });
    s.camera.far = 250.0;
    s.environment.sky = Some(Sky::Procedural(ProceduralSky {
        sun_disk: SunDisk::Simple,
        sun_size: 0.04,
        sun_size_convergence: 5.0,
        atmosphere_thickness: 0.5,
        exposure: 1.3,
        sky_tint: Vec3::splat(0.2),
        ground: Vec3::splat(0.1),
        sun_direction: Vec3::Y,
        sun_colour: Vec3::ONE,
    }));
    s.warnings = vec!["a warning".into()];
    s.seal();
    s
}

fn sample_kd() -> KdFile {
    KdFile {
        geometry_hash: sample_soup().geometry_hash,
        params: BuildParams::default(),
        stats: TreeStats {
            triangles: 2,
            nodes: 3,
            leaves: 2,
            ..Default::default()
        },
        bounds: [Vec3::ZERO, Vec3::ONE],
        nodes: vec![
            KdNode::interior(0, 0.5, 2),
            KdNode::leaf(1, 0),
            KdNode::leaf(2, 1),
        ],
        leaf_tris: vec![0, 0, 1],
    }
}

#[test]
fn soup_round_trips_through_a_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("a.soup");
    let s = sample_soup();
    s.write(&path).unwrap();
    assert_eq!(Soup::read(&path).unwrap(), s);
    let bytes = std::fs::read(&path).unwrap();
    assert_eq!(&bytes[..8], b"UTSOUP\0\0");
    assert_eq!(u32::from_le_bytes(bytes[8..12].try_into().unwrap()), 14);
    // Nothing but the artifact is left in the folder (the temp file was renamed).
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    // A gamma-space project's soup says so.
    let mut g = sample_soup();
    g.environment.color_space = formats::ColorSpace::Gamma;
    g.write(&path).unwrap();
    assert_eq!(Soup::read(&path).unwrap(), g);
    assert_ne!(g, s);
    // So does a URP project's shadow distance.
    let mut u = sample_soup();
    u.environment.shadow_distance = Some(ShadowDistance {
        distance: 42.0,
        border: 0.1,
    });
    u.write(&path).unwrap();
    assert_eq!(Soup::read(&path).unwrap(), u);
    // And the environment reflection's intensity.
    let mut r = sample_soup();
    r.environment.reflection = 0.75;
    r.write(&path).unwrap();
    assert_eq!(Soup::read(&path).unwrap().environment.reflection, 0.75);
}

#[test]
fn an_environment_reflection_must_be_a_finite_intensity() {
    for r in [-0.5, f32::NAN, f32::INFINITY] {
        refused(
            &|s| s.environment.reflection = r,
            &format!("environment reflection intensity {r}"),
        );
    }
}

#[test]
fn a_shadow_distance_fades_as_urp_computes_it_and_must_be_sane() {
    let d = ShadowDistance {
        distance: 50.0,
        border: 0.2,
    };
    // URP's fade runs linearly in d² from (0.8 · 50)² = 1600 to 2500.
    let (scale, bias) = d.scale_bias(50.0);
    let fade = |d2: f32| (d2 * scale + bias).clamp(0.0, 1.0);
    assert!((scale - 1.0 / 900.0).abs() < 1e-9 && (bias + 1600.0 / 900.0).abs() < 1e-5);
    assert!((fade(1600.0)).abs() < 1e-5 && (fade(2050.0) - 0.5).abs() < 1e-5);
    assert_eq!(fade(2500.0 + 1.0), 1.0);
    // A near far plane caps it; no border cuts shadows off at the distance.
    let mut camera = Soup::empty().camera;
    camera.far = 30.0;
    assert_eq!(d.far(&camera), 30.0);
    camera.far = 0.0;
    assert_eq!(
        d.far(&camera),
        50.0,
        "no far plane beyond the near one: no cap"
    );
    let cut = ShadowDistance { border: 0.0, ..d };
    let (scale, bias) = cut.scale_bias(50.0);
    assert_eq!(
        (
            (2499.0 * scale + bias).max(0.0),
            2501.0 * scale + bias >= 1.0
        ),
        (0.0, true)
    );
    for (distance, border) in [
        (0.0, 0.2),
        (f32::INFINITY, 0.2),
        (10.0, 1.5),
        (10.0, f32::NAN),
    ] {
        refused(
            &|s| s.environment.shadow_distance = Some(ShadowDistance { distance, border }),
            &format!("shadow distance {distance} with border {border}"),
        );
    }
}

/// A killed writer's temporary is removed by the next write into its folder once it is
/// stale; a fresh one (a writer still at work) and other files are left alone.
#[test]
fn writes_remove_the_stale_temporaries_of_killed_writers() {
    let dir = tempfile::tempdir().unwrap();
    let put = |name: &str, age: u64| {
        let p = dir.path().join(name);
        let f = std::fs::File::create(&p).unwrap();
        let t = std::time::SystemTime::now() - std::time::Duration::from_secs(age);
        f.set_modified(t).unwrap();
        p
    };
    let stale = envelope::STALE_TEMP_SECONDS;
    let killed = put(".unitrace-killed.tmp", stale + 60);
    let working = put(".unitrace-working.tmp", stale - 60);
    let other = put(".other-old.tmp", stale + 60);
    let user = put("notes.unitrace-.tmp", stale + 60);
    sample_soup().write(&dir.path().join("a.soup")).unwrap();
    assert!(!killed.exists());
    assert!(working.exists() && other.exists() && user.exists());
    envelope::write_atomic(&dir.path().join("b.png"), b"x").unwrap();
    let mut names: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    names.sort();
    let want = [
        ".other-old.tmp",
        ".unitrace-working.tmp",
        "a.soup",
        "b.png",
        "notes.unitrace-.tmp",
    ];
    assert_eq!(names, want);
}

/// `Soup::write` streams the payload into the file, its arrays as blocks, and patches the
/// header afterwards; the file must be the very bytes `to_bytes` frames in memory, and those
/// the bytes of the struct's own serde encoding that SOUP.md documents.
#[test]
fn streamed_soup_file_is_the_encoded_bytes() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("big.soup");
    let mut s = sample_soup();
    let n = 100_000;
    s.positions = (0..n)
        .flat_map(|i| {
            let f = i as f32;
            [
                Vec3::new(f, 0.0, 1.0),
                Vec3::new(0.0, f, 2.0),
                Vec3::ONE * f,
            ]
        })
        .collect();
    // Each triangle shares its first vertex with the previous one.
    s.triangles = (0..n as u32)
        .map(|i| [3 * i.saturating_sub(1), 3 * i + 1, 3 * i + 2])
        .collect();
    s.normals = vec![Vec3::Y; 3 * n];
    s.uvs = vec![Vec2::X; 3 * n];
    s.tri_material = vec![0; n];
    s.tri_object = vec![0; n];
    s.warnings = (0..2000)
        .map(|i| format!("warning {i} {}", "x".repeat(i)))
        .collect();
    // Texels larger than the writer's buffer pass through it as one block.
    s.textures[0].width = 256;
    s.textures[0].height = 256;
    s.textures[0].texels = (0..256 * 256 * 4).map(|i| (i * 7 % 251) as u8).collect();
    s.seal();
    // The geometry hash is over the coordinates as f32 little-endian, then the indices as
    // u32 little-endian, however it is computed.
    let mut le = Vec::new();
    for v in &s.positions {
        for c in v.to_array() {
            le.extend_from_slice(&c.to_le_bytes());
        }
    }
    for t in &s.triangles {
        for i in t {
            le.extend_from_slice(&i.to_le_bytes());
        }
    }
    assert_eq!(&s.geometry_hash, blake3::hash(&le).as_bytes());
    s.write(&path).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    assert!(bytes.len() > 4 << 20, "{} bytes", bytes.len());
    assert!(bytes == s.to_bytes(&path).unwrap());
    let config = bincode::config::standard()
        .with_little_endian()
        .with_fixed_int_encoding();
    let serde_payload = bincode::serde::encode_to_vec(&s, config).unwrap();
    assert!(bytes[52..] == serde_payload[..]);
    assert_eq!(Soup::read(&path).unwrap(), s);
}

/// Texels are encoded as bytes (one block); bincode lays those out exactly as the
/// `Vec<u8>` that SOUP.md documents.
#[test]
fn texel_bytes_encode_as_a_vec_of_u8() {
    let config = bincode::config::standard()
        .with_little_endian()
        .with_fixed_int_encoding();
    let texels: Vec<u8> = (0..=255).collect();
    let as_seq = bincode::serde::encode_to_vec(&texels, config).unwrap();
    let as_bytes = bincode::serde::encode_to_vec(serde_bytes::Bytes::new(&texels), config).unwrap();
    assert_eq!(as_seq.len(), 8 + 256);
    assert_eq!(as_seq, as_bytes);
}

#[test]
fn kd_round_trips() {
    let p = Path::new("t.kd");
    let k = sample_kd();
    let bytes = k.to_bytes(p).unwrap();
    assert_eq!(KdFile::from_bytes(&bytes, p).unwrap(), k);
    // Nodes and leaf lists are written as blocks; the bytes are still the struct's serde
    // encoding that KD.md documents.
    let config = bincode::config::standard()
        .with_little_endian()
        .with_fixed_int_encoding();
    assert!(bytes[52..] == bincode::serde::encode_to_vec(&k, config).unwrap()[..]);
}

#[test]
fn truncated_foreign_old_and_corrupt_files_are_named_errors() {
    let p = Path::new("scene.soup");
    let good = sample_soup().to_bytes(p).unwrap();
    let cases: Vec<(Vec<u8>, &str)> = vec![
        (vec![], "empty"),
        (good[..30].to_vec(), "truncated"),
        (good[..good.len() - 1].to_vec(), "truncated"),
        (
            b"\x89PNG\r\n\x1a\nxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxx".to_vec(),
            "not a soup",
        ),
        (sample_kd().to_bytes(p).unwrap(), "not a soup"),
        (
            {
                let mut b = good.clone();
                b[8] = 0;
                b
            },
            "version 0",
        ),
        (
            {
                let mut b = good.clone();
                let mid = b.len() / 2 + 10;
                b[mid] ^= 0x40;
                b
            },
            "checksum",
        ),
    ];
    for (bytes, want) in cases {
        let msg = Soup::from_bytes(&bytes, p).unwrap_err().to_string();
        assert!(msg.starts_with("scene.soup:"), "{msg}");
        assert!(msg.contains(want), "{msg} should mention {want}");
    }
}

/// Files of a mebibyte and more are mapped rather than read: the same tree comes back, and
/// a flipped byte, a cut-off end or stray bytes are the same named errors as in memory.
#[test]
fn large_files_read_through_a_mapping_as_small_ones_do() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("big.kd");
    let mut k = sample_kd();
    // Two leaves listing 150,000 triangles each: 1.2 MB of leaf lists.
    k.leaf_tris = (0..300_000u32).map(|i| i % 2).collect();
    k.nodes = vec![
        KdNode::interior(0, 0.5, 2),
        KdNode::leaf(150_000, 0),
        KdNode::leaf(150_000, 150_000),
    ];
    k.write(&path).unwrap();
    let len = std::fs::metadata(&path).unwrap().len();
    assert!(len > 1 << 20, "{len} bytes: below the mapping threshold");
    assert_eq!(KdFile::read(&path).unwrap(), k);
    let good = std::fs::read(&path).unwrap();
    let cases: [(Vec<u8>, &str); 3] = [
        (
            {
                let mut b = good.clone();
                b[good.len() / 2] ^= 1;
                b
            },
            "checksum",
        ),
        (good[..good.len() - 4].to_vec(), "truncated"),
        ([&good[..], &[0u8; 3]].concat(), "3 stray bytes"),
    ];
    for (bytes, want) in cases {
        std::fs::write(&path, &bytes).unwrap();
        let msg = KdFile::read(&path).unwrap_err().to_string();
        assert!(msg.starts_with(&path.display().to_string()), "{msg}");
        assert!(msg.contains(want), "{msg} should mention {want}");
    }
}

/// `sample_soup` grown to 300,000 triangles: arrays of 1–3.6 MB, copied out and checked
/// in blocks on all cores.
fn large_soup() -> Soup {
    let mut s = sample_soup();
    for i in 0..300_000 - 2 {
        let x = i as f32;
        let corners = [
            Vec3::new(x, 0.0, 0.0),
            Vec3::new(x, 1.0, 0.0),
            Vec3::new(x, 0.0, 1.0),
        ];
        s.push_triangle(corners, [Vec3::X; 3], Some([Vec2::ZERO, Vec2::X, Vec2::Y]));
        s.tri_material.push(0);
        s.tri_object.push(0);
    }
    s.seal();
    s
}

/// Large arrays come back as written (blocks of a mebibyte, a short last one), and a check
/// names the first bad entry, whichever block and thread finds it.
#[test]
fn large_arrays_round_trip_and_name_their_first_bad_entry() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("large.soup");
    let s = large_soup();
    assert!(s.triangles.len() * 12 > 3 << 20);
    s.write(&path).unwrap();
    assert_eq!(Soup::read(&path).unwrap(), s);
    type Edit<'a> = (&'a dyn Fn(&mut Soup), &'a str);
    let cases: [Edit; 4] = [
        (
            &|s| {
                s.triangles[290_000][0] = u32::MAX;
                s.triangles[200_001][2] = 900_001;
            },
            "triangle 200001 names vertices [600002, 600003, 900001] of 899999",
        ),
        (
            &|s| {
                s.positions[800_000].x = f32::INFINITY;
                s.positions[70_000].z = f32::NAN;
            },
            "vertex 70000 is not finite",
        ),
        (
            &|s| {
                s.tri_object[299_999] = 3;
                s.tri_object[131_072] = 1;
            },
            "triangle 131072 names object 1 of 1",
        ),
        (
            &|s| s.uvs[899_998].y = f32::NAN,
            "vertex 899998 has a non-finite UV",
        ),
    ];
    for (edit, want) in cases {
        refused_edit_of(s.clone(), edit, want);
    }
}

/// A soup's key, its checksum verified first.
fn read_key(path: &Path) -> Result<SoupKey, FormatError> {
    envelope::Checked::<Soup>::open(path)?.key()
}

/// A soup's geometry, its checksum verified first.
fn read_geometry(path: &Path) -> Result<SoupGeometry, FormatError> {
    envelope::Checked::<Soup>::open(path)?.geometry()
}

/// `soup2kd --cache` finds a tree from a soup's key and a tree's header: both read as the
/// full reads do, and only after the whole payload's checksum.
#[test]
fn keys_and_headers_match_the_full_reads() {
    let dir = tempfile::tempdir().unwrap();
    for (name, soup) in [("small.soup", sample_soup()), ("large.soup", large_soup())] {
        let path = dir.path().join(name);
        soup.write(&path).unwrap();
        let key = read_key(&path).unwrap();
        assert_eq!(key.triangles, soup.triangles.len());
        assert_eq!(key.geometry_hash, soup.geometry_hash);
        let mut bytes = std::fs::read(&path).unwrap();
        let at = bytes.len() - 40;
        bytes[at] ^= 1;
        std::fs::write(&path, &bytes).unwrap();
        let msg = read_key(&path).unwrap_err().to_string();
        assert!(msg.contains("checksum"), "{msg}");
    }
    // A well-framed payload that ends inside the arrays.
    let path = dir.path().join("short.soup");
    let good = sample_soup().to_bytes(&path).unwrap();
    std::fs::write(&path, framed(&good, &good[52..60 + 5 * 12])).unwrap();
    let msg = read_key(&path).unwrap_err().to_string();
    assert!(msg.contains("inside the count of normals"), "{msg}");

    let path = dir.path().join("t.kd");
    let k = sample_kd();
    k.write(&path).unwrap();
    let h = KdFile::read_header(&path).unwrap();
    assert_eq!(
        (h.geometry_hash, h.params, h.stats, h.bounds),
        (k.geometry_hash, k.params, k.stats.clone(), k.bounds)
    );
}

/// `soup2kd` builds from a soup's geometry alone: the positions and triangles as the full
/// read gives them, checked as it checks them; what the build does not read is not checked.
#[test]
fn geometry_reads_match_the_full_reads_and_check_the_geometry() {
    let dir = tempfile::tempdir().unwrap();
    for (name, soup) in [("small.soup", sample_soup()), ("large.soup", large_soup())] {
        let path = dir.path().join(name);
        soup.write(&path).unwrap();
        let g = read_geometry(&path).unwrap();
        assert_eq!(g.positions, soup.positions);
        assert_eq!(g.triangles, soup.triangles);
        assert_eq!(g.geometry_hash, soup.geometry_hash);
        assert_eq!(g.triangle_positions(), soup.triangle_positions());
    }
    let path = dir.path().join("edited.soup");
    let refused = |edit: &dyn Fn(&mut Soup), want: &str| {
        let mut s = sample_soup();
        edit(&mut s);
        s.seal();
        s.write(&path).unwrap();
        for msg in [
            read_geometry(&path).unwrap_err().to_string(),
            Soup::read(&path).unwrap_err().to_string(),
        ] {
            assert!(msg.contains(want), "{want}: {msg}");
        }
    };
    refused(
        &|s| s.triangles[1][2] = 5,
        "triangle 1 names vertices [3, 1, 5] of 5",
    );
    refused(&|s| s.positions[3].y = f32::NAN, "vertex 3 is not finite");
    // A geometry hash that is not the triangles' (written without sealing).
    let mut s = sample_soup();
    s.geometry_hash[0] ^= 1;
    s.write(&path).unwrap();
    let msg = read_geometry(&path).unwrap_err().to_string();
    assert!(msg.contains("geometry hash does not match"), "{msg}");
    // A material index past the end: the renderer's problem, not the build's.
    let mut s = sample_soup();
    s.tri_material[0] = 7;
    s.write(&path).unwrap();
    assert!(read_geometry(&path).is_ok());
    let msg = Soup::read(&path).unwrap_err().to_string();
    assert!(msg.contains("triangle 0 names material 7 of 1"), "{msg}");
}

/// `good`'s magic and version framing `payload`, with its length and a correct checksum:
/// only the decoder stands between a damaged payload and the reader.
fn framed(good: &[u8], payload: &[u8]) -> Vec<u8> {
    let mut bytes = good[..12].to_vec();
    bytes.extend_from_slice(&(payload.len() as u64).to_le_bytes());
    bytes.extend_from_slice(blake3::hash(payload).as_bytes());
    bytes.extend_from_slice(payload);
    bytes
}

/// Why the reader refuses `k` once written (it panics if the reader accepts it).
fn kd_refusal(k: &KdFile) -> String {
    let p = Path::new("bad.kd");
    KdFile::from_bytes(&k.to_bytes(p).unwrap(), p)
        .unwrap_err()
        .to_string()
}

/// A large tree's checks name the first bad node and leaf entry too.
#[test]
fn large_trees_name_their_first_bad_node_and_entry() {
    let p = Path::new("large.kd");
    let mut k = sample_kd();
    k.stats.triangles = 2;
    k.leaf_tris = (0..300_000u32).map(|i| i % 2).collect();
    // A chain of interior nodes, each with a one-entry leaf below, ending in a leaf.
    let n = 200_001u32;
    k.nodes = (0..n)
        .map(|i| match i {
            _ if i == n - 1 => KdNode::leaf(1, 0),
            _ if i % 2 == 0 => KdNode::interior(0, 0.5, i + 2),
            _ => KdNode::leaf(1, i),
        })
        .collect();
    assert!(KdFile::from_bytes(&k.to_bytes(p).unwrap(), p).is_ok());
    let mut bad = k.clone();
    bad.nodes[190_000] = KdNode::interior(0, 0.5, 7);
    bad.nodes[150_000] = KdNode::interior(1, 0.5, 150_000);
    let msg = kd_refusal(&bad);
    assert!(
        msg.contains("node 150000 points at child 150000 of 200001"),
        "{msg}"
    );
    let mut bad = k.clone();
    bad.nodes[199_999] = KdNode::leaf(2, 299_999);
    bad.nodes[70_001] = KdNode::leaf(9, 299_999);
    let msg = kd_refusal(&bad);
    assert!(
        msg.contains("leaf 70001 reaches past the triangle list"),
        "{msg}"
    );
    let mut bad = k;
    bad.leaf_tris[250_000] = 9;
    bad.leaf_tris[66_000] = 2;
    let msg = kd_refusal(&bad);
    assert!(
        msg.contains("leaf triangle 2 is out of range (2 triangles)"),
        "{msg}"
    );
}

#[test]
fn a_length_field_claiming_a_trillion_elements_fails_fast() {
    // A valid frame whose payload claims 10^12 triangles: the checksum is recomputed so
    // only the decoder stands between the claim and an allocation.
    let p = Path::new("huge.soup");
    let good = sample_soup().to_bytes(p).unwrap();
    let mut payload = good[52..].to_vec();
    payload[..8].copy_from_slice(&1_000_000_000_000u64.to_le_bytes());
    let msg = Soup::from_bytes(&framed(&good, &payload), p)
        .unwrap_err()
        .to_string();
    assert!(msg.contains("does not decode"), "{msg}");
}

/// Fuzzer find (`cargo fuzz run soup`): bincode allocated a string's claimed length
/// before reading it, so a string length of 2·10¹⁸ behind a valid checksum aborted the
/// process. Strings, and every other length, are now checked against the payload size.
#[test]
fn a_string_length_claiming_exabytes_fails_fast() {
    let p = Path::new("huge-name.soup");
    for claim in [0x2074_6c75_6166_6544u64, 1 << 40, 1 << 20] {
        let good = sample_soup().to_bytes(p).unwrap();
        let mut payload = good[52..].to_vec();
        // The object name "Cube" is preceded by its u64 length.
        let at = payload.windows(4).position(|w| w == b"Cube").unwrap() - 8;
        assert_eq!(&payload[at..at + 8], &4u64.to_le_bytes());
        payload[at..at + 8].copy_from_slice(&claim.to_le_bytes());
        let msg = Soup::from_bytes(&framed(&good, &payload), p)
            .unwrap_err()
            .to_string();
        assert!(
            msg.starts_with("huge-name.soup: corrupted: payload does not decode"),
            "{msg}"
        );
    }
}

#[test]
fn kd_with_a_dangling_child_is_refused() {
    let mut k = sample_kd();
    k.nodes[0] = KdNode::interior(0, 0.5, 7);
    let msg = kd_refusal(&k);
    assert!(msg.contains("node 0 points at child 7"), "{msg}");
}

#[test]
fn rays_and_hits_round_trip_and_reject_short_files() {
    let p = Path::new("r.rays");
    let rays = vec![RayRecord {
        origin: Vec3::new(1.0, -2.0, 3.5),
        tmin: 0.0,
        dir: Vec3::new(0.0, -0.0, 1.0),
        tmax: f32::INFINITY,
    }];
    let bytes = rays::encode_rays(&rays);
    assert_eq!(bytes.len(), 16 + 32);
    let back = rays::decode_rays(&bytes, p).unwrap();
    assert_eq!(back, rays);
    assert!(back[0].dir.y.is_sign_negative());
    let msg = rays::decode_rays(&bytes[..40], p).unwrap_err().to_string();
    assert!(msg.contains("truncated"), "{msg}");
    let hits = vec![
        Hit::MISS,
        Hit {
            t: 2.0,
            prim: 7,
            u: 0.25,
            v: 0.5,
        },
    ];
    assert_eq!(
        rays::decode_hits(&rays::encode_hits(&hits), p).unwrap(),
        hits
    );
}

#[test]
fn geometry_hash_depends_on_positions_only() {
    let a = sample_soup();
    let mut b = a.clone();
    b.lights.clear();
    b.materials[0].color = Vec3::X;
    b.seal();
    assert_eq!(a.geometry_hash, b.geometry_hash);
    b.positions[0].x += 1e-6;
    b.seal();
    assert_ne!(a.geometry_hash, b.geometry_hash);
    let mut c = a.clone();
    c.triangles[1].swap(0, 1);
    c.seal();
    assert_ne!(
        a.geometry_hash, c.geometry_hash,
        "the indices are hashed too"
    );
}

/// `sample_soup` edited by `edit` (its geometry hash recomputed) is refused on read with a
/// message containing `want`.
fn refused(edit: &dyn Fn(&mut Soup), want: &str) {
    refused_edit_of(sample_soup(), edit, want);
}

/// `soup` edited by `edit` (its geometry hash recomputed) is refused on read with a
/// message containing `want`.
fn refused_edit_of(mut s: Soup, edit: &dyn Fn(&mut Soup), want: &str) {
    let p = Path::new("edited.soup");
    edit(&mut s);
    s.seal();
    let msg = Soup::from_bytes(&s.to_bytes(p).unwrap(), p)
        .unwrap_err()
        .to_string();
    assert!(msg.contains(want), "{want}: {msg}");
}

/// Every index a reader follows is checked on read: a triangle naming a vertex past the
/// end, or a vertex without its normal.
#[test]
fn triangles_naming_missing_vertices_are_corrupt() {
    refused(
        &|s| s.triangles[1][2] = 5,
        "triangle 1 names vertices [3, 1, 5] of 5",
    );
    refused(&|s| s.normals.truncate(4), "5 vertices but 4 normals");
    refused(&|s| s.positions[3].y = f32::NAN, "vertex 3 is not finite");
}

/// SOUP.md promises a byte layout other programs can read: check its first fields by hand.
#[test]
fn payload_layout_matches_soup_md() {
    let p = Path::new("s.soup");
    let s = sample_soup();
    let b = s.to_bytes(p).unwrap();
    let payload = &b[52..];
    let u64_at = |o: usize| u64::from_le_bytes(payload[o..o + 8].try_into().unwrap());
    let f32_at = |o: usize| f32::from_le_bytes(payload[o..o + 4].try_into().unwrap());
    // positions: u64 count, then 3 f32 per vertex, no inner lengths.
    assert_eq!(u64_at(0), 5);
    assert_eq!(f32_at(8 + 12), 1.0); // vertex 1 (X), x
    assert_eq!(f32_at(8 + 4 * 12 + 8), 1.0); // vertex 4 (ONE), z
                                             // normals follow directly, then the UVs (2 f32 each), then the triangles.
    assert_eq!(u64_at(8 + 60), 5);
    let uvs = 8 + 60 + 8 + 60;
    assert_eq!(u64_at(uvs), 5);
    let tris = uvs + 8 + 40;
    assert_eq!(u64_at(tris), 2);
    let u32_at = |o: usize| u32::from_le_bytes(payload[o..o + 4].try_into().unwrap());
    assert_eq!(
        [u32_at(tris + 20), u32_at(tris + 24), u32_at(tris + 28)],
        [3, 1, 4],
        "the second triangle's indices"
    );
    assert_eq!(u64_at(tris + 32), 2, "tri_material's count follows");
    // The last 32 bytes are the geometry hash.
    assert_eq!(&payload[payload.len() - 32..], &s.geometry_hash);
    // Option<f32> is one tag byte then the value; enums are a u32 index.
    let m = Material {
        reflectivity: Some(0.5),
        ..Material::unity_default()
    };
    let mut one = Soup::empty();
    one.materials = vec![m];
    one.lights = s.lights.clone();
    let b = one.to_bytes(p).unwrap();
    let payload = &b[52..];
    let find = |needle: &[u8]| {
        payload
            .windows(needle.len())
            .position(|w| w == needle)
            .unwrap()
    };
    let refl = find(&[1, 0, 0, 0, 0x3f]); // tag 1, then 0.5f32 = 00 00 00 3f
    assert_eq!(
        f32::from_le_bytes(payload[refl + 1..refl + 5].try_into().unwrap()),
        0.5
    );
    let spot = find(b"Point Light") + "Point Light".len();
    assert_eq!(
        u32::from_le_bytes(payload[spot..spot + 4].try_into().unwrap()),
        1,
        "Spot is variant 1"
    );
    assert_eq!(
        f32::from_le_bytes(payload[spot + 4..spot + 8].try_into().unwrap()),
        30.0
    );
}

/// Outputs get the permissions a plain create gives (0666 less the umask), not the
/// temporary file's private 0600, so another user (a cluster's merge step) can read them.
#[cfg(target_os = "linux")]
#[test]
fn atomic_outputs_get_the_umask_permissions_not_the_temporary_files() {
    use std::os::unix::fs::PermissionsExt;
    let status = std::fs::read_to_string("/proc/self/status").unwrap();
    let umask = status
        .lines()
        .find_map(|l| l.strip_prefix("Umask:"))
        .map(|v| u32::from_str_radix(v.trim(), 8).unwrap())
        .expect("Linux reports the umask");
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("out.bin");
    write_atomic(&path, b"bytes").unwrap();
    let mode = std::fs::metadata(&path).unwrap().permissions().mode() & 0o777;
    assert_eq!(mode, 0o666 & !umask, "mode {mode:o} with umask {umask:o}");
    assert_eq!(std::fs::read(&path).unwrap(), b"bytes");
}

#[test]
fn a_version_13_soup_is_refused_with_the_versions_named() {
    let p = Path::new("old.soup");
    let mut b = sample_soup().to_bytes(p).unwrap();
    b[8..12].copy_from_slice(&13u32.to_le_bytes());
    let msg = Soup::from_bytes(&b, p).unwrap_err().to_string();
    assert!(
        msg.contains("soup format version 13, this build reads version 14"),
        "{msg}"
    );
    assert!(msg.contains("re-run the stage that made it"), "{msg}");
}

#[test]
fn draw_rule_fields_are_encoded_in_unitys_numbering() {
    let p = Path::new("rules.soup");
    let mut s = Soup::empty();
    s.materials = vec![Material {
        name: "M".into(),
        cull: Cull::Front,
        ..Material::unity_default()
    }];
    s.objects = vec![Object {
        layer: 7,
        cast_shadows: CastShadows::TwoSided,
        receive_shadows: false,
        ..Object::new("Obj", "src")
    }];
    let b = s.to_bytes(p).unwrap();
    let payload = &b[52..];
    let find = |needle: &[u8]| {
        payload
            .windows(needle.len())
            .position(|w| w == needle)
            .unwrap()
    };
    // Object: name, source, layer u8, cast_shadows u32 variant, receive_shadows bool.
    let o = find(b"src") + 3;
    assert_eq!(payload[o], 7);
    assert_eq!(&payload[o + 1..o + 5], &2u32.to_le_bytes(), "TwoSided is 2");
    assert_eq!(payload[o + 5], 0);
    // Material: colour, metallic, smoothness, smoothness_in_alpha, pbs, highlights and
    // reflections (a bool byte each), reflectivity (None: one byte), the 12-byte emission,
    // then cull (u32 variant).
    let m = find(b"builtin:Default-Material") + "builtin:Default-Material".len();
    assert_eq!(payload[m + 12 + 4 + 4], 0, "smoothness from _Glossiness");
    assert_eq!(payload[m + 12 + 4 + 4 + 1], 1, "physically based");
    assert_eq!(payload[m + 12 + 4 + 4 + 2], 1, "highlights on");
    assert_eq!(payload[m + 12 + 4 + 4 + 3], 1, "reflections on");
    let cull = m + 12 + 4 + 4 + 1 + 1 + 1 + 1 + 1 + 12;
    assert_eq!(&payload[cull..cull + 4], &1u32.to_le_bytes(), "Front is 1");
    assert_eq!(Soup::from_bytes(&b, p).unwrap(), s);
}

#[test]
fn a_lights_attenuation_follows_its_range_as_a_variant_number() {
    let p = Path::new("lights.soup");
    let mut s = sample_soup();
    for (attenuation, number) in [(Attenuation::BuiltIn, 0u32), (Attenuation::Universal, 1)] {
        s.lights[0].attenuation = attenuation;
        let b = s.to_bytes(p).unwrap();
        let payload = &b[52..];
        let name = b"Point Light";
        let at = payload.windows(name.len()).position(|w| w == name).unwrap() + name.len();
        // kind (variant and a spot's two angles), position, direction, colour, intensity.
        let range = at + 12 + 36 + 4;
        assert_eq!(&payload[range..range + 4], &10.0f32.to_le_bytes());
        assert_eq!(&payload[range + 4..range + 8], &number.to_le_bytes());
        assert_eq!(Soup::from_bytes(&b, p).unwrap(), s);
    }
}

#[test]
fn an_unlit_material_shows_its_colour_mirrors_nothing_and_round_trips() {
    let lit = Material {
        color: Vec3::new(0.8, 0.4, 0.2),
        metallic: 0.5,
        smoothness: 1.0,
        ..Material::unity_default()
    };
    assert_eq!(lit.albedo(), Vec3::new(0.4, 0.2, 0.1));
    assert_eq!(lit.reflectance(), Vec3::new(0.4, 0.2, 0.1));
    let unlit = Material {
        unlit: true,
        ..lit.clone()
    };
    assert_eq!(unlit.albedo(), Vec3::new(0.8, 0.4, 0.2));
    assert_eq!(unlit.reflectance(), Vec3::ZERO);
    let p = Path::new("unlit.soup");
    let mut s = Soup::empty();
    s.materials = vec![lit, unlit];
    assert_eq!(Soup::from_bytes(&s.to_bytes(p).unwrap(), p).unwrap(), s);
}

/// With a metallic map, metallic lies anywhere in 0–1 across the surface: the albedo's
/// largest value is the full colour, the reflectance's is the map's smoothness scale (or,
/// with smoothness in the albedo's alpha, the material's).
#[test]
fn a_metallic_map_bounds_albedo_and_reflectance_by_its_extremes() {
    let mut m = Material {
        color: Vec3::new(0.8, 0.4, 0.2),
        metallic: 0.25,
        smoothness: 0.5,
        metallic_map: Some(MetallicMap {
            map: TextureRef {
                texture: 0,
                tiling: Tiling::default(),
            },
            smoothness: 0.75,
        }),
        ..Material::unity_default()
    };
    assert_eq!(m.least_metallic(), 0.0);
    assert_eq!(m.albedo(), Vec3::new(0.8, 0.4, 0.2));
    assert_eq!(m.albedo_at(0.5), Vec3::new(0.4, 0.2, 0.1));
    assert_eq!(m.reflectance(), Vec3::new(0.8, 0.4, 0.2) * 0.75);
    m.smoothness_in_alpha = true;
    assert_eq!(m.reflectance(), Vec3::new(0.4, 0.2, 0.1));
    assert_eq!(m.reflectance_at(0.5, 0.5), Vec3::new(0.2, 0.1, 0.05));
    m.metallic_map = None;
    assert_eq!(m.least_metallic(), 0.25);
    assert_eq!(m.albedo(), Vec3::new(0.6, 0.3, 0.15));
}

#[test]
fn fog_that_is_not_finite_or_glows_negative_is_corrupt() {
    fn fog(s: &mut Soup) -> &mut Fog {
        s.environment.fog.as_mut().unwrap()
    }
    refused(
        &|s| {
            fog(s).mode = FogMode::Linear {
                start: 0.0,
                end: f32::INFINITY,
            }
        },
        "fog Linear { start: 0.0, end: inf }",
    );
    refused(
        &|s| fog(s).mode = FogMode::ExponentialSquared { density: f32::NAN },
        "fog ExponentialSquared { density: NaN }",
    );
    refused(&|s| fog(s).colour.y = -0.5, "with colour [0.3, -0.5, 0.5]");
}

#[test]
fn a_procedural_sky_with_a_non_finite_number_is_corrupt() {
    refused(
        &|s| {
            if let Some(Sky::Procedural(p)) = &mut s.environment.sky {
                p.exposure = f32::INFINITY;
            }
        },
        "holds a non-finite number",
    );
}

fn image_sky(layout: SkyLayout) -> Sky {
    Sky::Textured(TexturedSky {
        scale: Vec3::splat(0.98),
        rotation: 30.0,
        layout,
    })
}

fn sky_image(w: u32, h: u32) -> SkyImage {
    let rgb: Vec<Vec3> = (0..w * h).map(|i| Vec3::splat(i as f32 * 0.25)).collect();
    SkyImage::from_linear("sky.hdr", w, h, &rgb)
}

#[test]
fn an_image_sky_survives_the_round_trip_byte_for_byte() {
    let p = Path::new("sky.soup");
    let mut s = sample_soup();
    s.environment.sky = Some(image_sky(SkyLayout::LatLong {
        image: sky_image(4, 2),
        panorama: Panorama::HalfMirrored,
    }));
    s.seal();
    let b = s.to_bytes(p).unwrap();
    let back = Soup::from_bytes(&b, p).unwrap();
    assert_eq!(back, s);
    let Some(Sky::Textured(t)) = &back.environment.sky else {
        panic!("not an image sky");
    };
    let SkyLayout::LatLong { image, .. } = &t.layout else {
        panic!("not latitude-longitude");
    };
    // Texel 5 is 1.25 = 160·2^−7: mantissa 160, exponent byte 128 + 1.
    assert_eq!(&image.texels[20..24], &[160, 160, 160, 129]);
    assert_eq!(image.texel(1, 1), Vec3::splat(1.25));
}

#[test]
fn an_image_sky_with_a_bad_image_or_number_is_corrupt() {
    let cube = |faces: Vec<SkyImage>| {
        move |s: &mut Soup| {
            s.environment.sky = Some(image_sky(SkyLayout::Cube {
                faces: faces.clone(),
            }))
        }
    };
    refused(&cube(vec![sky_image(2, 2); 5]), "a cube sky with 5 faces");
    let mut short = vec![sky_image(2, 2); 6];
    short[3].texels.pop();
    refused(&cube(short), "15 texel bytes for 2x2 (want 16)");
    let mut empty = vec![sky_image(2, 2); 6];
    empty[0].width = 0;
    refused(&cube(empty), "sky image sky.hdr: 0x2");
    refused(
        &|s| {
            let mut sky = image_sky(SkyLayout::Cube {
                faces: vec![sky_image(1, 1); 6],
            });
            if let Sky::Textured(t) = &mut sky {
                t.rotation = f32::NAN;
            }
            s.environment.sky = Some(sky);
        },
        "sky rotation NaN",
    );
    refused(
        &|s| {
            let mut sky = image_sky(SkyLayout::Cube {
                faces: vec![sky_image(1, 1); 6],
            });
            if let Sky::Textured(t) = &mut sky {
                t.scale.y = -1.0;
            }
            s.environment.sky = Some(sky);
        },
        "is not a colour",
    );
}

#[test]
fn an_occlusion_strength_outside_0_to_1_or_a_missing_map_is_corrupt() {
    fn occlusion(s: &mut Soup) -> &mut OcclusionMap {
        s.materials[0].occlusion_map.as_mut().unwrap()
    }
    refused(
        &|s| occlusion(s).strength = 1.5,
        "material 0 has occlusion strength 1.5",
    );
    refused(
        &|s| occlusion(s).strength = f32::NAN,
        "material 0 has occlusion strength NaN",
    );
    refused(
        &|s| occlusion(s).map.texture = 9,
        "material 0 names texture 9 of 1",
    );
}

#[test]
fn a_metallic_map_smoothness_outside_0_to_1_or_a_missing_map_is_corrupt() {
    fn metal(s: &mut Soup) -> &mut MetallicMap {
        s.materials[0].metallic_map.as_mut().unwrap()
    }
    refused(
        &|s| metal(s).smoothness = -0.5,
        "material 0 has metallic map smoothness -0.5",
    );
    refused(
        &|s| metal(s).smoothness = f32::NAN,
        "material 0 has metallic map smoothness NaN",
    );
    refused(
        &|s| metal(s).map.texture = 3,
        "material 0 names texture 3 of 1",
    );
}

#[test]
fn a_shadow_strength_outside_0_to_1_is_corrupt() {
    refused(
        &|s| s.lights[0].shadow_strength = 1.5,
        "light 0 has shadow strength 1.5",
    );
    refused(
        &|s| s.lights[0].shadow_strength = f32::NAN,
        "light 0 has shadow strength NaN",
    );
}

#[test]
fn an_object_on_layer_32_is_corrupt() {
    let p = Path::new("layer.soup");
    let mut s = sample_soup();
    s.objects[0].layer = 32;
    let msg = Soup::from_bytes(&s.to_bytes(p).unwrap(), p)
        .unwrap_err()
        .to_string();
    assert!(msg.contains("layer 32"), "{msg}");
}

/// Each texture cross-reference a lookup would index or divide by is checked on read.
#[test]
fn bad_texture_references_are_corrupt() {
    refused(&|s| s.uvs.pop().map(drop).unwrap(), "5 vertices but 4 UVs");
    refused(&|s| s.uvs.clear(), "(a material has a texture)");
    refused(&|s| s.uvs[4].y = f32::NAN, "vertex 4 has a non-finite UV");
    refused(
        &|s| s.materials[0].albedo_map.as_mut().unwrap().texture = 1,
        "material 0 names texture 1 of 1",
    );
    refused(
        &|s| s.materials[0].albedo_map.as_mut().unwrap().tiling.offset[1] = f32::INFINITY,
        "non-finite texture tiling",
    );
    fn normal(s: &mut Soup) -> &mut NormalMap {
        s.materials[0].normal_map.as_mut().unwrap()
    }
    refused(
        &|s| normal(s).map.texture = 1,
        "material 0 names texture 1 of 1",
    );
    refused(
        &|s| normal(s).map.tiling.scale[0] = f32::NAN,
        "non-finite texture tiling",
    );
    refused(&|s| normal(s).scale = f32::INFINITY, "normal map scale inf");
    refused(
        &|s| s.materials[0].emission_map.as_mut().unwrap().texture = 2,
        "material 0 names texture 2 of 1",
    );
    refused(
        &|s| {
            s.materials[0].albedo_map = None;
            s.uvs.clear();
        },
        "(a material has a texture)",
    );
    refused(&|s| s.materials[0].opacity = 1.5, "opacity 1.5");
    refused(
        &|s| s.textures[0].texels.pop().map(drop).unwrap(),
        "7 texel bytes",
    );
    refused(&|s| s.textures[0].height = 0, "empty (2x0)");
    // Without a textured material the UVs may be left out.
    let mut s = sample_soup();
    s.materials[0].albedo_map = None;
    s.materials[0].normal_map = None;
    s.materials[0].emission_map = None;
    s.materials[0].occlusion_map = None;
    s.materials[0].metallic_map = None;
    s.uvs.clear();
    let p = Path::new("tex.soup");
    assert_eq!(Soup::from_bytes(&s.to_bytes(p).unwrap(), p).unwrap(), s);
}

#[test]
fn culling_keeps_the_side_unity_draws() {
    assert!(!Cull::Back.skips(true));
    assert!(Cull::Back.skips(false));
    assert!(Cull::Front.skips(true));
    assert!(!Cull::Front.skips(false));
    assert!(!Cull::None.skips(true) && !Cull::None.skips(false));
}

/// An artifact written over an existing one replaces it (the names are exchanged, then the
/// old file is deleted): the new bytes at the path, the old file gone, no temporary left.
#[test]
fn writing_over_an_artifact_replaces_it_and_leaves_nothing_behind() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("scene.soup");
    let mut s = sample_soup();
    s.write(&path).unwrap();
    assert_eq!(Soup::read(&path).unwrap(), s);
    s.warnings.push("second".into());
    s.write(&path).unwrap();
    assert_eq!(Soup::read(&path).unwrap(), s);
    let kd = dir.path().join("t.kd");
    sample_kd().write(&kd).unwrap();
    sample_kd().write(&kd).unwrap();
    let mut names: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(names, ["scene.soup", "t.kd"]);
}

/// A folder where the artifact should go is refused as before, and left where it is.
#[test]
fn writing_over_a_folder_fails_and_keeps_the_folder() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("scene.soup");
    std::fs::create_dir(&path).unwrap();
    std::fs::write(path.join("inside"), b"x").unwrap();
    let msg = sample_soup().write(&path).unwrap_err().to_string();
    assert!(msg.contains("scene.soup"), "{msg}");
    assert_eq!(std::fs::read(path.join("inside")).unwrap(), b"x");
    let names: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names, ["scene.soup"]);
}

#[test]
fn a_physical_camera_frames_its_sensor_as_unitys_gate_fit_says() {
    let lens = |gate_fit| Projection::Physical {
        focal_length: 50.0,
        sensor: Vec2::new(36.0, 24.0),
        lens_shift: Vec2::new(0.1, -0.2),
        gate_fit,
    };
    // The sensor spans 0.72 × 0.48 at unit distance; the shift moves the view by 0.1 of
    // its width right and 0.2 of its height down.
    let centre = Vec2::new(0.1 * 36.0 / 50.0, -0.2 * 24.0 / 50.0);
    let frame = |fit, aspect: f32| {
        let f = lens(fit).frustum(aspect).unwrap();
        assert!((f.centre - centre).abs().max_element() < 1e-6, "{fit:?}");
        (f.half_w, f.half_h)
    };
    let close = |a: (f32, f32), b: (f32, f32)| (a.0 - b.0).abs() < 1e-6 && (a.1 - b.1).abs() < 1e-6;
    use GateFit::*;
    // An image of the sensor's own aspect shows the sensor whatever the fit.
    for fit in [None, Vertical, Horizontal, Fill, Overscan] {
        assert!(close(frame(fit, 1.5), (0.36, 0.24)), "{fit:?}");
    }
    // A wider image (2:1): Fill crops the sensor's height, Overscan shows more than its
    // width, None stretches it.
    let (tall, wide) = ((0.48, 0.24), (0.36, 0.18));
    for (fit, want) in [
        (None, (0.36, 0.24)),
        (Vertical, tall),
        (Horizontal, wide),
        (Fill, wide),
        (Overscan, tall),
    ] {
        assert!(
            close(frame(fit, 2.0), want),
            "{fit:?}: {:?}",
            frame(fit, 2.0)
        );
    }
    // A narrower one (1:1): Fill crops the width, Overscan shows more than the height.
    assert!(close(frame(Fill, 1.0), (0.24, 0.24)));
    assert!(close(frame(Overscan, 1.0), (0.36, 0.36)));
    // Unity's field of view is the sensor height's: 2·atan(12/50).
    let fov = lens(Horizontal).fov_y().unwrap();
    assert!((fov - 26.991467).abs() < 1e-4, "{fov}");
    assert_eq!(lens(Horizontal).fault(), Option::None);
    let blind = Projection::Physical {
        focal_length: 0.0,
        sensor: Vec2::new(36.0, 24.0),
        lens_shift: Vec2::ZERO,
        gate_fit: Fill,
    };
    assert!(blind.fault().unwrap().contains("focal length 0 mm"));
    // It survives the soup file.
    let mut s = sample_soup();
    s.camera.projection = lens(Overscan);
    let p = Path::new("physical.soup");
    assert_eq!(Soup::from_bytes(&s.to_bytes(p).unwrap(), p).unwrap(), s);
}
