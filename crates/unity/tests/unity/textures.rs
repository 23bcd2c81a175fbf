//! Albedo textures of the corpus projects: every format they ship decodes at the size
//! Unity imports it, materials name the right slot and tiling, and no material's texture
//! makes the loader panic; the generated `textures` scenes convert into exactly the
//! texels, UVs, tiling and alpha they were written with.

use crate::support::copy_dir;
use formats::texture::{Filter, Wrap};
use std::path::PathBuf;
use unity::project::Project;
use unity::texture::{load, load_albedo, Import, TextureError};

fn corpus() -> Option<PathBuf> {
    crate::support::corpus("corpus texture tests")
}

/// (file, imported width, height): PNG 8-bit RGB and 16-bit RGBA, JPEG baseline and
/// progressive, TGA 24 and 32 bpp. Sizes follow nPOTScale ToNearest (355 → 256,
/// 894 → 1024, 1300×866 → 1024×1024, 391×129 → 512×128).
const FILES: &[(&str, u32, u32)] = &[
    (
        "Astraela__Escape-The-Room/Assets/Sprites/FabricWall.png",
        256,
        256,
    ),
    (
        "Astraela__Escape-The-Room/Assets/Sprites/cube.png",
        1024,
        1024,
    ),
    (
        "jonike__CubeRoom/Assets/Textures/wood/wood_color_01_basecolor.png",
        512,
        512,
    ),
    (
        "Astraela__Escape-The-Room/Assets/Sprites/Crate.jpg",
        1024,
        1024,
    ),
    (
        "Astraela__Escape-The-Room/Assets/Sprites/Plastic.jpg",
        1024,
        1024,
    ),
    (
        "kcherr1__UnityStressTest/Assets/Textures/grass.jpeg",
        512,
        128,
    ),
    (
        "Astraela__Escape-The-Room/Assets/Models/table/Table_Diffuse.tga",
        512,
        512,
    ),
    (
        "Pjaerr__GDSJam-Reflection/Assets/Models/textures/target.tga",
        256,
        256,
    ),
];

#[test]
fn every_corpus_format_decodes_at_unity_size() {
    let Some(root) = corpus() else { return };
    for &(rel, w, h) in FILES {
        let path = root.join(rel);
        let t = load(&path, rel, &Import::read(&path)).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!((t.width, t.height), (w, h), "{rel}");
        t.validate().unwrap();
        // Real albedo maps are neither blank nor one flat colour.
        let first = &t.texels[..4];
        assert!(t.texels.chunks(4).any(|c| c != first), "{rel}: flat");
    }
}

#[test]
fn materials_name_their_slot_and_tiling() {
    let Some(root) = corpus() else { return };
    let body = |project: &Project, rel: &str| {
        project
            .mat(&project.root.join(rel))
            .as_ref()
            .clone()
            .unwrap()
            .unwrap()
    };
    let escape = Project::open(&root.join("Astraela__Escape-The-Room"));
    let ceiling = load_albedo(&escape, &body(&escape, "Assets/Materials/Ceiling.mat"))
        .unwrap()
        .unwrap();
    assert_eq!(ceiling.property, "_MainTex");
    assert_eq!(ceiling.tiling.scale, [10.0, 5.0]);
    assert_eq!(ceiling.import.wrap_u, Wrap::Repeat);
    // The grunge map of Blauw.mat is imported as a normal map: sRGB off.
    let blauw = load_albedo(
        &escape,
        &body(&escape, "Assets/Materials/BookMaterials/Blauw.mat"),
    )
    .unwrap()
    .unwrap();
    assert!(!blauw.texture.srgb);
    let stress = Project::open(&root.join("kcherr1__UnityStressTest"));
    let grass = load_albedo(&stress, &body(&stress, "Assets/Materials/grass.mat"))
        .unwrap()
        .unwrap();
    assert_eq!(grass.property, "_BaseColorMap");
    assert_eq!(grass.tiling.scale, [100.0, 100.0]);
    assert_eq!(grass.texture.filter, grass.import.filter);
    assert!(matches!(
        grass.texture.filter,
        Filter::Point | Filter::Bilinear | Filter::Trilinear
    ));
}

