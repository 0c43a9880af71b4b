//! The perfect specular conductor: a mirror of constant reflectance.

use glam::{Vec2, Vec3};

use super::{BsdfSample, Lobe, MaterialParam, Model, Shading, TransportMode};
use crate::{Frame, Rgb};

/// Perfect specular reflection with a constant reflectance per channel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Mirror {
    /// Reflectance per channel.
    pub reflectance: Rgb,
}

impl Model for Mirror {
    const NAME: &'static str = "mirror";

    #[inline]
    fn lobe(&self) -> Lobe {
        Lobe::Specular
    }

    #[inline]
    fn albedo(&self) -> Rgb {
        self.reflectance
    }

    fn params(&self) -> Vec<MaterialParam> {
        vec![MaterialParam::Colour("reflectance", self.reflectance)]
    }

    #[inline]
    fn tint(&mut self, tint: Rgb) -> Rgb {
        self.reflectance *= tint;
        Rgb::ONE
    }

    /// One for the reflection of a mirror that reflects anything (its samples' `pdf`), zero for
    /// a black one, which samples nothing, and for refraction.
    #[inline]
    fn delta_probability(&self, _: &Shading, _: Vec3, transmission: bool) -> f32 {
        if transmission || self.reflectance == Rgb::ZERO {
            0.0
        } else {
            1.0
        }
    }

    #[inline]
    fn sample_local(
        &self,
        _: &Shading,
        frame: &Frame,
        wo: Vec3,
        _: f32,
        _: Vec2,
        _: TransportMode,
    ) -> Option<BsdfSample> {
        if self.reflectance == Rgb::ZERO {
            return None;
        }
        Some(BsdfSample {
            incoming: frame.to_world(Vec3::new(-wo.x, -wo.y, wo.z)),
            weight: self.reflectance,
            pdf: 1.0,
            is_specular: true,
            is_transmission: false,
        })
    }
}
