//! What a project's settings say of how it draws: the render pipeline (the package
//! `Packages/manifest.json` lists, where `ProjectSettings/` assigns its asset) and what a URP
//! asset lets lights do, how light colour and intensity combine, the colour space, and the
//! current quality level's shadows and LOD bias. Each file is read up to a bound; one that
//! cannot be read counts as absent, and Unity's defaults stand.

use crate::docs;
use crate::light::{LightUnits, UniversalAsset};
use crate::meta::GuidIndex;
use crate::quality::ShadowQuality;
use formats::{ColorSpace, Light};
use std::path::{Path, PathBuf};

/// The render pipeline a project draws with. Its lights, sky and fog follow that
/// pipeline's rules, so a scene renders as its own editor shows it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Pipeline {
    BuiltIn,
    /// The Universal Render Pipeline, or the Lightweight one it grew from.
    Universal,
    /// The High Definition Render Pipeline: lights in physical units, sky and fog in
    /// Volumes.
    HighDefinition,
}

impl Pipeline {
    /// The pipeline's name in messages.
    pub fn name(self) -> &'static str {
        match self {
            Pipeline::BuiltIn => "the built-in render pipeline",
            Pipeline::Universal => "URP",
            Pipeline::HighDefinition => "HDRP",
        }
    }

    /// The pipeline whose package a `Packages/manifest.json` lists (an installed pipeline
    /// package is, in practice, the one the project's graphics settings use).
    pub fn of_manifest(text: &str) -> Pipeline {
        let lists = |package: &str| text.contains(&format!("\"{package}\""));
        if lists("com.unity.render-pipelines.high-definition") {
            Pipeline::HighDefinition
        } else if lists("com.unity.render-pipelines.universal")
            || lists("com.unity.render-pipelines.lightweight")
        {
            Pipeline::Universal
        } else {
            Pipeline::BuiltIn
        }
    }
}

/// Settings files are a few kilobytes; a larger one (a GUID that names some other
/// asset, a damaged file) is not read whole, and its settings count as unknown.
const SETTINGS_BYTES: u64 = 16 << 20;

/// A settings file's text (invalid UTF-8 replaced), or `None` when it is missing,
/// unreadable or larger than [`SETTINGS_BYTES`].
fn settings_text(path: &Path) -> Option<String> {
    use std::io::Read;
    let mut bytes = Vec::new();
    std::fs::File::open(path)
        .ok()?
        .take(SETTINGS_BYTES + 1)
        .read_to_end(&mut bytes)
        .ok()?;
    (bytes.len() as u64 <= SETTINGS_BYTES).then(|| String::from_utf8_lossy(&bytes).into_owned())
}

/// The render pipeline asset a project's settings assign.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum PipelineAsset {
    /// The graphics settings are absent or do not say: only the manifest tells.
    Unknown,
    /// Neither the current quality level nor `GraphicsSettings.asset` assigns one: a
    /// pipeline package alone leaves Unity drawing with the built-in pipeline.
    Unassigned,
    /// The current quality level's asset, else `GraphicsSettings.asset`'s default
    /// (`m_CustomRenderPipeline`), by GUID.
    Assigned(Option<String>),
}

impl PipelineAsset {
    pub fn of(graphics: Option<&str>, quality: Option<&str>) -> PipelineAsset {
        if let Some((id, guid)) = quality.and_then(crate::quality::render_pipeline_asset) {
            if id != 0 {
                return PipelineAsset::Assigned(guid);
            }
        }
        let default = graphics.and_then(|text| {
            let body = docs::first(text, docs::GRAPHICS_SETTINGS)?;
            Some(crate::reference::fref(Some(
                body.get("m_CustomRenderPipeline")?,
            )))
        });
        match default {
            None => PipelineAsset::Unknown,
            Some((0, _)) => PipelineAsset::Unassigned,
            Some((_, guid)) => PipelineAsset::Assigned(guid),
        }
    }
}

