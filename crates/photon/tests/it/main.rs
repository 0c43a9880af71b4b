//! Integration tests of the `photon` crate: grid queries against a brute-force scan.
#![allow(clippy::unwrap_used, missing_docs)]

mod gather;
mod grid;
