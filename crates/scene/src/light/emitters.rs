//! The emitters of a scene, collected from a valid description ([`Emitters::collect`]), and
//! the check that some of them carry power ([`powered`]), whose [`Powered`] result the
//! sampler is built from.

use std::f32::consts::PI;

use glam::{Vec2, Vec3};

use super::environment::EnvironmentLight;
use super::textured::TexturedTriangle;
use crate::material::luminance;
use crate::sampling::Distribution1D;
use crate::validate::Invalid;
use crate::{Aabb, Frame, Light, Rgb, SceneDescription};

/// One emitter, ready for sampling.
#[derive(Clone, Copy, Debug)]
pub(super) enum Emitter {
    Point {
        position: Vec3,
        intensity: Rgb,
    },
    Spot {
        position: Vec3,
        frame: Frame,
        intensity: Rgb,
        cos_cone: f32,
        cos_start: f32,
        cone_angle: f32,
        falloff_start: f32,
    },
    Directional {
        frame: Frame,
        irradiance: Rgb,
        center: Vec3,
        radius: f32,
    },
    Triangle {
        p0: Vec3,
        e1: Vec3,
        e2: Vec3,
        normal: Vec3,
        area: f32,
        radiance: Rgb,
        /// What [`super::LightSampler::sample_emission`] needs, computed once here by the same
        /// expressions as it would per photon (so hoisting them changes no photon):
        /// `p0 + e1`, `p0 + e2`, the frame about `normal`, √area and π·L·A.
        p1: Vec3,
        p2: Vec3,
        frame: Frame,
        size: f32,
        flux: Rgb,
        /// Index into the textured emitters when an emission texture modulates `radiance`
        /// (which then holds the texture's mean over the triangle), else `u32::MAX`.
        texture: u32,
    },
    Sphere {
        center: Vec3,
        radius: f32,
        radiance: Rgb,
    },
    /// The scene's environment, held by [`super::LightSampler::environment`].
    Environment,
}

impl Emitter {
    fn power(&self) -> Rgb {
        match *self {
            Emitter::Point { intensity, .. } => intensity * (4.0 * PI),
            Emitter::Spot {
                intensity,
                cos_cone,
                cos_start,
                ..
            } => intensity * (2.0 * PI * ((1.0 - cos_start) + 0.5 * (cos_start - cos_cone))),
            Emitter::Directional {
                irradiance, radius, ..
            } => irradiance * (PI * radius * radius),
            Emitter::Triangle { area, radiance, .. } => radiance * (PI * area),
            Emitter::Sphere {
                radius, radiance, ..
            } => radiance * (PI * 4.0 * PI * radius * radius),
            // Held by the sampler, which knows its power (`Emitters::collect`).
            Emitter::Environment => Rgb::ZERO,
        }
    }
}

/// The emitters of a valid description (see `crate::validate`) and their powers, before
/// [`powered`] checks that some of them carry power.
#[derive(Clone, Debug)]
pub(crate) struct Emitters {
    pub(super) emitters: Vec<Emitter>,
    pub(super) powers: Vec<Rgb>,
    pub(super) triangle_emitter: Vec<u32>,
    pub(super) sphere_emitter: Vec<u32>,
    pub(super) textured: Vec<TexturedTriangle>,
    pub(super) environment: Option<(Box<EnvironmentLight>, usize)>,
}

