//! The Lambertian reflector.

use std::f32::consts::FRAC_1_PI;

use glam::{Vec2, Vec3};

use super::{BsdfSample, Lobe, MaterialParam, Model, Shading, TransportMode};
use crate::sampling::cosine_hemisphere;
use crate::{Frame, Rgb};

/// A Lambertian reflector: f = albedo/π on the side of `outgoing`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Diffuse {
    /// Albedo in [0, 1] per channel.
    pub albedo: Rgb,
}

/// f of a Lambertian of `albedo` about the unit `normal`: the local z of both directions is their
/// dot product with the normal, so no frame is built.
#[inline]
pub(super) fn eval_world(albedo: Rgb, normal: Vec3, outgoing: Vec3, incoming: Vec3) -> Rgb {
    if outgoing.dot(normal) * incoming.dot(normal) <= 0.0 {
        Rgb::ZERO
    } else {
        albedo * FRAC_1_PI
    }
}

impl Model for Diffuse {
    const NAME: &'static str = "diffuse";

    #[inline]
    fn lobe(&self) -> Lobe {
        Lobe::Lambert
    }

    #[inline]
    fn albedo(&self) -> Rgb {
        self.albedo
    }

    #[inline]
    fn lambertian_albedo(&self) -> Option<Rgb> {
        Some(self.albedo)
    }

    fn params(&self) -> Vec<MaterialParam> {
        vec![MaterialParam::Colour("albedo", self.albedo)]
    }

    #[inline]
    fn tint(&mut self, tint: Rgb) -> Rgb {
        self.albedo *= tint;
        Rgb::ONE
    }

    #[inline]
    fn eval_world(&self, s: &Shading, outgoing: Vec3, incoming: Vec3) -> Option<Rgb> {
        Some(eval_world(self.albedo, s.normal, outgoing, incoming))
    }

    #[inline]
    fn eval_local(&self, _: &Shading, _: Vec3, _: Vec3) -> Rgb {
        self.albedo * FRAC_1_PI
    }

    #[inline]
    fn pdf_local(&self, _: Vec3, wi: Vec3) -> f32 {
        wi.z * FRAC_1_PI
    }

    #[inline]
    fn sample_local(
        &self,
        _: &Shading,
        frame: &Frame,
        wo: Vec3,
        _: f32,
        u: Vec2,
        _: TransportMode,
    ) -> Option<BsdfSample> {
        if self.albedo == Rgb::ZERO {
            return None;
        }
        let mut wi = cosine_hemisphere(u);
        if wo.z < 0.0 {
            wi.z = -wi.z;
        }
        let pdf = wi.z.abs() * FRAC_1_PI;
        (pdf > 0.0).then(|| BsdfSample {
            incoming: frame.to_world(wi),
            weight: self.albedo,
            pdf,
            is_specular: false,
            is_transmission: false,
        })
    }
}
