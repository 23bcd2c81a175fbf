//! Renderer options: absurd ones are refused before any work.

use super::cases::*;
use super::project::*;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};
use unitrace::{bin, run};

#[test]
fn absurd_render_options_are_refused_before_work() {
    let a = artifacts();
    let o = a.p.out("r.exr");
    let (so, k, os) = (s(&a.soup), s(&a.kd), s(&o));
    let r = |extra: &[&str]| -> Vec<String> {
        let mut v: Vec<String> = [so.as_str(), k.as_str(), "-o", os.as_str()]
            .iter()
            .map(|s| s.to_string())
            .collect();
        v.extend(extra.iter().map(|s| s.to_string()));
        v
    };
    let mk = |what: &str, extra: &[&str], names: &[&str]| {
        let args = r(extra);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        case(what, "kd2exr", &args, 1, names, Out::Absent(o.clone()))
    };
    check(vec![
        mk("--width 0", &["--width", "0"], &["--width"]),
        mk("--height 0", &["--height", "0"], &["--height"]),
        mk("--spp 0", &["--spp", "0"], &["--spp"]),
        mk(
            "absurd resolution 10^6 × 10^6",
            &["--width", "1000000", "--height", "1000000"],
            &["1000000"],
        ),
        mk(
            "crop outside the image",
            &[
                "--width",
                "64",
                "--height",
                "64",
                "--crop",
                "100,100,120,120",
            ],
            &["--crop"],
        ),
        mk(
            "crop x1 < x0",
            &["--width", "64", "--height", "64", "--crop", "40,0,20,10"],
            &["--crop"],
        ),
        mk("unknown AOV", &["--aov", "depth,colour"], &["colour"]),
        mk("NaN exposure", &["--exposure", "NaN"], &["--exposure"]),
        // Bounds that keep the stack, the samples and the threads finite.
        mk(
            "--depth 5000",
            &["--depth", "5000"],
            &["--depth 5000: at most 256"],
        ),
        mk(
            "--spp 10^9",
            &["--spp", "1000000000"],
            &["--spp 1000000000: at most 65536"],
        ),
        mk(
            "--threads 100000",
            &["--threads", "100000"],
            &["--threads 100000: at most 1024"],
        ),
    ]);
    // 16k × 16k with every AOV: either refused before any work (naming the memory it
    // needs and has), or it fits and starts; never killed by the OOM killer or a failed
    // allocation. A render that fits is stopped after 20 s: only the decision is tested.
    let all = "depth,normal,albedo,object";
    let mut child = Command::new(bin("kd2exr"))
        .args(r(&["--width", "16384", "--height", "16384", "--aov", all]))
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn kd2exr");
    let t = Instant::now();
    let status = loop {
        if let Some(st) = child.try_wait().expect("try_wait") {
            break Some(st);
        }
        if t.elapsed() > Duration::from_secs(20) {
            let _ = child.kill();
            let _ = child.wait();
            break None;
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    let mut err = String::new();
    if let Some(mut e) = child.stderr.take() {
        use std::io::Read;
        let _ = e.read_to_string(&mut err);
    }
    assert!(!err.contains("panicked"), "{err}");
    match status {
        Some(st) => {
            println!("16k×16k with AOVs: exit {:?} after {:?}: {}", st.code(), t.elapsed(), err.lines().next().unwrap_or(""));
            assert_eq!(st.code(), Some(1), "{err}");
            assert!(err.contains("16384×16384") && err.contains("GiB"), "{err}");
            assert!(!o.exists());
        }
        None => println!("16k×16k with AOVs fits in this machine's memory: rendering started (stopped after 20 s)"),
    }
    // The same size rendered as a 16×16 crop needs only the crop's memory.
    let crop = run(
        "kd2exr",
        r(&[
            "--width",
            "16384",
            "--height",
            "16384",
            "--aov",
            all,
            "--crop",
            "0,0,16,16",
        ]),
    );
    assert_eq!(crop.code, 0, "{}", crop.stderr);
}

/// rayon's own variable is held to `--threads`'s bounds in every program (it started any
/// count it was given: 100,000 stalled `soup2kd` for minutes creating threads).
#[test]
fn rayon_num_threads_beyond_the_bound_is_refused() {
    let a = artifacts();
    let (so, k) = (s(&a.soup), s(&a.kd));
    let (kd, exr) = (a.p.out("t.kd"), a.p.out("t.exr"));
    for (program, args) in [
        ("soup2kd", vec![so.clone(), "-o".into(), s(&kd)]),
        ("kd2exr", vec![so.clone(), k.clone(), "-o".into(), s(&exr)]),
        (
            "raycast",
            vec![
                so.clone(),
                k.clone(),
                "rays".into(),
                "-o".into(),
                "hits".into(),
            ],
        ),
    ] {
        let out = Command::new(bin(program))
            .args(&args)
            .env("RAYON_NUM_THREADS", "100000")
            .output()
            .expect("run");
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{program}: {err}");
        assert!(
            err.contains("RAYON_NUM_THREADS=100000: at most 1024 threads"),
            "{program}: {err}"
        );
    }
    assert!(!kd.exists() && !exr.exists());
}
