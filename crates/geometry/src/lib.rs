//! Scenes, loaders, materials, lights, camera and BVH (work in progress for the issue
//! "`geometry`: load real scenes (TOML, OBJ+MTL, glTF), materials, lights, camera, and a fast obvhs BVH").
//!
//! The loaders turn a scene file into a plain [`SceneDescription`]:
//! [`load`] picks the loader by extension (`.toml` scene files of format version 1, lone
//! `.obj` files with their `.mtl`, `.gltf`/`.glb` files), [`load_toml_str`] reads a TOML scene
//! held in memory, and [`load_with`] takes [`LoadOptions`] (e.g. to accept a scene without
//! emitters for `fppm info`). Every failure is a [`LoadError`] naming the file.
//! [`SceneDescription::summary`] gives a [`SceneSummary`] for reports and snapshots.
//!
//! What the loaders decide where the scene format (`shared/design/scene-format.md`) is silent:
//! - no camera (lone OBJ, glTF without a perspective camera, TOML without `[camera]`): a
//!   pinhole on the +Z side of the bounding box looking down −Z at its centre, up +Y,
//!   [`FRAMED_FOV_Y_DEGREES`], far enough that the box's front face fills the image with a 5 %
//!   margin ([`LoadNotes::camera_framed`] is set);
//! - film [`DEFAULT_FILM_WIDTH`] × [`DEFAULT_FILM_HEIGHT`] unless given; a glTF camera's aspect
//!   ratio sets the height; sides at most [`MAX_FILM_SIDE`];
//! - OBJ faces without a (loadable) material get a diffuse material of albedo
//!   [`DEFAULT_ALBEDO`]; a missing MTL file is a warning, a malformed one an error; `Ka` is
//!   never emission (a warning says so when it looks like it was meant to be);
//! - glTF materials with metallic ≥ [`METALLIC_THRESHOLD`] are conductors (mirror below
//!   roughness 0.01, else glossy with α = roughness²);
//! - zero-area triangles are skipped and counted in [`LoadNotes::degenerate_triangles`];
//!   an emissive material left with no area is an error ([`LoadError::ZeroAreaEmitter`]).

mod description;
mod error;
mod load;
mod summary;

pub use description::{
    Camera, Film, Light, LoadNotes, Material, MaterialKind, RenderDefaults, Rgb, SceneDescription,
    Sphere, Triangle,
};
pub use error::LoadError;
pub use load::{
    DEFAULT_ALBEDO, DEFAULT_FILM_HEIGHT, DEFAULT_FILM_WIDTH, FRAMED_FOV_Y_DEGREES, LoadOptions,
    MAX_FILM_SIDE, METALLIC_THRESHOLD, load, load_toml_str, load_toml_str_with, load_with,
};
pub use summary::{Bounds, CameraSummary, F6, LightCounts, MaterialSummary, Rgb6, SceneSummary};
