//! `fppm.Renderer`: a progressive render driven pass by pass from Python.

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use numpy::{PyArray1, PyArrayMethods};
use ppm::{Aov, PassStats};
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict};

use crate::errors::{message, panic_error};
use crate::params::{param_message, render_params};
use crate::scene::Scene;
use crate::{InternalError, guarded};

/// The note a checkpoint saved from Python carries (`fppm resume` needs the command's own).
const NOTE: &str = "saved by the fppm Python module";

/// Share of physical memory a render may need by default, as the command's `--max-memory`.
const DEFAULT_MEMORY_SHARE: f64 = 0.8;

/// What the lock guards: the render and what this object counted of it.
struct State {
    renderer: ppm::Renderer,
    /// The last pass's statistics.
    last: Option<PassStats>,
    /// Wall-clock seconds spent in passes through this object.
    seconds: f64,
    /// NaN or infinite values dropped over those passes.
    non_finite: u64,
    /// A call panicked: the state may be half updated.
    broken: bool,
}

fn broken() -> PyErr {
    InternalError::new_err(
        "this renderer stopped in an internal error (a bug, please report it) and cannot be used any more",
    )
}

/// A progressive render of a scene: run passes with `iterate` or `render`, read the current
/// image with `image` (and `aov`) at any time, save and restore its exact state.
///
/// Args:
///     scene: the scene (`fppm.load`).
///     method: the integrator: freq-sppm, sppm, freq, ppm, appm, path or light (default: the
///         scene's `[render]` method, else freq-sppm).
///     threads: worker threads (default: one per core); the image does not depend on it.
///     max_memory: refuse a render that would need more bytes than this (default: 80 % of
///         physical memory; `"none"` for no limit), as the command's `--max-memory`.
///     **params: every render parameter by its name (`fppm.parameters()`), e.g.
///         `photons_per_pass=200_000`, `alpha=0.7`, `seed=3`, `light_tracing=False`: the names
///         of the command's flags with `_` for `-` and of a scene's `[render]` table. They
///         override the scene's `[render]` table, which overrides the preset.
///
/// Raises:
///     ValueError: an unknown parameter, or a value outside its range (NaN included), with the
///         command's one-line message; a render larger than `max_memory`.
///     TypeError: a value that is not a str, int, float or bool.
///
/// The same scene, parameters and seed give the image the `fppm render` command gives, bit for
/// bit. One renderer may be used from several threads: each call waits for the one running.
#[pyclass(module = "fppm", frozen)]
pub(crate) struct Renderer {
    scene: Py<Scene>,
    state: Mutex<State>,
    pool: Option<rayon::ThreadPool>,
}

impl Renderer {
    /// Runs `f` on the state without the GIL, once the state is free (a render in another
    /// thread holds it during a pass), in this renderer's thread pool (or the global one).
    ///
    /// A panic in `f` (a bug) becomes [`InternalError`] and leaves the renderer broken: its
    /// state may be half updated, so every later call raises [`InternalError`] too.
    fn with<R: Send>(&self, py: Python<'_>, f: impl FnOnce(&mut State) -> R + Send) -> PyResult<R> {
        py.detach(|| {
            let mut guard = self.state.lock().map_err(|_| broken())?;
            let state = &mut *guard;
            if state.broken {
                return Err(broken());
            }
            let run = || match &self.pool {
                Some(pool) => pool.install(|| f(state)),
                None => f(state),
            };
            match catch_unwind(AssertUnwindSafe(run)) {
                Ok(result) => Ok(result),
                Err(payload) => {
                    guard.broken = true;
                    Err(panic_error(payload.as_ref()))
                }
            }
        })
    }

    /// One pass, counted.
    fn pass(&self, py: Python<'_>) -> PyResult<PassStats> {
        self.with(py, |state| {
            let start = Instant::now();
            let stats = state.renderer.iterate();
            state.seconds += start.elapsed().as_secs_f64();
            state.non_finite += stats.non_finite;
            state.last = Some(stats);
            stats
        })
    }

