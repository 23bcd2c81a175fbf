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
    let (_d, root) = project(&[("Assets/s.unity", &sc.text)]);
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
    let mut sc = Scene::default();
    sc.camera(&Tf::at(0.0, 0.0, -5.0));
    let near = quad(&mut sc, 10, "Tree_LOD0", 0, "");
    let far = quad(&mut sc, 20, "Tree_LOD1", 0, "");
    let both = quad(&mut sc, 30, "Trunk", 0, "");
    let (go, _) = sc.object("Tree", &Tf::at(0.0, 0.0, 0.0), 0, true);
    sc.raw(&format!(
        "--- !u!205 &90\nLODGroup:\n  m_GameObject: {{fileID: {go}}}\n  m_Enabled: 1\n  serializedVersion: 2\n  m_LODs:\n  - screenRelativeHeight: 0.6\n    fadeTransitionWidth: 0\n    renderers:\n    - renderer: {{fileID: {near}}}\n    - renderer: {{fileID: {both}}}\n  - screenRelativeHeight: 0.1\n    fadeTransitionWidth: 0\n    renderers:\n    - renderer: {{fileID: {far}}}\n    - renderer: {{fileID: {both}}}\n"
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
