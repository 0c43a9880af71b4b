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

mod loop_subdiv;
mod tokenizer;

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use glam::{DMat4, DVec3, Vec3};

use self::tokenizer::{Tok, Token, tokenize};
use super::LoadOptions;
use super::import::{self, Builder, IndexedMesh};
use super::spectrum::{self, SpectrumUse};
use crate::description::{
    Camera, Film, Light, Material, MaterialKind, RenderDefaults, Rgb, SceneDescription,
};
use crate::error::LoadError;

/// Deepest `Include` nesting accepted (cycles are caught before that).
const MAX_INCLUDE_DEPTH: usize = 64;
/// GGX α standing in for a perfectly smooth coating (`coateddiffuse` with roughness 0).
const SMOOTH_COAT_ALPHA: f32 = 0.01;
/// Below this α a conductor is a mirror.
const MIRROR_ALPHA: f32 = 1e-3;
/// Index of refraction of pbrt's coatings (the `coateddiffuse` default).
const COAT_IOR: f32 = 1.5;
/// pbrt-v4's named glass spectra, as their refractive index at the sodium d line (587.6 nm);
/// dispersion is dropped.
const NAMED_GLASS: &[(&str, f32)] = &[
    ("glass-BK7", 1.5168),
    ("glass-BAF10", 1.6700),
    ("glass-FK51A", 1.4866),
    ("glass-LASF9", 1.8503),
    ("glass-F5", 1.6034),
    ("glass-F10", 1.6200),
    ("glass-F11", 1.6210),
];

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
        shapes: Vec::new(),
        objects: HashMap::new(),
        current_object: None,
        lights: Vec::new(),
        warnings: Vec::new(),
        include_stack: Vec::new(),
        active: Active::All,
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
}

