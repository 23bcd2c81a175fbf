//! Tiny Unity projects written into temporary folders: a few lines of YAML per object,
//! the way Unity writes them.

use std::fmt::Write;
use std::path::{Path, PathBuf};

/// The real Unity projects beside the repository (`../shared/corpus/unity`, or
/// `$UNITRACE_CORPUS/unity`); `None`, after saying loudly that `what` is skipped, when absent.
pub fn corpus(what: &str) -> Option<PathBuf> {
    let p = std::env::var_os("UNITRACE_CORPUS")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/corpus"))
        .join("unity");
    if p.is_dir() {
        Some(p)
    } else {
        eprintln!(
            "SKIPPED: {what}, because {} does not exist (the corpus lives beside the repo in ../shared, or set UNITRACE_CORPUS)",
            p.display()
        );
        None
    }
}

pub const HEADER: &str = "%YAML 1.1\n%TAG !u! tag:unity3d.com,2011:\n";
pub const CUBE: i64 = 10202;
pub const SPHERE: i64 = 10207;
pub const QUAD: i64 = 10210;
pub const PLANE: i64 = 10209;
pub const BUILTIN: &str = "0000000000000000e000000000000000";

pub struct Scene {
    pub text: String,
    next: i64,
}

pub struct Tf {
    pub pos: [f32; 3],
    /// Quaternion x, y, z, w.
    pub rot: [f32; 4],
    pub scale: [f32; 3],
}

impl Tf {
    pub fn at(x: f32, y: f32, z: f32) -> Tf {
        Tf {
            pos: [x, y, z],
            rot: [0.0, 0.0, 0.0, 1.0],
            scale: [1.0; 3],
        }
    }
    pub fn rot(mut self, q: [f32; 4]) -> Tf {
        self.rot = q;
        self
    }
    pub fn scale(mut self, x: f32, y: f32, z: f32) -> Tf {
        self.scale = [x, y, z];
        self
    }
}

impl Default for Scene {
    fn default() -> Self {
        Scene {
            text: HEADER.to_string(),
            next: 1000,
        }
    }
}

impl Scene {
    fn id(&mut self) -> i64 {
        self.next += 1;
        self.next
    }

    /// A GameObject with a Transform; returns (gameobject id, transform id).
    pub fn object(&mut self, name: &str, tf: &Tf, father: i64, active: bool) -> (i64, i64) {
        let (go, t) = (self.id(), self.id());
        let [px, py, pz] = tf.pos;
        let [qx, qy, qz, qw] = tf.rot;
        let [sx, sy, sz] = tf.scale;
        let _ = write!(
            self.text,
            "--- !u!1 &{go}\nGameObject:\n  m_ObjectHideFlags: 0\n  serializedVersion: 6\n  m_Component:\n  - component: {{fileID: {t}}}\n  m_Layer: 0\n  m_Name: {name}\n  m_IsActive: {}\n--- !u!4 &{t}\nTransform:\n  m_ObjectHideFlags: 0\n  m_GameObject: {{fileID: {go}}}\n  m_LocalRotation: {{x: {qx}, y: {qy}, z: {qz}, w: {qw}}}\n  m_LocalPosition: {{x: {px}, y: {py}, z: {pz}}}\n  m_LocalScale: {{x: {sx}, y: {sy}, z: {sz}}}\n  m_Children: []\n  m_Father: {{fileID: {father}}}\n",
            active as i32
        );
        (go, t)
    }

    /// MeshFilter + MeshRenderer on `go`.
    pub fn mesh(
        &mut self,
        go: i64,
        mesh_id: i64,
        guid: &str,
        materials: &[(i64, &str)],
        enabled: bool,
    ) {
        let (mf, mr) = (self.id(), self.id());
        let _ = write!(
            self.text,
            "--- !u!33 &{mf}\nMeshFilter:\n  m_ObjectHideFlags: 0\n  m_GameObject: {{fileID: {go}}}\n  m_Mesh: {{fileID: {mesh_id}, guid: {guid}, type: 3}}\n--- !u!23 &{mr}\nMeshRenderer:\n  m_GameObject: {{fileID: {go}}}\n  m_Enabled: {}\n  m_Materials:\n",
            enabled as i32
        );
        for (id, g) in materials {
            let _ = writeln!(self.text, "  - {{fileID: {id}, guid: {g}, type: 2}}");
        }
    }

    pub fn primitive(&mut self, name: &str, tf: &Tf, father: i64, mesh_id: i64) -> (i64, i64) {
        let (go, t) = self.object(name, tf, father, true);
        self.mesh(
            go,
            mesh_id,
            BUILTIN,
            &[(10303, "0000000000000000f000000000000000")],
            true,
        );
        (go, t)
    }

