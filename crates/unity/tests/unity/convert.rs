//! unity2soup on tiny hand-written projects: coordinates, handedness, hierarchy,
//! primitives, fileID schemes, prefab instances, visibility, lights and camera.

use crate::support::*;
use formats::{Attenuation, FogMode, LightKind, Shadows};
use glam::Vec3;
use std::f32::consts::{FRAC_1_SQRT_2, PI};
use std::path::{Path, PathBuf};

const OBJ_GUID: &str = "a1b2c3d4e5f60718293a4b5c6d7e8f90";

/// A triangle and a quad (two triangles) in a right-handed OBJ, normals along +Z.
const OBJ: &str = "v 1 2 3\nv 4 2 3\nv 1 5 3\nv 10 0 -1\nv 11 0 -1\nv 11 1 -1\nv 10 1 -1\nvn 0 0 1\ng default\nf 1//1 2//1 3//1\nf 4//1 5//1 6//1 7//1\n";

/// Default-Material, the slot every test model object uses.
const DEFAULT_MAT: (i64, &str) = (10303, "0000000000000000f000000000000000");

/// A scene whose one GameObject `name`, at the origin, draws the `default` mesh of the
/// model `OBJ_GUID` with Default-Material.
fn model_scene(name: &str) -> Scene {
    mesh_scene(name, 4300000, OBJ_GUID, &[DEFAULT_MAT])
}

/// A scene whose one GameObject `name`, at the origin, draws mesh `mesh_id` of asset
/// `guid` with `materials`.
fn mesh_scene(name: &str, mesh_id: i64, guid: &str, materials: &[(i64, &str)]) -> Scene {
    let mut sc = Scene::default();
    let (go, _) = sc.object(name, &Tf::at(0.0, 0.0, 0.0), 0, true);
    sc.mesh(go, mesh_id, guid, materials, true);
    sc
}

/// A project holding the OBJ text `obj` at `obj_path` (its legacy `.meta` names the one
/// mesh `default`) and `scene_text` at `scene_path`; returns the scene's path.
fn obj_project(
    obj_path: &str,
    obj: &str,
    scene_path: &str,
    scene_text: &str,
) -> (tempfile::TempDir, PathBuf) {
    let meta = legacy_meta(OBJ_GUID, &["default"]);
    let meta_path = format!("{obj_path}.meta");
    let (d, root) = project(&[
        (obj_path, obj),
        (&meta_path, &meta),
        (scene_path, scene_text),
    ]);
    (d, root.join(scene_path))
}

/// The error converting `scene`, as one line.
fn convert_error(scene: &Path) -> String {
    unity::convert(scene, &unity::Options::default())
        .unwrap_err()
        .to_string()
}

fn legacy_meta(guid: &str, names: &[&str]) -> String {
    let mut s = format!("fileFormatVersion: 2\nguid: {guid}\nModelImporter:\n  serializedVersion: 23\n  fileIDToRecycleName:\n    100000: //RootNode\n    400000: //RootNode\n");
    for (i, n) in names.iter().enumerate() {
        s += &format!(
            "    {}: {n}\n    {}: {n}\n    {}: {n}\n    {}: {n}\n    {}: {n}\n",
            100002 + 2 * i,
            400002 + 2 * i,
            2300000 + 2 * i,
            3300000 + 2 * i,
            4300000 + 2 * i
        );
    }
    s + "  meshes:\n    globalScale: 1\n"
}

#[test]
fn obj_at_identity_keeps_its_file_coordinates_and_winding() {
    let sc = model_scene("Model");
    let (_d, scene) = obj_project("Assets/m.obj", OBJ, "Assets/s.unity", &sc.text);
    let soup = convert(&scene);
    let v = |x, y, z| Vec3::new(x, y, z);
    assert_eq!(
        soup.triangle_positions(),
        vec![
            [v(1., 2., 3.), v(4., 2., 3.), v(1., 5., 3.)],
            [v(10., 0., -1.), v(11., 0., -1.), v(11., 1., -1.)],
            [v(10., 0., -1.), v(11., 1., -1.), v(10., 1., -1.)],
        ],
        "exactly the file's positions, in file order and winding"
    );
    assert!(soup.normals.iter().all(|n| *n == Vec3::Z));
    assert_eq!(soup.objects.len(), 1);
    assert_eq!(soup.objects[0].name, "Model");
    assert_eq!(soup.objects[0].source, "Assets/m.obj#default");
    assert!(
        soup.warnings.iter().all(|w| !w.contains("m.obj")),
        "{:?}",
        soup.warnings
    );
}

#[test]
fn object_at_unity_plus_x_is_right_of_the_camera() {
    let mut sc = Scene::default();
    sc.camera(&Tf::at(0.0, 0.0, 0.0));
    sc.primitive("Right", &Tf::at(3.0, 0.0, 10.0), 0, CUBE);
    let soup = convert_scene(&sc.text);
    let cam = &soup.camera;
    assert_eq!(cam.forward, Vec3::Z);
    assert_eq!(cam.up, Vec3::Y);
    let centre = corner_mean(&soup);
    assert!(
        close(centre, Vec3::new(-3.0, 0.0, 10.0), 1e-4),
        "soup x is negated: {centre}"
    );
    assert!(
        (centre - cam.position).dot(cam.right()) > 2.9,
        "right of the image"
    );
    // Solid background, sRGB 0.5 → linear.
    assert!((soup.environment.background.x - 0.21404114).abs() < 1e-6);
}

#[test]
fn the_far_clip_plane_is_read_and_one_not_beyond_the_near_plane_is_dropped() {
    let mut sc = Scene::default();
    sc.camera(&Tf::at(0.0, 0.0, 0.0));
    // No far plane written: Unity's default.
    assert_eq!(convert_scene(&sc.text).camera.far, 1000.0);
    let far = |f: &str| {
        let text = sc.text.replace(
            "  near clip plane: 0.3\n",
            &format!("  near clip plane: 0.3\n  far clip plane: {f}\n"),
        );
        convert_scene(&text)
    };
    assert_eq!(far("55.5").camera.far, 55.5);
    let bad = far("0.2");
    assert_eq!(bad.camera.far, f32::INFINITY);
    assert_warned(&bad, "far clip plane 0.2 is not beyond the near plane 0.3");
}

/// The bundled fog scene: its RenderSettings fog arrives in the soup, colour decoded.
#[test]
fn render_settings_fog_reaches_the_soup() {
    let scene =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/fog/Assets/Scenes/Fog.unity");
    let soup = convert(&scene);
    let fog = soup.environment.fog.expect("the scene has fog");
    assert_eq!(fog.mode, FogMode::ExponentialSquared { density: 0.04 });
    let grey = [0.62f32, 0.66, 0.72].map(unity::material::srgb_to_linear);
    assert_eq!(fog.colour, Vec3::from_array(grey));
    assert_eq!(soup.environment.background, fog.colour);
    assert!(soup.warnings.is_empty(), "{:?}", soup.warnings);
}

/// The bundled skybox scene: its panoramic material's HDR image, the sun in it brighter
/// than 1, where the directional light comes from.
#[test]
fn the_bundled_skybox_scene_reads_its_hdr_panorama() {
    let scene = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenes/skybox/Assets/Scenes/Skybox.unity");
    let soup = convert(&scene);
    assert!(soup.warnings.is_empty(), "{:?}", soup.warnings);
    assert_eq!(soup.environment.clear, formats::ClearFlags::Skybox);
    assert_eq!(soup.environment.ambient.mode, formats::AmbientMode::Skybox);
    let Some(formats::Sky::Textured(sky)) = &soup.environment.sky else {
        panic!("{:?}", soup.environment.sky);
    };
    let formats::SkyLayout::LatLong { image, panorama } = &sky.layout else {
        panic!("{:?}", sky.layout);
    };
    assert_eq!(*panorama, formats::Panorama::Full);
    assert_eq!((image.width, image.height), (1024, 512));
    assert_eq!(image.source, "Assets/Textures/Sky.hdr");
    // The brightest texel is the sun's 400 (red), within RGBE's rounding, and lies in the
    // direction opposite the light's (Unity's axes: the soup's with X negated).
    let (mut best, mut at) = (0.0f32, (0, 0));
    for y in 0..image.height {
        for x in 0..image.width {
            let r = image.texel(x, y).x;
            if r > best {
                (best, at) = (r, (x, y));
            }
        }
    }
    assert!((best - 400.0).abs() <= 400.0 / 256.0, "{best}");
    let u = (at.0 as f32 + 0.5) / 1024.0;
    let v = (at.1 as f32 + 0.5) / 512.0;
    let (polar, azimuth) = (PI * (1.0 - v), (0.5 - u) * 2.0 * PI);
    let d = Vec3::new(
        polar.sin() * azimuth.cos(),
        polar.cos(),
        polar.sin() * azimuth.sin(),
    );
    let light = soup.lights[0].direction;
    let towards_sun = -Vec3::new(-light.x, light.y, light.z);
    assert!(
        d.dot(towards_sun) > 1.5f32.to_radians().cos(),
        "{d} against {towards_sun}"
    );
}

#[test]
fn shadow_strength_is_read_and_kept_within_0_to_1() {
    let strength = |line: &str| {
        let mut sc = Scene::default();
        sc.camera(&Tf::at(0.0, 0.0, 0.0));
        sc.light(&Tf::at(0.0, 3.0, 0.0), 2, [1.0, 1.0, 1.0], 1);
        let text = sc.text.replace(
            "    m_Resolution: -1\n",
            &format!("    m_Resolution: -1\n{line}"),
        );
        convert_scene(&text).lights[0].shadow_strength
    };
    assert_eq!(strength(""), 1.0, "Unity's default");
    assert_eq!(strength("    m_Strength: 0.4\n"), 0.4);
    assert_eq!(strength("    m_Strength: 1.7\n"), 1.0);
    assert_eq!(strength("    m_Strength: -2\n"), 0.0);
}

