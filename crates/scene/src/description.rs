//! The loaded scene as plain data: what every loader produces and what
//! [`crate::Scene::new`] turns into something that answers ray queries.
//!
//! Everything here is in world space and in the units of the scene format
//! (`../shared/design/scene-format.md`): lengths in scene units, angles in
//! radians (the file says degrees; loaders convert), colours as linear Rec.709
//! RGB in `Vec3`.

use std::path::PathBuf;
use std::sync::Arc;

use glam::{Vec2, Vec3};

use crate::fingerprint::{Fingerprint, Fingerprinter};
use crate::material::{MaterialKind, MaterialParam};
use crate::material_spectra::MaterialSpectra;
use crate::texture::MaterialTextures;

/// Linear Rec.709 RGB triple.
pub type Rgb = Vec3;

/// A whole scene as loaded from a file, before acceleration structures exist.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneDescription {
    /// The file the scene came from (used in error messages and reports).
    pub source: PathBuf,
    /// The camera.
    pub camera: Camera,
    /// The film resolution.
    pub film: Film,
    /// Every material; shapes refer to them by index.
    pub materials: Vec<Material>,
    /// Every triangle of every mesh and quad, already transformed to world space.
    pub triangles: Vec<Triangle>,
    /// Analytic spheres.
    pub spheres: Vec<Sphere>,
    /// Analytic open cylinders (an extension to scene format 1, see `docs/scene-format-extensions.md`).
    pub cylinders: Vec<Cylinder>,
    /// Point, spot and directional lights (area emitters are emissive materials).
    pub lights: Vec<Light>,
    /// The environment light, if any (an extension to scene format 1, see
    /// `docs/scene-format-extensions.md`).
    pub environment: Option<crate::Environment>,
    /// Participating media, the shapes that bound them and the camera's medium (an extension to
    /// scene format 1, see `docs/scene-format-extensions.md` and `docs/media.md`); empty for a
    /// scene without media.
    pub media: crate::Media,
    /// Optional render defaults from the `[render]` table; flags override them.
    pub render: RenderDefaults,
    /// What the loader skipped or had to guess, for `fppm info` and reports.
    pub notes: LoadNotes,
}

/// Counters of what a loader dropped or inferred. Skipping is not an error.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct LoadNotes {
    /// Triangles with zero area (or collinear vertices) that were skipped.
    pub degenerate_triangles: usize,
    /// Whether the camera was made up by framing the bounding box.
    pub camera_framed: bool,
    /// Free-form remarks ("material `light` uses Ka, not Ke: no emission").
    pub warnings: Vec<String>,
}

/// Pinhole or thin-lens perspective camera.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Eye position.
    pub position: Vec3,
    /// Point looked at.
    pub look_at: Vec3,
    /// Up vector (need not be orthogonal to the view direction).
    pub up: Vec3,
    /// Vertical field of view in radians, in (0, π).
    pub fov_y: f32,
    /// Lens radius; 0 is a pinhole.
    pub aperture_radius: f32,
    /// Distance to the plane in focus (> 0).
    pub focus_distance: f32,
}

/// Largest film side accepted, in pixels.
pub const MAX_FILM_SIDE: u32 = 16384;

/// Image resolution in pixels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Film {
    /// Width in pixels (> 0).
    pub width: u32,
    /// Height in pixels (> 0).
    pub height: u32,
}

impl Film {
    /// This film with `width` and/or `height` set, as `fppm render --width/--height` does: a
    /// lone side keeps the aspect ratio (the other side rounded, within [1, MAX_FILM_SIDE]).
    #[must_use]
    pub fn resized(self, width: Option<u32>, height: Option<u32>) -> Film {
        let aspect = f64::from(self.width) / f64::from(self.height);
        let side = |v: f64| (v.round() as u32).clamp(1, MAX_FILM_SIDE);
        match (width, height) {
            (Some(width), Some(height)) => Film { width, height },
            (Some(width), None) => Film {
                width,
                height: side(f64::from(width) / aspect),
            },
            (None, Some(height)) => Film {
                width: side(f64::from(height) * aspect),
                height,
            },
            (None, None) => self,
        }
    }
}

