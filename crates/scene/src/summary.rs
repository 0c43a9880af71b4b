//! A compact report of a loaded scene: what `fppm info` prints and what snapshot tests store.

use std::fmt;
use std::sync::Arc;

use glam::Vec3;
use serde::{Serialize, Serializer};

use crate::MaterialParam;
use crate::description::{Light, SceneDescription};

/// Counts and parameters of a [`SceneDescription`], for display and snapshots.
///
/// Floats serialize and display rounded to 6 significant digits so that snapshots do not flip
/// on last-bit changes.
#[derive(Clone, Debug, Serialize)]
pub struct SceneSummary {
    /// The scene file.
    pub source: String,
    /// Number of triangles.
    pub triangles: usize,
    /// Number of analytic spheres.
    pub spheres: usize,
    /// Number of analytic cylinders (never emissive).
    pub cylinders: usize,
    /// Triangles whose material emits.
    pub emissive_triangles: usize,
    /// Spheres whose material emits.
    pub emissive_spheres: usize,
    /// Delta lights by kind.
    pub lights: LightCounts,
    /// The environment light: its file, size and memory, or its constant radiance, with scale
    /// and rotation (left out of snapshots when there is none).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub environment: Option<String>,
    /// Every material, with its parameters and how much geometry uses it.
    pub materials: Vec<MaterialSummary>,
    /// The camera.
    pub camera: CameraSummary,
    /// Film width and height in pixels.
    pub film: [u32; 2],
    /// Axis-aligned bounds of all geometry (`None` if there is none).
    pub bounds: Option<Bounds>,
    /// Triangles skipped as degenerate.
    pub degenerate_triangles: usize,
    /// Whether the camera was made up by framing the bounds.
    pub camera_framed: bool,
    /// Loader warnings.
    pub warnings: Vec<String>,
    /// The texture images, once each (left out of snapshots when there are none).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub textures: Vec<TextureSummary>,
    /// The participating media, each with its coefficients and what it fills (left out of
    /// snapshots when there are none).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub media: Vec<MediumSummary>,
}

/// One participating medium of a [`SceneSummary`].
#[derive(Clone, Debug, Serialize)]
pub struct MediumSummary {
    /// Name in the scene file.
    pub name: String,
    /// Absorption coefficient σa per channel.
    #[serde(serialize_with = "rounded3")]
    pub sigma_a: Vec3,
    /// Scattering coefficient σs per channel.
    #[serde(serialize_with = "rounded3")]
    pub sigma_s: Vec3,
    /// Henyey–Greenstein asymmetry.
    #[serde(serialize_with = "rounded")]
    pub g: f32,
    /// The density grid of a heterogeneous medium: voxels per axis, largest density, edge rule.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub grid: Option<GridSummary>,
    /// Shapes (triangle ranges and spheres) with this medium on their interior side.
    pub interior_of: usize,
    /// Shapes with this medium on their exterior side.
    pub exterior_of: usize,
    /// Whether the camera sits in it.
    pub around_camera: bool,
}

/// The density grid of a [`MediumSummary`].
#[derive(Clone, Debug, Serialize)]
pub struct GridSummary {
    /// Voxels along x, y and z.
    pub size: [u32; 3],
    /// The largest density.
    #[serde(serialize_with = "rounded")]
    pub max_density: f32,
    /// What samples outside the grid read (`clamp` or `zero`).
    pub edge: &'static str,
}

/// Number of delta lights of each kind.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct LightCounts {
    /// Point lights.
    pub point: usize,
    /// Spot lights.
    pub spot: usize,
    /// Directional lights.
    pub directional: usize,
}

/// One material in a [`SceneSummary`].
#[derive(Clone, Debug, Serialize)]
pub struct MaterialSummary {
    /// Name.
    pub name: String,
    /// The model's name ([`crate::MaterialKind::name`]).
    pub kind: &'static str,
    /// Diffuse albedo, or the Lambertian base of a glossy material from an OBJ file.
    #[serde(skip_serializing_if = "Option::is_none", serialize_with = "opt3")]
    pub albedo: Option<Vec3>,
    /// Mirror or glossy reflectance; a conductor's at normal incidence.
    #[serde(skip_serializing_if = "Option::is_none", serialize_with = "opt3")]
    pub reflectance: Option<Vec3>,
    /// Dielectric index of refraction.
    #[serde(skip_serializing_if = "Option::is_none", serialize_with = "opt")]
    pub ior: Option<f32>,
    /// Glossy GGX α.
    #[serde(skip_serializing_if = "Option::is_none", serialize_with = "opt")]
    pub roughness: Option<f32>,
    /// Emitted radiance (zero if none).
    #[serde(serialize_with = "rounded3")]
    pub emission: Vec3,
    /// Triangles using the material.
    pub triangles: usize,
    /// Spheres using the material.
    pub spheres: usize,
    /// Cylinders using the material (left out of snapshots when zero).
    #[serde(skip_serializing_if = "is_zero")]
    pub cylinders: usize,
    /// What its textures modulate (`color`, `emission`, `normal`, `alpha`; left out when none).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub textures: Vec<&'static str>,
}

