//! RGB to spectrum by Jakob and Hanika 2019, "A Low-Dimensional Function Space for Efficient
//! Spectral Upsampling": a reflectance is s(p(x)) with p a quadratic polynomial of the normalized
//! wavelength x = (λ − 360) / 470 and s(y) = ½ + y / (2 √(1 + y²)) a sigmoid, so it is smooth and
//! bounded by (0, 1). The three coefficients are those whose colour under D65 is the given RGB,
//! found by Gauss–Newton on the difference in CIELAB (a port of `rgb2spec_opt`, pbrt-v4's
//! `src/pbrt/cmd/rgb2spec_opt.cpp`).
//!
//! The fit is per colour, and [`UpliftCache`] keeps each colour's coefficients. `rgb2spec_opt`
//! instead fits a 3 × 64³ table offline and interpolates it; fitting that table at first use
//! would take about a minute on one core (786 432 warm-started fits), and a table coarse enough
//! to build in a second (16³) would add an interpolation error that has not been measured. A fit
//! walks from the grey of the colour's mean, whose coefficients are exact, to the colour in
//! `STEPS` steps, each a few Gauss–Newton iterations warm-started from the previous one: about
//! a millisecond per colour, nothing for a scene's few constant colours (`docs/spectral.md` has the measurements). Textures will need a table; that
//! belongs to the transport change.

use std::collections::HashMap;
use std::sync::{Mutex, OnceLock};

use glam::{DMat3, DVec3};

use super::SpectrumError;
use super::color::{SRGB_TO_XYZ, XYZ_TO_SRGB, cie_xyz, lerp_table};
use super::tables::D65_5NM;

/// The sigmoid of Jakob and Hanika: ½ + y / (2 √(1 + y²)), with its limits 0 and 1 at ∓∞.
fn sigmoid(y: f64) -> f64 {
    if y.is_infinite() {
        return if y > 0.0 { 1.0 } else { 0.0 };
    }
    0.5 + y / (2.0 * (1.0 + y * y).sqrt())
}

/// A smooth spectrum in [0, 1]: s(c₀ x² + c₁ x + c₂) with x = (λ − 360) / 470.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SigmoidPolynomial {
    /// The coefficients of x², x and 1.
    pub c: [f64; 3],
}

/// Steps of the walk from grey to the colour.
const STEPS: usize = 16;
/// Gauss–Newton iterations allowed per step, and at the end.
const ITERATIONS: usize = 12;
const FINAL_ITERATIONS: usize = 60;
/// Squared CIELAB residual at which a step has converged, and at which the fit is done.
const STEP_TOLERANCE: f64 = 1e-8;
const FINAL_TOLERANCE: f64 = 1e-16;
/// Central-difference step of the Jacobian (`rgb2spec_opt`'s `RGB2SPEC_EPSILON`).
const EPSILON: f64 = 1e-4;

impl SigmoidPolynomial {
    /// The value at `lambda` nm.
    pub fn eval(&self, lambda: f64) -> f64 {
        let x = (lambda - 360.0) / 470.0;
        sigmoid((self.c[0] * x + self.c[1]) * x + self.c[2])
    }

    /// The spectrum whose colour under D65 is `rgb` (linear sRGB, each channel in [0, 1]).
    ///
    /// A grey is exact and flat: c₀ = c₁ = 0 and s(c₂) = the grey (pbrt-v4's special case),
    /// so 0.8 gives 0.8 at every wavelength. A colour that no smooth reflectance reaches (a
    /// channel at 0 or 1 with the others apart) gets the closest spectrum Gauss–Newton finds,
    /// as in `rgb2spec_opt`.
    pub fn fit(rgb: [f64; 3]) -> Result<Self, SpectrumError> {
        if rgb
            .iter()
            .any(|c| !c.is_finite() || !(0.0..=1.0).contains(c))
        {
            return Err(SpectrumError::Colour {
                rgb,
                what: "a reflectance",
            });
        }
        if rgb[0] == rgb[1] && rgb[1] == rgb[2] {
            let v = rgb[0];
            // (v − ½) / √(v (1 − v)) inverts the sigmoid; ±∞ at 0 and 1.
            let c2 = if v <= 0.0 {
                f64::NEG_INFINITY
            } else if v >= 1.0 {
                f64::INFINITY
            } else {
                (v - 0.5) / (v * (1.0 - v)).sqrt()
            };
            return Ok(Self { c: [0.0, 0.0, c2] });
        }
        let tables = FitTables::get();
        let target = DVec3::from_array(rgb);
        // Start from the grey of the colour's mean, kept inside (0, 1).
        let grey = (target.element_sum() / 3.0).clamp(0.01, 0.99);
        let mut c = DVec3::new(0.0, 0.0, (grey - 0.5) / (grey * (1.0 - grey)).sqrt());
        for step in 1..=STEPS {
            let t = step as f64 / STEPS as f64;
            let goal = DVec3::splat(grey).lerp(target, t);
            let (iterations, tolerance) = if step == STEPS {
                (FINAL_ITERATIONS, FINAL_TOLERANCE)
            } else {
                (ITERATIONS, STEP_TOLERANCE)
            };
            c = tables.gauss_newton(goal, c, iterations, tolerance);
        }
        if c.is_finite() {
            Ok(Self { c: c.to_array() })
        } else {
            Err(SpectrumError::NoFit { rgb })
        }
    }
}

