//! Turning the parsed records into a scene: camera, lights, and shapes with their
//! materials.

use super::*;

impl Parser {
    /// Turns the parsed records into a scene.
    #[allow(clippy::too_many_lines)]
    pub(super) fn build(
        mut self,
        path: &Path,
        options: &LoadOptions,
    ) -> Result<SceneDescription, LoadError> {
        let mut builder = Builder::default();
        for w in std::mem::take(&mut self.warnings) {
            builder.warn(w);
        }
        // The camera, and the reflection that makes it right-handed (see the module docs).
        let (camera, fix) = match self.camera {
            Some((world_from_camera, fov, lens, focal)) => {
                let position = world_from_camera.transform_point3(DVec3::ZERO);
                let forward = world_from_camera
                    .transform_vector3(DVec3::Z)
                    .normalize_or_zero();
                let up = world_from_camera
                    .transform_vector3(DVec3::Y)
                    .normalize_or_zero();
                let right = world_from_camera.transform_vector3(DVec3::X);
                let fix = if right.dot(forward.cross(up)) < 0.0 {
                    mirror_fix(world_from_camera)
                } else {
                    DMat4::IDENTITY
                };
                let (w, h) = (f64::from(self.film.width), f64::from(self.film.height));
                let fov_y = if w >= h {
                    fov.to_radians()
                } else {
                    2.0 * ((fov.to_radians() * 0.5).tan() * h / w).atan()
                };
                let camera = Camera {
                    position: position.as_vec3(),
                    look_at: (position + forward).as_vec3(),
                    up: up.as_vec3(),
                    fov_y: fov_y as f32,
                    aperture_radius: lens as f32,
                    focus_distance: focal as f32,
                };
                (Some(camera), fix)
            }
            None => (None, DMat4::IDENTITY),
        };
        type Converted = Option<(
            MaterialKind,
            Option<std::sync::Arc<scene::texture::MaterialTextures>>,
            scene::MaterialSpectra,
        )>;
        let mut material_cache: HashMap<String, Converted> = HashMap::new();
        let shapes = std::mem::take(&mut self.shapes);
        for (n, shape) in shapes.iter().enumerate() {
            let (key, def) = match &shape.state.material {
                MaterialRef::Default => ("default".to_owned(), None),
                MaterialRef::Anonymous(i) => (
                    format!("material@{}", self.materials[*i].loc.line),
                    Some(self.materials[*i].clone()),
                ),
                MaterialRef::Named(name, loc) => {
                    let def = self.named_materials.get(name).cloned().ok_or_else(|| {
                        self.err(*loc, format!("NamedMaterial \"{name}\" was never made"))
                    })?;
                    (name.clone(), Some(def))
                }
            };
            let cache_key = match &shape.state.material {
                MaterialRef::Anonymous(i) => format!("#{i}"),
                _ => key.clone(),
            };
            let converted = match material_cache.get(&cache_key) {
                Some(k) => k.clone(),
                None => {
                    let k = match &def {
                        Some(def) => {
                            let label = format!("Material \"{}\" ({key})", def.kind);
                            let mut color = None;
                            let mut spectra = scene::MaterialSpectra::default();
                            self.material(def, &label, &mut color, &mut spectra)?
                                .map(|kind| {
                                    let textures = color.map(|c| {
                                        std::sync::Arc::new(scene::texture::MaterialTextures {
                                            color: Some(c),
                                            ..Default::default()
                                        })
                                    });
                                    (kind, textures, spectra)
                                })
                        }
                        None => Some((
                            MaterialKind::Diffuse(scene::Diffuse {
                                albedo: Rgb::splat(0.5),
                            }),
                            None,
                            scene::MaterialSpectra::default(),
                        )),
                    };
                    material_cache.insert(cache_key, k.clone());
                    k
                }
            };
            let media = self.shape_media(&shape.state)?;
            // `interface` is invisible, unless the shape bounds media: then it is their
            // boundary.
            let Some((kind, textures, mut spectra)) = converted.or_else(|| {
                media.map(|_| {
                    (
                        MaterialKind::Interface(scene::Interface),
                        None,
                        scene::MaterialSpectra::default(),
                    )
                })
            }) else {
                continue;
            };
            let emission = match &shape.state.area {
                Some(area) => {
                    let p = area.params.clone();
                    let l = self
                        .colour(&p, "L", SpectrumUse::Emission)?
                        .unwrap_or(Rgb::ONE);
                    let scale = self.float(&p, "scale")?.unwrap_or(1.0) as f32;
                    if let Some(l) = p.get("L") {
                        spectra.emission = self.blackbody(l)?.map(|b| {
                            scene::spectral::Spectrum::Scaled(f64::from(scale), Box::new(b))
                        });
                    }
                    if self.boolean(&p, "twosided")? == Some(true) {
                        builder.warn(format!(
                            "AreaLightSource at {}:{}: two-sided emission is rendered one-sided (front faces)",
                            self.files[area.loc.file].display(),
                            area.loc.line
                        ));
                    }
                    if p.get("power").is_some() {
                        builder.warn(
                            "AreaLightSource: \"power\" is ignored; L × scale is used".to_owned(),
                        );
                    }
                    l * scale
                }
                None => Rgb::ZERO,
            };
            let name = if emission.max_element() > 0.0 {
                format!("{key}+arealight{n}")
            } else {
                key
            };
            let material = builder.material(Material {
                name,
                kind,
                emission,
                textures,
                spectra: (!spectra.is_empty()).then(|| std::sync::Arc::new(spectra)),
            });
            let to_world = fix * shape.state.ctm;
            let (triangles, spheres, cylinders) = (
                builder.triangles.len(),
                builder.spheres.len(),
                builder.cylinders.len(),
            );
            self.shape(
                &mut builder,
                shape,
                to_world,
                material,
                emission.max_element() > 0.0,
            )?;
            if let Some((inside, outside)) = media {
                if builder.cylinders.len() > cylinders {
                    return Err(self.err(
                        shape.loc,
                        "a cylinder cannot bound a medium (it is open); MediumInterface changes the medium here",
                    ));
                }
                // pbrt's inside is behind the surface normal, fppm's interior behind the front
                // face: the same side for meshes (their winding follows pbrt's normal). A sphere
                // with ReverseOrientation has its normal inward, so its inside is the outer side.
                if builder.spheres.len() > spheres {
                    let (interior, exterior) = if shape.state.reverse {
                        (outside, inside)
                    } else {
                        (inside, outside)
                    };
                    builder.media.shapes.push(scene::ShapeMedia {
                        shape: scene::MediumShape::Sphere(spheres as u32),
                        interior,
                        exterior,
                    });
                }
                if builder.triangles.len() > triangles {
                    builder.media.shapes.push(scene::ShapeMedia {
                        shape: scene::MediumShape::Triangles {
                            start: triangles as u32,
                            end: builder.triangles.len() as u32,
                        },
                        interior: inside,
                        exterior: outside,
                    });
                }
            }
        }
        builder.media.list = std::mem::take(&mut self.media);
        // Grids were placed by the transform at `MakeNamedMedium`; the camera's reflection
        // applies to them as to shapes.
        if fix != DMat4::IDENTITY {
            let fix = glam::Affine3A::from_mat4(fix.as_mat4());
            for (i, m) in builder.media.list.iter_mut().enumerate() {
                if let Some(grid) = &m.density {
                    let placed = grid.placed(fix * grid.to_world()).map_err(|e| {
                        self.err(self.medium_locs[i], format!("medium \"{}\": {e}", m.name))
                    })?;
                    m.density = Some(std::sync::Arc::new(placed));
                }
            }
        }
        if let Some((name, loc)) = self.camera_medium.take() {
            builder.media.camera = self.medium_named(&name, loc)?;
        }
        for light in std::mem::take(&mut self.lights) {
            let p = light.params.clone();
            let ctm = fix * light.ctm;
            let em = SpectrumUse::Emission;
            let scale = self.float(&p, "scale")?.unwrap_or(1.0) as f32;
            if p.get("power").is_some() {
                builder.warn(format!(
                    "LightSource \"{}\": \"power\" is ignored; the scale is used",
                    light.kind
                ));
            }
            let point = |s: &Self, name: &str, default: DVec3| -> Result<DVec3, LoadError> {
                Ok(s.vec3s(&p, name, &["point3", "point"])?
                    .and_then(|v| v.first().copied())
                    .map_or(default, |v| v.as_dvec3()))
            };
            match light.kind.as_str() {
                "point" => {
                    let i = self.colour(&p, "I", em)?.unwrap_or(Rgb::ONE) * scale;
                    let from = point(&self, "from", DVec3::ZERO)?;
                    builder.lights.push(Light::Point {
                        position: ctm.transform_point3(from).as_vec3(),
                        intensity: i,
                    });
                }
                "spot" => {
                    let i = self.colour(&p, "I", em)?.unwrap_or(Rgb::ONE) * scale;
                    let from = point(&self, "from", DVec3::ZERO)?;
                    let to = point(&self, "to", DVec3::Z)?;
                    let cone = self.float(&p, "coneangle")?.unwrap_or(30.0);
                    let delta = self.float(&p, "conedelta")?.unwrap_or(5.0);
                    let dir = ctm
                        .transform_vector3(to - from)
                        .try_normalize()
                        .ok_or_else(|| self.err(light.loc, "spot light: from and to coincide"))?;
                    builder.lights.push(Light::Spot {
                        position: ctm.transform_point3(from).as_vec3(),
                        direction: dir.as_vec3(),
                        intensity: i,
                        cone_angle: (cone as f32).to_radians(),
                        falloff_start: ((cone - delta).max(0.0) as f32).to_radians(),
                    });
                }
                "distant" => {
                    let l = self.colour(&p, "L", em)?.unwrap_or(Rgb::ONE) * scale;
                    let from = point(&self, "from", DVec3::ZERO)?;
                    let to = point(&self, "to", DVec3::Z)?;
                    let dir = ctm
                        .transform_vector3(to - from)
                        .try_normalize()
                        .ok_or_else(|| {
                            self.err(light.loc, "distant light: from and to coincide")
                        })?;
                    builder.lights.push(Light::Directional {
                        direction: dir.as_vec3(),
                        irradiance: l,
                    });
                }
                // A constant sky.
                "infinite" if p.get("filename").is_none() => {
                    let l = self.colour(&p, "L", em)?.unwrap_or(Rgb::ONE);
                    if p.get("illuminance").is_some() {
                        builder.warn(
                            "LightSource \"infinite\": \"illuminance\" is ignored; L × scale is used",
                        );
                    }
                    let env = scene::Environment {
                        radiance: scene::EnvironmentRadiance::Constant(l),
                        scale,
                        to_world: glam::Mat3::IDENTITY,
                    };
                    let file = self.files[light.loc.file].display().to_string();
                    builder::set_environment(
                        &mut builder,
                        &format!("LightSource \"infinite\" ({file}:{})", light.loc.line),
                        env,
                    );
                }
                // An equal-area octahedral map, resampled to an equirectangular one whose
                // frame is the light's (x negated if the light's transform mirrors, so that
                // the frame's rotation stays a rotation).
                "infinite" => {
                    let name = self.str_param(&p, "filename")?.unwrap_or_default();
                    let path = self.resolve(&name);
                    if p.get("illuminance").is_some() {
                        builder.warn(
                            "LightSource \"infinite\": \"illuminance\" is ignored; the map × scale is used",
                        );
                    }
                    let linear = glam::DMat3::from_mat4(ctm);
                    let mirror = linear.determinant() < 0.0;
                    let unmirrored = if mirror {
                        linear * glam::DMat3::from_diagonal(DVec3::new(-1.0, 1.0, 1.0))
                    } else {
                        linear
                    };
                    let to_world = builder::rotation_part(glam::DMat4::from_mat3(unmirrored))
                        .ok_or_else(|| {
                            self.err(
                                light.loc,
                                "the infinite light's transform must be a rotation (and a uniform scale)",
                            )
                        })?;
                    let (map, negative) = crate::environment::load_equal_area(&path, mirror)?;
                    if negative > 0 {
                        builder.warn(format!("{name}: {negative} negative texels read as 0"));
                    }
                    let env = scene::Environment {
                        radiance: scene::EnvironmentRadiance::Map(std::sync::Arc::new(map)),
                        scale,
                        to_world,
                    };
                    let file = self.files[light.loc.file].display().to_string();
                    builder::set_environment(
                        &mut builder,
                        &format!("LightSource \"infinite\" ({file}:{})", light.loc.line),
                        env,
                    );
                }
                other => {
                    return Err(self.err(
                        light.loc,
                        format!("LightSource \"{other}\" is not supported"),
                    ));
                }
            }
        }
        for w in std::mem::take(&mut self.warnings) {
            builder.warn(w);
        }
        builder.finish(path, camera, self.film, self.render.clone(), options)
    }
}
