//! The project's current quality level (`ProjectSettings/QualitySettings.asset`, the
//! `m_CurrentQuality`-th entry of `m_QualitySettings`, the level the editor shows): its
//! lodBias, which scales LOD distances, and the realtime shadows it allows the built-in
//! pipeline (URP and HDRP take theirs from their pipeline assets, which are not read).

use crate::docs;
use crate::reference::fref;
use crate::yaml::Node;

/// The realtime shadows a built-in quality level allows (its `shadows`, Unity's
/// `ShadowQuality`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ShadowQuality {
    /// 0: no light casts a shadow.
    Disable,
    /// 1: soft shadows are drawn hard.
    HardOnly,
    /// 2: hard and soft shadows as each light asks (Unity's default).
    All,
}

/// `f` of the current quality level of a `QualitySettings.asset`'s text; `None` when the
/// text names no such level.
fn current_level<T>(text: &str, f: impl FnOnce(&Node) -> Option<T>) -> Option<T> {
    let body = docs::first(text, docs::QUALITY_SETTINGS)?;
    let current = usize::try_from(body.i64_at("m_CurrentQuality")?).ok()?;
    f(body.get("m_QualitySettings")?.as_seq().get(current)?)
}

/// lodBias of the current quality level. `None` when the text does not say, or says
/// something other than a positive finite number.
pub fn lod_bias(text: &str) -> Option<f32> {
    current_level(text, |level| {
        level
            .f32_at("lodBias")
            .filter(|b| b.is_finite() && *b > 0.0)
    })
}

/// The shadows the current quality level allows. `None` when the text does not say, or
/// says something Unity does not write.
pub fn shadows(text: &str) -> Option<ShadowQuality> {
    current_level(text, |level| match level.i64_at("shadows")? {
        0 => Some(ShadowQuality::Disable),
        1 => Some(ShadowQuality::HardOnly),
        2 => Some(ShadowQuality::All),
        _ => None,
    })
}

/// The render pipeline asset the current quality level overrides the default with
/// (`customRenderPipeline`: its fileID, 0 for none, and GUID); `None` when the text does
/// not say.
pub fn render_pipeline_asset(text: &str) -> Option<(i64, Option<String>)> {
    current_level(text, |level| {
        Some(fref(Some(level.get("customRenderPipeline")?)))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const QUALITY: &str = "%YAML 1.1\n%TAG !u! tag:unity3d.com,2011:\n--- !u!47 &1\nQualitySettings:\n  m_ObjectHideFlags: 0\n  serializedVersion: 5\n  m_CurrentQuality: 1\n  m_QualitySettings:\n  - serializedVersion: 2\n    name: Low\n    shadows: 0\n    lodBias: 0.4\n    maximumLODLevel: 0\n  - serializedVersion: 2\n    name: High\n    shadows: 1\n    shadowCascade4Split: {x: 0.06666667, y: 0.2, z: 0.46666667}\n    lodBias: 2\n    maximumLODLevel: 0\n  m_PerPlatformDefaultQuality:\n    Standalone: 0\n";

    #[test]
    fn lod_bias_is_the_current_quality_levels() {
        assert_eq!(lod_bias(QUALITY), Some(2.0));
        let first = QUALITY.replace("m_CurrentQuality: 1", "m_CurrentQuality: 0");
        assert_eq!(lod_bias(&first), Some(0.4));
    }

    #[test]
    fn odd_quality_settings_say_nothing() {
        for (from, to) in [
            ("m_CurrentQuality: 1", "m_CurrentQuality: 2"),
            ("m_CurrentQuality: 1", "m_CurrentQuality: -1"),
            ("m_CurrentQuality: 1", "m_CurrentQuality: x"),
            (
                "m_CurrentQuality: 1",
                "m_CurrentQuality: 99999999999999999999",
            ),
            ("m_CurrentQuality: 1\n", ""),
            ("lodBias: 2", "lodBias: 0"),
            ("lodBias: 2", "lodBias: -1"),
            ("lodBias: 2", "lodBias: NaN"),
            ("lodBias: 2", "lodBias: Infinity"),
            ("lodBias: 2", "lodBias: {x: 1}"),
            ("lodBias: 2", "lodBias:"),
            ("--- !u!47 &1", "--- !u!48 &1"),
            ("  m_QualitySettings:\n", "  m_QualitySettings: 3\n"),
        ] {
            let text = QUALITY.replace(from, to);
            assert_eq!(lod_bias(&text), None, "{to}");
        }
        for junk in [
            "",
            "\0\u{fffd}",
            "QualitySettings:\n  m_CurrentQuality: 0\n",
            "--- !u!47 &1\n",
        ] {
            assert_eq!(lod_bias(junk), None, "{junk:?}");
        }
        // Cut anywhere, the file still reads without a panic.
        for end in 0..QUALITY.len() {
            if QUALITY.is_char_boundary(end) {
                let _ = lod_bias(&QUALITY[..end]);
            }
        }
    }

    #[test]
    fn a_level_may_assign_its_own_render_pipeline() {
        let assigns = |text: &str| render_pipeline_asset(text).map(|(id, _)| id != 0);
        assert_eq!(assigns(QUALITY), None);
        let none = QUALITY.replace(
            "    lodBias: 2\n",
            "    lodBias: 2\n    customRenderPipeline: {fileID: 0}\n",
        );
        assert_eq!(assigns(&none), Some(false));
        let urp = none.replace(
            "{fileID: 0}",
            "{fileID: 11400000, guid: 19ba41d7c0026c3459d37c2fe90c55a0, type: 2}",
        );
        assert_eq!(assigns(&urp), Some(true));
        // The other level's asset is not the current one's.
        let low = urp.replace("m_CurrentQuality: 1", "m_CurrentQuality: 0");
        assert_eq!(assigns(&low), None);
    }

    #[test]
    fn shadows_are_the_current_quality_levels() {
        assert_eq!(shadows(QUALITY), Some(ShadowQuality::HardOnly));
        let first = QUALITY.replace("m_CurrentQuality: 1", "m_CurrentQuality: 0");
        assert_eq!(shadows(&first), Some(ShadowQuality::Disable));
        let all = QUALITY.replace("shadows: 1", "shadows: 2");
        assert_eq!(shadows(&all), Some(ShadowQuality::All));
        for odd in ["shadows: 3", "shadows: -1", "shadows: x", "shadows:", ""] {
            let text = QUALITY.replace("shadows: 1", odd);
            assert_eq!(shadows(&text), None, "{odd:?}");
        }
    }
}
