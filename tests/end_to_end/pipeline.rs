//! The three real binaries chained on a small Unity project written for this test:
//! unity2soup → soup2kd → kd2exr, then pixel values where the answer is known.
//!
//! The project (Unity coordinates, metres): an orthographic camera 10 m above the origin
//! looking straight down (half-height 5 m, so a 100×100 image has 0.1 m pixels, image
//! right = Unity +X, image up = Unity +Z); a grey 10 m Plane; one point light with hard
//! shadows at (−2, 2, 0), range 6; a 1 m horizontal Quad at (−1, 1, 1) that shadows the
//! floor around (0, 0, 2); a 2 m horizontal mirror Quad at (3, 0.5, −3); and 12 m up,
//! behind the camera, a red emissive Quad facing down that only the mirror can show.

use glam::Vec3;
use scenegen::effects::Builder;
use scenegen::material::MatDesc;
use scenegen::unity::{Ambient, CameraDesc, LightDesc, Xform, PLANE, QUAD};
use std::f32::consts::PI;
use std::path::Path;
use unitrace::{run_ok, unity_diffuse, Rgba};

const SIZE: u32 = 100;

fn write_project(root: &Path) -> std::path::PathBuf {
    let glow = MatDesc {
        name: "Glow",
        color: [0.0, 0.0, 0.0],
        metallic: 0.0,
        glossiness: 0.0,
        highlights: true,
        reflectivity: None,
        emission: Some([1.0, 0.1, 0.05]),
    };
    let mut b = Builder::new(
        "e2e",
        &[
            MatDesc::matte("Grey", [0.8, 0.8, 0.8]),
            MatDesc::mirror("Mirror"),
            glow,
        ],
    );
    let flat = |x: f32, y: f32, z: f32| Xform::at(x, y, z).euler(90.0, 0.0, 0.0);
    b.camera(
        flat(0.0, 10.0, 0.0),
        CameraDesc {
            orthographic: Some(5.0),
            ..CameraDesc::default()
        },
    )
    .mesh("Ground", PLANE, "Grey", Xform::at(0.0, 0.0, 0.0))
    .mesh("Occluder", QUAD, "Grey", flat(-1.0, 1.0, 1.0))
    .mesh("Mirror", QUAD, "Mirror", flat(3.0, 0.5, -3.0).uniform(2.0))
    // Facing down: Unity's Quad is one-sided, and the mirror sees it from below.
    .mesh(
        "Glow",
        QUAD,
        "Glow",
        Xform::at(3.0, 12.0, -3.0)
            .euler(-90.0, 0.0, 0.0)
            .uniform(4.0),
    )
    .light(
        "Point Light",
        Xform::at(-2.0, 2.0, 0.0),
        LightDesc {
            shadows: 1,
            ..LightDesc::point([1.0, 1.0, 1.0], 1.5, 6.0)
        },
    );
    // The pixels follow from the light and the mirror alone: no sky reflection.
    b.reflection(0.0);
    let project = b.finish("E2E", Ambient::Flat([0.0, 0.0, 0.0]));
    project.write(root).expect("write the test project");
    root.join("e2e/Assets/Scenes/E2E.unity")
}

/// Unity's point-light attenuation, written out again here so the pixels are checked against
/// Unity's formula rather than against the renderer's own code.
fn unity_falloff(d: f32, range: f32) -> f32 {
    let x = d / range;
    if x >= 1.0 {
        return 0.0;
    }
    let fade = if x <= 0.8 { 1.0 } else { (1.0 - x) / 0.2 };
    fade / (1.0 + 25.0 * x * x)
}

/// The built-in Standard shader's highlight from a punctual light per unit of its radiance,
/// the cosine included (`BRDF1_Unity_PBS`: GGX, Smith-joint visibility, Schlick's Fresnel),
/// written out again here from Unity's shader source; unit vectors towards the light `l`
/// and the eye `v`, normal `n`, a dielectric (f0 = 0.04).
fn unity_highlight(n: Vec3, l: Vec3, v: Vec3, smoothness: f32) -> f32 {
    let h = (l + v).normalize();
    let (nl, nv, nh, lh) = (n.dot(l), n.dot(v), n.dot(h), l.dot(h));
    let a = (1.0 - smoothness).powi(2).max(0.002);
    let visibility = 0.5 / (nl * (nv * (1.0 - a) + a) + nv * (nl * (1.0 - a) + a));
    let ggx = a * a / (PI * ((nh * nh) * (a * a - 1.0) + 1.0).powi(2));
    let fresnel = 0.04 + 0.96 * (1.0 - lh).powi(5);
    visibility * ggx * PI * nl * fresnel
}

/// Centre of pixel (px, py) in Unity coordinates on the floor, from the project's numbers.
fn unity_floor_point(px: u32, py: u32) -> (f32, f32) {
    let pixel = 10.0 / SIZE as f32;
    (
        -5.0 + (px as f32 + 0.5) * pixel,
        5.0 - (py as f32 + 0.5) * pixel,
    )
}

fn rgb(p: [f32; 4]) -> Vec3 {
    Vec3::new(p[0], p[1], p[2])
}

fn assert_close(got: Vec3, want: Vec3, rel: f32, what: &str) {
    let tol = want.abs().max_element() * rel + 1e-6;
    assert!(
        (got - want).abs().max_element() <= tol,
        "{what}: got {got}, want {want} (±{rel})"
    );
}

