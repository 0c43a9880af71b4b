//! Warping functions from the unit square and a discrete distribution.

use std::f32::consts::{FRAC_PI_2, FRAC_PI_4, PI};

use glam::{Vec2, Vec3};

/// Maps the unit square to the unit disc, preserving area (Shirley & Chiu 1997).
pub(crate) fn concentric_disk(u: Vec2) -> Vec2 {
    let o = 2.0 * u - Vec2::ONE;
    if o.x == 0.0 && o.y == 0.0 {
        return Vec2::ZERO;
    }
    let (r, theta) = if o.x.abs() > o.y.abs() {
        (o.x, FRAC_PI_4 * (o.y / o.x))
    } else {
        (o.y, FRAC_PI_2 - FRAC_PI_4 * (o.x / o.y))
    };
    r * Vec2::new(theta.cos(), theta.sin())
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
