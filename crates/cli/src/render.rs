//! The render loop: passes until the budget is spent or Ctrl-C, with progress, snapshots,
//! checkpoints, and the outputs at the end.

use std::io::IsTerminal;
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use anyhow::Context;
use indicatif::{ProgressBar, ProgressStyle};
use ppm::{PassStats, Renderer, StateHeader};

use crate::args::{RenderArgs, ResumeArgs};
use crate::duration;
use crate::settings::{self, Budget, Job};
use crate::{DEFAULT_SCENE_NAME, Outcome, usage};

/// Set by the Ctrl-C handler; the loop stops after the current pass.
static INTERRUPTED: AtomicBool = AtomicBool::new(false);

/// `fppm render` (and `fppm` alone, with `scene = None`).
pub(crate) fn render(scene: Option<&Path>, args: &RenderArgs) -> anyhow::Result<Outcome> {
    let job = settings::render_job(scene, args)?;
    check_memory(&job)?;
    let scene = std::sync::Arc::new(scene::Scene::new(job.description.clone())?);
    in_pool(job.run.threads, || {
        let renderer = Renderer::new(std::sync::Arc::clone(&scene), job.params)
            .map_err(|e| anyhow::anyhow!("{}: {e}", job.description.source.display()))?;
        drive(&job, renderer)
    })
}

/// `fppm resume CHECKPOINT`.
pub(crate) fn resume(args: &ResumeArgs) -> anyhow::Result<Outcome> {
    // Flags first: a bad flag is a usage error whatever the checkpoint holds.
    let passes = settings::passes_flag(args.passes)?;
    let run = settings::run_settings(&args.run)?;

    let path = &args.checkpoint;
    let bytes = std::fs::read(path)
        .with_context(|| format!("{}: cannot read checkpoint", path.display()))?;
    let header =
        StateHeader::read(&bytes).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    let note = settings::read_note(path, &header.note)?;
    let outputs = settings::outputs(&args.output, &args.aov, Some(&note))?;
    settings::check_aovs(&outputs.aovs, header.params.method)?;
    settings::check_outputs(&outputs, Some(path))?;

    let mut description = settings::load_scene(note.scene.as_deref(), note.env.as_deref())?;
    settings::apply_film(&mut description, (Some(note.width), Some(note.height)));
    let budget = match (passes, args.time) {
        (None, None) => Budget {
            passes: note.passes,
            time: note
                .time_seconds
                .and_then(|s| Duration::try_from_secs_f64(s).ok()),
        },
        (passes, time) => Budget { passes, time },
    };
    let job = Job {
        scene_path: note.scene.clone(),
        env_path: note.env.clone(),
        description,
        params: header.params,
        budget,
        outputs,
        checkpoint: Some(path.clone()),
        run,
        earlier_seconds: note.render_seconds,
    };
    check_memory(&job)?;
    let scene = std::sync::Arc::new(scene::Scene::new(job.description.clone())?);
    in_pool(job.run.threads, || {
        let renderer = Renderer::restore(std::sync::Arc::clone(&scene), &bytes)
            .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
        if let Some(n) = job.budget.passes
            && n < renderer.passes()
        {
            usage!(
                "--passes {n} is fewer than the {} passes the checkpoint {} already has",
                renderer.passes(),
                path.display()
            );
        }
        drive(&job, renderer)
    })
}

/// Refuses a job whose estimated memory exceeds `--max-memory` (or its default).
fn check_memory(job: &Job) -> anyhow::Result<()> {
    let film = job.description.film;
    job.run.max_memory.check(
        film.width,
        film.height,
        &job.params,
        job.checkpoint.is_some(),
    )
}

/// Runs `f` in a rayon pool of `threads` threads, or in the global pool.
pub(crate) fn in_pool<R: Send>(
    threads: Option<usize>,
    f: impl FnOnce() -> anyhow::Result<R> + Send,
) -> anyhow::Result<R> {
    match threads {
        None => f(),
        Some(n) => rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .context("cannot start the worker threads")?
            .install(f),
    }
}

