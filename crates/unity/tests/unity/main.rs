//! The crate's integration tests, one binary: the command-line tools, conversions of
//! tiny hand-written projects, and the real projects of the corpus.

mod cli;
mod convert;
mod corpus;
mod support;