fn is_zero(n: &usize) -> bool {
    *n == 0
}

/// The camera in a [`SceneSummary`] (field of view in degrees).
#[derive(Clone, Debug, Serialize)]
pub struct CameraSummary {
    /// Eye position.
    #[serde(serialize_with = "rounded3")]
    pub position: Vec3,
    /// Point looked at.
    #[serde(serialize_with = "rounded3")]
    pub look_at: Vec3,
    /// Up vector.
    #[serde(serialize_with = "rounded3")]
    pub up: Vec3,
    /// Vertical field of view in degrees.
    #[serde(serialize_with = "rounded")]
    pub fov_y_degrees: f32,
    /// Lens radius.
    #[serde(serialize_with = "rounded")]
    pub aperture_radius: f32,
    /// Focus distance.
    #[serde(serialize_with = "rounded")]
    pub focus_distance: f32,
}

/// Axis-aligned bounds.
#[derive(Clone, Debug, Serialize)]
pub struct Bounds {
    /// Smallest corner.
    #[serde(serialize_with = "rounded3")]
    pub min: Vec3,
    /// Largest corner.
    #[serde(serialize_with = "rounded3")]
    pub max: Vec3,
}

/// `x` rounded to 6 significant digits, so that snapshots do not flip on last-bit changes.
fn round6(x: f32) -> f64 {
    if !x.is_finite() || x == 0.0 {
        return f64::from(x) + 0.0;
    }
    format!("{:.5e}", f64::from(x))
        .parse()
        .unwrap_or(f64::from(x))
}

/// `x` rounded, as a number.
fn rounded<S: Serializer>(x: &f32, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_f64(round6(*x))
}

/// `v` rounded, as an array of three numbers.
fn rounded3<S: Serializer>(v: &Vec3, s: S) -> Result<S::Ok, S::Error> {
    [round6(v.x), round6(v.y), round6(v.z)].serialize(s)
}

/// [`rounded`] of an optional float (`serialize_with` passes the field by reference).
fn opt<S: Serializer>(x: &Option<f32>, s: S) -> Result<S::Ok, S::Error> {
    x.map(round6).serialize(s)
}

/// [`rounded3`] of an optional vector.
fn opt3<S: Serializer>(v: &Option<Vec3>, s: S) -> Result<S::Ok, S::Error> {
    v.map(|v| [round6(v.x), round6(v.y), round6(v.z)])
        .serialize(s)
}

/// A float as the summary shows it (6 significant digits).
struct Show(f32);

impl fmt::Display for Show {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", round6(self.0))
    }
}

/// A vector as the summary shows it.
struct Show3(Vec3);

impl fmt::Display for Show3 {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let v = self.0;
        write!(f, "[{}, {}, {}]", round6(v.x), round6(v.y), round6(v.z))
    }
}

