//! The bench crate's integration tests, one binary (linking dominates their build): the
//! quick benchmark in process, the accuracy report on a tiny scene, and the corpus meshes.

mod accuracy;
mod corpus;
mod quick;
