//! Test scenes: see `kdtree::gen`.
#![allow(unused_imports)]
pub use kdtree::gen::*;