    fn make(
        py: Python<'_>,
        scene: Py<Scene>,
        threads: Option<i64>,
        build: impl FnOnce(Arc<scene::Scene>) -> PyResult<ppm::Renderer> + Send,
    ) -> PyResult<Self> {
        let pool = match threads {
            None => None,
            Some(n) if (1..=4096).contains(&n) => Some(
                rayon::ThreadPoolBuilder::new()
                    .num_threads(n as usize)
                    .build()
                    .map_err(|e| {
                        PyRuntimeError::new_err(format!("cannot start the worker threads: {e}"))
                    })?,
            ),
            Some(n) => {
                return Err(PyValueError::new_err(format!(
                    "threads {n} is outside [1, 4096]"
                )));
            }
        };
        let shared = Arc::clone(&scene.get().scene);
        let renderer = py.detach(|| guarded(|| build(shared)))?;
        Ok(Self {
            scene,
            state: Mutex::new(State {
                renderer,
                last: None,
                seconds: 0.0,
                non_finite: 0,
                broken: false,
            }),
            pool,
        })
    }
}

#[pymethods]
impl Renderer {
    #[new]
    #[pyo3(signature = (scene, method=None, *, threads=None, max_memory=None, **params))]
    fn new(
        py: Python<'_>,
        scene: Py<Scene>,
        method: Option<&Bound<'_, PyAny>>,
        threads: Option<i64>,
        max_memory: Option<&Bound<'_, PyAny>>,
        params: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        let mut kwargs: Vec<(String, Bound<'_, PyAny>)> = Vec::new();
        if let Some(method) = method {
            kwargs.push(("method".to_owned(), method.clone()));
        }
        if let Some(params) = params {
            for (key, value) in params.iter() {
                kwargs.push((key.extract()?, value));
            }
        }
        let description = scene.get().description();
        let params = guarded(|| render_params(description, &kwargs))?;
        let film = description.film;
        check_memory(film.width, film.height, &params, max_memory)?;
        Self::make(py, scene, threads, move |shared| {
            ppm::Renderer::new(shared, params).map_err(|e| PyValueError::new_err(param_message(&e)))
        })
    }

    /// A renderer from the bytes of `save_state` (or a checkpoint file of `fppm render
    /// --checkpoint`), for the scene it was made with: its next passes are those the saved
    /// renderer would have run, bit for bit.
    ///
    /// Raises:
    ///     ValueError: the bytes are not a checkpoint of this version, are corrupt, or were
    ///         made for another scene (or film size).
    #[staticmethod]
    #[pyo3(signature = (scene, data, *, threads=None))]
    fn restore(
        py: Python<'_>,
        scene: Py<Scene>,
        data: &[u8],
        threads: Option<i64>,
    ) -> PyResult<Self> {
        let data = data.to_vec();
        Self::make(py, scene, threads, move |shared| {
            ppm::Renderer::restore(shared, &data)
                .map_err(|e| PyValueError::new_err(format!("checkpoint: {}", message(&e))))
        })
    }

    /// Runs `passes` passes (releasing the GIL during each) and returns the last one's
    /// statistics (as `stats()["last_pass"]`).
    ///
    /// Raises:
    ///     KeyboardInterrupt: Ctrl-C, after the pass that was running (the renderer keeps every
    ///         finished pass).
    #[pyo3(signature = (passes=1))]
    fn iterate<'py>(&self, py: Python<'py>, passes: u32) -> PyResult<Bound<'py, PyAny>> {
        let mut last = None;
        for _ in 0..passes {
            last = Some(self.pass(py)?);
            py.check_signals()?;
        }
        match last {
            Some(stats) => pass_dict(py, &stats),
            None => Ok(py.None().into_bound(py)),
        }
    }

    /// Runs passes until `time` seconds have passed or `passes` more passes are done,
    /// whichever comes first (at least one of them must be given), as `fppm render --time
    /// --passes` does: a pass that starts before the time is up is finished. The GIL is
    /// released during each pass, so other Python threads run.
    ///
    /// Returns:
    ///     dict: `stats()` at the end.
    ///
    /// Raises:
    ///     KeyboardInterrupt: Ctrl-C, after the current pass (the renderer keeps every
    ///         finished pass and can go on).
    ///     ValueError: neither a time nor passes, or a negative or NaN time.
    #[pyo3(signature = (time=None, passes=None))]
    fn render<'py>(
        &self,
        py: Python<'py>,
        time: Option<f64>,
        passes: Option<u32>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let budget = match time {
            None => None,
            Some(t) => Some(Duration::try_from_secs_f64(t).map_err(|_| {
                PyValueError::new_err(format!("time {t} is not a duration in seconds"))
            })?),
        };
        if budget.is_none() && passes.is_none() {
            return Err(PyValueError::new_err(
                "render needs a time (seconds) or a number of passes",
            ));
        }
        let start = Instant::now();
        let mut done = 0u32;
        loop {
            if passes.is_some_and(|n| done >= n) || budget.is_some_and(|t| start.elapsed() >= t) {
                break;
            }
            self.pass(py)?;
            done += 1;
            py.check_signals()?;
        }
        self.stats(py)
    }

    /// The current image: a `numpy.ndarray` of float32, height × width × 3, linear RGB
    /// radiance (the values the command writes to its EXR).
    fn image<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let ((width, height), pixels) =
            self.with(py, |s| (s.renderer.resolution(), s.renderer.image()))?;
        let flat = PyArray1::from_vec(py, pixels.into_flattened());
        Ok(flat
            .reshape([height as usize, width as usize, 3])?
            .into_any())
    }

    /// An auxiliary image by name (`fppm.AOVS`): `radius`, `count`, `freq.radius`,
    /// `freq.held`, `pool.width`, `albedo`, `normal`, `depth`. One-channel images are height × width, the
    /// others height × width × 3, float32.
    ///
    /// Raises:
    ///     ValueError: an unknown name, or one this integrator does not have (a radius for the
    ///         path tracer, a frequency radius for sppm).
    fn aov<'py>(&self, py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyAny>> {
        let aov = aov_by_name(name)?;
        let ((width, height), method, values) = self.with(py, |s| {
            (
                s.renderer.resolution(),
                s.renderer.params().method,
                s.renderer.aov(aov),
            )
        })?;
        let Some(values) = values else {
            return Err(PyValueError::new_err(format!(
                "the {method} integrator has no {name} output"
            )));
        };
        let flat = PyArray1::from_vec(py, values);
        let channels = aov.channel_names().len();
        let (h, w) = (height as usize, width as usize);
        Ok(if channels == 1 {
            flat.reshape([h, w])?.into_any()
        } else {
            flat.reshape([h, w, channels])?.into_any()
        })
    }

    /// The render so far: `passes`, `photons_emitted`, `seconds` (in passes run through this
    /// object), `non_finite` (values dropped over them), `method`, `memory` (bytes by part, or
    /// None for the path tracer) and `last_pass`, the last pass's statistics as `fppm render
    /// --json` reports them (`camera_paths`, `photons_traced`, `frequency_photons`,
    /// `frequency_held` (the share of held kernels), radii, `timings` by phase, ...; None
    /// before the first pass).
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let (passes, photons, seconds, non_finite, method, memory, last) = self.with(py, |s| {
            (
                s.renderer.passes(),
                s.renderer.photons_emitted(),
                s.seconds,
                s.non_finite,
                s.renderer.params().method.name(),
                s.renderer.memory(),
                s.last,
            )
        })?;
        let out = PyDict::new(py);
        out.set_item("passes", passes)?;
        out.set_item("photons_emitted", photons)?;
        out.set_item("seconds", seconds)?;
        out.set_item("non_finite", non_finite)?;
        out.set_item("method", method)?;
        match memory {
            Some(m) => {
                let memory = PyDict::new(py);
                memory.set_item("hitpoints", m.hitpoints)?;
                memory.set_item("records", m.records)?;
                memory.set_item("slot_columns", m.slot_columns)?;
                memory.set_item("grid", m.grid)?;
                memory.set_item("pass_hitpoint_buffers", m.pass_hitpoint_buffers)?;
                memory.set_item("pass_photon_buffers", m.pass_photon_buffers)?;
                memory.set_item("total", m.total())?;
                out.set_item("memory", memory)?;
            }
            None => out.set_item("memory", py.None())?,
        }
        match &last {
            Some(stats) => out.set_item("last_pass", pass_dict(py, stats)?)?,
            None => out.set_item("last_pass", py.None())?,
        }
        Ok(out)
    }

    /// The exact state of the render, as bytes (the format of `fppm render --checkpoint`);
    /// `Renderer.restore(scene, data)` goes on from it.
    fn save_state<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyBytes>> {
        let bytes = self.with(py, |s| s.renderer.save_state(NOTE))?;
        Ok(PyBytes::new(py, &bytes))
    }

    /// Every render parameter of this render by name, as text (what the command writes to an
    /// EXR's metadata).
    fn params<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let entries = self.with(py, |s| s.renderer.params().entries())?;
        let out = PyDict::new(py);
        for (name, value) in entries {
            out.set_item(name, value)?;
        }
        Ok(out)
    }

    /// Passes completed.
    #[getter]
    fn passes(&self, py: Python<'_>) -> PyResult<u32> {
        self.with(py, |s| s.renderer.passes())
    }

    /// Photons emitted over every pass (0 for the path tracer).
    #[getter]
    fn photons_emitted(&self, py: Python<'_>) -> PyResult<u64> {
        self.with(py, |s| s.renderer.photons_emitted())
    }

    /// The integrator's name, e.g. `freq-sppm`.
    #[getter]
    fn method(&self, py: Python<'_>) -> PyResult<&'static str> {
        self.with(py, |s| s.renderer.params().method.name())
    }

    /// The scene being rendered.
    #[getter]
    fn scene(&self, py: Python<'_>) -> Py<Scene> {
        self.scene.clone_ref(py)
    }

    /// Film width and height in pixels.
    #[getter]
    fn resolution(&self, py: Python<'_>) -> PyResult<(u32, u32)> {
        self.with(py, |s| s.renderer.resolution())
    }

    /// Writes the current image as `fppm render -o path` does: linear RGB, the given AOVs as
    /// extra channels, every render parameter and the pass and photon counts as metadata.
    ///
    /// Args:
    ///     path: the `.exr` file (written atomically).
    ///     aovs: AOV names (`fppm.AOVS`) to add as channels.
    ///
    /// Raises:
    ///     OSError: the file cannot be written. ValueError: an AOV this integrator lacks.
    #[pyo3(signature = (path, aovs=Vec::new()))]
    fn write_exr(
        &self,
        py: Python<'_>,
        path: std::path::PathBuf,
        aovs: Vec<String>,
    ) -> PyResult<()> {
        let chosen = aovs
            .iter()
            .map(|n| aov_by_name(n))
            .collect::<PyResult<Vec<Aov>>>()?;
        let source = self.scene.get().description().source.display().to_string();
        self.with(py, |state| -> PyResult<()> {
            let seconds = state.seconds;
            let r = &state.renderer;
            let (width, height) = r.resolution();
            let mut frame =
                film::Frame::new(film::Image::new(width as usize, height as usize, r.image()));
            frame.metadata = vec![
                ("scene".to_owned(), source),
                ("passes".to_owned(), r.passes().to_string()),
                ("photons".to_owned(), r.photons_emitted().to_string()),
            ];
            frame.metadata.extend(
                r.params()
                    .entries()
                    .into_iter()
                    .map(|(name, value)| (name.to_owned(), value)),
            );
            frame
                .metadata
                .push(("render_seconds".to_owned(), format!("{seconds:.3}")));
            frame
                .metadata
                .push(("version".to_owned(), env!("CARGO_PKG_VERSION").to_owned()));
            for (aov, name) in chosen.iter().zip(&aovs) {
                let values = r.aov(*aov).ok_or_else(|| {
                    PyValueError::new_err(format!(
                        "the {} integrator has no {name} output",
                        r.params().method
                    ))
                })?;
                frame.add_aov(aov.channel_names(), &values);
            }
            film::write_exr(&path, &frame).map_err(|e| crate::errors::film_error(&e))
        })?
    }

    /// Panics inside a call on the renderer's state, to test that the renderer then refuses
    /// every call with `fppm.InternalError`.
    fn _internal_error_for_tests(&self, py: Python<'_>) -> PyResult<()> {
        self.with(py, |_| {
            panic!("a panic raised on purpose by the test suite")
        })
    }

    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        let ((w, h), method, passes) = self.with(py, |s| {
            (
                s.renderer.resolution(),
                s.renderer.params().method.name(),
                s.renderer.passes(),
            )
        })?;
        Ok(format!("<fppm.Renderer {method} {w}x{h}, {passes} passes>"))
    }
}

