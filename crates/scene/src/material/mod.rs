//! Scattering models (BSDFs) of the scene format: Lambert, mirror, smooth dielectric and a GGX
//! conductor over an optional Lambertian base.
//!
//! Conventions (pbrt's): `outgoing` and `incoming` are world-space unit vectors pointing away from
//! the surface; `outgoing` points back along the path being traced (toward the camera for camera
//! paths, toward the light for photon paths). [`Bsdf::eval`] returns f without the cosine.
//! All materials scatter on both sides: a reflection needs `outgoing` and `incoming` on the same
//! side of the shading normal, whichever side that is.
//!
//! The glossy model is a GGX conductor over a Lambertian base, coupled so that it never reflects
//! more than it receives (the MTL `Kd` + `Ks` it comes from is additive, and reflected up to 1.3
//! of the incident light with Kd = 0.6, Ks = 0.7):
//! f = f_d + D·G₂·F/(4 cos θₒ cos θᵢ), with GGX D, height-correlated Smith G₂ and Schlick's
//! F = F₀ + (1 − F₀)(1 − cos θ_d)⁵ with F₀ = `reflectance`, and the base of Ashikhmin and Shirley
//! (2000), f_d = 28/(23π)·diffuse·(1 − F₀)·(1 − (1 − cos θᵢ/2)⁵)·(1 − (1 − cos θₒ/2)⁵): reciprocal,
//! weighted by what the specular layer leaves (1 − F₀), and fading at grazing angles where
//! Schlick's F → 1. Its directional albedo stays ≤ 1 for every roughness, `reflectance` and
//! `diffuse` in [0, 1] (tested on a grid). Single-scattering GGX loses energy at high roughness
//! (≈ 0.69 albedo at α = 0.5, 0.31 at α = 1, normal incidence).

use std::f32::consts::{FRAC_1_PI, PI};

use glam::{Vec2, Vec3};

use crate::{
    Frame, Hit, Material, MaterialKind, Rgb,
    sampling::{concentric_disk, cosine_hemisphere},
};

#[cfg(test)]
mod tests;

/// What a path carries, which matters for refraction (Veach 1997, §5.2; pbrt's `TransportMode`).
///
/// Camera paths carry [`TransportMode::Radiance`]: refraction scales it by 1/η′² (η′ = η of the side
/// `incoming` points into over η of the side of `outgoing`). Photon (light) paths carry
/// [`TransportMode::Importance`]-like flux, which refraction does not scale.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TransportMode {
    /// Camera paths: radiance.
    Radiance,
    /// Light (photon) paths: flux / importance.
    Importance,
}

/// The angular width of a material's scattering lobe, for the frequency operators (frequency-algebra §7).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Lobe {
    /// A delta lobe (mirror, smooth dielectric): σρ = 0.
    Specular,
    /// A Lambertian lobe: infinitely wide.
    Lambert,
    /// A GGX lobe of roughness α (not squared): σρ² ≈ α².
    Ggx {
        /// GGX α.
        alpha: f32,
    },
}

/// A direction drawn by [`Bsdf::sample`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BsdfSample {
    /// Unit world-space direction away from the surface.
    pub incoming: Vec3,
    /// f·|cos θᵢ|/pdf per channel: the factor the path throughput is multiplied by.
    pub weight: Rgb,
    /// Solid-angle density of `incoming`; for specular samples the discrete probability of the chosen lobe.
    pub pdf: f32,
    /// Whether `incoming` came from a delta lobe (no [`Bsdf::eval`]/[`Bsdf::pdf`] counterpart).
    pub is_specular: bool,
    /// Whether `incoming` is on the other side of the surface than `outgoing`.
    pub is_transmission: bool,
}

/// A material's scattering at one surface point, in the hit's shading frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bsdf {
    /// The unit shading normal. The shading frame is built from it where a method needs one
    /// (`Frame::from_normal` is a pure function of it): a photon killed by the roulette, or a
    /// Lambertian evaluated against a normal, never needs the tangents.
    normal: Vec3,
    kind: MaterialKind,
    /// For dielectrics: η on the far side of the shading normal over η on its side.
    eta: f32,
    /// A texture's colour multiplying a glossy BSDF (one otherwise: a diffuse albedo or a mirror
    /// reflectance takes the texture into `kind` itself).
    tint: Rgb,
}

impl MaterialKind {
    /// The lobe for the frequency operators. A glossy material with a diffuse base reports its GGX lobe.
    pub fn lobe(&self) -> Lobe {
        match *self {
            MaterialKind::Diffuse { .. } => Lobe::Lambert,
            MaterialKind::Mirror { .. } | MaterialKind::Dielectric { .. } => Lobe::Specular,
            MaterialKind::Glossy { roughness, .. } => Lobe::Ggx { alpha: roughness },
        }
    }

