//! The FBX reader on small ASCII FBX 7.4 files written by the test, with the expected
//! Unity-space numbers worked out by hand in each test's comment.
//!
//! Conventions used in the derivations: Unity = mirror(file) with mirror (x, y, z) →
//! (−x, y, z); quaternions (x, y, z, w) → (x, −y, −z, w); Rx(−90°) maps (x, y, z) →
//! (x, z, −y) and Ry(90°) maps (x, y, z) → (z, y, −x).

use crate::fbx_ascii::{Cluster, Fbx, Geometry, Node, SkinSpec};
use glam::{Mat4, Quat, Vec3};
use unity::fbx;
use unity::meta::ModelMeta;
use unity::model::Model;

const H: f32 = std::f32::consts::FRAC_1_SQRT_2;

fn meta(yaml: &str) -> ModelMeta {
    ModelMeta::parse(&format!("ModelImporter:\n{yaml}"))
}

/// `useFileScale: 1`, `globalScale: 1`, as Unity 2017+ writes a fresh import.
fn file_scale() -> ModelMeta {
    meta("  meshes:\n    globalScale: 1\n    useFileScale: 1\n")
}

fn load(f: &Fbx, stem: &str, m: &ModelMeta) -> Model {
    let dir = tempfile::tempdir().unwrap();
    let p = f.write(dir.path(), stem);
    fbx::load(&p, m).unwrap_or_else(|e| panic!("{e}\n{}", f.text()))
}

fn local(m: &Model, i: usize) -> Mat4 {
    let n = &m.nodes[i];
    Mat4::from_scale_rotation_translation(n.scale, n.rotation, n.translation)
}

fn world(m: &Model, i: usize) -> Mat4 {
    match m.nodes[i].parent {
        Some(p) => world(m, p) * local(m, i),
        None => local(m, i),
    }
}

/// World positions of the mesh on node `i`, in the mesh's vertex order.
fn world_positions(m: &Model, i: usize) -> Vec<Vec3> {
    let w = world(m, i);
    let mesh = &m.meshes[m.nodes[i].mesh.expect("node has a mesh")].mesh;
    mesh.positions
        .iter()
        .map(|&p| w.transform_point3(p))
        .collect()
}

/// Every triangle's corners, in order, world space.
fn world_triangles(m: &Model, i: usize) -> Vec<[Vec3; 3]> {
    let w = world(m, i);
    let mesh = &m.meshes[m.nodes[i].mesh.unwrap()].mesh;
    mesh.submeshes
        .iter()
        .flatten()
        .map(|t| t.map(|k| w.transform_point3(mesh.positions[k as usize])))
        .collect()
}

fn close(a: Vec3, b: Vec3) -> bool {
    (a - b).abs().max_element() < 1e-5
}

fn assert_has(points: &[Vec3], want: &[Vec3]) {
    for w in want {
        assert!(
            points.iter().any(|p| close(*p, *w)),
            "{w} not among {points:?}"
        );
    }
}

fn close_q(a: Quat, b: Quat) -> bool {
    a.dot(b).abs() > 1.0 - 1e-6
}

const TRI: [[f64; 3]; 3] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];

#[test]
fn identity_placement_negates_x_and_flips_winding() {
    // One node, no transform, no units conversion (a Unity 5 meta: globalScale 1, no
    // useFileScale). File triangle (0,0,0) (1,0,0) (0,1,0), counter-clockwise seen from
    // +Z; Unity: (0,0,0) (−1,0,0) (0,1,0), listed in reverse order after the first
    // corner: (0,0,0) (0,1,0) (−1,0,0). The root has one child, so the model collapses
    // into it: one node, named after the file, its mesh named after the FBX node.
    // Computed normal: the file's +Z mirrored, still +Z.
    let f = Fbx {
        nodes: vec![Node::new("Tri", None).mesh(Geometry::new(&TRI, &[&[0, 1, 2]]))],
        ..Default::default()
    };
    let m = load(&f, "single", &meta("  meshes:\n    globalScale: 1\n"));
    assert_eq!(m.nodes.len(), 1);
    assert_eq!(m.nodes[0].name, "single");
    assert_eq!(m.meshes.len(), 1);
    assert_eq!(m.meshes[0].name, "Tri");
    assert_eq!(m.meshes[0].materials, [""]);
    let t = world_triangles(&m, 0);
    assert_eq!(t.len(), 1);
    let want = [Vec3::ZERO, Vec3::Y, Vec3::NEG_X];
    assert!(t[0].iter().zip(want).all(|(a, b)| close(*a, b)), "{t:?}");
    let mesh = &m.meshes[0].mesh;
    assert!(
        mesh.normals.iter().all(|n| close(*n, Vec3::Z)),
        "{:?}",
        mesh.normals
    );
    assert!(m.warnings.is_empty(), "{:?}", m.warnings);
}

