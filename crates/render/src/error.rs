//! The renderer's typed errors. Each names what was wrong so that `kd2exr` can print it
//! as one line.

use std::path::PathBuf;

#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    #[error("invalid option: {0}")]
    Option(String),
    #[error("the camera {name:?} cannot form an image: {detail}")]
    Camera { name: String, detail: String },
    #[error(
        "a {width}×{height} render with {channels} channels needs about {need_gib:.1} GiB, \
         only {available_gib:.1} GiB of memory is available: render it in --crop tiles and \
         join them with `kd2exr merge`"
    )]
    OutOfMemory {
        width: u32,
        height: u32,
        channels: usize,
        need_gib: f64,
        available_gib: f64,
    },
    #[error(transparent)]
    Accel(#[from] kdtree::AccelError),
    #[error("cannot build a pool of {threads} threads: {detail}")]
    Threads { threads: usize, detail: String },
    #[error("{path}: cannot write the EXR: {detail}")]
    ExrWrite { path: PathBuf, detail: String },
    #[error("{path}: cannot read the EXR: {detail}")]
    ExrRead { path: PathBuf, detail: String },
    #[error("{path}: cannot write the PNG: {detail}")]
    PngWrite { path: PathBuf, detail: String },
    #[error("cannot merge: {0}")]
    Merge(String),
    #[error(transparent)]
    Format(#[from] formats::FormatError),
}
