//! BSDFs converted to fppm's materials.

use super::*;

/// GGX α that stands in for a perfectly smooth coating (`plastic`), which fppm's glossy
/// material cannot make delta.
const SMOOTH_COAT_ALPHA: f32 = 0.01;
/// Below this α a rough conductor is rendered as a mirror.
const MIRROR_ALPHA: f32 = 1e-3;

/// Mitsuba's named dielectric indices of refraction (`include/mitsuba/render/ior.h`).
const IOR_TABLE: &[(&str, f32)] = &[
    ("vacuum", 1.0),
    ("helium", 1.000_036),
    ("hydrogen", 1.000_132),
    ("air", 1.000_277),
    ("carbon dioxide", 1.000_45),
    ("water", 1.333),
    ("acetone", 1.36),
    ("ethanol", 1.361),
    ("carbon tetrachloride", 1.461),
    ("glycerol", 1.4729),
    ("benzene", 1.501),
    ("silicone oil", 1.520_45),
    ("bromine", 1.661),
    ("water ice", 1.31),
    ("fused quartz", 1.458),
    ("pyrex", 1.47),
    ("acrylic glass", 1.49),
    ("polypropylene", 1.49),
    ("bk7", 1.5046),
    ("sodium chloride", 1.544),
    ("amber", 1.55),
    ("pet", 1.575),
    ("diamond", 2.419),
];

impl<'a> Importer<'a> {
    /// Converts a BSDF (cached by element, so shared BSDFs warn once).
    pub(super) fn bsdf(&mut self, node: &'a Node) -> Result<ConvertedBsdf, LoadError> {
        let key = std::ptr::from_ref(node) as usize;
        if let Some(c) = self.bsdf_cache.get(&key) {
            return Ok(c.clone());
        }
        let name = node
            .attr("id")
            .map(str::to_owned)
            .unwrap_or_else(|| format!("{}@{}", node.attr("type").unwrap_or("bsdf"), node.line));
        let mut textures = MaterialTextures::default();
        let mut spectra = scene::MaterialSpectra::default();
        let kind = self.bsdf_kind(node, &name, &mut textures, &mut spectra)?;
        let textures = (!textures.is_empty()).then(|| std::sync::Arc::new(textures));
        let spectra = (!spectra.is_empty()).then(|| std::sync::Arc::new(spectra));
        let c = ConvertedBsdf {
            name,
            kind,
            textures,
            spectra,
        };
        self.bsdf_cache.insert(key, c.clone());
        Ok(c)
    }