    /// Whether every lobe is a delta (mirror, smooth dielectric).
    pub fn is_specular(&self) -> bool {
        matches!(
            self,
            MaterialKind::Mirror { .. } | MaterialKind::Dielectric { .. }
        )
    }
}

impl Bsdf {
    /// The BSDF of `material` at `hit`, in the frame of its shading normal. A dielectric's inside is
    /// behind the front face: a hit on the front face enters the medium.
    #[inline]
    pub fn new(material: &Material, hit: &Hit) -> Self {
        Self::from_normal(material.kind, hit.shading_normal, hit.front_face)
    }

    /// The BSDF of `kind` around the unit `normal`; `front_face` tells whether `normal` points to the
    /// outside of a dielectric.
    #[inline]
    pub fn from_normal(kind: MaterialKind, normal: Vec3, front_face: bool) -> Self {
        let eta = match kind {
            MaterialKind::Dielectric { ior } => {
                if front_face {
                    ior
                } else {
                    1.0 / ior
                }
            }
            _ => 1.0,
        };
        Self {
            normal,
            kind,
            eta,
            tint: Rgb::ONE,
        }
    }

    /// [`Bsdf::from_normal`] with a texture colour `tint` that multiplies the BSDF: folded into a
    /// diffuse albedo or a mirror reflectance, kept as a factor of the whole glossy BSDF, ignored
    /// by a dielectric.
    #[inline]
    pub fn tinted(kind: MaterialKind, normal: Vec3, front_face: bool, tint: Rgb) -> Self {
        let mut bsdf = Self::from_normal(kind, normal, front_face);
        match &mut bsdf.kind {
            MaterialKind::Diffuse { albedo } => *albedo *= tint,
            MaterialKind::Mirror { reflectance } => *reflectance *= tint,
            MaterialKind::Glossy { .. } => bsdf.tint = tint,
            MaterialKind::Dielectric { .. } => {}
        }
        bsdf
    }

    /// The scattering model, with a texture's colour folded into a diffuse albedo or a mirror
    /// reflectance (a glossy BSDF's texture colour is a separate factor).
    pub fn kind(&self) -> MaterialKind {
        self.kind
    }

    /// The shading frame (its `n` is the shading normal).
    #[inline]
    pub fn frame(&self) -> Frame {
        Frame::from_normal(self.normal)
    }

    /// Whether the BSDF is purely specular (mirror, smooth dielectric): [`Bsdf::eval`] is then always zero.
    pub fn is_specular(&self) -> bool {
        self.kind.is_specular()
    }

    /// The lobe width for the frequency operators; see [`MaterialKind::lobe`].
    pub fn lobe(&self) -> Lobe {
        self.kind.lobe()
    }

    /// The BSDF value f(outgoing, incoming), without the cosine; zero for delta lobes.
    pub fn eval(&self, outgoing: Vec3, incoming: Vec3) -> Rgb {
        if let MaterialKind::Diffuse { albedo } = self.kind {
            // The local z of both directions, without the tangents.
            return if outgoing.dot(self.normal) * incoming.dot(self.normal) <= 0.0 {
                Rgb::ZERO
            } else {
                albedo * FRAC_1_PI
            };
        }
        let frame = self.frame();
        let (wo, wi) = (frame.to_local(outgoing), frame.to_local(incoming));
        if wo.z * wi.z <= 0.0 {
            return Rgb::ZERO;
        }
        // Two-sided: mirror both into the upper hemisphere.
        let (wo, wi) = if wo.z < 0.0 { (-wo, -wi) } else { (wo, wi) };
        match self.kind {
            MaterialKind::Diffuse { albedo } => albedo * FRAC_1_PI,
            MaterialKind::Mirror { .. } | MaterialKind::Dielectric { .. } => Rgb::ZERO,
            MaterialKind::Glossy {
                reflectance,
                roughness,
                diffuse,
            } => {
                (coupled_diffuse(wo, wi, reflectance, diffuse)
                    + ggx_eval(wo, wi, roughness, reflectance))
                    * self.tint
            }
        }
    }

