//! Finite stand-ins for the infinite and zero limits of (a, b), and the input clamps.

use std::f64::consts::PI;

/// 2π², the factor between a primal variance and the matching quadratic-form coefficient.
pub(crate) const TWO_PI_SQ: f64 = 2.0 * PI * PI;

/// Smallest cosine |cos θ| accepted by the projection, reflection and refraction operators.
///
/// Grazing cosines are raised to this value, so 1/μ is at most 10⁴ and a/μ² at most
/// 10⁸·a, which the caps then absorb.
pub const MU_MIN: f64 = 1e-4;

/// The largest cap value [`Caps::new`] accepts (and the upper bound of
/// [`Caps::UNBOUNDED`]): products of two capped values stay finite.
const CAP_LIMIT: f64 = 1e150;

/// Bounds applied to (a, b, c) after every operator.
///
/// `a ∈ [a_min, a_max]` \[m²\], `b ∈ [b_min, b_max]` \[rad²\], then `c² ≤ a·b·(1 − 10⁻¹²)`.
/// A capped value stands for the physical limit: `a = a_max` is "spatially constant over
/// the scene", `b = b_max` is "angularly constant over the analysis window", `a_min` and
/// `b_min` are the finest spatial and angular detail the renderer resolves.
/// The caps are primal scales in disguise: `a_max = 2π²·L²`, `b_max = 2π²·W_θ²`, etc.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Caps {
    a_min: f64,
    a_max: f64,
    b_min: f64,
    b_max: f64,
}

impl Caps {
    /// Caps so wide that no operator meets them at ordinary magnitudes:
    /// a, b ∈ [0, 10¹⁵⁰]. Only the PSD repair `c² ≤ a·b·(1 − 10⁻¹²)` and the overflow
    /// guards remain, so the exact algebraic laws (composition, inverses, determinants)
    /// hold to rounding. Meant for tests and analysis, not for rendering: a zero `a` or `b`
    /// makes the covariance Σ singular.
    pub const UNBOUNDED: Caps = Caps {
        a_min: 0.0,
        a_max: CAP_LIMIT,
        b_min: 0.0,
        b_max: CAP_LIMIT,
    };

    /// Caps from explicit bounds, or `None` unless `0 ≤ a_min ≤ a_max ≤ 10¹⁵⁰` and
    /// `0 ≤ b_min ≤ b_max ≤ 10¹⁵⁰`.
    #[must_use]
    pub fn new(a_min: f64, a_max: f64, b_min: f64, b_max: f64) -> Option<Self> {
        let ordered = |lo: f64, hi: f64| 0.0 <= lo && lo <= hi && hi <= CAP_LIMIT;
        (ordered(a_min, a_max) && ordered(b_min, b_max)).then_some(Caps {
            a_min,
            a_max,
            b_min,
            b_max,
        })
    }

    /// Caps from primal scales: the largest and smallest spatial extents \[m\] and the
    /// largest and smallest angular extents \[rad\], each mapped through `2π²·s²`.
    ///
    /// `None` when the scales are not ordered non-negative numbers or exceed the limit.
    #[must_use]
    pub fn from_primal_scales(
        min_extent: f64,
        max_extent: f64,
        min_angle: f64,
        max_angle: f64,
    ) -> Option<Self> {
        let sq = |s: f64| TWO_PI_SQ * s * s;
        if !(min_extent >= 0.0 && min_angle >= 0.0) {
            return None;
        }
        Caps::new(sq(min_extent), sq(max_extent), sq(min_angle), sq(max_angle))
    }

    /// The suggested caps for a scene of length scale `scene_size` = L \[m\]:
    /// spatial window L and resolution ε_x = 10⁻⁴·L, angular window W_θ = 1 rad and
    /// resolution ε_θ = 10⁻⁴ rad, i.e.
    ///
    /// `a_max = 2π²L²`, `a_min = 2π²(10⁻⁴L)²`, `b_max = 2π² ≈ 19.739`, `b_min = 2π²·10⁻⁸`.
    ///
    /// These values are a design choice of this crate (the poster gives none). `L` is
    /// taken as |L| clamped to [10⁻³⁰, 10³⁰] m; a NaN counts as 1 m.
    #[must_use]
    pub fn for_scene_size(scene_size: f64) -> Self {
        let l = if scene_size.is_nan() {
            1.0
        } else {
            scene_size.abs().clamp(1e-30, 1e30)
        };
        Caps {
            a_min: TWO_PI_SQ * (1e-4 * l) * (1e-4 * l),
            a_max: TWO_PI_SQ * l * l,
            b_min: TWO_PI_SQ * 1e-8,
            b_max: TWO_PI_SQ,
        }
    }

    /// Lower bound of a \[m²\]: the finest spatial detail.
    #[must_use]
    pub fn a_min(&self) -> f64 {
        self.a_min
    }

    /// Upper bound of a \[m²\]: "spatially constant".
    #[must_use]
    pub fn a_max(&self) -> f64 {
        self.a_max
    }

    /// Lower bound of b \[rad²\]: the finest angular detail ("collimated").
    #[must_use]
    pub fn b_min(&self) -> f64 {
        self.b_min
    }

    /// Upper bound of b \[rad²\]: "angularly constant" (Lambertian).
    #[must_use]
    pub fn b_max(&self) -> f64 {
        self.b_max
    }