impl SceneDescription {
    /// Counts, materials, camera, film, bounds and notes of the scene.
    #[must_use]
    pub fn summary(&self) -> SceneSummary {
        let mut materials: Vec<MaterialSummary> = self
            .materials
            .iter()
            .map(|m| {
                let (mut albedo, mut reflectance, mut ior, mut roughness) =
                    (None, None, None, None);
                for param in m.kind.params() {
                    match param {
                        MaterialParam::Colour("albedo", c) => albedo = Some(c),
                        // A Lambertian base under another lobe shows as the albedo where it
                        // reflects anything.
                        MaterialParam::Colour("diffuse", c) if c != Vec3::ZERO => albedo = Some(c),
                        MaterialParam::Colour("reflectance", c) => reflectance = Some(c),
                        MaterialParam::Positive("ior", x) => ior = Some(x),
                        MaterialParam::Positive("roughness", x) => roughness = Some(x),
                        _ => {}
                    }
                }
                // A conductor shows its reflectance at normal incidence, Fresnel and tint.
                if let crate::MaterialKind::Conductor(_) = m.kind {
                    reflectance = Some(m.kind.albedo());
                }
                MaterialSummary {
                    name: m.name.clone(),
                    kind: m.kind.name(),
                    albedo,
                    reflectance,
                    ior,
                    roughness,
                    emission: m.emission,
                    triangles: 0,
                    spheres: 0,
                    cylinders: 0,
                    textures: m
                        .textures
                        .as_deref()
                        .map(crate::texture::MaterialTextures::uses)
                        .unwrap_or_default(),
                }
            })
            .collect();
        for t in &self.triangles {
            if let Some(m) = materials.get_mut(t.material as usize) {
                m.triangles += 1;
            }
        }
        for s in &self.spheres {
            if let Some(m) = materials.get_mut(s.material as usize) {
                m.spheres += 1;
            }
        }
        for c in &self.cylinders {
            if let Some(m) = materials.get_mut(c.material as usize) {
                m.cylinders += 1;
            }
        }
        let emits = |i: u32| {
            self.materials
                .get(i as usize)
                .is_some_and(|m| m.emission.max_element() > 0.0)
        };
        let mut lights = LightCounts::default();
        for l in &self.lights {
            match l {
                Light::Point { .. } => lights.point += 1,
                Light::Spot { .. } => lights.spot += 1,
                Light::Directional { .. } => lights.directional += 1,
            }
        }
        let c = &self.camera;
        SceneSummary {
            source: self.source.display().to_string(),
            triangles: self.triangles.len(),
            spheres: self.spheres.len(),
            cylinders: self.cylinders.len(),
            emissive_triangles: self.triangles.iter().filter(|t| emits(t.material)).count(),
            emissive_spheres: self.spheres.iter().filter(|s| emits(s.material)).count(),
            lights,
            environment: self.environment.as_ref().map(crate::Environment::describe),
            materials,
            camera: CameraSummary {
                position: c.position,
                look_at: c.look_at,
                up: c.up,
                fov_y_degrees: c.fov_y.to_degrees(),
                aperture_radius: c.aperture_radius,
                focus_distance: c.focus_distance,
            },
            film: [self.film.width, self.film.height],
            bounds: crate::primitive_bounds(&self.triangles, &self.spheres, &self.cylinders)
                .map(|(min, max)| Bounds { min, max }),
            degenerate_triangles: self.notes.degenerate_triangles,
            camera_framed: self.notes.camera_framed,
            warnings: self.notes.warnings.clone(),
            textures: summarize_textures(&self.materials),
            media: self.summarize_media(),
        }
    }

    fn summarize_media(&self) -> Vec<MediumSummary> {
        let media = &self.media;
        let count = |i: usize, side: fn(&crate::ShapeMedia) -> Option<u32>| {
            media
                .shapes
                .iter()
                .filter(|s| side(s) == Some(i as u32))
                .count()
        };
        media
            .list
            .iter()
            .enumerate()
            .map(|(i, m)| MediumSummary {
                name: m.name.clone(),
                sigma_a: m.sigma_a,
                sigma_s: m.sigma_s,
                g: m.g,
                grid: m.density.as_ref().map(|grid| GridSummary {
                    size: grid.size(),
                    max_density: grid.max_density(),
                    edge: grid.edge().name(),
                }),
                interior_of: count(i, |s| s.interior),
                exterior_of: count(i, |s| s.exterior),
                around_camera: media.camera == Some(i as u32),
            })
            .collect()
    }
}

impl SceneSummary {
    /// Number of emitters: emissive triangles and spheres plus delta lights.
    #[must_use]
    pub fn emitters(&self) -> usize {
        self.emissive_triangles
            + self.emissive_spheres
            + self.lights.point
            + self.lights.spot
            + self.lights.directional
            + usize::from(self.environment.is_some())
    }
}

