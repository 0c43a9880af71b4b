//! Scenes, loaders, materials, lights, camera and BVH (work in progress for the issue
//! "`geometry`: load real scenes (TOML, OBJ+MTL, glTF), materials, lights, camera, and a fast obvhs BVH").
//!
//! The loaders turn a scene file into a plain [`SceneDescription`]:
//! [`load`] picks the loader by extension (`.toml` scene files of format version 1, lone
//! `.obj` files with their `.mtl`, `.gltf`/`.glb` files), [`load_toml_str`] reads a TOML scene
//! held in memory, and [`load_with`] takes [`LoadOptions`] (e.g. to accept a scene without
//! emitters for `fppm info`). Every failure is a [`LoadError`] naming the file.
//! [`SceneDescription::summary`] gives a [`SceneSummary`] for reports and snapshots.

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
