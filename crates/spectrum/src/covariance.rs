//! The Σ form (p, q, r): covariance tracing's representation, for cross-checking.

use std::f64::consts::FRAC_PI_2;

use crate::caps::{clamp_eta, clamp_mu, harmonic};
use crate::lobe::Lobe;

/// The spectral covariance Σ = (2Q)⁻¹ = [[p, q], [q, r]] of the local spectrum viewed as a
/// density over (Ωx \[cycles/m\], Ωθ \[cycles/rad\]): p \[m⁻²\], q \[m⁻¹rad⁻¹\], r \[rad⁻²\].
///
/// Every ray map M acts as Σ' = M⁻ᵀ Σ M⁻¹; windows (occlusion, cosine) add to Σ; the BRDF
/// is a Woodbury update. These operators mirror those of [`Spectrum`](crate::Spectrum)
/// and agree with them (`Σ(op_Q(Q)) = op_Σ(Σ(Q))`). They are *not* capped: use them for
/// checks and analysis, and [`Spectrum`](crate::Spectrum) for rendering. Cosines and
/// indices are clamped as in the Q form; denominators are never below 1.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Covariance {
    p: f64,
    q: f64,
    r: f64,
}

impl Covariance {
    /// A covariance from its entries, or `None` unless they are finite, p, r ≥ 0 and
    /// `q² ≤ p·r` up to rounding (symmetric PSD).
    #[must_use]
    pub fn new(p: f64, q: f64, r: f64) -> Option<Self> {
        let ok = p.is_finite()
            && q.is_finite()
            && r.is_finite()
            && p >= 0.0
            && r >= 0.0
            && q * q <= p * r * (1.0 + 1e-9);
        ok.then_some(Covariance { p, q, r })
    }

    /// Σxx = p \[m⁻²\], the spatial-frequency variance.
    #[must_use]
    pub fn p(&self) -> f64 {
        self.p
    }

    /// Σxθ = q \[m⁻¹·rad⁻¹\].
    #[must_use]
    pub fn q(&self) -> f64 {
        self.q
    }

    /// Σθθ = r \[rad⁻²\], the angular-frequency variance.
    #[must_use]
    pub fn r(&self) -> f64 {
        self.r
    }

    /// Travel by d \[m\]: `p' = p`, `q' = q − d·p`, `r' = r − 2d·q + d²·p`.
    #[must_use]
    pub fn travel(self, distance: f64) -> Self {
        let d = distance;
        Covariance {
            p: self.p,
            q: self.q - d * self.p,
            r: self.r + d * (d * self.p - 2.0 * self.q),
        }
    }

    /// Angular kick by g \[rad/m\]: `p' = p − 2g·q + g²·r`, `q' = q − g·r`, `r' = r`.
    #[must_use]
    pub fn kick(self, g: f64) -> Self {
        Covariance {
            p: self.p + g * (g * self.r - 2.0 * self.q),
            q: self.q - g * self.r,
            r: self.r,
        }
    }

    /// Angle flip diag(1, −1): `q' = −q`.
    #[must_use]
    pub fn flip(self) -> Self {
        Covariance { q: -self.q, ..self }
    }

    /// Projection onto a surface at cosine μi: `p' = μi²·p`, `q' = μi·q`, `r' = r`.
    #[must_use]
    pub fn project_in(self, mu_i: f64) -> Self {
        let mu = clamp_mu(mu_i);
        Covariance {
            p: mu * mu * self.p,
            q: mu * self.q,
            r: self.r,
        }
    }

    /// Projection back to a ray at cosine μo: `p' = p/μo²`, `q' = q/μo`, `r' = r`.
    #[must_use]
    pub fn project_out(self, mu_o: f64) -> Self {
        let inv = 1.0 / clamp_mu(mu_o);
        Covariance {
            p: inv * inv * self.p,
            q: inv * self.q,
            r: self.r,
        }
    }

    /// Complete reflection (see [`Spectrum::reflect`](crate::Spectrum::reflect)); with
    /// m = μo/μi and g = 2κ/μi:
    /// `p' = (p + 2g·q + g²·r)/m²`, `q' = (q + g·r)/m`, `r' = r`, then the band-limit.
    #[must_use]
    pub fn reflect(self, mu_i: f64, mu_o: f64, curvature: f64, lobe: Lobe) -> Self {
        let mu_i = clamp_mu(mu_i);
        let m = clamp_mu(mu_o) / mu_i;
        let g = 2.0 * curvature / mu_i;
        Covariance {
            p: (self.p + g * (2.0 * self.q + g * self.r)) / (m * m),
            q: (self.q + g * self.r) / m,
            r: self.r,
        }
        .bandlimit(lobe)
    }

    /// Smooth refraction (see [`Spectrum::refract`](crate::Spectrum::refract)); with
    /// s = ηi·μi/(ηt·μt), t = μt/μi, h = (1 − s)·κ/μi and e = h/s:
    /// `p' = (p − 2e·q + e²·r)/t²`, `q' = (q − e·r)/(t·s)`, `r' = r/s²`.
    #[must_use]
    pub fn refract(self, eta_i: f64, eta_t: f64, mu_i: f64, mu_t: f64, curvature: f64) -> Self {
        let (mu_i, mu_t) = (clamp_mu(mu_i), clamp_mu(mu_t));
        let s = clamp_eta(eta_i) * mu_i / (clamp_eta(eta_t) * mu_t);
        let t = mu_t / mu_i;
        let e = (1.0 - s) * curvature / (mu_i * s);
        Covariance {
            p: (self.p + e * (e * self.r - 2.0 * self.q)) / (t * t),
            q: (self.q - e * self.r) / (t * s),
            r: self.r / (s * s),
        }
    }

    /// BRDF band-limit by Woodbury (no inverse), with β = 4π²σρ² \[rad²\]:
    /// `p' = p − β·q²/(1 + β·r)`, `q' = q/(1 + β·r)`, `r' = r/(1 + β·r)`.
    ///
    /// [`Lobe::Lambert`] (β = ∞): `p' = p − q²/r` (p if r = 0), `q' = r' = 0`.
    /// A literal pseudo-inverse sum would be wrong when Σ is singular.
    #[must_use]
    pub fn bandlimit(self, lobe: Lobe) -> Self {
        let x = match lobe.bandwidth() {
            None => f64::INFINITY,
            Some(b_rho) => 2.0 * b_rho * self.r,
        };
        let (r, p, q) = harmonic(self.r, self.p, self.q, x);
        Covariance { p, q, r }
    }

    /// Partial occlusion with spectral variance o \[m⁻²\]: `p' = p + o` (negative o counts
    /// as 0).
    #[must_use]
    pub fn occlude(self, o: f64) -> Self {
        Covariance {
            p: self.p + o.max(0.0),
            ..self
        }
    }

    /// The optional cosine term: `r' = r + w_c`, w_c = 1/max(π/2 − θi, 10⁻¹⁰)².
    #[must_use]
    pub fn cosine(self, theta_i: f64) -> Self {
        let gap = (FRAC_PI_2 - theta_i.abs()).max(1e-10);
        Covariance {
            r: self.r + 1.0 / (gap * gap),
            ..self
        }
    }
}