/// Every `.mat` of every corpus project: a texture, no texture, or a typed error, never a
/// panic; absent and unreadable textures are among them.
#[test]
fn every_corpus_material_loads_or_says_why() {
    let Some(root) = corpus() else { return };
    let (mut loaded, mut untextured, mut errors) = (0, 0, Vec::new());
    let mut projects: Vec<PathBuf> = std::fs::read_dir(&root)
        .unwrap()
        .filter_map(|e| Some(e.ok()?.path()))
        .filter(|p| p.join("Assets").is_dir())
        .collect();
    projects.sort();
    for dir in projects {
        let project = Project::open(&dir);
        let mut mats = Vec::new();
        let mut stack = vec![project.assets.clone()];
        while let Some(d) = stack.pop() {
            for e in std::fs::read_dir(&d).unwrap().flatten() {
                let p = e.path();
                if p.is_dir() {
                    stack.push(p);
                } else if p.extension().is_some_and(|x| x == "mat") {
                    mats.push(p);
                }
            }
        }
        for m in mats {
            let Ok(Some(body)) = project.mat(&m).as_ref().clone() else {
                continue;
            };
            match load_albedo(&project, &body) {
                Ok(Some(_)) => loaded += 1,
                Ok(None) => untextured += 1,
                Err(e) => {
                    eprintln!("{}: {e}", project.rel(&m));
                    errors.push(e)
                }
            }
        }
    }
    eprintln!(
        "corpus materials: {loaded} textured, {untextured} untextured, {} errors",
        errors.len()
    );
    assert!(loaded >= 60, "{loaded}");
    assert!(untextured > 0);
    // The corpus leaves out textures over 2 MB and non-albedo maps: unresolved guids.
    assert!(errors
        .iter()
        .any(|e| matches!(e, TextureError::Unresolved { .. })));
}

/// Every corpus model: each mesh has one UV per position or none, all finite, and the
/// FBX and OBJ files that carry texture coordinates keep them.
#[test]
fn corpus_models_carry_their_uvs() {
    let Some(root) = corpus() else { return };
    let (mut with, mut without) = (0usize, 0usize);
    let mut stack = vec![root.clone()];
    let mut models = Vec::new();
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap().flatten() {
            let p = e.path();
            if p.is_dir() {
                stack.push(p);
            } else if p
                .extension()
                .is_some_and(|x| x.eq_ignore_ascii_case("fbx") || x == "obj")
            {
                models.push(p);
            }
        }
    }
    models.sort();
    for path in models {
        let Some(project_root) = unity::project::find_root(path.parent().unwrap()) else {
            continue;
        };
        let project = Project::open(&project_root);
        let loaded = project.model(&path);
        let Ok(asset) = loaded.as_ref() else { continue };
        for m in &asset.model.meshes {
            let mesh = &m.mesh;
            if mesh.uvs.is_empty() {
                without += 1;
                continue;
            }
            with += 1;
            assert_eq!(mesh.uvs.len(), mesh.positions.len(), "{}", path.display());
            assert!(
                mesh.uvs.iter().all(|uv| uv.is_finite()),
                "{}",
                path.display()
            );
        }
    }
    eprintln!("corpus model meshes: {with} with UVs, {without} without");
    assert!(with > 100, "{with}");
}

/// CubeRoom's WindowTest holds scene-embedded meshes in Unity 2017's 8-channel layout,
/// with UV0 in channel 3.
#[test]
fn corpus_embedded_meshes_have_uv0() {
    let Some(root) = corpus() else { return };
    let path = root.join("jonike__CubeRoom/Assets/Scenes/WindowTest.unity");
    let text = std::fs::read_to_string(&path).unwrap();
    let mut decoded = 0;
    for d in unity::docs::split(&text)
        .into_iter()
        .filter(|d| d.class == unity::docs::MESH)
    {
        let mesh = unity::embedded::decode(&d.parse()).unwrap();
        assert_eq!(mesh.uvs.len(), mesh.positions.len());
        // A real unwrap spans the texture, it is not one point.
        assert!(mesh.uvs.iter().any(|&uv| uv != mesh.uvs[0]));
        assert!(mesh
            .uvs
            .iter()
            .all(|uv| uv.is_finite() && uv.abs().max_element() < 1e3));
        decoded += 1;
    }
    assert_eq!(decoded, 4);
}