impl Emitters {
    /// Collects the lights, the emissive triangles and spheres and the environment of `desc`;
    /// `bounds` sizes the disc of directional and environment lights.
    pub(crate) fn collect(desc: &SceneDescription, bounds: Aabb) -> Self {
        let mut emitters = Vec::new();
        for light in &desc.lights {
            match *light {
                Light::Point {
                    position,
                    intensity,
                } => emitters.push(Emitter::Point {
                    position,
                    intensity,
                }),
                Light::Spot {
                    position,
                    direction,
                    intensity,
                    cone_angle,
                    falloff_start,
                } => {
                    let falloff_start = falloff_start.clamp(0.0, cone_angle);
                    emitters.push(Emitter::Spot {
                        position,
                        frame: Frame::from_normal(direction.normalize()),
                        intensity,
                        cos_cone: cone_angle.cos(),
                        cos_start: falloff_start.cos(),
                        cone_angle,
                        falloff_start,
                    });
                }
                Light::Directional {
                    direction,
                    irradiance,
                } => emitters.push(Emitter::Directional {
                    frame: Frame::from_normal(direction.normalize()),
                    irradiance,
                    center: bounds.center(),
                    radius: bounds.bounding_radius().max(1e-3),
                }),
            }
        }
        let emission = |m: u32| {
            desc.materials
                .get(m as usize)
                .map(|m| m.emission)
                .filter(|e| e.cmpgt(Rgb::ZERO).any())
        };
        let mut triangle_emitter = Vec::new();
        let mut textured = Vec::new();
        for (i, tri) in desc.triangles.iter().enumerate() {
            let Some(mut radiance) = emission(tri.material) else {
                continue;
            };
            let mut texture = u32::MAX;
            if let Some(map) = desc.materials[tri.material as usize]
                .textures
                .as_deref()
                .and_then(|t| t.emission.as_ref())
            {
                let emitter = TexturedTriangle {
                    emission: radiance,
                    uv: tri.uv.unwrap_or([Vec2::ZERO, Vec2::X, Vec2::Y]),
                    texture: map.clone(),
                };
                radiance = emitter.mean();
                texture = textured.len() as u32;
                textured.push(emitter);
            }
            let [p0, p1, p2] = tri.positions;
            let (e1, e2) = (p1 - p0, p2 - p0);
            let n = e1.cross(e2);
            let area = 0.5 * n.length();
            if !(area > 0.0 && area.is_finite()) {
                continue;
            }
            if triangle_emitter.is_empty() {
                triangle_emitter = vec![u32::MAX; desc.triangles.len()];
            }
            triangle_emitter[i] = emitters.len() as u32;
            let normal = n / (2.0 * area);
            emitters.push(Emitter::Triangle {
                p0,
                e1,
                e2,
                normal,
                area,
                radiance,
                p1: p0 + e1,
                p2: p0 + e2,
                frame: Frame::from_normal(normal),
                size: textured
                    .get(texture as usize)
                    .map_or(area.sqrt(), |t| t.feature_size(area)),
                flux: radiance * (PI * area),
                texture,
            });
        }
        let mut sphere_emitter = Vec::new();
        for (i, s) in desc.spheres.iter().enumerate() {
            let Some(radiance) = emission(s.material) else {
                continue;
            };
            if sphere_emitter.is_empty() {
                sphere_emitter = vec![u32::MAX; desc.spheres.len()];
            }
            sphere_emitter[i] = emitters.len() as u32;
            emitters.push(Emitter::Sphere {
                center: s.center,
                radius: s.radius,
                radiance,
            });
        }
        let environment = desc
            .environment
            .as_ref()
            .and_then(|env| EnvironmentLight::new(env, bounds))
            .map(|light| {
                emitters.push(Emitter::Environment);
                (Box::new(light), emitters.len() - 1)
            });
        let powers: Vec<Rgb> = emitters
            .iter()
            .map(|e| match e {
                Emitter::Environment => environment
                    .as_ref()
                    .map_or(Rgb::ZERO, |(light, _)| light.power()),
                e => e.power(),
            })
            .collect();
        Self {
            emitters,
            powers,
            triangle_emitter,
            sphere_emitter,
            textured,
            environment,
        }
    }

    /// The weights by which emitters are picked: the luminance of their power.
    pub(crate) fn weights(&self) -> Vec<f64> {
        self.powers
            .iter()
            .map(|&p| f64::from(luminance(p)))
            .collect()
    }
}

/// Emitters of which at least one carries power, with the distribution that picks them by
/// power; only [`powered`] makes one, so that [`super::LightSampler::new`] cannot fail.
#[derive(Clone, Debug)]
pub(crate) struct Powered {
    emitters: Emitters,
    distribution: Distribution1D,
}

impl Powered {
    /// The emitters and the distribution over them.
    pub(crate) fn into_parts(self) -> (Emitters, Distribution1D) {
        (self.emitters, self.distribution)
    }
}

/// The emitters, if some light or emitter has positive (finite) power and none has a power
/// beyond what 32-bit floats hold (its photons would carry infinite flux).
pub(crate) fn powered(emitters: Emitters) -> Result<Powered, Invalid> {
    if let Some(i) = emitters.weights().iter().position(|w| w.is_infinite()) {
        return Err(Invalid::Value {
            key: format!("emitter {i}"),
            message: "has a power beyond the range of 32-bit floats (emission × area too large)"
                .to_owned(),
        });
    }
    let distribution = Distribution1D::new(&emitters.weights()).ok_or(Invalid::NoPower)?;
    Ok(Powered {
        emitters,
        distribution,
    })
}
