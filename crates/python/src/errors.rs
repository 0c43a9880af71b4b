//! The module's exceptions, the one-line messages of the library's errors, and the guard that
//! turns a panic into an exception.

use std::panic::{AssertUnwindSafe, catch_unwind};

use pyo3::create_exception;
use pyo3::exceptions::{
    PyException, PyFileNotFoundError, PyOSError, PyPermissionError, PyRuntimeError,
};
use pyo3::prelude::*;

create_exception!(
    fppm,
    SceneError,
    PyException,
    "A scene that cannot be loaded or built: malformed or out-of-range content, an unsupported \
     format, no emitter. A file that cannot be read at all raises OSError instead."
);

create_exception!(
    fppm,
    InternalError,
    PyRuntimeError,
    "A bug inside fppm (a Rust panic), caught before it reached Python. The object it happened \
     in may be left unusable; please report the message."
);

/// Runs a call into the library; a panic becomes [`InternalError`] with its message.
///
/// PyO3 would turn an uncaught panic into `pyo3_runtime.PanicException`, a `BaseException`
/// that `except Exception` does not catch; this keeps every failure an ordinary exception.
pub(crate) fn guarded<T>(f: impl FnOnce() -> PyResult<T>) -> PyResult<T> {
    catch_unwind(AssertUnwindSafe(f)).unwrap_or_else(|payload| Err(panic_error(payload.as_ref())))
}

/// The [`InternalError`] of a caught panic, with its message.
pub(crate) fn panic_error(payload: &(dyn std::any::Any + Send)) -> PyErr {
    let message = payload
        .downcast_ref::<&str>()
        .map(|s| (*s).to_owned())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "a panic without a message".to_owned());
    InternalError::new_err(format!(
        "internal error in fppm (a bug, please report it): {}",
        one_line(&message)
    ))
}

/// The error and its causes joined by `: `, skipping a cause whose text the message already
/// holds, on one line: what the `fppm` command prints after `fppm: `.
pub(crate) fn message(error: &(dyn std::error::Error + 'static)) -> String {
    let mut text = error.to_string();
    let mut cause = error.source();
    while let Some(c) = cause {
        let more = c.to_string();
        if !text.to_lowercase().contains(&more.to_lowercase()) {
            text.push_str(": ");
            text.push_str(&more);
        }
        cause = c.source();
    }
    one_line(&text)
}

/// Lines trimmed and joined by spaces (a TOML error quotes the line it is about).
pub(crate) fn one_line(text: &str) -> String {
    text.lines()
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .collect::<Vec<_>>()
        .join(" ")
}

/// A scene that cannot be loaded: `OSError` (`FileNotFoundError`, `PermissionError`) when the
/// scene file itself or a file it refers to cannot be read, [`SceneError`] otherwise.
pub(crate) fn load_error(error: &import::LoadError) -> PyErr {
    let text = message(error);
    match error {
        import::LoadError::Io { source, .. } => io_error(source.kind(), text),
        _ => SceneError::new_err(text),
    }
}

/// The `OSError` subclass of an IO error kind, with `text`.
pub(crate) fn io_error(kind: std::io::ErrorKind, text: String) -> PyErr {
    match kind {
        std::io::ErrorKind::NotFound => PyFileNotFoundError::new_err(text),
        std::io::ErrorKind::PermissionDenied => PyPermissionError::new_err(text),
        _ => PyOSError::new_err(text),
    }
}

/// An image file that cannot be read or written: `OSError`, or `ValueError` for images that do
/// not match.
pub(crate) fn film_error(error: &film::FilmError) -> PyErr {
    let text = message(error);
    match error {
        film::FilmError::SizeMismatch { .. } => pyo3::exceptions::PyValueError::new_err(text),
        _ => PyOSError::new_err(text),
    }
}

/// Keeps the panic hook silent for the panics that a loader contains (a dependency's), which
/// become the loader's one-line error, as the `fppm` command does; every other panic is
/// reported by the previous hook.
pub(crate) fn install_panic_hook() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if !import::containing_a_panic() {
                previous(info);
            }
        }));
    });
}

/// Panics inside the guard, to test that a panic becomes `fppm.InternalError`.
#[pyfunction]
#[pyo3(name = "_internal_error_for_tests")]
pub(crate) fn _internal_error_for_tests() -> PyResult<()> {
    guarded(|| -> PyResult<()> { panic!("a panic raised on purpose by the test suite") })
}
