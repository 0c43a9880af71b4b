//! Participating media: `MakeNamedMedium` of type `homogeneous` and `uniformgrid` (pbrt-v4's
//! `sigma_a`, `sigma_s`, `scale` and `g`, and a grid's `density`, `nx`, `ny`, `nz`, `p0`,
//! `p1`, `src/pbrt/media.cpp`), and the media a `MediumInterface` puts on either side of the
//! shapes that follow it and around the camera (`docs/media.md`).

use std::sync::Arc;

use super::*;

/// The (interior, exterior) media of a shape: indices into the list, `None` for vacuum.
pub(super) type Sides = (Option<u32>, Option<u32>);

impl Parser {
    /// Converts `MakeNamedMedium "name" …` into a medium of the list. pbrt-v4's defaults: σa = σs = 1,
    /// scale 1, g 0.
    pub(super) fn named_medium(
        &mut self,
        name: String,
        params: &Params,
        loc: Loc,
    ) -> Result<(), LoadError> {
        let label = format!("MakeNamedMedium \"{name}\"");
        let ty = self
            .str_param(params, "type")?
            .ok_or_else(|| self.err(loc, format!("{label} needs a \"string type\"")))?;
        match ty.as_str() {
            "homogeneous" | "uniformgrid" => {}
            "rgbgrid" | "cloud" | "nanovdb" => {
                return Err(self.err(
                    loc,
                    format!("{label}: medium type \"{ty}\" is not supported, only homogeneous and uniformgrid"),
                ));
            }
            other => {
                return Err(self.err(loc, format!("{label}: unknown medium type \"{other}\"")));
            }
        }
        if let Some(preset) = self.str_param(params, "preset")?.filter(|p| !p.is_empty()) {
            return Err(self.err(
                loc,
                format!("{label}: the measured preset \"{preset}\" is not supported; give sigma_a and sigma_s"),
            ));
        }
        let le = self.colour(params, "Le", SpectrumUse::Emission)?;
        if le.is_some_and(|l| l.max_element() > 0.0) {
            return Err(self.err(
                loc,
                format!("{label}: emissive media (Le) are not supported"),
            ));
        }
        if self.medium_index.contains_key(&name) {
            return Err(self.err(loc, format!("{label} is defined twice")));
        }
        let sigma_a = self
            .colour(params, "sigma_a", SpectrumUse::Ior)?
            .unwrap_or(Rgb::ONE);
        let sigma_s = self
            .colour(params, "sigma_s", SpectrumUse::Ior)?
            .unwrap_or(Rgb::ONE);
        let scale = self.float(params, "scale")?.unwrap_or(1.0) as f32;
        let g = self.float(params, "g")?.unwrap_or(0.0) as f32;
        let density = if ty == "uniformgrid" {
            Some(Arc::new(self.uniform_grid(&label, params, loc)?))
        } else {
            None
        };
        // Negative, non-finite or out-of-range values are refused by the scene's validation.
        self.medium_index
            .insert(name.clone(), self.media.len() as u32);
        self.medium_locs.push(loc);
        self.media.push(scene::Medium {
            name,
            sigma_a: sigma_a * scale,
            sigma_s: sigma_s * scale,
            g,
            density,
        });
        Ok(())
    }

    /// A `uniformgrid` medium's density grid (pbrt-v4's `GridMedium::Create`): `float density`
    /// (nx·ny·nz values, x fastest), `integer nx, ny, nz` (default 1), `point3 p0, p1` (the
    /// box in the medium's space, default the unit cube), placed by the current transform
    /// (medium to world), read as pbrt's `SampledGrid` (zero outside the samples). Emission
    /// (`Le`, `Lescale`, `temperature`) is refused.
    fn uniform_grid(
        &mut self,
        label: &str,
        params: &Params,
        loc: Loc,
    ) -> Result<scene::DensityGrid, LoadError> {
        for emissive in ["temperature", "Lescale"] {
            if params.get(emissive).is_some() {
                return Err(self.err(
                    loc,
                    format!("{label}: emissive media (\"{emissive}\") are not supported"),
                ));
            }
        }
        let dim = |parser: &Self, axis: &str| -> Result<u32, LoadError> {
            let n = parser.int(params, axis)?.unwrap_or(1);
            u32::try_from(n)
                .map_err(|_| parser.err(loc, format!("{label}: \"{axis}\" must be >= 0, got {n}")))
        };
        let size = [dim(self, "nx")?, dim(self, "ny")?, dim(self, "nz")?];
        // A bad grid is a bad medium (exit 2), as a bad `.vol` file is.
        let bad = |e: scene::GridError| self.err(loc, format!("{label}: {e}")).into_bad_medium();
        // The dimensions are checked before the values are converted.
        scene::check_grid_size(u64::from(size[0]), u64::from(size[1]), u64::from(size[2]))
            .map_err(bad)?;
        let Some(p) = params.get("density") else {
            return Err(self.err(loc, format!("{label} needs a \"float density\"")));
        };
        self.expect_type(p, &["float"])?;
        let density: Vec<f32> = self.nums(p)?.into_iter().map(|x| x as f32).collect();
        let point = |parser: &Self, key: &str, default: Vec3| -> Result<Vec3, LoadError> {
            match parser.vec3s(params, key, &["point3", "point"])?.as_deref() {
                None => Ok(default),
                Some([p]) => Ok(*p),
                Some(_) => Err(parser.err(loc, format!("{label}: \"{key}\" needs one point"))),
            }
        };
        let p0 = point(self, "p0", Vec3::ZERO)?;
        let p1 = point(self, "p1", Vec3::ONE)?;
        let to_world = glam::Affine3A::from_mat4(self.state.ctm.as_mat4());
        scene::DensityGrid::new(size, density, scene::GridEdge::Zero, p0, p1, to_world).map_err(bad)
    }

    /// The index of the medium `name` ("" is vacuum), or an error at `loc` if none was made.
    pub(super) fn medium_named(&self, name: &str, loc: Loc) -> Result<Option<u32>, LoadError> {
        if name.is_empty() {
            return Ok(None);
        }
        self.medium_index
            .get(name)
            .copied()
            .map(Some)
            .ok_or_else(|| {
                self.err(
                    loc,
                    format!("MediumInterface: no MakeNamedMedium \"{name}\" in the scene"),
                )
            })
    }

    /// A shape's (interior, exterior) media if crossing it changes the medium, else `None`.
    pub(super) fn shape_media(&self, state: &State) -> Result<Option<Sides>, LoadError> {
        let Some(names) = &state.media else {
            return Ok(None);
        };
        let inside = self.medium_named(&names.inside, names.loc)?;
        let outside = self.medium_named(&names.outside, names.loc)?;
        Ok((inside != outside).then_some((inside, outside)))
    }
}