#[test]
fn unity_scene_through_the_three_binaries_gives_the_known_pixels() {
    let dir = tempfile::tempdir().unwrap();
    let scene = write_project(dir.path());
    let soup_path = dir.path().join("e2e.soup");
    let exr = dir.path().join("e2e.exr");
    let s = run_ok(
        "unity2soup",
        [
            scene.as_os_str(),
            "-o".as_ref(),
            soup_path.as_os_str(),
            "--json".as_ref(),
        ],
    )
    .json();
    assert_eq!(s["objects"], 4, "{s}");
    // Plane 200 + three Quads of 2 triangles.
    assert_eq!(s["triangles"], 206, "{s}");
    assert_eq!(s["lights"], 1, "{s}");
    let cache = dir.path().join("cache");
    let k = run_ok(
        "soup2kd",
        [
            soup_path.as_os_str(),
            "--cache".as_ref(),
            cache.as_os_str(),
            "--json".as_ref(),
        ],
    )
    .json();
    assert_eq!(k["cache"], "miss");
    assert_eq!(k["triangles"], 206);
    let kd = k["path"].as_str().expect("the tree's path").to_string();
    let size = SIZE.to_string();
    let r = run_ok(
        "kd2exr",
        [
            soup_path.to_str().unwrap(),
            &kd,
            "-o",
            exr.to_str().unwrap(),
            "--width",
            &size,
            "--height",
            &size,
            "--json",
        ],
    )
    .json();
    assert_eq!(r["rays"]["camera"], SIZE * SIZE);
    let img = Rgba::read(&exr);
    img.assert_finite();
    assert_eq!((img.width, img.height), (SIZE as usize, SIZE as usize));

    // Material and light numbers as converted (their conversion is tested in crates/unity).
    let soup = formats::Soup::read(&soup_path).unwrap();
    let grey = soup.materials.iter().find(|m| m.name == "Grey").unwrap();
    let mirror = soup.materials.iter().find(|m| m.name == "Mirror").unwrap();
    let glow = soup.materials.iter().find(|m| m.name == "Glow").unwrap();
    let light = &soup.lights[0];
    // The soup is right-handed: Unity's X is negated, so Unity (x, y, z) is (−x, y, z) there.
    assert_eq!(light.position, Vec3::new(2.0, 2.0, 0.0));
    assert!(
        grey.pbs && grey.highlights,
        "the Standard shader draws highlights"
    );
    // The orthographic camera looks straight down: every floor point is seen from above.
    let lit = |ux: f32, uz: f32| {
        let to = light.position - Vec3::new(-ux, 0.0, uz);
        let d = to.length();
        let l = to / d;
        let reflected = grey.albedo() * unity_diffuse(Vec3::Y, l, Vec3::Y, grey.smoothness)
            + Vec3::splat(unity_highlight(Vec3::Y, l, Vec3::Y, grey.smoothness));
        reflected * light.color * light.intensity * unity_falloff(d, light.range)
    };

    // 1. A floor pixel in the light's reach matches the formula within 1 %.
    let (ux, uz) = unity_floor_point(20, 70);
    let want = lit(ux, uz);
    assert!(want.x > 0.05, "the test point must be well lit: {want}");
    assert_close(rgb(img.at(20, 70)), want, 0.01, "lit floor at (20, 70)");
    // Beyond the range the floor is black (no ambient, black clear colour).
    assert_eq!(
        rgb(img.at(95, 95)),
        Vec3::ZERO,
        "floor beyond the light's range"
    );

    // 2. The floor point whose path to the light crosses the occluder is dark.
    let (ux, uz) = unity_floor_point(50, 30);
    assert!((ux - 0.05).abs() < 1e-4 && (uz - 1.95).abs() < 1e-4);
    assert!(lit(ux, uz).x > 0.05, "without the occluder it would be lit");
    assert_eq!(rgb(img.at(50, 30)), Vec3::ZERO, "the shadowed floor point");

    // 3. The mirror at Unity x = +3, z = −3 (right half, lower half of the image: not
    //    mirrored) shows the red emitter above and behind the camera, which the camera
    //    cannot see directly.
    let want = mirror.reflectance() * glow.emission;
    assert!(want.x > 0.5 && want.x > 5.0 * want.y, "{want}");
    assert_close(rgb(img.at(80, 80)), want, 0.01, "mirror at (80, 80)");
    // The same spot mirrored left-right is plain lit floor.
    let (ux, uz) = unity_floor_point(19, 80);
    assert_close(rgb(img.at(19, 80)), lit(ux, uz), 0.01, "floor at (19, 80)");
}

/// The scale-test project (`scenegen --large`) at side 2: four copies of the baseline's
/// props on one floor under a sun. Side 16 (10.7 million triangles) is the same code; its
/// timings are in docs/PERFORMANCE.md.
#[test]
fn large_scene_converts_to_side_squared_copies_of_the_baseline_props() {
    let dir = tempfile::tempdir().unwrap();
    scenegen::baseline::large(2)
        .write(dir.path())
        .expect("write the large project");
    let scene = dir
        .path()
        .join("large")
        .join(scenegen::baseline::LARGE_SCENE_PATH);
    let soup = dir.path().join("large.soup");
    let s = run_ok(
        "unity2soup",
        [
            scene.as_os_str(),
            "-o".as_ref(),
            soup.as_os_str(),
            "--json".as_ref(),
        ],
    )
    .json();
    // The baseline minus its 12-triangle floor, four times, plus the stretched floor.
    let props = scenegen::baseline::TRIANGLES - 12;
    assert_eq!(s["triangles"], 4 * props + 12, "{s}");
    assert_eq!(s["objects"], 1 + 4 * 8, "{s}");
    assert_eq!(s["lights"], 1, "{s}");
    assert_eq!(s["warnings"].as_array().map(Vec::len), Some(0), "{s}");
}
