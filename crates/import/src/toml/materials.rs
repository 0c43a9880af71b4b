//! Materials of a TOML scene: each `[materials.NAME]` table to a scene material, with its
//! colour inputs (a colour, or an image texture) and its textures.

use std::sync::Arc;

use glam::{DVec3, Vec3};
use scene::spectral::{self, Blackbody, Ior, NamedIlluminant, PiecewiseLinear, Spectrum};
use scene::texture::{Alpha, AlphaMode, MaterialTextures, TextureRef};
use scene::{Material, MaterialKind, MaterialSpectra};

use super::convert::Converter;
use super::schema::*;
use crate::error::LoadError;

impl Converter<'_> {
    pub(super) fn material(&self, name: &str, m: MaterialToml) -> Result<Material, LoadError> {
        let key = |k: &str| format!("[materials.{name}] {k}");
        let mut color = None;
        let mut cutout_file = None;
        let mut spectra = MaterialSpectra::default();
        let (kind, emission) = match m {
            MaterialToml::Diffuse {
                albedo,
                emission,
                cutout,
            } => {
                cutout_file = cutout;
                let (albedo, texture, spectrum) =
                    self.colour_input(&key("albedo"), albedo, Usage::Reflectance)?;
                color = texture;
                spectra.reflectance = spectrum;
                (MaterialKind::Diffuse(scene::Diffuse { albedo }), emission)
            }
            MaterialToml::Mirror {
                reflectance,
                emission,
                cutout,
            } => {
                cutout_file = cutout;
                let (reflectance, texture, spectrum) = self.colour_input(
                    &key("reflectance"),
                    reflectance.unwrap_or(ColorToml::Rgb([1.0; 3])),
                    Usage::Reflectance,
                )?;
                color = texture;
                spectra.reflectance = spectrum;
                (
                    MaterialKind::Mirror(scene::Mirror { reflectance }),
                    emission,
                )
            }
            MaterialToml::Interface {} => (MaterialKind::Interface(scene::Interface), None),
            MaterialToml::Dielectric {
                ior,
                roughness,
                emission,
            } => {
                let ior = match ior {
                    IorToml::Number(n) => self.positive(&key("ior"), n)?,
                    law => {
                        let law = self.ior_law(&key("ior"), law)?;
                        let n = law.eval(scene::REPRESENTATIVE_WAVELENGTH) as f32;
                        spectra.ior = Some(law);
                        n
                    }
                };
                // Zero (or absent) is the smooth dielectric; anything else must be a GGX α.
                let roughness = match roughness {
                    None => 0.0,
                    Some(0.0) => 0.0,
                    Some(r) => self.positive(&key("roughness"), r)?,
                };
                (MaterialKind::dielectric(ior, roughness), emission)
            }
            MaterialToml::Glossy {
                reflectance,
                roughness,
                emission,
                cutout,
            } => {
                cutout_file = cutout;
                let (reflectance, texture, spectrum) =
                    self.colour_input(&key("reflectance"), reflectance, Usage::Reflectance)?;
                color = texture;
                spectra.reflectance = spectrum;
                (
                    MaterialKind::Glossy(scene::Glossy {
                        reflectance,
                        roughness: self.positive(&key("roughness"), roughness)?,
                        diffuse: Vec3::ZERO,
                    }),
                    emission,
                )
            }
            MaterialToml::Conductor {
                metal,
                eta,
                k,
                specular_reflectance,
                roughness,
                emission,
                cutout,
            } => {
                cutout_file = cutout;
                let (tint, texture, spectrum) = self.colour_input(
                    &key("specular_reflectance"),
                    specular_reflectance.unwrap_or(ColorToml::Rgb([1.0; 3])),
                    Usage::Reflectance,
                )?;
                color = texture;
                spectra.reflectance = spectrum;
                let (eta, k, conductor) = self.conductor_ior(name, metal, eta, k)?;
                spectra.conductor = conductor;
                let roughness = match roughness {
                    None | Some(0.0) => 0.0,
                    Some(r) => self.positive(&key("roughness"), r)?,
                };
                (
                    MaterialKind::Conductor(scene::Conductor {
                        eta,
                        k,
                        specular_reflectance: tint,
                        roughness,
                    }),
                    emission,
                )
            }
        };
        let (emission, emission_texture) = match emission {
            Some(e) => {
                let (emission, texture, spectrum) =
                    self.colour_input(&key("emission"), e, Usage::Emission)?;
                spectra.emission = spectrum;
                (emission, texture)
            }
            None => (Vec3::ZERO, None),
        };
        let alpha = match cutout_file {
            None => None,
            Some(file) => {
                let image = self.textures.borrow_mut().load(&self.dir.join(file))?;
                Some(Alpha {
                    texture: Some(TextureRef::new(image, false)),
                    factor: 1.0,
                    mode: AlphaMode::Mask { cutoff: 0.5 },
                })
            }
        };
        let textures = MaterialTextures {
            color,
            emission: emission_texture,
            alpha,
            ..MaterialTextures::default()
        };
        Ok(Material {
            name: name.to_owned(),
            kind,
            emission,
            textures: (!textures.is_empty()).then(|| Arc::new(textures)),
            spectra: (!spectra.is_empty()).then(|| Arc::new(spectra)),
        })
    }

    /// A colour given as `[r, g, b]`, as `{ texture = "file", scale = [r, g, b] }` or as a
    /// spectrum (`docs/scene-format-extensions.md`, "Spectra"): the constant colour the RGB
    /// transport uses (a texture's scale, 1 by default; a spectrum's colour), the texture, if
    /// any, read relative to the scene file, and the spectrum, if one was given. A reflectance
    /// must be at most 1 (the texture's texels are not checked: 8-bit colours are at most 1, and
    /// HDR images belong to emission).
    fn colour_input(
        &self,
        key: &str,
        input: ColorToml,
        usage: Usage,
    ) -> Result<(Vec3, Option<TextureRef>, Option<Spectrum>), LoadError> {
        let check = |v| match usage {
            Usage::Reflectance => self.reflectance(key, v),
            Usage::Emission => self.colour(key, v),
        };
        match input {
            ColorToml::Rgb(v) => Ok((check(v)?, None, None)),
            ColorToml::Texture { texture, scale } => {
                let scale = check(scale.unwrap_or([1.0; 3]))?;
                let image = self.textures.borrow_mut().load(&self.dir.join(texture))?;
                Ok((scale, Some(TextureRef::new(image, true)), None))
            }
            ColorToml::Spectrum(spectrum) => {
                if let Some(rgb) = spectrum.rgb {
                    let scale = self.scale(key, spectrum.scale)? as f32;
                    return Ok((check(rgb.map(|c| c * scale))?, None, None));
                }
                let spectrum = self.spectrum(key, *spectrum, usage)?;
                let colour = match usage {
                    Usage::Reflectance => {
                        spectrum.reflectance_srgb().clamp(DVec3::ZERO, DVec3::ONE)
                    }
                    Usage::Emission => spectrum.emission_srgb().max(DVec3::ZERO),
                };
                Ok((check(colour.as_vec3().to_array())?, None, Some(spectrum)))
            }
        }
    }

    /// A [`LoadError::BadSpectrum`] about `key`.
    fn bad(&self, key: impl Into<String>, message: impl Into<String>) -> LoadError {
        self.invalid(key, message).into_bad_spectrum()
    }

    /// A spectrum's `scale`: finite and ≥ 0, 1 by default.
    fn scale(&self, key: &str, scale: Option<f64>) -> Result<f64, LoadError> {
        match scale {
            None => Ok(1.0),
            Some(s) if s.is_finite() && s >= 0.0 => Ok(s),
            Some(s) => Err(self.bad(
                format!("{key} scale"),
                format!("must be finite and >= 0, got {s}"),
            )),
        }
    }

    /// The spectrum of a colour's spectral form (not `rgb`). An emission's blackbody and named
    /// illuminant have luminance `scale` (pbrt-v4 normalizes its lights so); measured values
    /// are taken as they are, times `scale`. A reflectance is measured, each value at most 1.
    fn spectrum(&self, key: &str, s: SpectrumToml, usage: Usage) -> Result<Spectrum, LoadError> {
        let scale = self.scale(key, s.scale)?;
        let emission_only =
            |what: &str| self.bad(key, format!("a {what} is an emission, not a reflectance"));
        if let Some(t) = s.blackbody {
            if usage != Usage::Emission {
                return Err(emission_only("blackbody"));
            }
            let b = Blackbody::new(t).map_err(|e| self.bad(key, e.to_string()))?;
            let y = Spectrum::Blackbody(b).to_xyz().y;
            return Ok(Spectrum::Scaled(
                scale / y,
                Box::new(Spectrum::Blackbody(b)),
            ));
        }
        if let Some(name) = s.illuminant {
            if usage != Usage::Emission {
                return Err(emission_only("named illuminant"));
            }
            let illuminant = NamedIlluminant::from_name(&name).ok_or_else(|| {
                self.bad(
                    key,
                    format!("unknown illuminant \"{name}\" (known: D65, A)"),
                )
            })?;
            return Ok(Spectrum::PiecewiseLinear(
                illuminant.spectrum().clone().scaled(scale),
            ));
        }
        let samples = s.samples.unwrap_or_default();
        let measured = self.measured(key, &samples)?;
        if usage == Usage::Reflectance
            && let Some((i, &v)) = measured
                .values()
                .iter()
                .enumerate()
                .find(|&(_, &v)| v * scale > 1.0)
        {
            return Err(self.bad(
                key,
                format!(
                    "a reflectance must be at most 1: sample {i} is {} at {} nm",
                    v * scale,
                    measured.lambdas()[i]
                ),
            ));
        }
        Ok(Spectrum::PiecewiseLinear(measured.scaled(scale)))
    }

    /// A measured spectrum from `[[nm, value], …]`.
    fn measured(&self, key: &str, samples: &[[f64; 2]]) -> Result<PiecewiseLinear, LoadError> {
        PiecewiseLinear::new(
            samples.iter().map(|s| s[0]).collect(),
            samples.iter().map(|s| s[1]).collect(),
        )
        .map_err(|e| self.bad(key, e.to_string()))
    }

    /// A dielectric's index of refraction given as a named glass or a dispersion law.
    fn ior_law(&self, key: &str, ior: IorToml) -> Result<Ior, LoadError> {
        let bad = |e: spectral::SpectrumError| self.bad(key, e.to_string());
        match ior {
            IorToml::Number(n) => Ior::constant(f64::from(n)).map_err(bad),
            IorToml::Named(name) => Ior::named(&name).ok_or_else(|| {
                self.bad(
                    key,
                    format!(
                        "unknown glass \"{name}\" (known: {})",
                        Ior::NAMES.join(", ")
                    ),
                )
            }),
            IorToml::Law(law) => {
                match (law.sellmeier, law.cauchy, law.samples) {
                    (Some(c), None, None) => {
                        let [b1, b2, b3, c1, c2, c3] = c[..] else {
                            return Err(self.bad(
                            key,
                            format!("sellmeier needs 6 coefficients [B1, B2, B3, C1, C2, C3], got {}", c.len()),
                        ));
                        };
                        spectral::Sellmeier::new([b1, b2, b3], [c1, c2, c3])
                            .map(Ior::Sellmeier)
                            .map_err(bad)
                    }
                    (None, Some(c), None) => {
                        let (a, b, c) = match c[..] {
                            [a, b] => (a, b, 0.0),
                            [a, b, c] => (a, b, c),
                            _ => {
                                return Err(self.bad(
                                    key,
                                    format!(
                                        "cauchy needs 2 or 3 coefficients [A, B, C], got {}",
                                        c.len()
                                    ),
                                ));
                            }
                        };
                        spectral::Cauchy::new(a, b, c).map(Ior::Cauchy).map_err(bad)
                    }
                    (None, None, Some(samples)) => {
                        Ior::tabulated(self.measured(key, &samples)?).map_err(bad)
                    }
                    _ => {
                        Err(self
                            .invalid(key, "needs exactly one of `sellmeier`, `cauchy`, `samples`"))
                    }
                }
            }
        }
    }

    /// A conductor's RGB η and k and its spectral ones: a named metal (pbrt-v4's measured
    /// spectra, their RGB derived as Mitsuba's RGB variants do; or Mitsuba's RGB-only
    /// conductors), or `eta` and `k` as colours or spectra (k 0 by default).
    fn conductor_ior(
        &self,
        name: &str,
        metal: Option<String>,
        eta: Option<ColorToml>,
        k: Option<ColorToml>,
    ) -> Result<(Vec3, Vec3, Option<spectral::Conductor>), LoadError> {
        let key = |k: &str| format!("[materials.{name}] {k}");
        match (metal, eta) {
            (Some(_), Some(_)) => {
                Err(self.bad(key("metal"), "give either `metal` or `eta` and `k`"))
            }
            (None, None) => Err(self.bad(key("eta"), "a conductor needs `metal` or `eta` and `k`")),
            (Some(metal), None) => {
                if k.is_some() {
                    return Err(self.bad(key("k"), "give either `metal` or `eta` and `k`"));
                }
                if let Some(c) = spectral::Conductor::named(&metal) {
                    let (eta, k) = c.rgb();
                    let rgb = |v: [f64; 3]| DVec3::from_array(v).as_vec3();
                    return Ok((rgb(eta), rgb(k), Some(c)));
                }
                let (eta, k) = crate::spectrum::metal(&metal).ok_or_else(|| {
                    self.bad(
                        key("metal"),
                        format!(
                            "unknown metal \"{metal}\" (spectral: {}; Mitsuba's RGB conductors by name)",
                            spectral::Conductor::NAMES.join(", ")
                        ),
                    )
                })?;
                Ok((eta, k, None))
            }
            (None, Some(eta)) => {
                let (eta_rgb, eta_spectrum) = self.ior_colour(&key("eta"), eta)?;
                let (k_rgb, k_spectrum) = match k {
                    Some(k) => self.ior_colour(&key("k"), k)?,
                    None => (Vec3::ZERO, None),
                };
                let spectra = match (eta_spectrum, k_spectrum) {
                    (None, None) => None,
                    (Some(eta), k) => {
                        if k.is_none() && k_rgb != Vec3::ZERO {
                            return Err(self
                                .bad(key("k"), "must be a spectrum (or absent) when eta is one"));
                        }
                        let k = k.unwrap_or_else(|| zero_spectrum(&eta));
                        Some(
                            spectral::Conductor::new(eta, k)
                                .map_err(|e| self.bad(key("eta"), e.to_string()))?,
                        )
                    }
                    (None, Some(_)) => {
                        return Err(self.bad(key("k"), "a spectral k needs a spectral eta"));
                    }
                };
                Ok((eta_rgb, k_rgb, spectra))
            }
        }
    }

    /// η or k as a colour or a measured spectrum (its RGB as [`spectral::Conductor::rgb`]
    /// derives it).
    fn ior_colour(
        &self,
        key: &str,
        c: ColorToml,
    ) -> Result<(Vec3, Option<PiecewiseLinear>), LoadError> {
        match c {
            ColorToml::Rgb(v) => Ok((self.colour(key, v)?, None)),
            ColorToml::Spectrum(s) if s.samples.is_some() && s.scale.is_none() => {
                let measured = self.measured(key, s.samples.as_deref().unwrap_or_default())?;
                let rgb = Spectrum::PiecewiseLinear(measured.clone())
                    .emission_srgb()
                    .max(DVec3::ZERO)
                    .as_vec3();
                Ok((rgb, Some(measured)))
            }
            ColorToml::Spectrum(s) if s.rgb.is_some() && s.scale.is_none() => {
                Ok((self.colour(key, s.rgb.unwrap_or_default())?, None))
            }
            _ => Err(self.bad(
                key,
                "must be [r, g, b], { rgb = [r, g, b] } or { samples = [[nm, value], …] }",
            )),
        }
    }
}

/// What a colour input describes: it decides its checks and how a spectrum becomes a colour.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Usage {
    /// A reflectance: at most 1, its colour under D65.
    Reflectance,
    /// Emitted radiance: its colour as an emission.
    Emission,
}

/// A k of zero over the wavelengths of `eta`.
fn zero_spectrum(eta: &PiecewiseLinear) -> PiecewiseLinear {
    eta.clone().scaled(0.0)
}
