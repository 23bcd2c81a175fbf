//! A Unity Terrain through the three binaries, on the bundled `scenes/terrain` project
//! (written by `scenegen`): a binary TerrainData of two hills, grass below and rock on
//! the high hill's upper slopes, with 24 trees of a prefab painted on the grass, under
//! Unity's default procedural sky.

use glam::Vec3;
use unitrace::{repo, run_ok, Rgba};

#[test]
fn the_terrain_is_converted_with_a_layer_per_cell_and_its_trees_and_renders_them() {
    let dir = tempfile::tempdir().unwrap();
    let scene = repo().join("scenes/terrain/Assets/Scenes/Terrain.unity");
    let (soup, kd, exr) = (
        dir.path().join("t.soup"),
        dir.path().join("t.kd"),
        dir.path().join("t.exr"),
    );
    let s = |p: &std::path::Path| p.to_str().unwrap().to_string();
    let report = run_ok(
        "unity2soup",
        [s(&scene), "-o".into(), s(&soup), "--json".into()],
    )
    .json();
    // 64 × 64 cells of two triangles, one material per layer that draws a cell; and 24
    // trees of two parts (Unity's cylinder and sphere, 800 triangles), bark and leaves.
    assert_eq!(report["triangles"], 8192 + 24 * 800);
    assert_eq!(report["objects"], 1 + 24 * 2);
    assert_eq!(report["materials"], 2 + 2);
    let warnings = report["warnings"].as_array().unwrap();
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    let w = warnings[0].as_str().unwrap();
    assert!(
        w.contains("2 terrain layers ('Grass' 87 %, 'Rock' 13 %)"),
        "{w}"
    );
    run_ok("soup2kd", [s(&soup), "-o".into(), s(&kd)]);
    run_ok(
        "kd2exr",
        [
            s(&soup),
            s(&kd),
            "-o".into(),
            s(&exr),
            "--width".into(),
            "64".into(),
            "--height".into(),
            "36".into(),
        ],
    );
    let img = Rgba::read(&exr);
    img.assert_finite();
    let rgb = |x: usize, y: usize| {
        let p = img.at(x, y);
        Vec3::new(p[0], p[1], p[2])
    };
    let grass = |c: Vec3| c.y > 1.5 * c.x && c.y > 1.5 * c.z;
    // Rock: the grey-brown texel (128, 118, 108) under a warm sun and the sky's light.
    let rock = |c: Vec3| c.x > c.y && c.y > c.z && c.y > 0.7 * c.x && c.x > 0.05;
    // The leaves' albedo (0.16, 0.42, 0.12) is greener than the grass (0.34, 0.55, 0.2).
    // (They reflect a little of the sky.)
    let leaves = |c: Vec3| c.y > 3.0 * c.x && c.y > 3.0 * c.z;
    // The foreground is grass, the trees stand in a band across the middle, the high
    // hill's top (right of centre, upper third) is rock, and the sky above it blue.
    for (x, y) in [(20, 28), (30, 31), (40, 16)] {
        assert!(grass(rgb(x, y)) && !leaves(rgb(x, y)), "{}", rgb(x, y));
    }
    for (x, y) in [(4, 21), (29, 20), (61, 21)] {
        assert!(leaves(rgb(x, y)), "{}", rgb(x, y));
    }
    let leaf_pixels = (0..36)
        .flat_map(|y| (0..64).map(move |x| (x, y)))
        .filter(|&(x, y)| leaves(rgb(x, y)))
        .count();
    assert!(
        (150..400).contains(&leaf_pixels),
        "{leaf_pixels} leaf pixels"
    );
    assert!(rock(rgb(38, 12)), "{}", rgb(38, 12));
    let sky = rgb(10, 3);
    assert!(sky.z > sky.y && sky.y > sky.x, "{sky}");
    let grass_pixels = (0..36)
        .flat_map(|y| (0..64).map(move |x| (x, y)))
        .filter(|&(x, y)| grass(rgb(x, y)))
        .count();
    assert!(grass_pixels > 64 * 36 / 3, "{grass_pixels} grass pixels");
}