/// The linear sRGB colour under D65 of the reflectance `f` (of wavelength in nm), integrated
/// as the fit integrates its spectra.
pub(super) fn reflectance_srgb(f: impl Fn(f64) -> f64) -> DVec3 {
    FitTables::get()
        .rgb
        .iter()
        .enumerate()
        .map(|(i, &rgb)| rgb * f(360.0 + i as f64))
        .sum()
}

/// What the fit integrates against, computed once: for each wavelength node of 360, 361, …,
/// 830 nm, the sRGB of the colour-matching functions times D65 (normalized to luminance 1)
/// times the node's trapezoid weight, and D65's XYZ, the white of CIELAB.
struct FitTables {
    rgb: Vec<DVec3>,
    white: DVec3,
}

impl FitTables {
    fn get() -> &'static Self {
        static TABLES: OnceLock<FitTables> = OnceLock::new();
        TABLES.get_or_init(|| {
            let to_rgb = DMat3::from_cols_array_2d(&XYZ_TO_SRGB).transpose();
            let nodes: Vec<(f64, f64)> = (360..=830)
                .map(|l| {
                    let w = if l == 360 || l == 830 { 0.5 } else { 1.0 };
                    (f64::from(l), w)
                })
                .collect();
            let d65 = |l: f64| lerp_table(&D65_5NM, 360.0, 5.0, l);
            let y: f64 = nodes.iter().map(|&(l, w)| w * cie_xyz(l).y * d65(l)).sum();
            let weighted: Vec<DVec3> = nodes
                .iter()
                .map(|&(l, w)| cie_xyz(l) * (w * d65(l) / y))
                .collect();
            Self {
                rgb: weighted.iter().map(|&xyz| to_rgb * xyz).collect(),
                white: weighted.iter().sum(),
            }
        })
    }

    /// The colour under D65 of the sigmoid polynomial `c`.
    fn colour(&self, c: DVec3) -> DVec3 {
        let n = (self.rgb.len() - 1) as f64;
        self.rgb
            .iter()
            .enumerate()
            .map(|(i, &rgb)| {
                let x = i as f64 / n;
                rgb * sigmoid((c.x * x + c.y) * x + c.z)
            })
            .sum()
    }

    /// CIELAB of a linear sRGB colour, relative to D65.
    fn lab(&self, rgb: DVec3) -> DVec3 {
        let xyz = DMat3::from_cols_array_2d(&SRGB_TO_XYZ).transpose() * rgb / self.white;
        let f = |t: f64| {
            const DELTA: f64 = 6.0 / 29.0;
            if t > DELTA * DELTA * DELTA {
                t.cbrt()
            } else {
                t / (3.0 * DELTA * DELTA) + 4.0 / 29.0
            }
        };
        let (fx, fy, fz) = (f(xyz.x), f(xyz.y), f(xyz.z));
        DVec3::new(116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz))
    }

    /// Gauss–Newton from `c` towards the colour `rgb`, as `rgb2spec_opt`'s `gauss_newton`
    /// (central-difference Jacobian, coefficients scaled back when the largest exceeds 200).
    fn gauss_newton(&self, rgb: DVec3, mut c: DVec3, iterations: usize, tolerance: f64) -> DVec3 {
        let goal = self.lab(rgb);
        let residual = |c: DVec3| goal - self.lab(self.colour(c));
        for _ in 0..iterations {
            let r = residual(c);
            if r.length_squared() < tolerance {
                break;
            }
            let mut jacobian = DMat3::ZERO;
            for k in 0..3 {
                let mut e = DVec3::ZERO;
                e[k] = EPSILON;
                let column = (residual(c + e) - residual(c - e)) / (2.0 * EPSILON);
                *jacobian.col_mut(k) = column;
            }
            if jacobian.determinant().abs() < 1e-15 {
                break;
            }
            let next = c - jacobian.inverse() * r;
            if !next.is_finite() {
                break;
            }
            c = next;
            let max = c.max_element();
            if max > 200.0 {
                c *= 200.0 / max;
            }
        }
        c
    }
}

/// The uplift's coefficients per colour, each fitted once.
#[derive(Debug, Default)]
pub struct UpliftCache {
    fits: Mutex<HashMap<[u64; 3], SigmoidPolynomial>>,
}

impl UpliftCache {
    /// An empty cache.
    pub fn new() -> Self {
        Self::default()
    }

    /// [`SigmoidPolynomial::fit`] of `rgb`, fitted on its first request.
    pub fn fit(&self, rgb: [f64; 3]) -> Result<SigmoidPolynomial, SpectrumError> {
        let key = rgb.map(f64::to_bits);
        // A poisoned lock still holds valid fits: every entry is inserted whole.
        if let Some(fit) = self
            .fits
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
            .get(&key)
        {
            return Ok(*fit);
        }
        let fit = SigmoidPolynomial::fit(rgb)?;
        self.fits
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
            .insert(key, fit);
        Ok(fit)
    }

    /// How many colours it holds.
    pub fn len(&self) -> usize {
        self.fits
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
            .len()
    }

    /// Whether it holds no colour.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

#[cfg(test)]
mod tests;
