//! The conductor: a metal with the exact unpolarized Fresnel reflectance of its complex index of
//! refraction η + i k, smooth (a delta reflection) or rough (GGX microfacets).
//!
//! - smooth (`roughness` below [`SMOOTH_ROUGHNESS`]): the mirror direction with weight
//!   F(cos θₒ)·`specular_reflectance`;
//! - rough: f = D(ωm)·G₂·F(ωi·ωm)·`specular_reflectance` / (4 cos θₒ cos θᵢ) with GGX D,
//!   height-correlated Smith G₂ and visible-normal sampling, as the glossy model (whose density
//!   it shares, so that the reverse densities of bidirectional methods come for free);
//!
//! F is [`fresnel_conductor`] per channel with the RGB η and k that the RGB transport uses
//! (Mitsuba 3's RGB variants: a named metal's spectra turned into colours, see
//! `docs/spectral.md`). The spectral η and k, when the scene has them, live in
//! [`crate::MaterialSpectra`] (a `MaterialKind` is `Copy` and rides in every [`super::Bsdf`]);
//! [`Conductor::eval_spectral`] evaluates the model at sampled wavelengths from them.
//! Single-scattering GGX loses energy at high roughness, as the glossy model does.

use glam::{Vec2, Vec3};

use super::glossy::{ggx_d, ggx_lambda, ggx_pdf, ggx_sample_visible_normal};
use super::{
    BsdfSample, Lobe, MaterialParam, Model, SMOOTH_ROUGHNESS, Shading, TransportMode, reflect,
};
use crate::spectral::{self, SampledSpectrum, SampledWavelengths, fresnel_conductor};
use crate::{Frame, Rgb};

/// A conductor with exact Fresnel for its complex index of refraction η + i k (relative to the
/// outside), smooth or with a GGX roughness.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Conductor {
    /// Real part of the index of refraction, per channel (finite, ≥ 0).
    pub eta: Rgb,
    /// Imaginary part (absorption), per channel (finite, ≥ 0).
    pub k: Rgb,
    /// A tint multiplying the Fresnel reflectance, per channel (Mitsuba's
    /// `specular_reflectance`; one for a plain metal).
    pub specular_reflectance: Rgb,
    /// GGX α (not squared); below [`SMOOTH_ROUGHNESS`] (zero included) the smooth conductor.
    pub roughness: f32,
}

impl Conductor {
    /// Whether it renders as the smooth conductor (a delta lobe).
    #[inline]
    #[must_use]
    pub fn is_smooth(&self) -> bool {
        self.roughness < SMOOTH_ROUGHNESS
    }

    /// The Fresnel reflectance per channel at `cos_theta` (≥ 0) of the incident direction.
    #[must_use]
    pub fn fresnel(&self, cos_theta: f32) -> Rgb {
        let cos = f64::from(cos_theta);
        let f = |c: usize| {
            fresnel_conductor(cos, f64::from(self.eta[c]).max(1e-6), f64::from(self.k[c])) as f32
        };
        Rgb::new(f(0), f(1), f(2))
    }

    /// The Fresnel reflectance at `cos_theta` for each sampled wavelength, with the spectral η
    /// and k of `ior` (without `specular_reflectance`, which is a colour).
    #[must_use]
    pub fn fresnel_spectral(
        ior: &spectral::Conductor,
        cos_theta: f32,
        wavelengths: &SampledWavelengths,
    ) -> SampledSpectrum {
        ior.fresnel(f64::from(cos_theta), wavelengths)
    }

    /// f for local directions (shading frame, z along the normal) at the sampled wavelengths,
    /// with the spectral η and k of `ior`, without `specular_reflectance`: zero for a smooth
    /// conductor (a delta lobe; [`Conductor::fresnel_spectral`] at cos θₒ is its weight) and for
    /// directions on opposite sides.
    #[must_use]
    pub fn eval_spectral(
        &self,
        ior: &spectral::Conductor,
        wo: Vec3,
        wi: Vec3,
        wavelengths: &SampledWavelengths,
    ) -> SampledSpectrum {
        if self.is_smooth() || wo.z * wi.z <= 0.0 {
            return SampledSpectrum([0.0; 4]);
        }
        let (wo, wi) = if wo.z < 0.0 { (-wo, -wi) } else { (wo, wi) };
        let Some((wm, scale)) = microfacet(wo, wi, self.roughness) else {
            return SampledSpectrum([0.0; 4]);
        };
        Self::fresnel_spectral(ior, wi.dot(wm).clamp(0.0, 1.0), wavelengths) * scale
    }
}

