//! The renderer's integration tests, in one binary so the workspace links it once: the
//! `kd2exr` command line, EXR output, known pixel values, the effects plan and robust
//! secondary rays. `common` builds the small scenes they render.

mod cli;
mod common;
mod draw_rules;
mod exr;
mod fog;
mod highlights;
mod lighting;
mod metallic;
mod plan;
mod reflections;
mod robustness;
mod textures;
