//! Unity's draw rules as converted: `_Cull`, `m_CastShadows` / `m_ReceiveShadows`,
//! `m_Layer` with camera and light culling masks, and LODGroup levels.

use crate::support::*;
use formats::{CastShadows, Cull};
use std::fmt::Write;

fn material(body_floats: &str) -> formats::Material {
    let text = format!(
        "Material:\n  m_Name: M\n  m_SavedProperties:\n    m_Floats:\n{body_floats}    m_Colors:\n    - _Color: {{r: 1, g: 1, b: 1, a: 1}}\n"
    );
    let doc = unity::yaml::parse(&text);
    unity::material::convert(doc.get("Material").expect("a Material"), "M.mat").0
}

#[test]
fn cull_reads_the_shaders_float_and_defaults_to_back() {
    assert_eq!(material("    - _Cull: 0\n").cull, Cull::None);
    assert_eq!(material("    - _Cull: 1\n").cull, Cull::Front);
    assert_eq!(material("    - _Cull: 2\n").cull, Cull::Back);
    assert_eq!(material("    - _Glossiness: 0.5\n").cull, Cull::Back);
    assert_eq!(formats::Material::unity_default().cull, Cull::Back);
}

/// A GameObject on `layer` drawing the built-in Quad with Default-Material, its renderer
/// carrying `renderer_extra` lines; ids from `id` up. Returns the renderer's fileID.
fn quad(sc: &mut Scene, id: i64, name: &str, layer: u8, renderer_extra: &str) -> i64 {
    let (go, t, mf, mr) = (id, id + 1, id + 2, id + 3);
    let _ = write!(
        sc.text,
        "--- !u!1 &{go}\nGameObject:\n  m_Component:\n  - component: {{fileID: {t}}}\n  m_Layer: {layer}\n  m_Name: {name}\n  m_IsActive: 1\n--- !u!4 &{t}\nTransform:\n  m_GameObject: {{fileID: {go}}}\n  m_LocalRotation: {{x: 0, y: 0, z: 0, w: 1}}\n  m_LocalPosition: {{x: 0, y: 0, z: 0}}\n  m_LocalScale: {{x: 1, y: 1, z: 1}}\n  m_Children: []\n  m_Father: {{fileID: 0}}\n--- !u!33 &{mf}\nMeshFilter:\n  m_GameObject: {{fileID: {go}}}\n  m_Mesh: {{fileID: {QUAD}, guid: {BUILTIN}, type: 3}}\n--- !u!23 &{mr}\nMeshRenderer:\n  m_GameObject: {{fileID: {go}}}\n  m_Enabled: 1\n{renderer_extra}  m_Materials:\n  - {{fileID: 10303, guid: 0000000000000000f000000000000000, type: 2}}\n"
    );
    mr
}

fn object<'a>(soup: &'a formats::Soup, name: &str) -> Option<&'a formats::Object> {
    soup.objects.iter().find(|o| o.name == name)
}

#[test]
fn renderer_shadow_flags_and_layers_reach_the_soup() {
    let mut sc = Scene::default();
    sc.camera(&Tf::at(0.0, 0.0, -5.0));
    quad(&mut sc, 10, "Plain", 0, "");
    quad(
        &mut sc,
        20,
        "Off",
        3,
        "  m_CastShadows: 0\n  m_ReceiveShadows: 0\n",
    );
    quad(
        &mut sc,
        30,
        "Two",
        4,
        "  m_CastShadows: 2\n  m_ReceiveShadows: 1\n",
    );
    quad(&mut sc, 40, "Only", 31, "  m_CastShadows: 3\n");
    let soup = convert_scene(&sc.text);
    let get = |n| object(&soup, n).unwrap_or_else(|| panic!("{n} converted"));
    let plain = get("Plain");
    assert_eq!(
        (plain.layer, plain.cast_shadows, plain.receive_shadows),
        (0, CastShadows::On, true)
    );
    let off = get("Off");
    assert_eq!(
        (off.layer, off.cast_shadows, off.receive_shadows),
        (3, CastShadows::Off, false)
    );
    assert_eq!(get("Two").cast_shadows, CastShadows::TwoSided);
    assert_eq!(
        (get("Only").layer, get("Only").cast_shadows),
        (31, CastShadows::ShadowsOnly)
    );
}

