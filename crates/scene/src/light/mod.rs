//! Light sampling: next-event estimation toward lights and emission sampling for photons.
//!
//! Every light is an *emitter*: a point, spot or directional light of the description, or one
//! emissive triangle (front face only) or emissive sphere (outward only). Emitters are chosen with
//! probability proportional to the luminance of their total power:
//! - point: 4π·I;
//! - spot: 2π·I·((1 − cos θ_start) + (cos θ_start − cos θ_cone)/2), exact for the smoothstep falloff;
//! - directional: π·r²·E over the disc of radius r that covers the scene's bounding sphere;
//! - area: π·L·A (a Lambertian emitter);
//! - environment: π·r²·∫L dω over the disc of radius r that covers the scene's bounding sphere
//!   (`environment.rs`).
//!
//! Spot falloff (pbrt-v4): intensity × smoothstep(cos θ; cos θ_cone, cos θ_start), i.e. full inside
//! `falloff_start`, zero outside `cone_angle`, a smoothstep in cos θ between.
//!
//! `densities.rs` gives the densities of both samplers per kind of emitter ([`EmissionPdf`]), which
//! the multiple importance sampling weights of bidirectional methods need.

use std::f32::consts::PI;

use glam::{Vec2, Vec3};

use crate::{
    Frame, Hit, Primitive, Ray, Rgb,
    ray::offset_ray_origin,
    sampling::{
        Distribution1D, concentric_disk, cosine_hemisphere, uniform_cone, uniform_sphere,
        uniform_triangle,
    },
};

mod densities;
mod emitters;
mod environment;
#[cfg(test)]
mod tests;
mod textured;
mod tree;

pub use densities::EmissionPdf;
use emitters::Emitter;
pub(crate) use emitters::{Emitters, Powered, powered};

use textured::TexturedTriangle;
use tree::DirectChoice;

use environment::EnvironmentLight;
pub use environment::{Environment, EnvironmentMap, EnvironmentRadiance};

/// What emitted a photon, for the frequency analysis of the emitted light field.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum EmitterShape {
    /// An area emitter (triangle or sphere).
    Area {
        /// Linear size of the emitter: √area for a triangle, the diameter for a sphere.
        size: f32,
        /// Cosine between the emitted direction and the emitter's normal.
        cos_theta: f32,
    },
    /// A point light.
    Point,
    /// A spot light.
    Spot {
        /// Half-angle of the cone in radians.
        cone_angle: f32,
        /// Half-angle in radians up to which the intensity is full.
        falloff_start: f32,
    },
    /// A directional light (photons start on a disc covering the scene).
    Directional,
    /// The environment (photons start on a disc covering the scene): a directional light of
    /// the angular width of the texel the photon comes from.
    Environment {
        /// Angular width in radians: √(solid angle) of the texel, π for a constant sky.
        angle: f32,
    },
}

/// A direction toward a light for next-event estimation at a point.
///
/// The estimate of the reflected radiance is f·|cos θ|·`radiance`/`pdf` when the light is visible
/// (see [`crate::Scene::light_visible`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightSample {
    /// Unit direction from the point toward the light.
    pub incoming: Vec3,
    /// Distance to the sampled point on the light; ∞ for a directional or environment light.
    pub distance: f32,
    /// Incident radiance for area emitters; for delta lights the incident irradiance on a surface
    /// facing the light (I·falloff/d² or E).
    pub radiance: Rgb,
    /// Solid-angle density (including the probability of choosing the light); for delta lights
    /// just the probability of choosing the light.
    pub pdf: f32,
    /// Whether the light is a delta light (point, spot, directional): no BSDF sample can hit it.
    pub is_delta: bool,
}

/// A photon leaving a light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EmissionSample {
    /// Point on the light (on the disc for a directional light).
    pub origin: Vec3,
    /// Unit direction of travel.
    pub direction: Vec3,
    /// Flux carried, already divided by all sampling densities: the mean of `power` over N photons
    /// estimates the total emitted flux ([`LightSampler::total_power`]).
    pub power: Rgb,
    /// Emitter normal (front face of area emitters; the travel direction for the other lights).
    pub normal: Vec3,
    /// What emitted the photon.
    pub emitter: EmitterShape,
    /// Bound on the floating-point error of `origin`, used by [`EmissionSample::ray`].
    origin_error: Vec3,
}

