//! The `unity2soup` and `soup2obj` binaries: arguments, JSON summary, exit codes, and
//! the OBJ export's layout.

use crate::support::*;
use std::process::Command;

fn scene() -> (tempfile::TempDir, std::path::PathBuf) {
    let mut sc = Scene::default();
    sc.camera(&Tf::at(0.0, 1.0, -10.0));
    sc.light(&Tf::at(0.0, 3.0, 0.0), 2, [1.0, 1.0, 1.0], 1);
    sc.primitive("Floor", &Tf::at(0.0, 0.0, 0.0), 0, PLANE);
    sc.primitive("Box A", &Tf::at(2.0, 0.5, 0.0), 0, CUBE);
    let linear = graphics_settings(1, 1);
    let (d, root) = project(&[
        ("Assets/Scenes/s.unity", &sc.text),
        (GRAPHICS_SETTINGS, &linear),
    ]);
    (d, root.join("Assets/Scenes/s.unity"))
}

#[test]
fn unity2soup_json_summary_and_soup_file() {
    let (d, scene) = scene();
    let out = d.path().join("s.soup");
    let o = Command::new(env!("CARGO_BIN_EXE_unity2soup"))
        .arg(&scene)
        .arg("-o")
        .arg(&out)
        .arg("--json")
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let j: serde_json::Value =
        serde_json::from_slice(&o.stdout).expect("one JSON object on stdout");
    assert_eq!(j["objects"], 2);
    assert_eq!(j["triangles"], 212);
    assert_eq!(j["lights"], 1);
    assert_eq!(j["materials"], 1);
    assert_eq!(j["warnings"].as_array().unwrap().len(), 0);
    assert!(j["seconds"].as_f64().unwrap() >= 0.0);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        stderr.contains("2 objects, 212 triangles, 1 lights"),
        "{stderr}"
    );
    let soup = formats::Soup::read(&out).unwrap();
    assert_eq!(soup.triangles.len(), 212);

    // soup2obj: one `o` per object, faces in soup order, a normal per corner.
    let obj = d.path().join("s.obj");
    let o = Command::new(env!("CARGO_BIN_EXE_soup2obj"))
        .arg(&out)
        .arg("-o")
        .arg(&obj)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = std::fs::read_to_string(&obj).unwrap();
    let objects: Vec<&str> = text.lines().filter(|l| l.starts_with("o ")).collect();
    assert_eq!(objects, ["o Floor", "o Box A"]);
    assert_eq!(text.lines().filter(|l| l.starts_with("f ")).count(), 212);
    assert_eq!(
        text.lines().filter(|l| l.starts_with("vn ")).count(),
        212 * 3
    );
    // The first face is the soup's first triangle.
    let v: Vec<&str> = text
        .lines()
        .filter(|l| l.starts_with("v "))
        .take(3)
        .collect();
    let t = soup.corners(0);
    assert_eq!(v[0], format!("v {} {} {}", t[0].x, t[0].y, t[0].z));
    assert_eq!(v[2], format!("v {} {} {}", t[2].x, t[2].y, t[2].z));
}

#[test]
fn errors_exit_1_with_one_line_and_bad_usage_exits_2() {
    let d = tempfile::tempdir().unwrap();
    let missing = d.path().join("nope.unity");
    let o = Command::new(env!("CARGO_BIN_EXE_unity2soup"))
        .arg(&missing)
        .arg("-o")
        .arg(d.path().join("x.soup"))
        .arg("--assets")
        .arg(d.path())
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(e.contains("nope.unity") && e.lines().count() == 1, "{e}");

    let (_p, root) = project(&[("Assets/b.unity", "\0\0\u{2e}K\0\0\u{36}\u{c}")]);
    let o = Command::new(env!("CARGO_BIN_EXE_unity2soup"))
        .arg(root.join("Assets/b.unity"))
        .arg("-o")
        .arg(d.path().join("x.soup"))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("binary"));
    assert!(!d.path().join("x.soup").exists(), "no output on failure");

    let o = Command::new(env!("CARGO_BIN_EXE_unity2soup"))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));

    let o = Command::new(env!("CARGO_BIN_EXE_soup2obj"))
        .arg(d.path().join("none.soup"))
        .arg("-o")
        .arg(d.path().join("x.obj"))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("none.soup"));
}