/// The half vector of two upper-hemisphere directions and D·G₂/(4 cos θₒ cos θᵢ) there.
fn microfacet(wo: Vec3, wi: Vec3, alpha: f32) -> Option<(Vec3, f32)> {
    let wm = wo + wi;
    if wm == Vec3::ZERO || wo.z <= 0.0 || wi.z <= 0.0 {
        return None;
    }
    let wm = wm.normalize();
    let g2 = 1.0 / (1.0 + ggx_lambda(wo, alpha) + ggx_lambda(wi, alpha));
    Some((wm, ggx_d(wm, alpha) * g2 / (4.0 * wo.z * wi.z)))
}

impl Model for Conductor {
    const NAME: &'static str = "conductor";

    /// The mirror's delta lobe when smooth, else its GGX lobe (as the glossy model's).
    #[inline]
    fn lobe(&self) -> Lobe {
        if self.is_smooth() {
            Lobe::Specular
        } else {
            Lobe::Ggx {
                alpha: self.roughness,
            }
        }
    }

    /// Its reflectance at normal incidence, ((η − 1)² + k²)/((η + 1)² + k²) per channel, times
    /// the tint.
    #[inline]
    fn albedo(&self) -> Rgb {
        self.fresnel(1.0) * self.specular_reflectance
    }

    /// η, k and the tint; the roughness unless it is exactly zero (the smooth conductor), so that
    /// a negative or non-finite one is refused.
    fn params(&self) -> Vec<MaterialParam> {
        let mut params = vec![
            MaterialParam::Colour("eta", self.eta),
            MaterialParam::Colour("k", self.k),
            MaterialParam::Colour("specular_reflectance", self.specular_reflectance),
        ];
        if self.roughness != 0.0 {
            params.push(MaterialParam::Positive("roughness", self.roughness));
        }
        params
    }

    /// A texture's colour multiplies the tint, which is a plain factor of the whole BSDF.
    #[inline]
    fn tint(&mut self, tint: Rgb) -> Rgb {
        self.specular_reflectance *= tint;
        Rgb::ONE
    }

    #[inline]
    fn eval_local(&self, _: &Shading, wo: Vec3, wi: Vec3) -> Rgb {
        if self.is_smooth() {
            return Rgb::ZERO;
        }
        match microfacet(wo, wi, self.roughness) {
            Some((wm, scale)) => {
                self.fresnel(wi.dot(wm).clamp(0.0, 1.0)) * self.specular_reflectance * scale
            }
            None => Rgb::ZERO,
        }
    }

    #[inline]
    fn pdf_local(&self, wo: Vec3, wi: Vec3) -> f32 {
        if self.is_smooth() {
            return 0.0;
        }
        ggx_pdf(wo, wi, self.roughness)
    }

    /// One for the reflection of a smooth conductor that reflects anything, zero otherwise.
    #[inline]
    fn delta_probability(&self, _: &Shading, _: Vec3, transmission: bool) -> f32 {
        if transmission || !self.is_smooth() || self.specular_reflectance == Rgb::ZERO {
            0.0
        } else {
            1.0
        }
    }

    fn sample_local(
        &self,
        _: &Shading,
        frame: &Frame,
        wo: Vec3,
        _: f32,
        u: Vec2,
        _: TransportMode,
    ) -> Option<BsdfSample> {
        if self.specular_reflectance == Rgb::ZERO {
            return None;
        }
        if self.is_smooth() {
            return Some(BsdfSample {
                incoming: frame.to_world(Vec3::new(-wo.x, -wo.y, wo.z)),
                weight: self.fresnel(wo.z.abs()) * self.specular_reflectance,
                pdf: 1.0,
                is_specular: true,
                is_transmission: false,
            });
        }
        let flip = wo.z < 0.0;
        let wo_up = if flip { -wo } else { wo };
        let wm = ggx_sample_visible_normal(wo_up, self.roughness, u);
        let wi_up = reflect(wo_up, wm);
        if wi_up.z <= 0.0 {
            return None;
        }
        let pdf = ggx_pdf(wo_up, wi_up, self.roughness);
        let (wm, scale) = microfacet(wo_up, wi_up, self.roughness)?;
        if pdf.is_nan() || pdf <= 0.0 {
            return None;
        }
        let f = self.fresnel(wi_up.dot(wm).clamp(0.0, 1.0)) * self.specular_reflectance * scale;
        let wi = if flip { -wi_up } else { wi_up };
        Some(BsdfSample {
            incoming: frame.to_world(wi),
            weight: f * (wi_up.z / pdf),
            pdf,
            is_specular: false,
            is_transmission: false,
        })
    }
}
