//! Materials and the constant colours standing in for the textures fppm cannot use.

use super::*;

/// GGX α standing in for a perfectly smooth coating (`coateddiffuse` with roughness 0).
const SMOOTH_COAT_ALPHA: f32 = 0.01;
/// Below this α a conductor is a mirror.
const MIRROR_ALPHA: f32 = 1e-3;
/// Index of refraction of pbrt's coatings (the `coateddiffuse` default).
const COAT_IOR: f32 = 1.5;

impl Parser {
    /// The constant colour that stands in for texture `name`.
    pub(super) fn texture_standin(
        &mut self,
        name: &str,
        loc: Loc,
        depth: usize,
    ) -> Result<Rgb, LoadError> {
        if depth > 32 {
            return Err(self.err(loc, format!("texture \"{name}\" refers to itself")));
        }
        let def = self
            .textures
            .get(name)
            .cloned()
            .ok_or_else(|| self.err(loc, format!("unknown texture \"{name}\"")))?;
        let rgb = match def.class.as_str() {
            "imagemap" => {
                let file = self.str_param(&def.params, "filename")?.ok_or_else(|| {
                    self.err(
                        def.loc,
                        format!("imagemap texture \"{name}\" needs a filename"),
                    )
                })?;
                let path = self.resolve(&file);
                let (rgb, what) = builder::image_texture_standin(&path)
                    .map_err(|e| self.err(def.loc, e.to_string()))?;
                self.warn(format!(
                    "Texture \"{name}\" (imagemap {file}): this use cannot be textured in fppm; {what} {} stands in",
                    super::super::fmt_vec(rgb)
                ));
                rgb
            }
            "scale" => {
                let tex = self.sub_texture(&def, "tex", depth)?.unwrap_or(Rgb::ONE);
                let scale = self.sub_texture(&def, "scale", depth)?.unwrap_or(Rgb::ONE);
                tex * scale
            }
            "constant" => self.sub_texture(&def, "value", depth)?.unwrap_or(Rgb::ONE),
            "mix" => {
                let a = self.sub_texture(&def, "tex1", depth)?.unwrap_or(Rgb::ZERO);
                let b = self.sub_texture(&def, "tex2", depth)?.unwrap_or(Rgb::ONE);
                let t = self
                    .sub_texture(&def, "amount", depth)?
                    .unwrap_or(Rgb::splat(0.5));
                a * (Rgb::ONE - t) + b * t
            }
            "checkerboard" => {
                let a = self.sub_texture(&def, "tex1", depth)?.unwrap_or(Rgb::ONE);
                let b = self.sub_texture(&def, "tex2", depth)?.unwrap_or(Rgb::ZERO);
                let rgb = 0.5 * (a + b);
                self.warn(format!(
                    "Texture \"{name}\" (checkerboard): procedural textures are not supported; the mean of its two colours {} stands in",
                    super::super::fmt_vec(rgb)
                ));
                rgb
            }
            other => {
                let rgb = Rgb::splat(builder::TEXTURE_STANDIN_GREY);
                self.warn(format!(
                    "Texture \"{name}\" ({other}) is not supported; grey {} stands in",
                    super::super::fmt_vec(rgb)
                ));
                rgb
            }
        };
        Ok(rgb)
    }

    pub(super) fn sub_texture(
        &mut self,
        def: &TextureDef,
        name: &str,
        depth: usize,
    ) -> Result<Option<Rgb>, LoadError> {
        match def.params.get(name) {
            Some(p) if p.ty == "texture" => {
                let (t, loc) = self.texture_name(p, name)?;
                self.texture_standin(&t, loc, depth + 1).map(Some)
            }
            _ => self.colour(&def.params, name, SpectrumUse::Reflectance),
        }
    }

    /// pbrt's roughness → GGX α: `sqrt(r)` when `remaproughness` (the default).
    pub(super) fn alpha(
        &mut self,
        params: &Params,
        name: &str,
        remap: bool,
    ) -> Result<f32, LoadError> {
        let r = match params.get(name) {
            Some(p) if p.ty == "texture" => {
                self.warn(format!(
                    "a textured \"{name}\" is not supported; 0 stands in"
                ));
                0.0
            }
            Some(_) => self.float(params, name)?.unwrap_or(0.0),
            None => {
                let u = self.float(params, &format!("u{name}"))?;
                let v = self.float(params, &format!("v{name}"))?;
                match (u, v) {
                    (Some(u), Some(v)) => {
                        if u != v {
                            self.warn(format!("anisotropic u{name}/v{name} ({u}, {v}) are rendered isotropic with their mean"));
                        }
                        0.5 * (u + v)
                    }
                    (Some(x), None) | (None, Some(x)) => x,
                    (None, None) => 0.0,
                }
            }
        };
        if r < 0.0 {
            let p = [name.to_owned(), format!("u{name}"), format!("v{name}")]
                .iter()
                .find_map(|n| params.get(n));
            if let Some(p) = p {
                return Err(self.err(
                    Self::loc_of_param(p),
                    format!("parameter \"{}\" must be ≥ 0, got {r}", p.name),
                ));
            }
        }
        let r = r.max(0.0) as f32;
        Ok(if remap { r.sqrt() } else { r })
    }

