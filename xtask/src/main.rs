//! Project automation in the cargo-xtask style (see github.com/matklad/cargo-xtask):
//! `cargo xtask <command>`. The golden-image commands arrive with the issue
//! "Proof that it works and that it is faster".

#![allow(clippy::print_stdout, clippy::print_stderr, clippy::unwrap_used)]

fn main() -> std::process::ExitCode {
    let command = std::env::args().nth(1);
    match command.as_deref() {
        None | Some("help" | "--help" | "-h") => {
            println!("cargo xtask <command>\n\ncommands: (none yet; render-all and converge are planned)");
            std::process::ExitCode::SUCCESS
        }
        Some(other) => {
            eprintln!("xtask: unknown command `{other}`");
            std::process::ExitCode::from(2)
        }
    }
}