/// A named material: a scattering model plus optional emission from the front face.
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    /// Name in the source file (TOML table key, MTL `newmtl`, glTF material name or index).
    pub name: String,
    /// How light scatters.
    pub kind: MaterialKind,
    /// Emitted radiance in W/(sr·m²) per channel, leaving the front face only. Zero if none.
    pub emission: Rgb,
    /// Image textures that modulate the material (colour, emission, normal, cut-out); `None`
    /// for an untextured material, which then costs no texture work anywhere.
    pub textures: Option<Arc<MaterialTextures>>,
    /// The spectra the RGB `kind` and `emission` were derived from, for spectral transport;
    /// `None` for a material given in colours only.
    pub spectra: Option<Arc<MaterialSpectra>>,
}

/// One world-space triangle. The front face is where v0, v1, v2 appear counter-clockwise.
///
/// In declaration order (`repr(C)`): what every hit reads (positions, normals, material) is
/// the first 80 bytes, and the texture data after it is touched only by textured hits, so an
/// untextured hit reads as few cache lines as it can (docs/performance.md).
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub struct Triangle {
    /// Vertex positions.
    pub positions: [Vec3; 3],
    /// Per-vertex shading normals (unit length), if the source had them.
    pub normals: Option<[Vec3; 3]>,
    /// Index into [`SceneDescription::materials`].
    pub material: u32,
    /// Per-vertex texture coordinates (image convention: v grows downwards, see
    /// [`crate::texture`]), if the source had them.
    pub uv: Option<[Vec2; 3]>,
    /// Per-vertex tangents of a normal map's frame (glTF `TANGENT`): xyz a unit tangent along
    /// the texture's u, w = ±1 the bitangent's side, B = w·(N × T). Loaders keep them only
    /// under a normal-mapped material; without them the frame is the triangle's own (see
    /// `docs/scene-format-extensions.md`, "Textures").
    pub tangents: Option<[[f32; 4]; 3]>,
}

/// An analytic sphere.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    /// Centre.
    pub center: Vec3,
    /// Radius (> 0).
    pub radius: f32,
    /// Index into [`SceneDescription::materials`].
    pub material: u32,
}

/// An analytic open cylinder (no caps), possibly cut to an arc of its circle.
///
/// The surface is every point `center + s·axis + radius·r` with `s` in `[0, height]` and `r` a
/// unit vector perpendicular to `axis` whose angle to `facing` is at most `arc / 2`. Its front
/// face is the outside (normals pointing away from the axis). It scatters on both sides and
/// cannot emit ([`crate::Scene::new`] rejects an emissive material).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cylinder {
    /// Centre of the bottom circle.
    pub center: Vec3,
    /// Unit axis direction, from the bottom circle to the top one.
    pub axis: Vec3,
    /// Radius (> 0).
    pub radius: f32,
    /// Height along `axis` (> 0).
    pub height: f32,
    /// Angle of the circle that is kept, in radians, in (0, 2π]; 2π is the whole cylinder.
    pub arc: f32,
    /// Unit vector perpendicular to `axis` on which the kept arc is centred.
    pub facing: Vec3,
    /// Index into [`SceneDescription::materials`].
    pub material: u32,
}

impl Cylinder {
    /// Axis-aligned bounds of the whole (uncut) cylinder: the box of its two end circles.
    #[must_use]
    pub fn bounds(&self) -> crate::Aabb {
        let top = self.center + self.height * self.axis;
        let extent = self.radius * (Vec3::ONE - self.axis * self.axis).max(Vec3::ZERO).sqrt();
        crate::Aabb {
            min: self.center.min(top) - extent,
            max: self.center.max(top) + extent,
        }
    }

    /// Whether the unit vector `radial` (perpendicular to the axis) lies in the kept arc.
    #[must_use]
    pub fn in_arc(&self, radial: Vec3) -> bool {
        self.arc >= std::f32::consts::TAU || radial.dot(self.facing) >= (0.5 * self.arc).cos()
    }
}

