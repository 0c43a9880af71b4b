//! Scene loaders: TOML scene files (format version 1), lone OBJ/MTL files and glTF 2.0.
//!
//! Every loader produces a [`SceneDescription`] and goes through the same final checks
//! ([`finish`]): all numbers finite, no negative radiance, at least one triangle or sphere,
//! no emissive material whose triangles all have zero area, and (unless
//! [`LoadOptions::require_emitter`] is off) at least one emitter.
//!
//! Decisions that the scene format leaves open:
//! - A scene without a camera (a lone OBJ, a glTF without a perspective camera, a TOML file
//!   without `[camera]`) gets one that frames the bounding box from +Z ([`frame_camera`]);
//!   [`LoadNotes::camera_framed`] says so.
//! - The film defaults to [`DEFAULT_FILM_WIDTH`] × [`DEFAULT_FILM_HEIGHT`]; a glTF camera with an
//!   aspect ratio keeps the width and derives the height. Film sides are limited to
//!   [`MAX_FILM_SIDE`].
//! - Triangles with zero area are skipped and counted, never an error.

pub(crate) mod files;
mod frame;
mod gltf;
mod gltf_document;
mod import;
mod mitsuba;
mod obj;
mod pbrt;
mod ply;
mod polygon;
mod serialized;
mod spectrum;
mod toml;

use std::collections::HashSet;
use std::path::{Path, PathBuf};

use glam::Vec3;

use crate::Environment;
use crate::description::{
    Camera, Cylinder, Film, Light, LoadNotes, Material, RenderDefaults, SceneDescription, Sphere,
    Triangle,
};
use crate::error::LoadError;
use crate::validate;
pub(crate) use crate::validate::fmt_vec;

pub use files::{FileSource, MemoryFiles};
pub use frame::FRAMED_FOV_Y_DEGREES;
pub(crate) use frame::{bounds, frame_camera};
pub use gltf::METALLIC_THRESHOLD;
pub(crate) use gltf::{MIRROR_ROUGHNESS, gltf_kind};
pub use obj::DEFAULT_ALBEDO;

/// Film width used when the scene file gives none.
pub const DEFAULT_FILM_WIDTH: u32 = 512;
/// Film height used when the scene file gives none (and no glTF camera aspect ratio).
pub const DEFAULT_FILM_HEIGHT: u32 = 512;
/// Largest film width or height accepted.
pub const MAX_FILM_SIDE: u32 = 16384;

/// Options of [`load_with`]. Build them with `LoadOptions { require_emitter: false,
/// ..Default::default() }` or [`LoadOptions::allow_no_emitter`].
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LoadOptions {
    /// Fail with [`LoadError::NoEmitter`] when nothing emits light (the default, and what
    /// [`load`] does). Turn it off to inspect a scene (`fppm info`) or to load a bare mesh.
    pub require_emitter: bool,
    /// An environment map (`.exr` or `.hdr`) to light the scene with, replacing the scene's
    /// own environment if it has one (the `--env` flag).
    pub environment: Option<PathBuf>,
}

impl Default for LoadOptions {
    fn default() -> Self {
        Self {
            require_emitter: true,
            environment: None,
        }
    }
}

impl LoadOptions {
    /// Options that accept a scene without any emitter.
    #[must_use]
    pub fn allow_no_emitter() -> Self {
        Self {
            require_emitter: false,
            environment: None,
        }
    }
}

/// Loads a scene file, choosing the loader by extension: `.toml`, `.obj`, `.gltf`, `.glb`,
/// `.xml` (Mitsuba 3) or `.pbrt` (pbrt-v4) (case-insensitive). The scene must contain an emitter.
///
/// # Errors
/// Any [`LoadError`]: unreadable file, unknown extension, malformed or out-of-range content,
/// empty scene, or no emitter.
pub fn load(path: &Path) -> Result<SceneDescription, LoadError> {
    load_with(path, &LoadOptions::default())
}

