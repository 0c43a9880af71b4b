//! pbrt-v4 scenes (`.pbrt`), with pbrt-v4's conventions (checked against its documentation
//! and source, `src/pbrt/parser.cpp`, `scene.cpp`, `cameras.cpp`, `lights.cpp`).
//!
//! The parser follows `Include`/`Import` (paths relative to the main scene file's folder, as
//! pbrt's search directory), keeps the graphics state (CTM, material, area light, reverse
//! orientation) with `AttributeBegin`/`End`, named coordinate systems (`camera` is the camera's
//! frame), and flattens `ObjectBegin`/`ObjectInstance`. The mapping to fppm is tabulated in
//! `docs/scene-import.md`. Conventions:
//! - `Camera` takes the CTM as camera-from-world. pbrt's camera space is left-handed (+x is the
//!   image's right, +y up, +z forward), so its images are mirrored relative to a right-handed
//!   camera with the same position, view and up. fppm's camera cannot mirror, so when the
//!   camera's x axis is not forward × up the whole world is reflected across the camera's
//!   vertical plane instead ([`mirror_fix`]): the image is then pbrt's, pixel for pixel.
//! - `fov` spans the image's shorter side; `Film` defaults to 1280 × 720.
//! - Triangles face the side their vertices turn counter-clockwise (pbrt's
//!   `cross(p0 − p2, p1 − p2)`), flipped by `ReverseOrientation`; area lights emit from the
//!   front only (`twosided` is warned).
//! - `Integrator "maxdepth"` is fppm's `max_depth` (both count scattering events).
//! - Motion blur (`ActiveTransform`) keeps the shutter-open transform, with a warning.
//! - `loopsubdiv` is subdivided as pbrt does it (`loop_subdiv.rs`).

mod build;
mod loop_subdiv;
mod materials;
mod media;
mod params;
mod parser;
mod shapes;
mod textures;
mod tokenizer;

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use glam::{DMat4, DVec3, Vec3};

use self::tokenizer::{Tok, Token, tokenize};
use super::LoadOptions;
use super::builder::{self, Builder, IndexedMesh};
use super::spectrum::{self, SpectrumUse};
use crate::error::LoadError;
use scene::{Camera, Film, Light, Material, MaterialKind, RenderDefaults, Rgb, SceneDescription};

/// Deepest `Include` nesting accepted (cycles are caught before that).
const MAX_INCLUDE_DEPTH: usize = 64;
/// Loads a pbrt-v4 scene.
pub(crate) fn load_pbrt(path: &Path, options: &LoadOptions) -> Result<SceneDescription, LoadError> {
    let mut parser = Parser {
        files: Vec::new(),
        base: path.parent().map(Path::to_path_buf).unwrap_or_default(),
        state: State::default(),
        stack: Vec::new(),
        named_coords: HashMap::new(),
        camera: None,
        film: Film {
            width: 1280,
            height: 720,
        },
        render: RenderDefaults::default(),
        materials: Vec::new(),
        named_materials: HashMap::new(),
        textures: HashMap::new(),
        images: crate::image_file::TextureCache::default(),
        shapes: Vec::new(),
        objects: HashMap::new(),
        current_object: None,
        lights: Vec::new(),
        warnings: Vec::new(),
        include_stack: Vec::new(),
        active: Active::All,
        media: Vec::new(),
        medium_locs: Vec::new(),
        medium_index: HashMap::new(),
        camera_medium: None,
    };
    parser.parse_file(path, None)?;
    parser.build(path, options)
}

/// One parameter: `"type name" value-or-list`.
#[derive(Clone, Debug)]
struct Param {
    ty: String,
    name: String,
    values: Vec<Value>,
    file: usize,
    line: u32,
    column: u32,
}

#[derive(Clone, Debug)]
enum Value {
    Num(f64),
    Str(String),
    Bool(bool),
}

/// A directive's parameter list.
#[derive(Clone, Debug, Default)]
struct Params(Vec<Param>);

/// A sampled spectrum: wavelengths (nm) and values.
type Samples = (Vec<f64>, Vec<f64>);

/// Where something was written: file index, line, column.
#[derive(Clone, Copy, Debug)]
struct Loc {
    file: usize,
    line: u32,
    column: u32,
}

#[derive(Clone, Debug)]
enum MaterialRef {
    /// Diffuse 0.5, pbrt's default.
    Default,
    /// Index into `Parser::materials`.
    Anonymous(usize),
    Named(String, Loc),
}

#[derive(Clone, Debug)]
struct AreaLight {
    params: Params,
    loc: Loc,
}

