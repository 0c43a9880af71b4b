//! Gather benchmark (placeholder).
fn main() {}
