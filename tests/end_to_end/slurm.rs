//! One frame over a Slurm cluster. The cluster tests start a throwaway single-node cluster
//! with every piece of state in a temporary folder (scripts/slurm/local-cluster.sh), render
//! the baseline through `just slurm` as 8 crop tiles of one array job and compare the merged
//! EXR with a one-machine render bit for bit, and check that a failing tile is resubmitted
//! once and then named with its log. They need root, `just` and the Debian packages
//! slurmctld, slurmd, slurm-client and munge, so they are ignored by default:
//!
//! ```text
//! cargo test --test end_to_end slurm -- --ignored
//! ```
//!
//! Without `slurmctld` they pass after saying loudly that they were skipped. The merge
//! refusals (a missing tile, tiles of other settings, soup or tree) need no cluster and run
//! with the rest of the suite.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use unitrace::{bin, repo, run, run_ok};

const BASELINE: &str = "scenes/baseline/Assets/Scenes/Baseline.unity";

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

fn script(name: &str) -> PathBuf {
    repo().join("scripts/slurm").join(name)
}

/// A running local cluster; dropping it cancels its jobs and ends its daemons, also when
/// the test fails.
struct Cluster {
    dir: tempfile::TempDir,
}

impl Cluster {
    /// None (after saying so on stderr) when Slurm is not installed.
    fn start() -> Option<Cluster> {
        let found = Command::new("sh")
            .args(["-c", "command -v slurmctld"])
            .output()
            .is_ok_and(|o| o.status.success());
        if !found {
            eprintln!(
                "\n*** SKIPPED: slurmctld is not installed \
                 (apt-get install slurmctld slurmd slurm-client munge) ***\n"
            );
            return None;
        }
        let dir = tempfile::Builder::new()
            .prefix("unitrace-slurm-")
            .tempdir()
            .expect("temporary cluster folder");
        let cluster = Cluster { dir };
        let out = Command::new(script("local-cluster.sh"))
            .arg("start")
            .arg(cluster.dir.path())
            .output()
            .expect("run local-cluster.sh");
        assert!(
            out.status.success(),
            "local-cluster.sh start failed:\n{}",
            text(&out.stderr)
        );
        Some(cluster)
    }

    fn conf(&self) -> PathBuf {
        self.dir.path().join("slurm.conf")
    }

    /// A command with the Slurm clients pointed at this cluster.
    fn command(&self, program: impl AsRef<std::ffi::OsStr>) -> Command {
        let mut c = Command::new(program);
        c.env("SLURM_CONF", self.conf());
        c
    }
}

impl Drop for Cluster {
    fn drop(&mut self) {
        let out = Command::new(script("local-cluster.sh"))
            .arg("stop")
            .arg(self.dir.path())
            .output();
        match out {
            Ok(o) if o.status.success() => {}
            Ok(o) => eprintln!("local-cluster.sh stop failed:\n{}", text(&o.stderr)),
            Err(e) => eprintln!("cannot run local-cluster.sh stop: {e}"),
        }
    }
}

/// Every channel of an EXR, as read by the `exr` crate: name and sample bits.
struct Channels {
    display: (usize, usize),
    data_origin: (i32, i32),
    data_size: (usize, usize),
    channels: Vec<(String, Vec<u32>)>,
}