/// A Skybox camera under Default-Skybox shows Unity's procedural sky, lit by the scene's
/// directional light; a skybox Unity draws but unitrace cannot read is a warning and the
/// gradient stays.
#[test]
fn the_default_skybox_is_a_procedural_sky_aimed_at_the_sun() {
    let skybox = |material: &str| {
        let mut sc = Scene::default();
        sc.camera(&Tf::at(0.0, 0.0, 0.0));
        // Unity's light shines along its local +Z: unrotated, towards +Z.
        sc.light(&Tf::at(0.0, 3.0, 0.0), 1, [1.0, 1.0, 1.0], 0);
        sc.raw(&format!(
            "--- !u!104 &2\nRenderSettings:\n  m_SkyboxMaterial: {material}\n  m_Sun: {{fileID: 0}}\n"
        ));
        sc.text
            .replace("  m_ClearFlags: 2\n", "  m_ClearFlags: 1\n")
    };
    let soup = convert_scene(&skybox(
        "{fileID: 10304, guid: 0000000000000000f000000000000000, type: 0}",
    ));
    let Some(formats::Sky::Procedural(sky)) = soup.environment.sky else {
        panic!("Default-Skybox is procedural");
    };
    assert_eq!(sky.sun_disk, formats::SunDisk::HighQuality);
    assert_eq!((sky.exposure, sky.atmosphere_thickness), (1.3, 1.0));
    assert_eq!(sky.sun_direction, -soup.lights[0].direction);
    assert_eq!(sky.sun_direction, -Vec3::Z);
    assert_eq!(
        sky.sun_colour,
        soup.lights[0].color * soup.lights[0].intensity
    );

    // A solid-colour camera still needs the sky for Skybox ambient (mode 0) and for the
    // default reflection probe (intensity 1 unless the file says otherwise), not for flat
    // ambient without reflection.
    let solid = |mode: u8, reflection: &str| {
        let text = skybox("{fileID: 10304, guid: 0000000000000000f000000000000000, type: 0}")
            .replace("  m_ClearFlags: 1\n", "  m_ClearFlags: 2\n")
            .replace(
                "  m_Sun: {fileID: 0}\n",
                &format!(
                    "  m_Sun: {{fileID: 0}}\n  m_AmbientMode: {mode}\n  m_AmbientIntensity: 0.5\n{reflection}"
                ),
            );
        convert_scene(&text).environment
    };
    let none = "  m_ReflectionIntensity: 0\n";
    let env = solid(0, none);
    assert!(env.sky.is_some());
    assert_eq!(env.ambient.intensity, 0.5);
    assert_eq!(env.reflection, 0.0);
    assert!(solid(3, none).sky.is_none());
    let reflecting = solid(3, "");
    assert!(reflecting.sky.is_some());
    assert_eq!(reflecting.reflection, 1.0, "Unity's default intensity");
    let half = solid(
        3,
        "  m_DefaultReflectionMode: 0\n  m_ReflectionIntensity: 0.5\n",
    );
    assert_eq!(half.reflection, 0.5);
    // A custom cubemap is not read: no reflection, and a warning says so.
    let text = skybox("{fileID: 10304, guid: 0000000000000000f000000000000000, type: 0}").replace(
        "  m_Sun: {fileID: 0}\n",
        "  m_Sun: {fileID: 0}\n  m_DefaultReflectionMode: 1\n",
    );
    let custom = convert_scene(&text);
    assert_eq!(custom.environment.reflection, 0.0);
    assert!(
        custom
            .warnings
            .iter()
            .any(|w| w.contains("custom cubemap, which is not read")),
        "{:?}",
        custom.warnings
    );

    let cubemap =
        "--- !u!21 &2100000\nMaterial:\n  m_Shader: {fileID: 103, guid: 0000000000000000f000000000000000, type: 0}\n";
    let scene = skybox("{fileID: 2100000, guid: 5ca1ab1e5ca1ab1e5ca1ab1e5ca1ab1e, type: 2}");
    let (_d, root) = project(&[
        ("Assets/s.unity", scene.as_str()),
        ("Assets/Sky.mat", cubemap),
        (
            "Assets/Sky.mat.meta",
            "fileFormatVersion: 2\nguid: 5ca1ab1e5ca1ab1e5ca1ab1e5ca1ab1e\n",
        ),
    ]);
    let soup = convert(&root.join("Assets/s.unity"));
    assert!(soup.environment.sky.is_none());
    // HDRP draws its sky from a Volume, whatever RenderSettings names.
    let default = skybox("{fileID: 10304, guid: 0000000000000000f000000000000000, type: 0}");
    let (_h, hdrp) = project(&[
        ("Assets/s.unity", default.as_str()),
        (
            "Packages/manifest.json",
            "{\"dependencies\": {\"com.unity.render-pipelines.high-definition\": \"14.0.9\"}}",
        ),
    ]);
    let hd = convert(&hdrp.join("Assets/s.unity"));
    assert!(hd.environment.sky.is_none());
    assert_warned(&hd, "HDRP ignores RenderSettings' skybox");
    assert!(
        soup.warnings.iter().any(|w| {
            w.contains(
                "RenderSettings: skybox Assets/Sky.mat: _Tex names no texture; a sky gradient \
             stands in, and surfaces reflect no sky",
            )
        }),
        "{:?}",
        soup.warnings
    );
}

#[test]
fn primitives_have_unity_dimensions() {
    let cases = [
        (10202, "Cube", 12, Vec3::splat(-0.5), Vec3::splat(0.5)),
        (
            10206,
            "Cylinder",
            0,
            Vec3::new(-0.5, -1.0, -0.5),
            Vec3::new(0.5, 1.0, 0.5),
        ),
        (10207, "Sphere", 0, Vec3::splat(-0.5), Vec3::splat(0.5)),
        (
            10208,
            "Capsule",
            0,
            Vec3::new(-0.5, -1.0, -0.5),
            Vec3::new(0.5, 1.0, 0.5),
        ),
        (
            10209,
            "Plane",
            200,
            Vec3::new(-5.0, 0.0, -5.0),
            Vec3::new(5.0, 0.0, 5.0),
        ),
        (
            10210,
            "Quad",
            2,
            Vec3::new(-0.5, -0.5, 0.0),
            Vec3::new(0.5, 0.5, 0.0),
        ),
    ];
    for (id, name, tris, lo, hi) in cases {
        let mut sc = Scene::default();
        sc.primitive(name, &Tf::at(0.0, 0.0, 0.0), 0, id);
        let soup = convert_scene(&sc.text);
        if tris > 0 {
            assert_eq!(soup.triangles.len(), tris, "{name}");
        }
        let (blo, bhi) = bounds(soup.triangle_positions().iter().flatten().copied());
        assert!(
            close(blo, lo, 1e-5) && close(bhi, hi, 1e-5),
            "{name}: {blo} {bhi}"
        );
        assert_eq!(soup.objects[0].source, format!("builtin:{name}"));
        // Every triangle's winding agrees with its shading normals (front = CCW).
        for (t, n) in soup.triangle_positions().iter().zip(corner_normals(&soup)) {
            let g = (t[1] - t[0]).cross(t[2] - t[0]);
            assert!(
                g.dot(n[0] + n[1] + n[2]) > 0.0,
                "{name}: winding against normals"
            );
        }
    }
    // Plane faces +Y, Quad faces −Z (z is unchanged by the x flip).
    let facing = |id: i64| {
        let mut sc = Scene::default();
        sc.primitive("P", &Tf::at(0.0, 0.0, 0.0), 0, id);
        let soup = convert_scene(&sc.text);
        let t = soup.corners(0);
        (t[1] - t[0]).cross(t[2] - t[0]).normalize()
    };
    assert!(close(facing(PLANE), Vec3::Y, 1e-6));
    assert!(close(facing(QUAD), Vec3::NEG_Z, 1e-6));
}

#[test]
fn negative_scale_mirrors_and_keeps_faces_outward() {
    // A Quad mirrored in Z (scale z = −1 does not move a z = 0 quad, but mirrors its
    // facing): it must now face +Z, with winding and normals agreeing.
    let mut sc = Scene::default();
    sc.primitive(
        "Mirrored",
        &Tf::at(0.0, 0.0, 0.0).scale(1.0, 1.0, -1.0),
        0,
        QUAD,
    );
    sc.primitive(
        "MirroredCube",
        &Tf::at(5.0, 0.0, 0.0).scale(-1.0, 2.0, 1.0),
        0,
        CUBE,
    );
    let soup = convert_scene(&sc.text);
    for (i, (t, n)) in soup
        .triangle_positions()
        .iter()
        .zip(corner_normals(&soup))
        .enumerate()
    {
        let g = (t[1] - t[0]).cross(t[2] - t[0]).normalize();
        assert!(
            g.dot(n[0]) > 0.99,
            "triangle {i}: winding {g} vs normal {}",
            n[0]
        );
        if soup.tri_object[i] == 0 {
            assert!(close(g, Vec3::Z, 1e-6), "mirrored quad faces +Z, got {g}");
        } else {
            // Outward: from the cube's centre (−5, 0, 0) towards the face.
            let c = (t[0] + t[1] + t[2]) / 3.0 - Vec3::new(-5.0, 0.0, 0.0);
            assert!(g.dot(c) > 0.0, "cube face {i} points inward");
        }
    }
}

