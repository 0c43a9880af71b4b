//! The glossy model: GGX (Trowbridge–Reitz) microfacets with Smith shadowing and Schlick's Fresnel of a
//! given normal-incidence colour (the exact Fresnel of a metal is `conductor.rs`), over an optional
//! Lambertian base.
//!
//! The model is coupled so that it never reflects more than it receives (the MTL `Kd` + `Ks` it
//! comes from is additive, and reflected up to 1.3 of the incident light with Kd = 0.6,
//! Ks = 0.7): f = f_d + D·G₂·F/(4 cos θₒ cos θᵢ), with GGX D, height-correlated Smith G₂ and
//! Schlick's F = F₀ + (1 − F₀)(1 − cos θ_d)⁵ with F₀ = `reflectance`, and the base of Ashikhmin
//! and Shirley (2000), f_d = 28/(23π)·diffuse·(1 − F₀)·(1 − (1 − cos θᵢ/2)⁵)·(1 − (1 − cos θₒ/2)⁵):
//! reciprocal, weighted by what the specular layer leaves (1 − F₀), and fading at grazing angles
//! where Schlick's F → 1. Its directional albedo stays ≤ 1 for every roughness, `reflectance` and
//! `diffuse` in [0, 1] (tested on a grid). Single-scattering GGX loses energy at high roughness
//! (≈ 0.69 albedo at α = 0.5, 0.31 at α = 1, normal incidence).

use std::f32::consts::{FRAC_1_PI, PI};

use glam::{Vec2, Vec3};

use super::{BsdfSample, Lobe, MaterialParam, Model, Shading, TransportMode, luminance, reflect};
use crate::sampling::{concentric_disk, cosine_hemisphere};
use crate::{Frame, Rgb};

/// A rough conductor with a GGX distribution and Smith shadowing, optionally over a Lambertian
/// base (the OBJ `Kd` + `Ks` mapping).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Glossy {
    /// Specular reflectance per channel.
    pub reflectance: Rgb,
    /// GGX α (not squared), > 0.
    pub roughness: f32,
    /// Albedo of the Lambertian base; zero for a pure conductor (the TOML `glossy`).
    pub diffuse: Rgb,
}

impl Model for Glossy {
    const NAME: &'static str = "glossy";

    /// Its GGX lobe, also over a diffuse base.
    #[inline]
    fn lobe(&self) -> Lobe {
        Lobe::Ggx {
            alpha: self.roughness,
        }
    }

    #[inline]
    fn albedo(&self) -> Rgb {
        self.reflectance + self.diffuse
    }

    fn params(&self) -> Vec<MaterialParam> {
        vec![
            MaterialParam::Colour("reflectance", self.reflectance),
            MaterialParam::Colour("diffuse", self.diffuse),
            MaterialParam::Positive("roughness", self.roughness),
        ]
    }

    /// A texture's colour multiplies the whole BSDF, kept apart from the reflectance that
    /// Fresnel and the coupling read.
    #[inline]
    fn tint(&mut self, tint: Rgb) -> Rgb {
        tint
    }

    #[inline]
    fn eval_local(&self, s: &Shading, wo: Vec3, wi: Vec3) -> Rgb {
        (coupled_diffuse(wo, wi, self.reflectance, self.diffuse)
            + ggx_eval(wo, wi, self.roughness, self.reflectance))
            * s.tint
    }

    #[inline]
    fn pdf_local(&self, wo: Vec3, wi: Vec3) -> f32 {
        let p_spec = specular_probability(self.reflectance, self.diffuse, wo.z);
        p_spec * ggx_pdf(wo, wi, self.roughness) + (1.0 - p_spec) * wi.z * FRAC_1_PI
    }

    fn sample_local(
        &self,
        s: &Shading,
        frame: &Frame,
        wo: Vec3,
        u_lobe: f32,
        u: Vec2,
        _: TransportMode,
    ) -> Option<BsdfSample> {
        let Self {
            reflectance,
            roughness,
            diffuse,
        } = *self;
        if reflectance == Rgb::ZERO && diffuse == Rgb::ZERO {
            return None;
        }
        let flip = wo.z < 0.0;
        let wo_up = if flip { -wo } else { wo };
        let p_spec = specular_probability(reflectance, diffuse, wo_up.z);
        let wi_up = if u_lobe < p_spec {
            let wm = ggx_sample_visible_normal(wo_up, roughness, u);
            reflect(wo_up, wm)
        } else {
            cosine_hemisphere(u)
        };
        if wi_up.z <= 0.0 {
            return None;
        }
        let f = coupled_diffuse(wo_up, wi_up, reflectance, diffuse)
            + ggx_eval(wo_up, wi_up, roughness, reflectance);
        let pdf = p_spec * ggx_pdf(wo_up, wi_up, roughness) + (1.0 - p_spec) * wi_up.z * FRAC_1_PI;
        if pdf.is_nan() || pdf <= 0.0 {
            return None;
        }
        let wi = if flip { -wi_up } else { wi_up };
        Some(BsdfSample {
            incoming: frame.to_world(wi),
            weight: f * (wi_up.z / pdf) * s.tint,
            pdf,
            is_specular: false,
            is_transmission: false,
        })
    }
}

