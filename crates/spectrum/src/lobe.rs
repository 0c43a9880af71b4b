//! BRDF lobes as angular Gaussians (the band-limit operator's parameter).

use crate::caps::TWO_PI_SQ;

/// A BRDF lobe seen as a Gaussian of angular variance σρ² \[rad²\] about the (local) mirror
/// direction, in the outgoing angle.
///
/// Widths come from matching the lobe's peak curvature. That sets the high-frequency
/// content correctly but ignores heavy tails (GGX), which matters for energy, not for
/// bandwidth. Negative or NaN parameters count as 0 (a mirror).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Lobe {
    /// Perfect mirror or smooth dielectric: σρ² = 0, the band-limit is a no-op.
    Mirror,
    /// Lambertian: σρ² = ∞. The band-limit sets b = b_max, c = 0 and the Lambertian flag.
    Lambert,
    /// Phong `cosⁿ` about the mirror direction: σρ² = 1/n.
    Phong {
        /// The exponent n (dimensionless).
        exponent: f64,
    },
    /// Blinn–Phong `cosⁿ θh` about the half vector: σρ² = 4/n (δθo = 2δθh at fixed ωi).
    BlinnPhong {
        /// The exponent n (dimensionless).
        exponent: f64,
    },
    /// Beckmann, `D ∝ exp(−tan²θh/α²)`: σρ² = 2α².
    Beckmann {
        /// The roughness α (dimensionless).
        roughness: f64,
    },
    /// GGX / Trowbridge–Reitz (peak curvature ≈ 2/α²): σρ² = α².
    Ggx {
        /// The roughness α (dimensionless).
        roughness: f64,
    },
    /// Any other lobe given by its angular variance σρ² \[rad²\] directly, e.g. rough
    /// dielectric transmission with σρ² = (1 − s)²σh².
    Gaussian {
        /// σρ² \[rad²\].
        variance: f64,
    },
}

impl Lobe {
    /// The lobe's angular variance σρ² \[rad²\]; `None` for [`Lobe::Lambert`] (infinite).
    #[must_use]
    pub fn angular_variance(&self) -> Option<f64> {
        let raw = match *self {
            Lobe::Mirror => 0.0,
            Lobe::Lambert => return None,
            Lobe::Phong { exponent } => 1.0 / exponent,
            Lobe::BlinnPhong { exponent } => 4.0 / exponent,
            Lobe::Beckmann { roughness } => 2.0 * roughness * roughness,
            Lobe::Ggx { roughness } => roughness * roughness,
            Lobe::Gaussian { variance } => variance,
        };
        // Negative and NaN variances count as a mirror.
        Some(if raw >= 0.0 { raw } else { 0.0 })
    }

    /// The lobe's quadratic-form increment `b_ρ = 2π²σρ²` \[rad²\], added to b by the
    /// band-limit; `None` for [`Lobe::Lambert`]. (Σ form: β = 4π²σρ² = 2·b_ρ.)
    #[must_use]
    pub fn bandwidth(&self) -> Option<f64> {
        self.angular_variance().map(|v| TWO_PI_SQ * v)
    }
}
