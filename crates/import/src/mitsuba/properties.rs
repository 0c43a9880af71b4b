//! Typed property access: numbers, vectors, colours, spectra, and the constant colours
//! that stand in for textures.

use super::*;

impl<'a> Importer<'a> {
    pub(super) fn float(&self, node: &Node, name: &str) -> Result<Option<f64>, LoadError> {
        let Some(p) = prop(node, name) else {
            return Ok(None);
        };
        if p.tag != "float" && p.tag != "integer" {
            return Err(self.err(
                p,
                format!("property \"{name}\" must be a <float>, got <{}>", p.tag),
            ));
        }
        let v = self.value(p)?;
        let x: f64 = v
            .trim()
            .parse()
            .map_err(|_| self.err(p, format!("\"{v}\" is not a number")))?;
        if !x.is_finite() {
            return Err(self.err(p, format!("\"{v}\" is not finite")));
        }
        Ok(Some(x))
    }

    pub(super) fn integer(&self, node: &Node, name: &str) -> Result<Option<i64>, LoadError> {
        let Some(p) = prop(node, name) else {
            return Ok(None);
        };
        if p.tag != "integer" {
            return Err(self.err(
                p,
                format!("property \"{name}\" must be an <integer>, got <{}>", p.tag),
            ));
        }
        let v = self.value(p)?;
        v.trim()
            .parse()
            .map(Some)
            .map_err(|_| self.err(p, format!("\"{v}\" is not an integer")))
    }

    pub(super) fn boolean(&self, node: &Node, name: &str) -> Result<Option<bool>, LoadError> {
        let Some(p) = prop(node, name) else {
            return Ok(None);
        };
        if p.tag != "boolean" {
            return Err(self.err(
                p,
                format!("property \"{name}\" must be a <boolean>, got <{}>", p.tag),
            ));
        }
        match self.value(p)?.trim().to_ascii_lowercase().as_str() {
            "true" => Ok(Some(true)),
            "false" => Ok(Some(false)),
            other => Err(self.err(p, format!("\"{other}\" is not true or false"))),
        }
    }

