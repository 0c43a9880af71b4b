//! Scenes, loaders, materials, lights, camera and BVH (work in progress for the issue
//! "`geometry`: load real scenes (TOML, OBJ+MTL, glTF), materials, lights, camera, and a fast obvhs BVH").
//!
//! So far this holds the plain scene description that loaders produce.

mod description;

pub use description::{
    Camera, Film, Light, LoadNotes, Material, MaterialKind, RenderDefaults, Rgb, SceneDescription,
    Sphere, Triangle,
};