#[test]
fn a_camera_culling_mask_hides_a_layer_and_the_report_names_it() {
    let mut sc = Scene::default();
    sc.camera(&Tf::at(0.0, 0.0, -5.0));
    // Everything but layer 8.
    sc.raw("  m_CullingMask:\n    serializedVersion: 2\n    m_Bits: 4294967039\n");
    quad(&mut sc, 10, "Seen", 0, "");
    quad(&mut sc, 20, "Hidden", 8, "");
    sc.light(&Tf::at(0.0, 3.0, 0.0), 2, [1.0, 1.0, 1.0], 1);
    sc.raw("  m_CullingMask:\n    serializedVersion: 2\n    m_Bits: 255\n");
    let linear = graphics_settings(1, 1);
    let (_d, root) = project(&[("Assets/s.unity", &sc.text), (GRAPHICS_SETTINGS, &linear)]);
    let r =
        unity::convert_report(&root.join("Assets/s.unity"), &unity::Options::default()).unwrap();
    assert!(object(&r.soup, "Seen").is_some());
    assert!(object(&r.soup, "Hidden").is_none(), "{:?}", r.soup.objects);
    assert_eq!(r.soup.triangles.len(), 2, "only the seen Quad");
    assert_eq!(r.skipped.len(), 1, "{:?}", r.skipped);
    assert!(
        r.skipped[0].contains("\"Hidden\"") && r.skipped[0].contains("layer 8"),
        "{}",
        r.skipped[0]
    );
    assert!(r.soup.warnings.is_empty(), "{:?}", r.soup.warnings);
    assert_eq!(r.soup.lights[0].culling_mask, 255);
}

#[test]
fn a_light_without_a_mask_lights_every_layer() {
    let mut sc = Scene::default();
    sc.camera(&Tf::at(0.0, 0.0, -5.0));
    sc.light(&Tf::at(0.0, 3.0, 0.0), 2, [1.0, 1.0, 1.0], 1);
    let soup = convert_scene(&sc.text);
    assert_eq!(soup.lights[0].culling_mask, u32::MAX);
}

#[test]
fn only_lod0_of_a_lod_group_is_converted() {
    // Size 4 seen from 5 m with a 60° FOV: 2 / (5·tan 30°) = 0.693 ≥ 0.6, so LOD0.
    let mut sc = Scene::default();
    sc.camera(&Tf::at(0.0, 0.0, -5.0));
    let near = quad(&mut sc, 10, "Tree_LOD0", 0, "");
    let far = quad(&mut sc, 20, "Tree_LOD1", 0, "");
    let both = quad(&mut sc, 30, "Trunk", 0, "");
    let (go, _) = sc.object("Tree", &Tf::at(0.0, 0.0, 0.0), 0, true);
    sc.raw(&format!(
        "--- !u!205 &90\nLODGroup:\n  m_GameObject: {{fileID: {go}}}\n  m_Enabled: 1\n  serializedVersion: 2\n  m_LocalReferencePoint: {{x: 0, y: 0, z: 0}}\n  m_Size: 4\n  m_LODs:\n  - screenRelativeHeight: 0.6\n    fadeTransitionWidth: 0\n    renderers:\n    - renderer: {{fileID: {near}}}\n    - renderer: {{fileID: {both}}}\n  - screenRelativeHeight: 0.1\n    fadeTransitionWidth: 0\n    renderers:\n    - renderer: {{fileID: {far}}}\n    - renderer: {{fileID: {both}}}\n"
    ));
    let (_d, root) = project(&[("Assets/s.unity", &sc.text)]);
    let r =
        unity::convert_report(&root.join("Assets/s.unity"), &unity::Options::default()).unwrap();
    assert!(object(&r.soup, "Tree_LOD0").is_some());
    assert!(object(&r.soup, "Trunk").is_some(), "listed in LOD0 too");
    assert!(object(&r.soup, "Tree_LOD1").is_none());
    assert_eq!(r.skipped.len(), 1, "{:?}", r.skipped);
    assert!(
        r.skipped[0].contains("LOD1 of LODGroup \"Tree\""),
        "{}",
        r.skipped[0]
    );
    assert!(
        r.skipped[0].contains("the camera shows LOD0 (relative screen height 0.693)"),
        "{}",
        r.skipped[0]
    );
}

