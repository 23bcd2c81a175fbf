//! A tiny Unity project, YAML written the way Unity writes it, and the artifacts converted
//! from it that the other cases damage.

use super::cases::*;
use formats::Soup;
use std::path::{Path, PathBuf};
use unitrace::run;

pub(super) const HEADER: &str = "%YAML 1.1\n%TAG !u! tag:unity3d.com,2011:\n";
pub(super) const BUILTIN_MESH: &str = "0000000000000000e000000000000000";
pub(super) const BUILTIN_EXTRA: &str = "0000000000000000f000000000000000";

/// GameObject `go` with Transform `go+1` at `pos` (a YAML flow map) under `father`.
pub(super) fn object(go: i64, name: &str, pos: &str, father: i64, comps: &[i64]) -> String {
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
pub(super) fn mesh_object(
    go: i64,
    name: &str,
    pos: &str,
    father: i64,
    mesh: &str,
    mat: &str,
) -> String {
    let (mf, mr) = (go + 2, go + 3);
    object(go, name, pos, father, &[mf, mr])
        + &format!(
            "--- !u!33 &{mf}\nMeshFilter:\n  m_GameObject: {{fileID: {go}}}\n  m_Mesh: {mesh}\n--- !u!23 &{mr}\nMeshRenderer:\n  m_GameObject: {{fileID: {go}}}\n  m_Enabled: 1\n  m_Materials:\n  - {mat}\n"
        )
}

pub(super) fn cube(go: i64, name: &str, pos: &str, father: i64) -> String {
    mesh_object(
        go,
        name,
        pos,
        father,
        &format!("{{fileID: 10202, guid: {BUILTIN_MESH}, type: 0}}"),
        &format!("{{fileID: 10303, guid: {BUILTIN_EXTRA}, type: 0}}"),
    )
}

pub(super) fn camera_and_light() -> String {
    object(10, "Main Camera", "{x: 0, y: 1, z: -10}", 0, &[12])
        + "--- !u!20 &12\nCamera:\n  m_GameObject: {fileID: 10}\n  m_Enabled: 1\n  m_ClearFlags: 2\n  m_BackGroundColor: {r: 0.2, g: 0.3, b: 0.5, a: 0}\n  near clip plane: 0.3\n  field of view: 60\n  orthographic: 0\n  orthographic size: 5\n  m_Depth: -1\n"
        + &object(20, "Sun", "{x: 0, y: 3, z: 0}", 0, &[22])
        + "--- !u!108 &22\nLight:\n  m_GameObject: {fileID: 20}\n  m_Enabled: 1\n  serializedVersion: 8\n  m_Type: 1\n  m_Color: {r: 1, g: 1, b: 1, a: 1}\n  m_Intensity: 1\n  m_Range: 10\n  m_SpotAngle: 30\n  m_Shadows:\n    m_Type: 0\n"
}

pub(super) fn pos(x: f32, y: f32, z: f32) -> String {
    format!("{{x: {x}, y: {y}, z: {z}}}")
}

/// A PrefabInstance of the model (or prefab) with `guid`.
pub(super) fn instance(id: i64, guid: &str) -> String {
    format!("--- !u!1001 &{id}\nPrefabInstance:\n  m_ObjectHideFlags: 0\n  serializedVersion: 2\n  m_Modification:\n    m_TransformParent: {{fileID: 0}}\n    m_Modifications: []\n    m_RemovedComponents: []\n  m_SourcePrefab: {{fileID: 100100000, guid: {guid}, type: 3}}\n")
}

pub(super) fn meta(guid: &str) -> String {
    format!("fileFormatVersion: 2\nguid: {guid}\nModelImporter:\n  serializedVersion: 22\n  meshes:\n    globalScale: 1\n")
}

pub(super) struct Project {
    pub(super) _dir: tempfile::TempDir,
    pub(super) root: PathBuf,
}

impl Project {
    pub(super) fn new() -> Project {
        let dir = tempfile::tempdir().expect("tempdir");
        let root = dir.path().join("Proj");
        std::fs::create_dir_all(root.join("Assets")).expect("Assets");
        Project { _dir: dir, root }
    }
    /// Write `bytes` at `rel` (relative to the project root); returns the full path.
    pub(super) fn file(&self, rel: &str, bytes: impl AsRef<[u8]>) -> PathBuf {
        let p = self.root.join(rel);
        std::fs::create_dir_all(p.parent().expect("parent")).expect("mkdir");
        std::fs::write(&p, bytes).expect("write");
        p
    }
    pub(super) fn scene(&self, name: &str, body: &str) -> PathBuf {
        self.file(&format!("Assets/{name}.unity"), format!("{HEADER}{body}"))
    }
    pub(super) fn out(&self, name: &str) -> PathBuf {
        self.root.join(name)
    }
}

/// Convert `scene` (must succeed) and return the soup.
pub(super) fn convert(scene: &Path, out: &Path) -> Soup {
    let r = run("unity2soup", [s(scene), "-o".into(), s(out)]);
    assert_eq!(r.code, 0, "unity2soup {}:\n{}", scene.display(), r.stderr);
    Soup::read(out).expect("soup")
}

/// A project with one good scene converted to `good.soup` and built into `good.kd`, and a
/// second scene (`other.soup`, `other.kd`) with different geometry.
pub(super) struct Artifacts {
    pub(super) p: Project,
    pub(super) soup: PathBuf,
    pub(super) kd: PathBuf,
    pub(super) other_soup: PathBuf,
    pub(super) other_kd: PathBuf,
}

pub(super) fn artifacts() -> Artifacts {
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
