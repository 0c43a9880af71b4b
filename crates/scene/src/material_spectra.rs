//! The spectral data of a material, kept beside its RGB model for the spectral transport of
//! issue #34 (`docs/spectral.md`).
//!
//! The RGB transport renders [`crate::Material::kind`] and [`crate::Material::emission`], which
//! the importers derive from these spectra (an emission's colour is its
//! [`Spectrum::emission_srgb`], a reflectance's its [`Spectrum::reflectance_srgb`], a
//! conductor's RGB η and k its [`spectral::Conductor::rgb`], a dispersive dielectric's index
//! η([`REPRESENTATIVE_WAVELENGTH`])). They live here rather than in the model because a
//! [`crate::MaterialKind`] is `Copy` and rides in every [`crate::Bsdf`], and measured spectra are
//! lists.

use crate::fingerprint::{Fingerprint, Fingerprinter};
use crate::spectral::{self, Ior, PiecewiseLinear, Spectrum};

/// The wavelength (nm) whose index of refraction a dispersive dielectric has in the RGB
/// transport: near the peak of the eye's sensitivity ȳ (555 nm), as `docs/spectral.md` explains.
pub const REPRESENTATIVE_WAVELENGTH: f64 = 550.0;

/// A material's spectra, each `None` where the scene gave a colour (or nothing).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MaterialSpectra {
    /// Emitted spectral radiance; its colour is the material's `emission`.
    pub emission: Option<Spectrum>,
    /// The model's colour parameter as a spectrum (a diffuse albedo, a mirror's or glossy
    /// material's reflectance, a conductor's `specular_reflectance`).
    pub reflectance: Option<Spectrum>,
    /// A conductor's spectral complex index of refraction.
    pub conductor: Option<spectral::Conductor>,
    /// A dielectric's index of refraction as a function of wavelength.
    pub ior: Option<Ior>,
}

impl MaterialSpectra {
    /// Whether it holds no spectrum at all.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.emission.is_none()
            && self.reflectance.is_none()
            && self.conductor.is_none()
            && self.ior.is_none()
    }
}

impl Fingerprint for MaterialSpectra {
    /// Each spectrum by kind and parameters (measured ones by every sample).
    fn fingerprint(&self, h: &mut Fingerprinter) {
        h.option(self.emission.as_ref(), |h, s| h.add(s));
        h.option(self.reflectance.as_ref(), |h, s| h.add(s));
        h.option(self.conductor.as_ref(), |h, c| {
            measured(h, c.eta());
            measured(h, c.k());
        });
        h.option(self.ior.as_ref(), |h, ior| h.add(ior));
    }
}

/// Feeds a measured spectrum: its length, then each (wavelength, value).
fn measured(h: &mut Fingerprinter, s: &PiecewiseLinear) {
    h.u64(s.lambdas().len() as u64);
    for (&l, &v) in s.lambdas().iter().zip(s.values()) {
        h.u64(l.to_bits());
        h.u64(v.to_bits());
    }
}

impl Fingerprint for Spectrum {
    fn fingerprint(&self, h: &mut Fingerprinter) {
        match self {
            Spectrum::Constant(c) => {
                h.str("constant");
                h.u64(c.to_bits());
            }
            Spectrum::PiecewiseLinear(s) => {
                h.str("measured");
                measured(h, s);
            }
            Spectrum::Blackbody(b) => {
                h.str("blackbody");
                h.u64(b.temperature().to_bits());
            }
            Spectrum::RgbAlbedo(s) => {
                h.str("rgb albedo");
                s.polynomial.c.iter().for_each(|c| h.u64(c.to_bits()));
            }
            Spectrum::RgbUnbounded(s) => {
                h.str("rgb unbounded");
                h.u64(s.scale.to_bits());
                s.polynomial.c.iter().for_each(|c| h.u64(c.to_bits()));
            }
            Spectrum::RgbIlluminant(s) => {
                h.str("rgb illuminant");
                h.u64(s.scale.to_bits());
                s.polynomial.c.iter().for_each(|c| h.u64(c.to_bits()));
            }
            Spectrum::Scaled(k, s) => {
                h.str("scaled");
                h.u64(k.to_bits());
                h.add(s.as_ref());
            }
        }
    }
}

impl Fingerprint for Ior {
    fn fingerprint(&self, h: &mut Fingerprinter) {
        match self {
            Ior::Constant(n) => {
                h.str("constant");
                h.u64(n.to_bits());
            }
            Ior::Sellmeier(s) => {
                h.str("sellmeier");
                let (b, c) = s.coefficients();
                b.iter().chain(&c).for_each(|x| h.u64(x.to_bits()));
            }
            Ior::Cauchy(c) => {
                h.str("cauchy");
                c.coefficients().iter().for_each(|x| h.u64(x.to_bits()));
            }
            Ior::Tabulated(t) => {
                h.str("tabulated");
                measured(h, t);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use super::*;
    use crate::{Material, MaterialKind, Rgb};

    fn fingerprint(m: &Material) -> u64 {
        let mut h = Fingerprinter::new();
        h.add(m);
        h.finish()
    }

    /// A material without spectra feeds what a material fed before spectra existed (emission,
    /// model, textures), so RGB scenes keep their fingerprints; spectra change it.
    #[test]
    fn spectra_count_only_when_present() {
        let m = Material {
            name: "gold".to_owned(),
            kind: MaterialKind::Conductor(crate::Conductor {
                eta: Rgb::new(0.14, 0.37, 1.44),
                k: Rgb::new(3.98, 2.38, 1.60),
                specular_reflectance: Rgb::ONE,
                roughness: 0.0,
            }),
            emission: Rgb::ZERO,
            textures: None,
            spectra: None,
        };
        let mut h = Fingerprinter::new();
        h.vec3(m.emission);
        h.add(&m.kind);
        h.option(None::<&crate::texture::MaterialTextures>, |h, t| h.add(t));
        assert_eq!(fingerprint(&m), h.finish());

        let with = |spectra: MaterialSpectra| Material {
            spectra: Some(Arc::new(spectra)),
            ..m.clone()
        };
        let gold = with(MaterialSpectra {
            conductor: spectral::Conductor::named("Au"),
            ..MaterialSpectra::default()
        });
        let copper = with(MaterialSpectra {
            conductor: spectral::Conductor::named("Cu"),
            ..MaterialSpectra::default()
        });
        let bk7 = with(MaterialSpectra {
            ior: Ior::named("glass-BK7"),
            ..MaterialSpectra::default()
        });
        let hot = |t: f64| {
            with(MaterialSpectra {
                emission: spectral::Blackbody::new(t).ok().map(Spectrum::Blackbody),
                ..MaterialSpectra::default()
            })
        };
        let prints = [&m, &gold, &copper, &bk7, &hot(3000.0), &hot(3001.0)].map(fingerprint);
        for i in 0..prints.len() {
            for j in 0..i {
                assert_ne!(prints[i], prints[j], "{i} {j}");
            }
        }
        assert_eq!(fingerprint(&gold), fingerprint(&gold.clone()));
    }
}