/// Passes until the budget is spent or Ctrl-C, then the outputs.
fn drive(job: &Job, mut renderer: Renderer) -> anyhow::Result<Outcome> {
    install_ctrlc_handler();
    let start = Instant::now();
    let first_pass = renderer.passes();
    let mut progress = Progress::new(job, first_pass);
    let mut last_write = Instant::now();
    let mut checkpoints = CheckpointPace::default();
    loop {
        if INTERRUPTED.load(Ordering::SeqCst) {
            break;
        }
        if job.budget.passes.is_some_and(|n| renderer.passes() >= n)
            || job.budget.time.is_some_and(|t| start.elapsed() >= t)
        {
            break;
        }
        let stats = renderer.iterate();
        let elapsed = start.elapsed();
        progress.pass(&renderer, &stats, elapsed);
        if let Some(checkpoint) = &job.checkpoint
            && checkpoints.due()
        {
            let clock = Instant::now();
            write_checkpoint(job, &renderer, checkpoint, elapsed)?;
            checkpoints.written(clock.elapsed());
        }
        if let Some(every) = job.run.snapshot_every
            && last_write.elapsed() >= every
        {
            write_images(job, &renderer, elapsed)?;
            progress.note(&format!(
                "snapshot written to {}",
                job.outputs.exr.display()
            ));
            last_write = Instant::now();
        }
    }
    let elapsed = start.elapsed();
    let interrupted = INTERRUPTED.load(Ordering::SeqCst);
    progress.finish();
    let readout = write_images(job, &renderer, elapsed)?;
    if let Some(checkpoint) = &job.checkpoint {
        write_checkpoint(job, &renderer, checkpoint, elapsed)?;
    }
    let seconds = job.earlier_seconds + elapsed.as_secs_f64();
    if job.run.json {
        let summary = serde_json::json!({
            "event": "done",
            "interrupted": interrupted,
            "passes": renderer.passes(),
            "photons_emitted": renderer.photons_emitted(),
            "non_finite": progress.non_finite,
            "seconds": elapsed.as_secs_f64(),
            "total_seconds": seconds,
            "readout_seconds": readout,
            "exr": job.outputs.exr,
            "png": job.outputs.png,
            "checkpoint": job.checkpoint,
        });
        crate::print_stdout(&format!("{summary}\n"))?;
    }
    if !job.run.quiet {
        let (width, height) = renderer.resolution();
        if interrupted {
            eprintln!("fppm: interrupted after pass {}", renderer.passes());
        }
        if progress.non_finite > 0 {
            eprintln!(
                "fppm: warning: {} NaN or infinite values were dropped before entering the image (per pass: `non_finite` in --json)",
                progress.non_finite
            );
        }
        eprintln!(
            "wrote {} ({width}x{height}, {} passes, {} photons, {})",
            job.outputs.exr.display(),
            renderer.passes(),
            human_count(renderer.photons_emitted()),
            duration::format(elapsed),
        );
        eprintln!("wrote {}", job.outputs.png.display());
        if let Some(checkpoint) = &job.checkpoint {
            eprintln!(
                "wrote {} (continue with: fppm resume {})",
                checkpoint.display(),
                checkpoint.display()
            );
        }
    }
    Ok(if interrupted {
        Outcome::Interrupted
    } else {
        Outcome::Done
    })
}

/// When to write the checkpoint during a render: after the first pass, then whenever the time
/// since the last write is at least [`CheckpointPace::RATIO`] times what that write took, so
/// that writing takes at most about 5 % of the render however large the state and however short
/// the passes. A kill loses at most those passes; `fppm resume` redoes them bit for bit.
#[derive(Default)]
struct CheckpointPace {
    last: Option<(Instant, Duration)>,
}

impl CheckpointPace {
    const RATIO: u32 = 20;

    fn due(&self) -> bool {
        self.last
            .is_none_or(|(at, took)| at.elapsed() >= took * Self::RATIO)
    }

    fn written(&mut self, took: Duration) {
        self.last = Some((Instant::now(), took));
    }
}

