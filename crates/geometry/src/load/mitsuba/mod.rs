//! Mitsuba 3 XML scenes (`.xml`), with the conventions of Mitsuba 3's own parser and plugins.
//!
//! `xml.rs` expands includes and parameters; this file interprets the expanded tree. The
//! mapping to fppm (what is read, approximated or refused) is tabulated in
//! `docs/scene-import.md`. In short:
//! - transforms compose as Mitsuba does: every child of `<transform>` multiplies from the left,
//!   so they apply in document order; `<matrix>` is row-major; `<lookat>` builds the frame
//!   (left, up, forward) with the camera looking down its +z;
//! - `<spectrum>` values become RGB as Mitsuba's RGB variants do ([`super::spectrum`]);
//! - colours given by a texture stand in as a constant (`Importer::texture_standin`); environment
//!   emitters are skipped with a warning ([`super::import::environment_light_standin`]);
//! - the integrator's `max_depth` (longest path in segments, Mitsuba's convention) becomes
//!   fppm's `max_depth` (scattering events) minus one.

mod xml;

use std::collections::HashMap;
use std::path::Path;

use glam::{DMat4, DVec3};

use self::xml::{Document, Node};
use super::LoadOptions;
use super::import::{self, Builder, IndexedMesh};
use super::spectrum::{self, SpectrumUse};
use crate::description::{
    Camera, Film, Light, Material, MaterialKind, RenderDefaults, Rgb, SceneDescription,
};
use crate::error::LoadError;

/// Reflectance of Mitsuba's default BSDF (a shape without one) and of `diffuse` without one.
const DEFAULT_REFLECTANCE: f32 = 0.5;
/// GGX α that stands in for a perfectly smooth coating (`plastic`), which fppm's glossy
/// material cannot make delta.
const SMOOTH_COAT_ALPHA: f32 = 0.01;
/// Below this α a rough conductor is rendered as a mirror.
const MIRROR_ALPHA: f32 = 1e-3;
/// hdrfilm's default size.
const DEFAULT_FILM: Film = Film {
    width: 768,
    height: 576,
};

/// Mitsuba's named dielectric indices of refraction (`include/mitsuba/render/ior.h`).
const IOR_TABLE: &[(&str, f32)] = &[
    ("vacuum", 1.0),
    ("helium", 1.000_036),
    ("hydrogen", 1.000_132),
    ("air", 1.000_277),
    ("carbon dioxide", 1.000_45),
    ("water", 1.333),
    ("acetone", 1.36),
    ("ethanol", 1.361),
    ("carbon tetrachloride", 1.461),
    ("glycerol", 1.4729),
    ("benzene", 1.501),
    ("silicone oil", 1.520_45),
    ("bromine", 1.661),
    ("water ice", 1.31),
    ("fused quartz", 1.458),
    ("pyrex", 1.47),
    ("acrylic glass", 1.49),
    ("polypropylene", 1.49),
    ("bk7", 1.5046),
    ("sodium chloride", 1.544),
    ("amber", 1.55),
    ("pet", 1.575),
    ("diamond", 2.419),
];

/// Loads a Mitsuba 3 scene.
pub(crate) fn load_mitsuba(
    path: &Path,
    options: &LoadOptions,
) -> Result<SceneDescription, LoadError> {
    let doc = xml::read_document(path)?;
    let mut ids: HashMap<String, &Node> = HashMap::new();
    collect_ids(&doc, &doc.root, &mut ids)?;
    let mut importer = Importer {
        doc: &doc,
        ids,
        builder: Builder::default(),
        bsdf_cache: HashMap::new(),
    };
    let mut camera = None;
    let mut film = DEFAULT_FILM;
    let mut render = RenderDefaults::default();
    let mut shape_count = 0usize;
    for node in &doc.root.children {
        match node.tag.as_str() {
            "shape" => {
                shape_count += 1;
                importer.shape(node, shape_count)?;
            }
            "emitter" => importer.emitter(node)?,
            "sensor" => {
                if camera.is_some() {
                    importer
                        .builder
                        .warn(format!("{}: only the first sensor is used", node.label()));
                } else {
                    let (c, f) = importer.sensor(node)?;
                    camera = Some(c);
                    film = f;
                }
            }
            "integrator" => importer.integrator(node, &mut render)?,
            // Declarations used through <ref>, and elements with no bearing on the image.
            "medium" | "volume" => {
                return Err(doc.error(node, "participating media are not supported"));
            }
            "bsdf" | "texture" | "spectrum" | "phase" | "float" | "integer" | "boolean"
            | "string" | "rgb" | "point" | "vector" | "alias" | "transform" | "ref" => {}
            other => {
                importer.builder.warn(format!(
                    "<{other}> at the top level of the scene is ignored"
                ));
            }
        }
    }
    importer.builder.finish(path, camera, film, render, options)
}

/// Every element with an `id`, by id. A repeated id is an error.
fn collect_ids<'a>(
    doc: &'a Document,
    node: &'a Node,
    ids: &mut HashMap<String, &'a Node>,
) -> Result<(), LoadError> {
    if let Some(id) = node.attr("id")
        && node.tag != "scene"
        && node.tag != "ref"
        && ids.insert(id.to_owned(), node).is_some()
    {
        return Err(doc.error(node, format!("id \"{id}\" is defined twice")));
    }
    for child in &node.children {
        collect_ids(doc, child, ids)?;
    }
    Ok(())
}

/// A BSDF converted: the scattering model, its name, and whether to skip the shape.
#[derive(Clone, Debug)]
struct ConvertedBsdf {
    name: String,
    kind: Option<MaterialKind>,
}

