//! Stage two: flags, scene defaults and presets become one validated render job.
//!
//! Precedence: a flag overrides the scene's `[render]` table, which overrides
//! [`ppm::RenderParams::preview`]. Flags are checked before anything is read, so a bad flag is
//! a usage error (exit 2) even when the scene is also missing.

use std::path::{Path, PathBuf};
use std::time::Duration;

use anyhow::Context;
use ppm::{Method, ParamError, RenderParams};
use scene::SceneDescription;

use crate::args::{AovArg, OutputArgs, ParamArgs, RenderArgs, RunArgs, TonemapArg};
use crate::output::{self, Tonemap};
use crate::{DEFAULT_SCENE, DEFAULT_SCENE_NAME, usage};

/// Passes rendered when neither the flags nor the scene give a budget.
pub(crate) const DEFAULT_PASSES: u32 = 16;
/// The EXR written when `-o` is not given.
pub(crate) const DEFAULT_EXR: &str = "fppm.exr";

/// A validated render: everything `render.rs` needs.
pub(crate) struct Job {
    /// Where the scene came from (`None`: the built-in default scene).
    pub(crate) scene_path: Option<PathBuf>,
    /// The `--env` map, absolute.
    pub(crate) env_path: Option<PathBuf>,
    /// The loaded scene, with the film overrides applied.
    pub(crate) description: SceneDescription,
    pub(crate) params: RenderParams,
    pub(crate) budget: Budget,
    pub(crate) outputs: Outputs,
    pub(crate) checkpoint: Option<PathBuf>,
    pub(crate) run: RunSettings,
    /// Render time of earlier runs (for a resumed render).
    pub(crate) earlier_seconds: f64,
}

/// When to stop: after `passes` passes in total or `time` of this run, whichever comes first.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Budget {
    pub(crate) passes: Option<u32>,
    pub(crate) time: Option<Duration>,
}

/// The output files and what goes into them.
#[derive(Clone, Debug)]
pub(crate) struct Outputs {
    pub(crate) exr: PathBuf,
    pub(crate) png: PathBuf,
    pub(crate) aovs: Vec<AovArg>,
    pub(crate) tonemap: Tonemap,
}

/// Threads, progress and snapshots.
#[derive(Clone, Copy, Debug)]
pub(crate) struct RunSettings {
    pub(crate) threads: Option<usize>,
    pub(crate) snapshot_every: Option<Duration>,
    pub(crate) quiet: bool,
    pub(crate) json: bool,
    pub(crate) max_memory: crate::memory::Limit,
}

/// What a checkpoint's note records so that `fppm resume` can go on: stored as JSON.
#[derive(Debug, serde::Serialize, serde::Deserialize)]
pub(crate) struct Note {
    /// Absolute scene path; `None` for the built-in default scene.
    pub(crate) scene: Option<PathBuf>,
    /// Absolute `--env` path, if given (absent from the notes of renders without).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(crate) env: Option<PathBuf>,
    /// Film size the render was started with (after `--width`/`--height`).
    pub(crate) width: u32,
    pub(crate) height: u32,
    /// Absolute output paths.
    pub(crate) exr: PathBuf,
    pub(crate) png: PathBuf,
    pub(crate) aovs: Vec<AovArg>,
    pub(crate) exposure: f32,
    pub(crate) tonemap: TonemapArg,
    /// The original budget.
    pub(crate) passes: Option<u32>,
    pub(crate) time_seconds: Option<f64>,
    /// Render time up to this checkpoint.
    pub(crate) render_seconds: f64,
}

