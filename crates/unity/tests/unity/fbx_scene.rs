//! FBX models in scenes: prefab instances with modifications, MeshFilters into a model,
//! the importer's material precedence, skinned meshes posed by their bones, and the
//! model files that are not converted. The FBX files are written by the test
//! ([`crate::fbx_ascii`]); every expected number is derived by hand in the comments.
//!
//! Conventions: file centimetres ×0.01 (`useFileScale: 1`); Unity = file with x negated;
//! soup = Unity with x negated again, so a model at the identity keeps its file's
//! coordinates (in metres) in the soup.

use crate::fbx_ascii::{Cluster, Fbx, Geometry, Node, SkinSpec};
use crate::support::{close, project, Scene, Tf, CUBE, HEADER};
use glam::Vec3;
use unity::meta::hash_id;

const G: &str = "fbf0000000000000000000000000000f";

fn model_meta(guid: &str, extra: &str) -> String {
    format!(
        "fileFormatVersion: 2\nguid: {guid}\nModelImporter:\n  serializedVersion: 22\n  internalIDToNameTable: []\n{extra}  meshes:\n    globalScale: 1\n    useFileScale: 1\n"
    )
}

fn mat(name: &str, rgb: [f32; 3]) -> String {
    format!(
        "{HEADER}--- !u!21 &2100000\nMaterial:\n  serializedVersion: 6\n  m_Name: {name}\n  m_Shader: {{fileID: 46, guid: 0000000000000000f000000000000000, type: 0}}\n  m_ShaderKeywords: \n  m_SavedProperties:\n    serializedVersion: 3\n    m_Colors:\n    - _Color: {{r: {}, g: {}, b: {}, a: 1}}\n",
        rgb[0], rgb[1], rgb[2]
    )
}

fn guid_meta(guid: &str) -> String {
    format!("fileFormatVersion: 2\nguid: {guid}\n")
}

/// A prefab instance of model `guid` with raw modification entries (each starting
/// `    - target:`), removed components and game objects.
fn instance(id: i64, guid: &str, mods: &str, removed: &str) -> String {
    let mods = if mods.is_empty() { " []" } else { mods };
    format!(
        "--- !u!1001 &{id}\nPrefabInstance:\n  m_ObjectHideFlags: 0\n  serializedVersion: 2\n  m_Modification:\n    m_TransformParent: {{fileID: 0}}\n    m_Modifications:{mods}\n    m_RemovedComponents: []\n    m_RemovedGameObjects:{removed}\n  m_SourcePrefab: {{fileID: 100100000, guid: {guid}, type: 3}}\n"
    )
}

fn modification(target: i64, guid: &str, path: &str, value: &str, reference: &str) -> String {
    format!("\n    - target: {{fileID: {target}, guid: {guid}, type: 3}}\n      propertyPath: {path}\n      value: {value}\n      objectReference: {reference}")
}

fn text_of(f: &Fbx) -> String {
    let dir = tempfile::tempdir().unwrap();
    std::fs::read_to_string(f.write(dir.path(), "x")).unwrap()
}

fn report(root: &std::path::Path, scene: &str) -> unity::Report {
    unity::convert_report(&root.join(scene), &unity::Options::default())
        .unwrap_or_else(|e| panic!("{e}"))
}

fn object_points(soup: &formats::Soup, name: &str) -> Vec<Vec3> {
    let i = soup
        .objects
        .iter()
        .position(|o| o.name == name)
        .unwrap_or_else(|| panic!("no {name}: {:?}", soup.objects));
    soup.triangle_positions()
        .into_iter()
        .zip(&soup.tri_object)
        .filter(|(_, &o)| o as usize == i)
        .flat_map(|(t, _)| t)
        .collect()
}

fn has_point(pts: &[Vec3], p: Vec3) -> bool {
    pts.iter().any(|&q| close(q, p, 1e-5))
}

