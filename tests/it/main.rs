//! Integration tests that span several crates: one binary, one module per area.

#![allow(
    clippy::unwrap_used,
    clippy::print_stdout,
    clippy::print_stderr,
    missing_docs
)]

mod architecture;
mod mitsuba_roundtrip;
mod pbrt_by_hand;
mod shared_scenes;