/// The generated `textures` project (scenegen writes it into scenes/).
fn textures_scene(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenes/textures/Assets/Scenes")
        .join(format!("{name}.unity"))
}

fn convert(scene: &std::path::Path) -> formats::Soup {
    unity::convert(scene, &unity::Options::default()).unwrap_or_else(|e| panic!("{e}"))
}

/// Texel bytes, bottom row first, of the quadrant texture: blue, white / red, green.
const QUADRANT_TEXELS: [u8; 16] = [
    0, 0, 255, 255, 255, 255, 255, 255, 255, 0, 0, 255, 0, 255, 0, 255,
];

/// Every corner of a Quad at the origin carries Unity's Quad UV of its position (the soup
/// negates Unity's x, so u = 0.5 − x there).
fn assert_quad_uvs(soup: &formats::Soup, triangles: std::ops::Range<usize>) {
    for t in triangles {
        for k in 0..3 {
            let (p, uv) = (soup.corners(t)[k], soup.corner_uvs(t)[k]);
            assert_eq!(
                [uv.x, uv.y],
                [0.5 - p.x, p.y + 0.5],
                "triangle {t} corner {k} at {p}"
            );
        }
    }
}

#[test]
fn quadrant_texture_point_filtered_upright_on_the_quad() {
    let soup = convert(&textures_scene("Quadrants"));
    assert!(soup.warnings.is_empty(), "{:?}", soup.warnings);
    assert_eq!(soup.textures.len(), 1);
    let t = &soup.textures[0];
    assert_eq!((t.width, t.height), (2, 2));
    assert_eq!(t.texels, QUADRANT_TEXELS);
    assert!(t.srgb && !t.mipmaps);
    assert_eq!(t.filter, Filter::Point);
    assert_eq!((t.wrap_u, t.wrap_v), (Wrap::Repeat, Wrap::Repeat));
    assert_eq!(t.source, "Assets/Textures/Quadrants.png");
    let m = &soup.materials[0];
    let map = m.albedo_map.unwrap();
    assert_eq!(map.texture, 0);
    assert_eq!(map.tiling, formats::texture::Tiling::default());
    assert_eq!((m.alpha, m.opacity), (formats::Alpha::Opaque, 1.0));
    assert_eq!((soup.positions.len(), soup.uvs.len()), (4, 4));
    assert_quad_uvs(&soup, 0..2);
    // The soup survives its own reader's validation.
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("q.soup");
    soup.write(&path).unwrap();
    assert_eq!(formats::Soup::read(&path).unwrap(), soup);
}

#[test]
fn uniform_grey_texture_is_srgb_128() {
    let soup = convert(&textures_scene("Grey"));
    let t = &soup.textures[0];
    assert_eq!((t.width, t.height), (4, 4));
    assert!(t.texels.chunks(4).all(|c| c == [128, 128, 128, 255]));
    assert_eq!(t.filter, Filter::Bilinear);
    assert!(t.mipmaps && t.srgb);
    assert!((t.texel(2, 3)[0] - 0.2158).abs() < 1e-4);
    assert_eq!(soup.materials[0].color, glam::Vec3::ONE);
}

#[test]
fn tiling_and_offset_reach_the_material() {
    let soup = convert(&textures_scene("Tiling"));
    assert_eq!(soup.textures[0].texels, QUADRANT_TEXELS);
    let tiling = soup.materials[0].albedo_map.unwrap().tiling;
    assert_eq!(tiling.scale, [2.0, 1.0]);
    assert_eq!(tiling.offset, [0.5, 0.0]);
    assert_quad_uvs(&soup, 0..2);
}

