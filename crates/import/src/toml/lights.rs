//! Lights and the environment of a TOML scene: `[[lights]]` tables to delta lights, and
//! `[environment]` to the environment light (a constant or an equirectangular map).

use scene::Light;

use super::convert::Converter;
use super::schema::*;
use crate::error::LoadError;

impl Converter<'_> {
    pub(super) fn light(&self, context: &str, l: LightToml) -> Result<Light, LoadError> {
        let key = |k: &str| format!("{context} {k}");
        Ok(match l {
            LightToml::Point {
                position,
                intensity,
            } => Light::Point {
                position: self.finite(&key("position"), position)?,
                intensity: self.colour(&key("intensity"), intensity)?,
            },
            LightToml::Spot {
                position,
                direction,
                intensity,
                cone_angle,
                falloff_start,
            } => {
                if !(cone_angle.is_finite() && cone_angle > 0.0 && cone_angle <= 180.0) {
                    return Err(self.invalid(
                        key("cone_angle"),
                        format!("must be in (0, 180] degrees, got {cone_angle}"),
                    ));
                }
                let falloff = falloff_start.unwrap_or(cone_angle);
                if !(falloff.is_finite() && falloff >= 0.0 && falloff <= cone_angle) {
                    return Err(self.invalid(
                        key("falloff_start"),
                        format!("must be in [0, cone_angle = {cone_angle}] degrees, got {falloff}"),
                    ));
                }
                Light::Spot {
                    position: self.finite(&key("position"), position)?,
                    direction: self.direction(&key("direction"), direction)?,
                    intensity: self.colour(&key("intensity"), intensity)?,
                    cone_angle: cone_angle.to_radians(),
                    falloff_start: falloff.to_radians(),
                }
            }
            LightToml::Directional {
                direction,
                irradiance,
            } => Light::Directional {
                direction: self.direction(&key("direction"), direction)?,
                irradiance: self.colour(&key("irradiance"), irradiance)?,
            },
            LightToml::Environment { .. } => {
                return Err(self.invalid(
                    key("type"),
                    "\"environment\" is not allowed here (only in a scene's own [[lights]])",
                ));
            }
        })
    }

    /// An environment light: `file` (relative to the scene file) or `radiance`, with an
    /// optional `scale` and `rotate`. Returns it with the count of negative texels read as 0.
    pub(super) fn environment(
        &self,
        context: &str,
        file: Option<String>,
        radiance: Option<[f32; 3]>,
        scale: Option<f32>,
        rotate: Option<[f32; 3]>,
    ) -> Result<(scene::Environment, usize), LoadError> {
        let key = |k: &str| format!("{context} {k}");
        let (mut env, negative) = match (file, radiance) {
            (Some(file), None) => crate::environment_from_file(&self.dir.join(file))?,
            (None, Some(radiance)) => (
                scene::Environment {
                    radiance: scene::EnvironmentRadiance::Constant(
                        self.colour(&key("radiance"), radiance)?,
                    ),
                    scale: 1.0,
                    to_world: glam::Mat3::IDENTITY,
                },
                0,
            ),
            _ => {
                return Err(self.invalid(
                    key("file"),
                    "or radiance: an environment needs exactly one of the two",
                ));
            }
        };
        if let Some(scale) = scale {
            if !(scale.is_finite() && scale >= 0.0) {
                return Err(self.invalid(
                    key("scale"),
                    format!("must be finite and >= 0, got {scale}"),
                ));
            }
            env.scale = scale;
        }
        if let Some(rotate) = rotate {
            env.to_world =
                scene::Environment::rotation_degrees(self.finite(&key("rotate"), rotate)?);
        }
        Ok((env, negative))
    }
}
