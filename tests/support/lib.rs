//! Support for the end-to-end tests: locating and running the real binaries.
