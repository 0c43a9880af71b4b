//! From the file as read to a `SceneDescription`: units, transforms, meshes, checks of each value.

use crate::error::LoadError;
use crate::{LoadOptions, MAX_FILM_SIDE, MeshData, SceneParts, fmt_vec};
use scene::{
    Camera, Cylinder, Film, LoadNotes, MediumShape, RenderDefaults, SceneDescription, ShapeMedia,
    Sphere, Triangle,
};

use crate::image_file::TextureCache;
use glam::{Mat3, Mat4, Vec3};
use std::collections::{BTreeMap, HashSet};
use std::path::Path;

use super::schema::*;

pub(super) struct Converter<'a> {
    pub(super) path: &'a Path,
    pub(super) dir: &'a Path,
    /// The texture images read so far (each file once).
    pub(super) textures: std::cell::RefCell<TextureCache>,
}

impl Converter<'_> {
    pub(super) fn invalid(&self, key: impl Into<String>, message: impl Into<String>) -> LoadError {
        LoadError::InvalidValue {
            path: self.path.to_path_buf(),
            key: key.into(),
            message: message.into(),
        }
    }

    pub(super) fn finite(&self, key: &str, v: [f32; 3]) -> Result<Vec3, LoadError> {
        let v = Vec3::from(v);
        if v.is_finite() {
            Ok(v)
        } else {
            Err(self.invalid(key, format!("must be finite, got {}", fmt_vec(v))))
        }
    }

    pub(super) fn direction(&self, key: &str, v: [f32; 3]) -> Result<Vec3, LoadError> {
        let v = self.finite(key, v)?;
        v.try_normalize()
            .ok_or_else(|| self.invalid(key, "must not be the zero vector"))
    }

    pub(super) fn colour(&self, key: &str, v: [f32; 3]) -> Result<Vec3, LoadError> {
        let c = Vec3::from(v);
        scene::validate::colour(key, c).map_err(|e| crate::invalid_in_file(e, self.path))?;
        Ok(c)
    }

    pub(super) fn reflectance(&self, key: &str, v: [f32; 3]) -> Result<Vec3, LoadError> {
        let c = self.colour(key, v)?;
        if c.max_element() > 1.0 {
            return Err(self.invalid(key, format!("must be at most 1, got {}", fmt_vec(c))));
        }
        Ok(c)
    }

    pub(super) fn positive(&self, key: &str, x: f32) -> Result<f32, LoadError> {
        if x.is_finite() && x > 0.0 {
            Ok(x)
        } else {
            Err(self.invalid(key, format!("must be finite and > 0, got {x}")))
        }
    }

    pub(super) fn convert(
        &self,
        mut file: SceneFile,
        options: &LoadOptions,
    ) -> Result<SceneDescription, LoadError> {
        // A medium's bad value is a usage error (exit 2); a grid file that cannot be read
        // keeps its own error.
        let media = self
            .media(std::mem::take(&mut file.media))
            .map_err(|e| match e {
                LoadError::InvalidValue { .. } => e.into_bad_medium(),
                e => e,
            })?;
        let camera_medium = file.camera.as_mut().and_then(|c| c.medium.take());
        let camera_medium = self.medium_ref(&media, "[camera] medium", camera_medium.as_deref())?;
        let mut shape_media = Vec::new();
        let camera = file.camera.map(|c| self.camera(c)).transpose()?;
        let film = match file.film {
            Some(f) => self.film(&f)?,
            None => crate::default_film(),
        };

        let mut names: BTreeMap<String, u32> = BTreeMap::new();
        let mut materials = Vec::new();
        for (name, m) in file.materials {
            let material = self.material(&name, m)?;
            names.insert(name, materials.len() as u32);
            materials.push(material);
        }
        let lookup = |context: &str, name: &str| -> Result<u32, LoadError> {
            names
                .get(name)
                .copied()
                .ok_or_else(|| LoadError::UnknownMaterial {
                    path: self.path.to_path_buf(),
                    context: context.to_owned(),
                    name: name.to_owned(),
                    defined: if names.is_empty() {
                        "none".to_owned()
                    } else {
                        names.keys().cloned().collect::<Vec<_>>().join(", ")
                    },
                })
        };

        let mut acc = Accumulator::default();
        for (i, shape) in file.shapes.into_iter().enumerate() {
            let context = format!("[[shapes]] #{}", i + 1);
            match shape {
                ShapeToml::Sphere {
                    center,
                    radius,
                    material,
                    interior,
                    exterior,
                } => {
                    let interior = self.medium_ref(
                        &media,
                        &format!("{context} interior"),
                        interior.as_deref(),
                    )?;
                    let exterior = self.medium_ref(
                        &media,
                        &format!("{context} exterior"),
                        exterior.as_deref(),
                    )?;
                    if interior.is_some() || exterior.is_some() {
                        shape_media.push(ShapeMedia {
                            shape: MediumShape::Sphere(acc.spheres.len() as u32),
                            interior,
                            exterior,
                        });
                    }
                    acc.spheres.push(Sphere {
                        center: self.finite(&format!("{context} center"), center)?,
                        radius: self.positive(&format!("{context} radius"), radius)?,
                        material: lookup(&context, &material)?,
                    });
                }
                ShapeToml::Cylinder {
                    center,
                    axis,
                    radius,
                    height,
                    arc,
                    facing,
                    material,
                } => {
                    let key = |k: &str| format!("{context} {k}");
                    let center = self.finite(&key("center"), center)?;
                    let axis = self.direction(&key("axis"), axis.unwrap_or([0.0, 1.0, 0.0]))?;
                    let radius = self.positive(&key("radius"), radius)?;
                    let height = self.positive(&key("height"), height)?;
                    let arc = arc.unwrap_or(360.0);
                    if !(arc.is_finite() && arc > 0.0 && arc <= 360.0) {
                        return Err(self.invalid(
                            key("arc"),
                            format!("must be in (0, 360] degrees, got {arc}"),
                        ));
                    }
                    let facing = match facing {
                        Some(f) => {
                            let f = self.direction(&key("facing"), f)?;
                            (f - f.dot(axis) * axis)
                                .try_normalize()
                                .filter(|p| p.dot(f) > 1e-3)
                                .ok_or_else(|| {
                                    self.invalid(key("facing"), "must not be parallel to the axis")
                                })?
                        }
                        None => default_facing(axis),
                    };
                    let m = lookup(&context, &material)?;
                    if let Some(mat) = materials.get(m as usize)
                        && mat.emission.max_element() > 0.0
                    {
                        return Err(self.invalid(
                            key("material"),
                            format!(
                                "cylinders cannot emit, but material `{material}` has emission {}",
                                fmt_vec(mat.emission)
                            ),
                        ));
                    }
                    acc.cylinders.push(Cylinder {
                        center,
                        axis,
                        radius,
                        height,
                        // Exactly 2π for a whole circle, whatever to_radians rounds to.
                        arc: if arc >= 360.0 {
                            std::f32::consts::TAU
                        } else {
                            arc.to_radians()
                        },
                        facing,
                        material: m,
                    });
                }
                ShapeToml::Quad {
                    corner,
                    edge1,
                    edge2,
                    material,
                } => {
                    let c = self.finite(&format!("{context} corner"), corner)?;
                    let e1 = self.finite(&format!("{context} edge1"), edge1)?;
                    let e2 = self.finite(&format!("{context} edge2"), edge2)?;
                    let m = lookup(&context, &material)?;
                    // Texture coordinates: the corner at the image's bottom left, edge1
                    // along u, edge2 up the image (v grows downwards, see `scene::texture`).
                    let uv = |a: f32, b: f32| glam::Vec2::new(a, 1.0 - b);
                    acc.push(
                        [c, c + e1, c + e1 + e2],
                        None,
                        Some([uv(0.0, 0.0), uv(1.0, 0.0), uv(1.0, 1.0)]),
                        None,
                        m,
                    );
                    acc.push(
                        [c, c + e1 + e2, c + e2],
                        None,
                        Some([uv(0.0, 0.0), uv(1.0, 1.0), uv(0.0, 1.0)]),
                        None,
                        m,
                    );
                }
                ShapeToml::Mesh {
                    file: mesh_file,
                    material,
                    transform,
                    interior,
                    exterior,
                } => {
                    let interior = self.medium_ref(
                        &media,
                        &format!("{context} interior"),
                        interior.as_deref(),
                    )?;
                    let exterior = self.medium_ref(
                        &media,
                        &format!("{context} exterior"),
                        exterior.as_deref(),
                    )?;
                    let start = acc.triangles.len() as u32;
                    let override_material =
                        material.map(|name| lookup(&context, &name)).transpose()?;
                    let matrix = match transform {
                        Some(t) => self.transform(&context, &t)?,
                        None => Mat4::IDENTITY,
                    };
                    let mesh_path = self.dir.join(&mesh_file);
                    let mesh = load_mesh(&mesh_path)?;
                    acc.notes.degenerate_triangles += mesh.degenerate_triangles;
                    acc.notes
                        .warnings
                        .extend(mesh.warnings.iter().map(|w| format!("{mesh_file}: {w}")));
                    if mesh.camera.is_some() || !mesh.lights.is_empty() {
                        acc.notes.warnings.push(format!(
                            "{mesh_file}: cameras and lights inside a mesh file are ignored"
                        ));
                    }
                    let offset = materials.len() as u32;
                    let material_of = |local: u32| override_material.unwrap_or(offset + local);
                    if override_material.is_none() {
                        materials.extend(mesh.materials.into_iter().map(|mut m| {
                            m.name = format!("{mesh_file}/{}", m.name);
                            m
                        }));
                        acc.degenerate_materials
                            .extend(mesh.degenerate_materials.iter().map(|&m| offset + m));
                    } else if let Some(m) = override_material
                        && !mesh.degenerate_materials.is_empty()
                    {
                        acc.degenerate_materials.insert(m);
                    }
                    let normal_matrix = Mat3::from_mat4(matrix).inverse().transpose();
                    let flip = matrix.determinant() < 0.0;
                    for t in mesh.triangles {
                        let mut p = t.positions.map(|p| matrix.transform_point3(p));
                        let mut uv = t.uv;
                        let mut n = t
                            .normals
                            .map(|n| n.map(|n| (normal_matrix * n).normalize_or_zero()));
                        if flip {
                            p.swap(1, 2);
                            if let Some(n) = n.as_mut() {
                                n.swap(1, 2);
                            }
                            if let Some(uv) = uv.as_mut() {
                                uv.swap(1, 2);
                            }
                        }
                        let n = n.filter(|n| n.iter().all(|v| *v != Vec3::ZERO));
                        let tangents = t
                            .tangents
                            .and_then(|t| crate::transform_tangents(t, matrix, flip));
                        acc.push(p, n, uv, tangents, material_of(t.material));
                    }
                    let end = acc.triangles.len() as u32;
                    if (interior.is_some() || exterior.is_some()) && end > start {
                        shape_media.push(ShapeMedia {
                            shape: MediumShape::Triangles { start, end },
                            interior,
                            exterior,
                        });
                    }
                }
            }
        }

        let mut lights = Vec::with_capacity(file.lights.len());
        let mut environment = None;
        for (i, l) in file.lights.into_iter().enumerate() {
            let context = format!("[[lights]] #{}", i + 1);
            match l {
                LightToml::Environment {
                    file,
                    radiance,
                    scale,
                    rotate,
                } => {
                    if environment.is_some() {
                        return Err(self.invalid(
                            format!("{context} type"),
                            "\"environment\" appears twice (a scene has at most one environment)",
                        ));
                    }
                    let (env, negative) =
                        self.environment(&context, file, radiance, scale, rotate)?;
                    if negative > 0 {
                        acc.notes.warnings.push(format!(
                            "{context}: {negative} negative texels of the environment map read as 0"
                        ));
                    }
                    environment = Some(env);
                }
                l => lights.push(self.light(&context, l)?),
            }
        }
        let render = file.render.map(|r| self.render(r)).transpose()?;

        let parts = SceneParts {
            camera,
            film,
            materials,
            triangles: acc.triangles,
            spheres: acc.spheres,
            cylinders: acc.cylinders,
            lights,
            environment,
            media: scene::Media {
                list: media.list,
                shapes: shape_media,
                camera: camera_medium,
            },
            render: render.unwrap_or_default(),
            notes: acc.notes,
            degenerate_materials: acc.degenerate_materials,
        };
        crate::finish(self.path, parts, options)
    }

    pub(super) fn camera(&self, c: CameraToml) -> Result<Camera, LoadError> {
        let position = self.finite("[camera] position", c.position)?;
        let look_at = self.finite("[camera] look_at", c.look_at)?;
        let up = self.direction("[camera] up", c.up.unwrap_or([0.0, 1.0, 0.0]))?;
        let view = look_at - position;
        if view.length_squared() <= 0.0 {
            return Err(self.invalid("[camera] look_at", "must differ from [camera] position"));
        }
        if view.normalize().cross(up).length() < 1e-6 {
            return Err(self.invalid("[camera] up", "must not be parallel to the view direction"));
        }
        if !(c.fov_y.is_finite() && c.fov_y > 0.0 && c.fov_y < 180.0) {
            return Err(self.invalid(
                "[camera] fov_y",
                format!("must be in (0, 180) degrees, got {}", c.fov_y),
            ));
        }
        let aperture_radius = c.aperture_radius.unwrap_or(0.0);
        if !(aperture_radius.is_finite() && aperture_radius >= 0.0) {
            return Err(self.invalid(
                "[camera] aperture_radius",
                format!("must be finite and >= 0, got {aperture_radius}"),
            ));
        }
        let focus_distance = match c.focus_distance {
            Some(d) => self.positive("[camera] focus_distance", d)?,
            None => view.length(),
        };
        Ok(Camera {
            position,
            look_at,
            up,
            fov_y: c.fov_y.to_radians(),
            aperture_radius,
            focus_distance,
        })
    }

    pub(super) fn film(&self, f: &FilmToml) -> Result<Film, LoadError> {
        let side = |key: &str, v: i64| -> Result<u32, LoadError> {
            u32::try_from(v)
                .ok()
                .filter(|&v| (1..=MAX_FILM_SIDE).contains(&v))
                .ok_or_else(|| {
                    self.invalid(
                        format!("[film] {key}"),
                        format!("must be from 1 to {MAX_FILM_SIDE} pixels, got {v}"),
                    )
                })
        };
        Ok(Film {
            width: side("width", f.width)?,
            height: side("height", f.height)?,
        })
    }

    /// Scale, then rotate about x, y, z (degrees), then translate.
    pub(super) fn transform(&self, context: &str, t: &TransformToml) -> Result<Mat4, LoadError> {
        let key = |k: &str| format!("{context} transform.{k}");
        let scale = self.finite(&key("scale"), t.scale.unwrap_or([1.0; 3]))?;
        if scale.abs().min_element() <= 0.0 {
            return Err(self.invalid(
                key("scale"),
                format!("must have no zero component, got {}", fmt_vec(scale)),
            ));
        }
        let rotate = self.finite(&key("rotate"), t.rotate.unwrap_or([0.0; 3]))?;
        let translate = self.finite(&key("translate"), t.translate.unwrap_or([0.0; 3]))?;
        let rotation = Mat4::from_rotation_z(rotate.z.to_radians())
            * Mat4::from_rotation_y(rotate.y.to_radians())
            * Mat4::from_rotation_x(rotate.x.to_radians());
        Ok(Mat4::from_translation(translate) * rotation * Mat4::from_scale(scale))
    }

    pub(super) fn render(&self, r: RenderToml) -> Result<RenderDefaults, LoadError> {
        let mut params = Vec::with_capacity(r.params.len());
        for (key, value) in r.params {
            let text = match value {
                ::toml::Value::String(s) => s,
                ::toml::Value::Integer(n) => n.to_string(),
                ::toml::Value::Float(x) => x.to_string(),
                ::toml::Value::Boolean(b) => b.to_string(),
                other => {
                    return Err(self.invalid(
                        format!("[render] {key}"),
                        format!(
                            "must be a string, a number or a boolean, got a {}",
                            other.type_str()
                        ),
                    ));
                }
            };
            params.push((key, text));
        }
        Ok(RenderDefaults {
            passes: r.passes,
            params,
        })
    }
}