#[test]
fn parented_rotated_scaled_hierarchy() {
    // Parent: position (1, 2, 3), rotation 90° about +Y (q = (0, sin 45°, 0, cos 45°)),
    // scale 2. Child Cube: local position (1, 0, 0), scale (1, 0.5, 1).
    // World (Unity) = T·R·S·child: S makes the offset (2, 0, 0); R (90° about Y) turns
    // +X into −Z, so (0, 0, −2); T adds (1, 2, 3): centre (1, 2, 1). Size: the cube's
    // 1×0.5×1 scaled by 2 → 2×1×2, turned about Y it stays 2×1×2.
    // Soup: x negated → centre (−1, 2, 1), bounds [−2, 1.5, 0] … [0, 2.5, 2].
    let mut sc = Scene::default();
    let (_, parent) = sc.object(
        "Parent",
        &Tf::at(1.0, 2.0, 3.0)
            .rot([0.0, FRAC_1_SQRT_2, 0.0, FRAC_1_SQRT_2])
            .scale(2.0, 2.0, 2.0),
        0,
        true,
    );
    sc.primitive(
        "Child",
        &Tf::at(1.0, 0.0, 0.0).scale(1.0, 0.5, 1.0),
        parent,
        CUBE,
    );
    // Non-uniform parent scale with a rotated child shears: parent scale (1, 3, 1), child
    // rotated 45° about Z. The child's local +X edge direction (1,1)/√2 becomes (1,3)/√2.
    let (_, p2) = sc.object(
        "Stretch",
        &Tf::at(0.0, 0.0, 20.0).scale(1.0, 3.0, 1.0),
        0,
        true,
    );
    let s = (std::f32::consts::PI / 8.0).sin();
    let c = (std::f32::consts::PI / 8.0).cos();
    sc.primitive(
        "Sheared",
        &Tf::at(0.0, 0.0, 0.0).rot([0.0, 0.0, s, c]),
        p2,
        CUBE,
    );
    let soup = convert_scene(&sc.text);
    assert_eq!(soup.objects[0].name, "Parent/Child");
    let tris = soup.triangle_positions();
    let pts = |o: u32| {
        tris.iter()
            .zip(&soup.tri_object)
            .filter(move |(_, &ob)| ob == o)
            .flat_map(|(t, _)| t.iter().copied())
    };
    let (lo, hi) = bounds(pts(0));
    assert!(
        close(lo, Vec3::new(-2.0, 1.5, 0.0), 1e-5) && close(hi, Vec3::new(0.0, 2.5, 2.0), 1e-5),
        "{lo} {hi}"
    );
    // Sheared cube: corner (0.5, 0.5) rotated 45° → (0, 0.7071), scaled y×3 → (0, 2.1213).
    let (lo, hi) = bounds(pts(1));
    assert!(
        (hi.y - 3.0 * FRAC_1_SQRT_2).abs() < 1e-5 && (lo.y + 3.0 * FRAC_1_SQRT_2).abs() < 1e-5,
        "{lo} {hi}"
    );
    assert!((hi.x - FRAC_1_SQRT_2).abs() < 1e-5, "{hi}");
}

#[test]
fn inactive_parents_and_disabled_renderers_draw_nothing() {
    let mut sc = Scene::default();
    let (_, hidden) = sc.object("Hidden", &Tf::at(0.0, 0.0, 0.0), 0, false);
    sc.primitive("UnderHidden", &Tf::at(0.0, 0.0, 0.0), hidden, CUBE);
    let (go, _) = sc.object("Disabled", &Tf::at(0.0, 0.0, 0.0), 0, true);
    sc.mesh(go, CUBE, BUILTIN, &[], false);
    sc.primitive("Shown", &Tf::at(0.0, 0.0, 0.0), 0, SPHERE);
    let soup = convert_scene(&sc.text);
    assert_eq!(soup.objects.len(), 1);
    assert_eq!(soup.objects[0].name, "Shown");
}

#[test]
fn lights_convert_position_direction_colour_and_shadows() {
    let mut sc = Scene::default();
    // Spot at (1, 2, 3) turned 90° about +Y: Unity's +Z becomes +X; soup −X.
    sc.light(
        &Tf::at(1.0, 2.0, 3.0).rot([0.0, FRAC_1_SQRT_2, 0.0, FRAC_1_SQRT_2]),
        0,
        [1.0, 0.5, 0.0],
        2,
    );
    sc.light(&Tf::at(0.0, 5.0, 0.0), 2, [1.0, 1.0, 1.0], 1);
    sc.light(&Tf::at(0.0, 0.0, 0.0), 1, [1.0, 1.0, 1.0], 0);
    sc.light(&Tf::at(0.0, 0.0, 0.0), 3, [1.0, 1.0, 1.0], 0);
    let soup = convert_scene(&sc.text);
    assert_eq!(soup.lights.len(), 3, "the area light is skipped");
    let spot = &soup.lights[0];
    assert_eq!(
        spot.kind,
        LightKind::Spot {
            angle: 40.0,
            inner_angle: 40.0
        }
    );
    assert!(close(spot.position, Vec3::new(-1.0, 2.0, 3.0), 1e-6));
    assert!(
        close(spot.direction, Vec3::new(-1.0, 0.0, 0.0), 1e-6),
        "{}",
        spot.direction
    );
    // A built-in project without graphics settings: Unity decodes the gamma colour times
    // the intensity, (1.5, 0.75, 0) → (1.5^2.2, sRGB⁻¹(0.75), 0).
    assert!(close(
        spot.color * spot.intensity,
        Vec3::new(2.4400615, 0.52252156, 0.0),
        1e-5
    ));
    assert!(
        (spot.intensity - 2.4400615).abs() < 1e-5,
        "{}",
        spot.intensity
    );
    assert_eq!(
        (spot.range, spot.shadows, spot.shadow_radius),
        (12.0, Shadows::Soft, 0.1)
    );
    assert_eq!(
        (soup.lights[1].kind, soup.lights[1].shadows),
        (LightKind::Point, Shadows::Hard)
    );
    assert_eq!(
        (soup.lights[2].kind, soup.lights[2].shadow_radius),
        (LightKind::Directional, 1.0)
    );
    assert_warned(&soup, "area light");
}

#[test]
fn lights_take_the_attenuation_of_the_projects_render_pipeline() {
    let mut sc = Scene::default();
    sc.light(&Tf::at(0.0, 5.0, 0.0), 2, [1.0, 1.0, 1.0], 1);
    sc.light(&Tf::at(1.0, 5.0, 0.0), 0, [1.0, 1.0, 1.0], 0);
    let manifest = |package: &str| {
        format!("{{\n  \"dependencies\": {{\n    \"com.unity.ugui\": \"1.0.0\",\n    \"{package}\": \"14.0.9\"\n  }}\n}}\n")
    };
    // The built-in pipeline decodes a gamma intensity (1.5^2.2); the scriptable ones do not.
    let gamma = 1.5f32.powf(2.2);
    let cases = [
        (None, Attenuation::BuiltIn, gamma),
        (
            Some("com.unity.render-pipelines.universal"),
            Attenuation::Universal,
            1.5,
        ),
        (
            Some("com.unity.render-pipelines.lightweight"),
            Attenuation::Universal,
            1.5,
        ),
        // HDRP's lamps are in lumen: mapped to the built-in scale (÷1000), as before.
        (
            Some("com.unity.render-pipelines.high-definition"),
            Attenuation::BuiltIn,
            0.0015,
        ),
        // A package whose name only begins like URP's is not URP.
        (
            Some("com.unity.render-pipelines.universal-config"),
            Attenuation::BuiltIn,
            gamma,
        ),
    ];
    for (package, attenuation, intensity) in cases {
        let text = package.map(manifest).unwrap_or_default();
        let mut files = vec![("Assets/s.unity", sc.text.as_str())];
        if package.is_some() {
            files.push(("Packages/manifest.json", text.as_str()));
        }
        let (_d, root) = project(&files);
        let soup = convert(&root.join("Assets/s.unity"));
        assert_eq!(soup.lights.len(), 2);
        for l in &soup.lights {
            assert_eq!(
                (l.attenuation, l.intensity),
                (attenuation, intensity),
                "{package:?}: {}",
                l.name
            );
        }
    }
}

#[test]
fn lights_combine_colour_and_intensity_as_the_projects_graphics_settings_say() {
    let mut sc = Scene::default();
    sc.light(&Tf::at(0.0, 5.0, 0.0), 2, [1.0, 0.5, 0.25], 1);
    sc.raw("  m_ColorTemperature: 5000\n  m_UseColorTemperature: 1\n");
    let urp = "{\"dependencies\": {\"com.unity.render-pipelines.universal\": \"14.0.9\"}}";
    let linear = Vec3::new(1.0, 0.21404114, 0.05087609) * 1.5;
    // Unity's fit at 5,000 K.
    let warm = Vec3::new(1.0, 0.77996, 0.61952);
    let cases: [(&str, Option<String>, Option<&str>, Vec3); 5] = [
        // Unity's defaults: gamma intensity, no temperature.
        (
            "default",
            None,
            None,
            Vec3::new(2.4400615, 0.52252156, 0.11601613),
        ),
        ("linear", Some(graphics_settings(1, 0)), None, linear),
        (
            "linear, temperature",
            Some(graphics_settings(1, 1)),
            None,
            linear * warm,
        ),
        // Temperature needs linear intensity.
        (
            "gamma, temperature",
            Some(graphics_settings(0, 1)),
            None,
            Vec3::new(2.4400615, 0.52252156, 0.11601613),
        ),
        // URP switches both on whatever the file says.
        (
            "URP",
            Some(graphics_settings(0, 0)),
            Some(urp),
            linear * warm,
        ),
    ];
    for (what, settings, manifest, want) in cases {
        let mut files = vec![("Assets/s.unity", sc.text.as_str())];
        if let Some(text) = &settings {
            files.push((GRAPHICS_SETTINGS, text));
        }
        if let Some(text) = manifest {
            files.push(("Packages/manifest.json", text));
        }
        let (_d, root) = project(&files);
        let soup = convert(&root.join("Assets/s.unity"));
        let l = &soup.lights[0];
        let got = l.color * l.intensity;
        assert!(close(got, want, 2e-5), "{what}: {got} against {want}");
        let assumed = soup
            .warnings
            .iter()
            .any(|w| w.contains("GraphicsSettings.asset is missing"));
        assert_eq!(assumed, what == "default", "{what}: {:?}", soup.warnings);
    }
    // Where every intensity is 1 the two conventions agree, and nothing is said.
    let one = sc.text.replace("m_Intensity: 1.5", "m_Intensity: 1");
    let (_d, root) = project(&[("Assets/s.unity", one.as_str())]);
    let soup = convert(&root.join("Assets/s.unity"));
    assert_eq!(soup.lights[0].intensity, 1.0);
    assert!(
        !soup.warnings.iter().any(|w| w.contains("GraphicsSettings")),
        "{:?}",
        soup.warnings
    );
}

