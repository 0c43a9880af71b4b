//! Hero-wavelength sampling (Wilkie et al. 2014) as pbrt-v4 does it: one wavelength is sampled,
//! three companions follow it at equal spacing (rotated into the range), and a path carries one
//! value per wavelength in a [`SampledSpectrum`].

use std::ops::{Add, AddAssign, Div, Index, IndexMut, Mul, MulAssign, Sub};

/// Shortest wavelength sampled, nm.
pub const LAMBDA_MIN: f32 = 360.0;
/// Longest wavelength sampled, nm.
pub const LAMBDA_MAX: f32 = 830.0;
/// Wavelengths carried by a path: the hero and its companions.
pub const N_LANES: usize = 4;

/// Values of a spectrum at the [`N_LANES`] wavelengths of a [`SampledWavelengths`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SampledSpectrum(pub [f32; N_LANES]);

impl SampledSpectrum {
    /// The same value in every lane.
    pub const fn splat(v: f32) -> Self {
        Self([v; N_LANES])
    }

    /// Every lane zero.
    pub fn is_black(&self) -> bool {
        self.0.iter().all(|&v| v == 0.0)
    }

    /// The largest lane.
    pub fn max_value(&self) -> f32 {
        self.0.iter().copied().fold(f32::NEG_INFINITY, f32::max)
    }

    /// The mean of the lanes.
    pub fn average(&self) -> f32 {
        self.0.iter().sum::<f32>() / N_LANES as f32
    }

    /// Lane-wise `self / d`, 0 where `d` is 0 (pbrt's `SafeDiv`): a terminated companion
    /// wavelength has pdf 0 and must contribute nothing.
    pub fn safe_div(&self, d: &Self) -> Self {
        Self(std::array::from_fn(|i| {
            if d.0[i] == 0.0 {
                0.0
            } else {
                self.0[i] / d.0[i]
            }
        }))
    }

    /// Lane-wise map.
    pub fn map(&self, f: impl Fn(f32) -> f32) -> Self {
        Self(self.0.map(f))
    }
}

impl Index<usize> for SampledSpectrum {
    type Output = f32;
    fn index(&self, i: usize) -> &f32 {
        &self.0[i]
    }
}

impl IndexMut<usize> for SampledSpectrum {
    fn index_mut(&mut self, i: usize) -> &mut f32 {
        &mut self.0[i]
    }
}

/// Lane-wise binary operators, with their assigning forms.
macro_rules! lanewise {
    ($trait:ident, $method:ident, $assign:ident, $assign_method:ident, $op:tt) => {
        impl $trait for SampledSpectrum {
            type Output = Self;
            fn $method(self, rhs: Self) -> Self {
                Self(std::array::from_fn(|i| self.0[i] $op rhs.0[i]))
            }
        }
        impl $trait<f32> for SampledSpectrum {
            type Output = Self;
            fn $method(self, rhs: f32) -> Self {
                Self(self.0.map(|v| v $op rhs))
            }
        }
        impl std::ops::$assign for SampledSpectrum {
            fn $assign_method(&mut self, rhs: Self) {
                *self = *self $op rhs;
            }
        }
    };
}
lanewise!(Add, add, AddAssign, add_assign, +);
lanewise!(Sub, sub, SubAssign, sub_assign, -);
lanewise!(Mul, mul, MulAssign, mul_assign, *);
lanewise!(Div, div, DivAssign, div_assign, /);

impl MulAssign<f32> for SampledSpectrum {
    fn mul_assign(&mut self, rhs: f32) {
        *self = *self * rhs;
    }
}

impl AddAssign<f32> for SampledSpectrum {
    fn add_assign(&mut self, rhs: f32) {
        *self = Self(self.0.map(|v| v + rhs));
    }
}

/// The wavelengths a path carries and the density each was sampled with.
///
/// The hero wavelength is lane 0; lane `i` is the hero moved by `i/N_LANES` of the range and
/// wrapped. Every lane, taken alone, is distributed by the sampler's density, so the estimate of a
/// spectral integral is the mean over lanes of value / pdf.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SampledWavelengths {
    lambda: [f32; N_LANES],
    pdf: [f32; N_LANES],
}

