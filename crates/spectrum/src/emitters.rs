//! Emitter constructors: the initial (a, b, c) in the emitted ray frame (design §6).
//!
//! A box of width w is replaced by the Gaussian of equal variance w²/12 (the box's sinc
//! spectrum has no finite variance). Angles are in radians, lengths in metres.

use crate::caps::{Caps, TWO_PI_SQ, clamp_mu};
use crate::spectrum::Spectrum;

impl Spectrum {
    /// A Lambertian area light of size s \[m\] seen at cosine μe between the emitted
    /// direction and the emitter normal:
    ///
    /// `a = 2π²·(s²/12)·μe² = (π²/6)·s²·μe²`, `b = b_max`, `c = 0`, Lambertian.
    ///
    /// (a = π²s²/6 on the surface, then the projection out.) A zero size gives a = a_min.
    #[must_use]
    pub fn area_light(size: f64, mu_e: f64, caps: &Caps) -> Self {
        let mu = clamp_mu(mu_e);
        let a = TWO_PI_SQ * size * size / 12.0 * mu * mu;
        Spectrum::finish(a, 0.0, 0.0, true, caps)
    }

    /// An isotropic point light at its own position: a spatial Dirac, angularly flat:
    /// `a = a_min`, `b = b_max`, `c = 0`, Lambertian.
    ///
    /// After travel d: a ≈ d²·b_max, c ≈ d·b_max (irradiance width ≈ d·W_θ).
    #[must_use]
    pub fn point_light(caps: &Caps) -> Self {
        Spectrum::finish(0.0, 0.0, 0.0, true, caps)
    }

    /// A spot light with a hard cone of half-angle θs \[rad\] (a box of width 2θs):
    /// `a = a_min`, `b = 2π²·θs²/3`, `c = 0`.
    #[must_use]
    pub fn spot_light(half_angle: f64, caps: &Caps) -> Self {
        Spectrum::finish(
            0.0,
            TWO_PI_SQ * half_angle * half_angle / 3.0,
            0.0,
            false,
            caps,
        )
    }

    /// A spot light with a smooth `cosᵐ` falloff about its axis (angular variance 1/m):
    /// `a = a_min`, `b = 2π²/m`, `c = 0`. For a Gaussian falloff of std σs use
    /// m = 1/σs². A non-positive m gives b = b_max.
    #[must_use]
    pub fn spot_light_falloff(exponent: f64, caps: &Caps) -> Self {
        let b = if exponent > 0.0 {
            TWO_PI_SQ / exponent
        } else {
            f64::INFINITY
        };
        Spectrum::finish(0.0, b, 0.0, false, caps)
    }

    /// A directional light of infinite extent: `a = a_max`, `b = b_min`, `c = 0`.
    /// Travel leaves it unchanged (up to the caps).
    #[must_use]
    pub fn directional_light(caps: &Caps) -> Self {
        Spectrum::finish(f64::INFINITY, 0.0, 0.0, false, caps)
    }

    /// A sun of angular diameter δ \[rad\] (a disc seen as a box of width δ):
    /// `a = a_max`, `b = 2π²·δ²/12 = π²δ²/6`, `c = 0` (δ = 0.0093 gives b ≈ 1.42·10⁻⁴).
    #[must_use]
    pub fn sun(angular_diameter: f64, caps: &Caps) -> Self {
        let d = angular_diameter;
        Spectrum::finish(f64::INFINITY, TWO_PI_SQ * d * d / 12.0, 0.0, false, caps)
    }
}
