//! The rough dielectric: GGX microfacet reflection and refraction (Walter et al. 2007,
//! "Microfacet Models for Refraction through Rough Surfaces") with exact unpolarised Fresnel,
//! sampled through the distribution of visible normals, as pbrt-v4's `DielectricBxDF` with a
//! roughness and Mitsuba 3's `roughdielectric` do.
//!
//! With η′ = η(side of ωi)/η(side of ωo) (one for reflection) and the generalized half vector
//! ωm = normalize(η′ωi + ωo) turned to the shading normal's side:
//! - reflection: f = D(ωm)·G₂·F(ωo·ωm)/(4|cos θo cos θi|);
//! - refraction: f = (1 − F)·D(ωm)·G₂·|ωi·ωm|·|ωo·ωm| / (|cos θo cos θi|·(ωi·ωm + ωo·ωm/η′)²),
//!   divided by η′² for radiance ([`TransportMode::Radiance`]);
//!
//! with GGX D, height-correlated Smith G₂ (as the glossy conductor) and F the exact Fresnel
//! reflectance seen from the side of ωo. Sampling draws a visible normal from ωo and reflects
//! with probability F, else refracts, so the densities carry F and 1 − F. Microfacets seen from
//! behind by either direction scatter nothing. Single scattering loses energy at high roughness,
//! as for the conductor. A roughness below [`SMOOTH_ROUGHNESS`] is the smooth dielectric (its
//! delta lobes), as pbrt-v4's `EffectivelySmooth`: the lobes are then too sharp to evaluate.

use glam::{Vec2, Vec3};

use super::dielectric::refract_about;
use super::glossy::{ggx_d, ggx_lambda, ggx_sample_visible_normal};
use super::{
    BsdfSample, Dielectric, Lobe, MaterialParam, Model, Shading, TransportMode, fresnel_dielectric,
    reflect,
};
use crate::{Frame, Rgb};

/// GGX α below which a rough dielectric is rendered as the smooth one.
pub const SMOOTH_ROUGHNESS: f32 = 1e-3;

/// A rough dielectric boundary: GGX microfacets, exact unpolarised Fresnel. Its inside is behind
/// the front face, as for [`Dielectric`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RoughDielectric {
    /// Index of refraction relative to the outside medium.
    pub ior: f32,
    /// GGX α (not squared), > 0.
    pub roughness: f32,
}

impl RoughDielectric {
    /// The smooth dielectric it is rendered as when its roughness is below [`SMOOTH_ROUGHNESS`].
    #[inline]
    fn smooth(&self) -> Option<Dielectric> {
        (self.roughness < SMOOTH_ROUGHNESS).then_some(Dielectric { ior: self.ior })
    }
}

impl Model for RoughDielectric {
    const NAME: &'static str = "roughdielectric";
    const TRANSMITS: bool = true;

    /// Its GGX lobe; the smooth dielectric's delta lobe below [`SMOOTH_ROUGHNESS`].
    #[inline]
    fn lobe(&self) -> Lobe {
        match self.smooth() {
            Some(_) => Lobe::Specular,
            None => Lobe::Ggx {
                alpha: self.roughness,
            },
        }
    }

    /// As for the smooth dielectric: at normal incidence it passes or reflects nearly everything.
    #[inline]
    fn albedo(&self) -> Rgb {
        Rgb::ONE
    }

    fn params(&self) -> Vec<MaterialParam> {
        vec![
            MaterialParam::Positive("ior", self.ior),
            MaterialParam::Positive("roughness", self.roughness),
        ]
    }

    /// A texture's colour does not tint a dielectric.
    #[inline]
    fn tint(&mut self, _: Rgb) -> Rgb {
        Rgb::ONE
    }

    #[inline]
    fn eta(&self, front_face: bool) -> f32 {
        Dielectric { ior: self.ior }.eta(front_face)
    }

    #[inline]
    fn refractive_index(&self) -> Option<f32> {
        Some(self.ior)
    }

    #[inline]
    fn delta_probability(&self, s: &Shading, wo: Vec3, transmission: bool) -> f32 {
        self.smooth()
            .map_or(0.0, |d| d.delta_probability(s, wo, transmission))
    }

    fn eval_through(&self, s: &Shading, wo: Vec3, wi: Vec3) -> Rgb {
        if self.smooth().is_some() {
            return Rgb::ZERO;
        }
        let Some(event) = Event::new(s.eta, wo, wi) else {
            return Rgb::ZERO;
        };
        let alpha = self.roughness;
        let d = ggx_d(event.wm, alpha);
        let g2 = 1.0 / (1.0 + ggx_lambda(wo, alpha) + ggx_lambda(wi, alpha));
        let cos_product = (wo.z * wi.z).abs();
        let f = if event.reflection {
            d * g2 * event.fresnel / (4.0 * cos_product)
        } else {
            let (i, o) = (wi.dot(event.wm), wo.dot(event.wm));
            let denom = event.refraction_denominator(wi, wo);
            // Radiance: 1/η′², the squeeze of the solid angle across the boundary.
            (1.0 - event.fresnel) * d * g2 * (i * o).abs()
                / (cos_product * denom * event.eta_p * event.eta_p)
        };
        if f.is_finite() {
            Rgb::splat(f)
        } else {
            Rgb::ZERO
        }
    }