impl SampledWavelengths {
    /// Uniform sampling of [`LAMBDA_MIN`, `LAMBDA_MAX`] from `u` in [0, 1) (pbrt-v4's
    /// `SampleUniform`).
    pub fn sample_uniform(u: f32) -> Self {
        let range = LAMBDA_MAX - LAMBDA_MIN;
        let first = LAMBDA_MIN + u.clamp(0.0, 1.0) * range;
        let delta = range / N_LANES as f32;
        let lambda = std::array::from_fn(|i| {
            let l = first + i as f32 * delta;
            if l > LAMBDA_MAX { l - range } else { l }
        });
        Self {
            lambda,
            pdf: [1.0 / range; N_LANES],
        }
    }

    /// Sampling proportional to pbrt-v4's fit of the visible response,
    /// pdf(λ) ∝ sech²(0.0072 (λ − 538)) on [360, 830] nm, from `u` in [0, 1); the companions
    /// use `u + i/N_LANES` wrapped (pbrt-v4's `SampleVisible`).
    pub fn sample_visible(u: f32) -> Self {
        let mut lambda = [0.0; N_LANES];
        let mut pdf = [0.0; N_LANES];
        for i in 0..N_LANES {
            let mut up = u.clamp(0.0, 1.0) + i as f32 / N_LANES as f32;
            if up > 1.0 {
                up -= 1.0;
            }
            lambda[i] = sample_visible_wavelength(up);
            pdf[i] = visible_wavelength_pdf(lambda[i]);
        }
        Self { lambda, pdf }
    }

    /// The wavelength of lane `i`, nm.
    pub fn lambda(&self, i: usize) -> f32 {
        self.lambda[i]
    }

    /// All wavelengths, nm.
    pub fn lambdas(&self) -> [f32; N_LANES] {
        self.lambda
    }

    /// The densities (per nm) the lanes were sampled with; 0 for a terminated companion.
    pub fn pdf(&self) -> SampledSpectrum {
        SampledSpectrum(self.pdf)
    }

    /// Keeps only the hero wavelength, as a dispersive interface must (its directions differ per
    /// wavelength): the companions get pdf 0 and the hero's pdf is divided by [`N_LANES`], so
    /// that the mean over lanes of value / pdf stays an unbiased estimate.
    pub fn terminate_secondary(&mut self) {
        if self.secondary_terminated() {
            return;
        }
        for p in &mut self.pdf[1..] {
            *p = 0.0;
        }
        self.pdf[0] /= N_LANES as f32;
    }

    /// Whether the companions were terminated.
    pub fn secondary_terminated(&self) -> bool {
        self.pdf[1..].iter().all(|&p| p == 0.0)
    }
}

/// pbrt-v4's density of visible-importance wavelength sampling, per nm (0 outside 360–830 nm),
/// computed in double precision with pbrt-v4's constants.
pub fn visible_wavelength_pdf(lambda: f32) -> f32 {
    if !(LAMBDA_MIN..=LAMBDA_MAX).contains(&lambda) {
        return 0.0;
    }
    let c = (0.0072 * (f64::from(lambda) - 538.0)).cosh();
    (0.003_939_804_2 / (c * c)) as f32
}

