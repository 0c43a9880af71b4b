//! Warping functions from the unit square and a discrete distribution.

use std::f32::consts::{FRAC_PI_4, PI};

use glam::{Vec2, Vec3, Vec4};

/// Maps the unit square to the unit disc, preserving area (Shirley & Chiu 1997).
///
/// The point is r·(cos θ, sin θ) with θ = π/4 · (other / r) in the wedge where |x| > |y|, and
/// θ = π/2 − π/4 · (other / r) in the other one; there cos θ and sin θ are the sine and cosine
/// of q = π/4 · (other / r). So both wedges need sin q and cos q for |q| ≤ π/4 only, which
/// [`sin_cos_quarter`] gives without range reduction, and the wedge only chooses which is which.
/// Computed on vectors, so that the compiler blends rather than branches (the wedge is a coin
/// toss per sample), and without libm's `sincosf`, which branches on the range of θ
/// (docs/performance.md).
#[inline]
pub(crate) fn concentric_disk(u: Vec2) -> Vec2 {
    let o = 2.0 * u - Vec2::ONE;
    if o.x == 0.0 && o.y == 0.0 {
        return Vec2::ZERO;
    }
    let wide = Vec4::splat(o.x.abs()).cmpgt(Vec4::splat(o.y.abs()));
    let picked = Vec4::select(
        wide,
        Vec4::new(o.x, o.y, 0.0, 0.0),
        Vec4::new(o.y, o.x, 0.0, 0.0),
    );
    let (r, other) = (picked.x, picked.y);
    let (sin, cos) = sin_cos_quarter(FRAC_PI_4 * (other / r));
    let d = Vec4::select(
        wide,
        Vec4::new(cos, sin, 0.0, 0.0),
        Vec4::new(sin, cos, 0.0, 0.0),
    );
    r * Vec2::new(d.x, d.y)
}

/// (sin x, cos x) for |x| ≤ π/4, by the minimax polynomials of Cephes' `sinf` and `cosf` for
/// that interval (Moshier 1989; within 1.2·10⁻⁷ of the exact values, tested below).
#[inline(always)]
fn sin_cos_quarter(x: f32) -> (f32, f32) {
    let z = x * x;
    let sin = ((-1.951_529_6e-4 * z + 8.332_161e-3) * z - 1.666_665_5e-1) * z * x + x;
    let cos = ((2.443_315_7e-5 * z - 1.388_731_6e-3) * z + 4.166_664_6e-2) * z * z - 0.5 * z + 1.0;
    (sin, cos)
}

/// Cosine-weighted direction about local +z; its pdf is `cos θ / π`.
pub(crate) fn cosine_hemisphere(u: Vec2) -> Vec3 {
    let d = concentric_disk(u);
    let z = (1.0 - d.length_squared()).max(0.0).sqrt();
    Vec3::new(d.x, d.y, z)
}

