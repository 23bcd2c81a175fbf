//! The k-d tree crate's integration tests, one binary (linking dominates their build):
//! equivalence with brute force, four-ray packets against single rays, the numerical hard
//! cases, and the command-line tools.

mod brute_equivalence;
mod cli;
mod packets;
mod watertight;
