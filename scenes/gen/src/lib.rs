//! Generator of the Unity projects bundled in `scenes/`: the original Haskell ray tracer's
//! baseline scene (OBJ models at exact triangle counts), one small project per rendering
//! effect, the textured and alpha-blended Quads of `textures`, `skybox`'s sky from an
//! HDR image, and `terrain`'s Unity Terrain.
//!
//! Everything is built in memory first ([`project::Project`]), so the same bytes are
//! written to disk by the binary and compared with the committed files by the tests.

pub mod baseline;
pub mod effects;
pub mod fbx;
pub mod fbx_scene;
pub mod ids;
pub mod material;
pub mod mesh;
pub mod meta;
pub mod models;
pub mod project;
pub mod sky;
pub mod terrain;
pub mod textures;
pub mod unity;

/// Every bundled project, baseline first.
pub fn all_projects() -> Vec<project::Project> {
    let mut v = vec![baseline::project()];
    v.extend(effects::all());
    v.push(textures::project());
    v.push(sky::project());
    v.push(terrain::project());
    v
}
