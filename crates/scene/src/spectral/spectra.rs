//! Spectra as functions of wavelength: constant, measured (piecewise linear), blackbody, the
//! named CIE illuminants, and the three uplifts of an RGB colour (pbrt-v4's `RGBAlbedoSpectrum`,
//! `RGBUnboundedSpectrum` and `RGBIlluminantSpectrum`).

use std::sync::OnceLock;

use super::SpectrumError;
use super::color::{CIE_Y_INTEGRAL, cie_xyz};
use super::sampled::{SampledSpectrum, SampledWavelengths};
use super::tables::{D65_5NM, ILLUM_A};
use super::uplift::SigmoidPolynomial;

/// A spectrum measured at increasing wavelengths, linear between them and zero outside them.
#[derive(Clone, Debug, PartialEq)]
pub struct PiecewiseLinear {
    lambdas: Vec<f64>,
    values: Vec<f64>,
}

impl PiecewiseLinear {
    /// A measured spectrum from its wavelengths (nm) and values. Refused: lists of different
    /// lengths, fewer than 2 samples, a non-finite wavelength or value, a wavelength ≤ 0, a
    /// negative value, a repeated or decreasing wavelength.
    pub fn new(lambdas: Vec<f64>, values: Vec<f64>) -> Result<Self, SpectrumError> {
        if lambdas.len() != values.len() {
            return Err(SpectrumError::LengthMismatch {
                wavelengths: lambdas.len(),
                values: values.len(),
            });
        }
        if lambdas.len() < 2 {
            return Err(SpectrumError::TooFewSamples {
                count: lambdas.len(),
            });
        }
        for (index, (&wavelength, &value)) in lambdas.iter().zip(&values).enumerate() {
            if !wavelength.is_finite() || !value.is_finite() {
                return Err(SpectrumError::NonFinite {
                    index,
                    wavelength,
                    value,
                });
            }
            if wavelength <= 0.0 {
                return Err(SpectrumError::NonPositiveWavelength { index, wavelength });
            }
            if value < 0.0 {
                return Err(SpectrumError::Negative {
                    index,
                    wavelength,
                    value,
                });
            }
            if index > 0 {
                let previous = lambdas[index - 1];
                if wavelength == previous {
                    return Err(SpectrumError::DuplicateWavelength { index, wavelength });
                }
                if wavelength < previous {
                    return Err(SpectrumError::NotIncreasing {
                        index,
                        wavelength,
                        previous,
                    });
                }
            }
        }
        Ok(Self { lambdas, values })
    }

    /// A built-in table of interleaved (nm, value) pairs, held constant from its ends out to
    /// 359 and 831 nm where it stops short of the sampled range, as pbrt-v4's `FromInterleaved`.
    /// The tables are ours and valid; a malformed one is a bug caught by the tests.
    pub(super) fn from_interleaved(samples: &[f64]) -> Self {
        let mut lambdas: Vec<f64> = samples.iter().step_by(2).copied().collect();
        let mut values: Vec<f64> = samples.iter().skip(1).step_by(2).copied().collect();
        if let (Some(&first), Some(&v)) = (lambdas.first(), values.first())
            && first > 360.0
        {
            lambdas.insert(0, 359.0);
            values.insert(0, v);
        }
        if let (Some(&last), Some(&v)) = (lambdas.last(), values.last())
            && last < 830.0
        {
            lambdas.push(831.0);
            values.push(v);
        }
        Self { lambdas, values }
    }

    /// The wavelengths, nm.
    pub fn lambdas(&self) -> &[f64] {
        &self.lambdas
    }

    /// The values.
    pub fn values(&self) -> &[f64] {
        &self.values
    }

