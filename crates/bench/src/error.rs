//! What can go wrong while benchmarking, each naming the file or object involved.

use std::path::PathBuf;

#[derive(Debug, thiserror::Error)]
pub enum BenchError {
    #[error(transparent)]
    Format(#[from] formats::FormatError),
    #[error("{path}: cannot load the OBJ: {source}")]
    Obj {
        path: PathBuf,
        source: tobj::LoadError,
    },
    #[error("{path}: no triangles to benchmark")]
    Empty { path: PathBuf },
    #[error("{path}: {source}")]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("cannot start a pool of {threads} threads: {detail}")]
    Pool { threads: usize, detail: String },
    #[error("scene {scene}: the k-d tree does not fit its triangles: {detail}")]
    Accel { scene: String, detail: String },
    #[cfg(feature = "embree")]
    #[error("scene {scene}: {source}")]
    Embree {
        scene: String,
        source: crate::embree::EmbreeError,
    },
}