struct Importer<'a> {
    doc: &'a Document,
    ids: HashMap<String, &'a Node>,
    builder: Builder,
    /// BSDFs by node address, so that shared BSDFs convert (and warn) once.
    bsdf_cache: HashMap<usize, ConvertedBsdf>,
}

/// The property child named `name`.
fn prop<'n>(node: &'n Node, name: &str) -> Option<&'n Node> {
    node.children.iter().find(|c| c.attr("name") == Some(name))
}

/// Splits a list of numbers separated by commas and/or whitespace.
fn numbers(text: &str) -> Result<Vec<f64>, String> {
    text.split(|c: char| c == ',' || c.is_whitespace())
        .filter(|t| !t.is_empty())
        .map(|t| {
            t.parse::<f64>()
                .map_err(|_| format!("\"{t}\" is not a number"))
        })
        .collect()
}

impl<'a> Importer<'a> {
    fn err(&self, node: &Node, message: impl Into<String>) -> LoadError {
        self.doc.error(node, message)
    }

    /// Follows a `<ref id>` to its element.
    fn deref(&self, node: &'a Node) -> Result<&'a Node, LoadError> {
        if node.tag != "ref" {
            return Ok(node);
        }
        let id = node
            .attr("id")
            .ok_or_else(|| self.err(node, "<ref> needs an id"))?;
        self.ids.get(id).copied().ok_or_else(|| {
            self.err(
                node,
                format!("refers to id \"{id}\", which no element defines"),
            )
        })
    }

    fn value<'n>(&self, node: &'n Node) -> Result<&'n str, LoadError> {
        node.attr("value")
            .ok_or_else(|| self.err(node, "needs a value attribute"))
    }

    fn float(&self, node: &Node, name: &str) -> Result<Option<f64>, LoadError> {
        let Some(p) = prop(node, name) else {
            return Ok(None);
        };
        if p.tag != "float" && p.tag != "integer" {
            return Err(self.err(
                p,
                format!("property \"{name}\" must be a <float>, got <{}>", p.tag),
            ));
        }
        let v = self.value(p)?;
        let x: f64 = v
            .trim()
            .parse()
            .map_err(|_| self.err(p, format!("\"{v}\" is not a number")))?;
        if !x.is_finite() {
            return Err(self.err(p, format!("\"{v}\" is not finite")));
        }
        Ok(Some(x))
    }

    fn integer(&self, node: &Node, name: &str) -> Result<Option<i64>, LoadError> {
        let Some(p) = prop(node, name) else {
            return Ok(None);
        };
        if p.tag != "integer" {
            return Err(self.err(
                p,
                format!("property \"{name}\" must be an <integer>, got <{}>", p.tag),
            ));
        }
        let v = self.value(p)?;
        v.trim()
            .parse()
            .map(Some)
            .map_err(|_| self.err(p, format!("\"{v}\" is not an integer")))
    }

    fn boolean(&self, node: &Node, name: &str) -> Result<Option<bool>, LoadError> {
        let Some(p) = prop(node, name) else {
            return Ok(None);
        };
        if p.tag != "boolean" {
            return Err(self.err(
                p,
                format!("property \"{name}\" must be a <boolean>, got <{}>", p.tag),
            ));
        }
        match self.value(p)?.trim().to_ascii_lowercase().as_str() {
            "true" => Ok(Some(true)),
            "false" => Ok(Some(false)),
            other => Err(self.err(p, format!("\"{other}\" is not true or false"))),
        }
    }

    fn string(&self, node: &'a Node, name: &str) -> Result<Option<&'a str>, LoadError> {
        let Some(p) = prop(node, name) else {
            return Ok(None);
        };
        if p.tag != "string" {
            return Err(self.err(
                p,
                format!("property \"{name}\" must be a <string>, got <{}>", p.tag),
            ));
        }
        Ok(Some(self.value(p)?))
    }

    /// A `<point>`/`<vector>` (x, y, z attributes or a value list).
    fn vector(&self, node: &Node, name: &str) -> Result<Option<DVec3>, LoadError> {
        let Some(p) = prop(node, name) else {
            return Ok(None);
        };
        if p.tag != "point" && p.tag != "vector" {
            return Err(self.err(
                p,
                format!(
                    "property \"{name}\" must be a <point> or <vector>, got <{}>",
                    p.tag
                ),
            ));
        }
        self.xyz(p, 0.0).map(Some)
    }

    /// x, y, z attributes (missing ones `default`) or a `value` of one or three numbers.
    fn xyz(&self, p: &Node, default: f64) -> Result<DVec3, LoadError> {
        if let Some(v) = p.attr("value") {
            let n = numbers(v).map_err(|m| self.err(p, m))?;
            return match n.as_slice() {
                [a] => Ok(DVec3::splat(*a)),
                [a, b, c] => Ok(DVec3::new(*a, *b, *c)),
                _ => Err(self.err(p, format!("needs 1 or 3 values, got {}", n.len()))),
            };
        }
        let mut out = DVec3::splat(default);
        for (i, k) in ["x", "y", "z"].iter().enumerate() {
            if let Some(v) = p.attr(k) {
                out[i] = v
                    .trim()
                    .parse()
                    .map_err(|_| self.err(p, format!("{k}=\"{v}\" is not a number")))?;
            }
        }
        if !out.is_finite() {
            return Err(self.err(p, "values must be finite"));
        }
        Ok(out)
    }

    /// A colour property: `<rgb>`, `<spectrum>`, `<float>`, or a texture (nested or by
    /// `<ref>`), which stands in as a constant with a warning. `None` if absent.
    fn colour(
        &mut self,
        node: &'a Node,
        name: &str,
        usage: SpectrumUse,
    ) -> Result<Option<Rgb>, LoadError> {
        let Some(p) = prop(node, name) else {
            return Ok(None);
        };
        let p = self.deref(p)?;
        let rgb = match p.tag.as_str() {
            "rgb" => {
                let n = numbers(self.value(p)?).map_err(|m| self.err(p, m))?;
                match n.as_slice() {
                    [a] => Rgb::splat(*a as f32),
                    [r, g, b] => Rgb::new(*r as f32, *g as f32, *b as f32),
                    _ => {
                        return Err(
                            self.err(p, format!("<rgb> needs 1 or 3 values, got {}", n.len()))
                        );
                    }
                }
            }
            "float" | "integer" => {
                let v: f64 = self
                    .value(p)?
                    .trim()
                    .parse()
                    .map_err(|_| self.err(p, "not a number"))?;
                Rgb::splat(v as f32)
            }
            "spectrum" if p.attr("type").is_none() => self.spectrum(p, usage)?,
            "texture" | "spectrum" => self.texture_standin(p)?,
            other => {
                return Err(self.err(
                    p,
                    format!("property \"{name}\" must be a colour, got <{other}>"),
                ));
            }
        };
        if !rgb.is_finite() {
            return Err(self.err(p, "colour must be finite"));
        }
        Ok(Some(rgb))
    }

    /// `<spectrum value="…">` (one value, or `wavelength:value` pairs) or `filename=".spd"`.
    fn spectrum(&self, p: &Node, usage: SpectrumUse) -> Result<Rgb, LoadError> {
        let (w, v) = if let Some(value) = p.attr("value") {
            if !value.contains(':') {
                let n = numbers(value).map_err(|m| self.err(p, m))?;
                let [x] = n.as_slice() else {
                    return Err(self.err(
                        p,
                        "a <spectrum> value is one number or wavelength:value pairs",
                    ));
                };
                return Ok(spectrum::constant_spectrum_to_rgb(*x, usage));
            }
            let mut w = Vec::new();
            let mut v = Vec::new();
            for pair in value.split(',').map(str::trim).filter(|s| !s.is_empty()) {
                let (a, b) = pair
                    .split_once(':')
                    .ok_or_else(|| self.err(p, format!("\"{pair}\" is not wavelength:value")))?;
                w.push(
                    a.trim()
                        .parse::<f64>()
                        .map_err(|_| self.err(p, format!("\"{a}\" is not a number")))?,
                );
                v.push(
                    b.trim()
                        .parse::<f64>()
                        .map_err(|_| self.err(p, format!("\"{b}\" is not a number")))?,
                );
            }
            (w, v)
        } else if let Some(file) = p.attr("filename") {
            let path = self.doc.resolve(p, file);
            read_spd(&path).map_err(|m| self.err(p, m))?
        } else {
            return Err(self.err(p, "<spectrum> needs a value or a filename"));
        };
        spectrum::spectrum_to_rgb(&w, &v, usage)
            .ok_or_else(|| self.err(p, "wavelengths must increase and values be finite"))
    }

    /// The constant colour that stands in for a texture, with a warning.
    fn texture_standin(&mut self, tex: &'a Node) -> Result<Rgb, LoadError> {
        let label = tex.label();
        match tex.attr("type") {
            Some("bitmap") => {
                let file = self
                    .string(tex, "filename")?
                    .ok_or_else(|| self.err(tex, "bitmap needs a filename"))?;
                let path = self.doc.resolve(tex, file);
                let (rgb, what) = import::image_texture_standin(&path)
                    .map_err(|e| self.err(tex, e.to_string()))?;
                self.builder.warn(format!(
                    "{label} ({file}): textures are not supported yet; {what} {} stands in",
                    super::fmt_vec(rgb)
                ));
                Ok(rgb)
            }
            Some("checkerboard") => {
                let a = self
                    .colour(tex, "color0", SpectrumUse::Reflectance)?
                    .unwrap_or(Rgb::splat(0.4));
                let b = self
                    .colour(tex, "color1", SpectrumUse::Reflectance)?
                    .unwrap_or(Rgb::splat(0.2));
                let rgb = 0.5 * (a + b);
                self.builder.warn(format!(
                    "{label}: textures are not supported yet; the mean of its two colours {} stands in",
                    super::fmt_vec(rgb)
                ));
                Ok(rgb)
            }
            _ => {
                let rgb = Rgb::splat(import::TEXTURE_STANDIN_GREY);
                self.builder.warn(format!(
                    "{label}: this texture is not supported; grey {} stands in",
                    super::fmt_vec(rgb)
                ));
                Ok(rgb)
            }
        }
    }

    /// The `to_world` (or other named) transform of `node`, identity if absent.
    fn transform(&self, node: &Node, name: &str) -> Result<DMat4, LoadError> {
        let Some(t) = prop(node, name) else {
            return Ok(DMat4::IDENTITY);
        };
        if t.tag != "transform" {
            return Err(self.err(
                t,
                format!("property \"{name}\" must be a <transform>, got <{}>", t.tag),
            ));
        }
        let mut m = DMat4::IDENTITY;
        for op in &t.children {
            let step = match op.tag.as_str() {
                "translate" => DMat4::from_translation(self.xyz(op, 0.0)?),
                "scale" => DMat4::from_scale(self.xyz(op, 1.0)?),
                "rotate" => {
                    let axis = self.xyz(op, 0.0)?;
                    let angle: f64 = op
                        .attr("angle")
                        .ok_or_else(|| self.err(op, "<rotate> needs an angle"))?
                        .trim()
                        .parse()
                        .map_err(|_| self.err(op, "angle is not a number"))?;
                    if axis == DVec3::ZERO {
                        return Err(self.err(op, "rotation axis cannot be zero"));
                    }
                    mitsuba_rotation(axis, angle.to_radians())
                }
                "lookat" => {
                    let parse = |k: &str| -> Result<Option<DVec3>, LoadError> {
                        op.attr(k)
                            .map(|v| {
                                let n = numbers(v).map_err(|m| self.err(op, m))?;
                                match n.as_slice() {
                                    [a, b, c] => Ok(DVec3::new(*a, *b, *c)),
                                    _ => Err(self.err(op, format!("{k} needs 3 values"))),
                                }
                            })
                            .transpose()
                    };
                    let origin =
                        parse("origin")?.ok_or_else(|| self.err(op, "<lookat> needs an origin"))?;
                    let target =
                        parse("target")?.ok_or_else(|| self.err(op, "<lookat> needs a target"))?;
                    let dir = (target - origin)
                        .try_normalize()
                        .ok_or_else(|| self.err(op, "origin and target coincide"))?;
                    let up = match parse("up")? {
                        Some(up) if up != DVec3::ZERO => up,
                        _ => dir.any_orthonormal_vector(),
                    };
                    let left = up
                        .cross(dir)
                        .try_normalize()
                        .ok_or_else(|| self.err(op, "up is parallel to the view direction"))?;
                    let new_up = dir.cross(left);
                    DMat4::from_cols(
                        left.extend(0.0),
                        new_up.extend(0.0),
                        dir.extend(0.0),
                        origin.extend(1.0),
                    )
                }
                "matrix" => {
                    let n = numbers(self.value(op)?).map_err(|m| self.err(op, m))?;
                    let size = match n.len() {
                        16 => 4,
                        9 => 3,
                        k => {
                            return Err(
                                self.err(op, format!("matrix needs 9 or 16 values, got {k}"))
                            );
                        }
                    };
                    let mut m = DMat4::IDENTITY;
                    for i in 0..size {
                        for j in 0..size {
                            // Row-major in the file; glam is column-major.
                            m.col_mut(j)[i] = n[i * size + j];
                        }
                    }
                    m
                }
                other => {
                    return Err(self.err(op, format!("unexpected <{other}> inside <transform>")));
                }
            };
            m = step * m;
        }
        if !m.is_finite() {
            return Err(self.err(t, "transform is not finite"));
        }
        Ok(m)
    }

    /// The BSDF of a shape: a nested `<bsdf>`, or a `<ref>` to one. `None` if it has none.
    fn shape_bsdf(&self, shape: &'a Node) -> Result<Option<&'a Node>, LoadError> {
        for child in &shape.children {
            let target = match child.tag.as_str() {
                "bsdf" => child,
                "ref" => {
                    let t = self.deref(child)?;
                    if t.tag != "bsdf" {
                        continue;
                    }
                    t
                }
                _ => continue,
            };
            return Ok(Some(target));
        }
        Ok(None)
    }

    /// The area emitter of a shape: a nested `<emitter>` or a `<ref>` to one.
    fn shape_emitter(&self, shape: &'a Node) -> Result<Option<&'a Node>, LoadError> {
        for child in &shape.children {
            let target = match child.tag.as_str() {
                "emitter" => child,
                "ref" => {
                    let t = self.deref(child)?;
                    if t.tag != "emitter" {
                        continue;
                    }
                    t
                }
                _ => continue,
            };
            if target.attr("type") != Some("area") {
                return Err(self.err(target, "a shape can only carry an area emitter"));
            }
            return Ok(Some(target));
        }
        Ok(None)
    }

    /// Converts a BSDF (cached by element, so shared BSDFs warn once).
    fn bsdf(&mut self, node: &'a Node) -> Result<ConvertedBsdf, LoadError> {
        let key = std::ptr::from_ref(node) as usize;
        if let Some(c) = self.bsdf_cache.get(&key) {
            return Ok(c.clone());
        }
        let name = node
            .attr("id")
            .map(str::to_owned)
            .unwrap_or_else(|| format!("{}@{}", node.attr("type").unwrap_or("bsdf"), node.line));
        let kind = self.bsdf_kind(node, &name)?;
        let c = ConvertedBsdf { name, kind };
        self.bsdf_cache.insert(key, c.clone());
        Ok(c)
    }

    /// The first nested BSDF of a wrapper (`twosided`, `mask`, …).
    fn inner_bsdf(&self, node: &'a Node) -> Result<&'a Node, LoadError> {
        for child in &node.children {
            let t = self.deref(child)?;
            if t.tag == "bsdf" {
                return Ok(t);
            }
        }
        Err(self.err(node, "needs a nested <bsdf>"))
    }

    fn ior(&self, node: &Node, name: &str, default: f32) -> Result<f32, LoadError> {
        let Some(p) = prop(node, name) else {
            return Ok(default);
        };
        match p.tag.as_str() {
            "float" => Ok(self.float(node, name)?.unwrap_or(f64::from(default)) as f32),
            "string" => {
                let v = self.value(p)?.to_ascii_lowercase();
                IOR_TABLE
                    .iter()
                    .find(|(n, _)| *n == v)
                    .map(|(_, x)| *x)
                    .ok_or_else(|| {
                        self.err(
                            p,
                            format!("unknown material \"{v}\" for an index of refraction"),
                        )
                    })
            }
            other => Err(self.err(
                p,
                format!("property \"{name}\" must be a <float> or <string>, got <{other}>"),
            )),
        }
    }

    fn alpha(&mut self, node: &'a Node, label: &str) -> Result<f32, LoadError> {
        if let Some(d) = self.string(node, "distribution")?
            && d != "ggx"
        {
            self.builder.warn(format!(
                "{label}: the {d} distribution is rendered as GGX with the same alpha"
            ));
        }
        let alpha = self.float(node, "alpha")?;
        let (u, v) = (self.float(node, "alpha_u")?, self.float(node, "alpha_v")?);
        let alpha = match (alpha, u, v) {
            (Some(a), _, _) => a,
            (None, Some(u), Some(v)) => {
                self.builder.warn(format!(
                    "{label}: anisotropic roughness ({u}, {v}) is rendered isotropic with alpha {}",
                    0.5 * (u + v)
                ));
                0.5 * (u + v)
            }
            _ => 0.1,
        };
        if prop(node, "alpha").is_some_and(|p| p.tag != "float") {
            self.builder.warn(format!(
                "{label}: a textured alpha is not supported; 0.1 stands in"
            ));
        }
        Ok(alpha as f32)
    }

    fn bsdf_kind(&mut self, node: &'a Node, name: &str) -> Result<Option<MaterialKind>, LoadError> {
        let label = node.label();
        let ty = node.attr("type").unwrap_or("");
        let refl = SpectrumUse::Reflectance;
        Ok(Some(match ty {
            "diffuse" => MaterialKind::Diffuse {
                albedo: self
                    .colour(node, "reflectance", refl)?
                    .unwrap_or(Rgb::splat(DEFAULT_REFLECTANCE)),
            },
            "twosided" => {
                let inner = self.inner_bsdf(node)?;
                return Ok(self.bsdf(inner)?.kind);
            }
            "mask" | "bumpmap" | "normalmap" | "blendbsdf" => {
                let what = match ty {
                    "mask" => "its opacity is ignored (the surface is opaque)",
                    "blendbsdf" => "only its first BSDF is used",
                    _ => "the normal perturbation is ignored",
                };
                self.builder
                    .warn(format!("{label}: {what}; the nested BSDF stands in"));
                let inner = self.inner_bsdf(node)?;
                return Ok(self.bsdf(inner)?.kind);
            }
            "conductor" | "roughconductor" => {
                let reflectance = self.conductor_reflectance(node, &label)?;
                let alpha = if ty == "roughconductor" {
                    self.alpha(node, &label)?
                } else {
                    0.0
                };
                if alpha <= MIRROR_ALPHA {
                    MaterialKind::Mirror { reflectance }
                } else {
                    MaterialKind::Glossy {
                        reflectance,
                        roughness: alpha,
                        diffuse: Rgb::ZERO,
                    }
                }
            }
            "dielectric" | "thindielectric" | "roughdielectric" => {
                let int = self.ior(node, "int_ior", 1.5046)?;
                let ext = self.ior(node, "ext_ior", 1.000_277)?;
                if ty == "thindielectric" {
                    self.builder.warn(format!(
                        "{label}: a thin dielectric is rendered as a solid dielectric of the same ior (rays bend)"
                    ));
                } else if ty == "roughdielectric" {
                    self.builder
                        .warn(format!("{label}: a rough dielectric is rendered smooth"));
                }
                if prop(node, "specular_reflectance").is_some()
                    || prop(node, "specular_transmittance").is_some()
                {
                    self.builder.warn(format!(
                        "{label}: specular_reflectance/transmittance are ignored (fppm's dielectric is clear)"
                    ));
                }
                MaterialKind::Dielectric { ior: int / ext }
            }
            "plastic" | "roughplastic" => {
                let int = self.ior(node, "int_ior", 1.49)?;
                let ext = self.ior(node, "ext_ior", 1.000_277)?;
                let f0 = spectrum::dielectric_reflectance(int / ext);
                let specular = self
                    .colour(node, "specular_reflectance", refl)?
                    .unwrap_or(Rgb::ONE);
                let diffuse = self
                    .colour(node, "diffuse_reflectance", refl)?
                    .unwrap_or(Rgb::splat(DEFAULT_REFLECTANCE));
                let alpha = if ty == "roughplastic" {
                    self.alpha(node, &label)?
                } else {
                    SMOOTH_COAT_ALPHA
                };
                self.builder.warn(format!(
                    "{label}: plastic is approximated by fppm's glossy-over-diffuse material (GGX alpha {alpha}, \
                     reflectance {f0:.4} = Fresnel at normal incidence, diffuse scaled by {:.4})",
                    1.0 - f0
                ));
                MaterialKind::Glossy {
                    reflectance: specular * f0,
                    roughness: if alpha > 0.0 {
                        alpha
                    } else {
                        SMOOTH_COAT_ALPHA
                    },
                    diffuse: diffuse * (1.0 - f0),
                }
            }
            "principled" => {
                let base = self
                    .colour(node, "base_color", refl)?
                    .unwrap_or(Rgb::splat(DEFAULT_REFLECTANCE));
                self.builder.warn(format!(
                    "{label}: the principled BSDF is approximated by a diffuse one of its base_color"
                ));
                MaterialKind::Diffuse { albedo: base }
            }
            "null" => {
                self.builder.warn(format!(
                    "{label}: shapes with a null BSDF are invisible; skipped"
                ));
                return Ok(None);
            }
            other => {
                let grey = Rgb::splat(DEFAULT_REFLECTANCE);
                self.builder.warn(format!(
                    "{label}: the {other} BSDF is not supported; a diffuse grey {} stands in (material {name:?})",
                    super::fmt_vec(grey)
                ));
                MaterialKind::Diffuse { albedo: grey }
            }
        }))
    }

    /// Reflectance at normal incidence of a (rough) conductor from its `material` or `eta`/`k`,
    /// times `specular_reflectance`.
    fn conductor_reflectance(&mut self, node: &'a Node, label: &str) -> Result<Rgb, LoadError> {
        let specular = self
            .colour(node, "specular_reflectance", SpectrumUse::Reflectance)?
            .unwrap_or(Rgb::ONE);
        let eta = self.colour(node, "eta", SpectrumUse::Ior)?;
        let k = self.colour(node, "k", SpectrumUse::Ior)?;
        let material = self.string(node, "material")?;
        let r0 = match (eta, k, material) {
            (Some(eta), k, _) => spectrum::conductor_reflectance(eta, k.unwrap_or(Rgb::ZERO)),
            (None, _, None | Some("none")) => Rgb::ONE,
            (None, _, Some(m)) => {
                let (eta, k) = spectrum::metal(m).ok_or_else(|| {
                    let p = prop(node, "material").unwrap_or(node);
                    self.err(p, format!("unknown conductor material \"{m}\""))
                })?;
                let r0 = spectrum::conductor_reflectance(eta, k);
                self.builder.warn(format!(
                    "{label}: conductor {m} uses its reflectance at normal incidence {} (no angular Fresnel)",
                    super::fmt_vec(r0)
                ));
                r0
            }
        };
        Ok(r0 * specular)
    }

    fn shape(&mut self, node: &'a Node, index: usize) -> Result<(), LoadError> {
        let label = node.label();
        let ty = node.attr("type").unwrap_or("");
        let bsdf = match self.shape_bsdf(node)? {
            Some(b) => self.bsdf(b)?,
            None => ConvertedBsdf {
                name: "default".to_owned(),
                kind: Some(MaterialKind::Diffuse {
                    albedo: Rgb::splat(DEFAULT_REFLECTANCE),
                }),
            },
        };
        let Some(kind) = bsdf.kind else {
            return Ok(());
        };
        let emitter = self.shape_emitter(node)?;
        let (name, emission) = match emitter {
            Some(e) => {
                let radiance = self
                    .colour(e, "radiance", SpectrumUse::Emission)?
                    .ok_or_else(|| self.err(e, "an area emitter needs a radiance"))?;
                let id = e
                    .attr("id")
                    .map_or_else(|| format!("shape{index}"), str::to_owned);
                (format!("{}+{id}", bsdf.name), radiance)
            }
            None => (bsdf.name.clone(), Rgb::ZERO),
        };
        let material = self.builder.material(Material {
            name,
            kind,
            emission,
        });
        let to_world = self.transform(node, "to_world")?;
        let m = to_world.as_mat4();
        let flip = self.boolean(node, "flip_normals")?.unwrap_or(false);
        let face_normals = self.boolean(node, "face_normals")?.unwrap_or(false);
        let mesh = match ty {
            "obj" | "ply" | "serialized" => {
                let file = self
                    .string(node, "filename")?
                    .ok_or_else(|| self.err(node, "needs a filename"))?;
                let path = self.doc.resolve(node, file);
                let wrap = |e: LoadError| self.err(node, e.to_string());
                let mut mesh = match ty {
                    "obj" => {
                        let data = super::obj::load_obj(&path).map_err(wrap)?;
                        let mut mesh = IndexedMesh::default();
                        let mut all_normals = true;
                        let mut normals = Vec::new();
                        for t in &data.triangles {
                            let base = mesh.positions.len() as u32;
                            mesh.positions.extend_from_slice(&t.positions);
                            match t.normals {
                                Some(n) => normals.extend_from_slice(&n),
                                None => all_normals = false,
                            }
                            mesh.indices.push([base, base + 1, base + 2]);
                        }
                        if all_normals && !data.triangles.is_empty() {
                            mesh.normals = Some(normals);
                        }
                        mesh
                    }
                    "ply" => super::ply::load_ply(&path).map_err(wrap)?,
                    _ => {
                        let index = self.integer(node, "shape_index")?.unwrap_or(0);
                        let index = usize::try_from(index)
                            .map_err(|_| self.err(node, "shape_index must not be negative"))?;
                        super::serialized::load_serialized(&path, index).map_err(wrap)?
                    }
                };
                if face_normals {
                    mesh.normals = None;
                } else if mesh.normals.is_none() && ty != "obj" {
                    mesh.compute_vertex_normals();
                }
                mesh
            }
            "rectangle" => IndexedMesh::rectangle(),
            "cube" => IndexedMesh::cube(),
            "disk" => {
                self.builder.warn(format!(
                    "{label}: the disk is tessellated into {} triangles",
                    import::DISK_SEGMENTS
                ));
                IndexedMesh::disk()
            }
            "sphere" => {
                let center = self
                    .vector(node, "center")?
                    .unwrap_or(DVec3::ZERO)
                    .as_vec3();
                let radius = self.float(node, "radius")?.unwrap_or(1.0) as f32;
                if !(radius > 0.0 && radius.is_finite()) {
                    return Err(self.err(node, format!("radius must be > 0, got {radius}")));
                }
                if flip {
                    self.builder
                        .warn(format!("{label}: flip_normals is ignored on a sphere"));
                }
                self.builder.sphere(center, radius, m, material, &label);
                return Ok(());
            }
            "cylinder" => {
                let p0 = self.vector(node, "p0")?.unwrap_or(DVec3::ZERO).as_vec3();
                let p1 = self.vector(node, "p1")?.unwrap_or(DVec3::Z).as_vec3();
                let radius = self.float(node, "radius")?.unwrap_or(1.0) as f32;
                if !(radius > 0.0 && radius.is_finite()) || (p1 - p0).length() <= 0.0 {
                    return Err(self.err(node, "a cylinder needs radius > 0 and p0 != p1"));
                }
                if flip {
                    self.builder
                        .warn(format!("{label}: flip_normals is ignored on a cylinder"));
                }
                let emissive = emission_of(&self.builder, material);
                import::cylinder(&mut self.builder, p0, p1, radius, m, material, emissive);
                return Ok(());
            }
            "shapegroup" | "instance" => {
                self.builder
                    .warn(format!("{label}: instancing is not supported; skipped"));
                return Ok(());
            }
            other => {
                return Err(self.err(node, format!("shape type \"{other}\" is not supported")));
            }
        };
        let mut mesh = mesh;
        if flip {
            mesh.flip();
        }
        self.builder.mesh(&mesh, m, material);
        Ok(())
    }

    fn emitter(&mut self, node: &'a Node) -> Result<(), LoadError> {
        let label = node.label();
        let to_world = self.transform(node, "to_world")?;
        let em = SpectrumUse::Emission;
        match node.attr("type").unwrap_or("") {
            // Used by shapes through <ref>.
            "area" => {}
            "point" => {
                let position = match self.vector(node, "position")? {
                    Some(p) => p,
                    None => to_world.transform_point3(DVec3::ZERO),
                };
                let intensity = self.colour(node, "intensity", em)?.unwrap_or(Rgb::ONE);
                self.builder.lights.push(Light::Point {
                    position: position.as_vec3(),
                    intensity,
                });
            }
            "spot" => {
                let intensity = self.colour(node, "intensity", em)?.unwrap_or(Rgb::ONE);
                let cutoff = self.float(node, "cutoff_angle")?.unwrap_or(20.0);
                let beam = self.float(node, "beam_width")?.unwrap_or(cutoff * 0.75);
                let direction = to_world
                    .transform_vector3(DVec3::Z)
                    .try_normalize()
                    .ok_or_else(|| self.err(node, "to_world has no direction"))?;
                self.builder.warn(format!(
                    "{label}: the spot's falloff between beam_width and cutoff_angle follows fppm's curve, not Mitsuba's"
                ));
                self.builder.lights.push(Light::Spot {
                    position: to_world.transform_point3(DVec3::ZERO).as_vec3(),
                    direction: direction.as_vec3(),
                    intensity,
                    cone_angle: (cutoff as f32).to_radians(),
                    falloff_start: (beam.min(cutoff) as f32).to_radians(),
                });
            }
            "directional" => {
                let irradiance = self.colour(node, "irradiance", em)?.unwrap_or(Rgb::ONE);
                let direction = match self.vector(node, "direction")? {
                    Some(d) => d,
                    None => to_world.transform_vector3(DVec3::Z),
                }
                .try_normalize()
                .ok_or_else(|| self.err(node, "direction cannot be zero"))?;
                self.builder.lights.push(Light::Directional {
                    direction: direction.as_vec3(),
                    irradiance,
                });
            }
            "envmap" | "constant" | "sunsky" | "sky" | "sun" => {
                import::environment_light_standin(&mut self.builder, &label);
            }
            other => {
                return Err(self.err(node, format!("emitter type \"{other}\" is not supported")));
            }
        }
        Ok(())
    }

    fn sensor(&mut self, node: &'a Node) -> Result<(Camera, Film), LoadError> {
        let label = node.label();
        let ty = node.attr("type").unwrap_or("");
        if ty != "perspective" && ty != "thinlens" {
            return Err(self.err(
                node,
                format!("sensor type \"{ty}\" is not supported (perspective and thinlens are)"),
            ));
        }
        let film = match node.children.iter().find(|c| c.tag == "film") {
            Some(f) => {
                let w = self
                    .integer(f, "width")?
                    .unwrap_or(i64::from(DEFAULT_FILM.width));
                let h = self
                    .integer(f, "height")?
                    .unwrap_or(i64::from(DEFAULT_FILM.height));
                let side = |v: i64| {
                    u32::try_from(v)
                        .ok()
                        .filter(|&v| v > 0 && v <= super::MAX_FILM_SIDE)
                };
                let (Some(width), Some(height)) = (side(w), side(h)) else {
                    return Err(self.err(f, format!("film size {w}x{h} is out of range")));
                };
                if let Some(r) = f.children.iter().find(|c| c.tag == "rfilter")
                    && r.attr("type") != Some("box")
                {
                    self.builder.warn(format!(
                        "{}: fppm's pixels are box-filtered; the {} filter is not used",
                        r.label(),
                        r.attr("type").unwrap_or("")
                    ));
                }
                if prop(f, "crop_width").is_some() || prop(f, "crop_offset_x").is_some() {
                    self.builder
                        .warn(format!("{}: the crop window is ignored", f.label()));
                }
                Film { width, height }
            }
            None => DEFAULT_FILM,
        };
        let to_world = self.transform(node, "to_world")?;
        if to_world.determinant() < 0.0 {
            self.builder.warn(format!(
                "{label}: to_world mirrors the image; fppm renders it unmirrored"
            ));
        }
        let position = to_world.transform_point3(DVec3::ZERO);
        let forward = to_world
            .transform_vector3(DVec3::Z)
            .try_normalize()
            .ok_or_else(|| self.err(node, "to_world has no view direction"))?;
        let up = to_world
            .transform_vector3(DVec3::Y)
            .try_normalize()
            .ok_or_else(|| self.err(node, "to_world has no up direction"))?;
        let fov = self
            .float(node, "fov")?
            .ok_or_else(|| self.err(node, "needs a fov (focal_length is not supported)"))?;
        if !(fov > 0.0 && fov < 180.0) {
            return Err(self.err(node, format!("fov must be in (0, 180) degrees, got {fov}")));
        }
        let axis = self.string(node, "fov_axis")?.unwrap_or("x");
        let (w, h) = (f64::from(film.width), f64::from(film.height));
        let along = match axis {
            "x" => w,
            "y" => h,
            "diagonal" => w.hypot(h),
            "smaller" => w.min(h),
            "larger" => w.max(h),
            other => {
                return Err(self.err(
                    node,
                    format!("fov_axis \"{other}\" is not one of x, y, diagonal, smaller, larger"),
                ));
            }
        };
        let fov_y = 2.0 * ((fov.to_radians() * 0.5).tan() * h / along).atan();
        let (aperture, focus) = if ty == "thinlens" {
            let a = self.float(node, "aperture_radius")?.unwrap_or(0.0);
            let f = self.float(node, "focus_distance")?.unwrap_or(0.0);
            if !(a >= 0.0 && f > 0.0) {
                return Err(self.err(
                    node,
                    "a thinlens needs aperture_radius ≥ 0 and focus_distance > 0",
                ));
            }
            (a, f)
        } else {
            (
                0.0,
                self.float(node, "focus_distance")?
                    .filter(|f| *f > 0.0)
                    .unwrap_or(1.0),
            )
        };
        Ok((
            Camera {
                position: position.as_vec3(),
                look_at: (position + forward).as_vec3(),
                up: up.as_vec3(),
                fov_y: fov_y as f32,
                aperture_radius: aperture as f32,
                focus_distance: focus as f32,
            },
            film,
        ))
    }

    fn integrator(&mut self, node: &'a Node, render: &mut RenderDefaults) -> Result<(), LoadError> {
        let label = node.label();
        let ty = node.attr("type").unwrap_or("");
        if !matches!(
            ty,
            "path" | "volpath" | "volpathmis" | "ptracer" | "prb" | "direct"
        ) {
            self.builder.warn(format!(
                "{label}: fppm renders global illumination with its own method instead"
            ));
        }
        if ty == "direct" {
            self.builder.warn(format!(
                "{label}: fppm renders all bounces, not direct light only"
            ));
        }
        if let Some(depth) = self.integer(node, "max_depth")? {
            match depth {
                -1 => {}
                d if d >= 2 => {
                    render.set("max_depth", u32::try_from(d - 1).unwrap_or(u32::MAX).min(1024));
                }
                d => self.builder.warn(format!(
                    "{label}: max_depth {d} (emitters seen directly only) cannot be rendered; fppm's default depth is used"
                )),
            }
        }
        if let Some(rr) = self.integer(node, "rr_depth")? {
            self.builder.warn(format!(
                "{label}: rr_depth {rr} is not carried; fppm's Russian roulette starts at its own depth (unbiased either way)"
            ));
        }
        if self.boolean(node, "hide_emitters")? == Some(true) {
            self.builder
                .warn(format!("{label}: hide_emitters is ignored"));
        }
        Ok(())
    }
}

/// Whether material `index` emits.
fn emission_of(builder: &Builder, index: u32) -> bool {
    builder
        .materials
        .get(index as usize)
        .is_some_and(|m| m.emission.max_element() > 0.0)
}

/// Mitsuba's rotation (Dr.Jit's `rotate`): c·I + (1 − c)·a aᵀ + s·\[a\]×, with the axis `a`
/// used as written. Mitsuba does not normalise it, so neither does the importer: a scene with a
/// non-unit axis renders as in Mitsuba.
fn mitsuba_rotation(a: DVec3, theta: f64) -> DMat4 {
    let (s, c) = theta.sin_cos();
    let k = 1.0 - c;
    // Rows of the 3 × 3 part.
    let r0 = DVec3::new(
        c + a.x * a.x * k,
        a.x * a.y * k - a.z * s,
        a.x * a.z * k + a.y * s,
    );
    let r1 = DVec3::new(
        a.y * a.x * k + a.z * s,
        c + a.y * a.y * k,
        a.y * a.z * k - a.x * s,
    );
    let r2 = DVec3::new(
        a.z * a.x * k - a.y * s,
        a.z * a.y * k + a.x * s,
        c + a.z * a.z * k,
    );
    DMat4::from_cols(
        DVec3::new(r0.x, r1.x, r2.x).extend(0.0),
        DVec3::new(r0.y, r1.y, r2.y).extend(0.0),
        DVec3::new(r0.z, r1.z, r2.z).extend(0.0),
        glam::DVec4::W,
    )
}

/// Reads a `.spd` file: lines of `wavelength value`, `#` comments.
pub(crate) fn read_spd(path: &Path) -> Result<(Vec<f64>, Vec<f64>), String> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| format!("cannot read spectrum file {}: {e}", path.display()))?;
    let mut w = Vec::new();
    let mut v = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let line = line.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let n = numbers(line).map_err(|m| format!("{} line {}: {m}", path.display(), i + 1))?;
        let [a, b] = n.as_slice() else {
            return Err(format!(
                "{} line {}: expected `wavelength value`",
                path.display(),
                i + 1
            ));
        };
        w.push(*a);
        v.push(*b);
    }
    Ok((w, v))
}
