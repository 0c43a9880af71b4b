//! The render loop: passes until the budget is spent or Ctrl-C, with progress, snapshots,
//! checkpoints, and the outputs at the end.

use std::path::Path;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use anyhow::Context;
use ppm::{Renderer, StateHeader};

use crate::args::{LiveArgs, RenderArgs, ResumeArgs};
use crate::duration;
use crate::live::{Live, Status};
use crate::progress::{Progress, human_count};
use crate::settings::{self, Budget, Job};
use crate::trend::Trend;
use crate::{DEFAULT_SCENE_NAME, Outcome, usage};

/// Set by the Ctrl-C handler; the loop stops after the current pass.
static INTERRUPTED: AtomicBool = AtomicBool::new(false);

/// `fppm render` (and `fppm` alone, with `scene = None`).
pub(crate) fn render(scene: Option<&Path>, args: &RenderArgs) -> anyhow::Result<Outcome> {
    let job = settings::render_job(scene, args)?;
    check_memory(&job)?;
    let live = start_live(&args.live, &job)?;
    let scene = std::sync::Arc::new(scene::Scene::new(job.description.clone())?);
    in_pool(job.run.threads, || {
        let renderer = Renderer::new(std::sync::Arc::clone(&scene), job.params)
            .map_err(|e| renderer_error(&job.description.source, e))?;
        drive(&job, renderer, live)
    })
}

/// The error of starting a render of the scene from `path`: a scene the method cannot render
/// (media) is a usage error (exit 2), every other problem a render error.
pub(crate) fn renderer_error(path: &Path, e: ppm::ParamError) -> anyhow::Error {
    let message = format!("{}: {e}", path.display());
    if matches!(
        e,
        ppm::ParamError::MediaUnsupported { .. } | ppm::ParamError::MediaDirectLighting
    ) {
        anyhow::Error::new(crate::UsageError(message))
    } else {
        anyhow::anyhow!(message)
    }
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
    let live = start_live(&args.live, &job)?;
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
        drive(&job, renderer, live)
    })
}

