//! TOML scene files, format version 1 (`shared/design/scene-format.md`).
//!
//! The file is read with serde (`schema.rs`: `deny_unknown_fields`, internally tagged `type`
//! enums) and converted (`convert.rs`). The toml crate reports the byte span of a problem but
//! not the table it is in; `errors.rs` recovers the table (`[materials.white]`,
//! `[[shapes]] #2`) from the text before the span and sorts serde's standard messages into
//! [`LoadError`] variants.
//!
//! Decisions beyond the format page: `[camera]` is optional (a missing camera frames the
//! bounding box) and so is `[film]` (512 × 512); film sides are 1 to 16384; albedo and
//! reflectance must lie in [0, 1]; a spot light's `falloff_start` defaults to `cone_angle`
//! (a hard edge); `cone_angle` is in (0, 180]; a mesh file's own materials are named
//! `FILE/NAME` in the scene; lights and cameras inside a mesh file are ignored (with a warning).
//!
//! Extensions (`docs/scene-format-extensions.md`): the `cylinder` shape, an analytic open
//! cylinder cut to an optional arc; its material must not emit. Participating media:
//! `[media.NAME]` tables, `interior`/`exterior` on mesh and sphere shapes, `[camera] medium`,
//! and the `interface` material (`media.rs`).

use std::path::Path;

use crate::LoadOptions;
use crate::error::LoadError;
use scene::SceneDescription;

mod convert;
mod errors;
mod lights;
mod materials;
mod media;
mod schema;

use self::convert::Converter;
use self::errors::{schema_error, syntax_error};
use self::schema::SceneFile;

/// Parses and converts a TOML scene.
pub(crate) fn load_toml(
    text: &str,
    path: &Path,
    options: &LoadOptions,
) -> Result<SceneDescription, LoadError> {
    // Syntax first, then the version, so that a future version's keys are not reported as
    // unknown keys.
    let table: ::toml::Table = ::toml::from_str(text).map_err(|e| syntax_error(path, text, &e))?;
    match table.get("format") {
        None => {
            return Err(LoadError::MissingKey {
                path: path.to_path_buf(),
                line: None,
                column: None,
                table: "the top level".to_owned(),
                key: "format".to_owned(),
            });
        }
        Some(::toml::Value::Integer(1)) => {}
        Some(::toml::Value::Integer(v)) => {
            return Err(LoadError::UnsupportedVersion {
                path: path.to_path_buf(),
                found: v.to_string(),
            });
        }
        Some(other) => {
            return Err(LoadError::WrongType {
                path: path.to_path_buf(),
                line: None,
                column: None,
                table: "the top level".to_owned(),
                key: "format".to_owned(),
                message: format!("expected the integer 1, got {} {other}", other.type_str()),
            });
        }
    }
    let file: SceneFile = ::toml::from_str(text).map_err(|e| schema_error(path, text, &e))?;
    Converter {
        path,
        dir: path.parent().unwrap_or(Path::new("")),
        textures: std::cell::RefCell::default(),
    }
    .convert(file, options)
}