/// One triangle (1, 0, 0), (0, 1, 0), (0, 0, 1) m, counter-clockwise seen from
/// (1, 1, 1), on node "Tri"; a quad on node "Quad" 2 m up; both under the file's root.
fn two_nodes() -> Fbx {
    Fbx {
        nodes: vec![
            Node::new("Tri", None)
                .mesh(Geometry::new(
                    &[[100.0, 0.0, 0.0], [0.0, 100.0, 0.0], [0.0, 0.0, 100.0]],
                    &[&[0, 1, 2]],
                ))
                .materials(&[0]),
            Node::new("Quad", None)
                .prop("Lcl Translation", [0.0, 200.0, 0.0])
                .mesh(Geometry::new(
                    &[
                        [0.0, 0.0, 0.0],
                        [100.0, 0.0, 0.0],
                        [100.0, 0.0, 100.0],
                        [0.0, 0.0, 100.0],
                    ],
                    &[&[0, 1, 2, 3]],
                )),
        ],
        materials: vec![("red".into(), [1.0, 0.0, 0.0])],
        ..Default::default()
    }
}

#[test]
fn fbx_instance_at_the_identity_keeps_the_files_coordinates_and_front() {
    // Unity negates x on import and the soup negates it back: the triangle lands at its
    // file coordinates ×0.01, and its front (counter-clockwise in the right-handed file)
    // still faces (1, 1, 1).
    let f = two_nodes();
    let mut sc = Scene::default();
    sc.raw(&instance(500, G, "", " []"));
    sc.camera(&Tf::at(0.0, 0.0, -10.0));
    let (_d, root) = project(&[
        ("Assets/m.fbx", &text_of(&f)),
        ("Assets/m.fbx.meta", &model_meta(G, "")),
        ("Assets/s.unity", &sc.text),
    ]);
    let r = report(&root, "Assets/s.unity");
    let soup = &r.soup;
    assert!(soup.warnings.is_empty(), "{:?}", soup.warnings);
    assert_eq!(soup.objects.len(), 2);
    assert_eq!(soup.triangles.len(), 3, "a triangle and a quad");
    let tri = object_points(soup, "m/Tri");
    for p in [Vec3::X, Vec3::Y, Vec3::Z] {
        assert!(has_point(&tri, p), "{p} not in {tri:?}");
    }
    let i = soup.objects.iter().position(|o| o.name == "m/Tri").unwrap();
    let t = soup.corners(
        soup.tri_object
            .iter()
            .position(|&o| o as usize == i)
            .unwrap(),
    );
    let n = (t[1] - t[0]).cross(t[2] - t[0]);
    assert!(n.dot(Vec3::ONE) > 0.0, "front faces (1, 1, 1): {t:?}");
    // The quad: y = 2, x and z in [0, 1].
    let q = object_points(soup, "m/Quad");
    assert!(q
        .iter()
        .all(|p| (p.y - 2.0).abs() < 1e-6 && p.x >= -1e-6 && p.x <= 1.0 + 1e-6));
    // The triangle's slot is the model's own "red" (diffuse (1, 0, 0)).
    let m = &soup.materials[soup.tri_material[soup
        .tri_object
        .iter()
        .position(|&o| o as usize == i)
        .unwrap()] as usize];
    assert_eq!((m.name.as_str(), m.color), ("red", Vec3::X));
    assert_eq!(r.material_origins[i][0].1, "model's own Assets/m.fbx#red");
}

