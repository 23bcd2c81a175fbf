//! What accuracy costs in time: a converged reference per scene, each render knob swept
//! alone from the defaults, every point timed and compared with the reference, written
//! as a markdown table with a reading and an error-vs-time SVG (`accuracy` binary).

pub mod metrics;
pub mod plot;
pub mod report;
pub mod scenes;
pub mod sweep;

pub use metrics::{compare, Errors};
pub use sweep::{measure, Config, SceneResult};