    pub fn camera(&mut self, tf: &Tf) {
        let (go, _) = self.object("Main Camera", tf, 0, true);
        let c = self.id();
        let _ = write!(
            self.text,
            "--- !u!20 &{c}\nCamera:\n  m_GameObject: {{fileID: {go}}}\n  m_Enabled: 1\n  m_ClearFlags: 2\n  m_BackGroundColor: {{r: 0.5, g: 0.5, b: 0.5, a: 0}}\n  near clip plane: 0.3\n  field of view: 60\n  orthographic: 0\n  orthographic size: 5\n  m_Depth: -1\n"
        );
    }

    /// A light of Unity `m_Type` `ty`.
    pub fn light(&mut self, tf: &Tf, ty: i32, color: [f32; 3], shadows: i32) {
        let (go, _) = self.object("Light", tf, 0, true);
        let l = self.id();
        let [r, g, b] = color;
        let _ = write!(
            self.text,
            "--- !u!108 &{l}\nLight:\n  m_GameObject: {{fileID: {go}}}\n  m_Enabled: 1\n  serializedVersion: 8\n  m_Type: {ty}\n  m_Color: {{r: {r}, g: {g}, b: {b}, a: 1}}\n  m_Intensity: 1.5\n  m_Range: 12\n  m_SpotAngle: 40\n  m_Shadows:\n    m_Type: {shadows}\n    m_Resolution: -1\n  m_ShadowRadius: 0\n  m_ShadowAngle: 0\n"
        );
    }

    pub fn raw(&mut self, s: &str) {
        self.text.push_str(s);
    }
}

/// Where a project keeps its graphics settings.
pub const GRAPHICS_SETTINGS: &str = "ProjectSettings/GraphicsSettings.asset";

/// A `GraphicsSettings.asset` with Lights Use Linear Intensity and Lights Use Color
/// Temperature on (1) or off (0).
pub fn graphics_settings(linear: i32, temperature: i32) -> String {
    format!("{HEADER}--- !u!30 &1\nGraphicsSettings:\n  m_ObjectHideFlags: 0\n  serializedVersion: 13\n  m_LightsUseLinearIntensity: {linear}\n  m_LightsUseColorTemperature: {temperature}\n")
}

/// A project folder with `Assets/` and the given files (paths relative to the root).
pub fn project(files: &[(&str, &str)]) -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let root = dir.path().to_path_buf();
    std::fs::create_dir_all(root.join("Assets")).unwrap();
    for (p, text) in files {
        let path = root.join(p);
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(path, text).unwrap();
    }
    (dir, root)
}

pub fn convert(scene: &Path) -> formats::Soup {
    unity::convert(scene, &unity::Options::default()).unwrap()
}

/// Convert a scene that needs no other file of its project.
pub fn convert_scene(text: &str) -> formats::Soup {
    let (_d, root) = project(&[("Assets/s.unity", text)]);
    convert(&root.join("Assets/s.unity"))
}

/// Fails, listing the soup's warnings, unless one of them contains `text`.
#[track_caller]
pub fn assert_warned(soup: &formats::Soup, text: &str) {
    assert!(
        soup.warnings.iter().any(|w| w.contains(text)),
        "no warning contains {text:?}: {:?}",
        soup.warnings
    );
}

/// The shading normals at each triangle's corners, in soup order.
pub fn corner_normals(soup: &formats::Soup) -> Vec<[glam::Vec3; 3]> {
    (0..soup.triangle_count())
        .map(|t| soup.corner_normals(t))
        .collect()
}

/// The mean of every triangle's corners.
pub fn corner_mean(soup: &formats::Soup) -> glam::Vec3 {
    let corners = soup.triangle_positions();
    corners.iter().flatten().copied().sum::<glam::Vec3>() / (corners.len() * 3) as f32
}

pub fn bounds(pts: impl Iterator<Item = glam::Vec3>) -> (glam::Vec3, glam::Vec3) {
    pts.fold(
        (glam::Vec3::splat(f32::MAX), glam::Vec3::splat(f32::MIN)),
        |(lo, hi), p| (lo.min(p), hi.max(p)),
    )
}

pub fn close(a: glam::Vec3, b: glam::Vec3, eps: f32) -> bool {
    (a - b).abs().max_element() <= eps
}

/// Copy folder `from` into `to`, recursively.
pub fn copy_dir(from: &std::path::Path, to: &std::path::Path) {
    for e in std::fs::read_dir(from).unwrap().flatten() {
        let (src, dst) = (e.path(), to.join(e.file_name()));
        if src.is_dir() {
            std::fs::create_dir_all(&dst).unwrap();
            copy_dir(&src, &dst);
        } else {
            std::fs::copy(&src, &dst).unwrap();
        }
    }
}
