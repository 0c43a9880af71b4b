//! Colour: the CIE 1931 colour-matching functions at any wavelength, XYZ ↔ linear sRGB, and the
//! Monte Carlo estimate of XYZ from a [`SampledSpectrum`].

use glam::{DMat3, DVec3};

use super::sampled::{SampledSpectrum, SampledWavelengths};
use super::tables::{CIE_X, CIE_Y, CIE_Z};

/// pbrt-v4's `CIE_Y_integral`: the integral of ȳ over its 1 nm table, nm. XYZ is
/// ∫ S(λ) (x̄, ȳ, z̄)(λ) dλ divided by it, so that a spectrum of 1 at every wavelength has Y = 1.
pub const CIE_Y_INTEGRAL: f64 = 106.856_895;

/// XYZ to linear sRGB (Rec.709 primaries, D65 white), rows as written: the matrix of
/// `rgb2spec_opt` and Mitsuba 3 (`xyz_to_srgb`).
pub const XYZ_TO_SRGB: [[f64; 3]; 3] = [
    [3.240_479, -1.537_150, -0.498_535],
    [-0.969_256, 1.875_991, 0.041_556],
    [0.055_648, -0.204_043, 1.057_311],
];

/// Linear sRGB to XYZ, rows as written (`rgb2spec_opt`'s `srgb_to_xyz`).
pub const SRGB_TO_XYZ: [[f64; 3]; 3] = [
    [0.412_453, 0.357_580, 0.180_423],
    [0.212_671, 0.715_160, 0.072_169],
    [0.019_334, 0.119_193, 0.950_227],
];

/// A row-major 3×3 table as a glam matrix (glam stores columns).
fn matrix(rows: &[[f64; 3]; 3]) -> DMat3 {
    DMat3::from_cols_array_2d(rows).transpose()
}

/// XYZ to linear sRGB with [`XYZ_TO_SRGB`].
pub fn xyz_to_srgb(xyz: DVec3) -> DVec3 {
    matrix(&XYZ_TO_SRGB) * xyz
}

/// Linear sRGB to XYZ with [`SRGB_TO_XYZ`].
pub fn srgb_to_xyz(rgb: DVec3) -> DVec3 {
    matrix(&SRGB_TO_XYZ) * rgb
}

/// Linear interpolation in a table sampled every `step` nm from `first` nm; 0 outside it.
pub(super) fn lerp_table(table: &[f64], first: f64, step: f64, lambda: f64) -> f64 {
    let x = (lambda - first) / step;
    let last = (table.len() - 1) as f64;
    if !(0.0..=last).contains(&x) {
        return 0.0;
    }
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    let i = (x as usize).min(table.len() - 2);
    let f = x - i as f64;
    (1.0 - f) * table[i] + f * table[i + 1]
}

/// The CIE 1931 2° colour-matching functions (x̄, ȳ, z̄) at `lambda` nm, linear between the
/// 1 nm samples; zero outside 360–830 nm.
pub fn cie_xyz(lambda: f64) -> DVec3 {
    DVec3::new(
        lerp_table(&CIE_X, 360.0, 1.0, lambda),
        lerp_table(&CIE_Y, 360.0, 1.0, lambda),
        lerp_table(&CIE_Z, 360.0, 1.0, lambda),
    )
}

impl SampledSpectrum {
    /// The estimate of the XYZ of the spectrum these lanes sample: the mean over lanes of
    /// S(λᵢ) (x̄, ȳ, z̄)(λᵢ) / pdf(λᵢ), divided by [`CIE_Y_INTEGRAL`] (pbrt-v4's
    /// `SampledSpectrum::ToXYZ`). Lanes of pdf 0 (terminated companions) contribute nothing.
    /// Its expectation is the exact XYZ, whichever sampler drew the wavelengths; a film
    /// accumulates it.
    pub fn to_xyz(&self, wavelengths: &SampledWavelengths) -> DVec3 {
        let pdf = wavelengths.pdf();
        let mut xyz = DVec3::ZERO;
        for i in 0..self.0.len() {
            if pdf[i] > 0.0 {
                let w = f64::from(self[i]) / f64::from(pdf[i]);
                xyz += cie_xyz(f64::from(wavelengths.lambda(i))) * w;
            }
        }
        xyz / (self.0.len() as f64 * CIE_Y_INTEGRAL)
    }
}

#[cfg(test)]
mod tests {
    use super::super::tables::{MITSUBA_CIE_X, MITSUBA_CIE_Y, MITSUBA_CIE_Z};
    use super::*;

