//! Mitsuba's `bitmap` textures as fppm image textures (`src/textures/bitmap.cpp`), and the
//! `mask` BSDF's opacity as a cut-out (`src/bsdfs/mask.cpp`).
//!
//! Conventions, from Mitsuba 3's source:
//! - a bitmap looks up `to_uv · si.uv` in a texture whose first row is the image's top row, so
//!   v = 0 is the top of the image: fppm's convention, and Mitsuba's uv are used as they are
//!   (its OBJ reader flips v by default, as fppm's does; PLY, `.serialized` and `rectangle`
//!   uv are not flipped);
//! - `to_uv` is a 3×3 affine transform; a 4×4 matrix keeps its x and y rows and columns and
//!   its translation column (`Transform::extract`);
//! - 8-bit images are sRGB-decoded unless `raw`; alpha channels are dropped (a Y+A image is
//!   read as Y, RGBA as RGB), so an opacity is the first channel;
//! - `mask` renders the nested BSDF with probability `opacity` and lets the ray through
//!   otherwise: fppm's stochastic cut-out.

use super::*;
use scene::texture::{Alpha, AlphaMode, TextureRef, Wrap};

/// A colour that may be an image: the constant factor and the texture it multiplies.
pub(super) type Textured = (Rgb, Option<TextureRef>);

impl<'a> Importer<'a> {
    /// A colour property that may be a `bitmap` (nested or by `<ref>`): the bitmap becomes an
    /// image texture (factor one); any other colour is read by [`Importer::colour`], other
    /// textures standing in as constants there.
    pub(super) fn textured_colour(
        &mut self,
        node: &'a Node,
        name: &str,
        usage: SpectrumUse,
    ) -> Result<Option<Textured>, LoadError> {
        if let Some(p) = prop(node, name) {
            let p = self.deref(p)?;
            if p.tag == "texture" && p.attr("type") == Some("bitmap") {
                return Ok(Some((Rgb::ONE, Some(self.bitmap(p)?))));
            }
        }
        Ok(self.colour(node, name, usage)?.map(|rgb| (rgb, None)))
    }

    /// A `<texture type="bitmap">` as an image texture.
    pub(super) fn bitmap(&mut self, tex: &'a Node) -> Result<TextureRef, LoadError> {
        let label = tex.label();
        let file = self
            .string(tex, "filename")?
            .ok_or_else(|| self.err(tex, "bitmap needs a filename"))?;
        let path = self.doc.resolve(tex, file);
        let image = self
            .images
            .load(&path)
            .map_err(|e| self.err(tex, e.to_string()))?;
        let raw = self.boolean(tex, "raw")?.unwrap_or(false);
        match self.string(tex, "filter_type")?.unwrap_or("bilinear") {
            "bilinear" => {}
            "nearest" => self.builder.warn(format!(
                "{label} ({file}): nearest filtering is rendered bilinear"
            )),
            other => {
                return Err(self.err(
                    tex,
                    format!("filter_type \"{other}\" is not bilinear or nearest"),
                ));
            }
        }
        let wrap = match self.string(tex, "wrap_mode")?.unwrap_or("repeat") {
            "repeat" => Wrap::Repeat,
            "mirror" => Wrap::Mirror,
            "clamp" => Wrap::Clamp,
            other => {
                return Err(self.err(
                    tex,
                    format!("wrap_mode \"{other}\" is not repeat, mirror or clamp"),
                ));
            }
        };
        let m = self.transform(tex, "to_uv")?;
        let transform = [
            m.x_axis.x, m.y_axis.x, m.x_axis.y, m.y_axis.y, m.w_axis.x, m.w_axis.y,
        ]
        .map(|v| v as f32);
        Ok(TextureRef {
            image,
            srgb: !raw,
            wrap: [wrap; 2],
            transform,
        })
    }

    /// The cut-out of a `mask` BSDF: its `opacity` (0.5 by default, Mitsuba's), a constant or a
    /// bitmap, as a stochastic cut-out; another texture stands in as its constant.
    pub(super) fn mask_opacity(&mut self, node: &'a Node) -> Result<Alpha, LoadError> {
        let (factor, texture) = self
            .textured_colour(node, "opacity", SpectrumUse::Reflectance)?
            .unwrap_or((Rgb::splat(0.5), None));
        Ok(Alpha {
            texture,
            factor: factor.x,
            mode: AlphaMode::Blend,
        })
    }
}
