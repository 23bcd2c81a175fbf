//! OBJ models: bad ones are named by file and line, absurd ones convert in bounded time.

use super::cases::*;
use super::noise::noise;
use super::project::*;

#[test]
fn bad_obj_models_are_named_by_file_and_line() {
    let p = Project::new();
    let good = camera_and_light() + &cube(100, "Box", &pos(0.0, 0.0, 0.0), 0);
    let tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
    let models: Vec<(&str, Vec<u8>, &[&str])> = vec![
        (
            "out-of-range index",
            format!("{tri}f 1 2 9\n").into_bytes(),
            &[":4:", "vertex index 9 out of range"],
        ),
        (
            "zero index",
            format!("{tri}f 0 1 2\n").into_bytes(),
            &[":4:", "vertex index 0 out of range"],
        ),
        (
            "negative index past the start",
            format!("{tri}f -1 -2 -4\n").into_bytes(),
            &[":4:", "vertex index -4 out of range"],
        ),
        (
            "normal index out of range",
            format!("{tri}vn 0 0 1\nf 1//1 2//2 3//1\n").into_bytes(),
            &[":5:", "normal index 2 out of range"],
        ),
        (
            "index past i64",
            format!("{tri}f 1 2 99999999999999999999\n").into_bytes(),
            &[":4:", "99999999999999999999"],
        ),
        (
            "bad number",
            format!("{tri}v 1 2 x\nf 1 2 3\n").into_bytes(),
            &[":4:", "bad number"],
        ),
        (
            "binary garbage",
            [b"v ".as_slice(), &noise(2048, 3)].concat(),
            &[":1:"],
        ),
        (
            "Git LFS pointer",
            b"version https://git-lfs.github.com/spec/v1\noid sha256:ab\nsize 9\n".to_vec(),
            &["git lfs pull"],
        ),
        ("zero-byte file (no faces)", vec![], &["no faces"]),
    ];
    let mut cases = Vec::new();
    for (i, (label, bytes, names)) in models.into_iter().enumerate() {
        let guid = format!("{:032x}", 0xabc000 + i);
        let rel = format!("Assets/bad{i}.obj");
        p.file(&rel, &bytes);
        p.file(&format!("{rel}.meta"), meta(&guid));
        let scene = p.scene(
            &format!("Obj{i}"),
            &(good.clone() + &instance(100_000, &guid)),
        );
        let mut names: Vec<&str> = names.to_vec();
        names.push(&rel);
        names.push("warning:");
        let o = p.out(&format!("obj{i}.soup"));
        // The model is skipped with a warning naming file and line; the scene converts.
        cases.push(case(
            &format!("OBJ: {label}"),
            "unity2soup",
            &[&s(&scene), "-o", &s(&o)],
            0,
            &names,
            Out::Written(o.clone()),
        ));
        let o = p.out(&format!("obj{i}-strict.soup"));
        cases.push(case(
            &format!("OBJ: {label}, --strict"),
            "unity2soup",
            &[&s(&scene), "-o", &s(&o), "--strict"],
            1,
            &[&rel],
            Out::Absent(o),
        ));
    }
    // Faces with fewer than 3 corners are skipped with a warning; the rest converts.
    let g = "77777777777777777777777777777777";
    p.file(
        "Assets/short.obj",
        format!("{tri}v 1 1 0\nf 1 2\nf 3\nf 1 2 3\nf 2 4 3\n"),
    );
    p.file("Assets/short.obj.meta", meta(g));
    let scene = p.scene("Short", &(good.clone() + &instance(100_000, g)));
    let o = p.out("short.soup");
    cases.push(case(
        "OBJ: faces with 2 and 1 corners",
        "unity2soup",
        &[&s(&scene), "-o", &s(&o)],
        0,
        &[
            "Assets/short.obj",
            "2 faces with fewer than 3 corners",
            "14 triangles",
        ],
        Out::Written(o),
    ));
    // A NaN vertex is an error naming the object that uses the model.
    let g = "88888888888888888888888888888888";
    p.file("Assets/nan.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n");
    p.file("Assets/nan.obj.meta", meta(g));
    let scene = p.scene("Nan", &(good.clone() + &instance(100_000, g)));
    let o = p.out("nan.soup");
    cases.push(case(
        "OBJ: NaN vertex",
        "unity2soup",
        &[&s(&scene), "-o", &s(&o)],
        1,
        &["nan.obj", "NaN or infinite"],
        Out::Absent(o),
    ));
    check(cases);
}

#[test]
fn absurd_obj_polygons_convert_in_bounded_time() {
    // One 20 000-corner non-convex (star) face: ear clipping is cubic in the corner
    // count, so a face this large must take the bounded path.
    let p = Project::new();
    let n = 20_000;
    let mut text = String::new();
    for i in 0..n {
        let a = i as f32 / n as f32 * std::f32::consts::TAU;
        let r = if i % 2 == 0 { 1.0 } else { 0.5 };
        text += &format!("v {} {} 0\n", r * a.cos(), r * a.sin());
    }
    text += "f";
    for i in 1..=n {
        text += &format!(" {i}");
    }
    text += "\n";
    let g = "99999999999999999999999999999999";
    p.file("Assets/star.obj", text);
    p.file("Assets/star.obj.meta", meta(g));
    let scene = p.scene("Star", &(camera_and_light() + &instance(100, g)));
    let o = p.out("star.soup");
    let soup = convert(&scene, &o);
    // A polygon of n corners makes n − 2 triangles (none are degenerate here).
    assert_eq!(
        soup.triangles.len() as u64 + soup.dropped_degenerate,
        n as u64 - 2
    );
}
