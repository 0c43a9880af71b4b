//! Scenes, loaders, materials, lights, camera and BVH.
//!
//! The principal type is [`Scene`], built from a plain [`SceneDescription`] by [`Scene::new`].
//! It answers closest-hit ([`Scene::intersect`]) and shadow ([`Scene::occluded`]) queries through one
//! obvhs CwBvh over triangles and analytic spheres, and owns the [`CameraModel`] and the
//! [`LightSampler`]. Materials become [`Bsdf`]s at a [`Hit`].
//!
//! Conventions: directions point away from surfaces (pbrt); a [`Hit`]'s normals face the side the ray
//! came from and `front_face` says whether that is the primitive's front (counter-clockwise triangle
//! side, sphere outside); curvature is signed as in frequency-algebra §3 (positive = concave seen from
//! the ray's side); secondary rays are spawned with pbrt-v4's error-bound origin offset.

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