/// How a LODGroup test sees its group: the camera, the group's Transform and its
/// `m_LocalReferencePoint`, and the project's `QualitySettings.asset`.
struct LodView<'a> {
    camera: Tf,
    /// `Some(orthographic size)` for an orthographic camera; else 60° perspective.
    ortho: Option<f32>,
    group: Tf,
    reference: [f32; 3],
    quality: Option<&'a str>,
}

impl LodView<'_> {
    /// A camera `d` metres down −Z from a size-1 group at the origin, 60° FOV.
    fn at(d: f32) -> Self {
        LodView {
            camera: Tf::at(0.0, 0.0, -d),
            ortho: None,
            group: Tf::at(0.0, 0.0, 0.0),
            reference: [0.0; 3],
            quality: None,
        }
    }
}

/// Group "Tree" of size 1 with three levels (thresholds 0.5, 0.2, 0.05): Tree_LOD0,
/// Tree_LOD1 and Tree_LOD2, and Trunk in LOD1 and LOD2, seen as `v` says.
fn lod_report(v: &LodView) -> unity::Report {
    let mut sc = Scene::default();
    let (cam, _) = sc.object("Main Camera", &v.camera, 0, true);
    let (ortho, size) = match v.ortho {
        Some(s) => (1, s),
        None => (0, 5.0),
    };
    sc.raw(&format!(
        "--- !u!20 &900\nCamera:\n  m_GameObject: {{fileID: {cam}}}\n  m_Enabled: 1\n  m_ClearFlags: 2\n  near clip plane: 0.3\n  field of view: 60\n  orthographic: {ortho}\n  orthographic size: {size}\n  m_Depth: -1\n"
    ));
    let l0 = quad(&mut sc, 10, "Tree_LOD0", 0, "");
    let l1 = quad(&mut sc, 20, "Tree_LOD1", 0, "");
    let l2 = quad(&mut sc, 30, "Tree_LOD2", 0, "");
    let trunk = quad(&mut sc, 40, "Trunk", 0, "");
    let (go, _) = sc.object("Tree", &v.group, 0, true);
    let [x, y, z] = v.reference;
    sc.raw(&format!(
        "--- !u!205 &90\nLODGroup:\n  m_GameObject: {{fileID: {go}}}\n  m_Enabled: 1\n  serializedVersion: 2\n  m_LocalReferencePoint: {{x: {x}, y: {y}, z: {z}}}\n  m_Size: 1\n  m_FadeMode: 0\n  m_AnimateCrossFading: 0\n  m_LastLODIsBillboard: 0\n  m_LODs:\n  - screenRelativeHeight: 0.5\n    fadeTransitionWidth: 0\n    renderers:\n    - renderer: {{fileID: {l0}}}\n  - screenRelativeHeight: 0.2\n    fadeTransitionWidth: 0\n    renderers:\n    - renderer: {{fileID: {l1}}}\n    - renderer: {{fileID: {trunk}}}\n  - screenRelativeHeight: 0.05\n    fadeTransitionWidth: 0\n    renderers:\n    - renderer: {{fileID: {l2}}}\n    - renderer: {{fileID: {trunk}}}\n"
    ));
    let mut files = vec![("Assets/s.unity", sc.text.as_str())];
    if let Some(q) = v.quality {
        files.push(("ProjectSettings/QualitySettings.asset", q));
    }
    let (_d, root) = project(&files);
    unity::convert_report(&root.join("Assets/s.unity"), &unity::Options::default()).unwrap()
}