impl EmissionSample {
    /// The photon's ray, with its origin pushed off an area emitter so it cannot hit it at t ≈ 0.
    #[inline]
    pub fn ray(&self) -> Ray {
        Ray::infinite(
            offset_ray_origin(self.origin, self.origin_error, self.normal, self.direction),
            self.direction,
        )
    }
}

/// All emitters of a scene, the distribution that picks them by power for photons, and the
/// choice that picks them by their importance at a point for next-event estimation (`tree.rs`).
#[derive(Clone, Debug)]
pub struct LightSampler {
    emitters: Vec<Emitter>,
    powers: Vec<Rgb>,
    distribution: Distribution1D,
    direct: DirectChoice,
    /// Emitter index per triangle (`u32::MAX` for none); empty if no triangle emits.
    triangle_emitter: Vec<u32>,
    /// Emitter index per sphere (`u32::MAX` for none); empty if no sphere emits.
    sphere_emitter: Vec<u32>,
    /// The emission textures of textured triangle emitters.
    textured: Vec<TexturedTriangle>,
    /// The environment light and its emitter index, if the scene has one.
    environment: Option<(Box<EnvironmentLight>, usize)>,
}

impl LightSampler {
    /// The sampler over emitters that [`powered`] found to carry power: it
    /// cannot fail, the validation has built the distribution.
    pub(crate) fn new(powered: Powered) -> Self {
        let (emitters, distribution) = powered.into_parts();
        let direct = DirectChoice::new(&emitters.emitters, &emitters.weights());
        let (
            Emitters {
                emitters,
                powers,
                triangle_emitter,
                sphere_emitter,
                textured,
                environment,
            },
            distribution,
        ) = (emitters, distribution);
        Self {
            emitters,
            powers,
            distribution,
            direct,
            triangle_emitter,
            sphere_emitter,
            textured,
            environment,
        }
    }

    /// Whether the scene has an environment light.
    #[inline]
    pub fn has_environment(&self) -> bool {
        self.environment.is_some()
    }

    /// Radiance arriving from the environment along the unit world direction `direction`
    /// (what a ray that escapes the scene sees); zero without an environment.
    #[inline]
    pub fn environment_radiance(&self, direction: Vec3) -> Rgb {
        match &self.environment {
            Some((light, _)) => light.eval(direction),
            None => Rgb::ZERO,
        }
    }

    /// Solid-angle density with which [`LightSampler::sample_direct`] draws the environment in
    /// the unit world direction `direction` (for multiple importance sampling of escaped rays);
    /// zero without an environment.
    pub fn pdf_environment(&self, direction: Vec3) -> f32 {
        match &self.environment {
            // The infinite lights' share does not depend on the point.
            Some((light, idx)) => {
                self.direct.pmf(Vec3::ZERO, Vec3::ZERO, *idx) * light.pdf(direction)
            }
            None => 0.0,
        }
    }

    /// Number of emitters (lights plus emissive triangles and spheres).
    pub fn emitter_count(&self) -> usize {
        self.emitters.len()
    }

    /// Total emitted flux (W per channel) of emitter `idx`; zero if out of range.
    pub fn emitter_power(&self, idx: usize) -> Rgb {
        self.powers.get(idx).copied().unwrap_or(Rgb::ZERO)
    }

    /// Total emitted flux of the scene (W per channel).
    pub fn total_power(&self) -> Rgb {
        self.powers.iter().copied().sum()
    }

