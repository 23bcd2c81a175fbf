//! Unity's draw rules through the three binaries, on a Unity scene written by hand: a
//! Quad seen from behind, a layer the camera's culling mask leaves out and a LOD1
//! renderer all show the camera's solid background where they stand, while a Quad seen
//! from the front and the LOD0 renderer are drawn.
//!
//! The camera is at Unity (0, 1, −10) looking along +Z (60° vertical, 64×48 pixels, so a
//! pixel is about 0.24 m at z = 0); each object is 2 m across, centred at z = 0.

use glam::Vec3;
use unitrace::{run_ok, Rgba};

const MESH: &str = "0000000000000000e000000000000000";
const EXTRA: &str = "0000000000000000f000000000000000";
const QUAD: i64 = 10210;
const CUBE: i64 = 10202;

/// GameObject `go` (Transform go+1, MeshFilter go+2, MeshRenderer go+3) on `layer`.
fn object(go: i64, name: &str, layer: u8, pos: [f32; 3], rot_y_180: bool, mesh: i64) -> String {
    let [x, y, z] = pos;
    let (qy, qw) = if rot_y_180 { (1, 0) } else { (0, 1) };
    format!(
        "--- !u!1 &{go}\nGameObject:\n  m_Component:\n  - component: {{fileID: {t}}}\n  m_Layer: {layer}\n  m_Name: {name}\n  m_IsActive: 1\n--- !u!4 &{t}\nTransform:\n  m_GameObject: {{fileID: {go}}}\n  m_LocalRotation: {{x: 0, y: {qy}, z: 0, w: {qw}}}\n  m_LocalPosition: {{x: {x}, y: {y}, z: {z}}}\n  m_LocalScale: {{x: 2, y: 2, z: 2}}\n  m_Children: []\n  m_Father: {{fileID: 0}}\n--- !u!33 &{mf}\nMeshFilter:\n  m_GameObject: {{fileID: {go}}}\n  m_Mesh: {{fileID: {mesh}, guid: {MESH}, type: 0}}\n--- !u!23 &{mr}\nMeshRenderer:\n  m_GameObject: {{fileID: {go}}}\n  m_Enabled: 1\n  m_Materials:\n  - {{fileID: 10303, guid: {EXTRA}, type: 0}}\n",
        t = go + 1,
        mf = go + 2,
        mr = go + 3
    )
}

fn scene() -> String {
    let mut s = String::from("%YAML 1.1\n%TAG !u! tag:unity3d.com,2011:\n");
    s += "--- !u!1 &1\nGameObject:\n  m_Component:\n  - component: {fileID: 2}\n  m_Layer: 0\n  m_Name: Main Camera\n  m_IsActive: 1\n--- !u!4 &2\nTransform:\n  m_GameObject: {fileID: 1}\n  m_LocalRotation: {x: 0, y: 0, z: 0, w: 1}\n  m_LocalPosition: {x: 0, y: 1, z: -10}\n  m_LocalScale: {x: 1, y: 1, z: 1}\n  m_Children: []\n  m_Father: {fileID: 0}\n--- !u!20 &3\nCamera:\n  m_GameObject: {fileID: 1}\n  m_Enabled: 1\n  m_ClearFlags: 2\n  m_BackGroundColor: {r: 0.2, g: 0.3, b: 0.5, a: 0}\n  m_CullingMask:\n    serializedVersion: 2\n    m_Bits: 4294967039\n  near clip plane: 0.3\n  field of view: 60\n  orthographic: 0\n  m_Depth: -1\n";
    // Unity's Quad faces −Z, towards the camera; turned 180° about Y it shows its back.
    s += &object(10, "Back", 0, [-4.0, 1.0, 0.0], true, QUAD);
    s += &object(20, "Front", 0, [0.0, 1.0, 0.0], false, QUAD);
    s += &object(30, "OnLayer8", 8, [4.0, 1.0, 0.0], false, CUBE);
    s += &object(40, "Far", 0, [0.0, 4.0, 0.0], false, CUBE);
    // The LODGroup shows Front up close (LOD0) and Far (LOD1) from afar: 12 m across and
    // 10.05 m from the camera, its relative screen height is 6 / (10.05 · tan 30°) = 1.03,
    // above LOD0's 0.5.
    s += "--- !u!1 &50\nGameObject:\n  m_Component:\n  - component: {fileID: 51}\n  - component: {fileID: 52}\n  m_Layer: 0\n  m_Name: Group\n  m_IsActive: 1\n--- !u!4 &51\nTransform:\n  m_GameObject: {fileID: 50}\n  m_LocalRotation: {x: 0, y: 0, z: 0, w: 1}\n  m_LocalPosition: {x: 0, y: 0, z: 0}\n  m_LocalScale: {x: 1, y: 1, z: 1}\n  m_Children: []\n  m_Father: {fileID: 0}\n--- !u!205 &52\nLODGroup:\n  m_GameObject: {fileID: 50}\n  m_Enabled: 1\n  serializedVersion: 2\n  m_LocalReferencePoint: {x: 0, y: 0, z: 0}\n  m_Size: 12\n  m_LODs:\n  - screenRelativeHeight: 0.5\n    renderers:\n    - renderer: {fileID: 23}\n  - screenRelativeHeight: 0.1\n    renderers:\n    - renderer: {fileID: 43}\n";
    s
}

#[test]
fn back_faces_masked_layers_and_lod1_show_the_background() {
    let dir = tempfile::tempdir().unwrap();
    let root = dir.path().join("Rules");
    std::fs::create_dir_all(root.join("Assets")).unwrap();
    let unity = root.join("Assets/Rules.unity");
    std::fs::write(&unity, scene()).unwrap();
    let soup_path = dir.path().join("rules.soup");
    let s = run_ok(
        "unity2soup",
        [
            unity.as_os_str(),
            "-o".as_ref(),
            soup_path.as_os_str(),
            "--json".as_ref(),
        ],
    )
    .json();
    // Back and Front are converted (two triangles each); the layer-8 Cube and LOD1 are not.
    assert_eq!(s["objects"], 2, "{s}");
    assert_eq!(s["triangles"], 4, "{s}");
    assert_eq!(s["skipped"].as_array().map(Vec::len), Some(2), "{s}");
    let kd = dir.path().join("rules.kd");
    run_ok(
        "soup2kd",
        [soup_path.as_os_str(), "-o".as_ref(), kd.as_os_str()],
    );
    let exr = dir.path().join("rules.exr");
    let r = run_ok(
        "kd2exr",
        [
            soup_path.to_str().unwrap(),
            kd.to_str().unwrap(),
            "-o",
            exr.to_str().unwrap(),
            "--width",
            "64",
            "--height",
            "48",
            "--json",
        ],
    )
    .json();
    let img = Rgba::read(&exr);
    img.assert_finite();
    let soup = formats::Soup::read(&soup_path).unwrap();
    let bg = soup.environment.background;
    let rgb = |x: usize, y: usize| {
        let p = img.at(x, y);
        Vec3::new(p[0], p[1], p[2])
    };
    // Image columns 16, 32 and 48 see Unity x ≈ −4, 0, +4; rows 24 and 12 see y ≈ 1, 4.
    assert_eq!(rgb(16, 24), bg, "the Quad seen from behind is invisible");
    assert_ne!(rgb(32, 24), bg, "the Quad seen from the front is drawn");
    assert_eq!(rgb(48, 24), bg, "the layer the camera leaves out");
    assert_eq!(rgb(32, 12), bg, "LOD1 is not drawn");
    assert!(r["rays"]["pass_through"].as_u64().unwrap() > 0, "{r}");
}
