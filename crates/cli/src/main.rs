//! The `fppm` command: not yet available; filled by the issue
//! "The `fppm` command: render any scene, a built-in default, EXR and PNG".

#![allow(clippy::print_stderr)]

fn main() -> std::process::ExitCode {
    eprintln!("fppm: rendering is not yet available (the integrators are still being built)");
    std::process::ExitCode::from(1)
}
