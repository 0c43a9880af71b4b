//! Project automation in the cargo-xtask style (see github.com/matklad/cargo-xtask):
//! `cargo xtask <command>`.
//!
//! - `render-all`: golden-image checks of every method against path-traced references.
//! - `converge`: error versus time of every method on one scene (CSV, SVG plots, masks, maps).
//! - `docs-image`: renders the CLI's default scene for `docs/default-scene.png`.
//! - `peers`: equal-time comparison with Mitsuba 3 against pixel-averaged references.
//! - `farm-test`: work units on a one-node Slurm cluster, merged bit for bit.
//! - `fuzz`: runs the cargo-fuzz targets of `fuzz/` and reports executions and crashes.

#![allow(clippy::print_stdout, clippy::print_stderr, clippy::unwrap_used)]

mod converge;
mod docs_image;
mod farm;
mod fuzz;
mod luxcore;
mod meshes;
mod peers;
#[cfg(test)]
mod peers_tests;
mod render_all;
mod suite;
#[cfg(test)]
mod tests;

use std::path::{Path, PathBuf};
use std::process::ExitCode;

const HELP: &str = "\
cargo xtask <command> [flags]

commands:
  render-all   golden-image check of every scene of tests/scenes.toml (see `render-all --help`)
  converge     error-versus-time study of one scene (see `converge --help`)
  docs-image   render docs/default-scene.png with the fppm binary
  peers        equal-time comparison with Mitsuba 3 (see `peers --help`)
  farm-test    work units on a local one-node Slurm cluster, merged bit for bit (needs root)
  fuzz         run the fuzz targets (nightly, cargo-fuzz; see `fuzz --help`)";

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some(command) = args.first() else {
        println!("{HELP}");
        return ExitCode::SUCCESS;
    };
    let rest = &args[1..];
    if rest.iter().any(|a| a == "--help" || a == "-h") {
        let help = match command.as_str() {
            "render-all" => render_all::HELP,
            "converge" => converge::HELP,
            "docs-image" => docs_image::HELP,
            "peers" => peers::HELP,
            "farm-test" => farm::HELP,
            "fuzz" => fuzz::HELP,
            _ => HELP,
        };
        println!("{help}");
        return ExitCode::SUCCESS;
    }
    let root = project_root();
    let result = match command.as_str() {
        "help" | "--help" | "-h" => {
            println!("{HELP}");
            Ok(true)
        }
        "render-all" => render_all::run(&root, rest),
        "converge" => converge::run(&root, rest),
        "docs-image" => docs_image::run(&root, rest),
        "peers" => peers::run(&root, rest),
        "farm-test" => farm::run(&root, rest),
        "fuzz" => fuzz::run(&root, rest),
        other => {
            eprintln!("xtask: unknown command `{other}`\n\n{HELP}");
            return ExitCode::from(2);
        }
    };
    match result {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::from(1),
        Err(error) => {
            eprintln!("xtask: {error:#}");
            ExitCode::from(2)
        }
    }
}

/// The workspace root: the parent of this crate's manifest directory.
fn project_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("xtask lives one level below the workspace root")
        .to_path_buf()
}
