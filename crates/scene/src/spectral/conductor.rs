//! Conductors: spectral complex indices of refraction η + i k and the exact unpolarized
//! Fresnel reflectance at a conductor.

use num_complex::Complex64;

use super::SpectrumError;
use super::metals::{
    AG_ETA, AG_K, AL_ETA, AL_K, AU_ETA, AU_K, CU_ETA, CU_K, CUZN_ETA, CUZN_K, MGO_ETA, MGO_K,
    TIO2_ETA, TIO2_K,
};
use super::sampled::{SampledSpectrum, SampledWavelengths};
use super::spectra::{PiecewiseLinear, Spectrum};

/// The unpolarized Fresnel reflectance of a smooth interface into a medium of complex index
/// of refraction `eta` + i `k` (relative to the side the light comes from), at `cos_theta` of
/// the incident direction to the normal: the mean of |r∥|² and |r⊥|², with the complex
/// refracted cosine (pbrt-v4's `FrComplex`). With `k` = 0 it is the dielectric's, total internal
/// reflection included. `eta` must be positive (as [`Conductor::new`] and the named metals
/// guarantee) and `k` non-negative.
pub fn fresnel_conductor(cos_theta: f64, eta: f64, k: f64) -> f64 {
    let cos_i = cos_theta.clamp(0.0, 1.0);
    if cos_i == 0.0 {
        // Grazing: both polarizations reflect entirely.
        return 1.0;
    }
    let eta = Complex64::new(eta, k);
    let sin2_i = 1.0 - cos_i * cos_i;
    let sin2_t = sin2_i / (eta * eta);
    let cos_t = (1.0 - sin2_t).sqrt();
    let r_parallel = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let r_perpendicular = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    0.5 * (r_parallel.norm_sqr() + r_perpendicular.norm_sqr())
}

/// A conductor's complex index of refraction as a function of wavelength.
#[derive(Clone, Debug, PartialEq)]
pub struct Conductor {
    eta: PiecewiseLinear,
    k: PiecewiseLinear,
}

impl Conductor {
    /// A conductor of measured η and k (valid measured spectra: finite, non-negative,
    /// increasing wavelengths). Refused: η of 0 anywhere in 360–830 nm, where Fresnel has no
    /// meaning (an η list that stops inside the range is 0 beyond it).
    pub fn new(eta: PiecewiseLinear, k: PiecewiseLinear) -> Result<Self, SpectrumError> {
        for i in 0..=470 {
            let wavelength = 360.0 + f64::from(i);
            let n = eta.eval(wavelength);
            if n <= 0.0 {
                return Err(SpectrumError::IorOutOfRange { wavelength, ior: n });
            }
        }
        Ok(Self { eta, k })
    }

    /// A metal by the name Mitsuba 3 (`Au`) or pbrt-v4 (`metal-Au`) gives it, with pbrt-v4's
    /// measured tables: Ag, Al, Au, Cu, CuZn (brass), MgO, TiO2.
    pub fn named(name: &str) -> Option<Self> {
        let name = name.strip_prefix("metal-").unwrap_or(name);
        let (eta, k): (&[f64], &[f64]) = match name {
            "Ag" => (&AG_ETA, &AG_K),
            "Al" => (&AL_ETA, &AL_K),
            "Au" => (&AU_ETA, &AU_K),
            "Cu" => (&CU_ETA, &CU_K),
            "CuZn" => (&CUZN_ETA, &CUZN_K),
            "MgO" => (&MGO_ETA, &MGO_K),
            "TiO2" => (&TIO2_ETA, &TIO2_K),
            _ => return None,
        };
        Some(Self {
            eta: PiecewiseLinear::from_interleaved(eta),
            k: PiecewiseLinear::from_interleaved(k),
        })
    }

    /// The names [`Conductor::named`] knows (without the `metal-` prefix).
    pub const NAMES: [&str; 7] = ["Ag", "Al", "Au", "Cu", "CuZn", "MgO", "TiO2"];

    /// A pbrt-v4 named spectrum of a metal, `metal-<name>-eta` or `metal-<name>-k`.
    pub fn named_spectrum(name: &str) -> Option<PiecewiseLinear> {
        if let Some(metal) = name.strip_suffix("-eta") {
            return Self::named(metal).map(|c| c.eta);
        }
        let metal = name.strip_suffix("-k")?;
        Self::named(metal).map(|c| c.k)
    }

    /// η as a measured spectrum.
    pub fn eta(&self) -> &PiecewiseLinear {
        &self.eta
    }

    /// k as a measured spectrum.
    pub fn k(&self) -> &PiecewiseLinear {
        &self.k
    }

    /// The RGB η and k that an RGB transport uses, as Mitsuba 3's RGB variants derive them for
    /// its named conductors: each spectrum's XYZ without an illuminant (a constant 1 has Y = 1),
    /// turned into linear sRGB and clamped to ≥ 0.
    pub fn rgb(&self) -> ([f64; 3], [f64; 3]) {
        let rgb = |s: &PiecewiseLinear| {
            Spectrum::PiecewiseLinear(s.clone())
                .emission_srgb()
                .max(glam::DVec3::ZERO)
                .to_array()
        };
        (rgb(&self.eta), rgb(&self.k))
    }

    /// (η, k) at `lambda` nm.
    pub fn eval(&self, lambda: f64) -> (f64, f64) {
        (self.eta.eval(lambda), self.k.eval(lambda))
    }

