//! Unity input: broken scenes, references and numbers are named and the rest converts;
//! asset paths never escape the project.

use super::cases::*;
use super::noise::noise;
use super::project::*;
use formats::Soup;
use glam::Vec3;
use std::path::Path;
use unitrace::run;

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
        &[&format!("{}: is not a Unity scene or prefab", s(&utf16))],
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
        // Once: the OS error is not repeated as the message's cause.
        &[&format!(
            "{}: No such file or directory (os error 2)\n",
            s(&missing)
        )],
    );
    let dir_scene = p.root.join("Assets");
    add(
        &mut cases,
        "a directory as the scene",
        &dir_scene,
        &[],
        1,
        &[&format!("{}: is a folder, not a scene file", s(&dir_scene))],
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
            // Named from the project root, as every other warning names files.
            &format!(
                "duplicate GUID {g} in Assets/B/two.obj and Assets/A/one.obj; using the first"
            ),
            "14 triangles",
        ],
        Out::Written(o),
    )]);
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
    let link = format!("warning: Assets/linked: symbolic link to {}", s(&outside));
    for want in ["secret.mtl", "outside the project", g_out, &link] {
        assert!(
            r.stderr.contains(want),
            "stderr lacks `{want}`:\n{}",
            r.stderr
        );
    }
}
