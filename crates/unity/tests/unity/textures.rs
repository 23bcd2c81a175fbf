//! Albedo textures of the corpus projects: every format they ship decodes at the size
//! Unity imports it, materials name the right slot and tiling, and no material's texture
//! makes the loader panic.

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