#[test]
fn cutout_quad_before_a_plain_wall() {
    let soup = convert(&textures_scene("Cutout"));
    assert!(soup.warnings.is_empty(), "{:?}", soup.warnings);
    let cut = soup
        .materials
        .iter()
        .position(|m| m.name == "Cutout")
        .unwrap();
    let m = &soup.materials[cut];
    assert_eq!(m.alpha, formats::Alpha::Cutout { cutoff: 0.5 });
    let t = &soup.textures[m.albedo_map.unwrap().texture as usize];
    // Left column alpha 0, right column opaque, in both rows.
    assert_eq!(
        t.texels,
        [255, 200, 0, 0, 255, 200, 0, 255, 255, 200, 0, 0, 255, 200, 0, 255]
    );
    // The wall comes first and is untextured; once a material is textured, every vertex
    // carries its mesh's UVs, the wall's too.
    assert_eq!(soup.uvs.len(), soup.positions.len());
    let quad: Vec<usize> = (0..soup.triangles.len())
        .filter(|&i| soup.tri_material[i] as usize == cut)
        .collect();
    assert_eq!(quad, vec![2, 3]);
    let mut wall_uvs: Vec<[f32; 2]> = (0..2)
        .flat_map(|t| soup.corner_uvs(t))
        .map(|uv| [uv.x, uv.y])
        .collect();
    wall_uvs.sort_by(|a, b| a.partial_cmp(b).unwrap());
    wall_uvs.dedup();
    assert_eq!(
        wall_uvs,
        [[0.0, 0.0], [0.0, 1.0], [1.0, 0.0], [1.0, 1.0]],
        "the wall Quad's own corners"
    );
    assert_quad_uvs(&soup, 2..4);
    let wall = &soup.materials[soup.tri_material[0] as usize];
    assert_eq!(
        (wall.alpha, wall.albedo_map),
        (formats::Alpha::Opaque, None)
    );
}

#[test]
fn transparent_tint_without_a_texture_keeps_the_soup_uv_free() {
    let soup = convert(&textures_scene("Transparent"));
    let glass = soup.materials.iter().find(|m| m.name == "HalfRed").unwrap();
    assert_eq!((glass.alpha, glass.opacity), (formats::Alpha::Blend, 0.5));
    assert!(soup.textures.is_empty() && soup.uvs.is_empty());
}

/// The bundled untextured scenes keep an empty UV array and no textures.
#[test]
fn untextured_scenes_carry_no_uvs() {
    let baseline = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenes/baseline/Assets/Scenes/Baseline.unity");
    let soup = convert(&baseline);
    assert!(soup.uvs.is_empty() && soup.textures.is_empty());
    assert!(soup.materials.iter().all(|m| m.albedo_map.is_none()));
}

/// A texture that cannot be read is one warning naming the material and the file; the
/// material keeps its tint; `--strict` refuses the scene.
#[test]
fn unreadable_texture_warns_and_strict_refuses() {
    let src = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes/textures");
    for (what, bytes) in [
        ("truncated", None),
        (
            "LFS pointer",
            Some(b"version https://git-lfs.github.com/spec/v1\noid sha256:00\nsize 9\n".to_vec()),
        ),
    ] {
        let dir = tempfile::tempdir().unwrap();
        copy_dir(&src, dir.path());
        let png = dir.path().join("Assets/Textures/Quadrants.png");
        let full = std::fs::read(&png).unwrap();
        std::fs::write(
            &png,
            bytes.unwrap_or_else(|| full[..full.len() / 2].to_vec()),
        )
        .unwrap();
        let scene = dir.path().join("Assets/Scenes/Quadrants.unity");
        let soup = convert(&scene);
        assert_eq!(soup.warnings.len(), 1, "{what}: {:?}", soup.warnings);
        let w = &soup.warnings[0];
        assert!(
            w.starts_with("Assets/Materials/Quadrants.mat: Assets/Textures/Quadrants.png: ")
                && w.ends_with("drawn with its tint alone"),
            "{what}: {w}"
        );
        assert!(soup.textures.is_empty() && soup.uvs.is_empty());
        assert_eq!(soup.materials[0].albedo_map, None);
        let strict = unity::Options {
            strict: true,
            ..Default::default()
        };
        assert!(unity::convert(&scene, &strict).is_err(), "{what}");
    }
}