/// The objects of [`lod_report`]'s scene that reached the soup, in a fixed order.
fn lod_drawn(r: &unity::Report) -> Vec<&'static str> {
    ["Tree_LOD0", "Tree_LOD1", "Tree_LOD2", "Trunk"]
        .into_iter()
        .filter(|n| object(&r.soup, n).is_some())
        .collect()
}

/// The skip line of object `name`.
fn skip_line<'a>(r: &'a unity::Report, name: &str) -> &'a str {
    let tag = format!("object {name:?}: ");
    r.skipped
        .iter()
        .find(|l| l.starts_with(&tag))
        .unwrap_or_else(|| panic!("{name} skipped: {:?}", r.skipped))
}

/// A project whose current quality level (the second) has lodBias 2; the first has 0.3.
const QUALITY_BIAS_2: &str = "%YAML 1.1\n%TAG !u! tag:unity3d.com,2011:\n--- !u!47 &1\nQualitySettings:\n  m_ObjectHideFlags: 0\n  serializedVersion: 5\n  m_CurrentQuality: 1\n  m_QualitySettings:\n  - serializedVersion: 2\n    name: Very Low\n    shadowCascade4Split: {x: 0.06666667, y: 0.2, z: 0.46666667}\n    lodBias: 0.3\n    maximumLODLevel: 0\n    excludedTargetPlatforms: []\n  - serializedVersion: 2\n    name: High\n    shadowCascade4Split: {x: 0.06666667, y: 0.2, z: 0.46666667}\n    lodBias: 2\n    maximumLODLevel: 0\n    excludedTargetPlatforms: []\n  m_PerPlatformDefaultQuality:\n    Standalone: 1\n";

#[test]
fn a_lod_group_shows_the_level_its_screen_height_picks() {
    // Size 1 at d metres, 60° FOV: relative height 0.5 / (d·tan 30°) = 0.866 / d.
    // d = 1 → 0.866 ≥ 0.5: LOD0.
    let r = lod_report(&LodView::at(1.0));
    assert_eq!(lod_drawn(&r), ["Tree_LOD0"], "{:?}", r.skipped);
    assert_eq!(r.skipped.len(), 3, "{:?}", r.skipped);
    assert_eq!(
        skip_line(&r, "Tree_LOD1"),
        "object \"Tree_LOD1\": LOD1 of LODGroup \"Tree\"; the camera shows LOD0 (relative screen height 0.866); not converted"
    );
    assert!(skip_line(&r, "Trunk").contains("LOD1 of LODGroup \"Tree\""));
    assert!(skip_line(&r, "Tree_LOD2").contains("LOD2 of LODGroup \"Tree\""));

    // d = 2 → 0.433: below 0.5, at least 0.2: LOD1, with Trunk (also listed in LOD2).
    let r = lod_report(&LodView::at(2.0));
    assert_eq!(lod_drawn(&r), ["Tree_LOD1", "Trunk"], "{:?}", r.skipped);
    assert_eq!(r.skipped.len(), 2, "{:?}", r.skipped);
    assert_eq!(
        skip_line(&r, "Tree_LOD0"),
        "object \"Tree_LOD0\": LOD0 of LODGroup \"Tree\"; the camera shows LOD1 (relative screen height 0.433); not converted"
    );
    assert!(skip_line(&r, "Tree_LOD2").contains("LOD2 of LODGroup \"Tree\"; the camera shows LOD1"));

    // d = 5 → 0.173: LOD2.
    let r = lod_report(&LodView::at(5.0));
    assert_eq!(lod_drawn(&r), ["Tree_LOD2", "Trunk"], "{:?}", r.skipped);
    assert!(
        skip_line(&r, "Tree_LOD1").contains("the camera shows LOD2 (relative screen height 0.173)")
    );

    // d = 20 → 0.043 < 0.05: Unity culls the group, every level with it.
    let r = lod_report(&LodView::at(20.0));
    assert!(lod_drawn(&r).is_empty(), "{:?}", r.skipped);
    assert_eq!(r.skipped.len(), 4, "{:?}", r.skipped);
    assert_eq!(
        skip_line(&r, "Trunk"),
        "object \"Trunk\": culled: LODGroup \"Tree\" is below its last level's screen height (relative screen height 0.043 < LOD2's 0.050); not converted"
    );
    assert!(r.soup.warnings.is_empty(), "{:?}", r.soup.warnings);
}

