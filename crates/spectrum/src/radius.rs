//! Kernel radii from the spectrum slices (poster §1, design §8.2).

use std::f64::consts::FRAC_PI_2;

/// β₉₅ = −ln 0.95: exp(−β₉₅) = 0.95.
pub const BETA_95: f64 = 0.051_293_294_387_550_58;

/// The poster's radius constant K = π·√β₉₅ ≈ 0.711509.
///
/// With a = 2π²σx² this is r_x ≈ 3.161·σx: about 9.87 (= π²) times the radius where the
/// irradiance falls to 95 % of its peak. It is what reproduces the poster.
pub const K_POSTER: f64 = 0.711_508_625_410_642;

/// The strict 95 % constant K = √β₉₅/π ≈ 0.0720909: the irradiance exp(−π²x²/a) falls
/// to 95 % of its peak at x = K·√a (≈ 0.320·σx).
pub const K_STRICT: f64 = 0.072_090_896_098_338_98;

/// The spatial radius `r_x = K·√a` \[m\] for a spatial coefficient a \[m²\] and radius
/// constant K ([`K_POSTER`] or [`K_STRICT`]). Negative a counts as 0.
#[must_use]
pub fn spatial_radius(a: f64, k: f64) -> f64 {
    k * a.max(0.0).sqrt()
}

/// The angular radius `r_θ = z·tan(K·√b)` \[m\] for an angular coefficient b \[rad²\], the
/// camera distance projected on the hitpoint normal z \[m\] and radius constant K.
///
/// It is the displacement on the surface that turns the direction to the camera by
/// K·√b (exact at normal viewing, conservative at oblique viewing). Once K·√b ≥ π/2 the
/// angular content never limits the kernel and the result is +∞ (with [`K_POSTER`]: from
/// b ≥ 1/(4β₉₅) ≈ 4.8739 rad²). Negative b counts as 0.
#[must_use]
pub fn angular_radius(b: f64, normal_distance: f64, k: f64) -> f64 {
    let angle = k * b.max(0.0).sqrt();
    if angle >= FRAC_PI_2 {
        f64::INFINITY
    } else {
        normal_distance.abs() * angle.tan()
    }
}