/// A delta light source.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Light {
    /// Isotropic point light.
    Point {
        /// Position.
        position: Vec3,
        /// Radiant intensity in W/sr per channel.
        intensity: Rgb,
    },
    /// Spot light: full intensity inside `falloff_start`, smooth falloff to zero at `cone_angle`.
    Spot {
        /// Position.
        position: Vec3,
        /// Unit axis of the cone.
        direction: Vec3,
        /// Radiant intensity on the axis in W/sr per channel.
        intensity: Rgb,
        /// Half-angle of the cone in radians: no light outside it.
        cone_angle: f32,
        /// Half-angle in radians up to which the intensity is full (≤ `cone_angle`).
        falloff_start: f32,
    },
    /// Infinitely distant light.
    Directional {
        /// Unit direction the light travels.
        direction: Vec3,
        /// Irradiance in W/m² on a surface facing the light.
        irradiance: Rgb,
    },
}

/// Optional render settings stored with a scene (`[render]` table): the number of passes,
/// and render parameters as text, which `ppm` reads (`ppm::RenderParams::set`: the names,
/// their parsing and their ranges are defined there, once). The command line overrides them.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RenderDefaults {
    /// Number of passes.
    pub passes: Option<u32>,
    /// Every other key of the table with its value as text (a string without its quotes, a
    /// number or `true`/`false` as written by Rust), in the order of the keys' names.
    pub params: Vec<(String, String)>,
}

impl RenderDefaults {
    /// The text of render parameter `name`, if the scene sets it.
    #[must_use]
    pub fn get(&self, name: &str) -> Option<&str> {
        self.params
            .iter()
            .find(|(key, _)| key == name)
            .map(|(_, value)| value.as_str())
    }

    /// Sets render parameter `name` (what an importer reads from another renderer's
    /// settings), replacing an earlier value.
    pub fn set(&mut self, name: &str, value: impl ToString) {
        let value = value.to_string();
        match self.params.iter_mut().find(|(key, _)| key == name) {
            Some(entry) => entry.1 = value,
            None => self.params.push((name.to_owned(), value)),
        }
    }
}

/// The axis-aligned bounds (min, max) of triangles, spheres and cylinders; `None` if there are
/// none.
#[must_use]
pub fn primitive_bounds(
    triangles: &[Triangle],
    spheres: &[Sphere],
    cylinders: &[Cylinder],
) -> Option<(Vec3, Vec3)> {
    let mut lo = Vec3::splat(f32::INFINITY);
    let mut hi = Vec3::splat(f32::NEG_INFINITY);
    for p in triangles.iter().flat_map(|t| t.positions) {
        lo = lo.min(p);
        hi = hi.max(p);
    }
    for s in spheres {
        lo = lo.min(s.center - Vec3::splat(s.radius));
        hi = hi.max(s.center + Vec3::splat(s.radius));
    }
    for c in cylinders {
        let b = c.bounds();
        lo = lo.min(b.min);
        hi = hi.max(b.max);
    }
    (lo.cmple(hi).all()).then_some((lo, hi))
}

impl SceneDescription {
    /// A stable 64-bit fingerprint of everything in the scene that affects rendering (camera,
    /// film, materials with their textures, triangles, spheres, cylinders, lights, environment;
    /// not the file name, the `[render]` defaults or the loader's notes), so that a checkpoint
    /// is never resumed on another scene. Textures count by file, size and use, not by texel;
    /// an environment map by its texels. Media count only when there are some, so a scene
    /// without media keeps the fingerprint it had before media existed.
    #[must_use]
    pub fn fingerprint(&self) -> u64 {
        let mut h = Fingerprinter::new();
        h.add(&self.camera);
        h.add(&self.film);
        h.list(&self.materials);
        h.list(&self.triangles);
        h.list(&self.spheres);
        h.list(&self.cylinders);
        h.list(&self.lights);
        h.option(self.environment.as_ref(), |h, env| h.add(env));
        if !self.media.is_empty() {
            h.add(&self.media);
        }
        h.finish()
    }
}