#[test]
fn the_quality_levels_lod_bias_divides_the_distance() {
    // lodBias 2 (the current level's, not the first level's 0.3): d = 2 → 0.866 / (2 / 2)
    // = 0.866: LOD0 where lodBias 1 shows LOD1.
    let mut v = LodView::at(2.0);
    v.quality = Some(QUALITY_BIAS_2);
    let r = lod_report(&v);
    assert_eq!(lod_drawn(&r), ["Tree_LOD0"], "{:?}", r.skipped);
    assert!(
        skip_line(&r, "Tree_LOD1").contains("the camera shows LOD0 (relative screen height 0.866)")
    );
    // d = 20 → 0.087: LOD2 where lodBias 1 culls the group.
    let mut v = LodView::at(20.0);
    v.quality = Some(QUALITY_BIAS_2);
    let r = lod_report(&v);
    assert_eq!(lod_drawn(&r), ["Tree_LOD2", "Trunk"], "{:?}", r.skipped);
    assert!(skip_line(&r, "Tree_LOD0").contains("relative screen height 0.087"));
    // A file that does not say (no current level's lodBias) leaves the bias at 1.
    let mut v = LodView::at(2.0);
    let odd = QUALITY_BIAS_2.replace("m_CurrentQuality: 1", "m_CurrentQuality: 7");
    v.quality = Some(&odd);
    assert_eq!(lod_drawn(&lod_report(&v)), ["Tree_LOD1", "Trunk"]);
    let mut v = LodView::at(2.0);
    v.quality = Some("not YAML at all {[");
    assert_eq!(lod_drawn(&lod_report(&v)), ["Tree_LOD1", "Trunk"]);
}

#[test]
fn an_orthographic_camera_measures_by_its_size_not_its_distance() {
    // Orthographic size 4: relative height 0.5 / 4 = 0.125, near or far: LOD2.
    for d in [1.0, 100.0] {
        let mut v = LodView::at(d);
        v.ortho = Some(4.0);
        let r = lod_report(&v);
        assert_eq!(
            lod_drawn(&r),
            ["Tree_LOD2", "Trunk"],
            "d {d}: {:?}",
            r.skipped
        );
        assert!(skip_line(&r, "Tree_LOD0").contains("relative screen height 0.125"));
    }
    // Orthographic size 2: 0.25: LOD1.
    let mut v = LodView::at(100.0);
    v.ortho = Some(2.0);
    assert_eq!(lod_drawn(&lod_report(&v)), ["Tree_LOD1", "Trunk"]);
    // Unity's run-time rule divides the orthographic size by lodBias too: size 4 with
    // lodBias 2 → 0.5 / (4 / 2) = 0.25: LOD1.
    let mut v = LodView::at(1.0);
    v.ortho = Some(4.0);
    v.quality = Some(QUALITY_BIAS_2);
    let r = lod_report(&v);
    assert_eq!(lod_drawn(&r), ["Tree_LOD1", "Trunk"], "{:?}", r.skipped);
    assert!(skip_line(&r, "Tree_LOD0").contains("relative screen height 0.250"));
}

