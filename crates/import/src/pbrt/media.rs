//! Participating media: `MakeNamedMedium` of type `homogeneous` (pbrt-v4's `sigma_a`,
//! `sigma_s`, `scale` and `g`, `src/pbrt/media.cpp`), and the media a `MediumInterface` puts on
//! either side of the shapes that follow it and around the camera (`docs/media.md`).

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
            "homogeneous" => {}
            "uniformgrid" | "rgbgrid" | "cloud" | "nanovdb" => {
                return Err(self.err(
                    loc,
                    format!("{label}: heterogeneous media (\"{ty}\") are not supported, only homogeneous"),
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
        // Negative, non-finite or out-of-range values are refused by the scene's validation.
        self.medium_index
            .insert(name.clone(), self.media.len() as u32);
        self.media.push(scene::Medium {
            name,
            sigma_a: sigma_a * scale,
            sigma_s: sigma_s * scale,
            g,
        });
        Ok(())
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