#[test]
fn fbx_instance_modifications_removed_objects_and_children_of_stripped_transforms() {
    // Name-hashed ids (empty internalIDToNameTable): the root Transform
    // `Type:Transform->//RootNode0` moves to Unity (10, 0, 0); the Quad GameObject is
    // removed; Tri's renderer gets Blue.mat; a scene Cube hangs under the stripped root
    // at local (0, 3, 0).
    let h = |s: &str| hash_id(s);
    let root_tf = h("Type:Transform->//RootNode0");
    let quad_go = h("Type:GameObject->Quad0");
    let tri_mr = h("Type:MeshRenderer->Tri0");
    let blue = "b1e00000000000000000000000000000";
    let mods = [
        modification(root_tf, G, "m_LocalPosition.x", "10", "{fileID: 0}"),
        modification(
            tri_mr,
            G,
            "m_Materials.Array.data[0]",
            "",
            &format!("{{fileID: 2100000, guid: {blue}, type: 2}}"),
        ),
    ]
    .concat();
    let removed = format!("\n    - {{fileID: {quad_go}, guid: {G}, type: 3}}");
    let mut sc = Scene::default();
    sc.raw(&instance(500, G, &mods, &removed));
    sc.raw(&format!("--- !u!4 &501 stripped\nTransform:\n  m_CorrespondingSourceObject: {{fileID: {root_tf}, guid: {G}, type: 3}}\n  m_PrefabInstance: {{fileID: 500}}\n  m_PrefabAsset: {{fileID: 0}}\n"));
    sc.primitive("Child", &Tf::at(0.0, 3.0, 0.0), 501, CUBE);
    sc.camera(&Tf::at(0.0, 0.0, -10.0));
    let (_d, root) = project(&[
        ("Assets/m.fbx", &text_of(&two_nodes())),
        ("Assets/m.fbx.meta", &model_meta(G, "")),
        ("Assets/Blue.mat", &mat("Blue", [0.0, 0.0, 1.0])),
        ("Assets/Blue.mat.meta", &guid_meta(blue)),
        ("Assets/s.unity", &sc.text),
    ]);
    let r = report(&root, "Assets/s.unity");
    let soup = &r.soup;
    let names: Vec<_> = soup.objects.iter().map(|o| o.name.as_str()).collect();
    assert_eq!(names, ["m/Tri", "m/Child"], "{:?}", soup.warnings);
    // Unity +10 in x is soup −10: (1, 0, 0) → (−9, 0, 0).
    let tri = object_points(soup, "m/Tri");
    for p in [
        Vec3::new(-9.0, 0.0, 0.0),
        Vec3::new(-10.0, 1.0, 0.0),
        Vec3::new(-10.0, 0.0, 1.0),
    ] {
        assert!(has_point(&tri, p), "{p} not in {tri:?}");
    }
    assert_eq!(soup.materials[soup.tri_material[0] as usize].color, Vec3::Z);
    assert_eq!(r.material_origins[0][0].1, "override Assets/Blue.mat");
    let cube = object_points(soup, "m/Child");
    let c = cube.iter().copied().sum::<Vec3>() / cube.len() as f32;
    assert!(close(c, Vec3::new(-10.0, 3.0, 0.0), 1e-5), "{c}");
}

