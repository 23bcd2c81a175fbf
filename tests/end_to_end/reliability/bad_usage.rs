//! Bad command lines exit 2 before touching any output.

use super::cases::*;
use super::project::*;

#[test]
fn bad_usage_exits_2() {
    let a = artifacts();
    let o = a.p.out("x");
    let so = s(&a.soup);
    let k = s(&a.kd);
    let os = s(&o);
    check(vec![
        case("no arguments", "unity2soup", &[], 2, &["Usage"], Out::None),
        case(
            "unknown flag",
            "unity2soup",
            &["--frobnicate"],
            2,
            &["--frobnicate"],
            Out::None,
        ),
        case(
            "no output",
            "soup2kd",
            &[&so],
            2,
            &["-o"],
            Out::Absent(o.clone()),
        ),
        case(
            "-o and --cache",
            "soup2kd",
            &[&so, "-o", &os, "--cache", &os],
            2,
            &["--cache"],
            Out::Absent(o.clone()),
        ),
        case("no output", "soup2obj", &[&so], 2, &["--output"], Out::None),
        case(
            "missing rays argument",
            "raycast",
            &[&so, &k, "-o", &os],
            2,
            &["RAYS"],
            Out::Absent(o.clone()),
        ),
        case(
            "--width not a number",
            "kd2exr",
            &[&so, &k, "-o", &os, "--width", "wide"],
            2,
            &["wide"],
            Out::Absent(o.clone()),
        ),
        case(
            "--width -5",
            "kd2exr",
            &[&so, &k, "-o", &os, "--width", "-5"],
            2,
            &["-5"],
            Out::Absent(o.clone()),
        ),
    ]);
}
