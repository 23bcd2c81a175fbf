//! The k-d tree crate's integration tests, one binary (linking dominates their build):
//! equivalence with brute force, the numerical hard cases, and the command-line tools.

mod brute_equivalence;
mod cli;
mod watertight;
