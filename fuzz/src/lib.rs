//! What the fuzz targets share: the stub files and the checkpoint framing ([`harness`], also
//! used by `xtask`), and the checks run on whatever loads.
//!
//! Every target reads its input in memory (no temporary files): scenes through
//! [`import::load_from`] with a resolver closure, checkpoints and EXRs from byte slices.

mod harness;

use std::path::Path;

use import::LoadOptions;
use scene::{Scene, SceneDescription};

pub use harness::*;

/// Loads `path` from `files` and, if it loads, builds the [`Scene`] (validation, lights, BVH)
/// and summarises it: what every loader target runs.
pub fn load_and_build(path: &Path, files: impl import::FileSource + 'static) {
    let Ok(description) = import::load_from(path, files, &LoadOptions::allow_no_emitter()) else {
        return;
    };
    build(description);
}

/// Summarises a description and builds its scene; errors are fine, panics are not.
pub fn build(description: SceneDescription) -> Option<Scene> {
    let _ = description.summary();
    Scene::new(description).ok()
}
