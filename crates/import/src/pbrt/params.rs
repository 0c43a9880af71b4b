//! Parameter access with type and arity checks: numbers, strings, colours, spectra.

use super::*;

/// pbrt-v4's named glass spectra, as their refractive index at the sodium d line (587.6 nm);
/// dispersion is dropped.
impl Parser {
    pub(super) fn loc_of_param(p: &Param) -> Loc {
        Loc {
            file: p.file,
            line: p.line,
            column: p.column,
        }
    }

    /// The texture a `"texture NAME"` parameter names, with where it stands.
    pub(super) fn texture_name(&self, p: &Param, name: &str) -> Result<(String, Loc), LoadError> {
        let loc = Self::loc_of_param(p);
        match p.values.as_slice() {
            [Value::Str(t)] => Ok((t.clone(), loc)),
            _ => Err(self.err(
                loc,
                format!("parameter \"texture {name}\" expects one texture name"),
            )),
        }
    }

    pub(super) fn nums(&self, p: &Param) -> Result<Vec<f64>, LoadError> {
        p.values
            .iter()
            .map(|v| match v {
                Value::Num(x) if x.is_finite() => Ok(*x),
                _ => Err(self.err(
                    Self::loc_of_param(p),
                    format!("parameter \"{} {}\" must hold numbers", p.ty, p.name),
                )),
            })
            .collect()
    }

    pub(super) fn expect_type(&self, p: &Param, types: &[&str]) -> Result<(), LoadError> {
        if types.contains(&p.ty.as_str()) {
            Ok(())
        } else {
            Err(self.err(
                Self::loc_of_param(p),
                format!(
                    "parameter \"{}\" must be of type {}, not \"{}\"",
                    p.name,
                    types.join(" or "),
                    p.ty
                ),
            ))
        }
    }

    pub(super) fn one(&self, p: &Param) -> Result<f64, LoadError> {
        let v = self.nums(p)?;
        match v.as_slice() {
            [x] => Ok(*x),
            _ => Err(self.err(
                Self::loc_of_param(p),
                format!(
                    "parameter \"{} {}\" expects 1 value, got {}",
                    p.ty,
                    p.name,
                    v.len()
                ),
            )),
        }
    }

    pub(super) fn float(&self, params: &Params, name: &str) -> Result<Option<f64>, LoadError> {
        let Some(p) = params.get(name) else {
            return Ok(None);
        };
        self.expect_type(p, &["float"])?;
        self.one(p).map(Some)
    }

    pub(super) fn int(&self, params: &Params, name: &str) -> Result<Option<i64>, LoadError> {
        let Some(p) = params.get(name) else {
            return Ok(None);
        };
        self.expect_type(p, &["integer"])?;
        let x = self.one(p)?;
        if x.fract() != 0.0 {
            return Err(self.err(
                Self::loc_of_param(p),
                format!("parameter \"integer {name}\" must be an integer, got {x}"),
            ));
        }
        Ok(Some(x as i64))
    }

    pub(super) fn boolean(&self, params: &Params, name: &str) -> Result<Option<bool>, LoadError> {
        let Some(p) = params.get(name) else {
            return Ok(None);
        };
        self.expect_type(p, &["bool"])?;
        match p.values.as_slice() {
            [Value::Bool(b)] => Ok(Some(*b)),
            [Value::Str(s)] if s == "true" || s == "false" => Ok(Some(s == "true")),
            _ => Err(self.err(
                Self::loc_of_param(p),
                format!("parameter \"bool {name}\" expects one true or false"),
            )),
        }
    }

    pub(super) fn str_param(
        &self,
        params: &Params,
        name: &str,
    ) -> Result<Option<String>, LoadError> {
        let Some(p) = params.get(name) else {
            return Ok(None);
        };
        self.expect_type(p, &["string", "texture"])?;
        match p.values.as_slice() {
            [Value::Str(s)] => Ok(Some(s.clone())),
            _ => Err(self.err(
                Self::loc_of_param(p),
                format!("parameter \"{} {name}\" expects one string", p.ty),
            )),
        }
    }