/// Opens the live views the flags ask for, once the job is known to be sound and before the
/// scene is built, so that a taken port fails at once.
fn start_live(args: &LiveArgs, job: &Job) -> anyhow::Result<Live> {
    let title = job
        .outputs
        .exr
        .file_name()
        .map_or_else(|| "fppm".to_owned(), |n| n.to_string_lossy().into_owned());
    let live = Live::start(args, &title, job.run.quiet)?;
    if let Some(url) = live.url()
        && job.run.json
    {
        let line = serde_json::json!({ "event": "preview", "url": url });
        crate::print_stdout(&format!("{line}\n"))?;
    }
    Ok(live)
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

/// Passes until the budget is spent, Ctrl-C or the preview's stop button, then the outputs.
fn drive(job: &Job, mut renderer: Renderer, live: Live) -> anyhow::Result<Outcome> {
    install_ctrlc_handler();
    let start = Instant::now();
    let first_pass = renderer.passes();
    let mut progress = Progress::new(job, first_pass);
    let mut watch = Watch::new(job, &renderer, live);
    let mut last_write = Instant::now();
    let mut checkpoints = CheckpointPace::default();
    loop {
        if INTERRUPTED.load(Ordering::SeqCst) || watch.live.stop_requested() {
            break;
        }
        if job.budget.passes.is_some_and(|n| renderer.passes() >= n)
            || job.budget.time.is_some_and(|t| start.elapsed() >= t)
        {
            break;
        }
        let stats = renderer.iterate();
        let elapsed = start.elapsed();
        let error_trend = watch.after_pass(job, &renderer, &progress, elapsed);
        progress.pass(&renderer, &stats, elapsed, error_trend);
        for note in watch.live.notes() {
            progress.note(&note);
        }
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
            write_images(job, &exr_frame(job, &renderer, elapsed).0)?;
            progress.note(&format!(
                "snapshot written to {}",
                job.outputs.exr.display()
            ));
            last_write = Instant::now();
        }
    }
    let elapsed = start.elapsed();
    let stopped_from_page = watch.live.stop_requested();
    let interrupted = INTERRUPTED.load(Ordering::SeqCst) || stopped_from_page;
    progress.finish();
    watch.state(&renderer, "writing", elapsed);
    let (frame, readout) = exr_frame(job, &renderer, elapsed);
    let frame = Arc::new(frame);
    write_images(job, &frame)?;
    if let Some(checkpoint) = &job.checkpoint {
        write_checkpoint(job, &renderer, checkpoint, elapsed)?;
    }
    for note in watch.finish(&renderer, &frame, elapsed) {
        progress.note(&note);
    }
    let seconds = job.earlier_seconds + elapsed.as_secs_f64();
    if job.run.json {
        let summary = serde_json::json!({
            "event": "done",
            "interrupted": interrupted,
            "passes": renderer.passes(),
            "photons_emitted": renderer.photons_emitted(),
            "non_finite": progress.non_finite,
            "error_trend": progress.trend(),
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
        if stopped_from_page {
            eprintln!(
                "fppm: stopped from the preview page after pass {}",
                renderer.passes()
            );
        } else if interrupted {
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

/// The read period over what an image read costs: the reads take at most 1/96 of the time.
const READ_COST_RATIO: u32 = 96;

/// What watches the render besides the progress line: the error trend and the live views.
/// The image is read from the renderer at most once a pass, and only when one of them needs
/// it: a snapshot of the trend is due, the trend is older than the read period (at least
/// [`Live::PERIOD`], longer where a read is costly), or a live view wants an image.
struct Watch {
    live: Live,
    trend: Trend,
    /// Whether anything shows the trend.
    trend_shown: bool,
    last_trend: Option<Instant>,
    /// What the last image read took: the views and the trend read one at most every
    /// [`Live::PERIOD`], and no more often than keeps the reads near 1 % of the time (a pooled
    /// read-out of a large film takes a large part of a second; the page's decoding and the
    /// PNG encoding of each image cost about as much again, and a live view may cost 3 % of a
    /// render in all: docs/notes/preview-overhead.md).
    read_cost: Duration,
    status: Status,
}

impl Watch {
    fn new(job: &Job, renderer: &Renderer, live: Live) -> Self {
        let (width, height) = renderer.resolution();
        let started = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .unwrap_or_default();
        let status = Status {
            run: format!("{}-{}", std::process::id(), started.as_millis()),
            scene: job.scene_path.as_ref().map_or_else(
                || DEFAULT_SCENE_NAME.to_string(),
                |p| p.display().to_string(),
            ),
            method: renderer.params().method.to_string(),
            width,
            height,
            pass: renderer.passes(),
            passes: job.budget.passes,
            time_budget: job.budget.time.map(|t| t.as_secs_f64()),
            photons: renderer.photons_emitted(),
            state: "rendering",
            exposure: job.outputs.tonemap.exposure,
            tonemap: match job.outputs.tonemap.curve {
                crate::args::TonemapArg::Srgb => "srgb",
                crate::args::TonemapArg::Filmic => "filmic",
            },
            ..Status::default()
        };
        let trend_shown = !job.run.quiet || job.run.json || live.is_on();
        let mut watch = Watch {
            live,
            trend: Trend::default(),
            trend_shown,
            last_trend: None,
            read_cost: Duration::ZERO,
            status,
        };
        watch.state(renderer, "rendering", Duration::ZERO);
        watch
    }

    /// After a pass: the trend if it was measured, and what the live views are due.
    fn after_pass(
        &mut self,
        job: &Job,
        renderer: &Renderer,
        progress: &Progress,
        elapsed: Duration,
    ) -> Option<f64> {
        let passes = renderer.passes();
        let period = Live::PERIOD.max(self.read_cost * READ_COST_RATIO);
        let live_image = self.live.wants_image(period);
        let trend_due = self.trend_shown
            && (self.trend.wants(passes) || self.last_trend.is_none_or(|t| t.elapsed() >= period));
        if !live_image && !trend_due {
            self.status(renderer, progress, elapsed);
            self.live.publish(&self.status, None);
            return None;
        }
        let read_clock = Instant::now();
        let pixels = renderer.image();
        self.read_cost = read_clock.elapsed();
        let error_trend = if self.trend_shown {
            self.last_trend = Some(Instant::now());
            self.trend.observe(passes, &pixels)
        } else {
            None
        };
        if error_trend.is_some() {
            self.status.error_trend = error_trend;
        }
        self.status(renderer, progress, elapsed);
        let frame =
            live_image.then(|| Arc::new(frame_of(job, renderer, pixels, self.live.wants_aovs())));
        self.live.publish(&self.status, frame.as_ref());
        error_trend
    }

    /// The status after a pass.
    fn status(&mut self, renderer: &Renderer, progress: &Progress, elapsed: Duration) {
        let outlook = progress.outlook(renderer.passes(), elapsed);
        self.status.pass = renderer.passes();
        self.status.photons = renderer.photons_emitted();
        self.status.elapsed = elapsed.as_secs_f64();
        self.status.remaining = outlook.remaining;
        self.status.fraction = outlook.fraction;
        self.status.state = if INTERRUPTED.load(Ordering::SeqCst) {
            "stopping"
        } else {
            "rendering"
        };
    }

    /// Tells the live views what the command is doing now.
    fn state(&mut self, renderer: &Renderer, state: &'static str, elapsed: Duration) {
        self.status.pass = renderer.passes();
        self.status.photons = renderer.photons_emitted();
        self.status.elapsed = elapsed.as_secs_f64();
        self.status.state = state;
        if state != "rendering" {
            self.status.remaining = Some(0.0);
        }
        self.live.publish(&self.status, None);
    }

    /// The final image to the live views; their last messages.
    fn finish(
        mut self,
        renderer: &Renderer,
        frame: &Arc<film::Frame>,
        elapsed: Duration,
    ) -> Vec<String> {
        self.state(renderer, "done", elapsed);
        self.status.fraction = 1.0;
        self.live.finish(&self.status, frame)
    }
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

/// The image and, with `aovs`, the `--aov` channels, as the EXR holds them.
fn frame_of(job: &Job, renderer: &Renderer, pixels: Vec<[f32; 3]>, aovs: bool) -> film::Frame {
    let (width, height) = renderer.resolution();
    let mut frame = film::Frame::new(film::Image::new(width as usize, height as usize, pixels));
    for aov_flag in job.outputs.aovs.iter().filter(|_| aovs) {
        for &aov in aov_flag.aovs() {
            if let Some(values) = renderer.aov(aov) {
                frame.add_aov(aov.channel_names(), &values);
            }
        }
    }
    frame
}

/// What the EXR holds: the image, the AOVs (a warning for one the integrator lacks) and the
/// metadata; and the seconds the image read-out took (the photon mappers' pooling runs there).
fn exr_frame(job: &Job, renderer: &Renderer, elapsed: Duration) -> (film::Frame, f64) {
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
    let mut frame = frame_of(job, renderer, image, true);
    frame.metadata = metadata;
    for aov_flag in &job.outputs.aovs {
        for &aov in aov_flag.aovs() {
            if !frame
                .channels
                .iter()
                .any(|(name, _)| aov.channel_names().contains(name))
            {
                eprintln!(
                    "fppm: warning: the {} integrator has no {aov:?} output",
                    params.method
                );
            }
        }
    }
    (frame, readout)
}

/// The EXR (with AOVs and metadata) and the PNG.
fn write_images(job: &Job, frame: &film::Frame) -> anyhow::Result<()> {
    film::write_exr(&job.outputs.exr, frame)?;
    film::write_preview(
        &job.outputs.png,
        &frame.image,
        job.outputs.tonemap.film(),
        1,
    )?;
    Ok(())
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
