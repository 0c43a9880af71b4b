//! A compact report of a loaded scene: what `fppm info` prints and what snapshot tests store.

use std::fmt;

use glam::Vec3;
use serde::{Serialize, Serializer};

use crate::description::{Light, MaterialKind, SceneDescription};

/// Counts and parameters of a [`SceneDescription`], for display and snapshots.
///
/// Floats serialize rounded to 6 significant digits so that snapshots do not flip on
/// last-bit changes.
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
    /// `diffuse`, `mirror`, `dielectric` or `glossy`.
    pub kind: &'static str,
    /// Diffuse albedo, or the Lambertian base of a glossy material from an OBJ file.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub albedo: Option<Rgb6>,
    /// Mirror or glossy reflectance.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reflectance: Option<Rgb6>,
    /// Dielectric index of refraction.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ior: Option<F6>,
    /// Glossy GGX α.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub roughness: Option<F6>,
    /// Emitted radiance (zero if none).
    pub emission: Rgb6,
    /// Triangles using the material.
    pub triangles: usize,
    /// Spheres using the material.
    pub spheres: usize,
    /// Cylinders using the material (left out of snapshots when zero).
    #[serde(skip_serializing_if = "is_zero")]
    pub cylinders: usize,
}

fn is_zero(n: &usize) -> bool {
    *n == 0
}

/// The camera in a [`SceneSummary`] (field of view in degrees).
#[derive(Clone, Debug, Serialize)]
pub struct CameraSummary {
    /// Eye position.
    pub position: Rgb6,
    /// Point looked at.
    pub look_at: Rgb6,
    /// Up vector.
    pub up: Rgb6,
    /// Vertical field of view in degrees.
    pub fov_y_degrees: F6,
    /// Lens radius.
    pub aperture_radius: F6,
    /// Focus distance.
    pub focus_distance: F6,
}

/// Axis-aligned bounds.
#[derive(Clone, Debug, Serialize)]
pub struct Bounds {
    /// Smallest corner.
    pub min: Rgb6,
    /// Largest corner.
    pub max: Rgb6,
}

/// A float that serializes rounded to 6 significant digits.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct F6(pub f32);

/// Three floats that serialize rounded to 6 significant digits.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rgb6(pub Vec3);

fn round6(x: f32) -> f64 {
    if !x.is_finite() || x == 0.0 {
        return f64::from(x) + 0.0;
    }
    format!("{:.5e}", f64::from(x))
        .parse()
        .unwrap_or(f64::from(x))
}

impl Serialize for F6 {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_f64(round6(self.0))
    }
}

impl Serialize for Rgb6 {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        [round6(self.0.x), round6(self.0.y), round6(self.0.z)].serialize(s)
    }
}

impl fmt::Display for F6 {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", round6(self.0))
    }
}

impl fmt::Display for Rgb6 {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "[{}, {}, {}]",
            round6(self.0.x),
            round6(self.0.y),
            round6(self.0.z)
        )
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
                let (kind, albedo, reflectance, ior, roughness) = match m.kind {
                    MaterialKind::Diffuse { albedo } => {
                        ("diffuse", Some(Rgb6(albedo)), None, None, None)
                    }
                    MaterialKind::Mirror { reflectance } => {
                        ("mirror", None, Some(Rgb6(reflectance)), None, None)
                    }
                    MaterialKind::Dielectric { ior } => {
                        ("dielectric", None, None, Some(F6(ior)), None)
                    }
                    MaterialKind::Glossy {
                        reflectance,
                        roughness,
                        diffuse,
                    } => (
                        "glossy",
                        (diffuse != Vec3::ZERO).then_some(Rgb6(diffuse)),
                        Some(Rgb6(reflectance)),
                        None,
                        Some(F6(roughness)),
                    ),
                };
                MaterialSummary {
                    name: m.name.clone(),
                    kind,
                    albedo,
                    reflectance,
                    ior,
                    roughness,
                    emission: Rgb6(m.emission),
                    triangles: 0,
                    spheres: 0,
                    cylinders: 0,
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
            materials,
            camera: CameraSummary {
                position: Rgb6(c.position),
                look_at: Rgb6(c.look_at),
                up: Rgb6(c.up),
                fov_y_degrees: F6(c.fov_y.to_degrees()),
                aperture_radius: F6(c.aperture_radius),
                focus_distance: F6(c.focus_distance),
            },
            film: [self.film.width, self.film.height],
            bounds: crate::load::bounds(&self.triangles, &self.spheres, &self.cylinders).map(
                |(min, max)| Bounds {
                    min: Rgb6(min),
                    max: Rgb6(max),
                },
            ),
            degenerate_triangles: self.notes.degenerate_triangles,
            camera_framed: self.notes.camera_framed,
            warnings: self.notes.warnings.clone(),
        }
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
        let c = &self.camera;
        writeln!(
            f,
            "camera     {} -> {}, up {}, fov_y {}°, aperture {}, focus {}{}",
            c.position,
            c.look_at,
            c.up,
            c.fov_y_degrees,
            c.aperture_radius,
            c.focus_distance,
            if self.camera_framed { " (framed)" } else { "" }
        )?;
        writeln!(f, "film       {} x {}", self.film[0], self.film[1])?;
        if let Some(b) = &self.bounds {
            writeln!(f, "bounds     {} .. {}", b.min, b.max)?;
        }
        writeln!(f, "materials  {}", self.materials.len())?;
        for m in &self.materials {
            write!(f, "  {:?} {}", m.name, m.kind)?;
            if let Some(a) = m.albedo {
                write!(f, " albedo {a}")?;
            }
            if let Some(r) = m.reflectance {
                write!(f, " reflectance {r}")?;
            }
            if let Some(i) = m.ior {
                write!(f, " ior {i}")?;
            }
            if let Some(r) = m.roughness {
                write!(f, " roughness {r}")?;
            }
            if m.emission.0 != Vec3::ZERO {
                write!(f, " emission {}", m.emission)?;
            }
            write!(f, " ({} triangles, {} spheres", m.triangles, m.spheres)?;
            if m.cylinders > 0 {
                write!(f, ", {} cylinders", m.cylinders)?;
            }
            writeln!(f, ")")?;
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
