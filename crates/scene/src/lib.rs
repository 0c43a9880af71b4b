//! The scene runtime: scene descriptions, materials, lights, textures, camera and BVH.
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
//! This crate is the scene runtime only: it reads no file. The `import` crate turns scene files
//! (TOML, OBJ, glTF, Mitsuba 3, pbrt-v4) into a [`SceneDescription`], decoding the images they
//! refer to into [`texture::Image`]s and [`EnvironmentMap`]s; a description built in code is
//! just as good. What makes a description valid is checked in [`validate`], by the importers
//! and by [`Scene::new`]. [`SceneDescription::summary`] gives a [`SceneSummary`] for reports
//! and snapshots.

mod aabb;
mod bvh;
mod camera;
mod density_grid;
mod description;
pub mod fingerprint;
mod frame;
mod light;
mod material;
mod material_spectra;
mod medium;
mod ray;
mod sampling;
mod scene;
pub mod spectral;
mod summary;
#[cfg(test)]
mod test_util;
pub mod texture;
pub mod validate;

pub use aabb::Aabb;
pub use camera::{CameraModel, LensConnection};
pub use density_grid::{
    DensityGrid, GridEdge, GridError, MAJORANT_CELLS, MAX_GRID_VOXELS, MajorantSegment,
    check_grid_size,
};
pub use description::{
    Camera, Cylinder, Film, Light, LoadNotes, MAX_FILM_SIDE, Material, RenderDefaults, Rgb,
    SceneDescription, Sphere, Triangle, primitive_bounds,
};
pub use frame::Frame;
pub use light::{
    EmissionPdf, EmissionSample, EmitterShape, Environment, EnvironmentMap, EnvironmentRadiance,
    LightSample, LightSampler,
};
pub use material::{
    Bsdf, BsdfPdfs, BsdfSample, Conductor, Dielectric, Diffuse, Glossy, Interface, Lobe,
    MaterialKind, MaterialParam, Mirror, RoughDielectric, SMOOTH_ROUGHNESS, TransportMode,
    fresnel_dielectric, luminance,
};
pub use material_spectra::{MaterialSpectra, REPRESENTATIVE_WAVELENGTH};
pub use medium::{
    FreeFlight, HenyeyGreenstein, Media, Medium, MediumShape, PhaseSample, ShapeMedia, medium_after,
};
pub use ray::{Hit, Primitive, Ray};
pub use scene::{Scene, SceneError};
pub use summary::{
    Bounds, CameraSummary, GridSummary, LightCounts, MaterialSummary, MediumSummary, SceneSummary,
    TextureSummary,
};