impl SceneDescription {
    /// Whether the scene has participating media that some path can be in ([`Media::are_used`])
    /// or a material that only bounds them ([`MaterialKind::Interface`]): only an integrator
    /// that handles media renders it right. Media that nothing refers to do not count.
    ///
    /// [`Media::are_used`]: crate::Media::are_used
    #[must_use]
    pub fn has_media(&self) -> bool {
        self.media.are_used()
            || self
                .materials
                .iter()
                .any(|m| matches!(m.kind, MaterialKind::Interface(_)))
    }
}

impl Fingerprint for Camera {
    fn fingerprint(&self, h: &mut Fingerprinter) {
        [self.position, self.look_at, self.up]
            .iter()
            .for_each(|&v| h.vec3(v));
        [self.fov_y, self.aperture_radius, self.focus_distance]
            .iter()
            .for_each(|&x| h.f32(x));
    }
}

impl Fingerprint for Film {
    fn fingerprint(&self, h: &mut Fingerprinter) {
        h.u32(self.width);
        h.u32(self.height);
    }
}

impl Fingerprint for Material {
    /// The model by name and parameters, the emission, the textures and the spectra (the name
    /// in the file does not count). Spectra count only when there are some, so a material in
    /// colours keeps the fingerprint it had before spectra existed.
    fn fingerprint(&self, h: &mut Fingerprinter) {
        h.vec3(self.emission);
        h.add(&self.kind);
        h.option(self.textures.as_deref(), |h, t| h.add(t));
        if let Some(spectra) = self.spectra.as_deref() {
            h.str("spectra");
            h.add(spectra);
        }
    }
}

impl Fingerprint for MaterialKind {
    fn fingerprint(&self, h: &mut Fingerprinter) {
        h.str(self.name());
        for param in self.params() {
            match param {
                MaterialParam::Colour(name, c) => {
                    h.str(name);
                    h.vec3(c);
                }
                MaterialParam::Positive(name, x) => {
                    h.str(name);
                    h.f32(x);
                }
            }
        }
    }
}

impl Fingerprint for Triangle {
    fn fingerprint(&self, h: &mut Fingerprinter) {
        self.positions.iter().for_each(|&p| h.vec3(p));
        h.u32(self.material);
        h.option(self.normals, |h, normals| {
            normals.iter().for_each(|&n| h.vec3(n))
        });
        h.option(self.uv, |h, uv| uv.iter().for_each(|&v| h.vec2(v)));
        h.option(self.tangents, |h, tangents| {
            tangents.iter().flatten().for_each(|&c| h.f32(c));
        });
    }
}

impl Fingerprint for Sphere {
    fn fingerprint(&self, h: &mut Fingerprinter) {
        h.vec3(self.center);
        h.f32(self.radius);
        h.u32(self.material);
    }
}

impl Fingerprint for Cylinder {
    fn fingerprint(&self, h: &mut Fingerprinter) {
        [self.center, self.axis, self.facing]
            .iter()
            .for_each(|&v| h.vec3(v));
        [self.radius, self.height, self.arc]
            .iter()
            .for_each(|&x| h.f32(x));
        h.u32(self.material);
    }
}

impl Fingerprint for Light {
    fn fingerprint(&self, h: &mut Fingerprinter) {
        match *self {
            Light::Point {
                position,
                intensity,
            } => {
                h.str("point");
                [position, intensity].iter().for_each(|&v| h.vec3(v));
            }
            Light::Spot {
                position,
                direction,
                intensity,
                cone_angle,
                falloff_start,
            } => {
                h.str("spot");
                [position, direction, intensity]
                    .iter()
                    .for_each(|&v| h.vec3(v));
                [cone_angle, falloff_start].iter().for_each(|&x| h.f32(x));
            }
            Light::Directional {
                direction,
                irradiance,
            } => {
                h.str("directional");
                [direction, irradiance].iter().for_each(|&v| h.vec3(v));
            }
        }
    }
}
