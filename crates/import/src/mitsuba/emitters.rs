//! Emitters other than area lights.

use super::*;

impl<'a> Importer<'a> {
    pub(super) fn emitter(&mut self, node: &'a Node) -> Result<(), LoadError> {
        let label = node.label();
        let to_world = self.transform(node, "to_world")?;
        let em = SpectrumUse::Emission;
        match node.attr("type").unwrap_or("") {
            // Used by shapes through <ref>.
            "area" => {}
            "point" => {
                let position = match self.vector(node, "position")? {
                    Some(p) => p,
                    None => to_world.transform_point3(DVec3::ZERO),
                };
                let intensity = self.colour(node, "intensity", em)?.unwrap_or(Rgb::ONE);
                self.builder.lights.push(Light::Point {
                    position: position.as_vec3(),
                    intensity,
                });
            }
            "spot" => {
                let intensity = self.colour(node, "intensity", em)?.unwrap_or(Rgb::ONE);
                let cutoff = self.float(node, "cutoff_angle")?.unwrap_or(20.0);
                let beam = self.float(node, "beam_width")?.unwrap_or(cutoff * 0.75);
                let direction = to_world
                    .transform_vector3(DVec3::Z)
                    .try_normalize()
                    .ok_or_else(|| self.err(node, "to_world has no direction"))?;
                self.builder.warn(format!(
                    "{label}: the spot's falloff between beam_width and cutoff_angle follows fppm's curve, not Mitsuba's"
                ));
                self.builder.lights.push(Light::Spot {
                    position: to_world.transform_point3(DVec3::ZERO).as_vec3(),
                    direction: direction.as_vec3(),
                    intensity,
                    cone_angle: (cutoff as f32).to_radians(),
                    falloff_start: (beam.min(cutoff) as f32).to_radians(),
                });
            }
            "directional" => {
                let irradiance = self.colour(node, "irradiance", em)?.unwrap_or(Rgb::ONE);
                let direction = match self.vector(node, "direction")? {
                    Some(d) => d,
                    None => to_world.transform_vector3(DVec3::Z),
                }
                .try_normalize()
                .ok_or_else(|| self.err(node, "direction cannot be zero"))?;
                self.builder.lights.push(Light::Directional {
                    direction: direction.as_vec3(),
                    irradiance,
                });
            }
            "constant" => {
                let radiance = self.colour(node, "radiance", em)?.unwrap_or(Rgb::ONE);
                let env = scene::Environment {
                    radiance: scene::EnvironmentRadiance::Constant(radiance),
                    scale: 1.0,
                    to_world: glam::Mat3::IDENTITY,
                };
                builder::set_environment(&mut self.builder, &label, env);
            }
            "envmap" => {
                let Some(file) = self.string(node, "filename")? else {
                    return Err(self.err(node, "an envmap needs a filename"));
                };
                let path = self.doc.resolve(node, file);
                let (mut env, negative) = crate::environment_from_file(&path)?;
                if negative > 0 {
                    self.builder.warn(format!(
                        "{label}: {negative} negative texels of {} read as 0",
                        path.display()
                    ));
                }
                env.scale = self.float(node, "scale")?.unwrap_or(1.0) as f32;
                env.to_world = builder::rotation_part(to_world)
                    .ok_or_else(|| self.err(node, "to_world must be a rotation for an envmap"))?;
                builder::set_environment(&mut self.builder, &label, env);
            }
            "sunsky" | "sky" | "sun" => {
                builder::environment_light_standin(&mut self.builder, &label);
            }
            other => {
                return Err(self.err(node, format!("emitter type \"{other}\" is not supported")));
            }
        }
        Ok(())
    }
}
