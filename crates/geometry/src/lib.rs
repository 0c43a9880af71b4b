//! Scenes, loaders, materials, lights, camera and BVH.
//!
//! The principal type is [`Scene`], built from a plain [`SceneDescription`] by [`Scene::new`].
//! It answers closest-hit ([`Scene::intersect`]) and shadow ([`Scene::occluded`], [`Scene::visible`])
//! queries through one obvhs CwBvh over triangles and analytic spheres, and owns the
//! [`CameraModel`] and the [`LightSampler`]. Materials become [`Bsdf`]s at a [`Hit`].
//!
//! Conventions:
//! - Directions point away from surfaces (pbrt): a BSDF's `outgoing` points back along the path.
//! - A [`Hit`]'s normals face the side the ray came from; `front_face` says whether that is the
//!   primitive's front (the counter-clockwise side of a triangle, the outside of a sphere).
//!   Emission leaves front faces only; a dielectric's outside is its front.
//! - [`Hit::curvature`] is signed as in frequency-algebra §3: positive when the centre of curvature
//!   lies on the side the ray came from (a sphere: −1/R from outside, +1/R from inside).
//! - Secondary rays ([`Hit::spawn_ray`], [`Hit::spawn_ray_to`]) start off the surface by pbrt-v4's
//!   floating-point error bound, so they neither re-hit their surface nor slip through corners.
//! - Refraction scales radiance by 1/η′² on camera paths only ([`TransportMode`]).
//!
//! The BVH works around two obvhs 0.4 limitations: `-0.0` direction components (crates.md G1) and
//! the CwBvh's culling of boxes a ray leaves within t < 10⁻⁴ (see `bvh.rs`).

mod aabb;
mod bsdf;
mod bvh;
mod camera;
mod description;
mod frame;
mod light;
mod ray;
mod sampling;
mod scene;
#[cfg(test)]
mod test_util;

pub use aabb::Aabb;
pub use bsdf::{Bsdf, BsdfSample, Lobe, TransportMode, fresnel_dielectric};
pub use camera::CameraModel;
pub use description::{
    Camera, Film, Light, LoadNotes, Material, MaterialKind, RenderDefaults, Rgb, SceneDescription,
    Sphere, Triangle,
};
pub use frame::Frame;
pub use light::{EmissionSample, EmitterShape, LightSample, LightSampler};
pub use ray::{Hit, Primitive, Ray};
pub use scene::{Scene, SceneError};