/// Loads a scene file like [`load`], with options.
///
/// # Errors
/// As [`load`]; [`LoadError::NoEmitter`] only if `options.require_emitter` is set.
pub fn load_with(path: &Path, options: &LoadOptions) -> Result<SceneDescription, LoadError> {
    let extension = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    match extension.as_str() {
        "toml" => {
            let text = read_text(path)?;
            toml::load_toml(&text, path, options)
        }
        "obj" => {
            let mesh = obj::load_obj(path)?;
            mesh.into_scene(path, options)
        }
        "gltf" | "glb" => {
            let mesh = gltf::load_gltf(path)?;
            mesh.into_scene(path, options)
        }
        "xml" => mitsuba::load_mitsuba(path, options),
        "pbrt" => pbrt::load_pbrt(path, options),
        _ => Err(LoadError::UnsupportedExtension {
            path: path.to_path_buf(),
            extension,
        }),
    }
}

/// Loads a scene like [`load_with`], reading `path` and every file it refers to from `files`
/// instead of the file system: a scene held in memory, with its meshes, includes and buffers.
/// Errors name the paths as the scene gives them.
///
/// ```
/// use std::path::Path;
/// use geometry::{LoadOptions, MemoryFiles, load_from};
///
/// let files = MemoryFiles::new()
///     .with("/s/scene.toml", "format = 1\n[[shapes]]\ntype = \"mesh\"\nfile = \"quad.obj\"\n")
///     .with("/s/quad.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n");
/// let options = LoadOptions::allow_no_emitter();
/// let scene = load_from(Path::new("/s/scene.toml"), files, &options).unwrap();
/// assert_eq!(scene.triangles.len(), 2);
/// ```
///
/// # Errors
/// As [`load_with`]; a file the source does not have is [`LoadError::Io`] (not found).
pub fn load_from(
    path: &Path,
    files: impl FileSource + 'static,
    options: &LoadOptions,
) -> Result<SceneDescription, LoadError> {
    let _installed = files::install(std::rc::Rc::new(files));
    load_with(path, options)
}

/// Parses a TOML scene held in memory, as if it had been read from `source`: paths inside
/// resolve relative to `source`'s parent directory, and errors name `source`. The scene must
/// contain an emitter.
///
/// # Errors
/// As [`load`] for a `.toml` file (there is no IO error for the text itself).
pub fn load_toml_str(text: &str, source: &Path) -> Result<SceneDescription, LoadError> {
    toml::load_toml(text, source, &LoadOptions::default())
}

/// [`load_toml_str`] with options.
///
/// # Errors
/// As [`load_toml_str`]; [`LoadError::NoEmitter`] only if `options.require_emitter` is set.
pub fn load_toml_str_with(
    text: &str,
    source: &Path,
    options: &LoadOptions,
) -> Result<SceneDescription, LoadError> {
    toml::load_toml(text, source, options)
}

/// Reads a whole file as UTF-8 text.
pub(crate) fn read_text(path: &Path) -> Result<String, LoadError> {
    let bytes = read_bytes(path)?;
    String::from_utf8(bytes).map_err(|_| LoadError::NotUtf8 {
        path: path.to_path_buf(),
    })
}

/// Reads a whole file.
pub(crate) fn read_bytes(path: &Path) -> Result<Vec<u8>, LoadError> {
    files::read(path).map_err(|source| LoadError::Io {
        path: path.to_path_buf(),
        source,
    })
}

/// Geometry and materials read from one mesh file (OBJ or glTF), in the file's own space
/// (glTF node transforms already applied). Triangle material indices are local.
#[derive(Debug, Default)]
pub(crate) struct MeshData {
    pub(crate) materials: Vec<Material>,
    pub(crate) triangles: Vec<Triangle>,
    /// Local material indices that had at least one degenerate triangle.
    pub(crate) degenerate_materials: HashSet<u32>,
    pub(crate) degenerate_triangles: usize,
    pub(crate) warnings: Vec<String>,
    /// A camera from the file (glTF), with the aspect ratio (width / height) if it gives one.
    pub(crate) camera: Option<(Camera, Option<f32>)>,
    /// Delta lights from the file (glTF `KHR_lights_punctual`).
    pub(crate) lights: Vec<Light>,
}

