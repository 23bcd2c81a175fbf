//! The crate's integration tests, one binary: the command-line tools, conversions of
//! tiny hand-written projects, the FBX reader on hand-written ASCII files (and under
//! concurrent loads), and the real projects of the corpus.

mod cli;
mod convert;
mod corpus;
mod draw_rules;
mod fbx;
mod fbx_ascii;
mod fbx_corpus;
mod fbx_scene;
mod fbx_threads;
mod fuzz_seeds;
mod skybox;
mod support;
mod textures;