#[test]
fn a_pipeline_package_without_an_assigned_asset_draws_built_in() {
    let mut sc = Scene::default();
    sc.light(&Tf::at(0.0, 5.0, 0.0), 2, [1.0, 1.0, 1.0], 1);
    let urp = "{\"dependencies\": {\"com.unity.render-pipelines.universal\": \"14.0.9\"}}";
    let asset = "{fileID: 11400000, guid: 19ba41d7c0026c3459d37c2fe90c55a0, type: 2}";
    let graphics = |default: &str| {
        format!("{HEADER}--- !u!30 &1\nGraphicsSettings:\n  m_ObjectHideFlags: 0\n  m_CustomRenderPipeline: {default}\n  m_LightsUseLinearIntensity: 0\n")
    };
    let quality = |level: &str| {
        format!("{HEADER}--- !u!47 &1\nQualitySettings:\n  m_CurrentQuality: 0\n  m_QualitySettings:\n  - serializedVersion: 2\n    name: High\n    customRenderPipeline: {level}\n")
    };
    let none = "{fileID: 0}";
    let cases = [
        // Without graphics settings only the manifest tells.
        (None, None, Attenuation::Universal),
        (Some(graphics(asset)), None, Attenuation::Universal),
        (Some(graphics(none)), None, Attenuation::BuiltIn),
        (
            Some(graphics(none)),
            Some(quality(none)),
            Attenuation::BuiltIn,
        ),
        // The current quality level's own asset is enough.
        (
            Some(graphics(none)),
            Some(quality(asset)),
            Attenuation::Universal,
        ),
    ];
    for (graphics, quality, attenuation) in cases {
        let mut files = vec![
            ("Assets/s.unity", sc.text.as_str()),
            ("Packages/manifest.json", urp),
        ];
        files.extend(graphics.as_deref().map(|t| (GRAPHICS_SETTINGS, t)));
        files.extend(
            quality
                .as_deref()
                .map(|t| ("ProjectSettings/QualitySettings.asset", t)),
        );
        let (_d, root) = project(&files);
        let soup = convert(&root.join("Assets/s.unity"));
        let what = format!("{graphics:?} {quality:?}");
        let l = &soup.lights[0];
        assert_eq!(l.attenuation, attenuation, "{what}");
        let built_in = attenuation == Attenuation::BuiltIn;
        // Built-in: the gamma intensity 1.5^2.2 of the graphics settings' default.
        let want = if built_in { 1.5f32.powf(2.2) } else { 1.5 };
        assert!((l.intensity - want).abs() < 1e-5, "{what}: {}", l.intensity);
        let warned = soup.warnings.iter().any(|w| w.contains("lists URP, but"));
        assert_eq!(warned, built_in, "{what}: {:?}", soup.warnings);
    }
}

#[test]
fn a_urp_projects_pipeline_asset_decides_which_lights_cast_shadows() {
    let mut sc = Scene::default();
    sc.light(&Tf::at(0.0, 5.0, 0.0), 1, [1.0, 1.0, 1.0], 2);
    sc.light(&Tf::at(0.0, 6.0, 0.0), 1, [0.5, 0.5, 0.5], 2);
    sc.light(&Tf::at(1.0, 5.0, 0.0), 2, [1.0, 1.0, 1.0], 2);
    let urp = "{\"dependencies\": {\"com.unity.render-pipelines.universal\": \"14.0.9\"}}";
    let guid = "19ba41d7c0026c3459d37c2fe90c55a0";
    let graphics = format!("{HEADER}--- !u!30 &1\nGraphicsSettings:\n  m_CustomRenderPipeline: {{fileID: 11400000, guid: {guid}, type: 2}}\n");
    let meta = format!("fileFormatVersion: 2\nguid: {guid}\n");
    let asset = |lights: i32, shadows: i32, soft: i32| {
        format!("{HEADER}--- !u!114 &11400000\nMonoBehaviour:\n  m_Name: URP\n  m_AdditionalLightsRenderingMode: {lights}\n  m_MainLightShadowsSupported: 1\n  m_AdditionalLightShadowsSupported: {shadows}\n  m_SoftShadowsSupported: {soft}\n")
    };
    let (s, h, n) = (Shadows::Soft, Shadows::Hard, Shadows::None);
    let cases: [(Option<String>, &[Shadows], &str); 4] = [
        // Without the asset only the main light rule holds: the second sun (equal
        // intensity, later) casts none.
        (None, &[s, n, s], "URP; "),
        (Some(asset(1, 1, 1)), &[s, n, s], "on, on, on"),
        (Some(asset(1, 0, 0)), &[h, n, n], "on, off, off"),
        // Without additional lights only the main light is left.
        (Some(asset(0, 1, 1)), &[s], "off, on, on"),
    ];
    for (asset, want, read) in cases {
        let mut files = vec![
            ("Assets/s.unity", sc.text.as_str()),
            ("Packages/manifest.json", urp),
            (GRAPHICS_SETTINGS, graphics.as_str()),
        ];
        if let Some(text) = &asset {
            files.push(("Assets/Settings/URP.asset", text));
            files.push(("Assets/Settings/URP.asset.meta", &meta));
        }
        let (_d, root) = project(&files);
        let opts = unity::Options::default();
        let r = unity::convert_report(&root.join("Assets/s.unity"), &opts).unwrap();
        let got: Vec<Shadows> = r.soup.lights.iter().map(|l| l.shadows).collect();
        assert_eq!(got, want, "{asset:?}");
        assert_warned(&r.soup, "URP draws shadows for its main light alone");
        let dropped = r
            .soup
            .warnings
            .iter()
            .any(|w| w.contains("2 light(s) not drawn"));
        assert_eq!(dropped, want.len() == 1, "{:?}", r.soup.warnings);
        // `--list`'s summary names the asset and what it lets lights do.
        let read = match &asset {
            None => read.to_string(),
            Some(_) => {
                let f: Vec<&str> = read.split(", ").collect();
                format!("URP (asset Assets/Settings/URP.asset: main light on, additional lights {}, main-light shadows on, additional-light shadows {}, soft shadows {}, shadow distance 50 m (border 0.2)); ", f[0], f[1], f[2])
            }
        };
        assert!(r.settings.starts_with(&read), "{}", r.settings);
        // Shadows end where the asset's class default puts them: 50 m, faded over 0.2.
        let reach = asset.as_ref().map(|_| formats::ShadowDistance {
            distance: 50.0,
            border: 0.2,
        });
        assert_eq!(r.soup.environment.shadow_distance, reach);
    }
}

#[test]
fn a_urp_assets_shadow_distance_reaches_the_soup_or_turns_shadows_off() {
    let mut sc = Scene::default();
    sc.camera(&Tf::at(0.0, 1.0, -10.0));
    sc.light(&Tf::at(0.0, 5.0, 0.0), 1, [1.0, 1.0, 1.0], 2);
    let urp = "{\"dependencies\": {\"com.unity.render-pipelines.universal\": \"14.0.9\"}}";
    let guid = "19ba41d7c0026c3459d37c2fe90c55a0";
    let graphics = format!("{HEADER}--- !u!30 &1\nGraphicsSettings:\n  m_CustomRenderPipeline: {{fileID: 11400000, guid: {guid}, type: 2}}\n");
    let meta = format!("fileFormatVersion: 2\nguid: {guid}\n");
    let asset = |distance: &str| {
        format!("{HEADER}--- !u!114 &11400000\nMonoBehaviour:\n  m_Name: URP\n  m_MainLightShadowsSupported: 1\n  m_ShadowDistance: {distance}\n  m_CascadeBorder: 0.1\n")
    };
    let convert = |distance: &str| {
        let text = asset(distance);
        let (_d, root) = project(&[
            ("Assets/s.unity", sc.text.as_str()),
            ("Packages/manifest.json", urp),
            (GRAPHICS_SETTINGS, graphics.as_str()),
            ("Assets/Settings/URP.asset", text.as_str()),
            ("Assets/Settings/URP.asset.meta", meta.as_str()),
        ]);
        convert(&root.join("Assets/s.unity"))
    };
    let soup = convert("42");
    assert_eq!(
        soup.environment.shadow_distance,
        Some(formats::ShadowDistance {
            distance: 42.0,
            border: 0.1
        })
    );
    // (Soft shadows are off by the asset's class default: drawn hard.)
    assert_eq!(soup.lights[0].shadows, Shadows::Hard);
    // A distance nearer than the camera's near plane (0.3 m) leaves URP drawing no shadow.
    let soup = convert("0.2");
    assert_eq!(soup.environment.shadow_distance, None);
    assert_eq!(soup.lights[0].shadows, Shadows::None);
    assert_warned(
        &soup,
        "shadow distance (0.2 m) is nearer than the camera's near plane (0.3 m)",
    );
}

#[test]
fn the_current_quality_level_limits_a_built_in_projects_shadows() {
    let mut sc = Scene::default();
    sc.light(&Tf::at(0.0, 5.0, 0.0), 2, [1.0, 1.0, 1.0], 2);
    sc.light(&Tf::at(1.0, 5.0, 0.0), 2, [1.0, 1.0, 1.0], 1);
    let quality = |shadows: i32| {
        format!("{HEADER}--- !u!47 &1\nQualitySettings:\n  m_ObjectHideFlags: 0\n  serializedVersion: 5\n  m_CurrentQuality: 1\n  m_QualitySettings:\n  - serializedVersion: 2\n    name: Low\n    shadows: 0\n  - serializedVersion: 2\n    name: High\n    shadows: {shadows}\n    lodBias: 1\n")
    };
    let urp = "{\"dependencies\": {\"com.unity.render-pipelines.universal\": \"14.0.9\"}}";
    let cases = [
        (2, None, [Shadows::Soft, Shadows::Hard], false),
        (1, None, [Shadows::Hard, Shadows::Hard], true),
        (0, None, [Shadows::None, Shadows::None], true),
        // URP's shadows are its pipeline asset's: the quality level's are not read.
        (0, Some(urp), [Shadows::Soft, Shadows::Hard], false),
    ];
    for (level, manifest, want, said) in cases {
        let text = quality(level);
        let mut files = vec![
            ("Assets/s.unity", sc.text.as_str()),
            ("ProjectSettings/QualitySettings.asset", text.as_str()),
        ];
        files.extend(manifest.map(|m| ("Packages/manifest.json", m)));
        let (_d, root) = project(&files);
        let soup = convert(&root.join("Assets/s.unity"));
        let got: Vec<Shadows> = soup.lights.iter().map(|l| l.shadows).collect();
        assert_eq!(got, want, "shadows {level}, {manifest:?}");
        let told = soup
            .warnings
            .iter()
            .any(|w| w.contains("QualitySettings.asset"));
        assert_eq!(told, said, "shadows {level}: {:?}", soup.warnings);
    }
}