    /// Converts a material definition; `None` for `interface` (invisible). An image texture
    /// of its (diffuse) reflectance goes to `color`.
    pub(super) fn material(
        &mut self,
        def: &MaterialDef,
        label: &str,
        color: &mut Option<scene::texture::TextureRef>,
        spectra: &mut scene::MaterialSpectra,
    ) -> Result<Option<MaterialKind>, LoadError> {
        let p = def.params.clone();
        let refl = SpectrumUse::Reflectance;
        let remap = self.boolean(&p, "remaproughness")?.unwrap_or(true);
        Ok(Some(match def.kind.as_str() {
            "diffuse" => {
                let (albedo, texture) = self
                    .textured_colour(&p, "reflectance")?
                    .unwrap_or((Rgb::splat(0.5), None));
                *color = texture;
                MaterialKind::Diffuse(scene::Diffuse { albedo })
            }
            "conductor" | "coatedconductor" => {
                let prefix = if def.kind == "coatedconductor" {
                    "conductor."
                } else {
                    ""
                };
                let (eta, k) = match self.colour(&p, &format!("{prefix}reflectance"), refl)? {
                    // pbrt-v4's reflectance form: η = 1 and k = 2√r/√(1 − r), whose Fresnel
                    // reflectance at normal incidence is r.
                    Some(r) => {
                        let r = r.clamp(Rgb::ZERO, Rgb::splat(0.9999));
                        (Rgb::ONE, 2.0 * r.powf(0.5) / (Rgb::ONE - r).powf(0.5))
                    }
                    None => self.conductor_ior(&p, prefix, def.loc, spectra)?,
                };
                let roughness = self.alpha(&p, &format!("{prefix}roughness"), remap)?;
                if def.kind == "coatedconductor" {
                    self.warn(format!(
                        "{label}: the dielectric coating of a coatedconductor is ignored"
                    ));
                }
                MaterialKind::Conductor(scene::Conductor {
                    eta,
                    k,
                    specular_reflectance: Rgb::ONE,
                    roughness: if roughness <= MIRROR_ALPHA {
                        0.0
                    } else {
                        roughness
                    },
                })
            }
            "dielectric" | "thindielectric" => {
                let eta = match p.get("eta") {
                    Some(e) if e.ty == "spectrum" => {
                        let law = self.ior_law(&p, "eta")?;
                        let eta = law.eval(scene::REPRESENTATIVE_WAVELENGTH) as f32;
                        if law.is_dispersive() {
                            spectra.ior = Some(law);
                        }
                        eta
                    }
                    Some(_) => self.float(&p, "eta")?.unwrap_or(1.5) as f32,
                    None => 1.5,
                };
                if def.kind == "thindielectric" {
                    self.warn(format!("{label}: a thin dielectric is rendered as a solid dielectric of the same ior (rays bend)"));
                }
                let roughness = self.alpha(&p, "roughness", remap)?;
                MaterialKind::dielectric(eta, roughness)
            }
            "coateddiffuse" => {
                let (reflectance, texture) = self
                    .textured_colour(&p, "reflectance")?
                    .unwrap_or((Rgb::splat(0.5), None));
                if texture.is_some() {
                    self.warn(format!(
                        "{label}: the reflectance texture tints the coating's reflection too \
                         (fppm's colour texture multiplies its whole glossy-over-diffuse material)"
                    ));
                }
                *color = texture;
                let alpha = self.alpha(&p, "roughness", remap)?;
                let alpha = if alpha > 0.0 {
                    alpha
                } else {
                    SMOOTH_COAT_ALPHA
                };
                let f0 = spectrum::dielectric_reflectance(
                    self.float(&p, "eta")?.map_or(COAT_IOR, |e| e as f32),
                );
                self.warn(format!(
                    "{label}: coateddiffuse is approximated by fppm's glossy-over-diffuse material (GGX alpha {alpha}, \
                     reflectance {f0:.4} = Fresnel at normal incidence, diffuse scaled by {:.4})",
                    1.0 - f0
                ));
                MaterialKind::Glossy(scene::Glossy {
                    reflectance: Rgb::splat(f0),
                    roughness: alpha,
                    diffuse: reflectance * (1.0 - f0),
                })
            }
            "interface" => return Ok(None),
            "mix" => {
                self.warn(format!(
                    "{label}: a mix material stands in as diffuse grey 0.5"
                ));
                MaterialKind::Diffuse(scene::Diffuse {
                    albedo: Rgb::splat(0.5),
                })
            }
            other => {
                self.warn(format!(
                    "{label}: material \"{other}\" is not supported; diffuse grey 0.5 stands in"
                ));
                MaterialKind::Diffuse(scene::Diffuse {
                    albedo: Rgb::splat(0.5),
                })
            }
        }))
    }
}

