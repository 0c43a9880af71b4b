//! The `fppm` command: render scenes with progressive photon mapping (PPM, SPPM and their
//! frequency-guided variants) and write EXR and PNG images.
//!
//! The command is thin, in two stages as in ripgrep: clap parses the flags into plain
//! structs (`args.rs`), `settings.rs` turns them into a validated [`ppm::RenderParams`], a
//! loaded scene, a budget and output paths, and `render.rs` drives [`ppm::Renderer`] pass by
//! pass, reporting progress and writing the outputs (`output.rs`) atomically.
//!
//! Exit codes: 0 success, 1 load/render/IO error, 2 usage error (bad flag or value),
//! 130 interrupted by Ctrl-C (outputs and checkpoint written).
//! Every error is one line on stderr: `fppm: <message>`.

// A binary reports on its own streams.
#![allow(clippy::print_stderr, clippy::print_stdout)]

mod args;
mod diff;
mod duration;
mod live;
mod memory;
mod output;
mod progress;
mod render;
mod settings;
mod trend;
mod units;

use std::io::Write;
use std::path::Path;
use std::process::ExitCode;

use clap::Parser;

use crate::args::{Cli, Command};

/// The built-in default scene (see `fppm scene default`).
pub(crate) const DEFAULT_SCENE: &str = include_str!("default_scene.toml");

/// The name the built-in default scene is loaded under (and that errors name).
pub(crate) const DEFAULT_SCENE_NAME: &str = "<built-in default scene>";

/// A usage error: a bad flag or flag value. Exits with code 2.
#[derive(Debug)]
pub(crate) struct UsageError(pub(crate) String);

impl std::fmt::Display for UsageError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for UsageError {}

/// Returns early with a [`UsageError`].
macro_rules! usage {
    ($($arg:tt)*) => {
        return Err(anyhow::Error::new($crate::UsageError(format!($($arg)*))))
    };
}
pub(crate) use usage;

/// How a successful command ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Outcome {
    /// Everything done.
    Done,
    /// Stopped by Ctrl-C after writing the outputs.
    Interrupted,
}

fn main() -> ExitCode {
    // A dependency's panic that a loader contains becomes that loader's one-line error: its
    // panic message is not printed first. Any other panic is reported as Rust does.
    let default_hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        if !import::containing_a_panic() {
            default_hook(info);
        }
    }));
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(err) => return clap_error(&err),
    };
    match run(cli) {
        Ok(Outcome::Done) => ExitCode::SUCCESS,
        Ok(Outcome::Interrupted) => ExitCode::from(130),
        Err(err) => {
            // A bad spectrum, medium or density grid in a scene is a usage error, as the issues
            // of spectra and media ask.
            let bad_value = err
                .downcast_ref::<import::LoadError>()
                .is_some_and(import::LoadError::is_bad_value);
            let code = if err.downcast_ref::<UsageError>().is_some() || bad_value {
                2
            } else {
                1
            };
            report_error(&error_chain(&err));
            ExitCode::from(code)
        }
    }
}

fn run(cli: Cli) -> anyhow::Result<Outcome> {
    match cli.command {
        None => render::render(None, &cli.render),
        Some(Command::Render { scene, mut args }) => {
            let scene = args.live.scene_of_render(scene)?;
            render::render(Some(&scene), &args)
        }
        Some(Command::Resume(args)) => render::resume(&args),
        Some(Command::Diff(args)) => diff::diff(&args),
        Some(Command::Info { scene, env }) => info(scene.as_deref(), env),
        Some(Command::Plan(args)) => units::plan(args),
        Some(Command::Unit(args)) => units::unit(&args),
        Some(Command::Merge(args)) => units::merge(&args),
        Some(Command::Scene { name: _ }) => {
            print_stdout(DEFAULT_SCENE)?;
            Ok(Outcome::Done)
        }
    }
}

/// `fppm info [SCENE]`: what was loaded, without rendering.
fn info(scene: Option<&Path>, env: Option<std::path::PathBuf>) -> anyhow::Result<Outcome> {
    let options = import::LoadOptions {
        environment: env,
        ..import::LoadOptions::allow_no_emitter()
    };
    let description = match scene {
        Some(path) => import::load_with(path, &options)?,
        None => import::load_toml_str_with(DEFAULT_SCENE, Path::new(DEFAULT_SCENE_NAME), &options)?,
    };
    let summary = description.summary();
    let mut text = summary.to_string();
    if summary.emitters() == 0 {
        text.push_str("emitters   none: this scene has no emitter and renders black\n");
    }
    print_stdout(&text)?;
    Ok(Outcome::Done)
}

/// Writes to stdout; a closed pipe (`fppm scene default | head`) is not an error.
pub(crate) fn print_stdout(text: &str) -> anyhow::Result<()> {
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => Err(e.into()),
        _ => Ok(()),
    }
}

/// The error and its causes joined by `: `, skipping a cause whose text the message already
/// holds (library errors such as `import::LoadError` quote their source).
fn error_chain(err: &anyhow::Error) -> String {
    let mut message = String::new();
    for cause in err.chain() {
        let text = cause.to_string();
        if message.is_empty() {
            message = text;
        } else if !message.to_lowercase().contains(&text.to_lowercase()) {
            message.push_str(": ");
            message.push_str(&text);
        }
    }
    message
}

/// Prints `fppm: message` on one line.
fn report_error(message: &str) {
    let one_line: Vec<&str> = message
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .collect();
    eprintln!("fppm: {}", one_line.join(" "));
}

/// Help and version go to stdout with exit code 0; usage errors become one line and exit 2.
fn clap_error(err: &clap::Error) -> ExitCode {
    use clap::error::ErrorKind;
    if matches!(
        err.kind(),
        ErrorKind::DisplayHelp
            | ErrorKind::DisplayVersion
            | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand
    ) {
        let _ = err.print();
        return ExitCode::from(
            if err.kind() == ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand {
                2
            } else {
                0
            },
        );
    }
    // clap renders "error: <problem>\n  <details>\n\nUsage: ...\n\nFor more information ...":
    // keep what comes before "Usage:" on one line.
    let rendered = err.render().to_string();
    let problem: Vec<&str> = rendered
        .lines()
        .take_while(|l| !l.starts_with("Usage:"))
        .map(str::trim)
        .filter(|l| {
            !l.is_empty() && !l.starts_with("tip:") && !l.starts_with("For more information")
        })
        .collect();
    let message = problem.join(" ");
    let message = message.strip_prefix("error: ").unwrap_or(&message);
    eprintln!("fppm: {message} (see fppm --help)");
    ExitCode::from(2)
}