    fn pdf_through(&self, s: &Shading, wo: Vec3, wi: Vec3) -> f32 {
        if self.smooth().is_some() {
            return 0.0;
        }
        let Some(event) = Event::new(s.eta, wo, wi) else {
            return 0.0;
        };
        let visible = visible_normal_pdf(wo, event.wm, self.roughness);
        let pdf = if event.reflection {
            visible / (4.0 * wo.dot(event.wm).abs()) * event.fresnel
        } else {
            let dwm_dwi = wi.dot(event.wm).abs() / event.refraction_denominator(wi, wo);
            visible * dwm_dwi * (1.0 - event.fresnel)
        };
        if pdf.is_finite() { pdf } else { 0.0 }
    }

    fn sample_local(
        &self,
        s: &Shading,
        frame: &Frame,
        wo: Vec3,
        u_lobe: f32,
        u: Vec2,
        mode: TransportMode,
    ) -> Option<BsdfSample> {
        if let Some(smooth) = self.smooth() {
            return smooth.sample_local(s, frame, wo, u_lobe, u, mode);
        }
        // Sample in the frame turned to the side of `wo`, where η is seen from that side.
        let flip = wo.z < 0.0;
        let wo_up = if flip { -wo } else { wo };
        let eta = if flip { 1.0 / s.eta } else { s.eta };
        let wm = ggx_sample_visible_normal(wo_up, self.roughness, u);
        let cos_m = wo_up.dot(wm);
        if cos_m <= 0.0 {
            return None;
        }
        let r = fresnel_dielectric(cos_m, eta);
        let (wi_up, is_transmission) = if u_lobe < r {
            (reflect(wo_up, wm), false)
        } else {
            (refract_about(wo_up, wm, eta)?, true)
        };
        // A direction on the wrong side of the macrosurface for its lobe carries nothing.
        if (wi_up.z <= 0.0) != is_transmission || wi_up.z == 0.0 {
            return None;
        }
        let wi = if flip { -wi_up } else { wi_up };
        let f = self.eval_through(s, wo, wi).x;
        let pdf = self.pdf_through(s, wo, wi);
        if pdf.is_nan() || pdf <= 0.0 {
            return None;
        }
        // Light paths carry flux, which refraction does not scale: undo the radiance's 1/η′².
        let scale = match (mode, is_transmission) {
            (TransportMode::Importance, true) => eta * eta,
            _ => 1.0,
        };
        Some(BsdfSample {
            incoming: frame.to_world(wi),
            weight: Rgb::splat(f * scale * wi.z.abs() / pdf),
            pdf,
            is_specular: false,
            is_transmission,
        })
    }
}

/// One scattering event of a rough dielectric between local directions: whether it reflects,
/// η′, the generalized half vector and Fresnel's reflectance there.
struct Event {
    reflection: bool,
    /// η(side of ωi)/η(side of ωo): one for reflection.
    eta_p: f32,
    /// The microfacet normal, on the side of the shading normal.
    wm: Vec3,
    /// Fresnel's R at ωo·ωm, seen from the side of ωo.
    fresnel: f32,
}

impl Event {
    /// The event between `wo` and `wi` for a boundary with η = `eta` on the far side of the
    /// shading normal over η on its side; `None` in the tangent plane, for a degenerate half
    /// vector and for microfacets that either direction sees from behind.
    #[inline]
    fn new(eta: f32, wo: Vec3, wi: Vec3) -> Option<Self> {
        let (cos_o, cos_i) = (wo.z, wi.z);
        if cos_o == 0.0 || cos_i == 0.0 || !(wo.is_finite() && wi.is_finite()) {
            return None;
        }
        let reflection = cos_o * cos_i > 0.0;
        // η beyond the boundary over η on the side of `wo`.
        let eta_across = if cos_o > 0.0 { eta } else { 1.0 / eta };
        let eta_p = if reflection { 1.0 } else { eta_across };
        let wm = wi * eta_p + wo;
        if wm.length_squared() == 0.0 {
            return None;
        }
        let wm = wm.normalize();
        let wm = if wm.z < 0.0 { -wm } else { wm };
        if wm.dot(wi) * cos_i <= 0.0 || wm.dot(wo) * cos_o <= 0.0 {
            return None;
        }
        let fresnel = fresnel_dielectric(wo.dot(wm).abs(), eta_across);
        Some(Self {
            reflection,
            eta_p,
            wm,
            fresnel,
        })
    }

    /// (ωi·ωm + ωo·ωm/η′)²: the Jacobian's denominator of refraction.
    #[inline]
    fn refraction_denominator(&self, wi: Vec3, wo: Vec3) -> f32 {
        let d = wi.dot(self.wm) + wo.dot(self.wm) / self.eta_p;
        d * d
    }
}

/// Density of the GGX visible normal `wm` seen from `wo` (either side):
/// G₁(ωo)·max(0, |ωo·ωm|)·D(ωm)/|cos θo| (Heitz 2018).
#[inline]
fn visible_normal_pdf(wo: Vec3, wm: Vec3, alpha: f32) -> f32 {
    let g1 = 1.0 / (1.0 + ggx_lambda(wo, alpha));
    g1 * wo.dot(wm).abs() * ggx_d(wm, alpha) / wo.z.abs()
}