#[test]
fn a_scaled_group_measures_by_its_largest_axis_at_its_reference_point() {
    // Scale (1, −3, 2): world size 1 · max(|1|, |−3|, |2|) = 3. Reference point (0, 0, 1)
    // → (0, 0, 2) in the world; the camera at z = −1 is 3 m from it.
    // 3 · 0.5 / (3 · tan 30°) = 0.866: LOD0 (unscaled it would be 0.289: LOD1).
    let mut v = LodView::at(1.0);
    v.group = Tf::at(0.0, 0.0, 0.0).scale(1.0, -3.0, 2.0);
    v.reference = [0.0, 0.0, 1.0];
    let r = lod_report(&v);
    assert_eq!(lod_drawn(&r), ["Tree_LOD0"], "{:?}", r.skipped);
    assert!(skip_line(&r, "Tree_LOD1").contains("relative screen height 0.866"));
    // Scale 3 on every axis, camera 5 m away: 1.5 / (5 · tan 30°) = 0.520: LOD0, where
    // the unscaled group (0.173) shows LOD2.
    let mut v = LodView::at(5.0);
    v.group = Tf::at(0.0, 0.0, 0.0).scale(3.0, 3.0, 3.0);
    let r = lod_report(&v);
    assert_eq!(lod_drawn(&r), ["Tree_LOD0"], "{:?}", r.skipped);
    assert!(skip_line(&r, "Tree_LOD2").contains("relative screen height 0.520"));
}

#[test]
fn a_skinned_renderer_in_a_level_not_shown_is_dropped_too() {
    // Size 1, 60° FOV: 1 m away → 0.866 (LOD0), 2 m → 0.433 (LOD1).
    let scene = |d: f32| {
        let mut sc = Scene::default();
        sc.camera(&Tf::at(0.0, 0.0, -d));
        let near = quad(&mut sc, 10, "Body_LOD0", 0, "");
        let (body, _) = sc.object("Body_LOD1", &Tf::at(0.0, 0.0, 0.0), 0, true);
        sc.raw(&format!(
            "--- !u!137 &95\nSkinnedMeshRenderer:\n  m_GameObject: {{fileID: {body}}}\n  m_Enabled: 1\n  m_Materials:\n  - {{fileID: 10303, guid: 0000000000000000f000000000000000, type: 0}}\n  m_Mesh: {{fileID: {QUAD}, guid: {BUILTIN}, type: 3}}\n  m_Bones: []\n"
        ));
        let (go, _) = sc.object("Body", &Tf::at(0.0, 0.0, 0.0), 0, true);
        sc.raw(&format!(
            "--- !u!205 &90\nLODGroup:\n  m_GameObject: {{fileID: {go}}}\n  m_Enabled: 1\n  m_Size: 1\n  m_LODs:\n  - screenRelativeHeight: 0.5\n    renderers:\n    - renderer: {{fileID: {near}}}\n  - screenRelativeHeight: 0.2\n    renderers:\n    - renderer: {{fileID: 95}}\n"
        ));
        let (_d, root) = project(&[("Assets/s.unity", &sc.text)]);
        unity::convert_report(&root.join("Assets/s.unity"), &unity::Options::default()).unwrap()
    };
    let r = scene(1.0);
    assert!(object(&r.soup, "Body_LOD0").is_some());
    assert!(object(&r.soup, "Body_LOD1").is_none(), "{:?}", r.skipped);
    assert_eq!(
        r.skipped,
        ["object \"Body_LOD1\": LOD1 of LODGroup \"Body\"; the camera shows LOD0 (relative screen height 0.866); not converted"]
    );
    // Shown, the skinned renderer is drawn (rigidly, its Quad having no skin).
    let r = scene(2.0);
    assert!(object(&r.soup, "Body_LOD0").is_none());
    assert!(
        object(&r.soup, "Body_LOD1").is_some(),
        "{:?}",
        r.soup.warnings
    );
}

