//! The densities with which the light sampler produces light, for the multiple importance
//! sampling weights of bidirectional methods (Georgiev, "Implementing Vertex Connection and
//! Merging", 2012; SmallVCM's `emissionPdfW`, `directPdfA` and `cosAtLight`).
//!
//! An [`EmissionPdf`] describes one point on an emitter and one direction of travel leaving it
//! (toward the next vertex of a light path, or back toward the previous vertex of a camera path):
//! how likely [`LightSampler::sample_emission`] is to start a photon there in that direction, and
//! [`LightSampler::sample_direct`] to choose that point. It comes with a sample
//! ([`LightSampler::sample_emission_with_pdf`], [`LightSampler::sample_direct_with_pdf`]), or for
//! a point a camera path reached ([`LightSampler::pdf_emission`] for a hit on an emitter,
//! [`LightSampler::pdf_emission_environment`] for a ray that escaped).
//!
//! Per kind, with A the emitter's area, r the radius of the disc that covers the scene's bounding
//! sphere, θ the angle between the direction of travel and the emitter's normal, θ_cone the spot's
//! cone, p_env the environment's solid-angle density of the sky direction (`environment.rs`):
//!
//! | kind | position (m⁻²) | direction (sr⁻¹) | direct | cos at light | delta |
//! |---|---|---|---|---|---|
//! | triangle, textured triangle | 1/A | cos θ/π | 1/A (area) | cos θ | no |
//! | sphere | 1/(4πR²) | cos θ/π | 1/(4πR²) (area) | cos θ | no |
//! | point | 1 (delta) | 1/(4π) | 1 (delta) | 1 | position |
//! | spot | 1 (delta) | 1/(2π(1 − cos θ_cone)) inside the cone, else 0 | 1 (delta) | 1 | position |
//! | directional | 1/(πr²) on its disc | 1 (delta) | 1 (delta) | 1 | direction |
//! | environment | 1/(πr²) on its disc | p_env | p_env (solid angle) | 1 | no |
//!
//! The spot's direction density is that of its sampler, uniform in the cone: its falloff is in
//! the photons' power, not in their density. A textured triangle samples like a plain one; its
//! texture changes only the probability of picking it. A direct sample of a surface has the
//! solid-angle density `pick · direct · d² / cos at light` at a distance d (what
//! [`LightSampler::pdf_direct`] returns), the others have `pick · direct` ([`LightSample::pdf`]).

use std::f32::consts::{FRAC_1_PI, PI};

use glam::{Vec2, Vec3};

use super::{EmissionSample, Emitter, EmitterShape, LightSample, LightSampler};
use crate::sampling::uniform_sphere;
use crate::{Hit, Primitive};

/// The densities with which the light sampler produces one point on an emitter and one direction
/// of travel leaving it; the table of this module's documentation gives them per kind.
///
/// Each density is that of one choice given the ones before it: `pick` the emitter, then
/// `position` the point on it, then `direction` the direction from there; `direct` is the density
/// of the point given the emitter for next-event estimation. A delta choice (a point or spot
/// light's position, a directional light's direction and its direct choice) has density one by
/// this convention: the Dirac factor is left out, as in SmallVCM and pbrt.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EmissionPdf {
    /// The emitter's index among the sampler's (for [`LightSampler::pick_direct`]).
    pub emitter: u32,
    /// Probability that [`LightSampler::sample_emission`] picks the emitter, by power.
    pub pick: f32,
    /// Probability that [`LightSampler::sample_direct`] picks the emitter from the receiving
    /// point (by its importance there, `tree.rs`): the point that `sample_direct_with_pdf`
    /// sampled for, the `receiver` of [`LightSampler::pdf_emission`]; zero from
    /// `sample_emission_with_pdf`, whose receiver (the photon's next vertex) is not known yet.
    pub pick_direct: f32,
    /// Area density (m⁻²) of the photon's start on the emitter (on the disc facing the scene for a
    /// directional or environment light); one for the delta position of a point or spot light.
    pub position: f32,
    /// Solid-angle density (sr⁻¹) of the direction of travel from that start; one for the delta
    /// direction of a directional light.
    pub direction: f32,
    /// Density with which [`LightSampler::sample_direct`] chooses the point, given the emitter:
    /// in area measure on a surface (m⁻²), in solid angle for the environment (its direction,
    /// sr⁻¹), one for the delta lights.
    pub direct: f32,
    /// Cosine between the direction of travel and the emitter's normal on a surface; one for
    /// the lights without a surface.
    pub cos_at_light: f32,
    /// Whether the light is a delta light (point, spot, directional; [`LightSample::is_delta`]):
    /// no path from the camera can reach it. A finite one has a delta position, an infinite one
    /// a delta direction.
    pub is_delta: bool,
    /// Whether the light is infinitely far (directional, environment): `direct` is then a
    /// density of directions, and no distance converts it.
    pub is_infinite: bool,
}