#[derive(Clone, Debug)]
struct State {
    ctm: DMat4,
    reverse: bool,
    material: MaterialRef,
    area: Option<AreaLight>,
    /// `MediumInterface "inside" "outside"`: the media's names ("" is vacuum) and where it was
    /// written, `None` before any.
    media: Option<MediumNames>,
}

/// The names of a `MediumInterface` (an empty name is vacuum) and where it was written.
#[derive(Clone, Debug)]
struct MediumNames {
    inside: String,
    outside: String,
    loc: Loc,
}

impl Default for State {
    fn default() -> Self {
        Self {
            ctm: DMat4::IDENTITY,
            reverse: false,
            material: MaterialRef::Default,
            area: None,
            media: None,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Active {
    Start,
    End,
    All,
}

#[derive(Clone, Debug)]
struct ShapeRecord {
    kind: String,
    params: Params,
    state: State,
    loc: Loc,
}

#[derive(Clone, Debug)]
struct MaterialDef {
    kind: String,
    params: Params,
    loc: Loc,
}

#[derive(Clone, Debug)]
struct TextureDef {
    class: String,
    params: Params,
    loc: Loc,
}

#[derive(Clone, Debug)]
struct LightRecord {
    kind: String,
    params: Params,
    ctm: DMat4,
    loc: Loc,
}

struct Parser {
    files: Vec<PathBuf>,
    /// pbrt's search directory: the main file's folder.
    base: PathBuf,
    state: State,
    /// Saved states of `AttributeBegin` (and `TransformBegin`, which saves only the CTM).
    stack: Vec<(State, Loc, bool)>,
    named_coords: HashMap<String, DMat4>,
    /// World-from-camera, fov (degrees), lens radius, focal distance, and where.
    camera: Option<(DMat4, f64, f64, f64)>,
    film: Film,
    render: RenderDefaults,
    materials: Vec<MaterialDef>,
    named_materials: HashMap<String, MaterialDef>,
    textures: HashMap<String, TextureDef>,
    /// The images of the imagemap textures, each decoded once.
    images: crate::image_file::TextureCache,
    shapes: Vec<ShapeRecord>,
    objects: HashMap<String, Vec<ShapeRecord>>,
    current_object: Option<(String, Vec<ShapeRecord>)>,
    lights: Vec<LightRecord>,
    warnings: Vec<String>,
    include_stack: Vec<PathBuf>,
    active: Active,
    /// `MakeNamedMedium`, in the order of definition.
    media: Vec<scene::Medium>,
    /// Where each medium of `media` was made.
    medium_locs: Vec<Loc>,
    /// Index into `media` by name.
    medium_index: HashMap<String, u32>,
    /// The outside medium's name at the `Camera` directive (pbrt-v4's camera medium).
    camera_medium: Option<(String, Loc)>,
}

fn err_at(files: &[PathBuf], loc: Loc, message: impl Into<String>) -> LoadError {
    LoadError::Pbrt {
        path: files.get(loc.file).cloned().unwrap_or_default(),
        line: Some(loc.line),
        column: Some(loc.column),
        message: message.into(),
    }
}

fn loc_of(t: &Token) -> Loc {
    Loc {
        file: t.file,
        line: t.line,
        column: t.column,
    }
}

impl Parser {
    fn err(&self, loc: Loc, message: impl Into<String>) -> LoadError {
        err_at(&self.files, loc, message)
    }

    fn warn(&mut self, message: String) {
        if !self.warnings.contains(&message) {
            self.warnings.push(message);
        }
    }

    fn resolve(&self, name: &str) -> PathBuf {
        let p = Path::new(name);
        if p.is_absolute() {
            p.to_path_buf()
        } else {
            self.base.join(p)
        }
    }
}

impl Params {
    fn get(&self, name: &str) -> Option<&Param> {
        self.0.iter().rev().find(|p| p.name == name)
    }
}

/// The reflection across the camera's vertical plane (through its position, containing its
/// forward and up axes): `world_from_camera · diag(−1, 1, 1) · camera_from_world`.
fn mirror_fix(world_from_camera: DMat4) -> DMat4 {
    world_from_camera * DMat4::from_scale(DVec3::new(-1.0, 1.0, 1.0)) * world_from_camera.inverse()
}

fn describe(t: &Tok) -> String {
    match t {
        Tok::Str(s) => format!("\"{s}\""),
        Tok::Word(w) => w.clone(),
        Tok::Open => "[".to_owned(),
        Tok::Close => "]".to_owned(),
    }
}