#[test]
fn meshfilter_into_an_fbx_and_a_prefab_asset_nesting_the_model() {
    // A scene MeshFilter on the Quad's mesh (`Type:Mesh->Quad0`) at Unity (0, 0, 5), and
    // a .prefab asset holding an instance of the model, itself instanced by the scene at
    // Unity (−20, 0, 0) (soup +20).
    let quad_mesh = hash_id("Type:Mesh->Quad0");
    let root_tf = hash_id("Type:Transform->//RootNode0");
    let pg = "9fab0000000000000000000000000000";
    let mut prefab = Scene::default();
    prefab.raw(&instance(
        700,
        G,
        &modification(root_tf, G, "m_LocalPosition.z", "1", "{fileID: 0}"),
        " []",
    ));
    let mut sc = Scene::default();
    let (go, _) = sc.object("Floor", &Tf::at(0.0, 0.0, 5.0), 0, true);
    sc.mesh(
        go,
        quad_mesh,
        G,
        &[(10303, "0000000000000000f000000000000000")],
        true,
    );
    let combined = (700 ^ root_tf) & i64::MAX;
    sc.raw(&instance(
        800,
        pg,
        &modification(combined, pg, "m_LocalPosition.x", "-20", "{fileID: 0}"),
        " []",
    ));
    sc.camera(&Tf::at(0.0, 0.0, -10.0));
    let (_d, root) = project(&[
        ("Assets/m.fbx", &text_of(&two_nodes())),
        ("Assets/m.fbx.meta", &model_meta(G, "")),
        ("Assets/p.prefab", &prefab.text),
        ("Assets/p.prefab.meta", &guid_meta(pg)),
        ("Assets/s.unity", &sc.text),
    ]);
    let soup = report(&root, "Assets/s.unity").soup;
    assert!(soup.warnings.is_empty(), "{:?}", soup.warnings);
    assert_eq!(soup.objects.len(), 3);
    assert_eq!(soup.triangles.len(), 2 + 3);
    // The Quad's mesh is in its node's frame: y = 0 there, z in [5, 6].
    let q = object_points(&soup, "Floor");
    assert!(q
        .iter()
        .all(|p| p.y.abs() < 1e-6 && p.z >= 5.0 - 1e-6 && p.z <= 6.0 + 1e-6));
    let floor = soup.objects.iter().find(|o| o.name == "Floor").unwrap();
    assert_eq!(floor.source, "Assets/m.fbx#Quad");
    // The nested instance: root at Unity (−20, 0, 1) → soup (20, 0, 1); the Tri's
    // (1, 0, 0) → (21, 0, 1).
    let tri = object_points(&soup, "m/Tri");
    assert!(has_point(&tri, Vec3::new(21.0, 0.0, 1.0)), "{tri:?}");
}