/// The colour space a `ProjectSettings.asset` text sets (`m_ActiveColorSpace` 0 Gamma, 1
/// Linear); Linear where it does not say.
pub fn color_space(text: &str) -> ColorSpace {
    let gamma = docs::first(text, docs::PLAYER_SETTINGS)
        .is_some_and(|b| b.i64_at("m_ActiveColorSpace") == Some(0));
    if gamma {
        ColorSpace::Gamma
    } else {
        ColorSpace::Linear
    }
}

/// What a project's settings say of how it draws.
#[derive(Clone, Debug, PartialEq)]
pub struct Settings {
    /// The render pipeline `Packages/manifest.json` names, unless the graphics settings
    /// assign no pipeline asset (then the built-in one).
    pub pipeline: Pipeline,
    /// The pipeline the manifest lists where no asset assigns it, for a warning.
    pub unassigned_pipeline: Option<Pipeline>,
    /// The assigned render pipeline asset's file, where the project holds it.
    pub pipeline_asset: Option<PathBuf>,
    /// What a URP project's assigned pipeline asset lets lights do, where it is found.
    pub universal_asset: Option<UniversalAsset>,
    /// How lights' colours and intensities combine, from the pipeline and
    /// `ProjectSettings/GraphicsSettings.asset`.
    pub light_units: LightUnits,
    /// A built-in project without `ProjectSettings/GraphicsSettings.asset`, whose lights take
    /// Unity's default units.
    pub light_units_assumed: bool,
    /// The colour space `ProjectSettings/ProjectSettings.asset` sets (absent: linear).
    pub color_space: ColorSpace,
    /// The realtime shadows the current quality level allows a built-in project (`All` for
    /// URP and HDRP, whose pipeline assets decide, and where the file does not say).
    pub shadow_quality: ShadowQuality,
    /// `ProjectSettings/QualitySettings.asset`'s lodBias at its current quality level; 1
    /// when the file is absent or does not say (see [`crate::lod`]).
    pub lod_bias: f32,
}

impl Settings {
    /// The settings of the project at `root`, whose assets `guids` indexes.
    pub fn read(root: &Path, guids: &GuidIndex) -> Settings {
        let settings = |name: &str| settings_text(&root.join("ProjectSettings").join(name));
        let quality = settings("QualitySettings.asset");
        let graphics = settings("GraphicsSettings.asset");
        let listed = std::fs::read_to_string(root.join("Packages").join("manifest.json"))
            .map_or(Pipeline::BuiltIn, |m| Pipeline::of_manifest(&m));
        let asset = PipelineAsset::of(graphics.as_deref(), quality.as_deref());
        let pipeline = match asset {
            PipelineAsset::Unassigned => Pipeline::BuiltIn,
            _ => listed,
        };
        let pipeline_asset = match &asset {
            PipelineAsset::Assigned(Some(guid)) => guids.get(guid).cloned(),
            _ => None,
        };
        let universal_asset = pipeline_asset
            .as_deref()
            .filter(|_| pipeline == Pipeline::Universal)
            .and_then(settings_text)
            .and_then(|text| UniversalAsset::of_asset(&text));
        let color_space = settings("ProjectSettings.asset")
            .as_deref()
            .map_or(ColorSpace::Linear, color_space);
        Settings {
            pipeline,
            unassigned_pipeline: (pipeline != listed).then_some(listed),
            pipeline_asset,
            universal_asset,
            light_units: LightUnits::of(pipeline, graphics.as_deref(), color_space),
            light_units_assumed: pipeline == Pipeline::BuiltIn && graphics.is_none(),
            color_space,
            shadow_quality: quality
                .as_deref()
                .filter(|_| pipeline == Pipeline::BuiltIn)
                .and_then(crate::quality::shadows)
                .unwrap_or(ShadowQuality::All),
            lod_bias: quality
                .as_deref()
                .and_then(crate::quality::lod_bias)
                .unwrap_or(1.0),
        }
    }