/// The Lambertian base of a glossy material under its specular layer (Ashikhmin and Shirley
/// 2000, eq. 5): 28/(23π)·diffuse·(1 − F₀)·(1 − (1 − cos θᵢ/2)⁵)·(1 − (1 − cos θₒ/2)⁵), with
/// both directions in the upper hemisphere.
fn coupled_diffuse(wo: Vec3, wi: Vec3, reflectance: Rgb, diffuse: Rgb) -> Rgb {
    if diffuse == Rgb::ZERO {
        return Rgb::ZERO;
    }
    let fade = |cos: f32| 1.0 - (1.0 - 0.5 * cos.abs()).powi(5);
    diffuse * (Rgb::ONE - reflectance) * (28.0 / (23.0 * PI) * fade(wo.z) * fade(wi.z))
}

/// Probability of sampling the GGX lobe of a glossy material seen at cosine `cos_o`: proportional
/// to the lobes' albedos there (luminance of Schlick's Fresnel at that angle, which grows toward
/// grazing even for a black `reflectance`, vs the diffuse base under the specular layer).
fn specular_probability(reflectance: Rgb, diffuse: Rgb, cos_o: f32) -> f32 {
    let c = (1.0 - cos_o.abs().min(1.0)).powi(5);
    let s = luminance(reflectance + (Rgb::ONE - reflectance) * c);
    let d = luminance(diffuse * (Rgb::ONE - reflectance));
    if s + d > 0.0 { s / (s + d) } else { 0.5 }
}

/// GGX normal distribution D(ωm) for roughness α.
pub(super) fn ggx_d(wm: Vec3, alpha: f32) -> f32 {
    let a2 = alpha * alpha;
    let c2 = wm.z * wm.z;
    let denom = c2 * (a2 - 1.0) + 1.0;
    a2 / (PI * denom * denom)
}

/// Smith Λ(ω) for GGX.
pub(super) fn ggx_lambda(w: Vec3, alpha: f32) -> f32 {
    let c2 = w.z * w.z;
    let s2 = (1.0 - c2).max(0.0);
    if c2 == 0.0 {
        return f32::INFINITY;
    }
    let tan2 = s2 / c2;
    0.5 * ((1.0 + alpha * alpha * tan2).sqrt() - 1.0)
}

/// The GGX conductor: D·G₂·F/(4 cos θₒ cos θᵢ) with height-correlated Smith G₂ and Schlick's Fresnel
/// with `reflectance` as F₀. Both directions in the upper hemisphere.
fn ggx_eval(wo: Vec3, wi: Vec3, alpha: f32, reflectance: Rgb) -> Rgb {
    let wm = wo + wi;
    if wm == Vec3::ZERO || wo.z <= 0.0 || wi.z <= 0.0 {
        return Rgb::ZERO;
    }
    let wm = wm.normalize();
    let g2 = 1.0 / (1.0 + ggx_lambda(wo, alpha) + ggx_lambda(wi, alpha));
    let c = (1.0 - wi.dot(wm).clamp(0.0, 1.0)).powi(5);
    let fresnel = reflectance + (Rgb::ONE - reflectance) * c;
    fresnel * (ggx_d(wm, alpha) * g2 / (4.0 * wo.z * wi.z))
}

/// Density of [`ggx_sample_visible_normal`] followed by reflection: D(ωm)·G₁(ωₒ)/(4 cos θₒ).
pub(super) fn ggx_pdf(wo: Vec3, wi: Vec3, alpha: f32) -> f32 {
    let wm = wo + wi;
    if wm == Vec3::ZERO || wo.z <= 0.0 || wi.z <= 0.0 {
        return 0.0;
    }
    let wm = wm.normalize();
    let g1 = 1.0 / (1.0 + ggx_lambda(wo, alpha));
    ggx_d(wm, alpha) * g1 / (4.0 * wo.z)
}

/// Samples a microfacet normal from the distribution of normals visible from `wo` (Heitz 2018,
/// "Sampling the GGX Distribution of Visible Normals"); `wo.z > 0`.
pub(super) fn ggx_sample_visible_normal(wo: Vec3, alpha: f32, u: Vec2) -> Vec3 {
    // Stretch to the hemisphere configuration.
    let vh = Vec3::new(alpha * wo.x, alpha * wo.y, wo.z).normalize();
    let len2 = vh.x * vh.x + vh.y * vh.y;
    let t1 = if len2 > 0.0 {
        Vec3::new(-vh.y, vh.x, 0.0) / len2.sqrt()
    } else {
        Vec3::X
    };
    let t2 = vh.cross(t1);
    // A point on the projected disc, warped toward the visible half.
    let p = concentric_disk(u);
    let s = 0.5 * (1.0 + vh.z);
    let py = (1.0 - s) * (1.0 - p.x * p.x).max(0.0).sqrt() + s * p.y;
    let nh = p.x * t1 + py * t2 + (1.0 - p.x * p.x - py * py).max(0.0).sqrt() * vh;
    // Unstretch.
    Vec3::new(alpha * nh.x, alpha * nh.y, nh.z.max(1e-6)).normalize()
}
