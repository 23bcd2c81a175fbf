//! unity2soup on the real projects of `../shared/corpus/unity/` (see its MANIFEST.md) and
//! on the bundled baseline scene.
//!
//! Expected numbers were derived by hand, not by running the converter:
//! * OBJ triangle counts: Σ (corners − 2) over the `f` lines of each file (quads give 2,
//!   n-gons n − 2), e.g. `awk '/^f /{t+=NF-3} END{print t}' bunny.obj`.
//! * Built-in primitive counts are this converter's tessellation (Cube 12, Plane 200,
//!   Quad 2, Sphere 720, Cylinder 80, Capsule 768), see `primitives.rs`.
//! * Objects: MeshFilter + MeshRenderer pairs whose GameObject and all ancestors are
//!   active (`m_IsActive`), whose renderer is enabled and has a material slot, and whose
//!   mesh resolves (built-in, or an OBJ in the project); a multi-group OBJ model gives one
//!   object per `g` group that has faces.
//! * FBX: each soup object drawn from an FBX mesh has that mesh's Σ (corners − 2) over
//!   the file's faces (ufbx's face sizes, no triangulation), less the zero-area triangles
//!   the soup drops; [`every_fbx_object_has_its_meshs_own_face_count`] checks this per
//!   object and per scene, so a scene's FBX total below is the sum of those face counts
//!   minus the scene's `dropped_degenerate`.
//! * Lights: enabled Light components of type 0–2 on active objects. Cameras: enabled
//!   Camera components on active objects.

use crate::support::bounds;
use glam::Vec3;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

const CUBE: usize = 12;
const PLANE: usize = 200;
const QUAD: usize = 2;
const SPHERE: usize = 720;
const CAPSULE: usize = 768;

fn corpus() -> Option<PathBuf> {
    crate::support::corpus("corpus tests")
}

/// The soup of a corpus scene (path relative to the corpus), `None` without the corpus.
fn corpus_soup(scene: &str) -> Option<formats::Soup> {
    corpus().map(|root| report(&root.join(scene)).soup)
}

fn report(path: &Path) -> unity::Report {
    unity::convert_report(path, &unity::Options::default())
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

struct Expect {
    scene: &'static str,
    objects: usize,
    triangles: usize,
    lights: usize,
    cameras: usize,
    /// Substrings that must appear in some warning.
    warns: &'static [&'static str],
}