/// CreateWithVR's TravisRoom: five FBX logs use their own material, whose texture Unity
/// finds in the `Textures/` folder beside the models' folder; it is the image two `.mat`
/// files name too, stored once. GDSJam's target material is cut out at its own cutoff.
#[test]
fn corpus_model_textures_are_found_and_shared() {
    let Some(root) = corpus() else { return };
    let soup = unity::convert(
        &root.join("thespeedyboy__CreateWithVR2021/Assets/Scenes/TravisRoom.unity"),
        &unity::Options::default(),
    )
    .unwrap();
    let swatch = "Assets/_Course Library/Source Files/Textures/InteriorColourSwatch.png";
    let users: Vec<&formats::Material> = soup
        .materials
        .iter()
        .filter(|m| {
            m.albedo_map
                .is_some_and(|r| soup.textures[r.texture as usize].source == swatch)
        })
        .collect();
    let own = users.iter().filter(|m| m.source.contains(".FBX#")).count();
    assert_eq!((users.len(), own), (7, 5));
    assert!(users
        .windows(2)
        .all(|w| w[0].albedo_map.unwrap().texture == w[1].albedo_map.unwrap().texture));
    assert_eq!(
        soup.textures.iter().filter(|t| t.source == swatch).count(),
        1
    );
    let glass = users
        .iter()
        .find(|m| m.name == "Material_Main_Transparent")
        .unwrap();
    assert_eq!(glass.alpha, formats::Alpha::Blend);
    assert_eq!(soup.uvs.len(), soup.positions.len());

    let soup = unity::convert(
        &root.join("Pjaerr__GDSJam-Reflection/Assets/Scenes/Tutorial.unity"),
        &unity::Options::default(),
    )
    .unwrap();
    let target = soup.materials.iter().find(|m| m.name == "target").unwrap();
    assert_eq!(target.alpha, formats::Alpha::Cutout { cutoff: 0.579 });
    assert!(target.albedo_map.is_some());
}

/// The `NormalMap` scene: the Quad's material keeps its map as a linear texture of the
/// file's texels, with the scale the material gives; the soup carries UVs for it alone.
#[test]
fn normal_maps_are_linear_textures_with_their_scale() {
    let soup = convert(&textures_scene("NormalMap"));
    assert!(soup.warnings.is_empty(), "{:?}", soup.warnings);
    let bent = soup.materials.iter().find(|m| m.name == "Bent").unwrap();
    assert_eq!(bent.albedo_map, None);
    let n = bent.normal_map.expect("the Bent material's normal map");
    assert_eq!(n.scale, 1.0);
    assert_eq!(n.map.tiling, formats::Tiling::default());
    let t = &soup.textures[n.map.texture as usize];
    assert_eq!(t.source, "Assets/Textures/Bent.png");
    assert!(!t.srgb);
    assert_eq!((t.width, t.height), (2, 2));
    assert_eq!(t.texels, [204, 128, 255, 255].repeat(4));
    assert_eq!(soup.uvs.len(), soup.positions.len());
    assert_quad_uvs(&soup, 0..2);
}

/// A normal map that is missing, unreadable, or made by Unity from a height map is one
/// warning naming the material and what it loses; the material draws without it.
#[test]
fn normal_maps_that_cannot_be_used_warn_and_are_dropped() {
    let src = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes/textures");
    type Damage = fn(&std::path::Path);
    let cases: [(&str, Damage, &str); 3] = [
        (
            "missing",
            |d| std::fs::remove_file(d.join("Assets/Textures/Bent.png.meta")).unwrap(),
            "Assets/Materials/Bent.mat: _BumpMap: texture GUID ",
        ),
        (
            "truncated",
            |d| std::fs::write(d.join("Assets/Textures/Bent.png"), b"\x89PNG\r\n").unwrap(),
            "Assets/Materials/Bent.mat: Assets/Textures/Bent.png: ",
        ),
        (
            "from grayscale",
            |d| {
                let meta = d.join("Assets/Textures/Bent.png.meta");
                let text = std::fs::read_to_string(&meta).unwrap();
                let text = text.replace("convertToNormalMap: 0", "convertToNormalMap: 1");
                std::fs::write(&meta, text).unwrap();
            },
            "Assets/Materials/Bent.mat: _BumpMap: Assets/Textures/Bent.png is a height map",
        ),
    ];
    for (what, damage, start) in cases {
        let dir = tempfile::tempdir().unwrap();
        copy_dir(&src, dir.path());
        damage(dir.path());
        let soup = convert(&dir.path().join("Assets/Scenes/NormalMap.unity"));
        assert_eq!(soup.warnings.len(), 1, "{what}: {:?}", soup.warnings);
        let w = &soup.warnings[0];
        assert!(
            w.starts_with(start) && w.ends_with("drawn without its normal map"),
            "{what}: {w}"
        );
        assert_eq!(soup.materials[0].normal_map, None, "{what}");
        assert!(soup.textures.is_empty() && soup.uvs.is_empty(), "{what}");
    }
}