#[test]
fn a_skinned_renderer_outside_the_cameras_culling_mask_is_not_converted() {
    let mut sc = Scene::default();
    sc.camera(&Tf::at(0.0, 0.0, -5.0));
    sc.raw("  m_CullingMask:\n    serializedVersion: 2\n    m_Bits: 1\n");
    for (go, name, layer) in [(60, "Seen", 0), (70, "Hidden", 5)] {
        let (t, smr) = (go + 1, go + 2);
        sc.raw(&format!(
            "--- !u!1 &{go}\nGameObject:\n  m_Component:\n  - component: {{fileID: {t}}}\n  - component: {{fileID: {smr}}}\n  m_Layer: {layer}\n  m_Name: {name}\n  m_IsActive: 1\n--- !u!4 &{t}\nTransform:\n  m_GameObject: {{fileID: {go}}}\n  m_LocalRotation: {{x: 0, y: 0, z: 0, w: 1}}\n  m_LocalPosition: {{x: 0, y: 0, z: 0}}\n  m_LocalScale: {{x: 1, y: 1, z: 1}}\n  m_Children: []\n  m_Father: {{fileID: 0}}\n--- !u!137 &{smr}\nSkinnedMeshRenderer:\n  m_GameObject: {{fileID: {go}}}\n  m_Enabled: 1\n  m_Materials:\n  - {{fileID: 10303, guid: 0000000000000000f000000000000000, type: 0}}\n  m_Mesh: {{fileID: {QUAD}, guid: {BUILTIN}, type: 3}}\n  m_Bones: []\n"
        ));
    }
    let (_d, root) = project(&[("Assets/s.unity", &sc.text)]);
    let r =
        unity::convert_report(&root.join("Assets/s.unity"), &unity::Options::default()).unwrap();
    assert_eq!(r.soup.objects.len(), 1);
    assert_eq!(r.soup.objects[0].name, "Seen");
    assert_eq!(r.soup.triangles.len(), 2);
    assert_eq!(
        r.skipped,
        ["object \"Hidden\": layer 5 is outside camera \"Main Camera\"'s culling mask; not converted"]
    );
}

#[test]
fn without_a_camera_a_lod_group_keeps_lod0() {
    let mut sc = Scene::default();
    let near = quad(&mut sc, 10, "Tree_LOD0", 0, "");
    let far = quad(&mut sc, 20, "Tree_LOD1", 0, "");
    let (go, _) = sc.object("Tree", &Tf::at(0.0, 0.0, 500.0), 0, true);
    sc.raw(&format!(
        "--- !u!205 &90\nLODGroup:\n  m_GameObject: {{fileID: {go}}}\n  m_Enabled: 1\n  m_Size: 1\n  m_LODs:\n  - screenRelativeHeight: 0.6\n    renderers:\n    - renderer: {{fileID: {near}}}\n  - screenRelativeHeight: 0.1\n    renderers:\n    - renderer: {{fileID: {far}}}\n"
    ));
    let (_d, root) = project(&[("Assets/s.unity", &sc.text)]);
    let r =
        unity::convert_report(&root.join("Assets/s.unity"), &unity::Options::default()).unwrap();
    assert!(object(&r.soup, "Tree_LOD0").is_some());
    assert!(object(&r.soup, "Tree_LOD1").is_none());
    assert_eq!(
        r.skipped,
        ["object \"Tree_LOD1\": LOD1 of LODGroup \"Tree\"; there is no camera; LOD0 kept; not converted"]
    );
}

#[test]
fn list_names_the_renderers_unitys_rules_skip() {
    let mut sc = Scene::default();
    sc.camera(&Tf::at(0.0, 0.0, -5.0));
    sc.raw("  m_CullingMask:\n    serializedVersion: 2\n    m_Bits: 1\n");
    quad(&mut sc, 10, "Seen", 0, "");
    quad(&mut sc, 20, "Hidden", 5, "");
    let (d, root) = project(&[("Assets/s.unity", &sc.text)]);
    let out = d.path().join("s.soup");
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_unity2soup"))
        .arg(root.join("Assets/s.unity"))
        .arg("-o")
        .arg(&out)
        .arg("--list")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(
        err.contains("skipped object \"Hidden\": layer 5 is outside camera \"Main Camera\"'s culling mask; not converted"),
        "{err}"
    );
    assert!(
        err.contains("skipped 1 renderers by Unity's draw rules"),
        "{err}"
    );
    assert!(err.contains("cull Back"), "{err}");
}