    /// The spectrum at `lambda` nm.
    pub fn eval(&self, lambda: f64) -> f64 {
        let n = self.lambdas.len();
        if n == 0 || !(self.lambdas[0]..=self.lambdas[n - 1]).contains(&lambda) {
            return 0.0;
        }
        let i = self
            .lambdas
            .partition_point(|&l| l <= lambda)
            .clamp(1, n - 1)
            - 1;
        let t = (lambda - self.lambdas[i]) / (self.lambdas[i + 1] - self.lambdas[i]);
        (1.0 - t) * self.values[i] + t * self.values[i + 1]
    }

    /// The same spectrum times `k`.
    pub fn scaled(mut self, k: f64) -> Self {
        for v in &mut self.values {
            *v *= k;
        }
        self
    }

    /// Scaled so that its luminance is 1: Σ S(λ) ȳ(λ) over 360, 361, …, 830 nm equals
    /// [`CIE_Y_INTEGRAL`] (pbrt-v4's normalization of its named illuminants).
    fn normalized(self) -> Self {
        let y: f64 = (360..=830)
            .map(|l| {
                let l = f64::from(l);
                self.eval(l) * cie_xyz(l).y
            })
            .sum();
        self.scaled(CIE_Y_INTEGRAL / y)
    }
}

/// Planck's law: the spectral radiance of a black body at `lambda` nm and `t` kelvin,
/// W / (m² sr m), with the exact SI constants.
fn planck(lambda: f64, t: f64) -> f64 {
    const C: f64 = 299_792_458.0;
    const H: f64 = 6.626_070_15e-34;
    const KB: f64 = 1.380_649e-23;
    let l = lambda * 1e-9;
    2.0 * H * C * C / (l.powi(5) * ((H * C / (l * KB * t)).exp_m1()))
}

/// Wien's displacement constant b, m·K: the radiance of a black body peaks at b / T.
const WIEN: f64 = 2.897_771_955e-3;

/// A black body's emission, normalized to 1 at its peak (pbrt-v4's `BlackbodySpectrum`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Blackbody {
    t: f64,
    normalization: f64,
}

impl Blackbody {
    /// The black body at `t` kelvin, which must be finite and positive.
    pub fn new(t: f64) -> Result<Self, SpectrumError> {
        if !(t.is_finite() && t > 0.0) {
            return Err(SpectrumError::Temperature(t));
        }
        Ok(Self {
            t,
            normalization: 1.0 / planck(WIEN / t * 1e9, t),
        })
    }

    /// Its temperature, K.
    pub fn temperature(&self) -> f64 {
        self.t
    }

    /// Its spectral radiance at the peak, W / (m² sr m): the factor that turns the normalized
    /// emission into Planck's law.
    pub fn peak_radiance(&self) -> f64 {
        1.0 / self.normalization
    }

    /// The normalized emission at `lambda` nm.
    pub fn eval(&self, lambda: f64) -> f64 {
        planck(lambda, self.t) * self.normalization
    }
}

/// The CIE standard illuminants that scenes name.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NamedIlluminant {
    /// Daylight, 6504 K.
    D65,
    /// Incandescent tungsten, 2856 K.
    A,
}

impl NamedIlluminant {
    /// The illuminant of a name as pbrt-v4 (`stdillum-D65`, `stdillum-A`) or plainly (`D65`,
    /// `A`) writes it.
    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "D65" | "stdillum-D65" => Some(Self::D65),
            "A" | "stdillum-A" => Some(Self::A),
            _ => None,
        }
    }

    /// Its relative spectral power, normalized to luminance 1 (Y = 1 in [`Spectrum::to_xyz`]),
    /// as pbrt-v4 normalizes its named illuminants.
    pub fn spectrum(self) -> &'static PiecewiseLinear {
        static D65: OnceLock<PiecewiseLinear> = OnceLock::new();
        static A: OnceLock<PiecewiseLinear> = OnceLock::new();
        match self {
            Self::D65 => D65.get_or_init(|| {
                let lambdas = (0..D65_5NM.len()).map(|i| 360.0 + 5.0 * i as f64).collect();
                PiecewiseLinear {
                    lambdas,
                    values: D65_5NM.to_vec(),
                }
                .normalized()
            }),
            Self::A => A.get_or_init(|| PiecewiseLinear::from_interleaved(&ILLUM_A).normalized()),
        }
    }
}

