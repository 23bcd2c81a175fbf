//! Arbitrary output variables: extra EXR channels beside RGBA.

use crate::RenderError;
use serde::Serialize;

/// One render pass that `--aov` can add to the EXR.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Aov {
    /// `Z`: distance along the camera ray to the first hit (f32; misses hold f32::MAX).
    Depth,
    /// `N.x N.y N.z`: world-space shading normal facing the camera (0 on misses).
    Normal,
    /// `albedo.R albedo.G albedo.B`: the Lambert albedo of the first hit (0 on misses).
    Albedo,
    /// `object`: the soup object index of the first hit as a float (−1 on misses).
    Object,
}

impl Aov {
    pub const ALL: [Aov; 4] = [Aov::Depth, Aov::Normal, Aov::Albedo, Aov::Object];

    pub fn name(self) -> &'static str {
        match self {
            Aov::Depth => "depth",
            Aov::Normal => "normal",
            Aov::Albedo => "albedo",
            Aov::Object => "object",
        }
    }

    /// EXR channel names, in the order the values are stored.
    pub fn channels(self) -> &'static [&'static str] {
        match self {
            Aov::Depth => &["Z"],
            Aov::Normal => &["N.x", "N.y", "N.z"],
            Aov::Albedo => &["albedo.R", "albedo.G", "albedo.B"],
            Aov::Object => &["object"],
        }
    }
}

/// Which AOVs a render writes (each at most once, in a fixed order).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct AovSet {
    pub depth: bool,
    pub normal: bool,
    pub albedo: bool,
    pub object: bool,
}

impl AovSet {
    pub fn all() -> Self {
        AovSet {
            depth: true,
            normal: true,
            albedo: true,
            object: true,
        }
    }

    /// Parse a comma-separated list such as `depth,normal`.
    pub fn parse(list: &str) -> Result<Self, RenderError> {
        let mut set = AovSet::default();
        for word in list.split(',').map(str::trim).filter(|w| !w.is_empty()) {
            match word {
                "depth" | "z" | "Z" => set.depth = true,
                "normal" | "N" => set.normal = true,
                "albedo" => set.albedo = true,
                "object" => set.object = true,
                other => {
                    return Err(RenderError::Option(format!(
                        "unknown AOV {other:?}: choose from depth, normal, albedo, object"
                    )))
                }
            }
        }
        Ok(set)
    }

    pub fn contains(&self, aov: Aov) -> bool {
        match aov {
            Aov::Depth => self.depth,
            Aov::Normal => self.normal,
            Aov::Albedo => self.albedo,
            Aov::Object => self.object,
        }
    }

    pub fn list(&self) -> Vec<Aov> {
        Aov::ALL.into_iter().filter(|a| self.contains(*a)).collect()
    }

    pub fn any(&self) -> bool {
        self.depth || self.normal || self.albedo || self.object
    }

    /// Number of extra channels these AOVs add.
    pub fn channel_count(&self) -> usize {
        self.list().iter().map(|a| a.channels().len()).sum()
    }
}