/// A component of `class` (its YAML name `kind`) on GameObject `go`.
fn component(sc: &mut Scene, id: i64, class: u32, kind: &str, go: i64, enabled: bool) {
    sc.raw(&format!(
        "--- !u!{class} &{id}\n{kind}:\n  m_GameObject: {{fileID: {go}}}\n  m_Enabled: {}\n",
        enabled as i32
    ));
}

#[test]
fn sprites_text_lines_and_particles_the_camera_would_show_are_named_once_per_kind() {
    let mut sc = Scene::default();
    sc.camera(&Tf::at(0.0, 0.0, -5.0));
    sc.raw("  m_CullingMask:\n    serializedVersion: 2\n    m_Bits: 4294967039\n");
    let mut id = 5000;
    let mut on = |sc: &mut Scene, name: &str, class: u32, kind: &str, enabled: bool| {
        let (go, _) = sc.object(name, &Tf::at(0.0, 0.0, 0.0), 0, true);
        id += 1;
        component(sc, id, class, kind, go, enabled);
        go
    };
    for name in ["S1", "S2", "S3", "S4", "S5"] {
        on(&mut sc, name, 212, "SpriteRenderer", true);
    }
    on(&mut sc, "OffSprite", 212, "SpriteRenderer", false);
    on(&mut sc, "Line", 120, "LineRenderer", true);
    on(&mut sc, "Ground", 218, "Terrain", true);
    // A TextMesh draws through its MeshRenderer: shown when that renderer is enabled.
    let label = on(&mut sc, "Label", 102, "TextMesh", true);
    component(&mut sc, 6001, 23, "MeshRenderer", label, true);
    let mute = on(&mut sc, "Mute", 102, "TextMesh", true);
    component(&mut sc, 6002, 23, "MeshRenderer", mute, false);
    // On layer 8, which the camera leaves out.
    let smoke = on(&mut sc, "Smoke", 199, "ParticleSystemRenderer", true);
    sc.text = sc.text.replace(
        &format!("--- !u!1 &{smoke}\nGameObject:\n  m_ObjectHideFlags: 0\n  serializedVersion: 6\n  m_Component:\n  - component: {{fileID: {}}}\n  m_Layer: 0", smoke + 1),
        &format!("--- !u!1 &{smoke}\nGameObject:\n  m_ObjectHideFlags: 0\n  serializedVersion: 6\n  m_Component:\n  - component: {{fileID: {}}}\n  m_Layer: 8", smoke + 1),
    );
    assert!(sc.text.contains("m_Layer: 8"), "Smoke moved to layer 8");
    let inactive = sc.object("Hidden", &Tf::at(0.0, 0.0, 0.0), 0, false).0;
    component(&mut sc, 7001, 120, "LineRenderer", inactive, true);
    let soup = convert_scene(&sc.text);
    let undrawn: Vec<&String> = soup
        .warnings
        .iter()
        .filter(|w| w.contains("not drawn"))
        .collect();
    assert_eq!(
        undrawn,
        [
            "Assets/s.unity: 5 SpriteRenderers not drawn ('S1', 'S2', 'S3' and 2 more): sprites are not converted",
            "Assets/s.unity: object 'Label': TextMesh not drawn: 3D text is not converted",
            "Assets/s.unity: object 'Line': LineRenderer not drawn: lines are not converted",
        ]
    );
    assert_eq!(soup.triangles.len(), 0);
    assert_warned(&soup, "object 'Ground' (fileID");
    assert_warned(&soup, "Terrain has no TerrainData; skipped");
}
