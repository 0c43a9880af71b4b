//! Integration tests of the integrators against independent references: analytic scenes, the
//! path tracer, and the laws every progressive render must keep (determinism, exact resume).

#![allow(
    clippy::unwrap_used,
    clippy::print_stdout,
    clippy::print_stderr,
    missing_docs
)]

mod agreement;
mod analytic;
mod checkpoint;
mod determinism;
mod environment;
mod frequency;
mod kernels;
mod light_tracer;
mod light_tracing;
mod media;
mod memory;
mod non_finite;
mod pooling;
mod statistics;
mod support;
mod vcm;