impl MeshData {
    /// Adds a triangle unless it is degenerate (zero area), which is counted instead.
    pub(crate) fn push_triangle(
        &mut self,
        positions: [Vec3; 3],
        normals: Option<[Vec3; 3]>,
        uv: Option<[glam::Vec2; 3]>,
        tangents: Option<[[f32; 4]; 3]>,
        material: u32,
    ) {
        if is_degenerate(positions) {
            self.degenerate_triangles += 1;
            self.degenerate_materials.insert(material);
            return;
        }
        self.triangles.push(Triangle {
            positions,
            normals: normals.and_then(clean_normals),
            material,
            uv,
            tangents,
        });
    }

    /// Turns a lone mesh file into a whole scene: its camera or a framed one, default film.
    fn into_scene(self, path: &Path, options: &LoadOptions) -> Result<SceneDescription, LoadError> {
        let (camera, film) = match self.camera {
            Some((camera, aspect)) => (Some(camera), film_for_aspect(aspect)),
            None => (None, default_film()),
        };
        let parts = SceneParts {
            camera,
            film,
            materials: self.materials,
            triangles: self.triangles,
            spheres: Vec::new(),
            cylinders: Vec::new(),
            lights: self.lights,
            environment: None,
            render: RenderDefaults::default(),
            notes: LoadNotes {
                degenerate_triangles: self.degenerate_triangles,
                camera_framed: false,
                warnings: self.warnings,
            },
            degenerate_materials: self.degenerate_materials,
        };
        finish(path, parts, options)
    }
}

/// Default film.
pub(crate) fn default_film() -> Film {
    Film {
        width: DEFAULT_FILM_WIDTH,
        height: DEFAULT_FILM_HEIGHT,
    }
}

/// Film of the default width whose height follows an aspect ratio (width / height).
fn film_for_aspect(aspect: Option<f32>) -> Film {
    match aspect {
        Some(a) if a.is_finite() && a > 0.0 => {
            let height = (DEFAULT_FILM_WIDTH as f32 / a).round();
            Film {
                width: DEFAULT_FILM_WIDTH,
                height: height.clamp(1.0, MAX_FILM_SIDE as f32) as u32,
            }
        }
        _ => default_film(),
    }
}

/// Whether a triangle has (numerically) zero area: collinear or coincident vertices.
pub(crate) fn is_degenerate(p: [Vec3; 3]) -> bool {
    let e1 = p[1] - p[0];
    let e2 = p[2] - p[0];
    let cross = e1.cross(e2).length();
    let scale = e1.length_squared().max(e2.length_squared());
    !(cross.is_finite() && cross > 0.0 && cross > 1e-12 * scale)
}

/// A vertex tangent `[x, y, z, w]` (see [`Triangle::tangents`]) carried through the affine map
/// `matrix`: xyz by its linear part and renormalised (a tangent is a direction in the surface);
/// a mirroring map (`flip`, negative determinant) turns N × T around, so w changes sign. `None`
/// if the tangent vanishes.
pub(crate) fn transform_tangent(
    [x, y, z, w]: [f32; 4],
    matrix: glam::Mat4,
    flip: bool,
) -> Option<[f32; 4]> {
    let t = matrix
        .transform_vector3(Vec3::new(x, y, z))
        .try_normalize()?;
    Some([t.x, t.y, t.z, if flip { -w } else { w }])
}

/// A triangle's tangents carried through `matrix` ([`transform_tangent`]); a mirroring map also
/// swaps vertices 1 and 2, as the loaders swap the positions. `None` if a tangent vanishes.
pub(crate) fn transform_tangents(
    tangents: [[f32; 4]; 3],
    matrix: glam::Mat4,
    flip: bool,
) -> Option<[[f32; 4]; 3]> {
    let [a, b, c] = tangents.map(|t| transform_tangent(t, matrix, flip));
    let (a, b, c) = (a?, b?, c?);
    Some(if flip { [a, c, b] } else { [a, b, c] })
}