    /// Keeps the angular slope of a field inside the angular window by narrowing the field in
    /// space, rather than by clamping b and c.
    ///
    /// A field whose angle is correlated with position (after a curved mirror or lens, c ≠ 0)
    /// spreads in angle for two reasons: the slope θ = (c/a)·x across its width, which
    /// contributes s = c²/a to b, and the spread at a fixed x, b − s. The clamp of b (then of c
    /// into `c² ≤ a·b`) lowers the slope when b exceeds `b_max`, which moves the focus of a
    /// converging field away: a caustic was predicted wide and smooth where it focuses. Here
    /// such a field is first narrowed by a spatial window (λ added to the inverse entry of a,
    /// as [`harmonic`] does) until its slope term is s' = max(`b_max` − (b − s), `b_max`/2):
    /// a and c scale by s'/s, which keeps the slope c/a (the focus distance a/|c|) and the
    /// spread at fixed x. Where that spread is at most half the window (a lamp focused by a
    /// mirror), the result has b = `b_max` exactly; where it is wider (a rough lobe) the clamp
    /// lowers it to the other half, with the slope kept. A field with b ≤ `b_max` is
    /// unchanged, and the result is continuous in (a, b, c). NaN and infinite inputs are left
    /// to the clamp.
    pub(crate) fn window_angles(&self, a: f64, b: f64, c: f64) -> (f64, f64, f64) {
        if !(b > self.b_max && a > 0.0 && a.is_finite() && b.is_finite() && c.is_finite()) {
            return (a, b, c);
        }
        let slope_part = c * (c / a);
        let spread = (b - slope_part).max(0.0);
        let target = (self.b_max - spread).max(0.5 * self.b_max);
        if slope_part <= target {
            return (a, b, c);
        }
        let keep = target / slope_part;
        (a * keep, spread + target, c * keep)
    }

    /// Clamps a and b into their ranges and shrinks c into `c² ≤ a·b·(1 − 10⁻¹²)`.
    ///
    /// Infinities land on the caps. A NaN (only reachable through NaN parameters) lands on
    /// the conservative side: the smallest a or b, and c = 0.
    pub(crate) fn clamp(&self, a: f64, b: f64, c: f64) -> (f64, f64, f64) {
        let a = if a.is_nan() {
            self.a_min
        } else {
            a.clamp(self.a_min, self.a_max)
        };
        let b = if b.is_nan() {
            self.b_min
        } else {
            b.clamp(self.b_min, self.b_max)
        };
        // The common case (inside the bound) needs no square root.
        let bound = a * b * (1.0 - 1e-12);
        let c = if c * c <= bound {
            c
        } else if c.is_nan() {
            0.0
        } else {
            let limit = bound.sqrt();
            c.clamp(-limit, limit)
        };
        (a, b, c)
    }
}

/// Clamps a cosine into [`MU_MIN`, 1] (NaN counts as [`MU_MIN`]).
pub(crate) fn clamp_mu(mu: f64) -> f64 {
    if mu.is_nan() {
        MU_MIN
    } else {
        mu.abs().clamp(MU_MIN, 1.0)
    }
}

/// Clamps a refractive index into [10⁻³, 10³] (NaN counts as 1).
pub(crate) fn clamp_eta(eta: f64) -> f64 {
    if eta.is_nan() {
        1.0
    } else {
        eta.abs().clamp(1e-3, 1e3)
    }
}

/// Replaces the NaN of `∞ − ∞` by +∞.
///
/// Used for the diagonal coefficient of a congruence, `x + 2t·y + t²·z`, which is ≥ 0 for
/// a PSD input; it only turns NaN when two of its terms overflow with opposite signs, and
/// then the positive square term dominates.
pub(crate) fn overflow_to_inf(x: f64) -> f64 {
    if x.is_nan() { f64::INFINITY } else { x }
}

/// The rank-one "harmonic" update shared by occlusion, the cosine term (Q form) and the
/// BRDF (Σ form).
///
/// For the symmetric form `[[u, k], [k, v]]`, adding `w` to the *inverse* entry of `u`
/// (x = w·u ≥ 0, possibly +∞) gives, with den = 1 + x:
/// `u' = u/den`, `k' = k/den`, `v' = v − x·k²/(u·den)`.
/// Written with t = x/den ∈ [0, 1], so no denominator is below 1 and x = ∞ is the limit
/// `u' = k' = 0`, `v' = v − k²/u` (the Schur complement).
pub(crate) fn harmonic(u: f64, v: f64, k: f64, x: f64) -> (f64, f64, f64) {
    if x.is_nan() || x <= 0.0 {
        return (u, v, k);
    }
    let (inv_den, t) = if x.is_finite() {
        let den = 1.0 + x;
        (1.0 / den, x / den)
    } else {
        (0.0, 1.0)
    };
    let v = if u > 0.0 {
        (v - t * k * (k / u)).max(0.0)
    } else {
        v
    };
    (u * inv_den, v, k * inv_den)
}

/// `x·y − z·w` with one rounding error (Kahan's compensated 2×2 determinant).
pub(crate) fn det2(x: f64, y: f64, z: f64, w: f64) -> f64 {
    let zw = z * w;
    let err = (-z).mul_add(w, zw);
    x.mul_add(y, -zw) + err
}

#[cfg(test)]
mod tests;
