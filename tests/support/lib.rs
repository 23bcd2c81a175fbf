//! Support for the end-to-end tests: building, locating and running the real binaries.
//!
//! The binaries live in other workspace packages, so cargo does not build them for this
//! package's tests. The first test that needs one runs `cargo test --workspace --no-run`
//! once, with the same profile and target folder as the running test, so the suite always
//! tests the binaries of the current source. That command resolves features as
//! `cargo test --workspace` does (the packages' own integration tests need the same
//! binaries), so after that command it has nothing left to build; a plain
//! `cargo build --bins` would resolve them without the dev-dependencies' features and
//! rebuild every binary.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::OnceLock;

/// Repository root (this package's manifest folder).
pub fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// `../shared/corpus` beside the repository, when it exists.
pub fn corpus() -> Option<PathBuf> {
    let p = repo().join("../shared/corpus");
    p.is_dir().then_some(p)
}

/// target/<profile>/ of the running test executable (target/<profile>/deps/<test>).
fn profile_dir() -> PathBuf {
    let exe = std::env::current_exe().expect("test executable path");
    exe.parent()
        .and_then(Path::parent)
        .expect("test executable lives in target/<profile>/deps")
        .to_path_buf()
}

/// Path of a workspace binary, built on first use.
pub fn bin(name: &str) -> PathBuf {
    static BUILT: OnceLock<()> = OnceLock::new();
    BUILT.get_or_init(|| {
        let dir = profile_dir();
        let profile = dir.file_name().and_then(|s| s.to_str()).unwrap_or("debug");
        let target = dir.parent().expect("target dir");
        let mut cmd = Command::new(env!("CARGO"));
        cmd.current_dir(repo())
            .args(["test", "--workspace", "--no-run", "--quiet"])
            .env("CARGO_TARGET_DIR", target);
        // `debug` is the test profile's output folder; any other folder is a named profile.
        if profile != "debug" {
            cmd.args(["--profile", profile]);
        }
        let status = cmd.status().expect("run cargo test --no-run");
        assert!(status.success(), "cargo test --workspace --no-run failed");
    });
    let p = profile_dir().join(format!("{name}{}", std::env::consts::EXE_SUFFIX));
    assert!(p.exists(), "binary {} was not built", p.display());
    p
}

/// What a binary run produced.
pub struct Run {
    pub code: i32,
    pub stdout: String,
    pub stderr: String,
}

impl Run {
    /// Parse stdout as the single JSON object a `--json` run prints.
    pub fn json(&self) -> serde_json::Value {
        serde_json::from_str(self.stdout.trim())
            .unwrap_or_else(|e| panic!("stdout is not one JSON object ({e}):\n{}", self.stdout))
    }
}

/// Run a binary with arguments; never panics on a non-zero exit (tests assert on it).
pub fn run<I, S>(name: &str, args: I) -> Run
where
    I: IntoIterator<Item = S>,
    S: AsRef<std::ffi::OsStr>,
{
    let Output {
        status,
        stdout,
        stderr,
    } = Command::new(bin(name))
        .args(args)
        .current_dir(repo())
        .output()
        .unwrap_or_else(|e| panic!("cannot start {name}: {e}"));
    let r = Run {
        code: status.code().unwrap_or(-1),
        stdout: String::from_utf8_lossy(&stdout).into_owned(),
        stderr: String::from_utf8_lossy(&stderr).into_owned(),
    };
    assert!(
        !r.stderr.contains("panicked"),
        "{name} panicked:\n{}",
        r.stderr
    );
    r
}

/// The built-in Standard shader's diffuse term per unit of albedo and of a light's radiance,
/// the cosine included, written out again from Unity's shader source (`BRDF1_Unity_PBS`):
/// the share a dielectric does not reflect (`OneMinusReflectivityFromMetallic`, 1 − 0.04,
/// a linear project) times `DisneyDiffuse` times n·l; unit vectors towards the light `l`
/// and the eye `v`, normal `n`.
pub fn unity_diffuse(n: glam::Vec3, l: glam::Vec3, v: glam::Vec3, smoothness: f32) -> f32 {
    let h = (l + v).normalize();
    let (nl, nv, lh) = (n.dot(l), n.dot(v).abs(), l.dot(h));
    let fd90 = 0.5 + 2.0 * lh * lh * (1.0 - smoothness);
    let light_scatter = 1.0 + (fd90 - 1.0) * (1.0 - nl).powi(5);
    let view_scatter = 1.0 + (fd90 - 1.0) * (1.0 - nv).powi(5);
    0.96 * light_scatter * view_scatter * nl
}

/// Run a binary and require exit code 0, showing its stderr otherwise.
pub fn run_ok<I, S>(name: &str, args: I) -> Run
where
    I: IntoIterator<Item = S>,
    S: AsRef<std::ffi::OsStr>,
{
    let r = run(name, args);
    assert_eq!(r.code, 0, "{name} failed:\n{}", r.stderr);
    r
}

/// An RGBA image read back from an EXR file with the `exr` crate (independent of the renderer).
pub struct Rgba {
    pub width: usize,
    pub height: usize,
    pub pixels: Vec<[f32; 4]>,
}

impl Rgba {
    pub fn read(path: &Path) -> Rgba {
        use exr::prelude::*;
        let img = read_first_rgba_layer_from_file(
            path,
            |res, _| Rgba {
                width: res.width(),
                height: res.height(),
                pixels: vec![[0.0; 4]; res.width() * res.height()],
            },
            |img: &mut Rgba, pos, (r, g, b, a): (f32, f32, f32, f32)| {
                let w = img.width;
                img.pixels[pos.y() * w + pos.x()] = [r, g, b, a];
            },
        )
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        img.layer_data.channel_data.pixels
    }

    pub fn at(&self, x: usize, y: usize) -> [f32; 4] {
        self.pixels[y * self.width + x]
    }

    /// Every test image is checked for NaN and Inf.
    pub fn assert_finite(&self) {
        let bad = self
            .pixels
            .iter()
            .filter(|p| p.iter().any(|c| !c.is_finite()))
            .count();
        assert_eq!(bad, 0, "{bad} pixels hold NaN or Inf");
    }
}