fn channels(path: &Path) -> Channels {
    use exr::prelude::*;
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_file(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let layer = image.layer_data;
    let channels = layer
        .channel_data
        .list
        .iter()
        .map(|c| {
            let bits = match &c.sample_data {
                FlatSamples::F16(v) => v.iter().map(|x| x.to_bits() as u32).collect(),
                FlatSamples::F32(v) => v.iter().map(|x| x.to_bits()).collect(),
                FlatSamples::U32(v) => v.clone(),
            };
            (c.name.to_string(), bits)
        })
        .collect();
    let d = image.attributes.display_window.size;
    let p = layer.attributes.layer_position;
    Channels {
        display: (d.0, d.1),
        data_origin: (p.0, p.1),
        data_size: (layer.size.0, layer.size.1),
        channels,
    }
}

fn assert_same_pixels(a: &Path, b: &Path) {
    let (x, y) = (channels(a), channels(b));
    assert_eq!(x.display, y.display, "image sizes");
    assert_eq!(
        (x.data_origin, x.data_size),
        (y.data_origin, y.data_size),
        "data windows"
    );
    let names = |c: &Channels| c.channels.iter().map(|c| c.0.clone()).collect::<Vec<_>>();
    assert_eq!(names(&x), names(&y), "channel lists");
    for ((name, p), (_, q)) in x.channels.iter().zip(&y.channels) {
        let diff = p.iter().zip(q).filter(|(s, t)| s != t).count();
        assert_eq!(
            diff,
            0,
            "channel {name}: {diff} of {} samples differ between {} and {}",
            p.len(),
            a.display(),
            b.display()
        );
    }
}

/// The baseline converted and compiled into `dir`: (soup, tree).
fn baseline_in(dir: &Path) -> (PathBuf, PathBuf) {
    let soup = dir.join("baseline.soup");
    run_ok(
        "unity2soup",
        [
            repo().join(BASELINE).as_os_str(),
            "-o".as_ref(),
            soup.as_os_str(),
        ],
    );
    let kd = dir.join("baseline.kd");
    run_ok("soup2kd", [soup.as_os_str(), "-o".as_ref(), kd.as_os_str()]);
    (soup, kd)
}

/// Removes a folder under the repository's out/ when the test ends, however it ends.
struct Remove(PathBuf);

impl Drop for Remove {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

#[test]
#[ignore = "starts a local Slurm cluster: cargo test --test end_to_end slurm -- --ignored"]
fn just_slurm_renders_the_baseline_bit_identical_to_one_machine() {
    let Some(cluster) = Cluster::start() else {
        return;
    };
    let just = Command::new("just").arg("--version").output();
    assert!(
        just.is_ok_and(|o| o.status.success()),
        "`just` is not installed (cargo install just --locked)"
    );
    // `just slurm` writes into the repository's out/ and cache/, like every recipe.
    let sub = format!("slurm-test-{}", std::process::id());
    let _cleanup = Remove(repo().join("out").join(&sub));
    let name = format!("{sub}/baseline");
    let started = std::time::Instant::now();
    let out = cluster
        .command("just")
        .current_dir(repo())
        // The default 1024×768, its height written with a leading zero that shell
        // arithmetic would read as octal: the tiles are bands of 96 rows.
        .args(["slurm", BASELINE, &name, "8", "--height", "0768"])
        .output()
        .expect("run just slurm");
    let err = text(&out.stderr);
    assert!(out.status.success(), "just slurm failed:\n{err}");
    eprintln!(
        "just slurm: 8 tiles in {:.1} s",
        started.elapsed().as_secs_f64()
    );
    assert!(err.contains("8 of 8 tiles done"), "{err}");
    assert!(err.contains("merged 8 crops"), "{err}");

    let base = repo().join("out").join(&name);
    let merged = base.with_extension("exr");
    assert!(base.with_extension("png").is_file(), "no PNG preview");
    // Each task ran on its one allocated CPU.
    let log = std::fs::read_to_string(base.with_extension("tiles").join("logs/tile-0.log"))
        .expect("the first tile's log");
    assert!(log.contains("with 1 threads"), "{log}");

    // The same soup and tree rendered on this machine in one go.
    let soup = base.with_extension("soup");
    let json = run_ok(
        "soup2kd",
        [
            soup.as_os_str(),
            "--cache".as_ref(),
            repo().join("cache").as_os_str(),
            "--json".as_ref(),
        ],
    )
    .json();
    let kd = repo().join(json["path"].as_str().expect("tree path"));
    let single = base.with_file_name("single.exr");
    run_ok(
        "kd2exr",
        [
            soup.as_os_str(),
            kd.as_os_str(),
            "-o".as_ref(),
            single.as_os_str(),
        ],
    );
    assert_same_pixels(&merged, &single);
}

#[test]
#[ignore = "starts a local Slurm cluster: cargo test --test end_to_end slurm -- --ignored"]
fn a_failing_tile_is_resubmitted_once_then_named_with_its_log() {
    let Some(cluster) = Cluster::start() else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let (soup, kd) = baseline_in(dir.path());
    // kd2exr, except that the tile of rows 24..36 (tile 2 of 4 at 48 rows) fails while
    // the file `always` exists, or once when the file `once` does.
    let wrapper = dir.path().join("kd2exr-failing");
    let (once_flag, always_flag) = (dir.path().join("once"), dir.path().join("always"));
    std::fs::write(
        &wrapper,
        format!(
            "#!/bin/sh\n\
             fail() {{ echo 'tile broken on purpose' >&2; exit 1; }}\n\
             case \"$*\" in *'--crop 0,24,64,36 '*)\n\
             \x20 [ -e '{always}' ] && fail\n\
             \x20 [ -e '{once}' ] && rm '{once}' && fail ;;\n\
             esac\n\
             exec '{real}' \"$@\"\n",
            always = always_flag.display(),
            once = once_flag.display(),
            real = bin("kd2exr").display()
        ),
    )
    .unwrap();
    std::fs::set_permissions(
        &wrapper,
        std::os::unix::fs::PermissionsExt::from_mode(0o755),
    )
    .unwrap();
    let render = |out: &Path| -> Output {
        cluster
            .command(script("render.sh"))
            .env("KD2EXR", &wrapper)
            .arg(&soup)
            .arg(&kd)
            .arg(out)
            .args(["4", "--width", "64", "--height", "48"])
            .output()
            .expect("run render.sh")
    };

    // Failing once: the retry renders it and the frame merges.
    std::fs::write(&once_flag, "").unwrap();
    let once = dir.path().join("once.exr");
    let out = render(&once);
    let err = text(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("tiles 2 failed; resubmitting them once"),
        "{err}"
    );
    assert!(once.is_file());

    // Failing always: named with its log, exit 1, no merged frame.
    std::fs::write(&always_flag, "").unwrap();
    let always = dir.path().join("always.exr");
    let out = render(&always);
    let err = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    let log = dir.path().join("always.tiles/logs/tile-2.retry.log");
    assert!(
        err.contains(&format!("tile 2 failed twice; see {}", log.display())),
        "{err}"
    );
    assert!(std::fs::read_to_string(&log)
        .unwrap()
        .contains("tile broken on purpose"));
    assert!(!always.exists(), "no merged frame after a failed tile");
}

/// `kd2exr merge` refuses what is not the whole of one render, naming the file.
#[test]
fn merge_refuses_a_missing_tile_and_tiles_of_another_render() {
    let dir = tempfile::tempdir().unwrap();
    let (soup, kd) = baseline_in(dir.path());
    let tile = |name: &str, soup: &Path, kd: &Path, crop: &str, extra: &[&str]| -> PathBuf {
        let out = dir.path().join(name);
        run_ok(
            "kd2exr",
            [
                soup.as_os_str(),
                kd.as_os_str(),
                "-o".as_ref(),
                out.as_os_str(),
                "--width".as_ref(),
                "48".as_ref(),
                "--height".as_ref(),
                "32".as_ref(),
                "--crop".as_ref(),
                crop.as_ref(),
            ]
            .into_iter()
            .chain(extra.iter().map(std::ffi::OsStr::new)),
        );
        out
    };
    let top = tile("top.exr", &soup, &kd, "0,0,48,16", &[]);
    let bottom = tile("bottom.exr", &soup, &kd, "0,16,48,32", &[]);
    let merged = dir.path().join("merged.exr");
    let merge = |parts: &[&Path]| {
        let mut args: Vec<&std::ffi::OsStr> = vec!["merge".as_ref()];
        args.extend(parts.iter().map(|p| p.as_os_str()));
        args.extend(["-o".as_ref(), merged.as_os_str()]);
        run("kd2exr", args)
    };
    let refused = |parts: &[&Path], needles: &[&str]| {
        let r = merge(parts);
        assert_eq!(r.code, 1, "{}", r.stderr);
        assert_eq!(r.stderr.trim().lines().count(), 1, "one line: {}", r.stderr);
        for n in needles {
            assert!(r.stderr.contains(n), "{n:?} not in: {}", r.stderr);
        }
        assert!(!merged.exists(), "no output after a refusal");
    };

    // A missing tile: as a gap, and as a file that is not there.
    refused(&[&top], &["768 pixels are in no input", "(0, 16)"]);
    let gone = dir.path().join("gone.exr");
    refused(&[&top, &gone], &[gone.to_str().unwrap()]);

    // Other settings.
    let spp = tile("spp.exr", &soup, &kd, "0,16,48,32", &["--spp", "4"]);
    refused(&[&top, &spp], &["spp", spp.to_str().unwrap()]);

    // The same geometry lit differently: only the soup's checksum tells.
    let mut changed = formats::Soup::read(&soup).unwrap();
    changed.lights[0].intensity *= 2.0;
    let soup2 = dir.path().join("relit.soup");
    changed.write(&soup2).unwrap();
    let relit = tile("relit.exr", &soup2, &kd, "0,16,48,32", &[]);
    refused(&[&top, &relit], &["soupDigest", relit.to_str().unwrap()]);

    // The same soup through a tree built with other parameters.
    let kd2 = dir.path().join("leafy.kd");
    run_ok(
        "soup2kd",
        [
            soup.as_os_str(),
            "-o".as_ref(),
            kd2.as_os_str(),
            "--leaf-size".as_ref(),
            "8".as_ref(),
        ],
    );
    let leafy = tile("leafy.exr", &soup, &kd2, "0,16,48,32", &[]);
    refused(&[&top, &leafy], &["treeParams", leafy.to_str().unwrap()]);

    // The two halves of one render merge into what one render gives.
    let r = merge(&[&bottom, &top]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    let single = dir.path().join("single.exr");
    run_ok(
        "kd2exr",
        [
            soup.as_os_str(),
            kd.as_os_str(),
            "-o".as_ref(),
            single.as_os_str(),
            "--width".as_ref(),
            "48".as_ref(),
            "--height".as_ref(),
            "32".as_ref(),
        ],
    );
    assert_same_pixels(&merged, &single);
}

/// `kd2exr merge` refuses, in one line naming the file, EXR files it did not write and
/// damaged ones: never a panic or an output. (Forged headers and offset tables are the
/// decoder's unit tests, `exrread::tests`.)
#[test]
fn merge_refuses_foreign_and_damaged_exr_files() {
    use exr::prelude::*;
    let dir = tempfile::tempdir().unwrap();
    let (soup, kd) = baseline_in(dir.path());
    // A whole 48×32 render as its one crop: two blocks of 16 lines.
    let tile = dir.path().join("tile.exr");
    run_ok(
        "kd2exr",
        [
            soup.as_os_str(),
            kd.as_os_str(),
            "-o".as_ref(),
            tile.as_os_str(),
            "--width".as_ref(),
            "48".as_ref(),
            "--height".as_ref(),
            "32".as_ref(),
            "--crop".as_ref(),
            "0,0,48,32".as_ref(),
        ],
    );
    let good = std::fs::read(&tile).unwrap();
    let merged = dir.path().join("merged.exr");
    let refused = |input: &Path, needles: &[&str]| {
        let r = run(
            "kd2exr",
            [
                "merge".as_ref(),
                input.as_os_str(),
                "-o".as_ref(),
                merged.as_os_str(),
            ],
        );
        assert_eq!(r.code, 1, "{}: {}", input.display(), r.stderr);
        assert_eq!(r.stderr.trim().lines().count(), 1, "one line: {}", r.stderr);
        assert!(
            r.stderr.contains(input.to_str().unwrap()),
            "the file is not named: {}",
            r.stderr
        );
        for n in needles {
            assert!(r.stderr.contains(n), "{n:?} not in: {}", r.stderr);
        }
        assert!(!merged.exists(), "no output after a refusal");
    };
    let file = |name: &str, bytes: &[u8]| {
        let p = dir.path().join(name);
        std::fs::write(&p, bytes).unwrap();
        p
    };

    // An ordinary EXR of the image's size that another program wrote.
    let foreign = dir.path().join("foreign.exr");
    write_rgba_file(&foreign, 48, 32, |_, _| (0.5f32, 0.5f32, 0.5f32, 1.0f32)).unwrap();
    refused(&foreign, &["was not written by kd2exr"]);

    // The crop re-encoded with a lossy compression, its attributes kept.
    let mut image = read_first_flat_layer_from_file(&tile).unwrap();
    image.layer_data.encoding.compression = Compression::PXR24;
    let lossy = dir.path().join("lossy.exr");
    image.write().to_file(&lossy).unwrap();
    refused(&lossy, &["pxr24 compression, which is lossy"]);

    // The crop as one part of a two-part file.
    let named = |name: &str| {
        let mut layer = image.layer_data.clone();
        layer.attributes.layer_name = Some(Text::from(name));
        layer
    };
    let two = Image::from_layers(
        image.attributes.clone(),
        SmallVec::from_vec(vec![named("a"), named("b")]),
    );
    let parts = dir.path().join("parts.exr");
    two.write().to_file(&parts).unwrap();
    refused(&parts, &["holds 2 parts"]);

    // Truncated, empty, not EXR at all, a folder, a device.
    refused(&file("half.exr", &good[..good.len() / 2]), &["truncated"]);
    refused(&file("empty.exr", &[]), &["the file is empty"]);
    refused(
        &file("text.exr", b"P3 1 1 255 0 0 0\n"),
        &["not an OpenEXR file"],
    );
    refused(dir.path(), &["is a folder"]);
    if cfg!(unix) {
        refused(Path::new("/dev/null"), &["not a regular file"]);
    }
}