impl Default for State {
    fn default() -> Self {
        Self {
            ctm: DMat4::IDENTITY,
            reverse: false,
            material: MaterialRef::Default,
            area: None,
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
    shapes: Vec<ShapeRecord>,
    objects: HashMap<String, Vec<ShapeRecord>>,
    current_object: Option<(String, Vec<ShapeRecord>)>,
    lights: Vec<LightRecord>,
    warnings: Vec<String>,
    include_stack: Vec<PathBuf>,
    active: Active,
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

    fn parse_file(&mut self, path: &Path, from: Option<Loc>) -> Result<(), LoadError> {
        let canonical = path.canonicalize().unwrap_or_else(|_| path.to_path_buf());
        if let Some(loc) = from {
            if self.include_stack.contains(&canonical) {
                return Err(self.err(
                    loc,
                    format!("include cycle: {} includes itself", path.display()),
                ));
            }
            if self.include_stack.len() >= MAX_INCLUDE_DEPTH {
                return Err(self.err(
                    loc,
                    format!("includes nested deeper than {MAX_INCLUDE_DEPTH}"),
                ));
            }
            if !path.exists() {
                return Err(self.err(loc, format!("included file {} not found", path.display())));
            }
        }
        let text = super::read_text(path)?;
        let file = self.files.len();
        self.files.push(path.to_path_buf());
        let tokens = tokenize(&text, file, path)?;
        self.include_stack.push(canonical);
        let mut i = 0;
        while i < tokens.len() {
            let t = &tokens[i];
            let loc = loc_of(t);
            let Tok::Word(directive) = &t.tok else {
                return Err(self.err(
                    loc,
                    format!(
                        "syntax error: expected a directive, found {}",
                        describe(&t.tok)
                    ),
                ));
            };
            i += 1;
            self.directive(directive, loc, &tokens, &mut i)?;
        }
        self.include_stack.pop();
        Ok(())
    }

    /// Reads `n` numbers (bare, or in one bracketed list).
    fn numbers(
        &self,
        tokens: &[Token],
        i: &mut usize,
        n: usize,
        loc: Loc,
        what: &str,
    ) -> Result<Vec<f64>, LoadError> {
        let bracket = matches!(tokens.get(*i).map(|t| &t.tok), Some(Tok::Open));
        if bracket {
            *i += 1;
        }
        let mut out = Vec::with_capacity(n);
        while out.len() < n {
            let Some(t) = tokens.get(*i) else {
                return Err(self.err(loc, format!("{what} needs {n} numbers, got {}", out.len())));
            };
            match &t.tok {
                Tok::Word(w) => {
                    let x: f64 = w.parse().map_err(|_| {
                        self.err(loc_of(t), format!("{what}: \"{w}\" is not a number"))
                    })?;
                    out.push(x);
                    *i += 1;
                }
                _ => {
                    return Err(
                        self.err(loc, format!("{what} needs {n} numbers, got {}", out.len()))
                    );
                }
            }
        }
        if bracket {
            match tokens.get(*i).map(|t| &t.tok) {
                Some(Tok::Close) => *i += 1,
                _ => {
                    return Err(self.err(
                        loc,
                        format!("{what} needs exactly {n} numbers in its brackets"),
                    ));
                }
            }
        }
        if out.iter().any(|x| !x.is_finite()) {
            return Err(self.err(loc, format!("{what}: numbers must be finite")));
        }
        Ok(out)
    }

    fn string(
        &self,
        tokens: &[Token],
        i: &mut usize,
        loc: Loc,
        what: &str,
    ) -> Result<String, LoadError> {
        match tokens.get(*i).map(|t| &t.tok) {
            Some(Tok::Str(s)) => {
                *i += 1;
                Ok(s.clone())
            }
            _ => Err(self.err(loc, format!("syntax error: {what} needs a quoted string"))),
        }
    }

    /// Reads the parameter list that follows a directive.
    fn params(&self, tokens: &[Token], i: &mut usize) -> Result<Params, LoadError> {
        let mut out = Vec::new();
        while let Some(t) = tokens.get(*i) {
            let Tok::Str(decl) = &t.tok else {
                break;
            };
            let loc = loc_of(t);
            let mut words = decl.split_whitespace();
            let (Some(ty), Some(name), None) = (words.next(), words.next(), words.next()) else {
                return Err(self.err(
                    loc,
                    format!(
                        "syntax error: \"{decl}\" is not a \"type name\" parameter declaration"
                    ),
                ));
            };
            *i += 1;
            let mut values = Vec::new();
            let single = !matches!(tokens.get(*i).map(|t| &t.tok), Some(Tok::Open));
            if !single {
                *i += 1;
            }
            loop {
                let Some(t) = tokens.get(*i) else {
                    if single {
                        return Err(self.err(loc, format!("parameter \"{decl}\" has no value")));
                    }
                    return Err(self.err(
                        loc,
                        format!("syntax error: parameter \"{decl}\" has no closing ]"),
                    ));
                };
                let v = match &t.tok {
                    Tok::Close if !single => {
                        *i += 1;
                        break;
                    }
                    Tok::Str(s) => Value::Str(s.clone()),
                    Tok::Word(w) if w == "true" || w == "false" => Value::Bool(w == "true"),
                    Tok::Word(w) => match w.parse::<f64>() {
                        Ok(x) => Value::Num(x),
                        Err(_) if single => {
                            return Err(self.err(loc, format!("parameter \"{decl}\" has no value")));
                        }
                        Err(_) => {
                            return Err(self.err(
                                loc,
                                format!("syntax error: parameter \"{decl}\" has no closing ] (found \"{w}\" on line {})", t.line),
                            ));
                        }
                    },
                    other => {
                        return Err(self.err(
                            loc_of(t),
                            format!("syntax error: unexpected {} in \"{decl}\"", describe(other)),
                        ));
                    }
                };
                values.push(v);
                *i += 1;
                if single {
                    break;
                }
            }
            out.push(Param {
                ty: ty.to_owned(),
                name: name.to_owned(),
                values,
                file: loc.file,
                line: loc.line,
                column: loc.column,
            });
        }
        Ok(Params(out))
    }

    /// Applies a transform to the CTM, honouring `ActiveTransform` (only the start time counts).
    fn apply(&mut self, m: DMat4, replace: bool) {
        if self.active == Active::End {
            return;
        }
        self.state.ctm = if replace { m } else { self.state.ctm * m };
    }

    #[allow(clippy::too_many_lines)]
    fn directive(
        &mut self,
        d: &str,
        loc: Loc,
        tokens: &[Token],
        i: &mut usize,
    ) -> Result<(), LoadError> {
        match d {
            "Include" | "Import" => {
                let name = self.string(tokens, i, loc, d)?;
                let path = self.resolve(&name);
                self.parse_file(&path, Some(loc))?;
            }
            "Identity" => self.apply(DMat4::IDENTITY, true),
            "Translate" => {
                let v = self.numbers(tokens, i, 3, loc, d)?;
                self.apply(DMat4::from_translation(DVec3::new(v[0], v[1], v[2])), false);
            }
            "Scale" => {
                let v = self.numbers(tokens, i, 3, loc, d)?;
                self.apply(DMat4::from_scale(DVec3::new(v[0], v[1], v[2])), false);
            }
            "Rotate" => {
                let v = self.numbers(tokens, i, 4, loc, d)?;
                let axis = DVec3::new(v[1], v[2], v[3])
                    .try_normalize()
                    .ok_or_else(|| self.err(loc, "Rotate: the axis cannot be zero"))?;
                self.apply(DMat4::from_axis_angle(axis, v[0].to_radians()), false);
            }
            "LookAt" => {
                let v = self.numbers(tokens, i, 9, loc, d)?;
                let pos = DVec3::new(v[0], v[1], v[2]);
                let look = DVec3::new(v[3], v[4], v[5]);
                let up = DVec3::new(v[6], v[7], v[8]);
                let dir = (look - pos).try_normalize().ok_or_else(|| {
                    self.err(loc, "LookAt: the eye and the point looked at coincide")
                })?;
                let right = up
                    .normalize_or_zero()
                    .cross(dir)
                    .try_normalize()
                    .ok_or_else(|| self.err(loc, "LookAt: up is parallel to the view direction"))?;
                let new_up = dir.cross(right);
                let world_from_camera = DMat4::from_cols(
                    right.extend(0.0),
                    new_up.extend(0.0),
                    dir.extend(0.0),
                    pos.extend(1.0),
                );
                self.apply(world_from_camera.inverse(), false);
            }
            "Transform" | "ConcatTransform" => {
                let v = self.numbers(tokens, i, 16, loc, d)?;
                // pbrt reads the 16 numbers column by column (its matrices are transposed on read).
                let m = DMat4::from_cols_array(
                    &v.try_into()
                        .map_err(|_| self.err(loc, "needs 16 numbers"))?,
                );
                self.apply(m, d == "Transform");
            }
            "CoordinateSystem" => {
                let name = self.string(tokens, i, loc, d)?;
                self.named_coords.insert(name, self.state.ctm);
            }
            "CoordSysTransform" => {
                let name = self.string(tokens, i, loc, d)?;
                let m = *self.named_coords.get(&name).ok_or_else(|| {
                    self.err(loc, format!("unknown coordinate system \"{name}\""))
                })?;
                self.apply(m, true);
            }
            "ReverseOrientation" => self.state.reverse = !self.state.reverse,
            "ActiveTransform" => {
                let which = match tokens.get(*i).map(|t| &t.tok) {
                    Some(Tok::Word(w)) => w.clone(),
                    _ => {
                        return Err(
                            self.err(loc, "ActiveTransform needs StartTime, EndTime or All")
                        );
                    }
                };
                *i += 1;
                self.active = match which.as_str() {
                    "StartTime" => Active::Start,
                    "EndTime" => Active::End,
                    "All" => Active::All,
                    other => {
                        return Err(self.err(
                            loc,
                            format!("ActiveTransform {other}: expected StartTime, EndTime or All"),
                        ));
                    }
                };
                self.warn("ActiveTransform: motion blur is not supported; the shutter-open (StartTime) transforms are used".to_owned());
            }
            "TransformTimes" => {
                self.numbers(tokens, i, 2, loc, d)?;
            }
            "AttributeBegin" | "TransformBegin" => {
                self.stack
                    .push((self.state.clone(), loc, d == "TransformBegin"));
            }
            "AttributeEnd" | "TransformEnd" => {
                let (saved, _, transform_only) = self
                    .stack
                    .pop()
                    .ok_or_else(|| self.err(loc, format!("{d} without a matching begin")))?;
                if transform_only {
                    self.state.ctm = saved.ctm;
                } else {
                    self.state = saved;
                }
            }
            "Attribute" => {
                self.string(tokens, i, loc, d)?;
                self.params(tokens, i)?;
                self.warn(
                    "Attribute: shape/light/material attribute defaults are ignored".to_owned(),
                );
            }
            "Option" | "ColorSpace" => {
                // Option "type name" value; ColorSpace "name".
                if d == "Option" {
                    self.params(tokens, i)?;
                } else {
                    self.string(tokens, i, loc, d)?;
                }
            }
            "Camera" => {
                let kind = self.string(tokens, i, loc, d)?;
                let p = self.params(tokens, i)?;
                if kind != "perspective" {
                    return Err(self.err(
                        loc,
                        format!("Camera \"{kind}\" is not supported (perspective is)"),
                    ));
                }
                let world_from_camera = self.state.ctm.inverse();
                if !world_from_camera.is_finite() {
                    return Err(self.err(loc, "Camera: the transform cannot be inverted"));
                }
                self.named_coords
                    .insert("camera".to_owned(), world_from_camera);
                let fov = self.float(&p, "fov")?.unwrap_or(90.0);
                if !(fov > 0.0 && fov < 180.0) {
                    return Err(self.err(
                        loc,
                        format!("Camera: fov must be in (0, 180) degrees, got {fov}"),
                    ));
                }
                let lens = self.float(&p, "lensradius")?.unwrap_or(0.0);
                let focal = self.float(&p, "focaldistance")?.unwrap_or(1e6);
                self.camera = Some((world_from_camera, fov, lens, focal));
            }
            "Film" => {
                let _kind = self.string(tokens, i, loc, d)?;
                let p = self.params(tokens, i)?;
                let w = self.int(&p, "xresolution")?.unwrap_or(1280);
                let h = self.int(&p, "yresolution")?.unwrap_or(720);
                let side = |v: i64| {
                    u32::try_from(v)
                        .ok()
                        .filter(|&v| v > 0 && v <= super::MAX_FILM_SIDE)
                };
                let (Some(width), Some(height)) = (side(w), side(h)) else {
                    return Err(self.err(loc, format!("Film: resolution {w}x{h} is out of range")));
                };
                self.film = Film { width, height };
                if p.get("cropwindow").is_some() {
                    self.warn("Film: the crop window is ignored".to_owned());
                }
            }
            "Integrator" => {
                let kind = self.string(tokens, i, loc, d)?;
                let p = self.params(tokens, i)?;
                if let Some(depth) = self.int(&p, "maxdepth")? {
                    let depth = u32::try_from(depth)
                        .ok()
                        .filter(|&d| d >= 1)
                        .ok_or_else(|| {
                            self.err(
                                loc,
                                format!("Integrator: maxdepth must be ≥ 1, got {depth}"),
                            )
                        })?;
                    self.render.set("max_depth", depth.min(1024));
                }
                if !matches!(
                    kind.as_str(),
                    "path" | "volpath" | "bdpt" | "mlt" | "sppm" | "lightpath" | "simplepath"
                ) {
                    self.warn(format!("Integrator \"{kind}\": fppm renders global illumination with its own method instead"));
                }
            }
            "Sampler" | "PixelFilter" | "Accelerator" => {
                self.string(tokens, i, loc, d)?;
                self.params(tokens, i)?;
            }
            "WorldBegin" => {
                self.state.ctm = DMat4::IDENTITY;
                self.named_coords
                    .insert("world".to_owned(), DMat4::IDENTITY);
            }
            "WorldEnd" => {}
            "MakeNamedMedium" | "MediumInterface" => {
                if d == "MakeNamedMedium" {
                    return Err(self.err(loc, "participating media are not supported"));
                }
                // MediumInterface "inside" "outside" (or one name).
                self.string(tokens, i, loc, d)?;
                if matches!(tokens.get(*i).map(|t| &t.tok), Some(Tok::Str(_))) {
                    *i += 1;
                }
            }
            "Material" => {
                let kind = self.string(tokens, i, loc, d)?;
                let params = self.params(tokens, i)?;
                self.materials.push(MaterialDef { kind, params, loc });
                self.state.material = MaterialRef::Anonymous(self.materials.len() - 1);
            }
            "MakeNamedMaterial" => {
                let name = self.string(tokens, i, loc, d)?;
                let params = self.params(tokens, i)?;
                let kind = params
                    .get("type")
                    .and_then(|p| match p.values.as_slice() {
                        [Value::Str(s)] => Some(s.clone()),
                        _ => None,
                    })
                    .ok_or_else(|| {
                        self.err(
                            loc,
                            format!("MakeNamedMaterial \"{name}\" needs a \"string type\""),
                        )
                    })?;
                self.named_materials
                    .insert(name, MaterialDef { kind, params, loc });
            }
            "NamedMaterial" => {
                let name = self.string(tokens, i, loc, d)?;
                self.state.material = MaterialRef::Named(name, loc);
            }
            "Texture" => {
                let name = self.string(tokens, i, loc, d)?;
                let _ty = self.string(tokens, i, loc, d)?;
                let class = self.string(tokens, i, loc, d)?;
                let params = self.params(tokens, i)?;
                self.textures
                    .insert(name, TextureDef { class, params, loc });
            }
            "LightSource" => {
                let kind = self.string(tokens, i, loc, d)?;
                let params = self.params(tokens, i)?;
                self.lights.push(LightRecord {
                    kind,
                    params,
                    ctm: self.state.ctm,
                    loc,
                });
            }
            "AreaLightSource" => {
                let kind = self.string(tokens, i, loc, d)?;
                let params = self.params(tokens, i)?;
                if kind != "diffuse" {
                    return Err(self.err(
                        loc,
                        format!("AreaLightSource \"{kind}\" is not supported (diffuse is)"),
                    ));
                }
                self.state.area = Some(AreaLight { params, loc });
            }
            "Shape" => {
                let kind = self.string(tokens, i, loc, d)?;
                let params = self.params(tokens, i)?;
                let record = ShapeRecord {
                    kind,
                    params,
                    state: self.state.clone(),
                    loc,
                };
                match &mut self.current_object {
                    Some((_, shapes)) => shapes.push(record),
                    None => self.shapes.push(record),
                }
            }
            "ObjectBegin" => {
                let name = self.string(tokens, i, loc, d)?;
                if self.current_object.is_some() {
                    return Err(self.err(loc, "ObjectBegin inside another object"));
                }
                self.stack.push((self.state.clone(), loc, false));
                self.current_object = Some((name, Vec::new()));
            }
            "ObjectEnd" => {
                let (name, shapes) = self
                    .current_object
                    .take()
                    .ok_or_else(|| self.err(loc, "ObjectEnd without ObjectBegin"))?;
                self.objects.insert(name, shapes);
                if let Some((saved, _, _)) = self.stack.pop() {
                    self.state = saved;
                }
            }
            "ObjectInstance" => {
                let name = self.string(tokens, i, loc, d)?;
                let shapes = self
                    .objects
                    .get(&name)
                    .ok_or_else(|| {
                        self.err(loc, format!("ObjectInstance of unknown object \"{name}\""))
                    })?
                    .clone();
                let instance = self.state.ctm;
                for mut s in shapes {
                    s.state.ctm = instance * s.state.ctm;
                    self.shapes.push(s);
                }
            }
            other => {
                return Err(self.err(loc, format!("syntax error: unknown directive \"{other}\"")));
            }
        }
        Ok(())
    }

    // ---- parameter access, with type and arity checks ----

    fn loc_of_param(p: &Param) -> Loc {
        Loc {
            file: p.file,
            line: p.line,
            column: p.column,
        }
    }

    fn nums(&self, p: &Param) -> Result<Vec<f64>, LoadError> {
        p.values
            .iter()
            .map(|v| match v {
                Value::Num(x) if x.is_finite() => Ok(*x),
                _ => Err(self.err(
                    Self::loc_of_param(p),
                    format!("parameter \"{} {}\" must hold numbers", p.ty, p.name),
                )),
            })
            .collect()
    }

    fn expect_type(&self, p: &Param, types: &[&str]) -> Result<(), LoadError> {
        if types.contains(&p.ty.as_str()) {
            Ok(())
        } else {
            Err(self.err(
                Self::loc_of_param(p),
                format!(
                    "parameter \"{}\" must be of type {}, not \"{}\"",
                    p.name,
                    types.join(" or "),
                    p.ty
                ),
            ))
        }
    }

    fn one(&self, p: &Param) -> Result<f64, LoadError> {
        let v = self.nums(p)?;
        match v.as_slice() {
            [x] => Ok(*x),
            _ => Err(self.err(
                Self::loc_of_param(p),
                format!(
                    "parameter \"{} {}\" expects 1 value, got {}",
                    p.ty,
                    p.name,
                    v.len()
                ),
            )),
        }
    }

    fn float(&self, params: &Params, name: &str) -> Result<Option<f64>, LoadError> {
        let Some(p) = params.get(name) else {
            return Ok(None);
        };
        self.expect_type(p, &["float"])?;
        self.one(p).map(Some)
    }

    fn int(&self, params: &Params, name: &str) -> Result<Option<i64>, LoadError> {
        let Some(p) = params.get(name) else {
            return Ok(None);
        };
        self.expect_type(p, &["integer"])?;
        let x = self.one(p)?;
        if x.fract() != 0.0 {
            return Err(self.err(
                Self::loc_of_param(p),
                format!("parameter \"integer {name}\" must be an integer, got {x}"),
            ));
        }
        Ok(Some(x as i64))
    }

    fn boolean(&self, params: &Params, name: &str) -> Result<Option<bool>, LoadError> {
        let Some(p) = params.get(name) else {
            return Ok(None);
        };
        self.expect_type(p, &["bool"])?;
        match p.values.as_slice() {
            [Value::Bool(b)] => Ok(Some(*b)),
            [Value::Str(s)] if s == "true" || s == "false" => Ok(Some(s == "true")),
            _ => Err(self.err(
                Self::loc_of_param(p),
                format!("parameter \"bool {name}\" expects one true or false"),
            )),
        }
    }

    fn str_param(&self, params: &Params, name: &str) -> Result<Option<String>, LoadError> {
        let Some(p) = params.get(name) else {
            return Ok(None);
        };
        self.expect_type(p, &["string", "texture"])?;
        match p.values.as_slice() {
            [Value::Str(s)] => Ok(Some(s.clone())),
            _ => Err(self.err(
                Self::loc_of_param(p),
                format!("parameter \"{} {name}\" expects one string", p.ty),
            )),
        }
    }

    /// Triples of numbers (points, normals).
    fn vec3s(
        &self,
        params: &Params,
        name: &str,
        types: &[&str],
    ) -> Result<Option<Vec<Vec3>>, LoadError> {
        let Some(p) = params.get(name) else {
            return Ok(None);
        };
        self.expect_type(p, types)?;
        let v = self.nums(p)?;
        if v.len() % 3 != 0 {
            return Err(self.err(
                Self::loc_of_param(p),
                format!(
                    "parameter \"{} {name}\" needs a multiple of 3 values, got {}",
                    p.ty,
                    v.len()
                ),
            ));
        }
        Ok(Some(
            v.chunks(3)
                .map(|c| Vec3::new(c[0] as f32, c[1] as f32, c[2] as f32))
                .collect(),
        ))
    }

    fn ints(&self, params: &Params, name: &str) -> Result<Option<Vec<i64>>, LoadError> {
        let Some(p) = params.get(name) else {
            return Ok(None);
        };
        self.expect_type(p, &["integer"])?;
        let v = self.nums(p)?;
        if v.iter().any(|x| x.fract() != 0.0) {
            return Err(self.err(
                Self::loc_of_param(p),
                format!("parameter \"integer {name}\" must hold integers"),
            ));
        }
        Ok(Some(v.into_iter().map(|x| x as i64).collect()))
    }

    /// A colour-like parameter: `rgb`, `spectrum` (named, file, or λ/value pairs), `blackbody`,
    /// `float`, or a `texture` (which stands in as a constant).
    fn colour(
        &mut self,
        params: &Params,
        name: &str,
        usage: SpectrumUse,
    ) -> Result<Option<Rgb>, LoadError> {
        let Some(p) = params.get(name).cloned() else {
            return Ok(None);
        };
        let loc = Self::loc_of_param(&p);
        let rgb = match p.ty.as_str() {
            "rgb" => {
                let v = self.nums(&p)?;
                let [r, g, b] = v.as_slice() else {
                    return Err(self.err(
                        loc,
                        format!("parameter \"rgb {name}\" expects 3 values, got {}", v.len()),
                    ));
                };
                Rgb::new(*r as f32, *g as f32, *b as f32)
            }
            "float" => Rgb::splat(self.one(&p)? as f32),
            "spectrum" => match p.values.as_slice() {
                [Value::Str(s)] => self.named_spectrum(s, loc, usage)?,
                _ => {
                    let v = self.nums(&p)?;
                    if v.len() < 2 || v.len() % 2 != 0 {
                        return Err(self.err(
                            loc,
                            format!("parameter \"spectrum {name}\" needs wavelength/value pairs"),
                        ));
                    }
                    let w: Vec<f64> = v.iter().step_by(2).copied().collect();
                    let x: Vec<f64> = v.iter().skip(1).step_by(2).copied().collect();
                    spectrum::spectrum_to_rgb(&w, &x, usage)
                        .ok_or_else(|| self.err(loc, "wavelengths must increase"))?
                }
            },
            "blackbody" => {
                self.warn(format!("parameter \"blackbody {name}\": a blackbody stands in as white of the same brightness"));
                Rgb::ONE
            }
            "texture" => {
                let [Value::Str(tex)] = p.values.as_slice() else {
                    return Err(self.err(
                        loc,
                        format!("parameter \"texture {name}\" expects one texture name"),
                    ));
                };
                self.texture_standin(tex, loc, 0)?
            }
            other => {
                return Err(self.err(loc, format!("parameter \"{name}\" must be a colour (rgb, spectrum, float or texture), not \"{other}\"")));
            }
        };
        if !rgb.is_finite() {
            return Err(self.err(loc, format!("parameter \"{name}\" must be finite")));
        }
        Ok(Some(rgb))
    }

    /// The samples of a `spectrum` parameter given as λ/value pairs or a `.spd` file; `None`
    /// for anything else (named spectra, rgb, absent).
    fn spectral(&self, params: &Params, name: &str) -> Result<Option<Samples>, LoadError> {
        let Some(p) = params.get(name) else {
            return Ok(None);
        };
        if p.ty != "spectrum" {
            return Ok(None);
        }
        let loc = Self::loc_of_param(p);
        match p.values.as_slice() {
            [Value::Str(s)] if s.starts_with("metal-") || s.starts_with("glass-") => Ok(None),
            [Value::Str(s)] if s.starts_with("stdillum-") => Ok(None),
            [Value::Str(s)] => super::mitsuba::read_spd(&self.resolve(s))
                .map(Some)
                .map_err(|m| self.err(loc, m)),
            _ => {
                let v = self.nums(p)?;
                if v.len() < 2 || v.len() % 2 != 0 {
                    return Err(self.err(
                        loc,
                        format!("parameter \"spectrum {name}\" needs wavelength/value pairs"),
                    ));
                }
                Ok(Some((
                    v.iter().step_by(2).copied().collect(),
                    v.iter().skip(1).step_by(2).copied().collect(),
                )))
            }
        }
    }

    /// A named pbrt spectrum (metals, glasses) or a `.spd` file.
    fn named_spectrum(&mut self, s: &str, loc: Loc, usage: SpectrumUse) -> Result<Rgb, LoadError> {
        if let Some(rest) = s.strip_prefix("metal-") {
            let (metal, part) = rest
                .rsplit_once('-')
                .ok_or_else(|| self.err(loc, format!("unknown named spectrum \"{s}\"")))?;
            let (eta, k) = spectrum::metal(metal).ok_or_else(|| {
                self.err(loc, format!("named spectrum \"{s}\" is not known to fppm"))
            })?;
            return match part {
                "eta" => Ok(eta),
                "k" => Ok(k),
                _ => Err(self.err(loc, format!("unknown named spectrum \"{s}\""))),
            };
        }
        if let Some((_, ior)) = NAMED_GLASS.iter().find(|(n, _)| *n == s) {
            self.warn(format!(
                "spectrum \"{s}\": dispersion is dropped; ior {ior} (sodium d line) is used"
            ));
            return Ok(Rgb::splat(*ior));
        }
        if s.starts_with("stdillum-") || s.starts_with("canon_") || s.starts_with("nikon_") {
            self.warn(format!("spectrum \"{s}\" stands in as white"));
            return Ok(Rgb::ONE);
        }
        let path = self.resolve(s);
        let (w, v) = super::mitsuba::read_spd(&path).map_err(|m| self.err(loc, m))?;
        spectrum::spectrum_to_rgb(&w, &v, usage)
            .ok_or_else(|| self.err(loc, format!("spectrum file {s}: wavelengths must increase")))
    }

    /// The constant colour that stands in for texture `name`.
    fn texture_standin(&mut self, name: &str, loc: Loc, depth: usize) -> Result<Rgb, LoadError> {
        if depth > 32 {
            return Err(self.err(loc, format!("texture \"{name}\" refers to itself")));
        }
        let def = self
            .textures
            .get(name)
            .cloned()
            .ok_or_else(|| self.err(loc, format!("unknown texture \"{name}\"")))?;
        let rgb = match def.class.as_str() {
            "imagemap" => {
                let file = self.str_param(&def.params, "filename")?.ok_or_else(|| {
                    self.err(
                        def.loc,
                        format!("imagemap texture \"{name}\" needs a filename"),
                    )
                })?;
                let path = self.resolve(&file);
                let (rgb, what) = import::image_texture_standin(&path)
                    .map_err(|e| self.err(def.loc, e.to_string()))?;
                self.warn(format!(
                    "Texture \"{name}\" (imagemap {file}): textures are not supported yet; {what} {} stands in",
                    super::fmt_vec(rgb)
                ));
                rgb
            }
            "scale" => {
                let tex = self.sub_texture(&def, "tex", depth)?.unwrap_or(Rgb::ONE);
                let scale = self.sub_texture(&def, "scale", depth)?.unwrap_or(Rgb::ONE);
                tex * scale
            }
            "constant" => self.sub_texture(&def, "value", depth)?.unwrap_or(Rgb::ONE),
            "mix" => {
                let a = self.sub_texture(&def, "tex1", depth)?.unwrap_or(Rgb::ZERO);
                let b = self.sub_texture(&def, "tex2", depth)?.unwrap_or(Rgb::ONE);
                let t = self
                    .sub_texture(&def, "amount", depth)?
                    .unwrap_or(Rgb::splat(0.5));
                a * (Rgb::ONE - t) + b * t
            }
            "checkerboard" => {
                let a = self.sub_texture(&def, "tex1", depth)?.unwrap_or(Rgb::ONE);
                let b = self.sub_texture(&def, "tex2", depth)?.unwrap_or(Rgb::ZERO);
                let rgb = 0.5 * (a + b);
                self.warn(format!(
                    "Texture \"{name}\" (checkerboard): textures are not supported yet; the mean of its two colours {} stands in",
                    super::fmt_vec(rgb)
                ));
                rgb
            }
            other => {
                let rgb = Rgb::splat(import::TEXTURE_STANDIN_GREY);
                self.warn(format!(
                    "Texture \"{name}\" ({other}) is not supported; grey {} stands in",
                    super::fmt_vec(rgb)
                ));
                rgb
            }
        };
        Ok(rgb)
    }

    fn sub_texture(
        &mut self,
        def: &TextureDef,
        name: &str,
        depth: usize,
    ) -> Result<Option<Rgb>, LoadError> {
        match def.params.get(name) {
            Some(p) if p.ty == "texture" => {
                let loc = Self::loc_of_param(p);
                let [Value::Str(t)] = p.values.as_slice() else {
                    return Err(self.err(
                        loc,
                        format!("parameter \"texture {name}\" expects one texture name"),
                    ));
                };
                let t = t.clone();
                self.texture_standin(&t, loc, depth + 1).map(Some)
            }
            _ => self.colour(&def.params, name, SpectrumUse::Reflectance),
        }
    }

    /// pbrt's roughness → GGX α: `sqrt(r)` when `remaproughness` (the default).
    fn alpha(&mut self, params: &Params, name: &str, remap: bool) -> Result<f32, LoadError> {
        let r = match params.get(name) {
            Some(p) if p.ty == "texture" => {
                self.warn(format!(
                    "a textured \"{name}\" is not supported; 0 stands in"
                ));
                0.0
            }
            Some(_) => self.float(params, name)?.unwrap_or(0.0),
            None => {
                let u = self.float(params, &format!("u{name}"))?;
                let v = self.float(params, &format!("v{name}"))?;
                match (u, v) {
                    (Some(u), Some(v)) => {
                        if u != v {
                            self.warn(format!("anisotropic u{name}/v{name} ({u}, {v}) are rendered isotropic with their mean"));
                        }
                        0.5 * (u + v)
                    }
                    (Some(x), None) | (None, Some(x)) => x,
                    (None, None) => 0.0,
                }
            }
        };
        let r = r.max(0.0) as f32;
        Ok(if remap { r.sqrt() } else { r })
    }

    /// Converts a material definition; `None` for `interface` (invisible).
    fn material(
        &mut self,
        def: &MaterialDef,
        label: &str,
    ) -> Result<Option<MaterialKind>, LoadError> {
        let p = def.params.clone();
        let refl = SpectrumUse::Reflectance;
        let remap = self.boolean(&p, "remaproughness")?.unwrap_or(true);
        Ok(Some(match def.kind.as_str() {
            "diffuse" => MaterialKind::Diffuse {
                albedo: self
                    .colour(&p, "reflectance", refl)?
                    .unwrap_or(Rgb::splat(0.5)),
            },
            "conductor" | "coatedconductor" => {
                let prefix = if def.kind == "coatedconductor" {
                    "conductor."
                } else {
                    ""
                };
                let r0 = match self.colour(&p, &format!("{prefix}reflectance"), refl)? {
                    Some(r) => r,
                    None if self.spectral(&p, &format!("{prefix}eta"))?.is_some()
                        && self.spectral(&p, &format!("{prefix}k"))?.is_some() =>
                    {
                        // Both measured spectra: the reflectance is computed per wavelength.
                        let (Some(eta), Some(k)) = (
                            self.spectral(&p, &format!("{prefix}eta"))?,
                            self.spectral(&p, &format!("{prefix}k"))?,
                        ) else {
                            return Err(self.err(def.loc, "conductor spectra vanished"));
                        };
                        spectrum::conductor_reflectance_spectral((&eta.0, &eta.1), (&k.0, &k.1))
                            .ok_or_else(|| {
                                self.err(def.loc, format!("{label}: malformed eta or k spectrum"))
                            })?
                    }
                    None => {
                        let eta = self.colour(&p, &format!("{prefix}eta"), SpectrumUse::Ior)?;
                        let k = self.colour(&p, &format!("{prefix}k"), SpectrumUse::Ior)?;
                        let (eta, k) = match (eta, k) {
                            (Some(e), Some(k)) => (e, k),
                            (e, k) => {
                                let (ce, ck) =
                                    spectrum::metal("Cu").unwrap_or((Rgb::ONE, Rgb::ZERO));
                                (e.unwrap_or(ce), k.unwrap_or(ck))
                            }
                        };
                        spectrum::conductor_reflectance(eta, k)
                    }
                };
                let alpha = self.alpha(&p, &format!("{prefix}roughness"), remap)?;
                self.warn(format!(
                    "{label}: the conductor uses its reflectance at normal incidence {} (no angular Fresnel)",
                    super::fmt_vec(r0)
                ));
                if def.kind == "coatedconductor" {
                    self.warn(format!(
                        "{label}: the dielectric coating of a coatedconductor is ignored"
                    ));
                }
                if alpha <= MIRROR_ALPHA {
                    MaterialKind::Mirror { reflectance: r0 }
                } else {
                    MaterialKind::Glossy {
                        reflectance: r0,
                        roughness: alpha,
                        diffuse: Rgb::ZERO,
                    }
                }
            }
            "dielectric" | "thindielectric" => {
                let eta = match p.get("eta") {
                    Some(e) if e.ty == "spectrum" => self
                        .colour(&p, "eta", SpectrumUse::Ior)?
                        .map_or(1.5, |c| c.y),
                    Some(_) => self.float(&p, "eta")?.unwrap_or(1.5) as f32,
                    None => 1.5,
                };
                if def.kind == "thindielectric" {
                    self.warn(format!("{label}: a thin dielectric is rendered as a solid dielectric of the same ior (rays bend)"));
                }
                if self.alpha(&p, "roughness", remap)? > 0.0 {
                    self.warn(format!("{label}: a rough dielectric is rendered smooth"));
                }
                MaterialKind::Dielectric { ior: eta }
            }
            "coateddiffuse" => {
                let reflectance = self
                    .colour(&p, "reflectance", refl)?
                    .unwrap_or(Rgb::splat(0.5));
                let alpha = self.alpha(&p, "roughness", remap)?;
                let alpha = if alpha > 0.0 {
                    alpha
                } else {
                    SMOOTH_COAT_ALPHA
                };
                let f0 = spectrum::dielectric_reflectance(
                    self.float(&p, "eta")?.map_or(COAT_IOR, |e| e as f32),
                );
                self.warn(format!(
                    "{label}: coateddiffuse is approximated by fppm's glossy-over-diffuse material (GGX alpha {alpha}, \
                     reflectance {f0:.4} = Fresnel at normal incidence, diffuse scaled by {:.4})",
                    1.0 - f0
                ));
                MaterialKind::Glossy {
                    reflectance: Rgb::splat(f0),
                    roughness: alpha,
                    diffuse: reflectance * (1.0 - f0),
                }
            }
            "interface" => return Ok(None),
            "mix" => {
                self.warn(format!(
                    "{label}: a mix material stands in as diffuse grey 0.5"
                ));
                MaterialKind::Diffuse {
                    albedo: Rgb::splat(0.5),
                }
            }
            other => {
                self.warn(format!(
                    "{label}: material \"{other}\" is not supported; diffuse grey 0.5 stands in"
                ));
                MaterialKind::Diffuse {
                    albedo: Rgb::splat(0.5),
                }
            }
        }))
    }

    /// Turns the parsed records into a scene.
    #[allow(clippy::too_many_lines)]
    fn build(mut self, path: &Path, options: &LoadOptions) -> Result<SceneDescription, LoadError> {
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
        let mut material_cache: HashMap<String, Option<MaterialKind>> = HashMap::new();
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
            let kind = match material_cache.get(&cache_key) {
                Some(k) => *k,
                None => {
                    let k = match &def {
                        Some(def) => {
                            let label = format!("Material \"{}\" ({key})", def.kind);
                            self.material(def, &label)?
                        }
                        None => Some(MaterialKind::Diffuse {
                            albedo: Rgb::splat(0.5),
                        }),
                    };
                    material_cache.insert(cache_key, k);
                    k
                }
            };
            let Some(kind) = kind else {
                continue;
            };
            let emission = match &shape.state.area {
                Some(area) => {
                    let p = area.params.clone();
                    let l = self
                        .colour(&p, "L", SpectrumUse::Emission)?
                        .unwrap_or(Rgb::ONE);
                    let scale = self.float(&p, "scale")?.unwrap_or(1.0) as f32;
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
            });
            let to_world = fix * shape.state.ctm;
            self.shape(
                &mut builder,
                shape,
                to_world,
                material,
                emission.max_element() > 0.0,
            )?;
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
                "infinite" => {
                    let file = self.files[light.loc.file].display().to_string();
                    import::environment_light_standin(
                        &mut builder,
                        &format!("LightSource \"infinite\" ({file}:{})", light.loc.line),
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

    fn shape(
        &mut self,
        builder: &mut Builder,
        shape: &ShapeRecord,
        to_world: DMat4,
        material: u32,
        emissive: bool,
    ) -> Result<(), LoadError> {
        let p = &shape.params;
        let m = to_world.as_mat4();
        let loc = shape.loc;
        let label = format!("Shape \"{}\"", shape.kind);
        let mut mesh = match shape.kind.as_str() {
            "trianglemesh" | "loopsubdiv" | "bilinearmesh" => {
                let positions = self
                    .vec3s(p, "P", &["point3", "point"])?
                    .ok_or_else(|| self.err(loc, format!("{label} needs \"point3 P\"")))?;
                let normals = self.vec3s(p, "N", &["normal", "normal3"])?;
                let indices = match self.ints(p, "indices")? {
                    Some(i) => i,
                    None if positions.len() == 3 && shape.kind == "trianglemesh" => vec![0, 1, 2],
                    None if positions.len() == 4 && shape.kind == "bilinearmesh" => {
                        vec![0, 1, 2, 3]
                    }
                    None => return Err(self.err(loc, format!("{label} needs \"integer indices\""))),
                };
                let per = if shape.kind == "bilinearmesh" { 4 } else { 3 };
                if indices.len() % per != 0 {
                    return Err(self.err(
                        loc,
                        format!(
                            "{label}: \"integer indices\" needs a multiple of {per} values, got {}",
                            indices.len()
                        ),
                    ));
                }
                let idx: Vec<u32> = indices
                    .iter()
                    .map(|&i| {
                        u32::try_from(i)
                            .map_err(|_| self.err(loc, format!("{label}: negative index {i}")))
                    })
                    .collect::<Result<_, _>>()?;
                let faces: Vec<[u32; 3]> = if per == 4 {
                    // pbrt's bilinear patch p00 p10 p01 p11, split along p00–p11.
                    idx.chunks(4)
                        .flat_map(|q| [[q[0], q[1], q[3]], [q[0], q[3], q[2]]])
                        .collect()
                } else {
                    idx.chunks(3).map(|t| [t[0], t[1], t[2]]).collect()
                };
                if shape.kind == "bilinearmesh" {
                    builder.warn(format!(
                        "{label}: each bilinear patch is split into two triangles"
                    ));
                }
                let mesh = IndexedMesh {
                    positions,
                    normals: normals.filter(|_| shape.kind == "trianglemesh"),
                    indices: faces,
                };
                mesh.check_indices()
                    .map_err(|m| self.err(loc, format!("{label}: {m}")))?;
                if shape.kind == "loopsubdiv" {
                    let levels = self.int(p, "levels")?.unwrap_or(3);
                    let levels = u32::try_from(levels)
                        .ok()
                        .filter(|&l| {
                            l <= 12 && (mesh.indices.len() << (2 * l)) <= loop_subdiv::MAX_TRIANGLES
                        })
                        .ok_or_else(|| {
                            self.err(
                                loc,
                                format!("{label}: {levels} levels would make too many triangles"),
                            )
                        })?;
                    loop_subdiv::subdivide(&mesh.positions, &mesh.indices, levels)
                } else {
                    mesh
                }
            }
            "plymesh" => {
                let file = self
                    .str_param(p, "filename")?
                    .ok_or_else(|| self.err(loc, format!("{label} needs a \"string filename\"")))?;
                let path = self.resolve(&file);
                if p.get("displacement").is_some() {
                    builder.warn(format!("{label} ({file}): displacement is ignored"));
                }
                super::ply::load_ply(&path).map_err(|e| self.err(loc, e.to_string()))?
            }
            "sphere" => {
                let radius = self.float(p, "radius")?.unwrap_or(1.0) as f32;
                if p.get("zmin").is_some() || p.get("zmax").is_some() || p.get("phimax").is_some() {
                    builder.warn(format!(
                        "{label}: a partial sphere (zmin/zmax/phimax) is rendered whole"
                    ));
                }
                if !(radius.is_finite() && radius > 0.0) {
                    return Err(self.err(loc, format!("{label}: radius must be > 0, got {radius}")));
                }
                if shape.state.reverse {
                    builder.warn(format!(
                        "{label}: ReverseOrientation is ignored on a sphere"
                    ));
                }
                builder.sphere(Vec3::ZERO, radius, m, material, &label);
                return Ok(());
            }
            "disk" => {
                let radius = self.float(p, "radius")?.unwrap_or(1.0);
                let height = self.float(p, "height")?.unwrap_or(0.0);
                if self.float(p, "innerradius")?.unwrap_or(0.0) > 0.0 {
                    builder.warn(format!(
                        "{label}: the inner radius is ignored (a full disk)"
                    ));
                }
                builder.warn(format!(
                    "{label}: the disk is tessellated into {} triangles",
                    import::DISK_SEGMENTS
                ));
                let mut mesh = IndexedMesh::disk();
                for v in &mut mesh.positions {
                    *v = Vec3::new(v.x * radius as f32, v.y * radius as f32, height as f32);
                }
                mesh
            }
            "cylinder" => {
                let radius = self.float(p, "radius")?.unwrap_or(1.0) as f32;
                let zmin = self.float(p, "zmin")?.unwrap_or(-1.0) as f32;
                let zmax = self.float(p, "zmax")?.unwrap_or(1.0) as f32;
                if !(radius > 0.0 && radius.is_finite() && zmax != zmin) {
                    return Err(
                        self.err(loc, format!("{label}: needs radius > 0 and zmin != zmax"))
                    );
                }
                if self.float(p, "phimax")?.is_some_and(|x| x < 360.0) {
                    builder.warn(format!("{label}: phimax is ignored (a whole cylinder)"));
                }
                import::cylinder(
                    builder,
                    Vec3::new(0.0, 0.0, zmin),
                    Vec3::new(0.0, 0.0, zmax),
                    radius,
                    m,
                    material,
                    emissive,
                );
                return Ok(());
            }
            other => {
                return Err(self.err(loc, format!("Shape \"{other}\" is not supported")));
            }
        };
        if shape.state.reverse {
            mesh.flip();
        }
        builder.mesh(&mesh, m, material);
        Ok(())
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