    /// Triples of numbers (points, normals).
    pub(super) fn vec3s(
        &self,
        params: &Params,
        name: &str,
        types: &[&str],
    ) -> Result<Option<Vec<Vec3>>, LoadError> {
        let Some(p) = params.get(name) else {
            return Ok(None);
        };
        self.expect_type(p, types)?;
        let v = self.nums(p)?;
        if v.len() % 3 != 0 {
            return Err(self.err(
                Self::loc_of_param(p),
                format!(
                    "parameter \"{} {name}\" needs a multiple of 3 values, got {}",
                    p.ty,
                    v.len()
                ),
            ));
        }
        Ok(Some(
            v.chunks(3)
                .map(|c| Vec3::new(c[0] as f32, c[1] as f32, c[2] as f32))
                .collect(),
        ))
    }

    /// A list of 2D points (`point2 uv`).
    pub(super) fn vec2s(
        &self,
        params: &Params,
        name: &str,
        types: &[&str],
    ) -> Result<Option<Vec<glam::Vec2>>, LoadError> {
        let Some(p) = params.get(name) else {
            return Ok(None);
        };
        self.expect_type(p, types)?;
        let v = self.nums(p)?;
        if v.len() % 2 != 0 {
            return Err(self.err(
                Self::loc_of_param(p),
                format!(
                    "parameter \"{} {name}\" needs a multiple of 2 values, got {}",
                    p.ty,
                    v.len()
                ),
            ));
        }
        Ok(Some(
            v.chunks(2)
                .map(|c| glam::Vec2::new(c[0] as f32, c[1] as f32))
                .collect(),
        ))
    }

    pub(super) fn ints(&self, params: &Params, name: &str) -> Result<Option<Vec<i64>>, LoadError> {
        let Some(p) = params.get(name) else {
            return Ok(None);
        };
        self.expect_type(p, &["integer"])?;
        let v = self.nums(p)?;
        if v.iter().any(|x| x.fract() != 0.0) {
            return Err(self.err(
                Self::loc_of_param(p),
                format!("parameter \"integer {name}\" must hold integers"),
            ));
        }
        Ok(Some(v.into_iter().map(|x| x as i64).collect()))
    }

    /// A colour-like parameter: `rgb`, `spectrum` (named, file, or λ/value pairs), `blackbody`,
    /// `float`, or a `texture` (which stands in as a constant).
    pub(super) fn colour(
        &mut self,
        params: &Params,
        name: &str,
        usage: SpectrumUse,
    ) -> Result<Option<Rgb>, LoadError> {
        let Some(p) = params.get(name).cloned() else {
            return Ok(None);
        };
        let loc = Self::loc_of_param(&p);
        let rgb = match p.ty.as_str() {
            "rgb" => {
                let v = self.nums(&p)?;
                let [r, g, b] = v.as_slice() else {
                    return Err(self.err(
                        loc,
                        format!("parameter \"rgb {name}\" expects 3 values, got {}", v.len()),
                    ));
                };
                Rgb::new(*r as f32, *g as f32, *b as f32)
            }
            "float" => Rgb::splat(self.one(&p)? as f32),
            "spectrum" => match p.values.as_slice() {
                [Value::Str(s)] => self.named_spectrum(s, loc, usage)?,
                _ => {
                    let v = self.nums(&p)?;
                    if v.len() < 2 || v.len() % 2 != 0 {
                        return Err(self.err(
                            loc,
                            format!("parameter \"spectrum {name}\" needs wavelength/value pairs"),
                        ));
                    }
                    let w: Vec<f64> = v.iter().step_by(2).copied().collect();
                    let x: Vec<f64> = v.iter().skip(1).step_by(2).copied().collect();
                    spectrum::spectrum_to_rgb(&w, &x, usage)
                        .ok_or_else(|| self.err(loc, "wavelengths must increase"))?
                }
            },
            // pbrt-v4 divides every light's scale by its spectrum's luminance: a blackbody emits
            // its colour at luminance 1 (times the light's scale).
            "blackbody" => match self.blackbody(&p)? {
                Some(b) => b.emission_srgb().max(glam::DVec3::ZERO).as_vec3(),
                None => Rgb::ONE,
            },
            "texture" => {
                let [Value::Str(tex)] = p.values.as_slice() else {
                    return Err(self.err(
                        loc,
                        format!("parameter \"texture {name}\" expects one texture name"),
                    ));
                };
                self.texture_standin(tex, loc, 0)?
            }
            other => {
                return Err(self.err(loc, format!("parameter \"{name}\" must be a colour (rgb, spectrum, float or texture), not \"{other}\"")));
            }
        };
        if !rgb.is_finite() {
            return Err(self.err(loc, format!("parameter \"{name}\" must be finite")));
        }
        Ok(Some(rgb))
    }