#[test]
fn model_materials_follow_remap_then_materials_folders_then_the_models_own() {
    // Model Assets/Art/Props/m.fbx, one mesh with five slots: "red" is remapped by
    // externalObjects to Remap.mat (grey 0.5 → linear 0.21404114); "blue" has
    // Assets/Art/Props/Materials/blue.mat (green (0, 1, 0) to tell it apart); "green"
    // is found one folder up, Assets/Art/Materials/green.mat ((1, 1, 0)), by Unity's
    // default Recursive-Up search; "plain" has no .mat: the file's own diffuse
    // (0, 0.5, 1), which Unity puts in the material's (sRGB) colour: linear
    // (0, 0.21404114, 1); slot 4 "over" is overridden by the instance with Blue.mat ((0, 0, 1)).
    // Remap beats the folder: a Materials/red.mat next to the model is not used.
    let remap = "7e3a0000000000000000000000000000";
    let blue = "b1e00000000000000000000000000000";
    let v = [[0.0, 0.0, 0.0], [100.0, 0.0, 0.0], [0.0, 100.0, 0.0]];
    let mut g = Geometry::new(
        &v,
        &[&[0, 1, 2], &[0, 2, 1], &[1, 0, 2], &[1, 2, 0], &[2, 0, 1]],
    );
    g.poly_materials = Some(vec![0, 1, 2, 3, 4]);
    let f = Fbx {
        nodes: vec![
            Node::new("Body", None).mesh(g).materials(&[0, 1, 2, 3, 4]),
            Node::new("Other", None),
        ],
        materials: vec![
            ("red".into(), [1.0, 0.0, 0.0]),
            ("blue".into(), [0.0, 0.0, 1.0]),
            ("green".into(), [0.0, 1.0, 0.0]),
            ("plain".into(), [0.0, 0.5, 1.0]),
            ("over".into(), [1.0, 1.0, 1.0]),
        ],
        ..Default::default()
    };
    let extra = format!("  externalObjects:\n  - first:\n      type: UnityEngine:Material\n      assembly: UnityEngine.CoreModule\n      name: red\n    second: {{fileID: 2100000, guid: {remap}, type: 2}}\n");
    let over_mr = hash_id("Type:MeshRenderer->Body0");
    let mut sc = Scene::default();
    sc.raw(&instance(
        500,
        G,
        &modification(
            over_mr,
            G,
            "m_Materials.Array.data[4]",
            "",
            &format!("{{fileID: 2100000, guid: {blue}, type: 2}}"),
        ),
        " []",
    ));
    sc.camera(&Tf::at(0.0, 0.0, -10.0));
    let (_d, root) = project(&[
        ("Assets/Art/Props/m.fbx", &text_of(&f)),
        ("Assets/Art/Props/m.fbx.meta", &model_meta(G, &extra)),
        ("Assets/Remap.mat", &mat("Remap", [0.5, 0.5, 0.5])),
        ("Assets/Remap.mat.meta", &guid_meta(remap)),
        (
            "Assets/Art/Props/Materials/red.mat",
            &mat("red", [1.0, 1.0, 1.0]),
        ),
        (
            "Assets/Art/Props/Materials/blue.mat",
            &mat("blue", [0.0, 1.0, 0.0]),
        ),
        (
            "Assets/Art/Materials/green.mat",
            &mat("green", [1.0, 1.0, 0.0]),
        ),
        ("Assets/Blue.mat", &mat("Blue", [0.0, 0.0, 1.0])),
        ("Assets/Blue.mat.meta", &guid_meta(blue)),
        ("Assets/s.unity", &sc.text),
    ]);
    let r = report(&root, "Assets/s.unity");
    let soup = &r.soup;
    assert_eq!(soup.triangles.len(), 5, "{:?}", soup.warnings);
    let colours: Vec<Vec3> = soup
        .tri_material
        .iter()
        .map(|&m| soup.materials[m as usize].color)
        .collect();
    let grey = 0.214_041_14;
    assert_eq!(
        colours,
        [
            Vec3::splat(grey),
            Vec3::Y,
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(0.0, grey, 1.0),
            Vec3::Z
        ]
    );
    let origins: Vec<&str> = r.material_origins[0]
        .iter()
        .map(|(_, o)| o.as_str())
        .collect();
    assert_eq!(
        origins,
        [
            "remap Assets/Remap.mat",
            "Materials folder Assets/Art/Props/Materials/blue.mat",
            "Materials folder Assets/Art/Materials/green.mat",
            "model's own Assets/Art/Props/m.fbx#plain",
            "override Assets/Blue.mat",
        ]
    );

    // materialLocation 1 keeps the materials inside the model: no folder search.
    let meta1 = model_meta(
        G,
        &format!("  materials:\n    materialLocation: 1\n{extra}"),
    );
    std::fs::write(root.join("Assets/Art/Props/m.fbx.meta"), meta1).unwrap();
    let r = report(&root, "Assets/s.unity");
    let origins: Vec<&str> = r.material_origins[0]
        .iter()
        .map(|(_, o)| o.as_str())
        .collect();
    assert_eq!(origins[1], "model's own Assets/Art/Props/m.fbx#blue");
    assert_eq!(
        r.soup.materials[r.soup.tri_material[1] as usize].color,
        Vec3::Z
    );
}