impl fmt::Display for SceneSummary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "scene      {}", self.source)?;
        writeln!(
            f,
            "geometry   {} triangles ({} emissive), {} spheres ({} emissive), {} cylinders",
            self.triangles,
            self.emissive_triangles,
            self.spheres,
            self.emissive_spheres,
            self.cylinders
        )?;
        writeln!(
            f,
            "lights     {} point, {} spot, {} directional",
            self.lights.point, self.lights.spot, self.lights.directional
        )?;
        if let Some(env) = &self.environment {
            writeln!(f, "environment {env}")?;
        }
        let c = &self.camera;
        writeln!(
            f,
            "camera     {} -> {}, up {}, fov_y {}°, aperture {}, focus {}{}",
            Show3(c.position),
            Show3(c.look_at),
            Show3(c.up),
            Show(c.fov_y_degrees),
            Show(c.aperture_radius),
            Show(c.focus_distance),
            if self.camera_framed { " (framed)" } else { "" }
        )?;
        writeln!(f, "film       {} x {}", self.film[0], self.film[1])?;
        if let Some(b) = &self.bounds {
            writeln!(f, "bounds     {} .. {}", Show3(b.min), Show3(b.max))?;
        }
        writeln!(f, "materials  {}", self.materials.len())?;
        for m in &self.materials {
            write!(f, "  {:?} {}", m.name, m.kind)?;
            if let Some(a) = m.albedo {
                write!(f, " albedo {}", Show3(a))?;
            }
            if let Some(r) = m.reflectance {
                write!(f, " reflectance {}", Show3(r))?;
            }
            if let Some(i) = m.ior {
                write!(f, " ior {}", Show(i))?;
            }
            if let Some(r) = m.roughness {
                write!(f, " roughness {}", Show(r))?;
            }
            if m.emission != Vec3::ZERO {
                write!(f, " emission {}", Show3(m.emission))?;
            }
            if !m.textures.is_empty() {
                write!(f, " textured ({})", m.textures.join(", "))?;
            }
            write!(f, " ({} triangles, {} spheres", m.triangles, m.spheres)?;
            if m.cylinders > 0 {
                write!(f, ", {} cylinders", m.cylinders)?;
            }
            writeln!(f, ")")?;
        }
        if !self.media.is_empty() {
            writeln!(f, "media      {}", self.media.len())?;
            for m in &self.media {
                let kind = match &m.grid {
                    None => "homogeneous".to_owned(),
                    Some(grid) => format!(
                        "grid {}x{}x{} (max density {}, edge {}), at density 1:",
                        grid.size[0],
                        grid.size[1],
                        grid.size[2],
                        Show(grid.max_density),
                        grid.edge
                    ),
                };
                writeln!(
                    f,
                    "  {:?} {kind} sigma_a {} sigma_s {} g {} (interior of {}, exterior of {} shapes{})",
                    m.name,
                    Show3(m.sigma_a),
                    Show3(m.sigma_s),
                    Show(m.g),
                    m.interior_of,
                    m.exterior_of,
                    if m.around_camera {
                        "; around the camera"
                    } else {
                        ""
                    }
                )?;
            }
        }
        if !self.textures.is_empty() {
            let bytes: usize = self.textures.iter().map(|t| t.bytes).sum();
            writeln!(
                f,
                "textures   {} ({:.1} MiB)",
                self.textures.len(),
                bytes as f64 / f64::from(1 << 20)
            )?;
            for t in &self.textures {
                writeln!(
                    f,
                    "  {} {}x{} {:.1} MiB ({})",
                    t.file,
                    t.resolution[0],
                    t.resolution[1],
                    t.bytes as f64 / f64::from(1 << 20),
                    t.uses.join(", ")
                )?;
            }
        }
        if self.degenerate_triangles > 0 {
            writeln!(
                f,
                "skipped    {} degenerate triangles",
                self.degenerate_triangles
            )?;
        }
        for w in &self.warnings {
            writeln!(f, "warning    {w}")?;
        }
        Ok(())
    }
}

/// One image in a [`crate::SceneSummary`]: its file name, resolution, memory and uses.
#[derive(Clone, Debug, serde::Serialize)]
pub struct TextureSummary {
    /// The image's file name (without its directory, so that snapshots do not depend on where
    /// the scene lies).
    pub file: String,
    /// Width and height in texels.
    pub resolution: [u32; 2],
    /// Bytes of the decoded texels.
    pub bytes: usize,
    /// How materials use it: `color`, `emission`, `normal`, `alpha`, `metallic-roughness`.
    pub uses: Vec<&'static str>,
}

/// Every image the materials of `materials` use, once each, in order of first use.
pub(crate) fn summarize_textures(materials: &[crate::Material]) -> Vec<TextureSummary> {
    let mut out: Vec<(Arc<crate::texture::Image>, TextureSummary)> = Vec::new();
    for t in materials.iter().filter_map(|m| m.textures.as_deref()) {
        let uses = [
            (t.color.as_ref(), "color"),
            (t.emission.as_ref(), "emission"),
            (t.normal.as_ref().map(|n| &n.texture), "normal"),
            (t.alpha.as_ref().and_then(|a| a.texture.as_ref()), "alpha"),
            (
                t.metallic_roughness.as_ref().map(|m| &m.texture),
                "metallic-roughness",
            ),
        ];
        for (texture, what) in uses {
            let Some(texture) = texture else { continue };
            let entry = match out.iter().position(|(i, _)| Arc::ptr_eq(i, &texture.image)) {
                Some(i) => &mut out[i].1,
                None => {
                    let image = &texture.image;
                    out.push((
                        Arc::clone(image),
                        TextureSummary {
                            file: image.path().file_name().map_or_else(
                                || image.path().display().to_string(),
                                |n| n.to_string_lossy().into_owned(),
                            ),
                            resolution: [image.resolution().0, image.resolution().1],
                            bytes: image.memory(),
                            uses: Vec::new(),
                        },
                    ));
                    &mut out.last_mut().expect("just pushed").1
                }
            };
            if !entry.uses.contains(&what) {
                entry.uses.push(what);
            }
        }
    }
    out.into_iter().map(|(_, s)| s).collect()
}
