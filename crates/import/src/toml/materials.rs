//! Materials of a TOML scene: each `[materials.NAME]` table to a scene material, with its
//! colour inputs (a colour, or an image texture) and its textures.

use glam::Vec3;
use scene::texture::{Alpha, AlphaMode, MaterialTextures, TextureRef};
use scene::{Material, MaterialKind};

use super::convert::Converter;
use super::schema::*;
use crate::error::LoadError;

impl Converter<'_> {
    pub(super) fn material(&self, name: &str, m: MaterialToml) -> Result<Material, LoadError> {
        let key = |k: &str| format!("[materials.{name}] {k}");
        let mut color = None;
        let mut cutout_file = None;
        let (kind, emission) = match m {
            MaterialToml::Diffuse {
                albedo,
                emission,
                cutout,
            } => {
                cutout_file = cutout;
                let (albedo, texture) = self.colour_input(&key("albedo"), albedo, true)?;
                color = texture;
                (MaterialKind::Diffuse(scene::Diffuse { albedo }), emission)
            }
            MaterialToml::Mirror {
                reflectance,
                emission,
                cutout,
            } => {
                cutout_file = cutout;
                let (reflectance, texture) = self.colour_input(
                    &key("reflectance"),
                    reflectance.unwrap_or(ColorToml::Rgb([1.0; 3])),
                    true,
                )?;
                color = texture;
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
                let ior = self.positive(&key("ior"), ior)?;
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
                let (reflectance, texture) =
                    self.colour_input(&key("reflectance"), reflectance, true)?;
                color = texture;
                (
                    MaterialKind::Glossy(scene::Glossy {
                        reflectance,
                        roughness: self.positive(&key("roughness"), roughness)?,
                        diffuse: Vec3::ZERO,
                    }),
                    emission,
                )
            }
        };
        let (emission, emission_texture) = match emission {
            Some(e) => self.colour_input(&key("emission"), e, false)?,
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
            textures: (!textures.is_empty()).then(|| std::sync::Arc::new(textures)),
            spectra: None,
        })
    }

    /// A colour given as `[r, g, b]` or as `{ texture = "file", scale = [r, g, b] }`: the
    /// constant colour (the scale, 1 by default) and the texture, if any, read relative to the
    /// scene file. A `reflectance` must be at most 1 (the texture's texels are not checked:
    /// 8-bit colours are at most 1, and HDR images belong to emission).
    fn colour_input(
        &self,
        key: &str,
        input: ColorToml,
        reflectance: bool,
    ) -> Result<(Vec3, Option<TextureRef>), LoadError> {
        let check = |v| {
            if reflectance {
                self.reflectance(key, v)
            } else {
                self.colour(key, v)
            }
        };
        match input {
            ColorToml::Rgb(v) => Ok((check(v)?, None)),
            ColorToml::Texture { texture, scale } => {
                let scale = check(scale.unwrap_or([1.0; 3]))?;
                let image = self.textures.borrow_mut().load(&self.dir.join(texture))?;
                Ok((scale, Some(TextureRef::new(image, true))))
            }
        }
    }
}