#[rustfmt::skip]
fn expectations() -> Vec<Expect> {
    vec![
        // 5 Cubes, 1 Plane and bunny.obj (11141 tris + 1394 quads + 1 pentagon = 13932);
        // no Light at all; bunny.mtl is missing.
        Expect { scene: "ADRC4__Voxel/Assets/Scenes/GraphTests.unity", objects: 7,
                 triangles: 5 * CUBE + PLANE + 13932, lights: 0, cameras: 1,
                 warns: &["bunny.mtl not found"] },
        // Scene-owned (listed from the YAML): 33 Cubes, 19 Spheres and 58 Planes are
        // active with enabled renderers; one Plane has no material slot (draws nothing),
        // one Plane and 4 key.obj objects are under inactive parents. Active OBJ
        // MeshFilters: key.obj (472) and InteriorDoor.obj groups 4300000/4300002 (30 for
        // both). OBJ prefab instances: table.obj ×2 (68 each, group polySurface27 only),
        // InteriorDoor.obj (2 groups, 30), TV.obj (264), blocc.obj (794, 9 n-gons),
        // Toilet.obj (294). Cameras: "Main Camera" is on; the second scene camera has
        // m_Enabled 0 and the FPSController instance is deactivated by an m_IsActive
        // modification. Objects without FBX: 33 + 19 + 57 + 1 + 2 + 2 + 2 + 1 + 1 + 1 =
        // 119. FBX: 237 objects (12 models, Book ×100, remote.FBX's 7 MeshFilters), their
        // faces 114546 triangles, 175 of them zero-area (door.FBX Box002 has 79).
        Expect { scene: "Astraela__Escape-The-Room/Assets/Scenes/Game.unity", objects: 119 + 237,
                 triangles: 33 * CUBE + 19 * SPHERE + 57 * PLANE + 472 + 30 + 2 * 68 + 30 + 264 + 794 + 294
                     + 114546 - 175,
                 lights: 1, cameras: 1,
                 warns: &["no material slot", "Mat_3", "table.mtl not found"] },
        // 5 Cubes + 1 Sphere.
        Expect { scene: "Ayinzhang__Rigidbody-Fracture/Assets/Scenes/RigidbodyFracture.unity", objects: 6,
                 triangles: 5 * CUBE + SPHERE, lights: 1, cameras: 1, warns: &[] },
        // A Plane, and the bunny instance whose m_Mesh is overridden to the embedded
        // Mesh 1770867978 (10000 triangles).
        Expect { scene: "Ayinzhang__Rigidbody-Fracture/Assets/Scenes/RigidbodySimulation.unity", objects: 2,
                 triangles: PLANE + 10000, lights: 1, cameras: 1, warns: &[] },
        // 8 Cubes, 3 Spheres, 1 Quad; 1 directional + 2 point lights; the second camera
        // renders into a RenderTexture.
        Expect { scene: "IceMiaoMiao__Unity-Shader-Study-Projects/Assets/Scenes/Scene_10_2.unity", objects: 12,
                 triangles: 8 * CUBE + 3 * SPHERE + QUAD, lights: 3, cameras: 2, warns: &[] },
        // PrefabInstance of suzanne.obj (15488 triangles, one group), mtllib missing.
        Expect { scene: "IceMiaoMiao__Unity-Shader-Study-Projects/Assets/Scenes/Scene_14_1.unity", objects: 1,
                 triangles: 15488, lights: 1, cameras: 1, warns: &["suzanne.mtl not found"] },
        // One Capsule; 1 directional + 4 point lights.
        Expect { scene: "IceMiaoMiao__Unity-Shader-Study-Projects/Assets/Scenes/Scene_9_2_2.unity", objects: 1,
                 triangles: CAPSULE, lights: 5, cameras: 1, warns: &[] },
        // The built-in Plane and 82 FBX objects (11 models, 58 legacy instances), their
        // faces 18836 triangles, none zero-area. Left out: the Player prefab's skinned
        // mesh (its .mb model is not in the corpus) and one instance whose source GUID
        // is not in the project.
        Expect { scene: "Pjaerr__GDSJam-Reflection/Assets/Scenes/Tutorial.unity", objects: 1 + 82,
                 triangles: PLANE + 18836, lights: 1, cameras: 1,
                 warns: &["SkinnedMeshRenderer: mesh GUID", "source GUID 4b40042732c5264439ac0f044a5fe854"] },
        // 70 Cubes, 2 Quads, 1 Sphere, Ramp.obj (8, its .mtl missing), and 50 FBX objects
        // (nested prefabs of walls, floors and furniture), their faces 13743 triangles,
        // 8 zero-area.
        Expect { scene: "notenoughbees__Unity-Essentials-Project-Unity-6/Assets/_Unity Essentials/Scenes/2_KidsRoom_3D_Scene.unity",
                 objects: 70 + 2 + 1 + 1 + 50, triangles: 70 * CUBE + 2 * QUAD + SPHERE + 8 + 13743 - 8,
                 lights: 1, cameras: 1, warns: &["Ramp.mtl not found"] },
        // 2 Cubes, 1 Plane, 1 Sphere and 56 FBX objects, their faces 13947 triangles,
        // 8 zero-area. Foreground_Buildings' mesh GUID is not in the project. One camera
        // is the scene's, the other comes with a prefab instance.
        Expect { scene: "thespeedyboy__CreateWithVR2021/Assets/Scenes/TravisRoom.unity",
                 objects: 4 + 56, triangles: 2 * CUBE + PLANE + SPHERE + 13947 - 8,
                 lights: 6, cameras: 2, warns: &["Foreground_Buildings"] },
        // 6 Cubes and 41 FBX objects (the ASCII wall kit ×18 with the models' own
        // materials, guns), their faces 5391 triangles, 142 zero-area (9mm.pistol base
        // 132).
        Expect { scene: "thespeedyboy__CreateWithVR2021/Assets/Scenes/final.unity",
                 objects: 6 + 41, triangles: 6 * CUBE + 5391 - 142,
                 lights: 1, cameras: 1, warns: &[] },
        // A Sphere (the player) and 5 FBX objects: the island (148) and SkyDome.fbx's
        // four meshes (160 + 18 + 66 + 20), from their faces, none zero-area.
        Expect { scene: "DarthTekin__Prototype4_CreateWithCode2_UnityLearn_05.04.2023/Assets/Scenes/Prototype 4.unity",
                 objects: 1 + 5, triangles: SPHERE + 148 + 160 + 18 + 66 + 20,
                 lights: 1, cameras: 1, warns: &[] },
        // multcoloredcube2.obj: 6 groups of 2 triangles.
        Expect { scene: "VidarUre__MeshToSvgConverter/Assets/Scenes/cubescene.unity", objects: 6,
                 triangles: 12, lights: 1, cameras: 1, warns: &[] },
        Expect { scene: "VidarUre__MeshToSvgConverter/Assets/Scenes/gridscene.unity", objects: 1,
                 triangles: 162, lights: 1, cameras: 1, warns: &[] },
        // terrainmodel.obj: 16 groups, 8959 triangles.
        Expect { scene: "VidarUre__MeshToSvgConverter/Assets/Scenes/terrainscene.unity", objects: 16,
                 triangles: 8959, lights: 1, cameras: 1, warns: &[] },
        Expect { scene: "VidarUre__MeshToSvgConverter/Assets/Scenes/torusscene.unity", objects: 1,
                 triangles: 288, lights: 1, cameras: 1, warns: &[] },
        // 2018.2 transitional Prefab of bunny.obj (one group `Bunny`, 4968 triangles).
        Expect { scene: "adcimon__mesh-deformer/Assets/Scenes/Scene.unity", objects: 1,
                 triangles: 4968, lights: 1, cameras: 1, warns: &[] },
        // MeshFilter → bunny.obj by the hashed id of `Type:Mesh->default0`.
        Expect { scene: "fuqunaga__ComputeShaderBVHMeshHit/Assets/Scenes/SampleScene.unity", objects: 1,
                 triangles: 4968, lights: 1, cameras: 1, warns: &[] },
        // The three item prefab instances are deactivated by modification, bg/floor/grid
        // are inactive; what remains is wall.obj's 2 groups (6 + 6).
        Expect { scene: "jonike__CubeRoom/Assets/Scenes/Capture.unity", objects: 2,
                 triangles: 12, lights: 1, cameras: 2, warns: &[] },
        // 3 MeshFilters on embedded meshes, 2 of whose renderers are disabled; the
        // enabled one (MaterialMesh) uses Mesh 892444932: indexCount 72 → 24 triangles.
        Expect { scene: "jonike__CubeRoom/Assets/Scenes/WindowTest.unity", objects: 1,
                 triangles: 24, lights: 1, cameras: 1, warns: &[] },
        // One Plane; the UI canvas is ignored; HDRP light units are mapped.
        Expect { scene: "kcherr1__UnityStressTest/Assets/Main.unity", objects: 1,
                 triangles: PLANE, lights: 1, cameras: 1, warns: &["HDRP"] },
        // The model is a Git LFS pointer: reported, nothing converted.
        Expect { scene: "superdump__unity-compute-shader-ray-tracer/Assets/Scenes/SampleScene.unity", objects: 0,
                 triangles: 0, lights: 1, cameras: 1, warns: &["Git LFS pointer"] },
        // suzanne.obj (32 tris + 468 quads = 968), Cube, Plane, Sphere.
        Expect { scene: "wbalaniucCentennialCollege__COMP396_F2018_Graphics/Assets/Scenes/Graphics.unity", objects: 4,
                 triangles: 968 + CUBE + PLANE + SPHERE, lights: 1, cameras: 1, warns: &[] },
    ]
}

