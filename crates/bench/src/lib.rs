//! Side-by-side measurements of the k-d tree: build time, SAH cost and memory, and
//! traversal throughput on primary, shadow, random and surface-origin rays, against brute
//! force and (with the `embree` feature) Embree 3 on the same triangles and rays, 1 and 2
//! threads.
//! Every run also checks that the contenders agree on the hits.
//!
//! [`run::run`] does the work; [`report::markdown`] renders it; the `kdbench` binary is
//! a thin command line over both.

pub mod accuracy;
pub mod agreement;
pub mod binned_build;
pub mod config;
pub mod contenders;
#[cfg(feature = "embree")]
pub mod embree;
pub mod error;
pub mod header;
pub mod measure;
pub mod plain;
pub mod rays;
pub mod report;
pub mod results;
pub mod run;
pub mod scenes;

pub use config::Config;
pub use error::BenchError;
pub use results::Report;
pub use run::run;