    /// The first nested BSDF of a wrapper (`twosided`, `mask`, …).
    pub(super) fn inner_bsdf(&self, node: &'a Node) -> Result<&'a Node, LoadError> {
        for child in &node.children {
            let t = self.deref(child)?;
            if t.tag == "bsdf" {
                return Ok(t);
            }
        }
        Err(self.err(node, "needs a nested <bsdf>"))
    }

    pub(super) fn ior(&self, node: &Node, name: &str, default: f32) -> Result<f32, LoadError> {
        let Some(p) = prop(node, name) else {
            return Ok(default);
        };
        match p.tag.as_str() {
            "float" => Ok(self.float(node, name)?.unwrap_or(f64::from(default)) as f32),
            "string" => {
                let v = self.value(p)?.to_ascii_lowercase();
                IOR_TABLE
                    .iter()
                    .find(|(n, _)| *n == v)
                    .map(|(_, x)| *x)
                    .ok_or_else(|| {
                        self.err(
                            p,
                            format!("unknown material \"{v}\" for an index of refraction"),
                        )
                    })
            }
            other => Err(self.err(
                p,
                format!("property \"{name}\" must be a <float> or <string>, got <{other}>"),
            )),
        }
    }

    pub(super) fn alpha(&mut self, node: &'a Node, label: &str) -> Result<f32, LoadError> {
        if let Some(d) = self.string(node, "distribution")?
            && d != "ggx"
        {
            self.builder.warn(format!(
                "{label}: the {d} distribution is rendered as GGX with the same alpha"
            ));
        }
        let alpha = self.float(node, "alpha")?;
        let (u, v) = (self.float(node, "alpha_u")?, self.float(node, "alpha_v")?);
        let alpha = match (alpha, u, v) {
            (Some(a), _, _) => a,
            (None, Some(u), Some(v)) => {
                self.builder.warn(format!(
                    "{label}: anisotropic roughness ({u}, {v}) is rendered isotropic with alpha {}",
                    0.5 * (u + v)
                ));
                0.5 * (u + v)
            }
            _ => 0.1,
        };
        if prop(node, "alpha").is_some_and(|p| p.tag != "float") {
            self.builder.warn(format!(
                "{label}: a textured alpha is not supported; 0.1 stands in"
            ));
        }
        Ok(alpha as f32)
    }

    /// The scattering model of a BSDF; its image textures go to `textures`.
    pub(super) fn bsdf_kind(
        &mut self,
        node: &'a Node,
        name: &str,
        textures: &mut MaterialTextures,
        spectra: &mut scene::MaterialSpectra,
    ) -> Result<Option<MaterialKind>, LoadError> {
        let label = node.label();
        let ty = node.attr("type").unwrap_or("");
        let refl = SpectrumUse::Reflectance;
        Ok(Some(match ty {
            "diffuse" => {
                let (albedo, texture) = self
                    .textured_colour(node, "reflectance", refl)?
                    .unwrap_or((Rgb::splat(DEFAULT_REFLECTANCE), None));
                textures.color = texture;
                MaterialKind::Diffuse(scene::Diffuse { albedo })
            }
            "twosided" => {
                let inner = self.inner_bsdf(node)?;
                let inner = self.bsdf(inner)?;
                *textures = inner.textures.as_deref().cloned().unwrap_or_default();
                *spectra = inner.spectra.as_deref().cloned().unwrap_or_default();
                return Ok(inner.kind);
            }
            "mask" => {
                let inner = self.inner_bsdf(node)?;
                let inner = self.bsdf(inner)?;
                *textures = inner.textures.as_deref().cloned().unwrap_or_default();
                *spectra = inner.spectra.as_deref().cloned().unwrap_or_default();
                textures.alpha = Some(self.mask_opacity(node)?);
                return Ok(inner.kind);
            }
            "bumpmap" | "normalmap" | "blendbsdf" => {
                let what = match ty {
                    "blendbsdf" => "only its first BSDF is used",
                    _ => "the normal perturbation is ignored",
                };
                self.builder
                    .warn(format!("{label}: {what}; the nested BSDF stands in"));
                let inner = self.inner_bsdf(node)?;
                let inner = self.bsdf(inner)?;
                *textures = inner.textures.as_deref().cloned().unwrap_or_default();
                *spectra = inner.spectra.as_deref().cloned().unwrap_or_default();
                return Ok(inner.kind);
            }
            "conductor" | "roughconductor" => {
                let alpha = if ty == "roughconductor" {
                    self.alpha(node, &label)?
                } else {
                    0.0
                };
                if !(alpha.is_finite() && alpha >= 0.0) {
                    let p = prop(node, "alpha").unwrap_or(node);
                    return Err(self.err(p, format!("alpha must be ≥ 0, got {alpha}")));
                }
                let roughness = if alpha <= MIRROR_ALPHA { 0.0 } else { alpha };
                match self.conductor(node, spectra)? {
                    // Mitsuba's `none`: a perfect mirror at every angle, tinted.
                    ConductorIor::None(reflectance) if roughness == 0.0 => {
                        MaterialKind::Mirror(scene::Mirror { reflectance })
                    }
                    ConductorIor::None(reflectance) => MaterialKind::Glossy(scene::Glossy {
                        reflectance,
                        roughness,
                        diffuse: Rgb::ZERO,
                    }),
                    ConductorIor::Complex {
                        eta,
                        k,
                        specular_reflectance,
                    } => MaterialKind::Conductor(scene::Conductor {
                        eta,
                        k,
                        specular_reflectance,
                        roughness,
                    }),
                }
            }
            "dielectric" | "thindielectric" | "roughdielectric" => {
                let int = self.ior(node, "int_ior", 1.5046)?;
                let ext = self.ior(node, "ext_ior", 1.000_277)?;
                if ty == "thindielectric" {
                    self.builder.warn(format!(
                        "{label}: a thin dielectric is rendered as a solid dielectric of the same ior (rays bend)"
                    ));
                }
                if prop(node, "specular_reflectance").is_some()
                    || prop(node, "specular_transmittance").is_some()
                {
                    self.builder.warn(format!(
                        "{label}: specular_reflectance/transmittance are ignored (fppm's dielectric is clear)"
                    ));
                }
                let roughness = if ty == "roughdielectric" {
                    let alpha = self.alpha(node, &label)?;
                    if alpha.is_nan() || alpha < 0.0 {
                        let p = prop(node, "alpha").unwrap_or(node);
                        return Err(self.err(p, format!("alpha must be ≥ 0, got {alpha}")));
                    }
                    alpha
                } else {
                    0.0
                };
                if int.is_nan() || ext.is_nan() || int <= 0.0 || ext <= 0.0 {
                    return Err(self.err(
                        node,
                        format!("int_ior and ext_ior must be > 0, got {int} and {ext}"),
                    ));
                }
                MaterialKind::dielectric(int / ext, roughness)
            }
            "plastic" | "roughplastic" => {
                let int = self.ior(node, "int_ior", 1.49)?;
                let ext = self.ior(node, "ext_ior", 1.000_277)?;
                let f0 = spectrum::dielectric_reflectance(int / ext);
                let specular = self
                    .colour(node, "specular_reflectance", refl)?
                    .unwrap_or(Rgb::ONE);
                let (diffuse, texture) = self
                    .textured_colour(node, "diffuse_reflectance", refl)?
                    .unwrap_or((Rgb::splat(DEFAULT_REFLECTANCE), None));
                if texture.is_some() {
                    self.builder.warn(format!(
                        "{label}: the diffuse_reflectance bitmap tints the coating's reflection too \
                         (fppm's colour texture multiplies its whole glossy-over-diffuse material)"
                    ));
                }
                textures.color = texture;
                let alpha = if ty == "roughplastic" {
                    self.alpha(node, &label)?
                } else {
                    SMOOTH_COAT_ALPHA
                };
                self.builder.warn(format!(
                    "{label}: plastic is approximated by fppm's glossy-over-diffuse material (GGX alpha {alpha}, \
                     reflectance {f0:.4} = Fresnel at normal incidence, diffuse scaled by {:.4})",
                    1.0 - f0
                ));
                MaterialKind::Glossy(scene::Glossy {
                    reflectance: specular * f0,
                    roughness: if alpha > 0.0 {
                        alpha
                    } else {
                        SMOOTH_COAT_ALPHA
                    },
                    diffuse: diffuse * (1.0 - f0),
                })
            }
            "principled" => {
                let base = self
                    .colour(node, "base_color", refl)?
                    .unwrap_or(Rgb::splat(DEFAULT_REFLECTANCE));
                self.builder.warn(format!(
                    "{label}: the principled BSDF is approximated by a diffuse one of its base_color"
                ));
                MaterialKind::Diffuse(scene::Diffuse { albedo: base })
            }
            "null" => {
                self.builder.warn(format!(
                    "{label}: shapes with a null BSDF are invisible; skipped"
                ));
                return Ok(None);
            }
            other => {
                let grey = Rgb::splat(DEFAULT_REFLECTANCE);
                self.builder.warn(format!(
                    "{label}: the {other} BSDF is not supported; a diffuse grey {} stands in (material {name:?})",
                    super::super::fmt_vec(grey)
                ));
                MaterialKind::Diffuse(scene::Diffuse { albedo: grey })
            }
        }))
    }

    /// The complex index of refraction of a (rough) conductor from its `material` (Mitsuba's RGB
    /// η and k of the name, and pbrt-v4's spectra where fppm has them) or `eta`/`k` (colours, or
    /// spectra converted as Mitsuba's RGB variants convert them, kept in `spectra`), with its
    /// `specular_reflectance`.
    fn conductor(
        &mut self,
        node: &'a Node,
        spectra: &mut scene::MaterialSpectra,
    ) -> Result<ConductorIor, LoadError> {
        let specular = self
            .colour(node, "specular_reflectance", SpectrumUse::Reflectance)?
            .unwrap_or(Rgb::ONE);
        let eta = self.colour(node, "eta", SpectrumUse::Ior)?;
        let k = self.colour(node, "k", SpectrumUse::Ior)?;
        let material = self.string(node, "material")?;
        let (eta, k) = match (eta, k, material) {
            (Some(eta), k, _) => {
                let eta_spectrum = self.measured_spectrum(node, "eta")?;
                let k_spectrum = self.measured_spectrum(node, "k")?;
                if let Some(scene::spectral::Spectrum::PiecewiseLinear(eta_s)) = eta_spectrum {
                    let k_s = match k_spectrum {
                        Some(scene::spectral::Spectrum::PiecewiseLinear(k_s)) => k_s,
                        // A constant or RGB k: held flat over η's wavelengths.
                        _ => {
                            let k0 = f64::from(k.unwrap_or(Rgb::ZERO).y);
                            let values = vec![k0; eta_s.lambdas().len()];
                            scene::spectral::PiecewiseLinear::new(eta_s.lambdas().to_vec(), values)
                                .map_err(|e| {
                                    self.err(node, format!("{}: k: {e}", node.label()))
                                        .into_bad_spectrum()
                                })?
                        }
                    };
                    let p = prop(node, "eta").unwrap_or(node);
                    spectra.conductor =
                        Some(scene::spectral::Conductor::new(eta_s, k_s).map_err(|e| {
                            self.err(p, format!("{}: eta: {e}", node.label()))
                                .into_bad_spectrum()
                        })?);
                }
                (eta, k.unwrap_or(Rgb::ZERO))
            }
            (None, _, None | Some("none")) => return Ok(ConductorIor::None(specular)),
            (None, _, Some(m)) => {
                let (eta, k) = spectrum::metal(m).ok_or_else(|| {
                    let p = prop(node, "material").unwrap_or(node);
                    self.err(
                        p,
                        format!("{}: unknown conductor material \"{m}\"", node.label()),
                    )
                    .into_bad_spectrum()
                })?;
                spectra.conductor = scene::spectral::Conductor::named(m);
                (eta, k)
            }
        };
        Ok(ConductorIor::Complex {
            eta,
            k,
            specular_reflectance: specular,
        })
    }
}

/// What a conductor's index of refraction is.
enum ConductorIor {
    /// Mitsuba's `none`: reflects everything, times this tint.
    None(Rgb),
    /// A complex index of refraction.
    Complex {
        eta: Rgb,
        k: Rgb,
        specular_reflectance: Rgb,
    },
}