    /// The integral of ȳ over the 1 nm table is pbrt-v4's normalization, 106.856895 nm.
    #[test]
    fn y_bar_integrates_to_the_cie_normalization() {
        // The table's own sum (pbrt's rectangle rule at 1 nm) and the trapezoid rule (the exact
        // integral of the linear interpolation) agree to the end samples' halves.
        let sum: f64 = CIE_Y.iter().sum();
        let trapezoid = sum - 0.5 * (CIE_Y[0] + CIE_Y[CIE_Y.len() - 1]);
        for v in [sum, trapezoid] {
            assert!((v / 106.856_895 - 1.0).abs() < 1e-3, "{v}");
        }
        assert!((sum - CIE_Y_INTEGRAL).abs() < 1e-4, "{sum}");
    }

    /// pbrt-v4's 1 nm table and Mitsuba 3's 5 nm table come from the same CIE data: at every
    /// 5 nm the two agree to single precision.
    #[test]
    fn the_two_cie_tables_agree() {
        for (fine, coarse) in [
            (&CIE_X, &MITSUBA_CIE_X),
            (&CIE_Y, &MITSUBA_CIE_Y),
            (&CIE_Z, &MITSUBA_CIE_Z),
        ] {
            for (i, &c) in coarse.iter().enumerate() {
                let f = fine[5 * i];
                assert!((f - c).abs() <= 1e-6 * f.abs().max(1e-3), "{i}: {f} vs {c}");
            }
        }
    }

    #[test]
    fn srgb_matrices_are_inverse_and_map_white_to_d65() {
        let m = matrix(&XYZ_TO_SRGB) * matrix(&SRGB_TO_XYZ);
        assert!(m.abs_diff_eq(DMat3::IDENTITY, 1e-5), "{m}");
        // The D65 white point (x, y) = (0.3127, 0.3290) of IEC 61966-2-1, at Y = 1.
        let white = srgb_to_xyz(DVec3::ONE);
        let (x, y) = (0.3127, 0.3290);
        let d65 = DVec3::new(x / y, 1.0, (1.0 - x - y) / y);
        assert!((white - d65).abs().max_element() < 1e-3, "{white} vs {d65}");
    }

    /// A SplitMix64 stream of uniform numbers in [0, 1): test randomness of its own.
    fn uniforms(seed: u64) -> impl Iterator<Item = f32> {
        let mut state = seed;
        std::iter::repeat_with(move || {
            state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = state;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            z ^= z >> 31;
            ((z >> 40) as f32) / (1u64 << 24) as f32
        })
    }

    /// The estimate of the XYZ of a constant spectrum of 1 through sampled wavelengths is
    /// unbiased with both samplers, with terminated companions too: its mean over many samples
    /// is the exact integral of the colour-matching functions (their trapezoid sum: the
    /// functions are linear between the 1 nm samples) within four standard errors.
    #[test]
    fn xyz_estimates_are_unbiased() {
        let trapezoid = |t: &[f64]| t.iter().sum::<f64>() - 0.5 * (t[0] + t[t.len() - 1]);
        let exact =
            DVec3::new(trapezoid(&CIE_X), trapezoid(&CIE_Y), trapezoid(&CIE_Z)) / CIE_Y_INTEGRAL;
        let one = SampledSpectrum::splat(1.0);
        type Sampler = fn(f32) -> SampledWavelengths;
        let samplers: [(&str, Sampler, bool); 4] = [
            ("uniform", SampledWavelengths::sample_uniform, false),
            ("visible", SampledWavelengths::sample_visible, false),
            (
                "uniform, hero only",
                SampledWavelengths::sample_uniform,
                true,
            ),
            (
                "visible, hero only",
                SampledWavelengths::sample_visible,
                true,
            ),
        ];
        for (name, sample, terminate) in samplers {
            let n = 200_000;
            let (mut sum, mut sum2) = (DVec3::ZERO, DVec3::ZERO);
            for u in uniforms(7).take(n) {
                let mut w = sample(u);
                if terminate {
                    w.terminate_secondary();
                }
                let xyz = one.to_xyz(&w);
                sum += xyz;
                sum2 += xyz * xyz;
            }
            let mean = sum / n as f64;
            let error = ((sum2 / n as f64 - mean * mean) / n as f64).sqrt();
            for c in 0..3 {
                assert!(
                    (mean[c] - exact[c]).abs() < 4.0 * error[c] + 1e-6,
                    "{name}, channel {c}: {} vs {} (standard error {})",
                    mean[c],
                    exact[c],
                    error[c]
                );
            }
            // And the estimate is useful: within 1 % of the exact value.
            assert!(
                ((mean - exact) / exact).abs().max_element() < 1e-2,
                "{name}: {mean}"
            );
        }
    }
}