/// A bundled project copied to a temporary folder, with `ProjectSettings.asset` setting
/// colour space `space` (0 Gamma, 1 Linear).
fn bundled_in_colour_space(name: &str, space: i32) -> tempfile::TempDir {
    let d = tempfile::tempdir().unwrap();
    let from = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenes")
        .join(name);
    copy_dir(&from, d.path());
    let player = format!("{HEADER}--- !u!129 &1\nPlayerSettings:\n  m_ObjectHideFlags: 0\n  serializedVersion: 26\n  productName: p\n  m_ActiveColorSpace: {space}\n");
    std::fs::write(
        d.path().join("ProjectSettings/ProjectSettings.asset"),
        player,
    )
    .unwrap();
    d
}

/// A gamma-space project's shaders take colours, lights and texels as Unity stores them:
/// the soup keeps them so and says so, and the renderer decodes the frame.
#[test]
fn a_gamma_colour_space_project_keeps_colours_and_texels_as_stored() {
    let convert_in = |name: &str, scene: &str, space: i32| {
        let d = bundled_in_colour_space(name, space);
        let soup = convert(&d.path().join("Assets/Scenes").join(scene));
        assert!(soup.warnings.is_empty(), "{:?}", soup.warnings);
        soup
    };
    let linear = convert_in("emission", "Emission.unity", 1);
    let gamma = convert_in("emission", "Emission.unity", 0);
    assert_eq!(linear.environment.color_space, formats::ColorSpace::Linear);
    assert_eq!(gamma.environment.color_space, formats::ColorSpace::Gamma);
    let cyan = |soup: &formats::Soup| {
        let m = soup
            .materials
            .iter()
            .find(|m| m.name == "GlowCyan")
            .unwrap();
        (m.color, m.emission)
    };
    // GlowCyan.mat stores _Color and _EmissionColor (0.1, 0.8, 1).
    let stored = Vec3::new(0.1, 0.8, 1.0);
    assert!(close(cyan(&gamma).0, stored, 1e-6) && close(cyan(&gamma).1, stored, 1e-6));
    assert!(close(
        cyan(&linear).0,
        Vec3::new(0.010022826, 0.6038273, 1.0),
        1e-6
    ));
    // The scene's white light of intensity 0.3, as stored; the linear project's bundled
    // settings ask for linear units (the same here: white).
    let l = &gamma.lights[0];
    assert!(
        close(l.color * l.intensity, Vec3::splat(0.3), 1e-6),
        "{}",
        l.color
    );
    let d = bundled_in_colour_space("emission", 0);
    let opts = unity::Options::default();
    let r = unity::convert_report(&d.path().join("Assets/Scenes/Emission.unity"), &opts).unwrap();
    let said =
        "light intensity as stored (gamma space), colour temperature off; colour space Gamma";
    assert!(r.settings.contains(said), "{}", r.settings);
    // An image sky: `_Tint` 0.5 and `_Exposure` 1 as stored, times a gamma-space
    // project's `unity_ColorSpaceDouble`, 2 (a linear one's 0.2140 × 4.5948 × 1).
    let scale = |space: i32| {
        let d = bundled_in_colour_space("skybox", space);
        match convert(&d.path().join("Assets/Scenes/Skybox.unity"))
            .environment
            .sky
        {
            Some(formats::Sky::Textured(t)) => t.scale,
            other => panic!("{other:?}"),
        }
    };
    assert!(close(scale(0), Vec3::splat(1.0), 1e-6), "{}", scale(0));
    assert!(
        close(scale(1), Vec3::splat(0.21404114 * 4.594794), 1e-5),
        "{}",
        scale(1)
    );
    // Texels are sampled as stored: the grey texture's bytes, no longer sRGB.
    let textures = bundled_in_colour_space("textures", 0);
    let grey = convert(&textures.path().join("Assets/Scenes/Grey.unity"));
    let t = &grey.textures[0];
    assert!(!t.srgb && t.texels.chunks(4).all(|c| c == [128, 128, 128, 255]));
    assert!((t.texel(2, 3)[0] - 128.0 / 255.0).abs() < 1e-6);
}

const TWO_GROUPS: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 5 0 0\nv 6 0 0\nv 5 1 0\nmtllib two.mtl\ng A\nusemtl red\nf 1 2 3\ng B\nusemtl green\nf 4 5 6\n";
const TWO_MTL: &str = "newmtl red\nKd 1 0 0\nnewmtl green\nKd 0 1 0\n";

/// Convert `scene_text` in a project holding two.obj, its `.mtl`, and a legacy `.meta`
/// naming the groups A and B.
fn convert_beside_two_groups(scene_text: &str) -> formats::Soup {
    let (_d, root) = project(&[
        ("Assets/two.obj", TWO_GROUPS),
        ("Assets/two.mtl", TWO_MTL),
        ("Assets/two.obj.meta", &legacy_meta(OBJ_GUID, &["A", "B"])),
        ("Assets/s.unity", scene_text),
    ]);
    convert(&root.join("Assets/s.unity"))
}

#[test]
fn legacy_table_resolves_sub_meshes_by_name() {
    // 4300002 is `B` in the table (4300000 is `A`).
    let sc = mesh_scene(
        "B",
        4300002,
        OBJ_GUID,
        &[(2100000, "ffffffffffffffffffffffffffffffff")],
    );
    let soup = convert_beside_two_groups(&sc.text);
    assert_eq!(soup.triangles.len(), 1);
    assert_eq!(soup.corners(0)[0], Vec3::new(5.0, 0.0, 0.0));
    assert_eq!(soup.objects[0].source, "Assets/two.obj#B");
    // The material GUID is unknown: Unity's default, with a warning that names it.
    assert_eq!(soup.materials[0].name, "Default-Material");
    assert!(soup
        .warnings
        .iter()
        .any(|w| w.contains("ffffffffffffffffffffffffffffffff")));
}

fn gen2_meta(guid: &str) -> String {
    format!("fileFormatVersion: 2\nguid: {guid}\nModelImporter:\n  serializedVersion: 22200\n  internalIDToNameTable: []\n  meshes:\n    globalScale: 1\n    fileIdsGeneration: 2\n")
}

#[test]
fn file_ids_generation_2_resolves_hashed_ids() {
    let mut sc = mesh_scene(
        "B",
        unity::meta::hash_id("Type:Mesh->B0"),
        OBJ_GUID,
        &[DEFAULT_MAT],
    );
    // A renderer without material slots draws nothing.
    let (go2, _) = sc.object("NoSlots", &Tf::at(0.0, 0.0, 0.0), 0, true);
    sc.mesh(
        go2,
        unity::meta::hash_id("Type:Mesh->A0"),
        OBJ_GUID,
        &[],
        true,
    );
    let (_d, root) = project(&[
        ("Assets/two.obj", TWO_GROUPS),
        ("Assets/two.obj.meta", &gen2_meta(OBJ_GUID)),
        ("Assets/s.unity", &sc.text),
    ]);
    let soup = convert(&root.join("Assets/s.unity"));
    assert_eq!(soup.objects.len(), 1);
    assert_eq!(soup.objects[0].source, "Assets/two.obj#B");
    assert_eq!(soup.triangles.len(), 1);
    assert_eq!(soup.corners(0)[0], Vec3::new(5.0, 0.0, 0.0));
    assert!(soup
        .warnings
        .iter()
        .any(|w| w.contains("'NoSlots'") && w.contains("no material slot")));
}

#[test]
fn prefab_instance_of_an_obj_model_applies_modifications() {
    // A 2018.3+ PrefabInstance of two.obj (fileIdsGeneration 2): the root Transform is
    // moved to (10, 0, 0) and group B's renderer is switched off, group A's material
    // overridden by a .mat; a scene Cube is parented under the instance's stripped root.
    let h = |s: &str| unity::meta::hash_id(s);
    let root_tf = h("Type:Transform->//RootNode/root/Transform0");
    let b_mr = h("Type:MeshRenderer->//RootNode/root/B/MeshRenderer0");
    let a_mr = h("Type:MeshRenderer->//RootNode/root/A/MeshRenderer0");
    let g = OBJ_GUID;
    let mat_guid = "0123456789abcdef0123456789abcdef";
    let mut sc = Scene::default();
    sc.raw(&format!(
        "--- !u!1001 &500\nPrefabInstance:\n  m_ObjectHideFlags: 0\n  serializedVersion: 2\n  m_Modification:\n    m_TransformParent: {{fileID: 0}}\n    m_Modifications:\n    - target: {{fileID: {root_tf}, guid: {g}, type: 3}}\n      propertyPath: m_LocalPosition.x\n      value: 10\n      objectReference: {{fileID: 0}}\n    - target: {{fileID: {b_mr}, guid: {g}, type: 3}}\n      propertyPath: m_Enabled\n      value: 0\n      objectReference: {{fileID: 0}}\n    - target: {{fileID: {a_mr}, guid: {g}, type: 3}}\n      propertyPath: m_Materials.Array.data[0]\n      value: \n      objectReference: {{fileID: 2100000, guid: {mat_guid},\n        type: 2}}\n    m_RemovedComponents: []\n  m_SourcePrefab: {{fileID: 100100000, guid: {g}, type: 3}}\n--- !u!4 &501 stripped\nTransform:\n  m_CorrespondingSourceObject: {{fileID: {root_tf}, guid: {g}, type: 3}}\n  m_PrefabInstance: {{fileID: 500}}\n  m_PrefabAsset: {{fileID: 0}}\n"
    ));
    sc.primitive("Child", &Tf::at(0.0, 3.0, 0.0), 501, CUBE);
    let mat = "%YAML 1.1\n%TAG !u! tag:unity3d.com,2011:\n--- !u!21 &2100000\nMaterial:\n  serializedVersion: 6\n  m_Name: Blue\n  m_Shader: {fileID: 46, guid: 0000000000000000f000000000000000, type: 0}\n  m_ShaderKeywords: \n  m_SavedProperties:\n    serializedVersion: 3\n    m_Floats:\n    - _Metallic: 0\n    - _Glossiness: 0.9\n    m_Colors:\n    - _Color: {r: 0, g: 0, b: 1, a: 1}\n";
    let (_d, root) = project(&[
        ("Assets/two.obj", TWO_GROUPS),
        ("Assets/two.mtl", TWO_MTL),
        ("Assets/two.obj.meta", &gen2_meta(g)),
        ("Assets/Blue.mat", mat),
        (
            "Assets/Blue.mat.meta",
            &format!("fileFormatVersion: 2\nguid: {mat_guid}\n"),
        ),
        ("Assets/s.unity", &sc.text),
    ]);
    let soup = convert(&root.join("Assets/s.unity"));
    let names: Vec<_> = soup.objects.iter().map(|o| o.name.as_str()).collect();
    assert_eq!(names, ["two/A", "two/Child"]);
    // Group A's triangle (0,0,0),(1,0,0),(0,1,0) moved by Unity +10 in x → soup −10.
    let t = soup.corners(0);
    assert!(
        close(t[0], Vec3::new(-10.0, 0.0, 0.0), 1e-6)
            && close(t[1], Vec3::new(-9.0, 0.0, 0.0), 1e-6),
        "{t:?}"
    );
    assert_eq!(soup.materials[soup.tri_material[0] as usize].name, "Blue");
    assert_eq!(soup.materials[soup.tri_material[0] as usize].color, Vec3::Z);
    // The Cube under the stripped root: Unity (10, 3, 0) → soup (−10, 3, 0).
    let cube: Vec3 = soup.triangle_positions()[1..]
        .iter()
        .flatten()
        .copied()
        .sum::<Vec3>()
        / (12.0 * 3.0);
    assert!(close(cube, Vec3::new(-10.0, 3.0, 0.0), 1e-5), "{cube}");
}

