//! The spectral foundation: wavelengths sampled by hero-wavelength sampling, spectra and their
//! colours, the uplift of RGB to smooth spectra, dispersive indices of refraction and the complex
//! indices of refraction of conductors.
//!
//! Nothing renders with these yet: they are the tested pieces that spectral transport will use
//! (`docs/spectral.md` says what is done and what is not).
//!
//! - [`SampledWavelengths`] (one hero wavelength and three rotated companions over
//!   [`LAMBDA_MIN`]–[`LAMBDA_MAX`], uniform or visible-importance sampled) and
//!   [`SampledSpectrum`], four lanes of values at those wavelengths (`sampled.rs`).
//! - [`cie_xyz`], [`xyz_to_srgb`], [`SampledSpectrum::to_xyz`]: colour (`color.rs`, with the CIE
//!   tables of `tables.rs`).
//! - [`Spectrum`]: constant, piecewise-linear (validated), blackbody, the named illuminants, and
//!   the uplifted RGB spectra (`spectra.rs`); [`SigmoidPolynomial::fit`] is the uplift (Jakob and
//!   Hanika 2019), [`UpliftCache`] caches it per colour (`uplift.rs`).
//! - [`Ior`]: constant, Sellmeier, Cauchy, tabulated and the named glasses (`dispersion.rs`).
//! - [`Conductor`] and [`fresnel_conductor`]: spectral complex indices of refraction and the exact
//!   unpolarized Fresnel reflectance of a conductor (`conductor.rs`, data in `metals.rs`).
//!
//! Wavelengths are in nanometres throughout.

mod color;
mod conductor;
mod dispersion;
mod metals;
mod sampled;
mod spectra;
pub mod tables;
mod uplift;

pub use color::{CIE_Y_INTEGRAL, SRGB_TO_XYZ, XYZ_TO_SRGB, cie_xyz, srgb_to_xyz, xyz_to_srgb};
pub use conductor::{Conductor, fresnel_conductor};
pub use dispersion::{Cauchy, Ior, Sellmeier};
pub use metals::MITSUBA_RGB_METALS;
pub use sampled::{
    LAMBDA_MAX, LAMBDA_MIN, N_LANES, SampledSpectrum, SampledWavelengths,
    sample_visible_wavelength, visible_wavelength_pdf,
};
pub use spectra::{
    Blackbody, NamedIlluminant, PiecewiseLinear, RgbAlbedo, RgbIlluminant, RgbUnbounded, Spectrum,
};
pub use uplift::{SigmoidPolynomial, UpliftCache};

/// Why a spectrum, an index of refraction or an uplift is refused.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SpectrumError {
    /// A measured spectrum needs at least two samples.
    #[error("a measured spectrum needs at least 2 samples, got {count}")]
    TooFewSamples {
        /// How many samples were given.
        count: usize,
    },
    /// The wavelength and value lists differ in length.
    #[error("{wavelengths} wavelengths but {values} values")]
    LengthMismatch {
        /// Number of wavelengths.
        wavelengths: usize,
        /// Number of values.
        values: usize,
    },
    /// A wavelength or a value is NaN or infinite.
    #[error("sample {index} is not finite (wavelength {wavelength}, value {value})")]
    NonFinite {
        /// Index of the sample.
        index: usize,
        /// Its wavelength, nm.
        wavelength: f64,
        /// Its value.
        value: f64,
    },
    /// A wavelength is zero or negative.
    #[error("sample {index} has a wavelength of {wavelength} nm (it must be positive)")]
    NonPositiveWavelength {
        /// Index of the sample.
        index: usize,
        /// The wavelength, nm.
        wavelength: f64,
    },
    /// A value is negative.
    #[error("sample {index} is negative: {value} at {wavelength} nm")]
    Negative {
        /// Index of the sample.
        index: usize,
        /// Its wavelength, nm.
        wavelength: f64,
        /// Its value.
        value: f64,
    },
    /// Two samples share a wavelength.
    #[error("wavelength {wavelength} nm appears twice (samples {index} and {})", index - 1)]
    DuplicateWavelength {
        /// Index of the second sample.
        index: usize,
        /// The repeated wavelength, nm.
        wavelength: f64,
    },
    /// The wavelengths are not increasing.
    #[error("wavelengths must increase: {wavelength} nm (sample {index}) follows {previous} nm")]
    NotIncreasing {
        /// Index of the sample.
        index: usize,
        /// Its wavelength, nm.
        wavelength: f64,
        /// The wavelength before it, nm.
        previous: f64,
    },
    /// A dispersion law gives an index of refraction below 1, or not finite, in 360–830 nm.
    #[error(
        "index of refraction {ior} at {wavelength} nm (it must be finite and at least 1 over 360-830 nm)"
    )]
    IorOutOfRange {
        /// Where, nm.
        wavelength: f64,
        /// The index of refraction there.
        ior: f64,
    },
    /// A coefficient is NaN or infinite.
    #[error("coefficient {name} is not finite: {value}")]
    NonFiniteCoefficient {
        /// Its name.
        name: &'static str,
        /// Its value.
        value: f64,
    },
    /// A blackbody's temperature is not a finite positive number.
    #[error("blackbody temperature must be finite and positive, got {0} K")]
    Temperature(f64),
    /// An RGB colour with a negative or non-finite channel, or a reflectance above 1.
    #[error("colour ({}, {}, {}) cannot be uplifted as {what}", rgb[0], rgb[1], rgb[2])]
    Colour {
        /// The colour.
        rgb: [f64; 3],
        /// What it was meant to be (a reflectance, an emission, …).
        what: &'static str,
    },
    /// The Gauss–Newton fit of the uplift did not converge.
    #[error("no smooth spectrum found for colour ({}, {}, {})", rgb[0], rgb[1], rgb[2])]
    NoFit {
        /// The colour.
        rgb: [f64; 3],
    },
}