    /// A `blackbody` parameter's spectrum at luminance 1 (pbrt-v4's lights normalize so); an
    /// error for a bad temperature.
    pub(super) fn blackbody(
        &self,
        p: &Param,
    ) -> Result<Option<scene::spectral::Spectrum>, LoadError> {
        use scene::spectral::{Blackbody, Spectrum};
        if p.ty != "blackbody" {
            return Ok(None);
        }
        let loc = Self::loc_of_param(p);
        // pbrt-v4 gives the temperature alone; pbrt-v3 a temperature and a scale.
        let t = match self.nums(p)?.as_slice() {
            [t] | [t, _] => *t,
            v => {
                return Err(self.err(
                    loc,
                    format!(
                        "parameter \"blackbody {}\" expects a temperature, got {} values",
                        p.name,
                        v.len()
                    ),
                ));
            }
        };
        let b = Blackbody::new(t).map_err(|e| {
            self.err(loc, format!("parameter \"blackbody {}\": {e}", p.name))
                .into_bad_spectrum()
        })?;
        let y = Spectrum::Blackbody(b).to_xyz().y;
        Ok(Some(Spectrum::Scaled(
            1.0 / y,
            Box::new(Spectrum::Blackbody(b)),
        )))
    }

    /// The samples of a `spectrum` parameter given as λ/value pairs or a `.spd` file; `None`
    /// for anything else (named spectra, rgb, absent).
    pub(super) fn spectral(
        &self,
        params: &Params,
        name: &str,
    ) -> Result<Option<Samples>, LoadError> {
        let Some(p) = params.get(name) else {
            return Ok(None);
        };
        if p.ty != "spectrum" {
            return Ok(None);
        }
        let loc = Self::loc_of_param(p);
        match p.values.as_slice() {
            [Value::Str(s)] if s.starts_with("metal-") || s.starts_with("glass-") => Ok(None),
            [Value::Str(s)] if s.starts_with("stdillum-") => Ok(None),
            [Value::Str(s)] => super::super::mitsuba::read_spd(&self.resolve(s))
                .map(Some)
                .map_err(|m| self.err(loc, m)),
            _ => {
                let v = self.nums(p)?;
                if v.len() < 2 || v.len() % 2 != 0 {
                    return Err(self.err(
                        loc,
                        format!("parameter \"spectrum {name}\" needs wavelength/value pairs"),
                    ));
                }
                Ok(Some((
                    v.iter().step_by(2).copied().collect(),
                    v.iter().skip(1).step_by(2).copied().collect(),
                )))
            }
        }
    }

    /// A named pbrt spectrum (metals, glasses) or a `.spd` file.
    pub(super) fn named_spectrum(
        &mut self,
        s: &str,
        loc: Loc,
        usage: SpectrumUse,
    ) -> Result<Rgb, LoadError> {
        if let Some(rest) = s.strip_prefix("metal-") {
            let (metal, part) = rest.rsplit_once('-').ok_or_else(|| {
                self.err(loc, format!("unknown named spectrum \"{s}\""))
                    .into_bad_spectrum()
            })?;
            let (eta, k) = spectrum::metal(metal).ok_or_else(|| {
                self.err(loc, format!("named spectrum \"{s}\" is not known to fppm"))
                    .into_bad_spectrum()
            })?;
            return match part {
                "eta" => Ok(eta),
                "k" => Ok(k),
                _ => Err(self
                    .err(loc, format!("unknown named spectrum \"{s}\""))
                    .into_bad_spectrum()),
            };
        }
        if let Some(ior) = scene::spectral::Ior::named(s) {
            // The RGB transport's index of a dispersive glass (`docs/spectral.md`); a dielectric
            // keeps the whole law in its spectra.
            return Ok(Rgb::splat(ior.eval(scene::REPRESENTATIVE_WAVELENGTH) as f32));
        }
        if s.starts_with("stdillum-") || s.starts_with("canon_") || s.starts_with("nikon_") {
            self.warn(format!("spectrum \"{s}\" stands in as white"));
            return Ok(Rgb::ONE);
        }
        let path = self.resolve(s);
        let (w, v) = super::super::mitsuba::read_spd(&path).map_err(|m| self.err(loc, m))?;
        spectrum::spectrum_to_rgb(&w, &v, usage)
            .ok_or_else(|| self.err(loc, format!("spectrum file {s}: wavelengths must increase")))
    }
}