/// Geometry gathered from the shapes.
#[derive(Default)]
pub(super) struct Accumulator {
    pub(super) triangles: Vec<Triangle>,
    pub(super) spheres: Vec<Sphere>,
    pub(super) cylinders: Vec<Cylinder>,
    pub(super) notes: LoadNotes,
    pub(super) degenerate_materials: HashSet<u32>,
}

impl Accumulator {
    pub(super) fn push(
        &mut self,
        positions: [Vec3; 3],
        normals: Option<[Vec3; 3]>,
        uv: Option<[glam::Vec2; 3]>,
        tangents: Option<[[f32; 4]; 3]>,
        material: u32,
    ) {
        if crate::is_degenerate(positions) {
            self.notes.degenerate_triangles += 1;
            self.degenerate_materials.insert(material);
        } else {
            self.triangles.push(Triangle {
                positions,
                normals,
                material,
                uv,
                tangents,
            });
        }
    }
}

/// The default `facing` of a cylinder with unit `axis`: +Z made perpendicular to the axis, or +X
/// when the axis is within about 25° of ±Z.
pub(super) fn default_facing(axis: Vec3) -> Vec3 {
    let reference = if axis.z.abs() < 0.9 { Vec3::Z } else { Vec3::X };
    (reference - reference.dot(axis) * axis).normalize_or(axis.any_orthonormal_vector())
}

/// Loads the mesh file of a `[[shapes]]` entry.
pub(super) fn load_mesh(path: &Path) -> Result<MeshData, LoadError> {
    let extension = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    match extension.as_str() {
        "obj" => crate::obj::load_obj(path),
        "gltf" | "glb" => crate::gltf::load_gltf(path),
        _ => Err(LoadError::UnsupportedExtension {
            path: path.to_path_buf(),
            extension,
        }),
    }
}