/// A reflectance uplifted from an RGB colour in [0, 1]³: a sigmoid of a quadratic polynomial,
/// bounded by [0, 1] (pbrt-v4's `RGBAlbedoSpectrum`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RgbAlbedo {
    /// The fitted polynomial.
    pub polynomial: SigmoidPolynomial,
}

impl RgbAlbedo {
    /// The smooth reflectance whose colour under D65 is `rgb` (linear sRGB, each in [0, 1]).
    pub fn new(rgb: [f64; 3]) -> Result<Self, SpectrumError> {
        check_colour(rgb, "a reflectance")?;
        if rgb.iter().any(|&c| c > 1.0) {
            return Err(SpectrumError::Colour {
                rgb,
                what: "a reflectance",
            });
        }
        Ok(Self {
            polynomial: SigmoidPolynomial::fit(rgb)?,
        })
    }

    /// The reflectance at `lambda` nm.
    pub fn eval(&self, lambda: f64) -> f64 {
        self.polynomial.eval(lambda)
    }
}

/// Finite, non-negative channels.
fn check_colour(rgb: [f64; 3], what: &'static str) -> Result<(), SpectrumError> {
    if rgb.iter().all(|c| c.is_finite() && *c >= 0.0) {
        Ok(())
    } else {
        Err(SpectrumError::Colour { rgb, what })
    }
}

/// The scale and normalized colour of an unbounded uplift: the colour over twice its largest
/// channel, whose reflectance fit stays away from the sigmoid's bounds (pbrt-v4).
fn split_scale(rgb: [f64; 3]) -> Result<(f64, SigmoidPolynomial), SpectrumError> {
    let m = rgb[0].max(rgb[1]).max(rgb[2]);
    let scale = 2.0 * m;
    let normalized = if scale > 0.0 {
        rgb.map(|c| c / scale)
    } else {
        [0.0; 3]
    };
    Ok((scale, SigmoidPolynomial::fit(normalized)?))
}

/// An unbounded spectrum (a scale factor, an emission seen as a colour under D65) uplifted from
/// an RGB colour ≥ 0: scale × a bounded uplift (pbrt-v4's `RGBUnboundedSpectrum`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RgbUnbounded {
    /// Twice the largest channel.
    pub scale: f64,
    /// The fit of the colour over `scale`.
    pub polynomial: SigmoidPolynomial,
}

impl RgbUnbounded {
    /// The unbounded spectrum of `rgb` (linear sRGB, each ≥ 0).
    pub fn new(rgb: [f64; 3]) -> Result<Self, SpectrumError> {
        check_colour(rgb, "an unbounded spectrum")?;
        let (scale, polynomial) = split_scale(rgb)?;
        Ok(Self { scale, polynomial })
    }

    /// The value at `lambda` nm.
    pub fn eval(&self, lambda: f64) -> f64 {
        self.scale * self.polynomial.eval(lambda)
    }
}

/// An emission uplifted from an RGB colour ≥ 0: scale × a bounded uplift × D65, so that white
/// (1, 1, 1) emits D65 of luminance 1 (pbrt-v4's `RGBIlluminantSpectrum` in sRGB).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RgbIlluminant {
    /// Twice the largest channel.
    pub scale: f64,
    /// The fit of the colour over `scale`.
    pub polynomial: SigmoidPolynomial,
}

impl RgbIlluminant {
    /// The emission of `rgb` (linear sRGB, each ≥ 0).
    pub fn new(rgb: [f64; 3]) -> Result<Self, SpectrumError> {
        check_colour(rgb, "an emission")?;
        let (scale, polynomial) = split_scale(rgb)?;
        Ok(Self { scale, polynomial })
    }