/// `fppm render [SCENE]` (the default scene when `scene` is `None`).
pub(crate) fn render_job(scene: Option<&Path>, args: &RenderArgs) -> anyhow::Result<Job> {
    // Flags alone, before anything is read.
    let flagged = apply_flags(RenderParams::preview(), &args.params)?;
    flagged.validate().map_err(flag_error)?;
    let passes = passes_flag(args.budget.passes)?;
    let film = film_flags(args.film.width, args.film.height)?;
    let run = run_settings(&args.run)?;
    let outputs = outputs(&args.output, &args.aov, None)?;
    if let Some(checkpoint) = &args.checkpoint
        && checkpoint
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("exr") || e.eq_ignore_ascii_case("png"))
    {
        usage!(
            "--checkpoint {} would overwrite an image; use e.g. state.fppm",
            checkpoint.display()
        );
    }
    check_outputs(&outputs, args.checkpoint.as_deref())?;

    // The scene and its [render] defaults.
    let mut description = load_scene(scene, args.film.env.as_deref())?;
    apply_film(&mut description, film);
    let defaults = description.render.clone();
    let source = description.source.clone();
    let base = RenderParams::preview()
        .with_scene_defaults(&defaults)
        .map_err(|e| anyhow::anyhow!("{}: [render] {}", source.display(), param_message(&e)))?;
    let mut params = apply_flags(base, &args.params)?;
    // The photons per pass the render will use, so that the memory check, the image's metadata
    // and a checkpoint see the number, not `auto`.
    let film = description.film;
    params.resolve_photons_per_pass(
        (u64::from(film.width) * u64::from(film.height))
            .saturating_mul(u64::from(params.film.samples_per_pixel)),
    );
    params
        .validate()
        .map_err(|e| anyhow::anyhow!("{}: [render] {}", source.display(), param_message(&e)))?;
    check_aovs(&outputs.aovs, params.method)?;

    let budget = Budget {
        passes: passes.or(if args.budget.time.is_some() {
            None
        } else {
            Some(defaults.passes.unwrap_or(DEFAULT_PASSES).max(1))
        }),
        time: args.budget.time,
    };
    Ok(Job {
        scene_path: scene.map(absolute),
        env_path: args.film.env.as_deref().map(absolute),
        description,
        params,
        budget,
        outputs,
        checkpoint: args.checkpoint.clone(),
        run,
        earlier_seconds: 0.0,
    })
}

/// The scene file, or the built-in default scene, lit by the environment map `env` if given.
pub(crate) fn load_scene(
    scene: Option<&Path>,
    env: Option<&Path>,
) -> anyhow::Result<SceneDescription> {
    let options = import::LoadOptions {
        environment: env.map(Path::to_path_buf),
        ..import::LoadOptions::default()
    };
    Ok(match scene {
        Some(path) => import::load_with(path, &options)?,
        None => import::load_toml_str_with(DEFAULT_SCENE, Path::new(DEFAULT_SCENE_NAME), &options)?,
    })
}

/// `--width`/`--height` after their range check: both, one (the other follows the scene's
/// aspect ratio) or none.
pub(crate) type FilmOverride = (Option<u32>, Option<u32>);

fn film_flags(width: Option<u32>, height: Option<u32>) -> anyhow::Result<FilmOverride> {
    for (flag, value) in [("--width", width), ("--height", height)] {
        if let Some(v) = value
            && !(1..=scene::MAX_FILM_SIDE).contains(&v)
        {
            usage!("{flag} {v} is outside [1, {}]", scene::MAX_FILM_SIDE);
        }
    }
    Ok((width, height))
}

/// Sets the film size; a lone side keeps the scene's aspect ratio.
pub(crate) fn apply_film(description: &mut SceneDescription, (width, height): FilmOverride) {
    description.film = description.film.resized(width, height);
}

/// `--passes` must be at least 1.
pub(crate) fn passes_flag(passes: Option<i64>) -> anyhow::Result<Option<u32>> {
    match passes {
        None => Ok(None),
        Some(n) if n >= 1 => match u32::try_from(n) {
            Ok(n) => Ok(Some(n)),
            Err(_) => usage!("--passes {n} is too large (at most {})", u32::MAX),
        },
        Some(n) => usage!("--passes {n} must be at least 1"),
    }
}

pub(crate) fn run_settings(run: &RunArgs) -> anyhow::Result<RunSettings> {
    let threads = match run.threads {
        None => None,
        Some(n) if (1..=4096).contains(&n) => Some(n as usize),
        Some(n) => usage!("--threads {n} is outside [1, 4096]"),
    };
    Ok(RunSettings {
        threads,
        snapshot_every: run.snapshot_every,
        quiet: run.quiet,
        json: run.json,
        max_memory: crate::memory::Limit::from_flag(run.max_memory.as_deref())?,
    })
}

/// Output paths and tone mapping from the flags, falling back to a checkpoint's `note`.
pub(crate) fn outputs(
    args: &OutputArgs,
    aovs: &[AovArg],
    note: Option<&Note>,
) -> anyhow::Result<Outputs> {
    let exr = match (&args.exr, note) {
        (Some(p), _) => p.clone(),
        (None, Some(n)) => n.exr.clone(),
        (None, None) => PathBuf::from(DEFAULT_EXR),
    };
    if !has_extension(&exr, "exr") {
        usage!("-o {} must name an .exr file", exr.display());
    }
    let png = match (&args.png, note) {
        (Some(p), _) => p.clone(),
        (None, Some(n)) if args.exr.is_none() => n.png.clone(),
        _ => exr.with_extension("png"),
    };
    if !has_extension(&png, "png") {
        usage!("--png {} must name a .png file", png.display());
    }
    if absolute(&png) == absolute(&exr) {
        usage!("--png and -o name the same file {}", png.display());
    }
    let exposure = args.exposure.or(note.map(|n| n.exposure)).unwrap_or(0.0);
    if !exposure.is_finite() || exposure.abs() > 64.0 {
        usage!("--exposure {exposure} is outside [-64, 64]");
    }
    let curve = args
        .tonemap
        .or(note.map(|n| n.tonemap))
        .unwrap_or(TonemapArg::Srgb);
    let mut aov_list: Vec<AovArg> = if aovs.is_empty() {
        note.map(|n| n.aovs.clone()).unwrap_or_default()
    } else {
        aovs.to_vec()
    };
    aov_list.dedup();
    Ok(Outputs {
        exr,
        png,
        aovs: aov_list,
        tonemap: Tonemap { exposure, curve },
    })
}

