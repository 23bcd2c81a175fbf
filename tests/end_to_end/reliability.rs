//! Bad input never crashes a stage or loses data (the table is docs/RELIABILITY.md).
//!
//! Every case runs a real binary on one bad input made in a temporary folder and checks
//! the exit code (1 for bad input, 2 for bad usage, 0 where the stage converts the rest
//! with a warning), that stderr names the input (file path, object name or byte offset),
//! that nothing panicked, and what happened to the output: not written, the previous file
//! left byte for byte, or (for warnings) written.
//!
//! Cases are tables; a table reports every failing case at once.

mod atomic_outputs;
mod bad_usage;
mod cases;
mod damaged_artifacts;
mod noise;
mod obj_models;
mod project;
mod render_options;
mod unity_input;