#[test]
fn authoring_tool_files_lfs_pointers_and_broken_fbx_are_one_warning_each() {
    // Four prefab instances whose sources are a .blend, a .max, an LFS pointer and a
    // truncated FBX; the scene's Cube still converts; --strict refuses the scene.
    let sources = [
        ("Assets/a.blend", "BLENDER-v293 not really"),
        ("Assets/b.max", "\u{d0}\u{cf} binary"),
        (
            "Assets/c.fbx",
            "version https://git-lfs.github.com/spec/v1\noid sha256:00\nsize 3\n",
        ),
        ("Assets/d.fbx", "Kaydara FBX Binary  \0\x1a\0"),
    ];
    let guids = [
        "a0000000000000000000000000000001",
        "a0000000000000000000000000000002",
        "a0000000000000000000000000000003",
        "a0000000000000000000000000000004",
    ];
    let mut sc = Scene::default();
    for (i, g) in guids.iter().enumerate() {
        sc.raw(&instance(500 + i as i64, g, "", " []"));
    }
    sc.primitive("Box", &Tf::at(0.0, 0.0, 0.0), 0, CUBE);
    let metas: Vec<(String, String)> = sources
        .iter()
        .zip(guids)
        .map(|((p, _), g)| (format!("{p}.meta"), model_meta(g, "")))
        .collect();
    let mut files: Vec<(&str, &str)> = sources.to_vec();
    files.extend(metas.iter().map(|(p, t)| (p.as_str(), t.as_str())));
    sc.camera(&Tf::at(0.0, 0.0, -10.0));
    files.push(("Assets/s.unity", &sc.text));
    let (_d, root) = project(&files);
    let soup = report(&root, "Assets/s.unity").soup;
    assert_eq!(soup.objects.len(), 1, "the Cube");
    let w = &soup.warnings;
    assert_eq!(w.len(), 4, "{w:#?}");
    assert_eq!(w[0], "Assets/s.unity: prefab instance 'a' (fileID 500): source Assets/a.blend is a .blend file; Unity imports it through Blender; export it as FBX; skipped");
    assert!(
        w[1].contains("'b'")
            && w[1].contains("Assets/b.max")
            && w[1].contains("Unity imports it through 3ds Max; export it as FBX"),
        "{}",
        w[1]
    );
    assert!(
        w[2].contains("'c'") && w[2].contains("Assets/c.fbx: is a Git LFS pointer"),
        "{}",
        w[2]
    );
    assert!(
        w[3].contains("'d'") && w[3].contains("Assets/d.fbx: not a readable FBX file"),
        "{}",
        w[3]
    );
    let err = unity::convert(
        &root.join("Assets/s.unity"),
        &unity::Options {
            project: None,
            strict: true,
            camera: None,
        },
    )
    .expect_err("--strict turns the warnings into an error");
    assert!(err.to_string().contains("4 warning(s)"), "{err}");
}

/// Body: triangle v0 (0, 0, 0), v1 (100, 0, 0), v2 (0, 100, 0) cm, skinned to B0 (at the
/// origin) and B1 (at (0, 100, 0) cm, bind matrix mesh → bone = translation
/// (0, −100, 0)): v0 half B0 half B1, v1 and v2 all B1.
fn skinned() -> Fbx {
    let v = [[0.0, 0.0, 0.0], [100.0, 0.0, 0.0], [0.0, 100.0, 0.0]];
    let id = {
        let mut m = [0.0; 16];
        for i in 0..4 {
            m[i * 5] = 1.0;
        }
        m
    };
    let (mut t1, mut l1) = (id, id);
    t1[13] = -100.0;
    l1[13] = 100.0;
    Fbx {
        nodes: vec![
            Node::new("Body", None).mesh(Geometry::new(&v, &[&[0, 1, 2]])),
            Node::new("B0", None).limb(),
            Node::new("B1", None)
                .limb()
                .prop("Lcl Translation", [0.0, 100.0, 0.0]),
        ],
        skins: vec![SkinSpec {
            mesh: 0,
            clusters: vec![
                Cluster {
                    bone: 1,
                    weights: vec![(0, 0.5)],
                    transform: id,
                    link: id,
                },
                Cluster {
                    bone: 2,
                    weights: vec![(0, 0.5), (1, 1.0), (2, 1.0)],
                    transform: t1,
                    link: l1,
                },
            ],
        }],
        ..Default::default()
    }
}