    /// η and k at the sampled wavelengths.
    pub fn sample(&self, wavelengths: &SampledWavelengths) -> (SampledSpectrum, SampledSpectrum) {
        let lambdas = wavelengths.lambdas();
        (
            SampledSpectrum(lambdas.map(|l| self.eta.eval(f64::from(l)) as f32)),
            SampledSpectrum(lambdas.map(|l| self.k.eval(f64::from(l)) as f32)),
        )
    }

    /// The Fresnel reflectance at `cos_theta` for each sampled wavelength.
    pub fn fresnel(&self, cos_theta: f64, wavelengths: &SampledWavelengths) -> SampledSpectrum {
        SampledSpectrum(wavelengths.lambdas().map(|l| {
            let (eta, k) = self.eval(f64::from(l));
            fresnel_conductor(cos_theta, eta, k) as f32
        }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The conductor's Fresnel reflectance in the closed form of Born and Wolf (as pbrt-v3's
    /// `FrConductor` writes it), with no complex arithmetic.
    fn born_wolf(cos: f64, n: f64, k: f64) -> f64 {
        let cos2 = cos * cos;
        let sin2 = 1.0 - cos2;
        let t0 = n * n - k * k - sin2;
        let a2_b2 = (t0 * t0 + 4.0 * n * n * k * k).sqrt();
        let a = (0.5 * (a2_b2 + t0)).sqrt();
        let rs = (a2_b2 + cos2 - 2.0 * a * cos) / (a2_b2 + cos2 + 2.0 * a * cos);
        let t3 = cos2 * a2_b2 + sin2 * sin2;
        let t4 = 2.0 * a * cos * sin2;
        let rp = rs * (t3 - t4) / (t3 + t4);
        0.5 * (rs + rp)
    }

    /// The real Fresnel equations with Snell's law (1 under total internal reflection).
    fn dielectric(cos_i: f64, eta: f64) -> f64 {
        let sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
        if sin2_t >= 1.0 {
            return 1.0;
        }
        let cos_t = (1.0 - sin2_t).sqrt();
        let rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
        let rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
        0.5 * (rs * rs + rp * rp)
    }

    #[test]
    fn normal_incidence_is_the_closed_form() {
        for (n, k) in [(0.15, 3.5), (1.5, 0.0), (0.2, 2.4), (2.9, 3.1), (1.0, 1.0)] {
            let expected = ((n - 1.0) * (n - 1.0) + k * k) / ((n + 1.0) * (n + 1.0) + k * k);
            assert!(
                (fresnel_conductor(1.0, n, k) - expected).abs() < 1e-12,
                "{n} {k}"
            );
        }
    }

    #[test]
    fn oblique_incidence_matches_born_and_wolf() {
        for (n, k) in [(0.15, 3.5), (0.27, 2.78), (1.66, 9.2), (2.9, 3.1)] {
            for i in 1..=20 {
                let cos = f64::from(i) / 20.0;
                let (r, e) = (fresnel_conductor(cos, n, k), born_wolf(cos, n, k));
                assert!((r - e).abs() < 1e-10, "n {n} k {k} cos {cos}: {r} vs {e}");
            }
        }
    }

    #[test]
    fn limits_of_the_conductor() {
        for cos in [0.05, 0.3, 0.7, 1.0] {
            // k → ∞: a perfect mirror.
            let r = fresnel_conductor(cos, 1.3, 1e5);
            assert!((r - 1.0).abs() < 1e-6, "{cos}: {r}");
            // k = 0: the dielectric, both from outside and from inside the denser medium.
            for eta in [1.5, 1.0 / 1.5, 2.4] {
                let (r, e) = (fresnel_conductor(cos, eta, 0.0), dielectric(cos, eta));
                assert!((r - e).abs() < 1e-12, "{cos} {eta}: {r} vs {e}");
            }
        }
        // Grazing incidence reflects everything, conductor or not.
        for (n, k) in [(0.15, 3.5), (1.5, 0.0), (2.9, 3.1)] {
            assert_eq!(fresnel_conductor(0.0, n, k), 1.0);
            assert!((fresnel_conductor(1e-6, n, k) - 1.0).abs() < 1e-4);
        }
    }

    /// Gold and copper reflect red far more than blue; silver and aluminium reflect more than
    /// 85 % across the range (at normal incidence, pbrt-v4's tables).
    #[test]
    fn named_metals_have_their_colours() {
        let r = |name: &str, l: f64| {
            let (n, k) = Conductor::named(name).unwrap().eval(l);
            fresnel_conductor(1.0, n, k)
        };
        assert!(r("Au", 650.0) > 0.9 && r("Au", 450.0) < 0.45);
        assert!(r("Cu", 650.0) > 0.9 && r("Cu", 450.0) < 0.65);
        for l in [400.0, 550.0, 700.0] {
            assert!(r("Ag", l) > 0.85 && r("Al", l) > 0.85, "{l}");
        }
        for name in Conductor::NAMES {
            let c = Conductor::named(name).unwrap();
            assert!(Conductor::new(c.eta.clone(), c.k.clone()).is_ok(), "{name}");
            assert_eq!(Conductor::named(&format!("metal-{name}")), Some(c.clone()));
            assert_eq!(
                Conductor::named_spectrum(&format!("metal-{name}-k")),
                Some(c.k)
            );
        }
        assert!(Conductor::named("Unobtainium").is_none());
        let w = SampledWavelengths::sample_uniform(0.5);
        let f = Conductor::named("Au").unwrap().fresnel(1.0, &w);
        for i in 0..4 {
            assert!((f64::from(f[i]) - r("Au", f64::from(w.lambda(i)))).abs() < 1e-6);
        }
    }
}