#[test]
fn every_text_scene_converts_to_the_hand_derived_counts() {
    let Some(root) = corpus() else { return };
    let mut failures = Vec::new();
    for e in expectations() {
        let r = report(&root.join(e.scene));
        let got = (
            r.soup.objects.len(),
            r.soup.triangles.len(),
            r.soup.lights.len(),
            r.cameras,
        );
        let want = (e.objects, e.triangles, e.lights, e.cameras);
        if got != want {
            failures.push(format!(
                "{}: (objects, triangles, lights, cameras) = {got:?}, expected {want:?}",
                e.scene
            ));
        }
        for w in e.warns {
            if !r.soup.warnings.iter().any(|x| x.contains(w)) {
                failures.push(format!(
                    "{}: no warning mentions {w:?}: {:#?}",
                    e.scene, r.soup.warnings
                ));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn urp_projects_draw_the_packages_lit_material_as_urp_ships_it() {
    let Some(root) = corpus() else { return };
    let scene = "Ayinzhang__Rigidbody-Fracture/Assets/Scenes/RigidbodyFracture.unity";
    let soup = report(&root.join(scene)).soup;
    assert!(soup.warnings.is_empty(), "{:#?}", soup.warnings);
    // Five of the six objects (all but the glass cube) use URP's Lit.mat: mid grey.
    let lit = soup
        .materials
        .iter()
        .position(|m| {
            m.source
                .ends_with("com.unity.render-pipelines.universal/Runtime/Materials/Lit.mat")
        })
        .expect("URP's Lit material");
    assert!(crate::support::close(
        soup.materials[lit].color,
        glam::Vec3::splat(0.21404114),
        1e-6
    ));
    let users: std::collections::HashSet<u32> = (soup.tri_object.iter())
        .zip(&soup.tri_material)
        .filter(|(_, &m)| m == lit as u32)
        .map(|(&o, _)| o)
        .collect();
    assert_eq!(users.len(), 5);
}

/// Σ (corners − 2) over the faces of each mesh node of an FBX file, by node name (the
/// name of the Mesh Unity imports; several nodes may share one), from ufbx's face sizes:
/// no triangulation involved.
fn fbx_face_triangles(path: &Path) -> HashMap<String, Vec<usize>> {
    let scene = ufbx::load_file(&path.to_string_lossy(), ufbx::LoadOpts::default())
        .unwrap_or_else(|e| panic!("{}: {}", path.display(), e.description));
    let mut out = HashMap::new();
    for n in scene.nodes.iter() {
        if let Some(m) = n.mesh.as_ref() {
            let t: usize = m
                .faces
                .iter()
                .map(|f| (f.num_indices as usize).saturating_sub(2))
                .sum();
            out.entry(n.element.name.to_string())
                .or_insert_with(Vec::new)
                .push(t);
        }
    }
    out
}

/// Scenes whose active renderers reference FBX models.
const FBX_SCENES: [&str; 6] = [
    "Astraela__Escape-The-Room/Assets/Scenes/Game.unity",
    "DarthTekin__Prototype4_CreateWithCode2_UnityLearn_05.04.2023/Assets/Scenes/Prototype 4.unity",
    "Pjaerr__GDSJam-Reflection/Assets/Scenes/Tutorial.unity",
    "notenoughbees__Unity-Essentials-Project-Unity-6/Assets/_Unity Essentials/Scenes/2_KidsRoom_3D_Scene.unity",
    "thespeedyboy__CreateWithVR2021/Assets/Scenes/TravisRoom.unity",
    "thespeedyboy__CreateWithVR2021/Assets/Scenes/final.unity",
];

#[test]
fn every_fbx_object_has_its_meshs_own_face_count() {
    // Each soup object drawn from an FBX mesh (source `<file>#<mesh>`) holds that mesh's
    // Σ (corners − 2) from the file's faces, less the zero-area triangles the soup drops:
    // per object at most the face count, and over the scene the face counts of all
    // objects (with the known counts of OBJ and built-in meshes) are exactly the soup's
    // triangles plus those dropped.
    let Some(root) = corpus() else { return };
    let mut failures = Vec::new();
    for scene in FBX_SCENES {
        let project = root.join(scene.split("/Assets/").next().unwrap());
        let r = report(&root.join(scene));
        let soup = &r.soup;
        let mut per_object = vec![0usize; soup.objects.len()];
        for &o in &soup.tri_object {
            per_object[o as usize] += 1;
        }
        let mut files: HashMap<String, HashMap<String, Vec<usize>>> = HashMap::new();
        let (mut fbx_objects, mut expected_fbx, mut got_fbx) = (0, 0, 0);
        for (o, &got) in soup.objects.iter().zip(&per_object) {
            let Some((file, mesh)) = o.source.split_once('#') else {
                continue;
            };
            if !file.to_ascii_lowercase().ends_with(".fbx") {
                continue;
            }
            let counts = files
                .entry(file.to_string())
                .or_insert_with(|| fbx_face_triangles(&project.join(file)));
            let Some(candidates) = counts.get(mesh) else {
                failures.push(format!(
                    "{scene}: {}: no mesh node {mesh} in {file}",
                    o.name
                ));
                continue;
            };
            // Meshes sharing a name are told apart by their ids, not by the soup's
            // source: the object is one of them, the smallest that can hold it.
            let want = candidates
                .iter()
                .copied()
                .filter(|&c| c >= got)
                .min()
                .unwrap_or(candidates[0]);
            fbx_objects += 1;
            expected_fbx += want;
            got_fbx += got;
            if got > want || got == 0 {
                failures.push(format!(
                    "{scene}: {}: {got} triangles, the file's faces give {want}",
                    o.name
                ));
            }
        }
        assert!(fbx_objects > 0, "{scene}: no FBX object");
        // In these scenes only FBX meshes have zero-area triangles.
        if (expected_fbx - got_fbx) as u64 != soup.dropped_degenerate {
            failures.push(format!(
                "{scene}: FBX objects have {got_fbx} triangles, their faces {expected_fbx}, but {} were dropped as degenerate",
                soup.dropped_degenerate
            ));
        }
        println!(
            "{scene}: {fbx_objects} FBX objects, {got_fbx} triangles (faces {expected_fbx}, {} degenerate dropped in the scene)",
            soup.dropped_degenerate
        );
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn binary_scene_is_refused_with_a_fix() {
    let Some(root) = corpus() else { return };
    let p = root.join("candycat1992__Unity_Shaders_Book/Assets/Scenes/Chapter14/Scene_14_1.unity");
    let err = unity::convert(
        &p,
        &unity::Options {
            project: Some(root.join("candycat1992__Unity_Shaders_Book")),
            strict: false,
            camera: None,
        },
    )
    .expect_err("binary scene must be refused");
    let msg = err.to_string();
    assert!(
        msg.contains("binary") && msg.contains("Force Text"),
        "{msg}"
    );
}

fn object_bounds(soup: &formats::Soup, name: &str) -> (Vec3, Vec3) {
    let idx = soup
        .objects
        .iter()
        .position(|o| o.name == name)
        .unwrap_or_else(|| {
            panic!(
                "no object {name}: {:?}",
                soup.objects.iter().map(|o| &o.name).collect::<Vec<_>>()
            )
        });
    bounds(
        soup.triangle_positions()
            .iter()
            .zip(&soup.tri_object)
            .filter(|(_, &o)| o as usize == idx)
            .flat_map(|(t, _)| t.iter().copied()),
    )
}

/// The world box of object `name` is `lo … hi` within `eps`.
fn assert_box(soup: &formats::Soup, name: &str, lo: Vec3, hi: Vec3, eps: f32) {
    let got = object_bounds(soup, name);
    assert!(
        (got.0 - lo).abs().max_element() < eps && (got.1 - hi).abs().max_element() < eps,
        "{name}: got {:?}, expected {lo} … {hi}",
        got
    );
}

/// sRGB → linear, written out here so the test does not lean on the library's.
fn eotf(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

#[test]
#[allow(clippy::excessive_precision)] // values as computed by hand
fn mesh_to_svg_prefab_instance_of_multi_group_obj() {
    // cubescene: PrefabInstance of multcoloredcube2.obj; root Transform 400012 moved to
    // (30.91, 390.74, −446.33), rotated q = (0.16436426, −0.68089753, −0.16095737,
    // −0.69530976). Group Cube_Cube.000 uses 4 vertices of the file; each was taken
    // (x, y, z) → Unity (−x, y, z) → q·v·q⁻¹ + T → soup (−x, y, z), by hand in a
    // 15-line Python script: box (−32.40334, 390.444_8, −444.35446) …
    // (−29.7201, 393.1286, −444.29826).
    let Some(soup) = corpus_soup("VidarUre__MeshToSvgConverter/Assets/Scenes/cubescene.unity")
    else {
        return;
    };
    assert_box(
        &soup,
        "multcoloredcube2/Cube_Cube.000",
        Vec3::new(-32.40334, 390.444_8, -444.35446),
        Vec3::new(-29.7201, 393.1286, -444.29826),
        1e-3,
    );

    // terrainscene: renderer 2300000 (group Earth_Plane.108, 2048 faces) has its material
    // overridden by the scene-embedded Material 525343101 (_Color sRGB (0.64, 0.295121,
    // 0.048366), _Glossiness 0, _Metallic 0).
    let Some(soup) = corpus_soup("VidarUre__MeshToSvgConverter/Assets/Scenes/terrainscene.unity")
    else {
        return;
    };
    let idx = soup
        .objects
        .iter()
        .position(|o| o.name == "terrainmodel/Earth_Plane.108")
        .expect("Earth_Plane.108");
    let t = soup
        .tri_object
        .iter()
        .position(|&o| o as usize == idx)
        .unwrap();
    let m = &soup.materials[soup.tri_material[t] as usize];
    assert!(m.name.starts_with("EarthTextureMaterial"), "{}", m.name);
    let want = Vec3::new(eotf(0.64), eotf(0.295121), eotf(0.048366));
    assert!(
        (m.color - want).abs().max_element() < 1e-6,
        "{} vs {want}",
        m.color
    );
    assert_eq!((m.metallic, m.smoothness), (0.0, 0.0));
    assert_eq!(
        soup.tri_object
            .iter()
            .filter(|&&o| o as usize == idx)
            .count(),
        2048
    );
}

#[test]
fn compute_shader_bvh_parented_scaled_obj() {
    // Meshs (identity) / bunny: position (1, −1.72, 0), rotation (0, 1, 0, 0) = 180°
    // about Y, scale 50, MeshFilter → bunny.obj by hashed fileID. A file vertex (x, y, z)
    // imports as (−x, y, z), turns to (x, y, −z), scales and moves to
    // (1 + 50x, −1.72 + 50y, −50z) and lands in the soup at (−1 − 50x, −1.72 + 50y, −50z).
    // File bounds: x [−0.09438042, 0.0607788], y [0.0333099, 0.18699602],
    // z [−0.06167917, 0.05871464] → soup x [−4.03894, 3.719021], y [−0.054505, 7.629801],
    // z [−2.935732, 3.0839585].
    let Some(soup) =
        corpus_soup("fuqunaga__ComputeShaderBVHMeshHit/Assets/Scenes/SampleScene.unity")
    else {
        return;
    };
    assert_box(
        &soup,
        "Meshs/bunny",
        Vec3::new(-4.03894, -0.054505, -2.935732),
        Vec3::new(3.719021, 7.629801, 3.0839585),
        1e-4,
    );
}

#[test]
fn cube_room_capture_legacy_prefab_scene() {
    // wall (identity) / mesh (scale x 0.66) / inner → wall.obj 4300000 = group Mesh1, one
    // quad at z = 0 with x ∈ [−3, 3], y ∈ [0, 6]: x scales to ±1.98 (symmetric, so the
    // two x negations do not show). outter → 4300002 = Mesh2, five quads over all
    // 8 vertices: z ∈ [−0.2, 0].
    let Some(soup) = corpus_soup("jonike__CubeRoom/Assets/Scenes/Capture.unity") else {
        return;
    };
    assert_box(
        &soup,
        "wall/mesh/inner",
        Vec3::new(-1.98, 0.0, 0.0),
        Vec3::new(1.98, 6.0, 0.0),
        1e-5,
    );
    assert_box(
        &soup,
        "wall/mesh/outter",
        Vec3::new(-1.98, 0.0, -0.2),
        Vec3::new(1.98, 6.0, 0.0),
        1e-5,
    );
    // The camera is orthographic.
    assert!(matches!(
        soup.camera.projection,
        formats::Projection::Orthographic { .. }
    ));
}

#[test]
fn rigidbody_fracture_unity6_bounds() {
    // Unity 6 scene (SceneRoots). "Cube (4)": position (−1.5, −0.6, 1.5), unit scale →
    // Unity box [−2, −1.1, 1] … [−1, −0.1, 2] → soup x negated: [1, −1.1, 1] … [2, −0.1, 2].
    // "Sphere": (0, 3, 1.5), scale 0.3 → radius 0.15. "Cube": origin, scale (3, 0.1, 3).
    let Some(soup) =
        corpus_soup("Ayinzhang__Rigidbody-Fracture/Assets/Scenes/RigidbodyFracture.unity")
    else {
        return;
    };
    assert_box(
        &soup,
        "Cube (4)",
        Vec3::new(1.0, -1.1, 1.0),
        Vec3::new(2.0, -0.1, 2.0),
        1e-5,
    );
    assert_box(
        &soup,
        "Sphere",
        Vec3::new(-0.15, 2.85, 1.35),
        Vec3::new(0.15, 3.15, 1.65),
        1e-5,
    );
    assert_box(
        &soup,
        "Cube",
        Vec3::new(-1.5, -0.05, -1.5),
        Vec3::new(1.5, 0.05, 1.5),
        1e-5,
    );
    // Camera at (0, 1, −10) with identity rotation: soup forward +Z, right = −X.
    assert_eq!(soup.camera.position, Vec3::new(0.0, 1.0, -10.0));
    assert_eq!(soup.camera.right(), Vec3::NEG_X);
}

#[test]
fn baseline_scene_has_41833_triangles() {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenes/baseline/Assets/Scenes/Baseline.unity");
    if !p.exists() {
        eprintln!(
            "SKIPPED: baseline test, because {} does not exist yet",
            p.display()
        );
        return;
    }
    let r = report(&p);
    assert_eq!(r.soup.triangles.len(), 41_833);
    assert_eq!(r.soup.objects.len(), 9);
    assert_eq!(r.soup.lights.len(), 2);
    assert!(r.soup.warnings.is_empty(), "{:?}", r.soup.warnings);
}

#[test]
fn legacy_material_with_repeated_data_keys() {
    // IceMiaoMiao mat_fence_02.mat (Unity ≤ 5.5 layout): _Glossiness .0649999976,
    // _Color {r: .882352948, g: .946450293, b: 1}, _EmissionColor black.
    let Some(root) = corpus() else { return };
    let p = root
        .join("IceMiaoMiao__Unity-Shader-Study-Projects/Assets/Models/Materials/mat_fence_02.mat");
    let text = std::fs::read_to_string(&p).unwrap();
    let doc = unity::docs::split(&text)
        .into_iter()
        .find(|d| d.class == unity::docs::MATERIAL)
        .unwrap();
    let (m, _) = unity::material::convert(&doc.parse(), "mat_fence_02.mat");
    assert_eq!(m.name, "mat_fence_02");
    assert!((m.smoothness - 0.065).abs() < 1e-6);
    let want = Vec3::new(eotf(0.882_352_95), eotf(0.946_450_3), 1.0);
    assert!((m.color - want).abs().max_element() < 1e-6, "{}", m.color);
    assert_eq!(m.emission, Vec3::ZERO);
}

/// Every (soup material, origin) of the objects drawn from mesh `source`.
fn origins_of<'a>(r: &'a unity::Report, source: &str) -> Vec<(&'a formats::Material, &'a str)> {
    let mut out = Vec::new();
    for (i, o) in r.soup.objects.iter().enumerate() {
        if o.source == source {
            for (m, origin) in &r.material_origins[i] {
                out.push((&r.soup.materials[*m as usize], origin.as_str()));
            }
        }
    }
    out
}

#[test]
fn fbx_model_materials_in_the_corpus() {
    let Some(root) = corpus() else { return };
    // GDSJam-Reflection floor.FBX (legacy meta: no materialLocation, `materialName: 0`):
    // its material's diffuse texture is basetile_basecolor, and Unity extracted
    // Assets/Models/models/Materials/basetile_basecolor.mat next to the model; the
    // instances without a material override use it.
    let r = report(&root.join("Pjaerr__GDSJam-Reflection/Assets/Scenes/Tutorial.unity"));
    let floor = origins_of(&r, "Assets/Models/models/floor.FBX#floor");
    assert!(
        floor
            .iter()
            .any(|(_, o)| *o
                == "Materials folder Assets/Models/models/Materials/basetile_basecolor.mat"),
        "{floor:?}"
    );
    // CreateWithVR2021 wall.fbx (ASCII, materialLocation 1, no remap): its own 'wood',
    // whose text says `P: "DiffuseColor", "Color", "", "A",0.8962264,0.6015712,0.3931559`
    // (Unity's sRGB material colour, linearised here).
    let r = report(&root.join("thespeedyboy__CreateWithVR2021/Assets/Scenes/final.unity"));
    let src = "Assets/_Course Library/models/FBX format-20250115T161328Z-001/FBX format/wall.fbx";
    let wall = origins_of(&r, &format!("{src}#wall"));
    let (wood, origin) = wall
        .iter()
        .find(|(m, _)| m.name == "wood")
        .unwrap_or_else(|| panic!("{wall:?}"));
    assert_eq!(*origin, format!("model's own {src}#wood"));
    let want = Vec3::new(eotf(0.896_226_4), eotf(0.601_571_2), eotf(0.393_155_9));
    assert!(
        (wood.color - want).abs().max_element() < 1e-6,
        "{}",
        wood.color
    );
}
