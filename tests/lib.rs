//! Workspace integration tests; the test binary lives in `it/main.rs`.
