//! Scenes: `fppm.load`, `fppm.load_string`, `fppm.default_scene` and the `Scene` they return.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict, PyString};
use scene::SceneDescription;

use crate::errors::{load_error, message};
use crate::{SceneError, guarded};

/// The `fppm` command's built-in default scene (`fppm scene default`).
const DEFAULT_SCENE: &str = include_str!("../../cli/src/default_scene.toml");
/// The name it is loaded under, as the command names it.
const DEFAULT_SCENE_NAME: &str = "<built-in default scene>";

/// A loaded scene, ready to render: its description and the acceleration structure built from
/// it. Immutable; one scene may be shared by several renderers.
///
/// Made by `fppm.load`, `fppm.load_string` or `fppm.default_scene`.
#[pyclass(module = "fppm", frozen)]
pub(crate) struct Scene {
    pub(crate) scene: Arc<scene::Scene>,
}

impl Scene {
    pub(crate) fn description(&self) -> &SceneDescription {
        self.scene.description()
    }
}

#[pymethods]
impl Scene {
    /// What `fppm info` prints, as a dict: counts of triangles, spheres, cylinders, emitters
    /// and lights, the environment, the materials with their parameters, the camera, the film
    /// size, the bounds, the loader's warnings and the textures.
    fn info<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        guarded(|| {
            let summary = self.description().summary();
            let mut value = serde_json::to_value(&summary).map_err(|e| {
                crate::InternalError::new_err(format!("cannot report the scene: {e}"))
            })?;
            if let Some(object) = value.as_object_mut() {
                object.insert("emitters".to_owned(), summary.emitters().into());
                object.insert("environment".to_owned(), summary.environment.clone().into());
            }
            crate::convert::to_python(py, &value)
        })
    }

    /// The scene file (or the name a scene given as text was loaded under).
    #[getter]
    fn source(&self) -> String {
        self.description().source.display().to_string()
    }

    /// Film width in pixels.
    #[getter]
    fn width(&self) -> u32 {
        self.description().film.width
    }

    /// Film height in pixels.
    #[getter]
    fn height(&self) -> u32 {
        self.description().film.height
    }

    /// The passes the scene's `[render]` table asks for, if it does.
    #[getter]
    fn passes(&self) -> Option<u32> {
        self.description().render.passes
    }

    /// The scene's `[render]` table: render parameters by name, as text.
    #[getter]
    fn render_defaults<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let out = PyDict::new(py);
        for (name, value) in &self.description().render.params {
            out.set_item(name, value)?;
        }
        Ok(out)
    }

    /// What `fppm info` prints, as text.
    fn __str__(&self) -> String {
        guarded(|| Ok(summary_text(self.description()))).unwrap_or_default()
    }

    fn __repr__(&self) -> String {
        let d = self.description();
        format!(
            "<fppm.Scene {:?} {}x{}, {} triangles, {} spheres>",
            d.source.display().to_string(),
            d.film.width,
            d.film.height,
            d.triangles.len(),
            d.spheres.len()
        )
    }
}

fn summary_text(description: &SceneDescription) -> String {
    let summary = description.summary();
    let mut text = summary.to_string();
    if summary.emitters() == 0 {
        text.push_str("emitters   none: this scene has no emitter and renders black\n");
    }
    text
}

/// Loads a scene file: TOML (`.toml`), OBJ (`.obj`), glTF (`.gltf`, `.glb`), Mitsuba 3
/// (`.xml`) or pbrt-v4 (`.pbrt`), as `fppm render` does.
///
/// Args:
///     path: the scene file.
///     env: an environment map (`.exr` or `.hdr`) that lights the scene, as `--env`.
///     width, height: the film size, as `--width`/`--height` (one alone keeps the aspect ratio).
///
/// Raises:
///     FileNotFoundError, OSError: the file, or one it refers to, cannot be read.
///     fppm.SceneError: the scene is malformed, out of range or has no emitter.
///     ValueError: a film size outside [1, 16384].
#[pyfunction]
#[pyo3(signature = (path, *, env=None, width=None, height=None))]
pub(crate) fn load(
    py: Python<'_>,
    path: PathBuf,
    env: Option<PathBuf>,
    width: Option<u32>,
    height: Option<u32>,
) -> PyResult<Scene> {
    check_film(width, height)?;
    let options = import::LoadOptions {
        environment: env,
        ..import::LoadOptions::default()
    };
    guarded(|| {
        let description = py
            .detach(|| guarded(|| Ok(import::load_with(&path, &options))))?
            .map_err(|e| load_error(&e))?;
        build(py, description, (width, height))
    })
}

