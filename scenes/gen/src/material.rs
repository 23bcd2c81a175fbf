//! Standard-shader `.mat` files as Unity 2022.3 writes them (Material serializedVersion 8).

use crate::unity::{num, rgba};
use std::fmt::Write;

/// One look. Colours are sRGB, as the inspector stores them.
#[derive(Clone, Debug)]
pub struct MatDesc {
    pub name: &'static str,
    pub color: [f32; 3],
    pub metallic: f32,
    pub glossiness: f32,
    /// The inspector's Specular Highlights switch (`_SpecularHighlights`; off also writes
    /// the `_SPECULARHIGHLIGHTS_OFF` keyword).
    pub highlights: bool,
    /// unitrace's own `_Reflectivity` float: overrides metallic·smoothness when present.
    pub reflectivity: Option<f32>,
    /// `_EmissionColor` (HDR, sRGB-encoded); `Some` also turns on the `_EMISSION` keyword.
    pub emission: Option<[f32; 3]>,
}

/// What a look draws with beyond its colours: its albedo texture and how it uses alpha.
#[derive(Clone, Debug)]
pub struct Surface {
    /// `_MainTex`: the texture's GUID with its tiling.
    pub main_tex: Option<TexSlot>,
    /// The `_Color` alpha.
    pub alpha: f32,
    /// The Standard shader's rendering mode (the inspector's other settings follow it).
    pub mode: Mode,
    /// `_Cutoff`, the alpha threshold in [`Mode::Cutout`].
    pub cutoff: f32,
    /// `_BumpMap`, a normal map's GUID (turns on the `_NORMALMAP` keyword), with
    /// `_BumpScale`.
    pub bump_map: Option<(String, f32)>,
    /// `_EmissionMap`: a texture's GUID, multiplied with the emission colour.
    pub emission_map: Option<String>,
}

impl Default for Surface {
    fn default() -> Self {
        Surface {
            main_tex: None,
            alpha: 1.0,
            mode: Mode::Opaque,
            cutoff: 0.5,
            bump_map: None,
            emission_map: None,
        }
    }
}

/// A texture in a material slot: uv' = uv · scale + offset.
#[derive(Clone, Debug)]
pub struct TexSlot {
    pub guid: String,
    pub scale: [f32; 2],
    pub offset: [f32; 2],
}

impl TexSlot {
    pub fn new(guid: &str) -> Self {
        TexSlot {
            guid: guid.to_string(),
            scale: [1.0, 1.0],
            offset: [0.0, 0.0],
        }
    }
}

/// Standard's `_Mode`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    Opaque = 0,
    Cutout = 1,
    Fade = 2,
    Transparent = 3,
}

impl Mode {
    /// The keyword, render queue, RenderType tag and blend state the inspector writes
    /// for the mode.
    fn inspector(self) -> (Option<&'static str>, i32, Option<&'static str>, [f32; 3]) {
        match self {
            Mode::Opaque => (None, -1, None, [1.0, 0.0, 1.0]),
            Mode::Cutout => (
                Some("_ALPHATEST_ON"),
                2450,
                Some("TransparentCutout"),
                [1.0, 0.0, 1.0],
            ),
            Mode::Fade => (
                Some("_ALPHABLEND_ON"),
                3000,
                Some("Transparent"),
                [5.0, 10.0, 0.0],
            ),
            Mode::Transparent => (
                Some("_ALPHAPREMULTIPLY_ON"),
                3000,
                Some("Transparent"),
                [1.0, 10.0, 0.0],
            ),
        }
    }
}

impl MatDesc {
    /// A non-metallic matte colour.
    pub fn matte(name: &'static str, color: [f32; 3]) -> Self {
        MatDesc {
            name,
            color,
            metallic: 0.0,
            glossiness: 0.2,
            highlights: true,
            reflectivity: None,
            emission: None,
        }
    }

    /// A perfect mirror: metallic 1, smoothness 1.
    pub fn mirror(name: &'static str) -> Self {
        MatDesc {
            name,
            color: [1.0, 1.0, 1.0],
            metallic: 1.0,
            glossiness: 1.0,
            highlights: true,
            reflectivity: None,
            emission: None,
        }
    }
}

const TEXTURES: [&str; 9] = [
    "_BumpMap",
    "_DetailAlbedoMap",
    "_DetailMask",
    "_DetailNormalMap",
    "_EmissionMap",
    "_MainTex",
    "_MetallicGlossMap",
    "_OcclusionMap",
    "_ParallaxMap",
];

pub fn write_material(m: &MatDesc) -> String {
    write_surface(m, &Surface::default())
}