/// A pass's statistics as `fppm render --json` writes its `pass` lines.
fn pass_dict<'py>(py: Python<'py>, s: &PassStats) -> PyResult<Bound<'py, PyAny>> {
    let finite = |x: f64| x.is_finite().then_some(x);
    let value = serde_json::json!({
        "pass": s.pass,
        "camera_paths": s.camera_paths,
        "photons_traced": s.photons_traced,
        "frequency_photons": s.frequency_photons,
        "photons_deposited": s.photons_deposited,
        "hitpoints_hit": s.hitpoints_hit,
        "hitpoints_valid": s.hitpoints_valid,
        "mean_radius": finite(s.mean_radius),
        "min_radius": finite(s.min_radius),
        "max_radius": finite(s.max_radius),
        "frequency_held": finite(s.frequency_held),
        "photons_stored": s.photons_stored,
        "light_connections": s.light_connections,
        "volume_photons": s.volume_photons,
        "non_finite": s.non_finite,
        "timings": {
            "camera": s.timings.camera,
            "index": s.timings.index,
            "trace": s.timings.trace,
            "gather": s.timings.gather,
            "update": s.timings.update,
            "frequency": s.timings.frequency,
            "volume": s.timings.volume,
            "total": s.timings.total(),
        },
    });
    crate::convert::to_python(py, &value)
}

