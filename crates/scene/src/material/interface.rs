//! The interface: a surface that does not scatter and only bounds participating media
//! (Mitsuba's `null` BSDF, pbrt's `interface` material). Light crosses it unchanged.

use glam::{Vec2, Vec3};

use super::{BsdfSample, Lobe, MaterialParam, Model, Shading, TransportMode};
use crate::{Frame, Rgb};

/// An index-matched boundary: light passes straight through with weight one.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Interface;

impl Model for Interface {
    const NAME: &'static str = "interface";

    #[inline]
    fn lobe(&self) -> Lobe {
        Lobe::Specular
    }

    /// Nothing is reflected.
    #[inline]
    fn albedo(&self) -> Rgb {
        Rgb::ZERO
    }

    fn params(&self) -> Vec<MaterialParam> {
        Vec::new()
    }

    /// A texture colour has nothing to tint.
    #[inline]
    fn tint(&mut self, _: Rgb) -> Rgb {
        Rgb::ONE
    }

    /// Always the straight transmission, never a reflection.
    #[inline]
    fn delta_probability(&self, _: &Shading, _: Vec3, transmission: bool) -> f32 {
        if transmission { 1.0 } else { 0.0 }
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
        Some(BsdfSample {
            incoming: frame.to_world(-wo),
            weight: Rgb::ONE,
            pdf: 1.0,
            is_specular: true,
            is_transmission: true,
        })
    }
}
