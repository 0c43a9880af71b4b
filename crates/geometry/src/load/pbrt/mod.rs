//! pbrt-v4 scenes (`.pbrt`).

use std::path::Path;

use super::LoadOptions;
use crate::description::SceneDescription;
use crate::error::LoadError;

/// Loads a pbrt-v4 scene.
pub(crate) fn load_pbrt(
    path: &Path,
    _options: &LoadOptions,
) -> Result<SceneDescription, LoadError> {
    Err(LoadError::Pbrt {
        path: path.to_path_buf(),
        line: None,
        column: None,
        message: "pbrt scenes are not supported yet".to_owned(),
    })
}
