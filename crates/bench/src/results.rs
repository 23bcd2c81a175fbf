//! The result rows a run produces, scene by scene, and the report that holds them.

use crate::config::Config;

/// Which ray set.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    Primary,
    /// The same camera rays in blocks of 4, 8 or 16 pixels, each block one packet query.
    PrimaryPackets(usize),
    Shadow,
    /// Shadow rays from the packets' primary hits, in their order, one packet per block.
    ShadowPackets(usize),
    /// A soft shadow's samples as the renderer traces them: from primary hits, several per
    /// hit toward a small cone around a sun direction, each traced alone.
    Soft,
    /// The same rays, one packet per hit (its samples share their origin).
    SoftPackets(usize),
    Random,
    /// From random surface points toward the light, closest hit.
    SurfaceLight,
    /// The same rays, any hit.
    SurfaceLightAny,
    /// From random surface points into the normal's hemisphere, closest hit.
    SurfaceHemisphere,
    /// The same rays, any hit.
    SurfaceHemisphereAny,
}

impl Kind {
    /// Every ray set, the packet ones in packets of `packet` rays.
    pub fn all(packet: usize) -> [Kind; 11] {
        [
            Kind::Primary,
            Kind::PrimaryPackets(packet),
            Kind::Shadow,
            Kind::ShadowPackets(packet),
            Kind::Soft,
            Kind::SoftPackets(packet),
            Kind::Random,
            Kind::SurfaceLight,
            Kind::SurfaceLightAny,
            Kind::SurfaceHemisphere,
            Kind::SurfaceHemisphereAny,
        ]
    }
    pub fn name(self) -> &'static str {
        match self {
            Kind::Primary => "primary",
            Kind::PrimaryPackets(4) => "primary ×4",
            Kind::PrimaryPackets(8) => "primary ×8",
            Kind::PrimaryPackets(_) => "primary ×16",
            Kind::Shadow => "shadow",
            Kind::ShadowPackets(4) => "shadow ×4",
            Kind::ShadowPackets(8) => "shadow ×8",
            Kind::ShadowPackets(_) => "shadow ×16",
            Kind::Soft => "soft",
            Kind::SoftPackets(4) => "soft ×4",
            Kind::SoftPackets(8) => "soft ×8",
            Kind::SoftPackets(_) => "soft ×16",
            Kind::Random => "random",
            Kind::SurfaceLight => "surface→light",
            Kind::SurfaceLightAny => "surface→light any",
            Kind::SurfaceHemisphere => "surface→hemisphere",
            Kind::SurfaceHemisphereAny => "surface→hemisphere any",
        }
    }
    /// Traced as any-hit (occlusion) queries rather than closest hits.
    pub fn any_hit(self) -> bool {
        matches!(
            self,
            Kind::Shadow
                | Kind::ShadowPackets(_)
                | Kind::Soft
                | Kind::SoftPackets(_)
                | Kind::SurfaceLightAny
                | Kind::SurfaceHemisphereAny
        )
    }
}

/// The k-d tree's work per ray on one ray set, with the origins as generated (just off
/// the surface) or moved 5 mm along the ray.
#[derive(Clone, Debug)]
pub struct WorkRow {
    pub kind: Kind,
    pub moved: bool,
    pub rays: usize,
    pub counts: kdtree::Counts,
}

#[derive(Clone, Debug)]
pub struct BuildRow {
    pub scene: String,
    pub triangles: usize,
    pub contender: String,
    pub threads: usize,
    /// Median wall time of the build.
    pub seconds: f64,
    pub sah_cost: Option<f64>,
    pub nodes: Option<u64>,
    /// Leaf references per input triangle.
    pub refs_per_triangle: Option<f64>,
    /// Memory held for queries, per input triangle.
    pub bytes_per_triangle: Option<f64>,
}

#[derive(Clone, Debug)]
pub struct TraceRow {
    pub scene: String,
    pub contender: String,
    pub threads: usize,
    pub kind: Kind,
    pub rays: usize,
    /// Median wall time of tracing all `rays`.
    pub seconds: f64,
}

impl TraceRow {
    pub fn mrays_per_s(&self) -> f64 {
        self.rays as f64 / self.seconds / 1e6
    }
}

#[derive(Clone, Debug)]
pub struct AgreeRow {
    pub scene: String,
    /// The contender compared with the k-d tree.
    pub other: String,
    pub kind: Kind,
    pub compared: usize,
    pub disagreements: usize,
    /// The first few disagreements, for the log.
    pub examples: Vec<String>,
    /// Brute force's verdict on the disagreements (Embree rows only).
    pub referee: Option<Referee>,
}

impl AgreeRow {
    pub fn agreement(&self) -> f64 {
        if self.compared == 0 {
            1.0
        } else {
            1.0 - self.disagreements as f64 / self.compared as f64
        }
    }
    /// The bar: at least 99.99% of rays agree.
    pub fn ok(&self) -> bool {
        self.agreement() >= 0.9999
    }
}

/// Where a scene came from (the targets single out the baseline and generated scenes).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Role {
    Baseline,
    Mesh,
    Generated,
}

pub struct SceneResult {
    pub name: String,
    pub role: Role,
    pub triangles: usize,
    pub builds: Vec<BuildRow>,
    pub traces: Vec<TraceRow>,
    pub agreement: Vec<AgreeRow>,
    pub work: Vec<WorkRow>,
    /// Per thread count: (CPU seconds, wall seconds) this process spent tracing. Their
    /// ratio is the number of cores the run actually got on a shared machine.
    pub cpu: std::collections::BTreeMap<usize, (f64, f64)>,
}

pub struct Report {
    pub config: Config,
    /// `- key: value` lines for the top of the report.
    pub header: Vec<String>,
    pub scenes: Vec<SceneResult>,
    /// Scenes skipped and why, notes on scenes.
    pub notes: Vec<String>,
}

impl Report {
    /// Every agreement check passed.
    pub fn all_agree(&self) -> bool {
        self.scenes
            .iter()
            .flat_map(|s| &s.agreement)
            .all(AgreeRow::ok)
    }
}

/// Brute force's verdict on disagreeing rays (a ray can side with both when the two
/// answers are ties, or with neither).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Referee {
    pub checked: usize,
    pub kdtree_right: usize,
    pub other_right: usize,
}
