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

    /// A spot light whose intensity falls off smoothly between the half-angles θstart and
    /// θcone \[rad\] (pbrt-v4's `smoothstep(cos θ; cos θcone, cos θstart)`, full inside
    /// θstart, none outside θcone): the Gaussian of the profile's own angular variance,
    ///
    /// `a = a_min`, `b = 2π²·∫θ²I(θ)dθ / ∫I(θ)dθ`, `c = 0`.
    ///
    /// The falloff concentrates the light inside the cone, so its variance is below the
    /// hard cone's θcone²/3 and its prediction the more conservative (smaller b, sharper);
    /// θstart ≥ θcone is the hard cone, [`Spectrum::spot_light`]. The integral is a fixed
    /// 256-point midpoint rule (exact to ~10⁻⁵ relative).
    #[must_use]
    pub fn spot_light_smoothstep(falloff_start: f64, cone: f64, caps: &Caps) -> Self {
        const STEPS: u32 = 256;
        let cone = if cone.is_finite() { cone.abs() } else { 0.0 };
        let start = if falloff_start.is_finite() {
            falloff_start.abs().min(cone)
        } else {
            cone
        };
        let (cos_cone, cos_start) = (cone.cos(), start.cos());
        let (mut moment, mut mass) = (0.0, 0.0);
        for i in 0..STEPS {
            let theta = cone * (f64::from(i) + 0.5) / f64::from(STEPS);
            let w = if cos_start > cos_cone {
                let t = ((theta.cos() - cos_cone) / (cos_start - cos_cone)).clamp(0.0, 1.0);
                t * t * (3.0 - 2.0 * t)
            } else {
                1.0
            };
            moment += w * theta * theta;
            mass += w;
        }
        let variance = if mass > 0.0 { moment / mass } else { 0.0 };
        Spectrum::finish(0.0, TWO_PI_SQ * variance, 0.0, false, caps)
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