/// The inverse of the cumulative distribution of [`visible_wavelength_pdf`]: `u` = 0 gives
/// 360 nm, `u` = 1 gives 830 nm.
pub fn sample_visible_wavelength(u: f32) -> f32 {
    let l = 538.0 - 138.888_889 * (0.856_910_62 - 1.827_501_97 * f64::from(u)).atanh();
    (l as f32).clamp(LAMBDA_MIN, LAMBDA_MAX)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn companions_are_evenly_spaced_and_wrapped() {
        let w = SampledWavelengths::sample_uniform(0.9);
        // 360 + 0.9 · 470 = 783; the others 117.5 nm apart, wrapped into [360, 830].
        let expected = [783.0, 430.5, 548.0, 665.5];
        for (l, e) in w.lambdas().iter().zip(expected) {
            assert!((l - e).abs() < 1e-3, "{l} vs {e}");
        }
        assert!((w.pdf()[0] - 1.0 / 470.0).abs() < 1e-9);
    }

    #[test]
    fn visible_sampler_covers_the_range_and_inverts_its_cdf() {
        assert!((sample_visible_wavelength(0.0) - 360.0).abs() < 0.01);
        assert!((sample_visible_wavelength(1.0) - 830.0).abs() < 0.01);
        // The density integrates to 1 over the range (trapezoid at 0.01 nm).
        let n = 47_000;
        let h = 470.0 / n as f64;
        let total: f64 = (0..=n)
            .map(|i| {
                let w = if i == 0 || i == n { 0.5 } else { 1.0 };
                w * f64::from(visible_wavelength_pdf((360.0 + i as f64 * h) as f32))
            })
            .sum::<f64>()
            * h;
        assert!((total - 1.0).abs() < 1e-4, "{total}");
        // The sampler's cumulative distribution at λ is u: compare with the integral of the pdf.
        for u in [0.1_f32, 0.37, 0.5, 0.81] {
            let l = f64::from(sample_visible_wavelength(u));
            let m = 10_000;
            let h = (l - 360.0) / m as f64;
            let cdf: f64 = (0..m)
                .map(|i| {
                    f64::from(visible_wavelength_pdf(
                        (360.0 + (i as f64 + 0.5) * h) as f32,
                    ))
                })
                .sum::<f64>()
                * h;
            assert!((cdf - f64::from(u)).abs() < 1e-3, "u {u}: cdf {cdf}");
        }
    }

    #[test]
    fn terminating_the_companions_keeps_the_hero_with_a_quarter_pdf() {
        let mut w = SampledWavelengths::sample_visible(0.3);
        let hero_pdf = w.pdf()[0];
        assert!(!w.secondary_terminated());
        w.terminate_secondary();
        assert!(w.secondary_terminated());
        assert_eq!(w.pdf().0[1..], [0.0; 3]);
        assert!((w.pdf()[0] - hero_pdf / 4.0).abs() < 1e-12);
        // Terminating twice changes nothing.
        w.terminate_secondary();
        assert!((w.pdf()[0] - hero_pdf / 4.0).abs() < 1e-12);
        // A value divided by the pdf is zero in the terminated lanes, four times in the hero's.
        let v = SampledSpectrum::splat(2.0).safe_div(&w.pdf());
        assert_eq!(v.0[1..], [0.0; 3]);
        assert!((v[0] - 8.0 / hero_pdf).abs() / v[0] < 1e-6);
    }

    #[test]
    fn arithmetic_is_lane_wise() {
        let a = SampledSpectrum([1.0, 2.0, 3.0, 4.0]);
        let b = SampledSpectrum([2.0, 2.0, 0.5, 8.0]);
        assert_eq!((a + b).0, [3.0, 4.0, 3.5, 12.0]);
        assert_eq!((a - b).0, [-1.0, 0.0, 2.5, -4.0]);
        assert_eq!((a * b).0, [2.0, 4.0, 1.5, 32.0]);
        assert_eq!((a / b).0, [0.5, 1.0, 6.0, 0.5]);
        assert_eq!((a * 2.0).0, [2.0, 4.0, 6.0, 8.0]);
        let mut c = a;
        c *= b;
        c += a;
        assert_eq!(c.0, [3.0, 6.0, 4.5, 36.0]);
        assert_eq!(a.average(), 2.5);
        assert_eq!(a.max_value(), 4.0);
        assert!(SampledSpectrum::splat(0.0).is_black() && !a.is_black());
        let z = SampledSpectrum([1.0, 0.0, 2.0, 0.0]);
        assert_eq!(a.safe_div(&z).0, [1.0, 0.0, 1.5, 0.0]);
    }
}