impl Parser {
    /// A conductor's RGB η and k from `eta` and `k` (pbrt-v4's default: copper), and its
    /// spectral ones in `spectra` where both are spectra: named metals get the RGB values
    /// Mitsuba 3 loads for them, measured spectra the RGB of Mitsuba's conversion.
    fn conductor_ior(
        &mut self,
        p: &Params,
        prefix: &str,
        loc: Loc,
        spectra: &mut scene::MaterialSpectra,
    ) -> Result<(Rgb, Rgb), LoadError> {
        let (eta_name, k_name) = (format!("{prefix}eta"), format!("{prefix}k"));
        let eta = self.colour(p, &eta_name, SpectrumUse::Ior)?;
        let k = self.colour(p, &k_name, SpectrumUse::Ior)?;
        let eta_s = self.measured_or_named(p, &eta_name)?;
        let k_s = self.measured_or_named(p, &k_name)?;
        let (ce, ck) = spectrum::metal("Cu").unwrap_or((Rgb::ONE, Rgb::ZERO));
        let (eta_s, k_s) = match (eta.is_none() && k.is_none(), eta_s, k_s) {
            (true, ..) => (
                scene::spectral::Conductor::named_spectrum("metal-Cu-eta"),
                scene::spectral::Conductor::named_spectrum("metal-Cu-k"),
            ),
            (false, e, k) => (e, k),
        };
        if let (Some(e), Some(k)) = (eta_s, k_s) {
            let loc = p.get(&eta_name).map_or(loc, Self::loc_of_param);
            spectra.conductor = Some(scene::spectral::Conductor::new(e, k).map_err(|e| {
                self.err(loc, format!("parameter \"{eta_name}\": {e}"))
                    .into_bad_spectrum()
            })?);
        }
        Ok((eta.unwrap_or(ce), k.unwrap_or(ck)))
    }

    /// A `spectrum` parameter as a validated measured spectrum: λ/value pairs, an `.spd` file or
    /// a named metal's η or k; `None` for other forms.
    fn measured_or_named(
        &self,
        p: &Params,
        name: &str,
    ) -> Result<Option<scene::spectral::PiecewiseLinear>, LoadError> {
        let Some(param) = p.get(name) else {
            return Ok(None);
        };
        let loc = Self::loc_of_param(param);
        if let [Value::Str(s)] = param.values.as_slice()
            && param.ty == "spectrum"
            && s.starts_with("metal-")
        {
            return Ok(scene::spectral::Conductor::named_spectrum(s));
        }
        match self.spectral(p, name)? {
            Some((w, v)) => scene::spectral::PiecewiseLinear::new(w, v)
                .map(Some)
                .map_err(|e| {
                    self.err(loc, format!("parameter \"spectrum {name}\": {e}"))
                        .into_bad_spectrum()
                }),
            None => Ok(None),
        }
    }

    /// A dielectric's `spectrum eta` as a dispersion law: a named glass, λ/value pairs or an
    /// `.spd` file (at least 1 over 360–830 nm).
    fn ior_law(&self, p: &Params, name: &str) -> Result<scene::spectral::Ior, LoadError> {
        use scene::spectral::Ior;
        let Some(param) = p.get(name) else {
            return Ok(Ior::Constant(1.5));
        };
        let loc = Self::loc_of_param(param);
        if let [Value::Str(s)] = param.values.as_slice()
            && let Some(ior) = Ior::named(s)
        {
            return Ok(ior);
        }
        if let [Value::Str(s)] = param.values.as_slice()
            && (s.starts_with("glass-") || s.starts_with("metal-"))
        {
            return Err(self.err(
                loc,
                format!(
                    "parameter \"spectrum {name}\": unknown named spectrum \"{s}\" (glasses: {})",
                    Ior::NAMES.join(", ")
                ),
            )
            .into_bad_spectrum());
        }
        let measured = self.measured_or_named(p, name)?.ok_or_else(|| {
            self.err(
                loc,
                format!("parameter \"spectrum {name}\" must be a glass or λ/value pairs"),
            )
        })?;
        Ior::tabulated(measured).map_err(|e| {
            self.err(loc, format!("parameter \"spectrum {name}\": {e}"))
                .into_bad_spectrum()
        })
    }
}
