//! Spectra to linear Rec.709 RGB, as Mitsuba 3 does in its RGB variants, and the RGB
//! complex indices of refraction of Mitsuba's named conductors.
//!
//! [`spectrum_to_rgb`] follows `spectrum_list_to_srgb` (Mitsuba 3, `src/core/spectrum.cpp`):
//! the piecewise-linear spectrum is sampled at 1000 wavelengths evenly spread over
//! [360, 830] nm (zero outside its own range), weighted by the CIE 1931 2° colour-matching
//! functions (and by the D65 illuminant for everything but emission), scaled by 1/106.75 (the
//! integral of ȳ), and converted from XYZ to linear sRGB. Reflectances are clamped to [0, 1],
//! emission and indices of refraction only to ≥ 0. (Mitsuba's *named* conductors are read
//! from files without the D65 weighting; `scene::spectral::MITSUBA_RGB_METALS` holds what it loads
//! for them.) The colour-matching functions are the CIE 1931 tables at 5 nm as Mitsuba stores them
//! and D65 at 5 nm, both read from `scene::spectral::tables`, where the spectral runtime's tables
//! live too; the XYZ to sRGB matrix is `scene::spectral::XYZ_TO_SRGB`.

use glam::DVec3;

use scene::Rgb;
use scene::spectral::tables::{
    D65_5NM as D65, MITSUBA_CIE_X as CIE_X, MITSUBA_CIE_Y as CIE_Y, MITSUBA_CIE_Z as CIE_Z,
};
use scene::spectral::{MITSUBA_RGB_METALS, XYZ_TO_SRGB};

/// First wavelength of the tables, nm.
const CIE_MIN: f64 = 360.0;
/// Last wavelength of the tables, nm.
const CIE_MAX: f64 = 830.0;
/// Integral of ȳ over [360, 830] nm (Mitsuba's `MI_CIE_Y_NORMALIZATION` is its inverse).
const CIE_Y_INTEGRAL: f64 = 106.750_259_399_414_06;
/// Mitsuba's `MI_CIE_D65_NORMALIZATION` is the inverse of this.
const D65_NORMALIZATION: f64 = 98.997_417_518_762_55;

/// What a spectrum describes: it decides the D65 weighting and the clamping.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum SpectrumUse {
    /// A reflectance (weighted by D65, clamped to [0, 1]).
    Reflectance,
    /// Emitted radiance or intensity (not weighted, clamped to ≥ 0).
    Emission,
    /// A real or imaginary index of refraction given as a spectrum. Mitsuba weights it by D65
    /// like any non-emitter property, but does not clamp it to 1 (clamped to ≥ 0).
    Ior,
}

/// Linear interpolation in a 95-entry table at wavelength `w` (zero outside [360, 830]).
fn table(t: &[f64; 95], w: f64) -> f64 {
    if !(CIE_MIN..=CIE_MAX).contains(&w) {
        return 0.0;
    }
    let x = (w - CIE_MIN) * 94.0 / (CIE_MAX - CIE_MIN);
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    let i0 = (x as usize).min(93);
    let f = x - i0 as f64;
    (1.0 - f) * t[i0] + f * t[i0 + 1]
}

/// XYZ to linear sRGB (Rec.709 primaries, D65 white), Mitsuba's `xyz_to_srgb`.
/// Written out row by row (not through glam's matrix product) so that the sums run in the order
/// they always have.
pub(crate) fn xyz_to_srgb(xyz: DVec3) -> DVec3 {
    let row = |r: [f64; 3]| r[0] * xyz.x + r[1] * xyz.y + r[2] * xyz.z;
    DVec3::new(
        row(XYZ_TO_SRGB[0]),
        row(XYZ_TO_SRGB[1]),
        row(XYZ_TO_SRGB[2]),
    )
}

/// A piecewise-linear spectrum (wavelengths in nm, increasing) as linear Rec.709 RGB.
/// `None` if the lists are empty, of different lengths, not increasing or not finite.
pub(crate) fn spectrum_to_rgb(
    wavelengths: &[f64],
    values: &[f64],
    usage: SpectrumUse,
) -> Option<Rgb> {
    if wavelengths.is_empty()
        || wavelengths.len() != values.len()
        || wavelengths.windows(2).any(|w| w[1] <= w[0])
        || wavelengths.iter().chain(values).any(|v| !v.is_finite())
    {
        return None;
    }
    if wavelengths.len() == 1 {
        // A single sample is a constant spectrum.
        return Some(constant_spectrum_to_rgb(values[0], usage));
    }
    const STEPS: usize = 1000;
    let mut xyz = DVec3::ZERO;
    let (first, last) = (wavelengths[0], wavelengths[wavelengths.len() - 1]);
    for i in 0..STEPS {
        let w = CIE_MIN + (i as f64 / (STEPS - 1) as f64) * (CIE_MAX - CIE_MIN);
        if w < first || w > last {
            continue;
        }
        let j = wavelengths
            .partition_point(|&x| x <= w)
            .clamp(1, wavelengths.len() - 1)
            - 1;
        let (w0, w1, v0, v1) = (wavelengths[j], wavelengths[j + 1], values[j], values[j + 1]);
        let v = ((w - w1) * v0 + (w0 - w) * v1) / (w0 - w1);
        let d65 = if usage != SpectrumUse::Emission {
            table(&D65, w) / D65_NORMALIZATION
        } else {
            1.0
        };
        xyz += DVec3::new(table(&CIE_X, w), table(&CIE_Y, w), table(&CIE_Z, w)) * v * d65;
    }
    xyz *= (CIE_MAX - CIE_MIN) / CIE_Y_INTEGRAL / STEPS as f64;
    let rgb = xyz_to_srgb(xyz).max(DVec3::ZERO);
    let rgb = if usage == SpectrumUse::Reflectance {
        rgb.min(DVec3::ONE)
    } else {
        rgb
    };
    Some(rgb.as_vec3())
}

