//! The `fppm` Python module: the renderer of this workspace driven from Python.
//!
//! ```python
//! import fppm
//! scene = fppm.load("scenes/cornell.toml")
//! r = fppm.Renderer(scene, method="freq-sppm", photons_per_pass="200k", seed=7)
//! r.render(time=30.0)          # releases the GIL; Ctrl-C stops after the current pass
//! image = r.image()            # numpy float32, height x width x 3, linear RGB
//! ```
//!
//! A thin layer, as the `fppm` command is: scenes are read by `import` (every format the command
//! opens), parameters by their names in [`ppm::PARAMS`] (the command's flags and a scene's
//! `[render]` table), renders run in [`ppm::Renderer`], images are written, read and compared by
//! `film`. So an image made here is bit for bit the command's for the same scene, parameters and
//! seed.
//!
//! Every call into the library runs under `guarded` (`errors.rs`): a panic (a bug) becomes
//! `fppm.InternalError`, a `RuntimeError`, rather than PyO3's `PanicException`, which derives
//! from `BaseException` and escapes `except Exception`. Errors of the input are `ValueError`,
//! `OSError` (a file that cannot be read or written) or `fppm.SceneError`, each with the one-line
//! message the command prints.
//!
//! Built by maturin (`pip install ./crates/python`); tested by pytest (`crates/python/tests`,
//! run by `crates/python/ci.sh`). `docs/python.md` describes the API.

mod convert;
mod errors;
mod images;
mod params;
mod renderer;
mod scene;

use pyo3::prelude::*;

pub(crate) use crate::errors::{InternalError, SceneError, guarded};

/// fppm: frequency-guided progressive photon mapping.
///
/// Load a scene with `load` (TOML, OBJ, glTF, Mitsuba 3 XML, pbrt-v4), `load_string` or
/// `default_scene`; render it with `Renderer` pass by pass (`iterate`) or for a time (`render`);
/// read the image as a NumPy array (`Renderer.image`, `Renderer.aov`); write and read EXR files
/// (`write_exr`, `read_exr`) and compare images (`diff`). Render parameters are those of the
/// `fppm` command and of a scene's `[render]` table, by name (`parameters()` lists them).
#[pymodule]
#[pyo3(name = "fppm")]
fn fppm_module(m: &Bound<'_, PyModule>) -> PyResult<()> {
    errors::install_panic_hook();
    let py = m.py();
    m.add("SceneError", py.get_type::<SceneError>())?;
    m.add("InternalError", py.get_type::<InternalError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("AOVS", renderer::aov_names())?;
    m.add_class::<scene::Scene>()?;
    m.add_class::<renderer::Renderer>()?;
    m.add_function(wrap_pyfunction!(scene::load, m)?)?;
    m.add_function(wrap_pyfunction!(scene::load_string, m)?)?;
    m.add_function(wrap_pyfunction!(scene::default_scene, m)?)?;
    m.add_function(wrap_pyfunction!(params::parameters, m)?)?;
    m.add_function(wrap_pyfunction!(images::write_exr, m)?)?;
    m.add_function(wrap_pyfunction!(images::read_exr, m)?)?;
    m.add_function(wrap_pyfunction!(images::diff, m)?)?;
    m.add_function(wrap_pyfunction!(errors::_internal_error_for_tests, m)?)?;
    Ok(())
}
