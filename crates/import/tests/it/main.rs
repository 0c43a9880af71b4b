//! Integration tests of the scene loaders (one test binary, see house style §20).

#![allow(clippy::unwrap_used, clippy::print_stdout, clippy::print_stderr)]

mod bad_input;
mod cylinder;
mod fuzz_regressions;
mod gltf;
mod grid_media;
mod import_textures;
mod media;
mod mitsuba;
mod obj;
mod pbrt;
mod pbrt_media;
mod rough_dielectric;
mod shared_scenes;
mod spectra;
mod toml_scene;

use std::path::{Path, PathBuf};

/// The shared scene folder (`/work/shared/scenes` on the project machines).
pub(crate) fn shared_scenes() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/scenes")
}

/// A fresh, empty directory for one test's fixtures.
pub(crate) fn temp_dir(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("fppm-import-tests-{}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Writes `files` (name, text) into a fresh directory and returns the path of the first.
pub(crate) fn fixture(test: &str, files: &[(&str, &str)]) -> PathBuf {
    let dir = temp_dir(test);
    for (name, text) in files {
        std::fs::write(dir.join(name), text).unwrap();
    }
    dir.join(files[0].0)
}

/// Asserts that the error's message is one line and starts with the file's path.
#[track_caller]
pub(crate) fn assert_names_file(err: &import::LoadError, file: &Path) {
    let msg = err.to_string();
    assert!(
        msg.starts_with(&file.display().to_string()),
        "message {msg:?} does not start with {}",
        file.display()
    );
    assert!(!msg.contains('\n'), "message {msg:?} is not one line");
    assert_eq!(err.path(), file);
}
