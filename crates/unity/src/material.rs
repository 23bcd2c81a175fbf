//! Unity materials (class 21, in `.mat` files or embedded in a scene) → soup materials.

use crate::yaml::Node;
use formats::Material;
use glam::{Vec3, Vec4};

/// sRGB electro-optical transfer function, per channel; HDR values above 1 follow the
/// same curve (Unity stores HDR colours gamma-encoded too).
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

pub fn linear_rgb(c: Vec4) -> Vec3 {
    Vec3::new(
        srgb_to_linear(c.x),
        srgb_to_linear(c.y),
        srgb_to_linear(c.z),
    )
}

/// The named float and colour properties of `m_SavedProperties`, in either layout: the
/// modern `- _Name: value` list, or Unity ≤ 5.5's repeated `data: {first: {name}, second}`.
fn props<'a>(saved: &'a Node, section: &str) -> Vec<(&'a str, &'a Node)> {
    let Some(sec) = saved.get(section) else {
        return vec![];
    };
    let mut out = Vec::new();
    for item in sec.as_seq() {
        for (k, v) in item.as_map() {
            out.push((k.as_str(), v));
        }
    }
    for d in sec.get_all("data") {
        if let (Some(name), Some(v)) = (
            d.path(&["first", "name"]).and_then(Node::as_str),
            d.get("second"),
        ) {
            out.push((name, v));
        }
    }
    out
}

/// Convert a parsed Material body. Returns the material and notes worth a warning.
pub fn convert(body: &Node, source: &str) -> (Material, Vec<String>) {
    let mut notes = Vec::new();
    let mut m = Material::unity_default();
    m.name = body.str_at("m_Name").unwrap_or("").to_string();
    m.source = source.to_string();
    let empty = Node::Map(vec![]);
    let saved = body.get("m_SavedProperties").unwrap_or(&empty);
    let floats = props(saved, "m_Floats");
    let colors = props(saved, "m_Colors");
    let float = |n: &str| {
        floats
            .iter()
            .find(|(k, _)| *k == n)
            .and_then(|(_, v)| v.as_f32())
    };
    let color = |n: &str| {
        colors
            .iter()
            .find(|(k, _)| *k == n)
            .and_then(|(_, v)| v.color())
    };

    if let Some(c) = color("_BaseColor").or_else(|| color("_Color")) {
        m.color = linear_rgb(c);
    } else {
        notes.push("no _Color or _BaseColor; white".to_string());
    }
    if let Some(x) = float("_Metallic") {
        m.metallic = x.clamp(0.0, 1.0);
    }
    if let Some(x) = float("_Smoothness").or_else(|| float("_Glossiness")) {
        m.smoothness = x.clamp(0.0, 1.0);
    }
    if let Some(x) = float("_Reflectivity") {
        m.reflectivity = Some(x.clamp(0.0, 1.0));
    }
    if let Some(e) = color("_EmissionColor") {
        let e = linear_rgb(e);
        // Unity's Standard and URP shaders glow only with the _EMISSION keyword; files
        // without any keyword list (custom shaders) glow when the colour is not black.
        let keywords: Vec<&str> = ["m_ShaderKeywords", "m_ValidKeywords"]
            .iter()
            .filter_map(|k| body.get(k))
            .flat_map(|n| match n {
                Node::Scalar(s) => s.split_whitespace().collect::<Vec<_>>(),
                Node::Seq(v) => v.iter().filter_map(Node::as_str).collect(),
                _ => vec![],
            })
            .collect();
        let has_keyword_info =
            body.get("m_ShaderKeywords").is_some() || body.get("m_ValidKeywords").is_some();
        let enabled = if has_keyword_info {
            keywords.contains(&"_EMISSION")
        } else {
            e != Vec3::ZERO
        };
        if enabled {
            m.emission = e;
        }
    }
    if !(m.color.is_finite()
        && m.emission.is_finite()
        && m.metallic.is_finite()
        && m.smoothness.is_finite())
    {
        notes.push("non-finite property; Unity's default used".to_string());
        let (name, source) = (m.name.clone(), m.source.clone());
        m = Material::unity_default();
        m.name = name;
        m.source = source;
    }
    (m, notes)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::yaml::parse;

    #[test]
    fn standard_urp_and_legacy_layouts() {
        let std_mat = parse("Material:\n  m_Name: Red\n  m_ShaderKeywords: _EMISSION\n  m_SavedProperties:\n    m_Floats:\n    - _Glossiness: 0.8\n    - _Metallic: 0.5\n    - _Reflectivity: 0.3\n    m_Colors:\n    - _Color: {r: 1, g: 0.5, b: 0, a: 1}\n    - _EmissionColor: {r: 2, g: 0, b: 0, a: 1}\n");
        let (m, _) = convert(std_mat.get("Material").unwrap(), "a.mat");
        assert_eq!(m.name, "Red");
        assert!(
            (m.color.y - 0.21404114).abs() < 1e-6,
            "sRGB 0.5 → linear {}",
            m.color.y
        );
        assert_eq!(
            (m.metallic, m.smoothness, m.reflectivity),
            (0.5, 0.8, Some(0.3))
        );
        assert!((m.emission.x - srgb_to_linear(2.0)).abs() < 1e-6 && m.emission.x > 4.0);

        let urp = parse("Material:\n  m_ValidKeywords: []\n  m_SavedProperties:\n    m_Floats:\n    - _Smoothness: 0.25\n    m_Colors:\n    - _BaseColor: {r: 0, g: 0, b: 1, a: 1}\n    - _Color: {r: 1, g: 1, b: 1, a: 1}\n    - _EmissionColor: {r: 1, g: 1, b: 1, a: 1}\n");
        let (m, _) = convert(urp.get("Material").unwrap(), "b.mat");
        assert_eq!(m.color, Vec3::new(0.0, 0.0, 1.0));
        assert_eq!(m.smoothness, 0.25);
        assert_eq!(m.emission, Vec3::ZERO, "no _EMISSION keyword");

        let legacy = parse("Material:\n  m_SavedProperties:\n    m_Floats:\n      data:\n        first:\n          name: _Metallic\n        second: 1\n    m_Colors:\n      data:\n        first:\n          name: _Color\n        second: {r: 0.2, g: 0.2, b: 0.2, a: 1}\n");
        let (m, _) = convert(legacy.get("Material").unwrap(), "c.mat");
        assert_eq!(m.metallic, 1.0);
        assert!((m.color.x - srgb_to_linear(0.2)).abs() < 1e-7);
    }
}