impl EmissionPdf {
    /// pick · position · direction: the density of the whole emission, SmallVCM's
    /// `emissionPdfW` times the probability of picking the emitter.
    #[inline]
    #[must_use]
    pub fn emission_with_pick(&self) -> f32 {
        self.pick * self.position * self.direction
    }

    /// pick_direct · direct: the density of next-event estimation choosing the point, SmallVCM's
    /// `directPdfA` (`directPdfW` for an infinite light) times the probability of picking the
    /// emitter.
    #[inline]
    #[must_use]
    pub fn direct_with_pick(&self) -> f32 {
        self.pick_direct * self.direct
    }
}

impl LightSampler {
    /// [`LightSampler::sample_emission`] with the densities of the photon it drew: the same
    /// sample for the same arguments, bit for bit, and its start and direction of travel as an
    /// [`EmissionPdf`].
    pub fn sample_emission_with_pdf(
        &self,
        u_light: f32,
        u_pos: Vec2,
        u_dir: Vec2,
    ) -> Option<(EmissionSample, EmissionPdf)> {
        let sample = self.sample_emission(u_light, u_pos, u_dir)?;
        let (idx, _) = self.distribution.sample(u_light);
        let mut pdf = self.emitter_pdf(idx, sample.normal, sample.direction, None);
        match sample.emitter {
            // The cosine of the local direction the sampler drew, rather than that of its
            // world-space image.
            EmitterShape::Area { cos_theta, .. } => {
                pdf.direction = cos_theta * FRAC_1_PI;
                pdf.cos_at_light = cos_theta;
            }
            // The density of the texel the sky sampler drew, rather than that of the texel its
            // direction falls in, which differs within rounding of a texel's edge.
            EmitterShape::Environment { .. } => {
                let sky = self.sky_pdf(u_dir)?;
                pdf.direction = sky;
                pdf.direct = sky;
            }
            EmitterShape::Point | EmitterShape::Spot { .. } | EmitterShape::Directional => {}
        }
        Some((sample, pdf))
    }

    /// [`LightSampler::sample_direct`] with the densities of the light it drew: the same sample
    /// for the same arguments, bit for bit, and as an [`EmissionPdf`] the point it chose with the
    /// direction from there toward `point` (−`incoming`), which a photon would travel to reach it.
    pub fn sample_direct_with_pdf(
        &self,
        point: Vec3,
        normal: Vec3,
        u_light: f32,
        u: Vec2,
    ) -> Option<(LightSample, EmissionPdf)> {
        let sample = self.sample_direct(point, normal, u_light, u)?;
        let (idx, _) = self.direct.sample(point, normal, u_light)?;
        let normal = match self.emitters[idx] {
            // The normal at the point the sampler drew, by the same expression.
            Emitter::Sphere { .. } => uniform_sphere(u),
            _ => Vec3::ZERO,
        };
        let mut pdf = self.emitter_pdf(idx, normal, -sample.incoming, Some((point, normal)));
        if let Emitter::Environment = self.emitters[idx] {
            let sky = self.sky_pdf(u)?;
            pdf.direction = sky;
            pdf.direct = sky;
        }
        Some((sample, pdf))
    }

    /// The densities with which the light sampler produces the point of `hit` on an emitter and
    /// the unit direction `outgoing` leaving it toward `receiver` (position and unit normal, zero
    /// off a surface: where the ray that found it came from), and next-event estimation from
    /// there picks it: what a camera path that reaches an emitter needs of the light paths
    /// (SmallVCM's `GetRadiance`). `None` unless `hit` is on an emitting front face; the
    /// direction density is zero for an `outgoing` behind the surface.
    pub fn pdf_emission(
        &self,
        hit: &Hit,
        outgoing: Vec3,
        receiver: (Vec3, Vec3),
    ) -> Option<EmissionPdf> {
        if !hit.front_face {
            return None;
        }
        let idx = match hit.primitive {
            Primitive::Triangle(i) => self.triangle_emitter.get(i as usize),
            Primitive::Sphere(i) => self.sphere_emitter.get(i as usize),
            Primitive::Cylinder(_) => None,
        };
        let &idx = idx.filter(|&&i| i != u32::MAX)?;
        // A front face's geometric normal faces the outside of a sphere, the front of a triangle
        // (whose emitter keeps its own).
        Some(self.emitter_pdf(idx as usize, hit.geometric_normal, outgoing, Some(receiver)))
    }