/// Loads a scene held in a string, as if read from a file named `name` in `base_dir`.
///
/// Args:
///     text: the scene file's content.
///     format: `"toml"`, `"obj"`, `"gltf"`, `"xml"` (Mitsuba 3) or `"pbrt"`.
///     files: other files the scene refers to, by path relative to `base_dir` (or absolute),
///         as `str` or `bytes`; a file not given is read from the file system.
///     base_dir: where the scene's relative paths start (default: the working directory).
///     name: the scene's file name, which errors quote (default: `<string>.FORMAT`).
///     env, width, height: as for `load`.
///
/// Raises:
///     fppm.SceneError, OSError, ValueError: as `load`; ValueError for an unknown format.
#[pyfunction]
#[pyo3(signature = (text, format="toml", *, files=None, base_dir=None, name=None, env=None,
    width=None, height=None))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn load_string(
    py: Python<'_>,
    text: &str,
    format: &str,
    files: Option<&Bound<'_, PyDict>>,
    base_dir: Option<PathBuf>,
    name: Option<String>,
    env: Option<PathBuf>,
    width: Option<u32>,
    height: Option<u32>,
) -> PyResult<Scene> {
    check_film(width, height)?;
    let format = format.to_ascii_lowercase();
    if !["toml", "obj", "gltf", "xml", "pbrt"].contains(&format.as_str()) {
        return Err(PyValueError::new_err(format!(
            "format {format:?} is not one of toml, obj, gltf, xml, pbrt"
        )));
    }
    let base = base_dir.unwrap_or_default();
    let path = base.join(name.unwrap_or_else(|| format!("<string>.{format}")));
    let mut served: HashMap<PathBuf, Vec<u8>> = HashMap::new();
    if let Some(files) = files {
        for (key, value) in files.iter() {
            let key: PathBuf = key.extract()?;
            let bytes = if let Ok(s) = value.cast::<PyString>() {
                s.to_str()?.as_bytes().to_vec()
            } else if let Ok(b) = value.cast::<PyBytes>() {
                b.as_bytes().to_vec()
            } else {
                return Err(pyo3::exceptions::PyTypeError::new_err(format!(
                    "files[{:?}] must be str or bytes",
                    key.display().to_string()
                )));
            };
            served.insert(normalize(&base.join(key)), bytes);
        }
    }
    served.insert(normalize(&path), text.as_bytes().to_vec());
    let options = import::LoadOptions {
        environment: env,
        ..import::LoadOptions::default()
    };
    guarded(|| {
        let source = move |p: &Path| -> std::io::Result<Vec<u8>> {
            match served.get(&normalize(p)) {
                Some(bytes) => Ok(bytes.clone()),
                None => std::fs::read(p),
            }
        };
        let description = py
            .detach(|| guarded(|| Ok(import::load_from(&path, source, &options))))?
            .map_err(|e| load_error(&e))?;
        build(py, description, (width, height))
    })
}

/// The `fppm` command's built-in default scene (`fppm scene default` prints it): a nephroid
/// caustic inside a mirror half-cylinder, 512 × 384.
///
/// Args:
///     width, height: the film size, as for `load`.
#[pyfunction]
#[pyo3(signature = (*, width=None, height=None))]
pub(crate) fn default_scene(
    py: Python<'_>,
    width: Option<u32>,
    height: Option<u32>,
) -> PyResult<Scene> {
    check_film(width, height)?;
    guarded(|| {
        let description = import::load_toml_str(DEFAULT_SCENE, Path::new(DEFAULT_SCENE_NAME))
            .map_err(|e| load_error(&e))?;
        build(py, description, (width, height))
    })
}

/// Applies the film size and builds the scene (its BVH) without the GIL.
fn build(
    py: Python<'_>,
    mut description: SceneDescription,
    film: (Option<u32>, Option<u32>),
) -> PyResult<Scene> {
    apply_film(&mut description, film);
    let scene = py
        .detach(|| guarded(|| Ok(scene::Scene::new(description))))?
        .map_err(|e| SceneError::new_err(message(&e)))?;
    Ok(Scene {
        scene: Arc::new(scene),
    })
}

fn check_film(width: Option<u32>, height: Option<u32>) -> PyResult<()> {
    for (name, value) in [("width", width), ("height", height)] {
        if let Some(v) = value
            && !(1..=scene::MAX_FILM_SIDE).contains(&v)
        {
            return Err(PyValueError::new_err(format!(
                "{name} {v} is outside [1, {}]",
                scene::MAX_FILM_SIDE
            )));
        }
    }
    Ok(())
}

/// Sets the film size as `fppm render --width/--height` does: a lone side keeps the scene's
/// aspect ratio.
fn apply_film(description: &mut SceneDescription, (width, height): (Option<u32>, Option<u32>)) {
    description.film = description.film.resized(width, height);
}

/// `a/./b` and `a/c/../b` as `a/b`: the loaders join relative names to a file's directory.
fn normalize(path: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for c in path.components() {
        match c {
            std::path::Component::CurDir => {}
            std::path::Component::ParentDir
                if matches!(
                    out.components().next_back(),
                    Some(std::path::Component::Normal(_))
                ) =>
            {
                out.pop();
            }
            _ => out.push(c),
        }
    }
    out
}