/// Fails early (exit 1) if an output cannot be created in its directory.
pub(crate) fn check_outputs(outputs: &Outputs, checkpoint: Option<&Path>) -> anyhow::Result<()> {
    output::check_writable(&outputs.exr, "-o")?;
    output::check_writable(&outputs.png, "--png")?;
    if let Some(c) = checkpoint {
        output::check_writable(c, "--checkpoint")?;
    }
    Ok(())
}

/// AOVs the chosen method cannot produce are a usage error.
pub(crate) fn check_aovs(aovs: &[AovArg], method: Method) -> anyhow::Result<()> {
    for &aov in aovs {
        let ok = match aov {
            AovArg::Radius | AovArg::Count | AovArg::PoolWidth => method.is_photon_mapper(),
            AovArg::Freq => method.uses_frequency(),
            AovArg::Albedo | AovArg::Normal | AovArg::Depth => true,
        };
        if !ok {
            let needs = if aov == AovArg::Freq {
                "a frequency method (freq or freq-sppm)"
            } else {
                "a photon mapping method (ppm, sppm, freq or freq-sppm)"
            };
            usage!(
                "--aov {} needs {needs}, but the method is {}",
                aov.name(),
                method.name()
            );
        }
    }
    Ok(())
}

/// The flags over `base`. Only conversions are checked here; ranges are checked by
/// [`RenderParams::validate`].
fn apply_flags(base: RenderParams, flags: &ParamArgs) -> anyhow::Result<RenderParams> {
    let mut p = base;
    for (name, value) in &flags.values {
        p.set(name, value).map_err(flag_error)?;
    }
    Ok(p)
}

/// A [`ParamError`] of the flags as a usage error naming the flag.
fn flag_error(e: ParamError) -> anyhow::Error {
    anyhow::Error::new(crate::UsageError(match &e {
        ParamError::OutOfRange { name, value, range } => {
            format!("--{} {value} is outside {range}", flag_name(name))
        }
        ParamError::Unreadable {
            name,
            value,
            problem,
        } => format!("--{} {value} {problem}", flag_name(name)),
        other => other.to_string(),
    }))
}

/// The flag of the parameter called `name`.
fn flag_name(name: &str) -> &str {
    ppm::param(name).map_or(name, |p| p.flag)
}

/// `alpha 1.5 is outside (0, 1]`.
fn param_message(e: &ParamError) -> String {
    match e {
        ParamError::OutOfRange { name, value, range } => {
            format!("{name} {value} is outside {range}")
        }
        other => other.to_string(),
    }
}

fn has_extension(path: &Path, extension: &str) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case(extension))
}

/// The note of a checkpoint (or plan) of `job` after `render_seconds` of rendering.
pub(crate) fn note_for(job: &Job, render_seconds: f64) -> Note {
    let film = job.description.film;
    Note {
        scene: job.scene_path.clone(),
        env: job.env_path.clone(),
        width: film.width,
        height: film.height,
        exr: absolute(&job.outputs.exr),
        png: absolute(&job.outputs.png),
        aovs: job.outputs.aovs.clone(),
        exposure: job.outputs.tonemap.exposure,
        tonemap: job.outputs.tonemap.curve,
        passes: job.budget.passes,
        time_seconds: job.budget.time.map(|t| t.as_secs_f64()),
        render_seconds,
    }
}

/// The absolute form of a path (the file need not exist).
pub(crate) fn absolute(path: &Path) -> PathBuf {
    std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf())
}

/// Reads a checkpoint's note.
pub(crate) fn read_note(checkpoint: &Path, note: &str) -> anyhow::Result<Note> {
    serde_json::from_str(note).with_context(|| {
        format!(
            "{}: checkpoint note is not one fppm render writes (was it made by another program?)",
            checkpoint.display()
        )
    })
}