    /// The emission at `lambda` nm.
    pub fn eval(&self, lambda: f64) -> f64 {
        self.scale * self.polynomial.eval(lambda) * NamedIlluminant::D65.spectrum().eval(lambda)
    }
}

/// Any spectrum a scene can hold.
#[derive(Clone, Debug, PartialEq)]
pub enum Spectrum {
    /// The same value at every wavelength.
    Constant(f64),
    /// Measured.
    PiecewiseLinear(PiecewiseLinear),
    /// A black body, normalized to 1 at its peak.
    Blackbody(Blackbody),
    /// An uplifted reflectance.
    RgbAlbedo(RgbAlbedo),
    /// An uplifted unbounded colour.
    RgbUnbounded(RgbUnbounded),
    /// An uplifted emission.
    RgbIlluminant(RgbIlluminant),
    /// Another spectrum times a factor (a blackbody or a named illuminant at a given
    /// luminance).
    Scaled(f64, Box<Spectrum>),
}

impl Spectrum {
    /// The value at `lambda` nm.
    pub fn eval(&self, lambda: f64) -> f64 {
        match self {
            Self::Constant(c) => *c,
            Self::PiecewiseLinear(s) => s.eval(lambda),
            Self::Blackbody(s) => s.eval(lambda),
            Self::RgbAlbedo(s) => s.eval(lambda),
            Self::RgbUnbounded(s) => s.eval(lambda),
            Self::RgbIlluminant(s) => s.eval(lambda),
            Self::Scaled(k, s) => k * s.eval(lambda),
        }
    }

    /// The values at the sampled wavelengths.
    pub fn sample(&self, wavelengths: &SampledWavelengths) -> SampledSpectrum {
        SampledSpectrum(
            wavelengths
                .lambdas()
                .map(|l| self.eval(f64::from(l)) as f32),
        )
    }

    /// The exact XYZ of the spectrum (as an emission: no illuminant), Σ S(λ) (x̄, ȳ, z̄)(λ) over
    /// 360, 361, …, 830 nm divided by [`CIE_Y_INTEGRAL`] (pbrt-v4's `SpectrumToXYZ`).
    pub fn to_xyz(&self) -> glam::DVec3 {
        (360..=830)
            .map(|l| {
                let l = f64::from(l);
                cie_xyz(l) * self.eval(l)
            })
            .sum::<glam::DVec3>()
            / CIE_Y_INTEGRAL
    }

    /// Its linear sRGB colour as an emission: [`super::xyz_to_srgb`] of [`Spectrum::to_xyz`] (a
    /// spectrum of 1 everywhere has luminance 1; D65 normalized to luminance 1 is white).
    pub fn emission_srgb(&self) -> glam::DVec3 {
        super::xyz_to_srgb(self.to_xyz())
    }

