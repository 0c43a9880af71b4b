//! Images as NumPy arrays: `fppm.write_exr`, `fppm.read_exr`, `fppm.diff`.

use std::path::PathBuf;

use numpy::{PyArray1, PyArrayDyn, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::errors::film_error;
use crate::guarded;
use crate::renderer::aov_by_name;

/// An array of `height × width × channels` values (or `height × width` for one channel) as
/// `(height, width, values)`, row-major. Any real dtype is converted to float32.
fn planes(
    array: &Bound<'_, PyAny>,
    what: &str,
    channels: usize,
) -> PyResult<(usize, usize, Vec<f32>)> {
    let numpy = array.py().import("numpy")?;
    let converted = numpy
        .call_method1("ascontiguousarray", (array, "float32"))
        .map_err(|e| PyTypeError::new_err(format!("{what} is not an array of numbers: {e}")))?;
    let array = converted.cast::<PyArrayDyn<f32>>()?;
    let shape = array.shape().to_vec();
    let ok = match shape.as_slice() {
        [_, _] => channels == 1,
        [_, _, c] => *c == channels,
        _ => false,
    };
    if !ok {
        let wanted = if channels == 1 {
            "height x width (or height x width x 1)".to_owned()
        } else {
            format!("height x width x {channels}")
        };
        return Err(PyValueError::new_err(format!(
            "{what} has shape {shape:?}, not {wanted}"
        )));
    }
    let values = array.readonly().as_slice()?.to_vec();
    Ok((shape[0], shape[1], values))
}

/// An RGB image from an array (height × width × 3) or from an EXR file (a path).
fn image_of(value: &Bound<'_, PyAny>, what: &str) -> PyResult<film::Image> {
    if let Ok(path) = value.extract::<PathBuf>() {
        return guarded(|| film::read_exr(&path).map_err(|e| film_error(&e)));
    }
    let (height, width, values) = planes(value, what, 3)?;
    let pixels = values.chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect();
    Ok(film::Image::new(width, height, pixels))
}

/// Writes an image as an EXR (32-bit float, lossless), as the command writes its images.
///
/// Args:
///     path: the `.exr` file (written atomically: a temporary file, then a rename).
///     image: linear RGB, height × width × 3 (any real dtype; stored as float32).
///     aovs: auxiliary images by AOV name (`fppm.AOVS`), each height × width for one channel
///         or height × width × 3, stored as the command's channels (`albedo.R`, `radius`).
///     metadata: text attributes, stored as `fppm.KEY`.
///
/// Raises:
///     OSError: the file cannot be written. ValueError: an array of the wrong shape or an
///     unknown AOV name.
#[pyfunction]
#[pyo3(signature = (path, image, aovs=None, metadata=None))]
pub(crate) fn write_exr(
    py: Python<'_>,
    path: PathBuf,
    image: &Bound<'_, PyAny>,
    aovs: Option<&Bound<'_, PyDict>>,
    metadata: Option<&Bound<'_, PyDict>>,
) -> PyResult<()> {
    let (height, width, values) = planes(image, "image", 3)?;
    let pixels = values.chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect();
    let mut frame = film::Frame::new(film::Image::new(width, height, pixels));
    if let Some(aovs) = aovs {
        for (key, value) in aovs.iter() {
            let name: String = key.extract()?;
            let aov = aov_by_name(&name)?;
            let names = aov.channel_names();
            let (h, w, values) = planes(&value, &format!("aov {name}"), names.len())?;
            if (h, w) != (height, width) {
                return Err(PyValueError::new_err(format!(
                    "aov {name} is {w}x{h} but the image is {width}x{height}"
                )));
            }
            frame.add_aov(names, &values);
        }
    }
    if let Some(metadata) = metadata {
        for (key, value) in metadata.iter() {
            frame
                .metadata
                .push((key.extract()?, value.str()?.to_string()));
        }
    }
    py.detach(|| guarded(|| film::write_exr(&path, &frame).map_err(|e| film_error(&e))))
}

/// Reads the R, G and B channels of an EXR file (any EXR, not only fppm's).
///
/// Returns:
///     numpy.ndarray: float32, height × width × 3.
///
/// Raises:
///     OSError: the file cannot be read as an EXR, or lacks R, G or B.
#[pyfunction]
pub(crate) fn read_exr(py: Python<'_>, path: PathBuf) -> PyResult<Bound<'_, PyAny>> {
    let image = py.detach(|| guarded(|| film::read_exr(&path).map_err(|e| film_error(&e))))?;
    let flat = PyArray1::from_vec(py, image.pixels.into_flattened());
    Ok(flat.reshape([image.height, image.width, 3])?.into_any())
}

/// Error metrics of image `a` against the reference `b`, as `fppm diff a.exr b.exr --json`
/// prints them: `rmse`, `rel_mse` (Σ (a − b)² / (b² + 0.01) / n), `mean_ratio` (mean(a) /
/// mean(b); NaN for a black reference), `width`, `height`.
///
/// Args:
///     a, b: arrays (height × width × 3) or paths of EXR files.
///
/// Raises:
///     ValueError: the images differ in size or are not RGB arrays. OSError: a file cannot be
///     read.
#[pyfunction]
pub(crate) fn diff<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    b: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyDict>> {
    let a = image_of(a, "a")?;
    let b = image_of(b, "b")?;
    let m = py.detach(|| guarded(|| film::errors(&a, &b, None).map_err(|e| film_error(&e))))?;
    let out = PyDict::new(py);
    out.set_item("rmse", m.rmse)?;
    out.set_item("rel_mse", m.rel_mse)?;
    out.set_item("mean_ratio", m.mean_ratio)?;
    out.set_item("width", a.width)?;
    out.set_item("height", a.height)?;
    Ok(out)
}