/// Uniform direction on the unit sphere; its pdf is `1 / 4π`.
pub(crate) fn uniform_sphere(u: Vec2) -> Vec3 {
    let z = 1.0 - 2.0 * u.x;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * PI * u.y;
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// Uniform direction in the cone about local +z with `cos θ ≥ cos_max`; its pdf is `1 / (2π (1 − cos_max))`.
pub(crate) fn uniform_cone(u: Vec2, cos_max: f32) -> Vec3 {
    let cos_theta = (1.0 - u.x) + u.x * cos_max;
    let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    let phi = 2.0 * PI * u.y;
    Vec3::new(sin_theta * phi.cos(), sin_theta * phi.sin(), cos_theta)
}

/// Barycentrics (b1, b2) of a uniformly distributed point on a triangle (b0 = 1 − b1 − b2).
pub(crate) fn uniform_triangle(u: Vec2) -> Vec2 {
    let su = u.x.sqrt();
    Vec2::new(1.0 - su, u.y * su)
}

/// A discrete distribution over indices with probabilities proportional to given weights.
#[derive(Clone, Debug, Default)]
pub(crate) struct Distribution1D {
    /// Cumulative sums normalised to end at 1, one entry per index.
    cdf: Vec<f32>,
    /// Normalised probabilities.
    pmf: Vec<f32>,
}

impl Distribution1D {
    /// Builds the distribution; `None` when no weight is positive and finite.
    pub(crate) fn new(weights: &[f64]) -> Option<Self> {
        let clean: Vec<f64> = weights
            .iter()
            .map(|&w| if w.is_finite() && w > 0.0 { w } else { 0.0 })
            .collect();
        let total: f64 = clean.iter().sum();
        if total.is_nan() || total <= 0.0 {
            return None;
        }
        let mut acc = 0.0f64;
        let mut cdf = Vec::with_capacity(clean.len());
        for &w in &clean {
            acc += w;
            cdf.push((acc / total) as f32);
        }
        // Make the last non-zero entry (and everything after it) exactly 1.
        if let Some(last) = clean.iter().rposition(|&w| w > 0.0) {
            for c in &mut cdf[last..] {
                *c = 1.0;
            }
        }
        let pmf = clean.iter().map(|&w| (w / total) as f32).collect();
        Some(Self { cdf, pmf })
    }

    /// Picks an index for `u` in [0, 1) and returns it with its probability (never a zero-weight index).
    pub(crate) fn sample(&self, u: f32) -> (usize, f32) {
        let idx = self
            .cdf
            .partition_point(|&c| c <= u)
            .min(self.cdf.len() - 1);
        // Skip zero-probability entries that share the cdf value.
        let mut i = idx;
        while self.pmf[i] == 0.0 && i + 1 < self.pmf.len() {
            i += 1;
        }
        (i, self.pmf[i])
    }

    /// Probability of index `i` (0 outside the range).
    pub(crate) fn pmf(&self, i: usize) -> f32 {
        self.pmf.get(i).copied().unwrap_or(0.0)
    }
}

#[cfg(test)]
mod tests {
    use std::f64::consts::FRAC_PI_4;

    use glam::Vec2;

    use super::{concentric_disk, sin_cos_quarter};

    #[test]
    fn sin_cos_quarter_matches_f64_to_an_ulp_of_one() {
        let n = 200_000;
        for i in 0..=n {
            let x = (-FRAC_PI_4 + 2.0 * FRAC_PI_4 * f64::from(i) / f64::from(n)) as f32;
            let (sin, cos) = sin_cos_quarter(x);
            let (want_sin, want_cos) = f64::from(x).sin_cos();
            // An ulp of 1 is 1.2e-7; sin(x) for small x is checked relative to itself.
            assert!(
                (f64::from(cos) - want_cos).abs() <= 1.2e-7,
                "cos {x}: {cos} vs {want_cos}"
            );
            assert!(
                (f64::from(sin) - want_sin).abs() <= 1.2e-7 * want_sin.abs().max(1e-30).max(0.1),
                "sin {x}: {sin} vs {want_sin}"
            );
        }
    }

    /// The textbook form with libm's trigonometry, which `concentric_disk` must match to
    /// rounding.
    fn reference(u: Vec2) -> Vec2 {
        let o = 2.0 * u.as_dvec2() - glam::DVec2::ONE;
        if o.x == 0.0 && o.y == 0.0 {
            return Vec2::ZERO;
        }
        let (r, theta) = if o.x.abs() > o.y.abs() {
            (o.x, FRAC_PI_4 * (o.y / o.x))
        } else {
            (o.y, 2.0 * FRAC_PI_4 - FRAC_PI_4 * (o.x / o.y))
        };
        (r * glam::DVec2::new(theta.cos(), theta.sin())).as_vec2()
    }

    #[test]
    fn concentric_disk_matches_the_textbook_mapping() {
        let n = 400;
        for i in 0..=n {
            for j in 0..=n {
                let u = Vec2::new(i as f32 / n as f32, j as f32 / n as f32);
                let (got, want) = (concentric_disk(u), reference(u));
                assert!((got - want).length() <= 4e-7, "{u}: {got} vs {want}");
                assert!(got.length() <= 1.0 + 2e-7, "{u}: {got}");
            }
        }
        assert_eq!(concentric_disk(Vec2::splat(0.5)), Vec2::ZERO);
    }
}