/// An AOV's name: its first channel's, without a colour or axis suffix (`albedo.R` →
/// `albedo`).
fn aov_name(aov: Aov) -> &'static str {
    let first = aov.channel_names().first().copied().unwrap_or_default();
    match aov.channel_names().len() {
        1 => first,
        _ => first.rsplit_once('.').map_or(first, |(stem, _)| stem),
    }
}

/// Every AOV's name, in the library's order.
pub(crate) fn aov_names() -> Vec<&'static str> {
    Aov::ALL.iter().map(|&a| aov_name(a)).collect()
}

/// The AOV called `name`.
pub(crate) fn aov_by_name(name: &str) -> PyResult<Aov> {
    Aov::ALL
        .iter()
        .copied()
        .find(|&a| aov_name(a) == name)
        .ok_or_else(|| {
            PyValueError::new_err(format!(
                "{name:?} is not an aov: one of {}",
                aov_names().join(", ")
            ))
        })
}

/// Refuses a render whose estimated memory exceeds `max_memory` bytes (default: a share of
/// physical memory), before anything is allocated: an allocation that fails would abort the
/// interpreter.
fn check_memory(
    width: u32,
    height: u32,
    params: &ppm::RenderParams,
    max_memory: Option<&Bound<'_, PyAny>>,
) -> PyResult<()> {
    let limit = match max_memory {
        None => {
            let mut system = sysinfo::System::new();
            system.refresh_memory();
            let physical = system.total_memory();
            (physical > 0).then_some((physical as f64 * DEFAULT_MEMORY_SHARE) as u64)
        }
        Some(v) => {
            if let Ok(text) = v.extract::<String>()
                && text.eq_ignore_ascii_case("none")
            {
                None
            } else {
                match v.extract::<u64>() {
                    Ok(bytes) if bytes > 0 => Some(bytes),
                    _ => {
                        return Err(PyValueError::new_err(format!(
                            "max_memory {} is not a positive number of bytes or \"none\"",
                            v.repr()?
                        )));
                    }
                }
            }
        }
    };
    let Some(limit) = limit else {
        return Ok(());
    };
    let total = ppm::MemoryEstimate::of(width, height, params).total(false);
    if total <= limit {
        return Ok(());
    }
    let gib = |b: u64| b as f64 / f64::from(1u32 << 30);
    Err(PyValueError::new_err(format!(
        "the render needs about {:.1} GiB, more than the limit of {:.1} GiB (max_memory to \
         change; lower photons_per_pass, spp or the film size)",
        gib(total),
        gib(limit)
    )))
}
