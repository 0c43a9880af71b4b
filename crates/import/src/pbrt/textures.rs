//! pbrt's `imagemap` textures (and `scale` textures of one) as fppm image textures, from
//! pbrt-v4's `src/pbrt/textures.{h,cpp}`:
//! - the `uv` mapping gives (s, t) = (uscale·u + udelta, vscale·v + vdelta), and the lookup
//!   flips t (`c.st[1] = 1 - c.st[1]`, "texture coordinates are (0,0) in the lower left
//!   corner, but image coordinates are (0,0) in the upper left"). fppm's meshes carry
//!   v' = 1 − v ([`IndexedMesh::flip_v`]), so the image coordinates are
//!   (uscale·u + udelta, vscale·v' + 1 − vscale − vdelta): the texture transform below;
//! - `encoding` (sRGB by default) applies to PNG files only; other 8-bit files (JPEG, ...) are
//!   read through stb_image as sRGB whatever it says; EXR and HDR are linear;
//! - `scale` multiplies the texel, `invert` takes 1 − texel (not supported here: warned).

use super::*;
use scene::texture::{TextureRef, Wrap};

/// A colour that may be an image: the constant factor and the texture it multiplies.
pub(super) type Textured = (Rgb, Option<TextureRef>);

impl Parser {
    /// A colour parameter that may be a `texture` of an imagemap (directly or through a
    /// `scale` texture): the image becomes a texture, the rest its factor. Anything else is
    /// read by [`Parser::colour`] (other textures stand in as constants there).
    pub(super) fn textured_colour(
        &mut self,
        params: &Params,
        name: &str,
    ) -> Result<Option<Textured>, LoadError> {
        match params.get(name) {
            Some(p) if p.ty == "texture" => {
                let (t, loc) = self.texture_name(p, name)?;
                self.texture_value(&t, loc, 0).map(Some)
            }
            _ => Ok(self
                .colour(params, name, SpectrumUse::Reflectance)?
                .map(|c| (c, None))),
        }
    }

    /// Texture `name` as a factor times an optional image.
    fn texture_value(&mut self, name: &str, loc: Loc, depth: usize) -> Result<Textured, LoadError> {
        if depth > 32 {
            return Err(self.err(loc, format!("texture \"{name}\" refers to itself")));
        }
        let def = self
            .textures
            .get(name)
            .cloned()
            .ok_or_else(|| self.err(loc, format!("unknown texture \"{name}\"")))?;
        match def.class.as_str() {
            "imagemap" => self.imagemap(name, &def),
            "scale" => {
                let (a, ta) = self
                    .sub_value(&def, "tex", depth)?
                    .unwrap_or((Rgb::ONE, None));
                let (b, tb) = self
                    .sub_value(&def, "scale", depth)?
                    .unwrap_or((Rgb::ONE, None));
                match (ta, tb) {
                    (Some(t), None) | (None, Some(t)) => Ok((a * b, Some(t))),
                    (None, None) => Ok((a * b, None)),
                    (Some(t), Some(other)) => {
                        // One image per colour: the second stands in as its mean.
                        let mean = other.image.mean(other.srgb);
                        self.warn(format!(
                            "Texture \"{name}\" (scale of two images): fppm textures a colour with one image; \
                             the mean colour {} of {} stands in for the second",
                            super::super::fmt_vec(mean),
                            other.image.path().display()
                        ));
                        Ok((a * b * mean, Some(t)))
                    }
                }
            }
            _ => Ok((self.texture_standin(name, loc, depth)?, None)),
        }
    }

    fn sub_value(
        &mut self,
        def: &TextureDef,
        name: &str,
        depth: usize,
    ) -> Result<Option<Textured>, LoadError> {
        match def.params.get(name) {
            Some(p) if p.ty == "texture" => {
                let (t, loc) = self.texture_name(p, name)?;
                self.texture_value(&t, loc, depth + 1).map(Some)
            }
            _ => Ok(self
                .colour(&def.params, name, SpectrumUse::Reflectance)?
                .map(|c| (c, None))),
        }
    }

    /// An `imagemap` texture: its image with pbrt's encoding, wrap mode and uv mapping; the
    /// factor is its `scale`.
    fn imagemap(&mut self, name: &str, def: &TextureDef) -> Result<Textured, LoadError> {
        let p = &def.params;
        let file = self.str_param(p, "filename")?.ok_or_else(|| {
            self.err(
                def.loc,
                format!("imagemap texture \"{name}\" needs a filename"),
            )
        })?;
        let path = self.resolve(&file);
        let image = self
            .images
            .load(&path)
            .map_err(|e| self.err(def.loc, e.to_string()))?;
        let label = format!("Texture \"{name}\" (imagemap {file})");
        let png = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("png"));
        let srgb = match self.str_param(p, "encoding")? {
            Some(e) if png && e == "linear" => false,
            Some(e) if png && e.starts_with("gamma") => {
                self.warn(format!(
                    "{label}: encoding \"{e}\" is decoded with the sRGB curve"
                ));
                true
            }
            _ => true,
        };
        let wrap = match self.str_param(p, "wrap")?.as_deref().unwrap_or("repeat") {
            "repeat" => Wrap::Repeat,
            "clamp" => Wrap::Clamp,
            other @ ("black" | "octahedralsphere") => {
                self.warn(format!(
                    "{label}: wrap mode \"{other}\" is not supported; clamp stands in"
                ));
                Wrap::Clamp
            }
            other => {
                return Err(self.err(def.loc, format!("{label}: unknown wrap mode \"{other}\"")));
            }
        };
        if let Some(m) = self.str_param(p, "mapping")?
            && m != "uv"
        {
            self.warn(format!(
                "{label}: the {m} mapping is not supported; the uv mapping stands in"
            ));
        }
        if self.boolean(p, "invert")? == Some(true) {
            self.warn(format!(
                "{label}: invert is not supported; the image is used as it is"
            ));
        }
        let num = |s: &mut Self, key: &str, default: f64| -> Result<f32, LoadError> {
            Ok(s.float(p, key)?.unwrap_or(default) as f32)
        };
        let (su, sv) = (num(self, "uscale", 1.0)?, num(self, "vscale", 1.0)?);
        let (du, dv) = (num(self, "udelta", 0.0)?, num(self, "vdelta", 0.0)?);
        let scale = num(self, "scale", 1.0)?;
        Ok((
            Rgb::splat(scale),
            Some(TextureRef {
                image,
                srgb,
                wrap: [wrap; 2],
                transform: [su, 0.0, 0.0, sv, du, 1.0 - sv - dv],
            }),
        ))
    }
}
