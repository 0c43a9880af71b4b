//! TOML scene files, format version 1 (`shared/design/scene-format.md`).
//!
//! The file is read with serde (`deny_unknown_fields`, internally tagged `type` enums). The
//! toml crate reports the byte span of a problem but not the table it is in; the table
//! (`[materials.white]`, `[[shapes]] #2`) is recovered from the text before the span, and
//! serde's standard messages are sorted into [`LoadError`] variants.
//!
//! Decisions beyond the format page: `[camera]` is optional (a missing camera frames the
//! bounding box) and so is `[film]` (512 × 512); film sides are 1 to 16384; albedo and
//! reflectance must lie in [0, 1]; a spot light's `falloff_start` defaults to `cone_angle`
//! (a hard edge); `cone_angle` is in (0, 180]; a mesh file's own materials are named
//! `FILE/NAME` in the scene; lights and cameras inside a mesh file are ignored (with a warning).
//!
//! Extensions (`docs/scene-format-extensions.md`): the `cylinder` shape, an analytic open
//! cylinder cut to an optional arc; its material must not emit.

use std::collections::{BTreeMap, HashSet};
use std::path::Path;

use glam::{Mat3, Mat4, Vec3};
use serde::Deserialize;

use super::{LoadOptions, MAX_FILM_SIDE, MeshData, SceneParts, check_colour, fmt_vec};
use crate::description::{
    Camera, Cylinder, Film, Light, LoadNotes, Material, MaterialKind, RenderDefaults,
    SceneDescription, Sphere, Triangle,
};
use crate::error::LoadError;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SceneFile {
    #[allow(dead_code, reason = "checked before the typed parse")]
    format: ::toml::Value,
    camera: Option<CameraToml>,
    film: Option<FilmToml>,
    #[serde(default)]
    materials: BTreeMap<String, MaterialToml>,
    #[serde(default)]
    shapes: Vec<ShapeToml>,
    #[serde(default)]
    lights: Vec<LightToml>,
    render: Option<RenderToml>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CameraToml {
    position: [f32; 3],
    look_at: [f32; 3],
    up: Option<[f32; 3]>,
    fov_y: f32,
    aperture_radius: Option<f32>,
    focus_distance: Option<f32>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FilmToml {
    width: i64,
    height: i64,
}

#[derive(Deserialize)]
#[serde(tag = "type", rename_all = "lowercase", deny_unknown_fields)]
enum MaterialToml {
    Diffuse {
        albedo: [f32; 3],
        emission: Option<[f32; 3]>,
    },
    Mirror {
        reflectance: Option<[f32; 3]>,
        emission: Option<[f32; 3]>,
    },
    Dielectric {
        ior: f32,
        emission: Option<[f32; 3]>,
    },
    Glossy {
        reflectance: [f32; 3],
        roughness: f32,
        emission: Option<[f32; 3]>,
    },
}

#[derive(Deserialize)]
#[serde(tag = "type", rename_all = "lowercase", deny_unknown_fields)]
enum ShapeToml {
    Mesh {
        file: String,
        material: Option<String>,
        transform: Option<TransformToml>,
    },
    Sphere {
        center: [f32; 3],
        radius: f32,
        material: String,
    },
    Quad {
        corner: [f32; 3],
        edge1: [f32; 3],
        edge2: [f32; 3],
        material: String,
    },
    /// Extension to format 1 (`docs/scene-format-extensions.md`).
    Cylinder {
        center: [f32; 3],
        axis: Option<[f32; 3]>,
        radius: f32,
        height: f32,
        arc: Option<f32>,
        facing: Option<[f32; 3]>,
        material: String,
    },
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TransformToml {
    scale: Option<[f32; 3]>,
    rotate: Option<[f32; 3]>,
    translate: Option<[f32; 3]>,
}

#[derive(Deserialize)]
#[serde(tag = "type", rename_all = "lowercase", deny_unknown_fields)]
enum LightToml {
    Point {
        position: [f32; 3],
        intensity: [f32; 3],
    },
    Spot {
        position: [f32; 3],
        direction: [f32; 3],
        intensity: [f32; 3],
        cone_angle: f32,
        falloff_start: Option<f32>,
    },
    Directional {
        direction: [f32; 3],
        irradiance: [f32; 3],
    },
}

/// The `[render]` table: `passes`, and render parameters that `ppm` reads.
#[derive(Deserialize)]
struct RenderToml {
    passes: Option<u32>,
    #[serde(flatten)]
    params: std::collections::BTreeMap<String, ::toml::Value>,
}

/// Parses and converts a TOML scene.
pub(crate) fn load_toml(
    text: &str,
    path: &Path,
    options: &LoadOptions,
) -> Result<SceneDescription, LoadError> {
    // Syntax first, then the version, so that a future version's keys are not reported as
    // unknown keys.
    let table: ::toml::Table = ::toml::from_str(text).map_err(|e| syntax_error(path, text, &e))?;
    match table.get("format") {
        None => {
            return Err(LoadError::MissingKey {
                path: path.to_path_buf(),
                line: None,
                column: None,
                table: "the top level".to_owned(),
                key: "format".to_owned(),
            });
        }
        Some(::toml::Value::Integer(1)) => {}
        Some(::toml::Value::Integer(v)) => {
            return Err(LoadError::UnsupportedVersion {
                path: path.to_path_buf(),
                found: v.to_string(),
            });
        }
        Some(other) => {
            return Err(LoadError::WrongType {
                path: path.to_path_buf(),
                line: None,
                column: None,
                table: "the top level".to_owned(),
                key: "format".to_owned(),
                message: format!("expected the integer 1, got {} {other}", other.type_str()),
            });
        }
    }
    let file: SceneFile = ::toml::from_str(text).map_err(|e| schema_error(path, text, &e))?;
    Converter {
        path,
        dir: path.parent().unwrap_or(Path::new("")),
    }
    .convert(file, options)
}

struct Converter<'a> {
    path: &'a Path,
    dir: &'a Path,
}

impl Converter<'_> {
    fn invalid(&self, key: impl Into<String>, message: impl Into<String>) -> LoadError {
        LoadError::InvalidValue {
            path: self.path.to_path_buf(),
            key: key.into(),
            message: message.into(),
        }
    }

    fn finite(&self, key: &str, v: [f32; 3]) -> Result<Vec3, LoadError> {
        let v = Vec3::from(v);
        if v.is_finite() {
            Ok(v)
        } else {
            Err(self.invalid(key, format!("must be finite, got {}", fmt_vec(v))))
        }
    }

    fn direction(&self, key: &str, v: [f32; 3]) -> Result<Vec3, LoadError> {
        let v = self.finite(key, v)?;
        v.try_normalize()
            .ok_or_else(|| self.invalid(key, "must not be the zero vector"))
    }

    fn colour(&self, key: &str, v: [f32; 3]) -> Result<Vec3, LoadError> {
        let c = Vec3::from(v);
        check_colour(self.path, key, c)?;
        Ok(c)
    }

    fn reflectance(&self, key: &str, v: [f32; 3]) -> Result<Vec3, LoadError> {
        let c = self.colour(key, v)?;
        if c.max_element() > 1.0 {
            return Err(self.invalid(key, format!("must be at most 1, got {}", fmt_vec(c))));
        }
        Ok(c)
    }

    fn positive(&self, key: &str, x: f32) -> Result<f32, LoadError> {
        if x.is_finite() && x > 0.0 {
            Ok(x)
        } else {
            Err(self.invalid(key, format!("must be finite and > 0, got {x}")))
        }
    }

    fn convert(
        &self,
        file: SceneFile,
        options: &LoadOptions,
    ) -> Result<SceneDescription, LoadError> {
        let camera = file.camera.map(|c| self.camera(c)).transpose()?;
        let film = match file.film {
            Some(f) => self.film(&f)?,
            None => super::default_film(),
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
                } => {
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
                    acc.push([c, c + e1, c + e1 + e2], None, m);
                    acc.push([c, c + e1 + e2, c + e2], None, m);
                }
                ShapeToml::Mesh {
                    file: mesh_file,
                    material,
                    transform,
                } => {
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
                        let mut n = t
                            .normals
                            .map(|n| n.map(|n| (normal_matrix * n).normalize_or_zero()));
                        if flip {
                            p.swap(1, 2);
                            if let Some(n) = n.as_mut() {
                                n.swap(1, 2);
                            }
                        }
                        let n = n.filter(|n| n.iter().all(|v| *v != Vec3::ZERO));
                        acc.push(p, n, material_of(t.material));
                    }
                }
            }
        }

        let lights = file
            .lights
            .into_iter()
            .enumerate()
            .map(|(i, l)| self.light(&format!("[[lights]] #{}", i + 1), l))
            .collect::<Result<Vec<_>, _>>()?;
        let render = file.render.map(|r| self.render(r)).transpose()?;

        let parts = SceneParts {
            camera,
            film,
            materials,
            triangles: acc.triangles,
            spheres: acc.spheres,
            cylinders: acc.cylinders,
            lights,
            render: render.unwrap_or_default(),
            notes: acc.notes,
            degenerate_materials: acc.degenerate_materials,
        };
        super::finish(self.path, parts, options)
    }

    fn camera(&self, c: CameraToml) -> Result<Camera, LoadError> {
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

    fn film(&self, f: &FilmToml) -> Result<Film, LoadError> {
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

    fn material(&self, name: &str, m: MaterialToml) -> Result<Material, LoadError> {
        let key = |k: &str| format!("[materials.{name}] {k}");
        let (kind, emission) = match m {
            MaterialToml::Diffuse { albedo, emission } => (
                MaterialKind::Diffuse {
                    albedo: self.reflectance(&key("albedo"), albedo)?,
                },
                emission,
            ),
            MaterialToml::Mirror {
                reflectance,
                emission,
            } => (
                MaterialKind::Mirror {
                    reflectance: self
                        .reflectance(&key("reflectance"), reflectance.unwrap_or([1.0; 3]))?,
                },
                emission,
            ),
            MaterialToml::Dielectric { ior, emission } => (
                MaterialKind::Dielectric {
                    ior: self.positive(&key("ior"), ior)?,
                },
                emission,
            ),
            MaterialToml::Glossy {
                reflectance,
                roughness,
                emission,
            } => (
                MaterialKind::Glossy {
                    reflectance: self.reflectance(&key("reflectance"), reflectance)?,
                    roughness: self.positive(&key("roughness"), roughness)?,
                    diffuse: Vec3::ZERO,
                },
                emission,
            ),
        };
        let emission = match emission {
            Some(e) => self.colour(&key("emission"), e)?,
            None => Vec3::ZERO,
        };
        Ok(Material {
            name: name.to_owned(),
            kind,
            emission,
        })
    }

    /// Scale, then rotate about x, y, z (degrees), then translate.
    fn transform(&self, context: &str, t: &TransformToml) -> Result<Mat4, LoadError> {
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

    fn light(&self, context: &str, l: LightToml) -> Result<Light, LoadError> {
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
        })
    }

    fn render(&self, r: RenderToml) -> Result<RenderDefaults, LoadError> {
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
struct Accumulator {
    triangles: Vec<Triangle>,
    spheres: Vec<Sphere>,
    cylinders: Vec<Cylinder>,
    notes: LoadNotes,
    degenerate_materials: HashSet<u32>,
}

impl Accumulator {
    fn push(&mut self, positions: [Vec3; 3], normals: Option<[Vec3; 3]>, material: u32) {
        if super::is_degenerate(positions) {
            self.notes.degenerate_triangles += 1;
            self.degenerate_materials.insert(material);
        } else {
            self.triangles.push(Triangle {
                positions,
                normals,
                material,
            });
        }
    }
}

/// The default `facing` of a cylinder with unit `axis`: +Z made perpendicular to the axis, or +X
/// when the axis is within about 25° of ±Z.
fn default_facing(axis: Vec3) -> Vec3 {
    let reference = if axis.z.abs() < 0.9 { Vec3::Z } else { Vec3::X };
    (reference - reference.dot(axis) * axis).normalize_or(axis.any_orthonormal_vector())
}

/// Loads the mesh file of a `[[shapes]]` entry.
fn load_mesh(path: &Path) -> Result<MeshData, LoadError> {
    let extension = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    match extension.as_str() {
        "obj" => super::obj::load_obj(path),
        "gltf" | "glb" => super::gltf::load_gltf(path),
        _ => Err(LoadError::UnsupportedExtension {
            path: path.to_path_buf(),
            extension,
        }),
    }
}

/// 1-based line and column of a byte offset.
fn line_column(text: &str, offset: usize) -> (u32, u32) {
    let offset = offset.min(text.len());
    let before = text.get(..offset).unwrap_or(text);
    let line = before.matches('\n').count() + 1;
    let column = before
        .rsplit('\n')
        .next()
        .map_or(1, |l| l.chars().count() + 1);
    (to_u32(line), to_u32(column))
}

fn to_u32(x: usize) -> u32 {
    u32::try_from(x).unwrap_or(u32::MAX)
}

fn syntax_error(path: &Path, text: &str, e: &::toml::de::Error) -> LoadError {
    let (line, column) = match e.span() {
        Some(span) => {
            let (l, c) = line_column(text, span.start);
            (Some(l), Some(c))
        }
        None => (None, None),
    };
    LoadError::Toml {
        path: path.to_path_buf(),
        line,
        column,
        message: first_line(e.message()),
    }
}

fn first_line(s: &str) -> String {
    s.lines().next().unwrap_or("").trim().to_owned()
}

/// Byte offset of the end of the line holding `offset`.
fn end_of_line(text: &str, offset: usize) -> usize {
    let offset = offset.min(text.len());
    text.get(offset..)
        .and_then(|rest| rest.find('\n'))
        .map_or(text.len(), |i| offset + i)
}

/// Strips a `#` comment (good enough for header lines).
fn uncomment(line: &str) -> &str {
    line.split('#').next().unwrap_or(line).trim()
}

/// The table header in force at byte `offset` (the header line itself counts):
/// `[camera]`, `[materials.white]`, `[[shapes]] #2`, or `the top level`.
fn table_at(text: &str, offset: usize) -> String {
    let before = text.get(..end_of_line(text, offset)).unwrap_or(text);
    let header = before.lines().map(str::trim).rfind(|l| l.starts_with('['));
    match header {
        None => "the top level".to_owned(),
        Some(h) => {
            let h = uncomment(h);
            if h.starts_with("[[") {
                let n = before.lines().filter(|l| uncomment(l) == h).count();
                format!("{h} #{n}")
            } else {
                h.to_owned()
            }
        }
    }
}

/// The key on the line at byte `offset` (`albedo` in `albedo = "red"`), if any.
fn key_at(text: &str, offset: usize) -> Option<String> {
    let start = text
        .get(..offset.min(text.len()))
        .and_then(|b| b.rfind('\n'))
        .map_or(0, |i| i + 1);
    let line = text
        .get(start..)
        .and_then(|l| l.lines().next())
        .unwrap_or("");
    match line.split_once('=') {
        Some((k, _)) if !line.trim_start().starts_with('[') => Some(k.trim().to_owned()),
        _ => None,
    }
}

/// The lines of the table whose header (or any line) holds `offset`, with 0-based indices:
/// from the table's header line to the line before the next header.
fn section(text: &str, offset: usize) -> Vec<(usize, &str)> {
    let first = text
        .get(..end_of_line(text, offset))
        .unwrap_or(text)
        .lines()
        .enumerate()
        .filter(|(_, l)| l.trim_start().starts_with('['))
        .map(|(i, _)| i)
        .last()
        .unwrap_or(0);
    text.lines()
        .enumerate()
        .skip(first)
        .take_while(|(i, l)| *i == first || !l.trim_start().starts_with('['))
        .collect()
}

/// The line and column of `key = …` inside the table holding `offset`.
fn find_key(text: &str, offset: usize, key: &str) -> Option<(u32, u32)> {
    section(text, offset).into_iter().find_map(|(i, l)| {
        let (k, _) = l.split_once('=')?;
        (k.trim() == key).then(|| (to_u32(i + 1), to_u32(l.len() - l.trim_start().len() + 1)))
    })
}

/// For `invalid type: string "white", …`, the key in the table holding `offset` whose value
/// is written `"white"` (serde does not name the key; this finds it for plain values).
fn find_key_by_value(text: &str, offset: usize, message: &str) -> Option<(String, u32, u32)> {
    let matches: Box<dyn Fn(&str) -> bool> = if let Some(rest) =
        message.strip_prefix("invalid length ")
    {
        // `invalid length 2, expected an array of length 3`: an array of 2 elements.
        let n: usize = rest.split(',').next()?.trim().parse().ok()?;
        Box::new(move |v: &str| {
            v.strip_prefix('[')
                .and_then(|v| v.strip_suffix(']'))
                .is_some_and(|inner| inner.split(',').filter(|e| !e.trim().is_empty()).count() == n)
        })
    } else {
        let rest = message.strip_prefix("invalid type: ")?;
        let literal = if let Some(r) = rest.strip_prefix("string ") {
            r.split(", expected").next()?.to_owned()
        } else {
            let (_, r) = rest.split_once('`')?;
            r.split('`').next()?.to_owned()
        };
        Box::new(move |v: &str| v == literal)
    };
    section(text, offset).into_iter().find_map(|(i, l)| {
        let (k, v) = l.split_once('=')?;
        matches(uncomment(v)).then(|| {
            (
                k.trim().to_owned(),
                to_u32(i + 1),
                to_u32(l.len() - l.trim_start().len() + 1),
            )
        })
    })
}

/// Turns a serde/toml error into the most specific variant.
fn schema_error(path: &Path, text: &str, e: &::toml::de::Error) -> LoadError {
    let message = first_line(e.message());
    let offset = e.span().map(|s| s.start);
    let (line, column) = match offset {
        Some(o) => {
            let (l, c) = line_column(text, o);
            (Some(l), Some(c))
        }
        None => (None, None),
    };
    let table = offset.map_or_else(|| "the scene".to_owned(), |o| table_at(text, o));
    let path = path.to_path_buf();
    if let Some(rest) = message.strip_prefix("unknown field `")
        && let Some((key, rest)) = rest.split_once('`')
    {
        let (line, column) = match offset.and_then(|o| find_key(text, o, key)) {
            Some((l, c)) => (Some(l), Some(c)),
            None => (line, column),
        };
        let mut expected = expected_list(rest);
        // Serde leaves the tag out of a tagged table's list.
        let tagged = ["[materials.", "[[shapes]]", "[[lights]]"]
            .iter()
            .any(|t| table.starts_with(t));
        if tagged && !expected.split(", ").any(|k| k == "type") {
            expected = format!("type, {expected}");
        }
        return LoadError::UnknownKey {
            path,
            line,
            column,
            table,
            key: key.to_owned(),
            expected,
        };
    }
    if let Some(rest) = message.strip_prefix("missing field `")
        && let Some((key, _)) = rest.split_once('`')
    {
        return LoadError::MissingKey {
            path,
            line,
            column,
            table,
            key: key.to_owned(),
        };
    }
    if let Some(rest) = message.strip_prefix("unknown variant `")
        && let Some((found, rest)) = rest.split_once('`')
    {
        return LoadError::UnknownType {
            path,
            line,
            column,
            table,
            found: found.to_owned(),
            expected: expected_list(rest),
        };
    }
    if message.starts_with("invalid type")
        || message.starts_with("invalid length")
        || message.starts_with("invalid value")
    {
        let (key, line, column) = match offset.and_then(|o| key_at(text, o)) {
            Some(key) => (key, line, column),
            None => match offset.and_then(|o| find_key_by_value(text, o, &message)) {
                Some((key, l, c)) => (key, Some(l), Some(c)),
                None => (String::new(), line, column),
            },
        };
        return LoadError::WrongType {
            path,
            line,
            column,
            table,
            key,
            message,
        };
    }
    LoadError::Toml {
        path,
        line,
        column,
        message,
    }
}

/// `", expected one of `a`, `b`"` → `"a, b"`.
fn expected_list(rest: &str) -> String {
    let names: Vec<&str> = rest.split('`').skip(1).step_by(2).collect();
    if names.is_empty() {
        "none".to_owned()
    } else {
        names.join(", ")
    }
}