#[test]
fn unity2soup_list_says_where_each_material_came_from() {
    // Both primitives' slots name Unity's built-in Default-Material.
    let (_d, scene) = scene();
    let stderr = list(&scene);
    assert!(
        stderr.starts_with("project: the built-in render pipeline; light intensity linear, colour temperature on; colour space linear; quality-level shadows All; LOD bias 1\n"),
        "{stderr}"
    );
    assert!(
        stderr.contains("object \"Box A\": 12 triangles from builtin:Cube [Default-Material rgb(1.000,1.000,1.000) cull Back from default], layer 0, shadows On"),
        "{stderr}"
    );
}

/// What `unity2soup SCENE -o s.soup --list` prints, asserting it succeeds.
fn list(scene: &std::path::Path) -> String {
    let d = tempfile::tempdir().unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_unity2soup"))
        .arg(scene)
        .arg("-o")
        .arg(d.path().join("s.soup"))
        .arg("--list")
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    String::from_utf8_lossy(&o.stderr).into_owned()
}

#[test]
fn unity2soup_list_names_each_materials_maps() {
    let textures = |name: &str| {
        list(
            &std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"))
                .join(format!("../../scenes/textures/Assets/Scenes/{name}.unity")),
        )
    };
    let bent = textures("NormalMap");
    assert!(
        bent.contains("material \"Bent\" (Assets/Materials/Bent.mat): no texture, normal map Assets/Textures/Bent.png 2x2 scale 1, opacity 1, alpha Opaque"),
        "{bent}"
    );
    let glow = textures("EmissionMap");
    assert!(
        glow.contains("material \"Glow\" (Assets/Materials/Glow.mat): no texture, emission map Assets/Textures/Quadrants.png 2x2, opacity 1, alpha Opaque"),
        "{glow}"
    );
}

#[test]
fn unity2soup_list_marks_unlit_materials() {
    let mut sc = Scene::default();
    let (go, _) = sc.object("Sign", &Tf::at(0.0, 0.0, 0.0), 0, true);
    sc.mesh(
        go,
        CUBE,
        BUILTIN,
        &[(2100000, "0123456789abcdef0123456789abcdef")],
        true,
    );
    let flat = "%YAML 1.1\n--- !u!21 &2100000\nMaterial:\n  m_Name: Flat\n  m_Shader: {fileID: 10755, guid: 0000000000000000f000000000000000, type: 0}\n  m_SavedProperties:\n    m_Colors:\n    - _Color: {r: 1, g: 0, b: 0, a: 1}\n";
    let (_d, root) = project(&[
        ("Assets/s.unity", sc.text.as_str()),
        ("Assets/Flat.mat", flat),
        (
            "Assets/Flat.mat.meta",
            "fileFormatVersion: 2\nguid: 0123456789abcdef0123456789abcdef\n",
        ),
    ]);
    let stderr = list(&root.join("Assets/s.unity"));
    assert!(
        stderr.contains(
            "material \"Flat\" (Assets/Flat.mat): no texture, opacity 1, alpha Opaque, unlit"
        ),
        "{stderr}"
    );
}

#[test]
fn unity2soup_renders_the_camera_it_is_asked_for_and_names_the_others_when_none_matches() {
    let (d, scene) = scene();
    let out = d.path().join("s.soup");
    let run = |name: &str| {
        Command::new(env!("CARGO_BIN_EXE_unity2soup"))
            .arg(&scene)
            .arg("-o")
            .arg(&out)
            .arg("--camera")
            .arg(name)
            .output()
            .unwrap()
    };
    let o = run("Main Camera");
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let soup = formats::Soup::read(&out).unwrap();
    assert_eq!(soup.camera.position, glam::Vec3::new(0.0, 1.0, -10.0));
    std::fs::remove_file(&out).unwrap();
    let o = run("Drone");
    assert_eq!(o.status.code(), Some(1));
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(
        e.contains("no enabled camera is named 'Drone'; the enabled cameras: Main Camera"),
        "{e}"
    );
    assert!(!out.exists(), "no output on failure");
}