    /// The densities with which the light sampler produces a photon from the environment that
    /// travels against the unit `direction` (that of a ray that escaped the scene, toward the
    /// sky): its start on the disc, its direction, and next-event estimation's choice of
    /// `direction`. `None` without an environment.
    pub fn pdf_emission_environment(&self, direction: Vec3) -> Option<EmissionPdf> {
        let (_, idx) = self.environment.as_ref()?;
        // The infinite lights' share of next-event estimation does not depend on the point.
        Some(self.emitter_pdf(*idx, Vec3::ZERO, -direction, Some((Vec3::ZERO, Vec3::ZERO))))
    }

    /// The densities of emitter `idx` for a start with the unit `normal` (used by a sphere only:
    /// a triangle keeps its normal, the other lights have none) and the unit direction of travel
    /// `direction`, next-event estimation's pick from `receiver` (position and normal; none: 0).
    pub(super) fn emitter_pdf(
        &self,
        idx: usize,
        normal: Vec3,
        direction: Vec3,
        receiver: Option<(Vec3, Vec3)>,
    ) -> EmissionPdf {
        let pick = self.distribution.pmf(idx);
        let pick_direct = receiver.map_or(0.0, |(p, n)| self.pick_direct(idx, p, n));
        let emitter = idx as u32;
        let surface = |normal: Vec3, area: f32| {
            let cos = direction.dot(normal).max(0.0);
            EmissionPdf {
                emitter,
                pick,
                pick_direct,
                position: 1.0 / area,
                direction: cos * FRAC_1_PI,
                direct: 1.0 / area,
                cos_at_light: cos,
                is_delta: false,
                is_infinite: false,
            }
        };
        let delta_position = |direction: f32| EmissionPdf {
            emitter,
            pick,
            pick_direct,
            position: 1.0,
            direction,
            direct: 1.0,
            cos_at_light: 1.0,
            is_delta: true,
            is_infinite: false,
        };
        match self.emitters[idx] {
            Emitter::Triangle { normal, area, .. } => surface(normal, area),
            Emitter::Sphere { radius, .. } => surface(normal, 4.0 * PI * radius * radius),
            Emitter::Point { .. } => delta_position(1.0 / (4.0 * PI)),
            Emitter::Spot {
                frame, cos_cone, ..
            } => {
                // `uniform_cone`'s density; zero outside the cone, and for a cone too narrow to
                // emit anything.
                let cone = 1.0 / (2.0 * PI * (1.0 - cos_cone));
                let inside = direction.dot(frame.n) > cos_cone && cone.is_finite();
                delta_position(if inside { cone } else { 0.0 })
            }
            Emitter::Directional { radius, .. } => EmissionPdf {
                emitter,
                pick,
                pick_direct,
                position: 1.0 / (PI * radius * radius),
                direction: 1.0,
                direct: 1.0,
                cos_at_light: 1.0,
                is_delta: true,
                is_infinite: true,
            },
            Emitter::Environment => {
                let (position, sky) = self.environment.as_ref().map_or((0.0, 0.0), |(light, _)| {
                    (light.disc_pdf(), light.pdf(-direction))
                });
                EmissionPdf {
                    emitter,
                    pick,
                    pick_direct,
                    position,
                    direction: sky,
                    direct: sky,
                    cos_at_light: 1.0,
                    is_delta: false,
                    is_infinite: true,
                }
            }
        }
    }

    /// The probability that [`LightSampler::sample_direct`] from `point` on a surface of unit
    /// `normal` (zero: none) picks emitter `emitter`.
    pub fn pick_direct(&self, emitter: usize, point: Vec3, normal: Vec3) -> f32 {
        self.direct.pmf(point, normal, emitter)
    }

    /// The solid-angle density of the sky direction that the environment's sampler draws for
    /// `u`, exactly as the sample it makes has it.
    fn sky_pdf(&self, u: Vec2) -> Option<f32> {
        let (light, _) = self.environment.as_ref()?;
        light.sample(u).map(|s| s.pdf)
    }
}

#[cfg(test)]
#[path = "densities_tests.rs"]
mod tests;
