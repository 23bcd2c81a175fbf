//! Helpers for tests and benchmarks, not for the product: closed meshes whose neighbouring
//! triangles share bit-identical vertices (the watertightness premise), flat grids, the
//! rays that must not leave a closed mesh, a small deterministic RNG, and brute-force
//! references to check the tree against.
//!
//! Compiled for this crate's own tests and behind the `testkit` feature, which the bench
//! crate and the workspace's end-to-end tests turn on.

pub mod brute;
mod meshes;
mod rng;

pub use meshes::{escapes, grid, grid_box, rays_inside, sphere};
pub use rng::Rng;