    /// Samples a direction toward a light as seen from `point` on a surface of unit `normal`
    /// (zero where there is no surface): `u_light` ∈ [0, 1) picks the emitter (an infinite light
    /// by its share of the power, the others by their importance at the point, `tree.rs`), `u` ∈
    /// [0, 1)² the point on it. `None` when the sample carries nothing (outside a spot cone,
    /// behind a one-sided emitter, no emitter facing the point).
    pub fn sample_direct(
        &self,
        point: Vec3,
        normal: Vec3,
        u_light: f32,
        u: Vec2,
    ) -> Option<LightSample> {
        let (idx, p_light) = self.direct.sample(point, normal, u_light)?;
        let (target, radiance, pdf_area_to_solid) = match self.emitters[idx] {
            Emitter::Point {
                position,
                intensity,
            } => {
                let d = position - point;
                let d2 = d.length_squared();
                return (d2 > 0.0).then(|| LightSample {
                    incoming: d / d2.sqrt(),
                    distance: d2.sqrt(),
                    radiance: intensity / d2,
                    pdf: p_light,
                    is_delta: true,
                });
            }
            Emitter::Spot {
                position,
                frame,
                intensity,
                cos_cone,
                cos_start,
                ..
            } => {
                let d = position - point;
                let d2 = d.length_squared();
                let dist = d2.sqrt();
                let incoming = d / dist;
                let falloff = spot_falloff(-incoming.dot(frame.n), cos_cone, cos_start);
                return (d2 > 0.0 && falloff > 0.0).then(|| LightSample {
                    incoming,
                    distance: dist,
                    radiance: intensity * (falloff / d2),
                    pdf: p_light,
                    is_delta: true,
                });
            }
            Emitter::Directional {
                frame, irradiance, ..
            } => {
                return Some(LightSample {
                    incoming: -frame.n,
                    distance: f32::INFINITY,
                    radiance: irradiance,
                    pdf: p_light,
                    is_delta: true,
                });
            }
            Emitter::Triangle {
                p0,
                e1,
                e2,
                normal,
                area,
                radiance,
                texture,
                ..
            } => {
                let b = uniform_triangle(u);
                let radiance = match self.textured.get(texture as usize) {
                    None => radiance,
                    Some(t) => t.radiance(b),
                };
                (p0 + b.x * e1 + b.y * e2, radiance, (normal, area))
            }
            Emitter::Sphere {
                center,
                radius,
                radiance,
            } => {
                let n = uniform_sphere(u);
                (
                    center + radius * n,
                    radiance,
                    (n, 4.0 * PI * radius * radius),
                )
            }
            Emitter::Environment => {
                let (light, _) = self.environment.as_ref()?;
                let s = light.sample(u)?;
                let pdf = p_light * s.pdf;
                return (pdf > 0.0 && pdf.is_finite()).then_some(LightSample {
                    incoming: s.direction,
                    distance: f32::INFINITY,
                    radiance: s.radiance,
                    pdf,
                    is_delta: false,
                });
            }
        };
        let (normal, area) = pdf_area_to_solid;
        let d = target - point;
        let d2 = d.length_squared();
        let distance = d2.sqrt();
        let incoming = d / distance;
        let cos_light = -incoming.dot(normal);
        if !(cos_light > 0.0 && d2 > 0.0) {
            return None;
        }
        let pdf = p_light * d2 / (cos_light * area);
        pdf.is_finite().then_some(LightSample {
            incoming,
            distance,
            radiance,
            pdf,
            is_delta: false,
        })
    }

    /// Solid-angle density with which [`LightSampler::sample_direct`] at `point` with `normal`
    /// draws the point of `hit` on an emitter (for multiple importance sampling); zero if `hit` is
    /// not on an emitting front face.
    pub fn pdf_direct(&self, point: Vec3, normal: Vec3, hit: &Hit) -> f32 {
        if !hit.front_face {
            return 0.0;
        }
        let idx = match hit.primitive {
            Primitive::Triangle(i) => self.triangle_emitter.get(i as usize),
            Primitive::Sphere(i) => self.sphere_emitter.get(i as usize),
            Primitive::Cylinder(_) => None,
        };
        let Some(&idx) = idx.filter(|&&i| i != u32::MAX) else {
            return 0.0;
        };
        let area = match self.emitters[idx as usize] {
            Emitter::Triangle { area, .. } => area,
            Emitter::Sphere { radius, .. } => 4.0 * PI * radius * radius,
            _ => return 0.0,
        };
        let d = hit.position - point;
        let d2 = d.length_squared();
        let cos_light = hit.geometric_normal.dot(d).abs() / d2.sqrt();
        if cos_light.is_nan() || cos_light <= 0.0 {
            return 0.0;
        }
        self.direct.pmf(point, normal, idx as usize) * d2 / (cos_light * area)
    }

