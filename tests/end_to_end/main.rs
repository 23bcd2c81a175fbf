//! End-to-end tests of the real binaries, in one test binary so the workspace links it
//! once: the pipeline on a Unity project with known pixels, bad input at every stage, merging
//! crop tiles, and (ignored by default) a million rays through `raycast` against brute force
//! and a frame rendered on a throwaway Slurm cluster.

mod draw_rules;
mod million_rays;
mod pipeline;
mod reliability;
mod slurm;
mod terrain;
mod textures;
