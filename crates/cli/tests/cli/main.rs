//! Tests of the `fppm` binary.

fn main() {}