/// The first Ctrl-C asks the loop to stop after the current pass; a second one exits at once
/// (outputs are written atomically, so nothing half-written is left behind but a temporary).
fn install_ctrlc_handler() {
    let result = ctrlc::set_handler(|| {
        if INTERRUPTED.swap(true, Ordering::SeqCst) {
            std::process::exit(130);
        }
    });
    if let Err(e) = result {
        eprintln!(
            "fppm: warning: cannot handle Ctrl-C ({e}); it will stop the render without writing outputs"
        );
    }
}

/// The EXR (with AOVs and metadata) and the PNG.
/// Writes the EXR (with its AOVs) and the PNG; returns the seconds the image read-out took (the
/// photon mappers' pooling runs there).
fn write_images(job: &Job, renderer: &Renderer, elapsed: Duration) -> anyhow::Result<f64> {
    let (width, height) = renderer.resolution();
    let params = renderer.params();
    let scene_name = job.scene_path.as_ref().map_or_else(
        || DEFAULT_SCENE_NAME.to_string(),
        |p| p.display().to_string(),
    );
    // Every render parameter (`ppm::PARAMS`), so that the image says exactly how it was made.
    let mut metadata = vec![
        ("scene".to_owned(), scene_name),
        ("passes".to_owned(), renderer.passes().to_string()),
        ("photons".to_owned(), renderer.photons_emitted().to_string()),
    ];
    metadata.extend(
        params
            .entries()
            .into_iter()
            .map(|(name, value)| (name.to_owned(), value)),
    );
    metadata.push((
        "render_seconds".to_owned(),
        format!("{:.3}", job.earlier_seconds + elapsed.as_secs_f64()),
    ));
    metadata.push(("version".to_owned(), env!("CARGO_PKG_VERSION").to_owned()));
    let readout_clock = Instant::now();
    let image = renderer.image();
    let readout = readout_clock.elapsed().as_secs_f64();
    let mut frame = film::Frame::new(film::Image::new(width as usize, height as usize, image));
    frame.metadata = metadata;
    for aov_flag in &job.outputs.aovs {
        for &aov in aov_flag.aovs() {
            match renderer.aov(aov) {
                Some(values) => frame.add_aov(aov.channel_names(), &values),
                None => eprintln!(
                    "fppm: warning: the {} integrator has no {aov:?} output",
                    params.method
                ),
            }
        }
    }
    film::write_exr(&job.outputs.exr, &frame)?;
    film::write_preview(
        &job.outputs.png,
        &frame.image,
        job.outputs.tonemap.film(),
        1,
    )?;
    Ok(readout)
}

/// The renderer's state with a note that lets `fppm resume` find the scene and the outputs.
fn write_checkpoint(
    job: &Job,
    renderer: &Renderer,
    path: &Path,
    elapsed: Duration,
) -> anyhow::Result<()> {
    let note = settings::note_for(job, job.earlier_seconds + elapsed.as_secs_f64());
    let note = serde_json::to_string(&note)
        .context("internal error: cannot encode the checkpoint note")?;
    let bytes = renderer.save_state(&note);
    film::write_atomically(path, |w| {
        std::io::Write::write_all(w, &bytes).map_err(|e| film::lower_first(&e.to_string()))
    })?;
    Ok(())
}

/// `1.2M`, `350k`, `999`.
fn human_count(n: u64) -> String {
    if n >= 10_000_000 {
        format!("{:.0}M", n as f64 / 1e6)
    } else if n >= 1_000_000 {
        format!("{:.1}M", n as f64 / 1e6)
    } else if n >= 10_000 {
        format!("{:.0}k", n as f64 / 1e3)
    } else {
        n.to_string()
    }
}

/// Per-pass reporting: a progress bar on a terminal, plain lines otherwise, JSON on request.
struct Progress {
    bar: Option<ProgressBar>,
    budget: Budget,
    quiet: bool,
    json: bool,
    first_pass: u32,
    /// NaN or infinite values dropped over the passes of this run.
    non_finite: u64,
}

