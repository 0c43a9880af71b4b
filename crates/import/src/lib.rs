//! Scene importers: every scene file format fppm reads, turned into the runtime's plain
//! [`SceneDescription`] (crate `scene`), with the images the files refer to decoded into the
//! runtime's types (textures into [`scene::texture::Image`], environment maps into
//! [`scene::EnvironmentMap`]).
//!
//! [`load()`] picks the importer by extension: `.toml` scene files of format version 1
//! (`toml/`), lone `.obj` files with their `.mtl` (`obj.rs`), `.gltf`/`.glb` files (`gltf.rs`),
//! Mitsuba 3 `.xml` (`mitsuba/`) and pbrt-v4 `.pbrt` scenes (`pbrt/`), whose mapping is in
//! `docs/scene-import.md`; the last two share a world-space builder (`builder.rs`), and PLY
//! (`ply.rs`) and Mitsuba `.serialized` (`serialized.rs`) meshes. [`load_toml_str`] reads a
//! TOML scene held in memory, [`load_from`] reads a scene and the files it refers to from a
//! [`FileSource`] (e.g. [`MemoryFiles`]) instead of the file system, and [`load_with`] takes
//! [`LoadOptions`] (e.g. to accept a scene without emitters for `fppm info`).
//! [`environment_from_file`] reads an environment map alone (`fppm render --env`). Every
//! failure is a [`LoadError`] naming the file. A new format is one module here plus one arm of
//! [`load_with`].
//!
//! Every importer goes through the same final checks (`finish`): the runtime's
//! [`scene::validate`] (all numbers finite, no negative radiance, material indices in range), at
//! least one triangle, sphere or cylinder, no emissive material whose triangles all have zero
//! area, and (unless [`LoadOptions::require_emitter`] is off) at least one emitter.
//!
//! What the importers decide where the scene format (`shared/design/scene-format.md`) is
//! silent:
//! - no camera (lone OBJ, glTF without a perspective camera, TOML without `[camera]`): a
//!   pinhole on the +Z side of the bounding box looking down −Z at its centre, up +Y,
//!   [`FRAMED_FOV_Y_DEGREES`], far enough that the box's front face fills the image with a 5 %
//!   margin ([`LoadNotes::camera_framed`] is set);
//! - film [`DEFAULT_FILM_WIDTH`] × [`DEFAULT_FILM_HEIGHT`] unless given; a glTF camera's aspect
//!   ratio sets the height; sides at most [`scene::MAX_FILM_SIDE`];
//! - OBJ faces without a (loadable) material get a diffuse material of albedo
//!   [`DEFAULT_ALBEDO`]; a missing MTL file is a warning, a malformed one an error; `Ka` is
//!   never emission (a warning says so when it looks like it was meant to be);
//! - glTF materials with metallic ≥ [`scene::texture::METALLIC_THRESHOLD`] are conductors
//!   (mirror below roughness 0.01, else glossy with α = roughness²:
//!   [`scene::texture::MetallicRoughness::kind`]);
//! - zero-area triangles are skipped and counted in [`LoadNotes::degenerate_triangles`];
//!   an emissive material left with no area is an error ([`LoadError::ZeroAreaEmitter`]).

mod builder;
mod environment;
mod error;
pub(crate) mod files;
mod frame;
mod gltf;
mod gltf_document;
mod gltf_material;
mod guard;
mod image_file;
mod mitsuba;
mod obj;
mod pbrt;
mod ply;
mod polygon;
mod serialized;
mod spectrum;
mod toml;
mod vol;

use std::collections::HashSet;
use std::path::{Path, PathBuf};

use glam::Vec3;
use scene::validate::{self, Invalid};
use scene::{
    Camera, Cylinder, Environment, Film, Light, LoadNotes, MAX_FILM_SIDE, Material, RenderDefaults,
    SceneDescription, Sphere, Triangle,
};

pub use environment::{environment_from_file, load_environment_map};
pub use error::LoadError;
pub use files::{FileSource, MemoryFiles};
pub use frame::FRAMED_FOV_Y_DEGREES;
pub(crate) use frame::frame_camera;
pub use guard::containing_a_panic;
pub use obj::DEFAULT_ALBEDO;
pub(crate) use scene::validate::fmt_vec;
pub use vol::write_vol;

/// Film width used when the scene file gives none.
pub const DEFAULT_FILM_WIDTH: u32 = 512;
/// Film height used when the scene file gives none (and no glTF camera aspect ratio).
pub const DEFAULT_FILM_HEIGHT: u32 = 512;
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
/// use import::{LoadOptions, MemoryFiles, load_from};
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
            media: scene::Media::default(),
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
    /// Participating media (none unless the file has some).
    pub(crate) media: scene::Media,
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
        media,
        render,
        mut notes,
        degenerate_materials,
    } = parts;
    if let Some(file) = &options.environment {
        let (env, negative) = environment_from_file(file)?;
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
        validate::environment(env).map_err(|e| invalid_in_file(e, path))?;
    }
    validate::materials_and_lights(&materials, &lights).map_err(|e| invalid_in_file(e, path))?;
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
        media,
        render,
        notes,
    };
    validate::primitives(&description).map_err(|e| invalid_in_file(e, path))?;
    validate::media(&description).map_err(|e| invalid_in_file(e, path).into_bad_medium())?;
    Ok(description)
}

/// The importers' error for a problem of the description read from the file `path`.
pub(crate) fn invalid_in_file(invalid: Invalid, path: &Path) -> LoadError {
    let message = invalid.to_string();
    let (key, message) = match invalid {
        Invalid::Value { key, message } => (key, message),
        Invalid::MaterialIndex { what, .. } => (what, message),
        Invalid::NoPower => {
            return LoadError::NoEmitter {
                path: path.to_path_buf(),
            };
        }
        // A kind of problem this version does not know yet is reported by its message.
        _ => (String::from("scene"), message),
    };
    LoadError::InvalidValue {
        path: path.to_path_buf(),
        key,
        message,
    }
}
