//! Scenes, loaders, materials, lights, camera and BVH.
//!
//! The principal type is [`Scene`], built from a plain [`SceneDescription`] by [`Scene::new`].
//! It answers closest-hit ([`Scene::intersect`]) and shadow ([`Scene::occluded`], [`Scene::visible`])
//! queries through one BVH over triangles, analytic spheres and analytic open cylinders
//! (a scene-format extension, `docs/scene-format-extensions.md`), and owns the
//! [`CameraModel`] and the [`LightSampler`]. Materials become [`Bsdf`]s at a [`Hit`].
//!
//! Conventions:
//! - Directions point away from surfaces (pbrt): a BSDF's `outgoing` points back along the path.
//! - A [`Hit`]'s normals face the side the ray came from; `front_face` says whether that is the
//!   primitive's front (the counter-clockwise side of a triangle, the outside of a sphere or of
//!   a cylinder).
//!   Emission leaves front faces only; a dielectric's outside is its front.
//! - [`Hit::curvature`] is signed as in frequency-algebra §3: positive when the centre of curvature
//!   lies on the side the ray came from (a sphere: −1/R from outside, +1/R from inside). It is
//!   the largest principal curvature from that side, the one that focuses most: a cylinder,
//!   curved by 1/R around its axis and not along it, gives 0 from outside and +1/R from inside.
//! - Secondary rays ([`Hit::spawn_ray`], [`Hit::spawn_ray_to`]) start off the surface by pbrt-v4's
//!   floating-point error bound, so they neither re-hit their surface nor slip through corners.
//! - Refraction scales radiance by 1/η′² on camera paths only ([`TransportMode`]).
//!
//! obvhs builds the BVH; the crate collapses it into its own 8-wide SIMD layout for traversal
//! (see `bvh/mod.rs`), which is exact: it never culls a primitive the ray meets.
//!
//! The loaders turn a scene file into a plain [`SceneDescription`]:
//! [`load()`] picks the loader by extension (`.toml` scene files of format version 1, lone
//! `.obj` files with their `.mtl`, `.gltf`/`.glb` files, Mitsuba 3 `.xml` and pbrt-v4 `.pbrt`
//! scenes, whose mapping is in `docs/scene-import.md`), [`load_toml_str`] reads a TOML scene
//! held in memory, [`load_from`] reads a scene and the files it refers to from a [`FileSource`]
//! (e.g. [`MemoryFiles`]) instead of the file system, and [`load_with`] takes [`LoadOptions`] (e.g. to accept a scene without
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

mod aabb;
mod bsdf;
mod bvh;
mod camera;
mod description;
mod error;
mod frame;
mod guard;
mod light;
mod load;
mod ray;
mod sampling;
mod scene;
mod summary;
#[cfg(test)]
mod test_util;
pub mod texture;
mod validate;

pub use aabb::Aabb;
pub use bsdf::{Bsdf, BsdfSample, Lobe, TransportMode, fresnel_dielectric};
pub use camera::{CameraModel, LensConnection};
pub use description::{
    Camera, Cylinder, Film, Light, LoadNotes, Material, MaterialKind, RenderDefaults, Rgb,
    SceneDescription, Sphere, Triangle,
};
pub use error::LoadError;
pub use frame::Frame;
pub use guard::containing_a_panic;
pub use light::{
    EmissionSample, EmitterShape, Environment, EnvironmentMap, EnvironmentRadiance, LightSample,
    LightSampler,
};
pub use load::{
    DEFAULT_ALBEDO, DEFAULT_FILM_HEIGHT, DEFAULT_FILM_WIDTH, FRAMED_FOV_Y_DEGREES, FileSource,
    LoadOptions, MAX_FILM_SIDE, METALLIC_THRESHOLD, MemoryFiles, load, load_from, load_toml_str,
    load_toml_str_with, load_with,
};
pub use ray::{Hit, Primitive, Ray};
pub use scene::{Scene, SceneError};
pub use summary::{Bounds, CameraSummary, LightCounts, MaterialSummary, SceneSummary};
