//! Bad-input cases as tables: run each, then report every case that did not hold at once.

use std::path::{Path, PathBuf};
use unitrace::run;

/// What must be true of the output file after the run.
pub(super) enum Out {
    /// Not created.
    Absent(PathBuf),
    /// Held these bytes before the run and still does.
    Intact(PathBuf, Vec<u8>),
    /// Written (the stage converted what it could).
    Written(PathBuf),
    /// The stage writes nothing on this path (a usage error before any output exists).
    None,
}

pub(super) struct Case {
    pub(super) what: String,
    pub(super) bin: &'static str,
    pub(super) args: Vec<String>,
    pub(super) code: i32,
    /// Stderr must contain each of these (the input's name, the object, the problem).
    pub(super) names: Vec<String>,
    pub(super) out: Out,
}

pub(super) fn case(
    what: &str,
    bin: &'static str,
    args: &[&str],
    code: i32,
    names: &[&str],
    out: Out,
) -> Case {
    Case {
        what: what.to_string(),
        bin,
        args: args.iter().map(|s| s.to_string()).collect(),
        code,
        names: names.iter().map(|s| s.to_string()).collect(),
        out,
    }
}

/// Run every case, then fail once listing every case that did not hold. Each case also
/// prints a row (`--nocapture`) in the shape of the RELIABILITY.md table.
pub(super) fn check(cases: Vec<Case>) {
    let mut failures = Vec::new();
    for c in &cases {
        let r = run(c.bin, &c.args);
        let first = r
            .stderr
            .lines()
            .find(|l| !l.trim().is_empty())
            .unwrap_or("");
        println!("| {} | {} | {} | {} |", c.what, c.bin, r.code, first);
        let mut bad = Vec::new();
        if r.code != c.code {
            bad.push(format!("exit code {} (want {})", r.code, c.code));
        }
        for n in &c.names {
            if !r.stderr.contains(n.as_str()) {
                bad.push(format!("stderr does not name `{n}`"));
            }
        }
        if c.code != 0 && r.stderr.lines().filter(|l| !l.is_empty()).count() == 0 {
            bad.push("no message".into());
        }
        match &c.out {
            Out::Absent(p) if p.exists() => bad.push(format!("{} was written", p.display())),
            Out::Intact(p, before) => match std::fs::read(p) {
                Ok(now) if &now == before => {}
                _ => bad.push(format!("{} changed", p.display())),
            },
            Out::Written(p) if !p.exists() => bad.push(format!("{} missing", p.display())),
            _ => {}
        }
        if !bad.is_empty() {
            failures.push(format!(
                "{} ({} {}): {}\n  stderr: {}",
                c.what,
                c.bin,
                c.args.join(" "),
                bad.join("; "),
                r.stderr.trim().replace('\n', "\n          ")
            ));
        }
    }
    assert!(
        failures.is_empty(),
        "{} of {} cases failed:\n{}",
        failures.len(),
        cases.len(),
        failures.join("\n")
    );
}

pub(super) fn s(p: &Path) -> String {
    p.display().to_string()
}