/// The posed triangle when B0 stays at the identity and B1 stands at Unity (0, 2, 0)
/// turned 90° about Z ((x, y, z) → (−y, x, z)). In Unity, v1 = (−1, 0, 0) and
/// v2 = (0, 1, 0); B1's bind pose is the translation (0, −1, 0). v1: bone space
/// (−1, −1, 0) → turned (1, −1, 0) → (1, 1, 0). v2: bone space 0 → (0, 2, 0). v0: B0
/// gives (0, 0, 0), B1 gives (0, 2, 0) + turned (0, −1, 0) = (1, 2, 0); half each
/// (0.5, 1, 0). Soup: x negated.
const POSED: [Vec3; 3] = [
    Vec3::new(-0.5, 1.0, 0.0),
    Vec3::new(-1.0, 1.0, 0.0),
    Vec3::new(0.0, 2.0, 0.0),
];

const Z90: [f32; 4] = [
    0.0,
    0.0,
    std::f32::consts::FRAC_1_SQRT_2,
    std::f32::consts::FRAC_1_SQRT_2,
];

#[test]
fn skinned_instance_is_posed_by_its_moved_bone() {
    // The instance moves B1 (name-hashed `Type:Transform->B10`) to (0, 2, 0) and turns
    // it 90° about Z, and gives the SkinnedMeshRenderer Unity made for Body
    // (`Type:SkinnedMeshRenderer->Body0`) Blue.mat.
    let b1 = hash_id("Type:Transform->B10");
    let smr = hash_id("Type:SkinnedMeshRenderer->Body0");
    let blue = "b1e00000000000000000000000000000";
    let s = Z90[2].to_string();
    let mods = [
        modification(b1, G, "m_LocalPosition.y", "2", "{fileID: 0}"),
        modification(b1, G, "m_LocalRotation.z", &s, "{fileID: 0}"),
        modification(b1, G, "m_LocalRotation.w", &s, "{fileID: 0}"),
        modification(
            smr,
            G,
            "m_Materials.Array.data[0]",
            "",
            &format!("{{fileID: 2100000, guid: {blue}, type: 2}}"),
        ),
    ]
    .concat();
    let mut sc = Scene::default();
    sc.raw(&instance(500, G, &mods, " []"));
    sc.camera(&Tf::at(0.0, 0.0, -10.0));
    let (_d, root) = project(&[
        ("Assets/rig.fbx", &text_of(&skinned())),
        ("Assets/rig.fbx.meta", &model_meta(G, "")),
        ("Assets/Blue.mat", &mat("Blue", [0.0, 0.0, 1.0])),
        ("Assets/Blue.mat.meta", &guid_meta(blue)),
        ("Assets/s.unity", &sc.text),
    ]);
    let soup = report(&root, "Assets/s.unity").soup;
    assert!(soup.warnings.is_empty(), "{:?}", soup.warnings);
    assert_eq!(soup.materials[soup.tri_material[0] as usize].color, Vec3::Z);
    let pts = object_points(&soup, "rig/Body");
    assert_eq!(pts.len(), 3);
    for p in POSED {
        assert!(has_point(&pts, p), "{p} not in {pts:?}");
    }
}

