//! `cargo xtask docs-image`: renders the CLI's built-in default scene into
//! `docs/default-scene.png` by running the `fppm` binary in release mode.

use std::path::Path;
use std::process::Command;

use anyhow::{Context, Result, bail};

pub(crate) const HELP: &str = "\
cargo xtask docs-image [-- EXTRA FPPM FLAGS]

Runs `cargo run --release -p cli -- -o target/docs-image/default-scene.exr --png
docs/default-scene.png [EXTRA]` from the workspace root: the built-in default scene of the CLI
rendered with its default settings (the EXR stays under target/).";

pub(crate) fn run(root: &Path, args: &[String]) -> Result<bool> {
    let extra: Vec<&String> = args.iter().skip_while(|a| *a == "--").collect();
    std::fs::create_dir_all(root.join("target/docs-image"))?;
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".to_string());
    let mut command = Command::new(cargo);
    command
        .current_dir(root)
        .args([
            "run",
            "--release",
            "-p",
            "cli",
            "--",
            "-o",
            "target/docs-image/default-scene.exr",
            "--png",
            "docs/default-scene.png",
        ])
        .args(extra);
    println!("docs-image: {command:?}");
    let status = command.status().context("running cargo")?;
    if !status.success() {
        bail!("fppm failed ({status}); check `cargo run --release -p cli -- --help` for its flags");
    }
    println!("docs-image: wrote docs/default-scene.png");
    Ok(true)
}
