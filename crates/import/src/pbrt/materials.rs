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
                let r0 = match self.colour(&p, &format!("{prefix}reflectance"), refl)? {
                    Some(r) => r,
                    None if self.spectral(&p, &format!("{prefix}eta"))?.is_some()
                        && self.spectral(&p, &format!("{prefix}k"))?.is_some() =>
                    {
                        // Both measured spectra: the reflectance is computed per wavelength.
                        let (Some(eta), Some(k)) = (
                            self.spectral(&p, &format!("{prefix}eta"))?,
                            self.spectral(&p, &format!("{prefix}k"))?,
                        ) else {
                            return Err(self.err(def.loc, "conductor spectra vanished"));
                        };
                        spectrum::conductor_reflectance_spectral((&eta.0, &eta.1), (&k.0, &k.1))
                            .ok_or_else(|| {
                                self.err(def.loc, format!("{label}: malformed eta or k spectrum"))
                            })?
                    }
                    None => {
                        let eta = self.colour(&p, &format!("{prefix}eta"), SpectrumUse::Ior)?;
                        let k = self.colour(&p, &format!("{prefix}k"), SpectrumUse::Ior)?;
                        let (eta, k) = match (eta, k) {
                            (Some(e), Some(k)) => (e, k),
                            (e, k) => {
                                let (ce, ck) =
                                    spectrum::metal("Cu").unwrap_or((Rgb::ONE, Rgb::ZERO));
                                (e.unwrap_or(ce), k.unwrap_or(ck))
                            }
                        };
                        spectrum::conductor_reflectance(eta, k)
                    }
                };
                let alpha = self.alpha(&p, &format!("{prefix}roughness"), remap)?;
                self.warn(format!(
                    "{label}: the conductor uses its reflectance at normal incidence {} (no angular Fresnel)",
                    super::super::fmt_vec(r0)
                ));
                if def.kind == "coatedconductor" {
                    self.warn(format!(
                        "{label}: the dielectric coating of a coatedconductor is ignored"
                    ));
                }
                if alpha <= MIRROR_ALPHA {
                    MaterialKind::Mirror(scene::Mirror { reflectance: r0 })
                } else {
                    MaterialKind::Glossy(scene::Glossy {
                        reflectance: r0,
                        roughness: alpha,
                        diffuse: Rgb::ZERO,
                    })
                }
            }
            "dielectric" | "thindielectric" => {
                let eta = match p.get("eta") {
                    Some(e) if e.ty == "spectrum" => self
                        .colour(&p, "eta", SpectrumUse::Ior)?
                        .map_or(1.5, |c| c.y),
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
