//! Mitsuba 3 XML scenes (`.xml`), with the conventions of Mitsuba 3's own parser and plugins.
//!
//! `xml.rs` expands includes and parameters; the other files interpret the expanded tree, one
//! file per kind of element (`shapes.rs`, `bsdfs.rs`, `emitters.rs`, `sensor.rs`, ...). The
//! mapping to fppm (what is read, approximated or refused) is tabulated in
//! `docs/scene-import.md`. In short:
//! - transforms compose as Mitsuba does: every child of `<transform>` multiplies from the left,
//!   so they apply in document order; `<matrix>` is row-major; `<lookat>` builds the frame
//!   (left, up, forward) with the camera looking down its +z;
//! - `<spectrum>` values become RGB as Mitsuba's RGB variants do ([`super::spectrum`]);
//! - `bitmap` textures of a diffuse reflectance, a plastic's diffuse reflectance and a `mask`'s
//!   opacity become image textures (`textures.rs`); other textured colours stand in as a
//!   constant (`Importer::texture_standin`); environment emitters that fppm cannot render are
//!   skipped with a warning ([`super::builder::environment_light_standin`]);
//! - `homogeneous` media become fppm's media (`media.rs`), a `null` BSDF on a shape that bounds
//!   them its interface;
//! - the integrator's `max_depth` (longest path in segments, Mitsuba's convention) becomes
//!   fppm's `max_depth` (scattering events) minus one; its `rr_depth` is carried as is.

mod bsdfs;
mod emitters;
mod media;
mod properties;
mod sensor;
mod shapes;
mod textures;
mod transforms;
mod xml;

use std::collections::HashMap;
use std::path::Path;

use glam::{DMat4, DVec3};

use self::xml::{Document, Node};
use super::LoadOptions;
use super::builder::{self, Builder, IndexedMesh};
use super::spectrum::{self, SpectrumUse};
use crate::error::LoadError;
use scene::texture::MaterialTextures;
use scene::{Camera, Film, Light, Material, MaterialKind, RenderDefaults, Rgb, SceneDescription};

/// Reflectance of Mitsuba's default BSDF (a shape without one) and of `diffuse` without one.
const DEFAULT_REFLECTANCE: f32 = 0.5;
/// hdrfilm's default size.
const DEFAULT_FILM: Film = Film {
    width: 768,
    height: 576,
};

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
        medium_cache: HashMap::new(),
        images: crate::image_file::TextureCache::default(),
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
                    importer.builder.media.camera = importer.sensor_medium(node)?;
                    camera = Some(c);
                    film = f;
                }
            }
            "integrator" => importer.integrator(node, &mut render)?,
            // Declarations used through <ref> (a `volume` as a heterogeneous medium's
            // `sigma_t`), and elements with no bearing on the image.
            "bsdf" | "medium" | "volume" | "texture" | "spectrum" | "phase" | "float"
            | "integer" | "boolean" | "string" | "rgb" | "point" | "vector" | "alias"
            | "transform" | "ref" => {}
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
    /// Its image textures (diffuse colour, cut-out), if any.
    textures: Option<std::sync::Arc<scene::texture::MaterialTextures>>,
    /// The spectra its colours and indices came from, if any.
    spectra: Option<std::sync::Arc<scene::MaterialSpectra>>,
}

struct Importer<'a> {
    doc: &'a Document,
    ids: HashMap<String, &'a Node>,
    builder: Builder,
    /// BSDFs by node address, so that shared BSDFs convert (and warn) once.
    bsdf_cache: HashMap<usize, ConvertedBsdf>,
    /// Media by node address: each converted once, whoever refers to it.
    medium_cache: HashMap<usize, u32>,
    /// The images of the scene's bitmaps, each decoded once.
    images: crate::image_file::TextureCache,
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
}

/// Reads a `.spd` file: lines of `wavelength value`, `#` comments.
pub(crate) fn read_spd(path: &Path) -> Result<(Vec<f64>, Vec<f64>), String> {
    let bytes = super::files::read(path)
        .map_err(|e| format!("cannot read spectrum file {}: {e}", path.display()))?;
    let text = String::from_utf8(bytes)
        .map_err(|_| format!("spectrum file {} is not UTF-8 text", path.display()))?;
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