/// The `EmissionMap` scene: the glowing material keeps the quadrant texture as its
/// emission map; a map that cannot be found is one warning, and a material that does not
/// glow reads no emission map at all.
#[test]
fn emission_maps_belong_to_glowing_materials() {
    let soup = convert(&textures_scene("EmissionMap"));
    assert!(soup.warnings.is_empty(), "{:?}", soup.warnings);
    let glow = &soup.materials[0];
    assert_eq!(
        (glow.name.as_str(), glow.emission),
        ("Glow", glam::Vec3::ONE)
    );
    let r = glow.emission_map.expect("the Glow material's emission map");
    let t = &soup.textures[r.texture as usize];
    assert_eq!(t.source, "Assets/Textures/Quadrants.png");
    assert!(t.srgb);
    assert_eq!(t.texels, QUADRANT_TEXELS);

    let (dir, mat, text) = glow_project();
    let guid = text
        .split("_EmissionMap:\n        m_Texture: {fileID: 2800000, guid: ")
        .nth(1)
        .and_then(|t| t.get(..32))
        .unwrap()
        .to_string();
    let missing = text.replace(&guid, "0123456789abcdef0123456789abcdef");
    std::fs::write(&mat, &missing).unwrap();
    let scene = dir.path().join("Assets/Scenes/EmissionMap.unity");
    let soup = convert(&scene);
    assert_eq!(soup.warnings.len(), 1, "{:?}", soup.warnings);
    assert_eq!(
        soup.warnings[0],
        "Assets/Materials/Glow.mat: _EmissionMap: texture GUID 0123456789abcdef0123456789abcdef \
         is not in the project; glows with its emission colour alone"
    );
    assert_eq!(soup.materials[0].emission_map, None);
    // Without the _EMISSION keyword the material does not glow and its map is not loaded.
    std::fs::write(&mat, text.replace("  - _EMISSION\n", "")).unwrap();
    let soup = convert(&scene);
    assert_eq!(soup.materials[0].emission, glam::Vec3::ZERO);
    assert_eq!(soup.materials[0].emission_map, None);
    assert!(soup.textures.is_empty() && soup.uvs.is_empty());
}

/// An occlusion map reaches the soup with its strength, sharing the decoded image with the
/// emission map that names the same file and import; a missing one is a warning.
#[test]
fn an_occlusion_map_is_read_with_its_strength() {
    let (dir, mat, text) = glow_project();
    let quadrants = "b9c15245bb706d4c19dc7f7ee351e73a";
    let with = |guid: &str| {
        text.replace(
            "    - _MainTex:\n",
            &format!(
                "    - _OcclusionMap:\n        m_Texture: {{fileID: 2800000, guid: {guid}, type: 3}}\n        m_Scale: {{x: 1, y: 1}}\n        m_Offset: {{x: 0, y: 0}}\n    - _MainTex:\n"
            ),
        )
        .replace("    m_Floats:\n", "    m_Floats:\n    - _OcclusionStrength: 0.75\n")
    };
    std::fs::write(&mat, with(quadrants)).unwrap();
    let scene = dir.path().join("Assets/Scenes/EmissionMap.unity");
    let soup = convert(&scene);
    assert!(soup.warnings.is_empty(), "{:?}", soup.warnings);
    let m = &soup.materials[0];
    let occlusion = m.occlusion_map.expect("an occlusion map");
    assert_eq!(occlusion.strength, 0.75);
    assert_eq!(
        Some(occlusion.map.texture),
        m.emission_map.map(|r| r.texture)
    );
    assert_eq!(soup.textures.len(), 1);

    std::fs::write(&mat, with("0123456789abcdef0123456789abcdef")).unwrap();
    let soup = convert(&scene);
    assert_eq!(soup.materials[0].occlusion_map, None);
    assert_eq!(
        soup.warnings,
        vec!["Assets/Materials/Glow.mat: _OcclusionMap: texture GUID 0123456789abcdef0123456789abcdef \
              is not in the project; drawn without its occlusion map"
            .to_string()]
    );
}