/// Normalises shading normals; drops them if any is zero or not finite.
fn clean_normals(normals: [Vec3; 3]) -> Option<[Vec3; 3]> {
    let mut out = [Vec3::ZERO; 3];
    for (o, n) in out.iter_mut().zip(normals) {
        *o = n.try_normalize()?;
    }
    Some(out)
}

/// Everything a loader gathered, before the final checks.
pub(crate) struct SceneParts {
    pub(crate) camera: Option<Camera>,
    pub(crate) film: Film,
    pub(crate) materials: Vec<Material>,
    pub(crate) triangles: Vec<Triangle>,
    pub(crate) spheres: Vec<Sphere>,
    pub(crate) cylinders: Vec<Cylinder>,
    pub(crate) lights: Vec<Light>,
    pub(crate) environment: Option<Environment>,
    pub(crate) render: RenderDefaults,
    pub(crate) notes: LoadNotes,
    /// Material indices that lost at least one triangle as degenerate.
    pub(crate) degenerate_materials: HashSet<u32>,
}

/// The checks every loader ends with, and the camera framing.
pub(crate) fn finish(
    path: &Path,
    parts: SceneParts,
    options: &LoadOptions,
) -> Result<SceneDescription, LoadError> {
    let SceneParts {
        camera,
        film,
        materials,
        triangles,
        spheres,
        cylinders,
        lights,
        mut environment,
        render,
        mut notes,
        degenerate_materials,
    } = parts;
    if let Some(file) = &options.environment {
        let (env, negative) = Environment::from_file(file)?;
        if negative > 0 {
            notes.warnings.push(format!(
                "{}: {negative} negative texels read as 0",
                file.display()
            ));
        }
        if environment.is_some() {
            notes.warnings.push(format!(
                "--env {} replaces the scene's environment",
                file.display()
            ));
        }
        environment = Some(env);
    }
    if let Some(env) = &environment {
        validate::environment(env).map_err(|e| e.in_file(path))?;
    }
    validate::materials_and_lights(&materials, &lights).map_err(|e| e.in_file(path))?;
    if triangles.is_empty() && spheres.is_empty() && cylinders.is_empty() {
        return Err(LoadError::EmptyScene {
            path: path.to_path_buf(),
        });
    }
    let mut used = vec![false; materials.len()];
    for m in triangles
        .iter()
        .map(|t| t.material)
        .chain(spheres.iter().map(|s| s.material))
        .chain(cylinders.iter().map(|c| c.material))
    {
        if let Some(u) = used.get_mut(m as usize) {
            *u = true;
        }
    }
    let is_emissive = |m: &Material| m.emission.max_element() > 0.0;
    let mut sorted_degenerate: Vec<u32> = degenerate_materials.into_iter().collect();
    sorted_degenerate.sort_unstable();
    for m in sorted_degenerate {
        if let Some(material) = materials.get(m as usize)
            && is_emissive(material)
            && !used[m as usize]
        {
            return Err(LoadError::ZeroAreaEmitter {
                path: path.to_path_buf(),
                material: material.name.clone(),
            });
        }
    }
    let has_area_emitter = materials
        .iter()
        .zip(&used)
        .any(|(m, &u)| u && is_emissive(m));
    let has_delta_emitter = lights
        .iter()
        .any(|l| validate::light_power(l).max_element() > 0.0);
    let has_environment = environment
        .as_ref()
        .is_some_and(|env| env.integrated_radiance().max_element() > 0.0);
    if options.require_emitter && !has_area_emitter && !has_delta_emitter && !has_environment {
        return Err(LoadError::NoEmitter {
            path: path.to_path_buf(),
        });
    }
    let camera = match camera {
        Some(c) => c,
        None => {
            notes.camera_framed = true;
            let aspect = film.width as f32 / film.height as f32;
            frame_camera(&triangles, &spheres, &cylinders, aspect)
        }
    };
    let description = SceneDescription {
        source: PathBuf::from(path),
        camera,
        film,
        materials,
        triangles,
        spheres,
        cylinders,
        lights,
        environment,
        render,
        notes,
    };
    validate::primitives(&description).map_err(|e| e.in_file(path))?;
    Ok(description)
}