/// A look with a texture or alpha ([`Surface`]).
pub fn write_surface(m: &MatDesc, surface: &Surface) -> String {
    let mut s =
        String::from("%YAML 1.1\n%TAG !u! tag:unity3d.com,2011:\n--- !u!21 &2100000\nMaterial:\n");
    let (mode_keyword, queue, render_type, [src, dst, zwrite]) = surface.mode.inspector();
    let mut keywords: Vec<&str> = mode_keyword.into_iter().collect();
    if m.emission.is_some() {
        keywords.push("_EMISSION");
    }
    if surface.bump_map.is_some() {
        keywords.push("_NORMALMAP");
    }
    if !m.highlights {
        keywords.push("_SPECULARHIGHLIGHTS_OFF");
    }
    keywords.sort();
    let keywords = if keywords.is_empty() {
        " []".to_string()
    } else {
        keywords.iter().map(|k| format!("\n  - {k}")).collect()
    };
    let tags = match render_type {
        Some(t) => format!("\n    RenderType: {t}"),
        None => " {}".to_string(),
    };
    // Emissive materials default to realtime GI emission (1); others to "emissive is
    // black" (4), exactly as the inspector sets them.
    let lightmap_flags = if m.emission.is_some() { 1 } else { 4 };
    let _ = write!(
        s,
        "  serializedVersion: 8
  m_ObjectHideFlags: 0
  m_CorrespondingSourceObject: {{fileID: 0}}
  m_PrefabInstance: {{fileID: 0}}
  m_PrefabAsset: {{fileID: 0}}
  m_Name: {name}
  m_Shader: {{fileID: 46, guid: 0000000000000000f000000000000000, type: 0}}
  m_Parent: {{fileID: 0}}
  m_ModifiedSerializedProperties: 0
  m_ValidKeywords:{keywords}
  m_InvalidKeywords: []
  m_LightmapFlags: {lightmap_flags}
  m_EnableInstancingVariants: 0
  m_DoubleSidedGI: 0
  m_CustomRenderQueue: {queue}
  stringTagMap:{tags}
  disabledShaderPasses: []
  m_LockedProperties: 
  m_SavedProperties:
    serializedVersion: 3
    m_TexEnvs:
",
        name = m.name
    );
    for t in TEXTURES {
        let (texture, scale, offset) = match &surface.main_tex {
            Some(slot) if t == "_MainTex" => (
                format!("{{fileID: 2800000, guid: {}, type: 3}}", slot.guid),
                slot.scale,
                slot.offset,
            ),
            _ if t == "_EmissionMap" && surface.emission_map.is_some() => (
                format!(
                    "{{fileID: 2800000, guid: {}, type: 3}}",
                    surface.emission_map.as_deref().unwrap_or("")
                ),
                [1.0, 1.0],
                [0.0, 0.0],
            ),
            _ if t == "_BumpMap" && surface.bump_map.is_some() => (
                format!(
                    "{{fileID: 2800000, guid: {}, type: 3}}",
                    surface.bump_map.as_ref().map_or("", |b| &b.0)
                ),
                [1.0, 1.0],
                [0.0, 0.0],
            ),
            _ => ("{fileID: 0}".to_string(), [1.0, 1.0], [0.0, 0.0]),
        };
        let _ = write!(
            s,
            "    - {t}:
        m_Texture: {texture}
        m_Scale: {{x: {}, y: {}}}
        m_Offset: {{x: {}, y: {}}}
",
            num(scale[0]),
            num(scale[1]),
            num(offset[0]),
            num(offset[1])
        );
    }
    s += "    m_Ints: []\n    m_Floats:\n";
    // Unity keeps properties sorted by name; `_Reflectivity` slots in among them.
    let mut floats: Vec<(&str, f32)> = vec![
        ("_BumpScale", surface.bump_map.as_ref().map_or(1.0, |b| b.1)),
        ("_Cutoff", surface.cutoff),
        ("_DetailNormalMapScale", 1.0),
        ("_DstBlend", dst),
        ("_GlossMapScale", 1.0),
        ("_Glossiness", m.glossiness),
        ("_GlossyReflections", 1.0),
        ("_Metallic", m.metallic),
        ("_Mode", surface.mode as i32 as f32),
        ("_OcclusionStrength", 1.0),
        ("_Parallax", 0.02),
        ("_SmoothnessTextureChannel", 0.0),
        ("_SpecularHighlights", if m.highlights { 1.0 } else { 0.0 }),
        ("_SrcBlend", src),
        ("_UVSec", 0.0),
        ("_ZWrite", zwrite),
    ];
    if let Some(r) = m.reflectivity {
        floats.push(("_Reflectivity", r));
    }
    floats.sort_by(|a, b| a.0.cmp(b.0));
    for (k, v) in floats {
        let _ = writeln!(s, "    - {k}: {}", num(v));
    }
    let emission = m.emission.unwrap_or([0.0, 0.0, 0.0]);
    let _ = write!(
        s,
        "    m_Colors:
    - _Color: {}
    - _EmissionColor: {}
  m_BuildTextureStacks: []
",
        rgba(m.color, surface.alpha),
        rgba(emission, 1.0)
    );
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn floor_material_carries_reflectivity_in_sorted_order() {
        let m = MatDesc {
            name: "Floor",
            color: [0.1, 0.2, 0.9],
            metallic: 0.6,
            glossiness: 1.0,
            highlights: true,
            reflectivity: Some(0.8),
            emission: None,
        };
        let text = write_material(&m);
        let p = text.find("    - _Parallax: 0.02").unwrap();
        let r = text.find("    - _Reflectivity: 0.8").unwrap();
        let sm = text.find("    - _SmoothnessTextureChannel: 0").unwrap();
        assert!(p < r && r < sm);
        assert!(text.contains("    - _Metallic: 0.6\n"));
        assert!(text.contains("    - _Color: {r: 0.1, g: 0.2, b: 0.9, a: 1}\n"));
        assert!(text.contains("  m_ValidKeywords: []\n"));
    }

    #[test]
    fn emission_turns_on_the_keyword() {
        let mut m = MatDesc::matte("Glow", [1.0, 1.0, 1.0]);
        m.emission = Some([2.0, 1.0, 0.25]);
        let text = write_material(&m);
        assert!(text.contains("  m_ValidKeywords:\n  - _EMISSION\n"));
        assert!(text.contains("    - _EmissionColor: {r: 2, g: 1, b: 0.25, a: 1}\n"));
    }
}