/// A constant spectrum of value `v`. Mitsuba's RGB variants give a constant *emission* the
/// colour of an equal-energy white in sRGB (`v · xyz_to_srgb(1, 1, 1)`, slightly purple), so
/// that they match its spectral variants; a constant reflectance or ior stays grey.
pub(crate) fn constant_spectrum_to_rgb(v: f64, usage: SpectrumUse) -> Rgb {
    match usage {
        SpectrumUse::Emission => (xyz_to_srgb(DVec3::ONE) * v).as_vec3(),
        SpectrumUse::Reflectance | SpectrumUse::Ior => Rgb::splat(v as f32),
    }
}

/// Reflectance of a smooth dielectric interface at normal incidence: ((η − 1) / (η + 1))².
pub(crate) fn dielectric_reflectance(eta: f32) -> f32 {
    let r = (eta - 1.0) / (eta + 1.0);
    r * r
}

/// η and k of a named conductor (Mitsuba names, e.g. `Au`, `Cu`, `Al`), if known.
pub(crate) fn metal(name: &str) -> Option<(Rgb, Rgb)> {
    MITSUBA_RGB_METALS
        .iter()
        .find(|(n, _, _)| *n == name)
        .map(|(_, eta, k)| (Rgb::from_array(*eta), Rgb::from_array(*k)))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Mitsuba 3.9.1 (`scalar_rgb`) loads the shared spectral Cornell box's red wall
    /// reflectance and light radiance as these RGB values (read with `mi.traverse`).
    #[test]
    fn matches_mitsuba_rgb_mode() {
        let red_w: Vec<f64> = (0..76).map(|i| 400.0 + 4.0 * f64::from(i)).collect();
        let red_v = [
            0.04, 0.046, 0.048, 0.053, 0.049, 0.05, 0.053, 0.055, 0.057, 0.056, 0.059, 0.057,
            0.061, 0.061, 0.06, 0.062, 0.062, 0.062, 0.061, 0.062, 0.06, 0.059, 0.057, 0.058,
            0.058, 0.058, 0.056, 0.055, 0.056, 0.059, 0.057, 0.055, 0.059, 0.059, 0.058, 0.059,
            0.061, 0.061, 0.063, 0.063, 0.067, 0.068, 0.072, 0.08, 0.09, 0.099, 0.124, 0.154,
            0.192, 0.255, 0.287, 0.349, 0.402, 0.443, 0.487, 0.513, 0.558, 0.584, 0.62, 0.606,
            0.609, 0.651, 0.612, 0.61, 0.65, 0.638, 0.627, 0.62, 0.63, 0.628, 0.642, 0.639, 0.657,
            0.639, 0.635, 0.642,
        ];
        let red = spectrum_to_rgb(&red_w, &red_v, SpectrumUse::Reflectance).unwrap();
        let mitsuba = Rgb::new(0.49132, 0.049_228_1, 0.050_921_9);
        assert!(
            (red - mitsuba).abs().max_element() < 1e-4,
            "{red} vs {mitsuba}"
        );
        let light = spectrum_to_rgb(
            &[400.0, 500.0, 600.0, 700.0],
            &[0.0, 8.0, 15.6, 18.4],
            SpectrumUse::Emission,
        )
        .unwrap();
        let mitsuba = Rgb::new(20.7108, 10.8546, 2.77115);
        assert!(
            (light - mitsuba).abs().max_element() < 1e-3,
            "{light} vs {mitsuba}"
        );
    }

    #[test]
    fn conductor_reflectance_is_fresnel_at_normal_incidence() {
        assert!((dielectric_reflectance(1.5) - 0.04).abs() < 1e-6);
        // Gold is reddish-yellow: red above blue.
        let (eta, k) = metal("Au").unwrap();
        let gold = scene::MaterialKind::Conductor(scene::Conductor {
            eta,
            k,
            specular_reflectance: Rgb::ONE,
            roughness: 0.0,
        })
        .albedo();
        assert!(gold.x > 0.9 && gold.z < 0.7, "{gold}");
    }
}