    /// Solid-angle density with which [`Bsdf::sample`] draws `incoming`; zero for delta lobes.
    pub fn pdf(&self, outgoing: Vec3, incoming: Vec3) -> f32 {
        let frame = self.frame();
        let (wo, wi) = (frame.to_local(outgoing), frame.to_local(incoming));
        if wo.z * wi.z <= 0.0 {
            return 0.0;
        }
        let (wo, wi) = if wo.z < 0.0 { (-wo, -wi) } else { (wo, wi) };
        match self.kind {
            MaterialKind::Diffuse { .. } => wi.z * FRAC_1_PI,
            MaterialKind::Mirror { .. } | MaterialKind::Dielectric { .. } => 0.0,
            MaterialKind::Glossy {
                reflectance,
                roughness,
                diffuse,
            } => {
                let p_spec = specular_probability(reflectance, diffuse, wo.z);
                p_spec * ggx_pdf(wo, wi, roughness) + (1.0 - p_spec) * wi.z * FRAC_1_PI
            }
        }
    }

    /// Draws `incoming` for `outgoing` with `u_lobe` ∈ [0, 1) choosing a lobe (Fresnel reflection vs
    /// refraction, specular vs diffuse) and `u` ∈ [0, 1)² the direction; `None` when nothing is scattered.
    /// `mode` matters only for refraction (see [`TransportMode`]).
    pub fn sample(
        &self,
        outgoing: Vec3,
        u_lobe: f32,
        u: Vec2,
        mode: TransportMode,
    ) -> Option<BsdfSample> {
        let frame = self.frame();
        let wo = frame.to_local(outgoing);
        if wo.z == 0.0 || !wo.is_finite() {
            return None;
        }
        match self.kind {
            MaterialKind::Diffuse { albedo } => {
                if albedo == Rgb::ZERO {
                    return None;
                }
                let mut wi = cosine_hemisphere(u);
                if wo.z < 0.0 {
                    wi.z = -wi.z;
                }
                let pdf = wi.z.abs() * FRAC_1_PI;
                (pdf > 0.0).then(|| BsdfSample {
                    incoming: frame.to_world(wi),
                    weight: albedo,
                    pdf,
                    is_specular: false,
                    is_transmission: false,
                })
            }
            MaterialKind::Mirror { reflectance } => {
                if reflectance == Rgb::ZERO {
                    return None;
                }
                Some(BsdfSample {
                    incoming: frame.to_world(Vec3::new(-wo.x, -wo.y, wo.z)),
                    weight: reflectance,
                    pdf: 1.0,
                    is_specular: true,
                    is_transmission: false,
                })
            }
            MaterialKind::Dielectric { .. } => self.sample_dielectric(&frame, wo, u_lobe, mode),
            MaterialKind::Glossy {
                reflectance,
                roughness,
                diffuse,
            } => {
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
                let pdf = p_spec * ggx_pdf(wo_up, wi_up, roughness)
                    + (1.0 - p_spec) * wi_up.z * FRAC_1_PI;
                if pdf.is_nan() || pdf <= 0.0 {
                    return None;
                }
                let wi = if flip { -wi_up } else { wi_up };
                Some(BsdfSample {
                    incoming: frame.to_world(wi),
                    weight: f * (wi_up.z / pdf) * self.tint,
                    pdf,
                    is_specular: false,
                    is_transmission: false,
                })
            }
        }
    }

    fn sample_dielectric(
        &self,
        frame: &Frame,
        wo: Vec3,
        u_lobe: f32,
        mode: TransportMode,
    ) -> Option<BsdfSample> {
        // Relative η across the boundary, seen from the side of `wo`.
        let eta = if wo.z > 0.0 { self.eta } else { 1.0 / self.eta };
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

/// Rec.709 luminance.
pub(crate) fn luminance(c: Rgb) -> f32 {
    c.dot(Vec3::new(0.2126, 0.7152, 0.0722))
}

/// Mirror of `w` about the unit normal `n` (both pointing away from the surface).
fn reflect(w: Vec3, n: Vec3) -> Vec3 {
    -w + 2.0 * w.dot(n) * n
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
    let cos_i = wo.z.abs();
    let sin2_i = (1.0 - cos_i * cos_i).max(0.0);
    let sin2_t = sin2_i / (eta * eta);
    if sin2_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    Some((-wo / eta + (cos_i / eta - cos_t) * n).normalize())
}

/// GGX normal distribution D(ωm) for roughness α.
fn ggx_d(wm: Vec3, alpha: f32) -> f32 {
    let a2 = alpha * alpha;
    let c2 = wm.z * wm.z;
    let denom = c2 * (a2 - 1.0) + 1.0;
    a2 / (PI * denom * denom)
}

/// Smith Λ(ω) for GGX.
fn ggx_lambda(w: Vec3, alpha: f32) -> f32 {
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
fn ggx_pdf(wo: Vec3, wi: Vec3, alpha: f32) -> f32 {
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
fn ggx_sample_visible_normal(wo: Vec3, alpha: f32, u: Vec2) -> Vec3 {
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