#[test]
fn model_materials_take_the_mtl_colour() {
    // A legacy MeshFilter on group A; its renderer uses the model's internal material.
    let mat_id = unity::meta::hash_id("Type:Material->red0");
    let sc = mesh_scene("A", 4300000, OBJ_GUID, &[(mat_id, OBJ_GUID)]);
    let soup = convert_beside_two_groups(&sc.text);
    assert_eq!(soup.materials.len(), 1);
    assert_eq!(soup.materials[0].color, Vec3::X);
    assert_eq!(soup.materials[0].source, "Assets/two.obj#red");
}

#[test]
fn the_pipelines_own_default_materials_are_drawn_as_their_packages_ship_them() {
    // The URP package's Lit.mat lives in the package cache, never under Assets/.
    let lit = (2100000, "31321ba15b8f8eb4c954353edc038b1d");
    let sc = mesh_scene("Cube", 10202, BUILTIN, &[lit]);
    let urp = "{\n  \"dependencies\": {\n    \"com.unity.render-pipelines.universal\": \"12.1.15\"\n  }\n}\n";
    let (_d, root) = project(&[
        ("Assets/s.unity", &sc.text),
        ("Packages/manifest.json", urp),
    ]);
    let soup = convert(&root.join("Assets/s.unity"));
    assert!(
        !soup.warnings.iter().any(|w| w.contains("material")),
        "{:?}",
        soup.warnings
    );
    let m = &soup.materials[0];
    // Its base colour, 0.5 in sRGB, is 0.2140 in linear.
    assert!(close(m.color, Vec3::splat(0.21404114), 1e-6), "{}", m.color);
    assert_eq!(
        (m.smoothness, m.metallic, m.cull),
        (0.5, 0.0, formats::Cull::Back)
    );
    assert_eq!(
        m.source,
        "package:com.unity.render-pipelines.universal/Runtime/Materials/Lit.mat"
    );
    // Without URP the GUID names nothing the project has.
    let soup = convert_scene(&sc.text);
    assert_warned(
        &soup,
        "31321ba15b8f8eb4c954353edc038b1d is not in the project",
    );
    assert_eq!(soup.materials[0].color, Vec3::ONE);
    // HDRP's default material: light grey (0.728 in sRGB), smoothness 0.7; not in URP.
    let hd = (2100000, "73c176f402d2c2f4d929aa5da7585d17");
    let sc = mesh_scene("Cube", 10202, BUILTIN, &[hd]);
    let hdrp = urp.replace("universal", "high-definition");
    let (_h, root) = project(&[
        ("Assets/s.unity", &sc.text),
        ("Packages/manifest.json", &hdrp),
    ]);
    let m = &convert(&root.join("Assets/s.unity")).materials[0];
    let grey = formats::srgb::srgb_to_linear(0.72794116);
    assert!(close(m.color, Vec3::splat(grey), 1e-6), "{}", m.color);
    assert_eq!((m.smoothness, m.metallic), (0.7, 0.0));
    assert!(m.source.ends_with("DefaultHDMaterial.mat"), "{}", m.source);
    let (_u, root) = project(&[
        ("Assets/s.unity", &sc.text),
        ("Packages/manifest.json", urp),
    ]);
    assert_eq!(
        convert(&root.join("Assets/s.unity")).materials[0].color,
        Vec3::ONE
    );
}

/// A MeshFilter whose mesh GUID is not in the project, on an object named after the only
/// model, `Assets/Models/m.obj`.
fn unresolved_mesh_project() -> (tempfile::TempDir, PathBuf) {
    let sc = mesh_scene(
        "m",
        4300000,
        "99999999999999999999999999999999",
        &[DEFAULT_MAT],
    );
    project(&[("Assets/Models/m.obj", OBJ), ("Assets/s.unity", &sc.text)])
}

#[test]
fn the_search_by_name_walks_a_link_loop_once() {
    let (_d, root) = unresolved_mesh_project();
    // Forty links back to Assets/ would make a walk that follows them blindly visit 40^depth
    // folders; followed once each, the model is found as without them.
    for i in 0..40 {
        std::os::unix::fs::symlink(".", root.join(format!("Assets/loop{i}"))).unwrap();
    }
    let soup = convert(&root.join("Assets/s.unity"));
    assert_eq!(soup.triangles.len(), 3);
    assert_eq!(soup.objects[0].source, "Assets/Models/m.obj");
}

#[test]
fn unresolved_mesh_falls_back_to_the_object_name() {
    let (_d, root) = unresolved_mesh_project();
    let soup = convert(&root.join("Assets/s.unity"));
    assert_eq!(soup.triangles.len(), 3);
    assert_warned(&soup, "found by the object's name");
}

#[test]
fn binary_scene_is_refused() {
    let (_d, root) = project(&[("Assets/s.unity", "\0\0\u{2e}K\0\0\u{36}\u{c}\0\0\0\u{f}")]);
    let msg = convert_error(&root.join("Assets/s.unity"));
    assert!(
        msg.contains("binary") && msg.contains("Force Text"),
        "{msg}"
    );
}

#[test]
fn files_that_are_not_unity_scenes_are_refused_by_what_they_are() {
    let (_d, root) = project(&[
        ("Assets/compose.unity", "services:\n  web:\n    image: x\n"),
        ("Assets/plain.unity", "%YAML 1.1\nfoo: bar\n"),
    ]);
    let assets = root.join("Assets");
    for (file, want) in [
        (
            "compose.unity",
            "compose.unity: is not a Unity scene or prefab",
        ),
        ("plain.unity", "plain.unity: holds no Unity objects"),
        ("missing.unity", "missing.unity: No such file or directory"),
        ("", "Assets/: is a folder, not a scene file"),
    ] {
        let msg = convert_error(&assets.join(file));
        assert!(msg.contains(want), "{file}: {msg}");
        assert!(!msg.contains("Force Text"), "{file}: {msg}");
    }
}

#[test]
fn non_finite_transform_is_an_error_naming_the_object() {
    let mut sc = Scene::default();
    sc.primitive("Broken", &Tf::at(f32::NAN, 0.0, 0.0), 0, CUBE);
    let (_d, root) = project(&[("Assets/s.unity", &sc.text)]);
    let err = convert_error(&root.join("Assets/s.unity"));
    assert!(err.contains("'Broken'"), "{err}");
}

#[test]
fn degenerate_triangles_are_dropped_and_counted() {
    let obj = "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 4\nf 1 1 4\n";
    let sc = model_scene("D");
    let (_d, scene) = obj_project("Assets/d.obj", obj, "Assets/s.unity", &sc.text);
    let soup = convert(&scene);
    assert_eq!(soup.triangles.len(), 1);
    assert_eq!(soup.dropped_degenerate, 2);
}

/// An object whose triangles are all degenerate is dropped, and the objects after it are
/// renumbered so that object indices stay dense.
#[test]
fn an_object_of_degenerate_triangles_is_dropped_and_the_next_renumbered() {
    let obj = "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\nf 3 2 1\n";
    let mut sc = model_scene("Flat");
    sc.primitive("Box", &Tf::at(5.0, 0.0, 0.0), 0, CUBE);
    let (_d, scene) = obj_project("Assets/d.obj", obj, "Assets/s.unity", &sc.text);
    let report = unity::convert_report(&scene, &unity::Options::default()).unwrap();
    let soup = &report.soup;
    assert_eq!(soup.dropped_degenerate, 2);
    let names: Vec<&str> = soup.objects.iter().map(|o| o.name.as_str()).collect();
    assert_eq!(names, ["Box"]);
    assert_eq!(report.material_origins.len(), 1);
    assert_eq!(soup.triangles.len(), 12);
    assert!(soup.tri_object.iter().all(|&o| o == 0));
    soup.validate().unwrap();
}

/// UVs follow the positions through the winding flip and the squeezing out of degenerate
/// triangles: each kept corner keeps its own vertex's UV.
#[test]
fn uvs_follow_their_corners_past_dropped_triangles() {
    let obj = "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nvt 0 0\nvt 0.25 0\nvt 0.5 0\nvt 0 1\n\
               f 1/1 2/2 3/3\nf 1/1 1/1 4/4\nf 1/1 2/2 4/4\n";
    let textures = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/textures/Assets");
    let read = |rel: &str| std::fs::read_to_string(textures.join(rel)).unwrap();
    let mat_meta = read("Materials/Quadrants.mat.meta");
    let mat_guid = mat_meta
        .lines()
        .find_map(|l| l.strip_prefix("guid: "))
        .unwrap()
        .to_string();
    let sc = mesh_scene("D", 4300000, OBJ_GUID, &[(2100000, &mat_guid)]);
    let (_d, scene) = obj_project("Assets/d.obj", obj, "Assets/s.unity", &sc.text);
    let assets = scene.parent().unwrap();
    for rel in ["Materials/Quadrants.mat", "Textures/Quadrants.png"] {
        std::fs::create_dir_all(assets.join(rel).parent().unwrap()).unwrap();
        std::fs::copy(textures.join(rel), assets.join(rel)).unwrap();
        let meta = format!("{rel}.meta");
        std::fs::copy(textures.join(&meta), assets.join(&meta)).unwrap();
    }
    let soup = convert(&scene);
    assert_eq!((soup.triangles.len(), soup.dropped_degenerate), (1, 2));
    assert_eq!(soup.uvs.len(), soup.positions.len());
    assert!(soup.materials[0].albedo_map.is_some());
    // The soup keeps the OBJ's x (Unity negates it, the soup negates it back).
    for (p, uv) in soup.corners(0).iter().zip(soup.corner_uvs(0)) {
        let want = match (p.x, p.y) {
            (0.0, 0.0) => glam::Vec2::new(0.0, 0.0),
            (1.0, 0.0) => glam::Vec2::new(0.25, 0.0),
            (0.0, 1.0) => glam::Vec2::new(0.0, 1.0),
            _ => panic!("unexpected corner {p}"),
        };
        assert_eq!(uv, want, "corner {p}");
    }
}