    pub(super) fn string(&self, node: &'a Node, name: &str) -> Result<Option<&'a str>, LoadError> {
        let Some(p) = prop(node, name) else {
            return Ok(None);
        };
        if p.tag != "string" {
            return Err(self.err(
                p,
                format!("property \"{name}\" must be a <string>, got <{}>", p.tag),
            ));
        }
        Ok(Some(self.value(p)?))
    }

    /// A `<point>`/`<vector>` (x, y, z attributes or a value list).
    pub(super) fn vector(&self, node: &Node, name: &str) -> Result<Option<DVec3>, LoadError> {
        let Some(p) = prop(node, name) else {
            return Ok(None);
        };
        if p.tag != "point" && p.tag != "vector" {
            return Err(self.err(
                p,
                format!(
                    "property \"{name}\" must be a <point> or <vector>, got <{}>",
                    p.tag
                ),
            ));
        }
        self.xyz(p, 0.0).map(Some)
    }

    /// x, y, z attributes (missing ones `default`) or a `value` of one or three numbers.
    pub(super) fn xyz(&self, p: &Node, default: f64) -> Result<DVec3, LoadError> {
        if let Some(v) = p.attr("value") {
            let n = numbers(v).map_err(|m| self.err(p, m))?;
            return match n.as_slice() {
                [a] => Ok(DVec3::splat(*a)),
                [a, b, c] => Ok(DVec3::new(*a, *b, *c)),
                _ => Err(self.err(p, format!("needs 1 or 3 values, got {}", n.len()))),
            };
        }
        let mut out = DVec3::splat(default);
        for (i, k) in ["x", "y", "z"].iter().enumerate() {
            if let Some(v) = p.attr(k) {
                out[i] = v
                    .trim()
                    .parse()
                    .map_err(|_| self.err(p, format!("{k}=\"{v}\" is not a number")))?;
            }
        }
        if !out.is_finite() {
            return Err(self.err(p, "values must be finite"));
        }
        Ok(out)
    }

    /// A colour property: `<rgb>`, `<spectrum>`, `<float>`, or a texture (nested or by
    /// `<ref>`), which stands in as a constant with a warning. `None` if absent.
    pub(super) fn colour(
        &mut self,
        node: &'a Node,
        name: &str,
        usage: SpectrumUse,
    ) -> Result<Option<Rgb>, LoadError> {
        let Some(p) = prop(node, name) else {
            return Ok(None);
        };
        let p = self.deref(p)?;
        let rgb = match p.tag.as_str() {
            "rgb" => {
                let n = numbers(self.value(p)?).map_err(|m| self.err(p, m))?;
                match n.as_slice() {
                    [a] => Rgb::splat(*a as f32),
                    [r, g, b] => Rgb::new(*r as f32, *g as f32, *b as f32),
                    _ => {
                        return Err(
                            self.err(p, format!("<rgb> needs 1 or 3 values, got {}", n.len()))
                        );
                    }
                }
            }
            "float" | "integer" => {
                let v: f64 = self
                    .value(p)?
                    .trim()
                    .parse()
                    .map_err(|_| self.err(p, "not a number"))?;
                Rgb::splat(v as f32)
            }
            "spectrum" if p.attr("type").is_none() => self.spectrum(p, usage)?,
            // A blackbody emits its exact colour (Mitsuba renders it only spectrally).
            "spectrum" if p.attr("type") == Some("blackbody") && usage == SpectrumUse::Emission => {
                match self.measured_spectrum(node, name)? {
                    Some(s) => s.emission_srgb().max(glam::DVec3::ZERO).as_vec3(),
                    None => return Err(self.err(p, "blackbody spectrum vanished")),
                }
            }
            "texture" | "spectrum" => self.texture_standin(p)?,
            other => {
                return Err(self.err(
                    p,
                    format!("property \"{name}\" must be a colour, got <{other}>"),
                ));
            }
        };
        if !rgb.is_finite() {
            return Err(self.err(p, "colour must be finite"));
        }
        Ok(Some(rgb))
    }

    /// `<spectrum value="…">` (one value, or `wavelength:value` pairs) or `filename=".spd"`.
    pub(super) fn spectrum(&self, p: &Node, usage: SpectrumUse) -> Result<Rgb, LoadError> {
        match self.spectrum_samples(p)? {
            SpectrumValue::Constant(x) => Ok(spectrum::constant_spectrum_to_rgb(x, usage)),
            SpectrumValue::Pairs(w, v) => {
                spectrum::spectrum_to_rgb(&w, &v, usage).ok_or_else(|| {
                    self.err(p, "wavelengths must increase and values be finite")
                        .into_bad_spectrum()
                })
            }
        }
    }

    /// The samples of a `<spectrum>` without a plugin type: one value, or `wavelength:value`
    /// pairs, or an `.spd` file.
    pub(super) fn spectrum_samples(&self, p: &Node) -> Result<SpectrumValue, LoadError> {
        if let Some(value) = p.attr("value") {
            if !value.contains(':') {
                let n = numbers(value).map_err(|m| self.err(p, m))?;
                let [x] = n.as_slice() else {
                    return Err(self.err(
                        p,
                        "a <spectrum> value is one number or wavelength:value pairs",
                    ));
                };
                return Ok(SpectrumValue::Constant(*x));
            }
            let mut w = Vec::new();
            let mut v = Vec::new();
            for pair in value.split(',').map(str::trim).filter(|s| !s.is_empty()) {
                let (a, b) = pair
                    .split_once(':')
                    .ok_or_else(|| self.err(p, format!("\"{pair}\" is not wavelength:value")))?;
                w.push(
                    a.trim()
                        .parse::<f64>()
                        .map_err(|_| self.err(p, format!("\"{a}\" is not a number")))?,
                );
                v.push(
                    b.trim()
                        .parse::<f64>()
                        .map_err(|_| self.err(p, format!("\"{b}\" is not a number")))?,
                );
            }
            Ok(SpectrumValue::Pairs(w, v))
        } else if let Some(file) = p.attr("filename") {
            let path = self.doc.resolve(p, file);
            let (w, v) = read_spd(&path).map_err(|m| self.err(p, m))?;
            Ok(SpectrumValue::Pairs(w, v))
        } else {
            Err(self.err(p, "<spectrum> needs a value or a filename"))
        }
    }

    /// The spectrum of property `name` when it is one: measured `wavelength:value` pairs or an
    /// `.spd` file (validated: positive, increasing wavelengths, values ≥ 0), or a `blackbody`
    /// (Mitsuba's: Planck's radiance in W/(m² sr nm)). `None` for a colour or a constant.
    pub(super) fn measured_spectrum(
        &self,
        node: &'a Node,
        name: &str,
    ) -> Result<Option<scene::spectral::Spectrum>, LoadError> {
        use scene::spectral::{Blackbody, PiecewiseLinear, Spectrum};
        let Some(p) = prop(node, name) else {
            return Ok(None);
        };
        let p = self.deref(p)?;
        if p.tag != "spectrum" {
            return Ok(None);
        }
        match p.attr("type") {
            None => match self.spectrum_samples(p)? {
                SpectrumValue::Constant(_) => Ok(None),
                SpectrumValue::Pairs(w, v) => PiecewiseLinear::new(w, v)
                    .map(|s| Some(Spectrum::PiecewiseLinear(s)))
                    .map_err(|e| {
                        self.err(p, format!("{}: spectrum \"{name}\": {e}", node.label()))
                            .into_bad_spectrum()
                    }),
            },
            Some("blackbody") => {
                let t = self
                    .float(p, "temperature")?
                    .ok_or_else(|| self.err(p, "a blackbody needs a temperature"))?;
                let b = Blackbody::new(t).map_err(|e| {
                    self.err(p, format!("{}: spectrum \"{name}\": {e}", node.label()))
                        .into_bad_spectrum()
                })?;
                Ok(Some(Spectrum::Scaled(
                    b.peak_radiance() * 1e-9,
                    Box::new(Spectrum::Blackbody(b)),
                )))
            }
            Some(_) => Ok(None),
        }
    }

    /// The constant colour that stands in for a texture, with a warning.
    pub(super) fn texture_standin(&mut self, tex: &'a Node) -> Result<Rgb, LoadError> {
        let label = tex.label();
        match tex.attr("type") {
            Some("bitmap") => {
                let file = self
                    .string(tex, "filename")?
                    .ok_or_else(|| self.err(tex, "bitmap needs a filename"))?;
                let path = self.doc.resolve(tex, file);
                let (rgb, what) = builder::image_texture_standin(&path)
                    .map_err(|e| self.err(tex, e.to_string()))?;
                self.builder.warn(format!(
                    "{label} ({file}): this property cannot be textured in fppm; {what} {} stands in",
                    super::super::fmt_vec(rgb)
                ));
                Ok(rgb)
            }
            Some("checkerboard") => {
                let a = self
                    .colour(tex, "color0", SpectrumUse::Reflectance)?
                    .unwrap_or(Rgb::splat(0.4));
                let b = self
                    .colour(tex, "color1", SpectrumUse::Reflectance)?
                    .unwrap_or(Rgb::splat(0.2));
                let rgb = 0.5 * (a + b);
                self.builder.warn(format!(
                    "{label}: procedural textures are not supported; the mean of its two colours {} stands in",
                    super::super::fmt_vec(rgb)
                ));
                Ok(rgb)
            }
            _ => {
                let rgb = Rgb::splat(builder::TEXTURE_STANDIN_GREY);
                self.builder.warn(format!(
                    "{label}: this texture is not supported; grey {} stands in",
                    super::super::fmt_vec(rgb)
                ));
                Ok(rgb)
            }
        }
    }
}

/// A `<spectrum>`'s samples: one value, or wavelength and value lists.
pub(super) enum SpectrumValue {
    Constant(f64),
    Pairs(Vec<f64>, Vec<f64>),
}