    /// What a scene lit by `lights` should be told of these settings: defaults assumed for
    /// a missing file, a pipeline package left unassigned, shadows the quality level limits.
    pub fn notes(&self, lights: &[Light]) -> Vec<String> {
        let mut notes = Vec::new();
        // Only an intensity other than 1 lights differently in the two conventions.
        if self.light_units_assumed && lights.iter().any(|l| l.intensity != 1.0) {
            notes.push(
                "ProjectSettings/GraphicsSettings.asset is missing: lights take the built-in \
                 pipeline's default, gamma colour × intensity decoded (intensity 0.5 lights as \
                 0.21, 2 as 4.6); a project set to Lights Use Linear Intensity looks different"
                    .into(),
            );
        }
        if let Some(listed) = self.unassigned_pipeline {
            notes.push(format!(
                "Packages/manifest.json lists {}, but neither ProjectSettings/GraphicsSettings.asset \
                 nor the current quality level assigns a render pipeline asset: Unity draws the \
                 project with the built-in pipeline, and so does unitrace",
                listed.name()
            ));
        }
        let quality_says = match self.shadow_quality {
            ShadowQuality::Disable => Some("disables shadows: no light casts one"),
            ShadowQuality::HardOnly => {
                Some("allows hard shadows only: soft-shadow lights cast hard ones")
            }
            ShadowQuality::All => None,
        };
        if let Some(says) = quality_says.filter(|_| !lights.is_empty()) {
            notes.push(format!(
                "ProjectSettings/QualitySettings.asset: the current quality level {says}, as in Unity"
            ));
        }
        notes
    }

    /// What was read, in one line (for `--list`); `rel` names the pipeline asset's file.
    pub fn describe(&self, rel: impl Fn(&Path) -> String) -> String {
        let on = |b: bool| if b { "on" } else { "off" };
        let mut pipeline = self.pipeline.name().to_string();
        if let Some(path) = &self.pipeline_asset {
            pipeline += &format!(" (asset {}", rel(path));
            if let Some(u) = self.universal_asset {
                pipeline += &format!(
                    ": main light {}, additional lights {}, main-light shadows {}, \
                     additional-light shadows {}, soft shadows {}, shadow distance {} m \
                     (border {})",
                    on(u.main_light),
                    on(u.additional_lights),
                    on(u.main_shadows),
                    on(u.additional_shadows),
                    on(u.soft_shadows),
                    u.shadow_distance.distance,
                    u.shadow_distance.border
                );
            }
            pipeline += ")";
        }
        let units = self.light_units;
        let intensity = if units.gamma_space {
            "as stored (gamma space)"
        } else if units.linear_intensity {
            "linear"
        } else {
            "gamma"
        };
        let assumed = if self.light_units_assumed {
            ", no GraphicsSettings.asset: Unity's default"
        } else {
            ""
        };
        let space = match self.color_space {
            ColorSpace::Gamma => "Gamma",
            ColorSpace::Linear => "linear",
        };
        let shadows = match self.pipeline {
            Pipeline::BuiltIn => format!("; quality-level shadows {:?}", self.shadow_quality),
            _ => String::new(),
        };
        format!(
            "{pipeline}; light intensity {intensity}, colour temperature {}{assumed}; colour space {space}{shadows}; LOD bias {}",
            on(units.linear_intensity && units.color_temperature && !units.gamma_space),
            self.lod_bias
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn settings_files_are_read_up_to_a_bound() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("QualitySettings.asset");
        std::fs::write(&path, "m_CurrentQuality: 0\n").unwrap();
        assert_eq!(
            settings_text(&path).as_deref(),
            Some("m_CurrentQuality: 0\n")
        );
        let f = std::fs::File::create(&path).unwrap();
        f.set_len(SETTINGS_BYTES).unwrap();
        assert_eq!(
            settings_text(&path).map(|t| t.len()),
            Some(SETTINGS_BYTES as usize)
        );
        f.set_len(SETTINGS_BYTES + 1).unwrap();
        assert_eq!(settings_text(&path), None);
        assert_eq!(settings_text(&dir.path().join("absent")), None);
    }
}