#[test]
fn scene_skinned_mesh_renderer_uses_its_m_bones_or_falls_back_to_the_bind_pose() {
    // A scene SkinnedMeshRenderer on `Type:Mesh->Body0` whose m_Bones are two scene
    // Transforms: b0 at the origin, b1 at (0, 2, 0) turned 90° about Z: the same pose as
    // the instance test. A second one at (5, 0, 0) has no bones: drawn in the bind pose
    // at its own transform, Unity v1 (−1, 0, 0) → (4, 0, 0) → soup (−4, 0, 0).
    let body = hash_id("Type:Mesh->Body0");
    let mut sc = Scene::default();
    let (_, b0) = sc.object("b0", &Tf::at(0.0, 0.0, 0.0), 0, true);
    let (_, b1) = sc.object("b1", &Tf::at(0.0, 2.0, 0.0).rot(Z90), 0, true);
    let (go, _) = sc.object("Skin", &Tf::at(9.0, 9.0, 9.0), 0, true);
    let (lone, _) = sc.object("Lone", &Tf::at(5.0, 0.0, 0.0), 0, true);
    let smr = |go: i64, id: i64, bones: &str| {
        format!("--- !u!137 &{id}\nSkinnedMeshRenderer:\n  m_GameObject: {{fileID: {go}}}\n  m_Enabled: 1\n  m_Materials:\n  - {{fileID: 10303, guid: 0000000000000000f000000000000000, type: 0}}\n  m_Mesh: {{fileID: {body}, guid: {G}, type: 3}}\n  m_Bones:{bones}\n")
    };
    sc.raw(&smr(
        go,
        9001,
        &format!("\n  - {{fileID: {b0}}}\n  - {{fileID: {b1}}}"),
    ));
    sc.raw(&smr(lone, 9002, " []"));
    sc.camera(&Tf::at(0.0, 0.0, -10.0));
    let (_d, root) = project(&[
        ("Assets/rig.fbx", &text_of(&skinned())),
        ("Assets/rig.fbx.meta", &model_meta(G, "")),
        ("Assets/s.unity", &sc.text),
    ]);
    let soup = report(&root, "Assets/s.unity").soup;
    let pts = object_points(&soup, "Skin");
    for p in POSED {
        assert!(has_point(&pts, p), "{p} not in {pts:?}");
    }
    let lone = object_points(&soup, "Lone");
    assert!(has_point(&lone, Vec3::new(-4.0, 0.0, 0.0)), "{lone:?}");
    assert!(has_point(&lone, Vec3::new(-5.0, 1.0, 0.0)), "{lone:?}");
    assert_eq!(
        soup.warnings,
        ["Assets/s.unity: object 'Lone' (fileID 1007): SkinnedMeshRenderer has no bones (m_Bones is empty); drawn in its bind pose at the renderer's transform"]
    );
}

#[test]
fn an_fbx_mesh_without_material_is_unitys_no_name_for_remaps() {
    // A mesh with no material: Unity names its material "No Name"; the meta remaps that
    // name to Remap.mat (grey 0.5 → linear 0.21404114). Without the remap it is Unity's
    // default material, silently.
    let remap = "7e3a0000000000000000000000000000";
    let extra = format!("  externalObjects:\n  - first:\n      type: UnityEngine:Material\n      assembly: UnityEngine.CoreModule\n      name: No Name\n    second: {{fileID: 2100000, guid: {remap}, type: 2}}\n");
    let f = Fbx {
        nodes: vec![
            Node::new("Bare", None).mesh(Geometry::new(
                &[[0.0, 0.0, 0.0], [100.0, 0.0, 0.0], [0.0, 100.0, 0.0]],
                &[&[0, 1, 2]],
            )),
            Node::new("Other", None),
        ],
        ..Default::default()
    };
    let mut sc = Scene::default();
    sc.raw(&instance(500, G, "", " []"));
    sc.camera(&Tf::at(0.0, 0.0, -10.0));
    let (_d, root) = project(&[
        ("Assets/m.fbx", &text_of(&f)),
        ("Assets/m.fbx.meta", &model_meta(G, &extra)),
        ("Assets/Remap.mat", &mat("Remap", [0.5, 0.5, 0.5])),
        ("Assets/Remap.mat.meta", &guid_meta(remap)),
        ("Assets/s.unity", &sc.text),
    ]);
    let r = report(&root, "Assets/s.unity");
    assert!(r.soup.warnings.is_empty(), "{:?}", r.soup.warnings);
    assert_eq!(r.material_origins[0][0].1, "remap Assets/Remap.mat");
    assert_eq!(r.soup.materials[0].color, Vec3::splat(0.214_041_14));
    std::fs::write(root.join("Assets/m.fbx.meta"), model_meta(G, "")).unwrap();
    let r = report(&root, "Assets/s.unity");
    assert!(r.soup.warnings.is_empty(), "{:?}", r.soup.warnings);
    assert_eq!(r.material_origins[0][0].1, "default");
}