    /// Its linear sRGB colour as a reflectance under D65, normalized as the uplift is (D65 of
    /// luminance 1, trapezoid rule on the 1 nm nodes of 360–830 nm), so that a reflectance of 1
    /// everywhere is white and an uplifted colour comes back as itself.
    pub fn reflectance_srgb(&self) -> glam::DVec3 {
        super::uplift::reflectance_srgb(|l| self.eval(l))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    /// ∫ f(λ) (x̄, ȳ, z̄)(λ) dλ by the midpoint rule at 0.1 nm: a quadrature of its own, not the
    /// code's sums at 1 nm.
    fn xyz_integral(f: impl Fn(f64) -> f64) -> DVec3 {
        let n = 4700;
        let h = 470.0 / f64::from(n);
        (0..n)
            .map(|i| {
                let l = 360.0 + (f64::from(i) + 0.5) * h;
                cie_xyz(l) * f(l)
            })
            .sum::<DVec3>()
            * h
    }

    /// D65 in XYZ, normalized to Y = 1, is (0.9505, 1, 1.089) (the CIE white point of D65,
    /// x = 0.31272, y = 0.32903).
    #[test]
    fn d65_white_point() {
        let xyz = xyz_integral(|l| NamedIlluminant::D65.spectrum().eval(l));
        let w = xyz / xyz.y;
        assert!(
            (w - DVec3::new(0.9505, 1.0, 1.089)).abs().max_element() < 1e-3,
            "{w}"
        );
        // Its normalization gives luminance 1.
        assert!((xyz.y / CIE_Y_INTEGRAL - 1.0).abs() < 1e-3, "{xyz}");
    }

    /// The RGB colour of a spectrum: D65 of luminance 1 is sRGB white as an emission, a
    /// reflectance of 1 is white under D65, an uplifted reflectance comes back as its colour,
    /// and a scaled spectrum scales its colour.
    #[test]
    fn colours_of_emissions_and_reflectances() {
        let d65 = Spectrum::PiecewiseLinear(NamedIlluminant::D65.spectrum().clone());
        let white = d65.emission_srgb();
        assert!((white - DVec3::ONE).abs().max_element() < 2e-3, "{white}");
        let one = Spectrum::Constant(1.0).reflectance_srgb();
        assert!((one - DVec3::ONE).abs().max_element() < 2e-3, "{one}");
        for rgb in [[0.8, 0.3, 0.1], [0.1, 0.5, 0.9], [0.5, 0.5, 0.5]] {
            let s = Spectrum::RgbAlbedo(RgbAlbedo::new(rgb).unwrap());
            let back = s.reflectance_srgb();
            assert!(
                (back - DVec3::from_array(rgb)).abs().max_element() < 0.01,
                "{rgb:?}: {back}"
            );
        }
        let scaled = Spectrum::Scaled(3.0, Box::new(d65.clone())).emission_srgb();
        assert!((scaled - 3.0 * white).abs().max_element() < 1e-9);
    }

    /// Illuminant A is a 2856 K black body: its chromaticity is the CIE's (0.44757, 0.40745),
    /// and Planck's law at 2856 K gives the same.
    #[test]
    fn illuminant_a_is_a_2856_k_black_body() {
        let a = xyz_integral(|l| NamedIlluminant::A.spectrum().eval(l));
        let (x, y) = (a.x / a.element_sum(), a.y / a.element_sum());
        assert!(
            (x - 0.44757).abs() < 2e-4 && (y - 0.40745).abs() < 2e-4,
            "{x} {y}"
        );
        let bb = Blackbody::new(2856.0).unwrap();
        let b = xyz_integral(|l| bb.eval(l));
        let (bx, by) = (b.x / b.element_sum(), b.y / b.element_sum());
        assert!((bx - x).abs() < 5e-4 && (by - y).abs() < 5e-4, "{bx} {by}");
    }

    /// The normalized black body peaks at Wien's λ = 2.8977719e-3 m·K / T, with value 1.
    #[test]
    fn blackbody_peaks_at_wien() {
        for t in [3000.0, 5000.0, 6500.0] {
            let bb = Blackbody::new(t).unwrap();
            // Golden-section search for the maximum over 100–2000 nm.
            let (mut a, mut b) = (100.0_f64, 2000.0_f64);
            let g = (5.0_f64.sqrt() - 1.0) / 2.0;
            while b - a > 1e-6 {
                let (c, d) = (b - g * (b - a), a + g * (b - a));
                if bb.eval(c) > bb.eval(d) {
                    b = d;
                } else {
                    a = c;
                }
            }
            let peak = 0.5 * (a + b);
            let wien = 2.897_771_9e-3 / t * 1e9;
            assert!((peak - wien).abs() < 1e-3, "{t} K: {peak} vs {wien}");
            assert!((bb.eval(peak) - 1.0).abs() < 1e-9);
        }
        assert!(Blackbody::new(0.0).is_err());
        assert!(Blackbody::new(f64::NAN).is_err());
    }

    #[test]
    fn measured_spectra_are_validated() {
        let ok = PiecewiseLinear::new(vec![400.0, 500.0, 600.0], vec![0.0, 1.0, 0.5]).unwrap();
        assert_eq!(ok.eval(450.0), 0.5);
        assert_eq!(ok.eval(600.0), 0.5);
        assert_eq!(ok.eval(399.0), 0.0);
        assert_eq!(ok.eval(601.0), 0.0);
        use SpectrumError as E;
        let err = |l: Vec<f64>, v: Vec<f64>| PiecewiseLinear::new(l, v).unwrap_err();
        assert!(matches!(
            err(vec![400.0], vec![1.0]),
            E::TooFewSamples { count: 1 }
        ));
        assert!(matches!(err(vec![], vec![]), E::TooFewSamples { count: 0 }));
        assert!(matches!(
            err(vec![400.0, 500.0], vec![1.0]),
            E::LengthMismatch {
                wavelengths: 2,
                values: 1
            }
        ));
        assert!(matches!(
            err(vec![400.0, 500.0], vec![1.0, -0.1]),
            E::Negative { index: 1, .. }
        ));
        assert!(matches!(
            err(vec![-400.0, 500.0], vec![1.0, 1.0]),
            E::NonPositiveWavelength { index: 0, .. }
        ));
        assert!(matches!(
            err(vec![400.0, 500.0, 500.0], vec![1.0, 1.0, 1.0]),
            E::DuplicateWavelength { index: 2, .. }
        ));
        assert!(matches!(
            err(vec![400.0, 500.0, 450.0], vec![1.0, 1.0, 1.0]),
            E::NotIncreasing { index: 2, .. }
        ));
        assert!(matches!(
            err(vec![400.0, f64::NAN], vec![1.0, 1.0]),
            E::NonFinite { index: 1, .. }
        ));
        assert!(matches!(
            err(vec![400.0, 500.0], vec![f64::INFINITY, 1.0]),
            E::NonFinite { index: 0, .. }
        ));
    }

    /// Every kind of spectrum evaluates through the enum as it does alone, lane by lane, and the
    /// exact XYZ of a spectrum of 1 everywhere has Y = 1.
    #[test]
    fn the_enum_samples_each_kind() {
        let kinds = [
            Spectrum::Constant(0.25),
            Spectrum::PiecewiseLinear(NamedIlluminant::A.spectrum().clone()),
            Spectrum::Blackbody(Blackbody::new(4000.0).unwrap()),
            Spectrum::RgbAlbedo(RgbAlbedo::new([0.7, 0.2, 0.1]).unwrap()),
            Spectrum::RgbUnbounded(RgbUnbounded::new([2.0, 4.0, 1.0]).unwrap()),
            Spectrum::RgbIlluminant(RgbIlluminant::new([1.0, 0.5, 0.25]).unwrap()),
        ];
        let w = SampledWavelengths::sample_visible(0.42);
        for s in &kinds {
            let sampled = s.sample(&w);
            for i in 0..4 {
                let l = f64::from(w.lambda(i));
                assert!((f64::from(sampled[i]) - s.eval(l)).abs() <= 1e-6 * s.eval(l).max(1.0));
            }
        }
        assert!((kinds[0].eval(612.0) - 0.25).abs() < 1e-15);
        assert!(
            (NamedIlluminant::A.spectrum().eval(560.0) / NamedIlluminant::A.spectrum().eval(300.0)
                - 100.0 / 0.930_483)
                .abs()
                < 1e-6
        );
        let y = Spectrum::Constant(1.0).to_xyz().y;
        assert!((y - 1.0).abs() < 1e-6, "{y}");
        // pbrt's names resolve; others do not.
        assert_eq!(
            NamedIlluminant::from_name("stdillum-D65"),
            Some(NamedIlluminant::D65)
        );
        assert_eq!(NamedIlluminant::from_name("A"), Some(NamedIlluminant::A));
        assert_eq!(NamedIlluminant::from_name("F11"), None);
    }
}
