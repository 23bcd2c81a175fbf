//! The k-d tree crate's integration tests, one binary (linking dominates their build):
//! equivalence with brute force, four-ray packets against single rays, the numerical hard
//! cases, no subnormal arithmetic on spawned rays, and the command-line tools.

mod brute_equivalence;
mod cli;
mod packets;
mod subnormals;
mod watertight;