#[test]
fn strict_turns_warnings_into_an_error() {
    let mut sc = Scene::default();
    sc.primitive("C", &Tf::at(0.0, 0.0, 0.0), 0, CUBE);
    let (_d, root) = project(&[("Assets/s.unity", &sc.text)]);
    let opts = unity::Options {
        project: None,
        strict: true,
        camera: None,
    };
    let err = unity::convert(&root.join("Assets/s.unity"), &opts).unwrap_err();
    assert!(err.to_string().contains("no enabled camera"), "{err}");
}

#[test]
fn nested_prefabs_apply_overrides_outermost_last() {
    // Base.prefab: root "Base" (Transform 400) with a child "Box" (GameObject 101,
    // Transform 401, built-in Cube at (1, 0, 0)).
    let base_guid = "b0000000000000000000000000000001";
    let outer_guid = "b0000000000000000000000000000002";
    let mut base = Scene::default();
    base.raw("--- !u!1 &100\nGameObject:\n  m_Name: Base\n  m_IsActive: 1\n--- !u!4 &400\nTransform:\n  m_GameObject: {fileID: 100}\n  m_LocalRotation: {x: 0, y: 0, z: 0, w: 1}\n  m_LocalPosition: {x: 0, y: 0, z: 0}\n  m_LocalScale: {x: 1, y: 1, z: 1}\n  m_Father: {fileID: 0}\n--- !u!1 &101\nGameObject:\n  m_Name: Box\n  m_IsActive: 1\n--- !u!4 &401\nTransform:\n  m_GameObject: {fileID: 101}\n  m_LocalRotation: {x: 0, y: 0, z: 0, w: 1}\n  m_LocalPosition: {x: 1, y: 0, z: 0}\n  m_LocalScale: {x: 1, y: 1, z: 1}\n  m_Father: {fileID: 400}\n");
    base.mesh(101, CUBE, BUILTIN, &[DEFAULT_MAT], true);
    // Outer.prefab: root "Outer" (Transform 410) holding an instance 900 of Base that
    // moves Box to x = 2 (the stripped 920 stands for Base's root, parented under 410).
    let mut outer = Scene::default();
    outer.raw(&format!("--- !u!1 &110\nGameObject:\n  m_Name: Outer\n  m_IsActive: 1\n--- !u!4 &410\nTransform:\n  m_GameObject: {{fileID: 110}}\n  m_LocalRotation: {{x: 0, y: 0, z: 0, w: 1}}\n  m_LocalPosition: {{x: 0, y: 0, z: 0}}\n  m_LocalScale: {{x: 1, y: 1, z: 1}}\n  m_Father: {{fileID: 0}}\n--- !u!1001 &900\nPrefabInstance:\n  m_Modification:\n    m_TransformParent: {{fileID: 410}}\n    m_Modifications:\n    - target: {{fileID: 401, guid: {base_guid}, type: 3}}\n      propertyPath: m_LocalPosition.x\n      value: 2\n      objectReference: {{fileID: 0}}\n    - target: {{fileID: 401, guid: {base_guid}, type: 3}}\n      propertyPath: m_LocalPosition.y\n      value: 1\n      objectReference: {{fileID: 0}}\n  m_SourcePrefab: {{fileID: 100100000, guid: {base_guid}, type: 3}}\n"));
    // Scene: instance 500 of Outer at x = 10; it also overrides the nested Box's y through
    // Unity's combined id (900 ^ 401) & i64::MAX — the outermost override wins.
    let nested_box = (900i64 ^ 401) & i64::MAX;
    let mut sc = Scene::default();
    sc.raw(&format!("--- !u!1001 &500\nPrefabInstance:\n  m_Modification:\n    m_TransformParent: {{fileID: 0}}\n    m_Modifications:\n    - target: {{fileID: 410, guid: {outer_guid}, type: 3}}\n      propertyPath: m_LocalPosition.x\n      value: 10\n      objectReference: {{fileID: 0}}\n    - target: {{fileID: {nested_box}, guid: {outer_guid}, type: 3}}\n      propertyPath: m_LocalPosition.y\n      value: 5\n      objectReference: {{fileID: 0}}\n  m_SourcePrefab: {{fileID: 100100000, guid: {outer_guid}, type: 3}}\n"));
    let (_d, root) = project(&[
        ("Assets/Base.prefab", &base.text),
        (
            "Assets/Base.prefab.meta",
            &format!("fileFormatVersion: 2\nguid: {base_guid}\n"),
        ),
        ("Assets/Outer.prefab", &outer.text),
        (
            "Assets/Outer.prefab.meta",
            &format!("fileFormatVersion: 2\nguid: {outer_guid}\n"),
        ),
        ("Assets/s.unity", &sc.text),
    ]);
    let soup = convert(&root.join("Assets/s.unity"));
    assert_eq!(soup.objects.len(), 1);
    assert_eq!(soup.objects[0].name, "Outer/Base/Box");
    // Box: (2, 5, 0) under Outer at (10, 0, 0) → Unity (12, 5, 0) → soup (−12, 5, 0).
    let c = corner_mean(&soup);
    assert!(close(c, Vec3::new(-12.0, 5.0, 0.0), 1e-5), "{c}");
}

#[test]
fn children_of_a_missing_prefab_keep_its_placement() {
    // An instance of an FBX that is not in the project (guid unknown), moved to x = 4 and
    // scaled ×2 by its modifications; a scene Cube at local (1, 0, 0) under its stripped
    // root Transform lands at Unity (4 + 2, 0, 0) → soup (−6, 0, 0), size 2.
    let g = "fbx00000000000000000000000000000";
    let mut sc = Scene::default();
    sc.raw(&format!("--- !u!1001 &700\nPrefab:\n  m_Modification:\n    m_TransformParent: {{fileID: 0}}\n    m_Modifications:\n    - target: {{fileID: 400000, guid: {g}, type: 3}}\n      propertyPath: m_LocalPosition.x\n      value: 4\n      objectReference: {{fileID: 0}}\n    - target: {{fileID: 400000, guid: {g}, type: 3}}\n      propertyPath: m_LocalScale.x\n      value: 2\n      objectReference: {{fileID: 0}}\n    - target: {{fileID: 400000, guid: {g}, type: 3}}\n      propertyPath: m_LocalScale.y\n      value: 2\n      objectReference: {{fileID: 0}}\n    - target: {{fileID: 400000, guid: {g}, type: 3}}\n      propertyPath: m_LocalScale.z\n      value: 2\n      objectReference: {{fileID: 0}}\n  m_ParentPrefab: {{fileID: 100100000, guid: {g}, type: 3}}\n  m_IsPrefabParent: 0\n--- !u!4 &701 stripped\nTransform:\n  m_PrefabParentObject: {{fileID: 400000, guid: {g}, type: 3}}\n  m_PrefabInternal: {{fileID: 700}}\n"));
    sc.primitive("Child", &Tf::at(1.0, 0.0, 0.0), 701, CUBE);
    let soup = convert_scene(&sc.text);
    let (lo, hi) = bounds(soup.triangle_positions().iter().flatten().copied());
    assert!(
        close(lo, Vec3::new(-7.0, -1.0, -1.0), 1e-5) && close(hi, Vec3::new(-5.0, 1.0, 1.0), 1e-5),
        "{lo} {hi}"
    );
    assert!(soup
        .warnings
        .iter()
        .any(|w| w.contains("prefab instance") && w.contains("not in the project")));
}

#[test]
fn non_finite_obj_vertex_is_an_error_naming_the_object() {
    let obj = "v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n";
    let sc = model_scene("Bad Mesh");
    let (_d, scene) = obj_project("Assets/n.obj", obj, "Assets/s.unity", &sc.text);
    let msg = convert_error(&scene);
    assert!(msg.contains("'Bad Mesh'") && msg.contains("NaN"), "{msg}");
}

#[test]
fn unity5_forms_recttransform_hex_floats_and_model_scale() {
    // Unity 5 writes component lists as `- <class>: {fileID}`; a RectTransform is a
    // Transform; `0x40400000(3)` is 3.0 by its bits (the decimal is only a hint, here
    // deliberately wrong). The model's .meta has globalScale 0.5.
    let text = format!("{HEADER}--- !u!1 &1\nGameObject:\n  m_ObjectHideFlags: 0\n  m_PrefabParentObject: {{fileID: 0}}\n  m_PrefabInternal: {{fileID: 0}}\n  serializedVersion: 4\n  m_Component:\n  - 224: {{fileID: 2}}\n  - 33: {{fileID: 3}}\n  - 23: {{fileID: 4}}\n  m_Name: Old\n  m_IsActive: 1\n--- !u!224 &2\nRectTransform:\n  m_GameObject: {{fileID: 1}}\n  m_LocalRotation: {{x: 0, y: 0, z: 0, w: 1}}\n  m_LocalPosition: {{x: 0x40400000(9), y: 0, z: 0}}\n  m_LocalScale: {{x: 1, y: 1, z: 1}}\n  m_Children: []\n  m_Father: {{fileID: 0}}\n  m_AnchorMin: {{x: 0, y: 0}}\n--- !u!33 &3\nMeshFilter:\n  m_GameObject: {{fileID: 1}}\n  m_Mesh: {{fileID: 4300000, guid: {OBJ_GUID}, type: 3}}\n--- !u!23 &4\nMeshRenderer:\n  m_GameObject: {{fileID: 1}}\n  m_Enabled: 1\n  m_Materials:\n  - {{fileID: 10303, guid: 0000000000000000f000000000000000, type: 0}}\n");
    let meta = legacy_meta(OBJ_GUID, &["default"]).replace("globalScale: 1", "globalScale: 0.5");
    let (_d, root) = project(&[
        ("Assets/m.obj", OBJ),
        ("Assets/m.obj.meta", &meta),
        ("Assets/s.unity", &text),
    ]);
    let soup = convert(&root.join("Assets/s.unity"));
    assert_eq!(soup.objects[0].name, "Old");
    // File vertex (1, 2, 3) → scaled 0.5 → Unity (−0.5, 1, 1.5) + (3, 0, 0) → soup (−2.5, 1, 1.5).
    assert!(
        close(soup.corners(0)[0], Vec3::new(-2.5, 1.0, 1.5), 1e-6),
        "{}",
        soup.corners(0)[0]
    );
}