#[test]
fn file_normals_are_mirrored_and_split_where_the_file_splits_them() {
    // Two triangles sharing the edge (1,0,0)–(0,1,0); the file gives the first +X normals
    // and the second +Y normals at every corner. Unity: +X → (−1,0,0), +Y stays; the two
    // shared positions get one vertex per normal: 4 positions + 2 duplicates = 6.
    let mut g = Geometry::new(
        &[
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [1.0, 1.0, 0.0],
        ],
        &[&[0, 1, 2], &[1, 3, 2]],
    );
    g.normals = Some(vec![
        [1.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
    ]);
    let f = Fbx {
        nodes: vec![Node::new("N", None).mesh(g)],
        ..Default::default()
    };
    let m = load(&f, "normals", &file_scale());
    let mesh = &m.meshes[0].mesh;
    assert_eq!(mesh.positions.len(), 6);
    let t = &mesh.submeshes[0];
    assert!(t[0]
        .iter()
        .all(|&k| close(mesh.normals[k as usize], Vec3::NEG_X)));
    assert!(t[1]
        .iter()
        .all(|&k| close(mesh.normals[k as usize], Vec3::Y)));
    // normalImportMode 1 (Calculate) ignores them: the flat quad's normal, +Z.
    let calc = meta("  meshes:\n    useFileScale: 1\n  tangentSpace:\n    normalImportMode: 1\n");
    let m = load(&f, "normals", &calc);
    let mesh = &m.meshes[0].mesh;
    assert_eq!(mesh.positions.len(), 4);
    assert!(
        mesh.normals.iter().all(|n| close(*n, Vec3::Z)),
        "{:?}",
        mesh.normals
    );
}

#[test]
fn blender_style_root_rotation_and_scale_stay_on_the_node() {
    // Blender: UnitScaleFactor 1 (cm), the object with Lcl Rotation (−90,0,0), Lcl
    // Scaling 100, here Lcl Translation (100,200,300); useFileScale: 1 → ×0.01.
    // Node (collapsed into the root): translation (100,200,300)·0.01 mirrored = (−1,2,3);
    // rotation Rx(−90°) = (−√½,0,0,√½), unchanged by the mirror; scale 100 (not touched
    // by the unit). Vertex (1,2,3) → mesh (−0.01,0.02,0.03). World, in the file:
    // (100,200,300) + Rx(−90°)·100·(1,2,3) = (100,200,300) + (100,300,−200) = (200,500,100)
    // cm = (2,5,1) m, mirrored (−2,5,1). Same in Unity: S·v = (−1,2,3), R·(−1,2,3) =
    // (−1,3,−2), + (−1,2,3) = (−2,5,1).
    let g = Geometry::new(
        &[[1.0, 2.0, 3.0], [0.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        &[&[0, 1, 2]],
    );
    let f = Fbx {
        nodes: vec![Node::new("Cube", None)
            .prop("Lcl Translation", [100.0, 200.0, 300.0])
            .prop("Lcl Rotation", [-90.0, 0.0, 0.0])
            .prop("Lcl Scaling", [100.0, 100.0, 100.0])
            .mesh(g)],
        ..Default::default()
    };
    let m = load(&f, "blender", &file_scale());
    assert_eq!(m.nodes.len(), 1);
    let n = &m.nodes[0];
    assert!(close(n.translation, Vec3::new(-1.0, 2.0, 3.0)), "{n:?}");
    assert!(
        close_q(n.rotation, Quat::from_xyzw(-H, 0.0, 0.0, H)),
        "{n:?}"
    );
    assert!(close(n.scale, Vec3::splat(100.0)), "{n:?}");
    let mesh = &m.meshes[0].mesh;
    assert_has(&mesh.positions, &[Vec3::new(-0.01, 0.02, 0.03)]);
    assert_has(&world_positions(&m, 0), &[Vec3::new(-2.0, 5.0, 1.0)]);
}

#[test]
fn max_style_pre_rotation_inches_and_geometric_translation() {
    // 3ds Max: UnitScaleFactor 2.54 (inches) → ×0.0254 with useFileScale: 1. Box: Lcl
    // Translation (10,0,0), PreRotation (−90,0,0), GeometricTranslation (0,0,5); its
    // child Helper: Lcl Translation (0,0,10).
    // Box vertex (1,0,0): in the file, world = (10,0,0) + Rx(−90°)·((1,0,0) + (0,0,5)) =
    // (10,0,0) + (1,5,0) = (11,5,0) in → (0.2794,0.127,0) m → mirrored (−0.2794,0.127,0).
    // Box node: translation (−0.254,0,0), rotation Rx(−90°); its mesh vertex
    // (1,0,5)·0.0254 mirrored = (−0.0254,0,0.127).
    // Helper: local translation (0,0,0.254) exactly (the geometric translation is the
    // mesh's only); world (−0.254,0,0) + Rx(−90°)·(0,0,0.254) = (−0.254,0.254,0).
    let g = Geometry::new(&TRI, &[&[0, 1, 2]]);
    let f = Fbx {
        unit_scale_factor: 2.54,
        nodes: vec![
            Node::new("Box", None)
                .prop("Lcl Translation", [10.0, 0.0, 0.0])
                .prop("PreRotation", [-90.0, 0.0, 0.0])
                .prop("GeometricTranslation", [0.0, 0.0, 5.0])
                .mesh(g),
            Node::new("Helper", Some(0)).prop("Lcl Translation", [0.0, 0.0, 10.0]),
        ],
        ..Default::default()
    };
    let m = load(&f, "max", &file_scale());
    let names: Vec<_> = m.nodes.iter().map(|n| n.name.as_str()).collect();
    assert_eq!(names, ["max", "Helper"]);
    assert!(close(m.nodes[0].translation, Vec3::new(-0.254, 0.0, 0.0)));
    assert!(close_q(
        m.nodes[0].rotation,
        Quat::from_xyzw(-H, 0.0, 0.0, H)
    ));
    assert_has(
        &m.meshes[0].mesh.positions,
        &[Vec3::new(-0.0254, 0.0, 0.127)],
    );
    assert_has(&world_positions(&m, 0), &[Vec3::new(-0.2794, 0.127, 0.0)]);
    assert!(
        close(m.nodes[1].translation, Vec3::new(0.0, 0.0, 0.254)),
        "{:?}",
        m.nodes[1]
    );
    let helper = world(&m, 1).transform_point3(Vec3::ZERO);
    assert!(close(helper, Vec3::new(-0.254, 0.254, 0.0)), "{helper}");
}

#[test]
fn maya_style_pivots_move_into_the_node_translation() {
    // A door hinged at its rotation/scaling pivot (50,0,0) cm, Lcl Rotation (0,90,0).
    // FBX: world = T + Rp + R·(v − Rp). Vertex (100,0,0): (50,0,0) + Ry(90°)·(50,0,0) =
    // (50,0,0) + (0,0,−50) = (50,0,−50) cm → (0.5,0,−0.5) m → mirrored (−0.5,0,−0.5).
    // Unity: the node translation gains the pivot, (50,0,0)·0.01 mirrored = (−0.5,0,0);
    // mesh vertices are relative to the pivot: (100,0,0) → (50,0,0)·0.01 mirrored =
    // (−0.5,0,0), the hinge vertex (50,0,0) → the origin. Rotation Ry(90°) = (0,√½,0,√½)
    // mirrored (0,−√½,0,√½).
    let g = Geometry::new(
        &[[50.0, 0.0, 0.0], [100.0, 0.0, 0.0], [50.0, 100.0, 0.0]],
        &[&[0, 1, 2]],
    );
    let f = Fbx {
        nodes: vec![Node::new("Door", None)
            .prop("Lcl Rotation", [0.0, 90.0, 0.0])
            .prop("RotationPivot", [50.0, 0.0, 0.0])
            .prop("ScalingPivot", [50.0, 0.0, 0.0])
            .mesh(g)],
        ..Default::default()
    };
    let m = load(&f, "door", &file_scale());
    let n = &m.nodes[0];
    assert!(close(n.translation, Vec3::new(-0.5, 0.0, 0.0)), "{n:?}");
    assert!(
        close_q(n.rotation, Quat::from_xyzw(0.0, -H, 0.0, H)),
        "{n:?}"
    );
    assert_has(
        &m.meshes[0].mesh.positions,
        &[Vec3::ZERO, Vec3::new(-0.5, 0.0, 0.0)],
    );
    assert_has(&world_positions(&m, 0), &[Vec3::new(-0.5, 0.0, -0.5)]);
}

#[test]
fn z_up_axis_conversion_below_the_root_or_baked() {
    // Up +Z; UnitScaleFactor 100 (m) → ×1. Unity goes by the up axis alone and treats a
    // Z-up file as right −X, up +Z, front +Y: before the mirror (x,y,z) → (−x,z,y), the
    // half turn about (0,1,1)/√2, quaternion (0,½√2,½√2,0), mirrored (0,−½√2,−½√2,0);
    // after the mirror a file point lands at (x,z,y). Checked for two files that differ
    // only in front and right signs: 3ds Max's (right +X, front −Y) and Blender-style
    // (right −X, front +Y).
    // Two root children (no collapse): A at (1,2,3) with vertices (1,0,0) (0,1,0)
    // (0,0,1), and an empty B. World positions either way: (t + v) with y and z swapped:
    // (2,2,3) → (2,3,2); (1,3,3) → (1,3,3); (1,2,4) → (1,4,2).
    // bakeAxisConversion 0: each node under the file's root carries the rotation (the
    // model's root stays identity): A's rotation is the half turn, its translation the
    // half turn of mirror(1,2,3) = (−1,2,3) → (1,3,2), its vertex (1,0,0) → (−1,0,0).
    // bakeAxisConversion 1: root rotation identity, A's translation (1,3,2), vertices
    // (1,0,0) (0,0,1) (0,1,0).
    for axes in [[2, 1, 1, -1, 0, 1], [2, 1, 1, 1, 0, -1]] {
        let g = Geometry::new(
            &[[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            &[&[0, 1, 2]],
        );
        let f = Fbx {
            axes,
            unit_scale_factor: 100.0,
            nodes: vec![
                Node::new("A", None)
                    .prop("Lcl Translation", [1.0, 2.0, 3.0])
                    .mesh(g),
                Node::new("B", None),
            ],
            ..Default::default()
        };
        let world_want = [
            Vec3::new(2.0, 3.0, 2.0),
            Vec3::new(1.0, 3.0, 3.0),
            Vec3::new(1.0, 4.0, 2.0),
        ];
        let m = load(&f, "zup", &file_scale());
        assert_eq!(m.nodes.len(), 3);
        assert!(
            close_q(m.nodes[0].rotation, Quat::IDENTITY),
            "{:?}",
            m.nodes[0]
        );
        for n in &m.nodes[1..] {
            let q = n.rotation;
            assert!(
                close_q(q, Quat::from_xyzw(0.0, -H, -H, 0.0)),
                "{axes:?}: {n:?}"
            );
        }
        assert!(close(m.nodes[1].translation, Vec3::new(1.0, 3.0, 2.0)));
        assert_has(&m.meshes[0].mesh.positions, &[Vec3::NEG_X]);
        assert_has(&world_positions(&m, 1), &world_want);

        let baked = meta("  meshes:\n    useFileScale: 1\n    bakeAxisConversion: 1\n");
        let m = load(&f, "zup", &baked);
        assert!(
            close_q(m.nodes[0].rotation, Quat::IDENTITY),
            "{:?}",
            m.nodes[0]
        );
        assert!(close(m.nodes[1].translation, Vec3::new(1.0, 3.0, 2.0)));
        assert_has(&m.meshes[0].mesh.positions, &[Vec3::X, Vec3::Z, Vec3::Y]);
        assert_has(&world_positions(&m, 1), &world_want);
    }
}

#[test]
fn sub_meshes_follow_the_node_material_slots() {
    // Materials defined blue, red, green; the node's slots are red, green, blue. Polygons:
    // a triangle (slot 2), a triangle (slot 0), a quad (slot 1), a pentagon (slot 0).
    // Sub-meshes in slot order: red = triangle + pentagon (1 + 3 = 4 triangles),
    // green = the quad (2), blue = one triangle.
    let v = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
        [-1.0, 0.5, 0.0],
    ];
    let mut g = Geometry::new(
        &v,
        &[&[0, 1, 2], &[0, 2, 3], &[0, 1, 2, 3], &[0, 1, 2, 3, 4]],
    );
    g.poly_materials = Some(vec![2, 0, 1, 0]);
    let f = Fbx {
        materials: vec![
            ("blue".into(), [0.0, 0.0, 1.0]),
            ("red".into(), [1.0, 0.0, 0.0]),
            ("green".into(), [0.0, 1.0, 0.0]),
        ],
        nodes: vec![Node::new("M", None).mesh(g).materials(&[1, 2, 0])],
        ..Default::default()
    };
    let m = load(&f, "mats", &file_scale());
    assert_eq!(m.meshes[0].materials, ["red", "green", "blue"]);
    let counts: Vec<usize> = m.meshes[0].mesh.submeshes.iter().map(Vec::len).collect();
    assert_eq!(counts, [4, 2, 1]);
    assert_eq!(m.triangle_count(), 7);
    assert_eq!(m.material("red").unwrap().color, Vec3::X);
    assert_eq!(m.material("blue").unwrap().color, Vec3::Z);
    assert_eq!(m.material("green").unwrap().texture, None);
}

#[test]
fn duplicate_node_names_are_kept_depth_first() {
    // Root children Part, Part; the first has a child Part. Depth first, parents first:
    // root, Part (0), Part (its child), Part (1), each with its own mesh; the vertex x
    // tells them apart (1, 2, 3 cm in the file → −0.01, −0.02, −0.03 in Unity).
    let part = |x: f64| {
        Geometry::new(
            &[[x, 0.0, 0.0], [x, 1.0, 0.0], [x, 0.0, 1.0]],
            &[&[0, 1, 2]],
        )
    };
    let f = Fbx {
        nodes: vec![
            Node::new("Part", None).mesh(part(1.0)),
            Node::new("Part", None).mesh(part(3.0)),
            Node::new("Part", Some(0)).mesh(part(2.0)),
        ],
        ..Default::default()
    };
    let m = load(&f, "dups", &file_scale());
    let shape: Vec<(&str, Option<usize>)> = m
        .nodes
        .iter()
        .map(|n| (n.name.as_str(), n.parent))
        .collect();
    assert_eq!(
        shape,
        [
            ("dups", None),
            ("Part", Some(0)),
            ("Part", Some(1)),
            ("Part", Some(0))
        ]
    );
    for (i, x) in [(1, -0.01), (2, -0.02), (3, -0.03)] {
        let mesh = &m.meshes[m.nodes[i].mesh.unwrap()];
        assert_eq!(mesh.name, "Part");
        assert!(
            (mesh.mesh.positions[0].x - x).abs() < 1e-6,
            "node {i}: {mesh:?}"
        );
    }
}

#[test]
fn unreadable_files_are_typed_errors_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let m = file_scale();
    let missing = dir.path().join("missing.fbx");
    let e = fbx::load(&missing, &m).unwrap_err();
    assert!(matches!(e, fbx::FbxError::Io { .. }), "{e}");
    assert!(e.to_string().contains("missing.fbx"), "{e}");

    let lfs = dir.path().join("lfs.fbx");
    std::fs::write(
        &lfs,
        "version https://git-lfs.github.com/spec/v1\noid sha256:00\nsize 3\n",
    )
    .unwrap();
    let e = fbx::load(&lfs, &m).unwrap_err();
    assert!(matches!(e, fbx::FbxError::LfsPointer(_)), "{e}");
    assert!(e.to_string().contains("git lfs pull"), "{e}");

    // An OBJ saved as .fbx is not read as OBJ.
    let obj = dir.path().join("obj.fbx");
    std::fs::write(&obj, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    let e = fbx::load(&obj, &m).unwrap_err();
    assert!(matches!(e, fbx::FbxError::Corrupt { .. }), "{e}");
    println!("{e}");

    let junk = dir.path().join("junk.fbx");
    std::fs::write(
        &junk,
        b"Kaydara FBX Binary  \x00\x1a\x00\xe8\x1c\x00\x00\xff\xff\xff\xff",
    )
    .unwrap();
    let e = fbx::load(&junk, &m).unwrap_err();
    assert!(matches!(e, fbx::FbxError::Corrupt { .. }), "{e}");
    assert!(
        e.to_string().starts_with(&format!("{}: ", junk.display())),
        "{e}"
    );
}

#[test]
fn the_fuzz_seed_loads() {
    // 3ds Max axes, inches, a pivot and a geometric translation; a triangle on the first
    // material and a quad on the second.
    let p = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fuzz/corpus/unity_fbx/seed-triangle.fbx");
    let m = fbx::load(&p, &file_scale()).unwrap();
    assert_eq!(m.meshes[0].materials, ["red", "blue"]);
    assert_eq!(m.triangle_count(), 3);
    assert_eq!(m.materials.len(), 2);
}

#[test]
fn skin_bones_bind_poses_and_four_normalised_weights() {
    // A mesh at the origin skinned to five bones B0..B4 whose bind-time global matrices
    // are translations (10k, 100, 0) cm; the mesh's is the identity, so mesh → bone at
    // bind is the translation (−10k, −100, 0). Unity's bind pose of
    // B_k = (bone world at bind)⁻¹ · (mesh world): the bone sits at (−0.1k, 1, 0) in Unity
    // (×0.01, X mirrored), so the bind pose is the translation (0.1k, −1, 0).
    // Weights: vertex 0 has B0..B4 at 0.1..0.5 → the four largest, largest first,
    // normalised by 1.4: B4 5/14, B3 4/14, B2 3/14, B1 2/14. Vertex 1: B0 0.5, B1 1.5 →
    // B1 0.75, B0 0.25. Vertex 2: B2 alone → 1.
    let v = [[0.0, 0.0, 0.0], [100.0, 0.0, 0.0], [0.0, 100.0, 0.0]];
    let mut nodes = vec![Node::new("Body", None).mesh(Geometry::new(&v, &[&[0, 1, 2]]))];
    let mut clusters = Vec::new();
    for k in 0..5 {
        nodes.push(
            Node::new(&format!("B{k}"), None)
                .limb()
                .prop("Lcl Translation", [10.0 * k as f64, 100.0, 0.0]),
        );
        let mut weights = vec![(0, 0.1 * (k + 1) as f64)];
        match k {
            0 => weights.push((1, 0.5)),
            1 => weights.push((1, 1.5)),
            2 => weights.push((2, 1.0)),
            _ => {}
        }
        let mut link = [0.0; 16];
        for i in 0..4 {
            link[i * 5] = 1.0;
        }
        let mut transform = link;
        link[12] = 10.0 * k as f64;
        link[13] = 100.0;
        transform[12] = -10.0 * k as f64;
        transform[13] = -100.0;
        clusters.push(Cluster {
            bone: k + 1,
            weights,
            transform,
            link,
        });
    }
    let f = Fbx {
        nodes,
        skins: vec![SkinSpec { mesh: 0, clusters }],
        ..Default::default()
    };
    let m = load(&f, "skinned", &file_scale());
    let mm = &m.meshes[0];
    let skin = mm.skin.as_ref().expect("a skin");
    assert_eq!(skin.bones, ["B0", "B1", "B2", "B3", "B4"]);
    for (k, b) in skin.bind_poses.iter().enumerate() {
        let want = Mat4::from_translation(Vec3::new(0.1 * k as f32, -1.0, 0.0));
        assert!(b.abs_diff_eq(want, 1e-5), "bone {k}: {b}");
    }
    let at = |p: Vec3| {
        let i = mm.mesh.positions.iter().position(|q| close(*q, p)).unwrap();
        skin.weights[i]
    };
    let w0 = at(Vec3::ZERO);
    let want0 = [
        (4, 5.0 / 14.0),
        (3, 4.0 / 14.0),
        (2, 3.0 / 14.0),
        (1, 2.0 / 14.0),
    ];
    for (got, want) in w0.iter().zip(want0) {
        assert_eq!(got.0, want.0, "{w0:?}");
        assert!((got.1 - want.1).abs() < 1e-6, "{w0:?}");
    }
    let w1 = at(Vec3::new(-1.0, 0.0, 0.0));
    assert_eq!((w1[0].0, w1[1].0), (1, 0), "{w1:?}");
    assert!(
        (w1[0].1 - 0.75).abs() < 1e-6 && (w1[1].1 - 0.25).abs() < 1e-6,
        "{w1:?}"
    );
    assert_eq!(w1[2].1 + w1[3].1, 0.0);
    let w2 = at(Vec3::new(0.0, 1.0, 0.0));
    assert_eq!(w2[0], (2, 1.0), "{w2:?}");
}

#[test]
fn blend_shapes_are_ignored_with_a_warning_naming_the_mesh() {
    // The shape would lift vertex 0 by 1 cm; ignored, the mesh keeps its rest pose.
    let f = Fbx {
        nodes: vec![
            Node::new("Face", None).mesh(Geometry::new(&TRI, &[&[0, 1, 2]])),
            Node::new("Other", None),
        ],
        blend_shapes: vec![0],
        ..Default::default()
    };
    let m = load(&f, "morph", &file_scale());
    assert_eq!(m.warnings, ["mesh Face: blend shapes ignored"]);
    assert_has(&m.meshes[0].mesh.positions, &[Vec3::ZERO]);
}