impl Progress {
    fn new(job: &Job, first_pass: u32) -> Self {
        let quiet = job.run.quiet;
        let bar = (!quiet && std::io::stderr().is_terminal()).then(|| {
            let bar = ProgressBar::new(1000);
            let style =
                ProgressStyle::with_template("{spinner} [{bar:30}] {elapsed_precise} {msg}")
                    .unwrap_or_else(|_| ProgressStyle::default_bar())
                    .progress_chars("=> ");
            bar.set_style(style);
            bar.set_message("first pass…");
            bar.enable_steady_tick(Duration::from_millis(200));
            bar
        });
        Progress {
            bar,
            budget: job.budget,
            quiet,
            json: job.run.json,
            first_pass,
            non_finite: 0,
        }
    }

    fn pass(&mut self, renderer: &Renderer, stats: &PassStats, elapsed: Duration) {
        let passes = renderer.passes();
        self.non_finite += stats.non_finite;
        if self.json {
            let line = serde_json::json!({
                "event": "pass",
                "pass": stats.pass,
                "passes": passes,
                "camera_paths": stats.camera_paths,
                "photons_traced": stats.photons_traced,
                "frequency_photons": stats.frequency_photons,
                "photons_deposited": stats.photons_deposited,
                "hitpoints_hit": stats.hitpoints_hit,
                "hitpoints_valid": stats.hitpoints_valid,
                "mean_radius": finite_or_null(stats.mean_radius),
                "min_radius": finite_or_null(stats.min_radius),
                "max_radius": finite_or_null(stats.max_radius),
                "frequency_held": finite_or_null(stats.frequency_held),
                "photons_stored": stats.photons_stored,
                "light_connections": stats.light_connections,
                "non_finite": stats.non_finite,
                "timings": {
                    "camera": stats.timings.camera,
                    "index": stats.timings.index,
                    "trace": stats.timings.trace,
                    "gather": stats.timings.gather,
                    "update": stats.timings.update,
                    "frequency": stats.timings.frequency,
                },
                "photons_emitted": renderer.photons_emitted(),
                "elapsed_seconds": elapsed.as_secs_f64(),
            });
            // A closed stdout is not worth stopping the render for.
            let _ = crate::print_stdout(&format!("{line}\n"));
        }
        if self.quiet {
            return;
        }
        let done_here = passes.saturating_sub(self.first_pass).max(1);
        let per_pass = elapsed.as_secs_f64() / f64::from(done_here);
        let mut fraction: f64 = 0.0;
        let mut remaining: Option<f64> = None;
        if let Some(n) = self.budget.passes {
            fraction = fraction.max(f64::from(passes) / f64::from(n.max(1)));
            remaining = Some(per_pass * f64::from(n.saturating_sub(passes)));
        }
        if let Some(t) = self.budget.time {
            let left = (t.as_secs_f64() - elapsed.as_secs_f64()).max(0.0);
            fraction = fraction.max(elapsed.as_secs_f64() / t.as_secs_f64());
            remaining = Some(remaining.map_or(left, |r| r.min(left)));
        }
        let of = self
            .budget
            .passes
            .map(|n| format!("/{n}"))
            .unwrap_or_default();
        let left = remaining.map_or(String::new(), |r| {
            format!(", ~{} left", duration::format(Duration::from_secs_f64(r)))
        });
        let photons = if renderer.params().method.traces_light_paths() {
            format!(", {} photons", human_count(renderer.photons_emitted()))
        } else {
            String::new()
        };
        match &self.bar {
            Some(bar) => {
                bar.set_position((fraction.min(1.0) * 1000.0) as u64);
                bar.set_message(format!("pass {passes}{of}{photons}{left}"));
            }
            None => eprintln!(
                "pass {passes}{of}{photons}, {} elapsed{left}",
                duration::format(elapsed)
            ),
        }
    }

    /// A remark between progress updates.
    fn note(&self, message: &str) {
        if self.quiet {
            return;
        }
        match &self.bar {
            Some(bar) => bar.println(message),
            None => eprintln!("{message}"),
        }
    }

    fn finish(&mut self) {
        if let Some(bar) = self.bar.take() {
            bar.finish_and_clear();
        }
    }
}

fn finite_or_null(v: f64) -> serde_json::Value {
    if v.is_finite() {
        serde_json::json!(v)
    } else {
        serde_json::Value::Null
    }
}