    /// Samples a photon: `u_light` ∈ [0, 1) picks the emitter by power, `u_pos` ∈ [0, 1)² the point
    /// on it (or on the directional light's disc) and `u_dir` ∈ [0, 1)² the direction (cosine-weighted
    /// about the normal for area emitters, uniform for point lights, uniform in the cone for spots).
    pub fn sample_emission(
        &self,
        u_light: f32,
        u_pos: Vec2,
        u_dir: Vec2,
    ) -> Option<EmissionSample> {
        let (idx, p_light) = self.distribution.sample(u_light);
        if p_light.is_nan() || p_light <= 0.0 {
            return None;
        }
        let sample = match self.emitters[idx] {
            Emitter::Point {
                position,
                intensity,
            } => {
                let direction = uniform_sphere(u_dir);
                EmissionSample {
                    origin: position,
                    direction,
                    power: intensity * (4.0 * PI),
                    normal: direction,
                    emitter: EmitterShape::Point,
                    origin_error: Vec3::ZERO,
                }
            }
            Emitter::Spot {
                position,
                frame,
                intensity,
                cos_cone,
                cos_start,
                cone_angle,
                falloff_start,
            } => {
                let local = uniform_cone(u_dir, cos_cone);
                let falloff = spot_falloff(local.z, cos_cone, cos_start);
                let direction = frame.to_world(local);
                EmissionSample {
                    origin: position,
                    direction,
                    power: intensity * (falloff * 2.0 * PI * (1.0 - cos_cone)),
                    normal: direction,
                    emitter: EmitterShape::Spot {
                        cone_angle,
                        falloff_start,
                    },
                    origin_error: Vec3::ZERO,
                }
            }
            Emitter::Directional {
                frame,
                irradiance,
                center,
                radius,
            } => {
                let disc = radius * concentric_disk(u_pos);
                let origin = center - radius * frame.n + disc.x * frame.s + disc.y * frame.t;
                EmissionSample {
                    origin,
                    direction: frame.n,
                    power: irradiance * (PI * radius * radius),
                    normal: frame.n,
                    emitter: EmitterShape::Directional,
                    origin_error: Vec3::ZERO,
                }
            }
            Emitter::Triangle {
                p0,
                normal,
                p1,
                p2,
                frame,
                size,
                flux,
                texture,
                area,
                ..
            } => {
                let b = uniform_triangle(u_pos);
                let flux = match self.textured.get(texture as usize) {
                    None => flux,
                    Some(t) => t.radiance(b) * (PI * area),
                };
                let b0 = 1.0 - b.x - b.y;
                let origin = b0 * p0 + b.x * p1 + b.y * p2;
                let error =
                    (7.0 * f32::EPSILON) * ((b0 * p0).abs() + (b.x * p1).abs() + (b.y * p2).abs());
                let local = cosine_hemisphere(u_dir);
                let direction = frame.to_world(local);
                EmissionSample {
                    origin,
                    direction,
                    power: flux,
                    normal,
                    emitter: EmitterShape::Area {
                        size,
                        cos_theta: local.z,
                    },
                    origin_error: error,
                }
            }
            Emitter::Sphere {
                center,
                radius,
                radiance,
            } => {
                let normal = uniform_sphere(u_pos);
                let origin = center + radius * normal;
                let local = cosine_hemisphere(u_dir);
                let direction = Frame::from_normal(normal).to_world(local);
                EmissionSample {
                    origin,
                    direction,
                    power: radiance * (PI * 4.0 * PI * radius * radius),
                    normal,
                    emitter: EmitterShape::Area {
                        size: 2.0 * radius,
                        cos_theta: local.z,
                    },
                    origin_error: (8.0 * f32::EPSILON) * (origin.abs() + center.abs()),
                }
            }
            Emitter::Environment => {
                let (light, _) = self.environment.as_ref()?;
                let (origin, direction, power, angle) = light.sample_emission(u_pos, u_dir)?;
                EmissionSample {
                    origin,
                    direction,
                    power,
                    normal: direction,
                    emitter: EmitterShape::Environment { angle },
                    origin_error: Vec3::ZERO,
                }
            }
        };
        let power = sample.power / p_light;
        (power.is_finite() && power.cmpgt(Rgb::ZERO).any())
            .then_some(EmissionSample { power, ..sample })
    }
}

/// Spot falloff: 1 inside `cos_start`, 0 outside `cos_cone`, smoothstep in cos θ between (pbrt-v4).
fn spot_falloff(cos_theta: f32, cos_cone: f32, cos_start: f32) -> f32 {
    if cos_theta >= cos_start {
        return 1.0;
    }
    if cos_theta <= cos_cone {
        return 0.0;
    }
    let x = ((cos_theta - cos_cone) / (cos_start - cos_cone)).clamp(0.0, 1.0);
    x * x * (3.0 - 2.0 * x)
}
