//! The smooth dielectric: specular reflection and refraction with exact unpolarised Fresnel.

use glam::{Vec2, Vec3};

use super::{BsdfSample, Lobe, MaterialParam, Model, Shading, TransportMode};
use crate::{Frame, Rgb};

/// A smooth dielectric boundary with exact unpolarised Fresnel. Its inside is behind the front
/// face: a hit on the front face enters the medium.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Dielectric {
    /// Index of refraction relative to the outside medium.
    pub ior: f32,
}

impl Model for Dielectric {
    const NAME: &'static str = "dielectric";

    #[inline]
    fn lobe(&self) -> Lobe {
        Lobe::Specular
    }

    /// Seen at normal incidence a dielectric passes or reflects everything.
    #[inline]
    fn albedo(&self) -> Rgb {
        Rgb::ONE
    }

    fn params(&self) -> Vec<MaterialParam> {
        vec![MaterialParam::Positive("ior", self.ior)]
    }

    /// A texture's colour does not tint a dielectric.
    #[inline]
    fn tint(&mut self, _: Rgb) -> Rgb {
        Rgb::ONE
    }

    #[inline]
    fn eta(&self, front_face: bool) -> f32 {
        if front_face { self.ior } else { 1.0 / self.ior }
    }

    #[inline]
    fn refractive_index(&self) -> Option<f32> {
        Some(self.ior)
    }

    /// Fresnel's R seen from the side of `wo` for reflection, 1 − R for refraction, which is
    /// zero under total internal reflection: the choice [`Model::sample_local`] makes, by the
    /// same expressions.
    #[inline]
    fn delta_probability(&self, s: &Shading, wo: Vec3, transmission: bool) -> f32 {
        let eta = if wo.z > 0.0 { s.eta } else { 1.0 / s.eta };
        let r = fresnel_dielectric(wo.z.abs(), eta);
        if !transmission {
            r
        } else if refract(wo, eta).is_some() {
            1.0 - r
        } else {
            0.0
        }
    }

    fn sample_local(
        &self,
        s: &Shading,
        frame: &Frame,
        wo: Vec3,
        u_lobe: f32,
        _: Vec2,
        mode: TransportMode,
    ) -> Option<BsdfSample> {
        // Relative η across the boundary, seen from the side of `wo`.
        let eta = if wo.z > 0.0 { s.eta } else { 1.0 / s.eta };
        let r = fresnel_dielectric(wo.z.abs(), eta);
        if u_lobe < r {
            return Some(BsdfSample {
                incoming: frame.to_world(Vec3::new(-wo.x, -wo.y, wo.z)),
                weight: Rgb::ONE,
                pdf: r,
                is_specular: true,
                is_transmission: false,
            });
        }
        let wi = refract(wo, eta)?;
        let scale = match mode {
            TransportMode::Radiance => 1.0 / (eta * eta),
            TransportMode::Importance => 1.0,
        };
        Some(BsdfSample {
            incoming: frame.to_world(wi),
            weight: Rgb::splat(scale),
            pdf: 1.0 - r,
            is_specular: true,
            is_transmission: true,
        })
    }
}

/// Unpolarised Fresnel reflectance of a smooth dielectric boundary for light arriving at
/// `cos_theta_i` (≥ 0) from the side with η₁, where `eta` = η₂/η₁. Total internal reflection gives 1.
pub fn fresnel_dielectric(cos_theta_i: f32, eta: f32) -> f32 {
    let cos_i = cos_theta_i.clamp(0.0, 1.0);
    let sin2_i = 1.0 - cos_i * cos_i;
    let sin2_t = sin2_i / (eta * eta);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin2_t).max(0.0).sqrt();
    let r_parallel = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let r_perpendicular = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    0.5 * (r_parallel * r_parallel + r_perpendicular * r_perpendicular)
}

/// Refraction of the local direction `wo` (either side of z) through the z = 0 boundary with relative
/// η = η(far side)/η(side of `wo`); `None` under total internal reflection.
fn refract(wo: Vec3, eta: f32) -> Option<Vec3> {
    let n = if wo.z > 0.0 { Vec3::Z } else { -Vec3::Z };
    refract_about(wo, n, eta)
}

/// Refraction of the unit `w` through a boundary of unit normal `n` on the side of `w`
/// (`w·n` ≥ 0), with relative η = η(far side)/η(side of `w`); `None` under total internal
/// reflection.
pub(super) fn refract_about(w: Vec3, n: Vec3, eta: f32) -> Option<Vec3> {
    let cos_i = w.dot(n).clamp(0.0, 1.0);
    let sin2_i = (1.0 - cos_i * cos_i).max(0.0);
    let sin2_t = sin2_i / (eta * eta);
    if sin2_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    Some((-w / eta + (cos_i / eta - cos_t) * n).normalize())
}