#[test]
fn removed_components_and_game_objects_draw_nothing() {
    // Instance of two.obj (fileIdsGeneration 2) that removes group A's MeshRenderer and
    // group B's GameObject: nothing of the model is drawn.
    let h = |s: &str| unity::meta::hash_id(s);
    let a_mr = h("Type:MeshRenderer->//RootNode/root/A/MeshRenderer0");
    let b_go = h("Type:GameObject->//RootNode/root/B0");
    let g = OBJ_GUID;
    let mut sc = Scene::default();
    sc.raw(&format!("--- !u!1001 &500\nPrefabInstance:\n  m_Modification:\n    serializedVersion: 3\n    m_TransformParent: {{fileID: 0}}\n    m_Modifications: []\n    m_RemovedComponents:\n    - {{fileID: {a_mr}, guid: {g}, type: 3}}\n    m_RemovedGameObjects:\n    - {{fileID: {b_go}, guid: {g}, type: 3}}\n    m_AddedGameObjects: []\n    m_AddedComponents: []\n  m_SourcePrefab: {{fileID: 100100000, guid: {g}, type: 3}}\n"));
    sc.primitive("Other", &Tf::at(0.0, 0.0, 0.0), 0, CUBE);
    let (_d, root) = project(&[
        ("Assets/two.obj", TWO_GROUPS),
        ("Assets/two.mtl", TWO_MTL),
        ("Assets/two.obj.meta", &gen2_meta(g)),
        ("Assets/s.unity", &sc.text),
    ]);
    let soup = convert(&root.join("Assets/s.unity"));
    let names: Vec<_> = soup.objects.iter().map(|o| o.name.as_str()).collect();
    assert_eq!(names, ["Other"]);
}

#[test]
fn project_root_is_found_or_given() {
    let sc = model_scene("Model");
    let (d, scene) = obj_project(
        "Assets/Deep/m.obj",
        OBJ,
        "Assets/Scenes/Sub/s.unity",
        &sc.text,
    );
    let root = d.path().to_path_buf();
    let found = convert(&scene);
    assert_eq!(found.triangles.len(), 3);
    for given in [root.clone(), root.join("Assets")] {
        let opts = unity::Options {
            project: Some(given),
            strict: false,
            camera: None,
        };
        assert_eq!(
            unity::convert(&scene, &opts).unwrap().triangles,
            found.triangles
        );
    }
    // A scene outside any project.
    let lone = tempfile::tempdir().unwrap();
    std::fs::write(lone.path().join("s.unity"), &sc.text).unwrap();
    let err = convert_error(&lone.path().join("s.unity"));
    assert!(err.contains("--assets"), "{err}");
}

#[test]
fn a_physical_camera_keeps_its_lens_sensor_shift_and_gate_fit() {
    let camera = |fields: &str| {
        let mut sc = Scene::default();
        let (go, _) = sc.object("Cam", &Tf::at(0.0, 1.0, -10.0), 0, true);
        sc.raw(&format!("--- !u!20 &900\nCamera:\n  m_GameObject: {{fileID: {go}}}\n  m_Enabled: 1\n  m_ClearFlags: 2\n  near clip plane: 0.3\n  field of view: 39.6\n  orthographic: 0\n  m_Depth: -1\n{fields}"));
        convert_scene(&sc.text).camera.projection
    };
    let physical = "  m_projectionMatrixMode: 2\n  m_SensorSize: {x: 24.89, y: 18.66}\n  m_LensShift: {x: 0.1, y: -0.05}\n  m_GateFitMode: 3\n  m_FocalLength: 35\n";
    assert_eq!(
        camera(physical),
        formats::Projection::Physical {
            focal_length: 35.0,
            sensor: glam::Vec2::new(24.89, 18.66),
            lens_shift: glam::Vec2::new(0.1, -0.05),
            gate_fit: formats::GateFit::Fill,
        }
    );
    // Fields a file lacks take a new camera's: 50 mm, 36 × 24 mm, no shift, Horizontal.
    assert_eq!(
        camera("  m_projectionMatrixMode: 2\n"),
        formats::Projection::Physical {
            focal_length: 50.0,
            sensor: glam::Vec2::new(36.0, 24.0),
            lens_shift: glam::Vec2::ZERO,
            gate_fit: formats::GateFit::Horizontal,
        }
    );
    // Implicit projection (the default) keeps the field of view; the lens is not read.
    assert_eq!(
        camera(&physical.replace("Mode: 2", "Mode: 1")),
        formats::Projection::Perspective { fov_y: 39.6 }
    );
}

/// A scene with a main camera at z = −10 (depth −1, clear `main_clear`) and a second one at
/// z = −3 (depth 1, clear `over_clear`), each with URP camera data of `m_CameraType`
/// `types` and `m_RenderShadows` `shadows` when given, and a shadowed sun.
fn two_camera_scene(
    (main_clear, over_clear): (i32, i32),
    urp: Option<((i32, i32), i32)>,
) -> String {
    let mut sc = Scene::default();
    sc.light(&Tf::at(0.0, 5.0, 0.0), 1, [1.0, 1.0, 1.0], 1);
    for (i, (z, depth, clear)) in [(-10.0, -1, main_clear), (-3.0, 1, over_clear)]
        .into_iter()
        .enumerate()
    {
        let name = ["Main", "Weapon"][i];
        let (go, _) = sc.object(name, &Tf::at(0.0, 1.0, z), 0, true);
        let id = 900 + 2 * i;
        sc.raw(&format!("--- !u!20 &{id}\nCamera:\n  m_GameObject: {{fileID: {go}}}\n  m_Enabled: 1\n  m_ClearFlags: {clear}\n  near clip plane: 0.3\n  field of view: 60\n  orthographic: 0\n  m_Depth: {depth}\n"));
        if let Some(((main_type, over_type), shadows)) = urp {
            let ty = [main_type, over_type][i];
            sc.raw(&format!("--- !u!114 &{}\nMonoBehaviour:\n  m_GameObject: {{fileID: {go}}}\n  m_Enabled: 1\n  m_Script: {{fileID: 11500000, guid: a79441f348de89743a2939f4d699eac1, type: 3}}\n  m_RenderShadows: {shadows}\n  m_CameraType: {ty}\n", id + 1));
        }
    }
    sc.text
}

#[test]
fn the_view_is_the_highest_camera_that_clears_not_one_drawn_over_it() {
    // Built-in: a depth-only (3) or don't-clear (4) camera draws over the main one.
    for over in [3, 4] {
        let soup = convert_scene(&two_camera_scene((1, over), None));
        assert_eq!(soup.camera.position.z, -10.0, "clear flags {over}");
        assert_warned(&soup, "camera(s) 'Weapon' draw over 'Main'");
    }
    // Below the main camera, a depth-only camera is cleared away: nothing to say.
    let low = two_camera_scene((1, 3), None).replace("m_Depth: 1\n", "m_Depth: -2\n");
    let soup = convert_scene(&low);
    assert_eq!(soup.camera.position.z, -10.0);
    assert!(
        !soup.warnings.iter().any(|w| w.contains("draw over")),
        "{:?}",
        soup.warnings
    );
    // One that clears is the view, as before.
    let soup = convert_scene(&two_camera_scene((1, 2), None));
    assert_eq!(soup.camera.position.z, -3.0);
    assert_warned(&soup, "2 enabled cameras; using 'Weapon'");
    // URP: its camera data's type decides, not the clear flags.
    let urp = "{\"dependencies\": {\"com.unity.render-pipelines.universal\": \"14.0.9\"}}";
    let convert_urp = |text: &str| {
        let (_d, root) = project(&[("Assets/s.unity", text), ("Packages/manifest.json", urp)]);
        convert(&root.join("Assets/s.unity"))
    };
    let soup = convert_urp(&two_camera_scene((1, 1), Some(((0, 1), 1))));
    assert_eq!(soup.camera.position.z, -10.0);
    assert_eq!(soup.lights[0].shadows, Shadows::Hard);
    let soup = convert_urp(&two_camera_scene((1, 3), Some(((0, 0), 1))));
    assert_eq!(
        soup.camera.position.z, -3.0,
        "a URP base camera, whatever its clear flags"
    );
    // The chosen URP camera's Render Shadows off leaves no shadow.
    let soup = convert_urp(&two_camera_scene((1, 1), Some(((0, 1), 0))));
    assert_eq!(soup.lights[0].shadows, Shadows::None);
    assert_warned(&soup, "Render Shadows is off");
}

#[test]
fn an_asked_for_camera_is_the_view_by_name_or_path_overlay_or_not() {
    let text = two_camera_scene((1, 3), None);
    let (_d, root) = project(&[("Assets/s.unity", text.as_str())]);
    let with = |camera: &str| {
        let opts = unity::Options {
            camera: Some(camera.into()),
            ..Default::default()
        };
        unity::convert(&root.join("Assets/s.unity"), &opts)
    };
    // The depth-only camera the Game view draws over the main one, asked for by name.
    let soup = with("Weapon").unwrap();
    assert_eq!(soup.camera.position.z, -3.0);
    assert!(!soup.warnings.iter().any(|w| w.contains("draw over")));
    assert_eq!(with("Main").unwrap().camera.position.z, -10.0);
    let err = with("Drone").unwrap_err().to_string();
    assert!(err.contains("the enabled cameras: Main, Weapon"), "{err}");
}