/// A metallic map reaches the soup with its smoothness scale (`_GlossMapScale`) where the
/// `_METALLICGLOSSMAP` keyword is on, sharing the decoded image with the emission map that
/// names the same file; without the keyword it is not loaded, and a missing one is a
/// warning that leaves the material its `_Metallic` and `_Glossiness`.
#[test]
fn a_metallic_map_is_read_with_its_smoothness_scale_where_its_keyword_is_on() {
    let (dir, mat, text) = glow_project();
    let quadrants = "b9c15245bb706d4c19dc7f7ee351e73a";
    let with = |guid: &str, keyword: bool| {
        let t = text
            .replace(
                "    - _MetallicGlossMap:\n        m_Texture: {fileID: 0}\n",
                &format!(
                    "    - _MetallicGlossMap:\n        m_Texture: {{fileID: 2800000, guid: {guid}, type: 3}}\n"
                ),
            )
            .replace("    - _GlossMapScale: 1\n", "    - _GlossMapScale: 0.625\n")
            .replace("    - _Metallic: 0\n", "    - _Metallic: 0.25\n");
        if keyword {
            t.replace("  - _EMISSION\n", "  - _EMISSION\n  - _METALLICGLOSSMAP\n")
        } else {
            t
        }
    };
    let scene = dir.path().join("Assets/Scenes/EmissionMap.unity");
    std::fs::write(&mat, with(quadrants, true)).unwrap();
    let soup = convert(&scene);
    assert!(soup.warnings.is_empty(), "{:?}", soup.warnings);
    let m = &soup.materials[0];
    let metal = m.metallic_map.expect("a metallic map");
    assert_eq!(metal.smoothness, 0.625);
    assert_eq!((m.metallic, m.smoothness), (0.25, 0.0));
    assert_eq!(Some(metal.map.texture), m.emission_map.map(|r| r.texture));
    assert_eq!(soup.textures.len(), 1);

    std::fs::write(&mat, with(quadrants, false)).unwrap();
    let soup = convert(&scene);
    assert_eq!(soup.materials[0].metallic_map, None, "no _METALLICGLOSSMAP");

    std::fs::write(&mat, with("0123456789abcdef0123456789abcdef", true)).unwrap();
    let soup = convert(&scene);
    assert_eq!(soup.materials[0].metallic_map, None);
    assert_eq!(soup.materials[0].metallic, 0.25);
    assert_eq!(
        soup.warnings,
        vec![
            "Assets/Materials/Glow.mat: _MetallicGlossMap: texture GUID \
              0123456789abcdef0123456789abcdef is not in the project; drawn with its metallic \
              and smoothness values, without its metallic map"
                .to_string()
        ]
    );
}

/// A copy of the bundled `textures` project, the path of its `Glow.mat` (the glowing quad of
/// `EmissionMap.unity`) and that file's text, for a test to rewrite.
fn glow_project() -> (tempfile::TempDir, PathBuf, String) {
    let src = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes/textures");
    let dir = tempfile::tempdir().unwrap();
    copy_dir(&src, dir.path());
    let mat = dir.path().join("Assets/Materials/Glow.mat");
    let text = std::fs::read_to_string(&mat).unwrap();
    (dir, mat, text)
}
