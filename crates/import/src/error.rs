//! The one error type of the scene loaders.

use std::path::{Path, PathBuf};

/// Why a scene could not be loaded.
///
/// Every variant carries the file the problem is in (the scene file, or the mesh file a
/// scene refers to), and `Display` is one lowercase line that starts with that path,
/// e.g. `scenes/a.toml: line 7, column 1: unknown key "colour" in [materials.white]
/// (expected one of: type, albedo, emission)`.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum LoadError {
    /// The file could not be opened or read.
    #[error("{}: cannot read file: {}", path.display(), lower_first(&source.to_string()))]
    Io {
        /// The file.
        path: PathBuf,
        /// What the operating system said.
        source: std::io::Error,
    },
    /// The file is not valid UTF-8 text.
    #[error("{}: file is not valid utf-8 text", path.display())]
    NotUtf8 {
        /// The file.
        path: PathBuf,
    },
    /// The file name has an extension no loader handles.
    #[error(
        "{}: unsupported scene file extension {extension:?} (expected .toml, .obj, .gltf, .glb, .xml or .pbrt)",
        path.display()
    )]
    UnsupportedExtension {
        /// The file.
        path: PathBuf,
        /// The extension found (empty if none).
        extension: String,
    },
    /// The TOML text is not well-formed TOML.
    #[error("{}: {}invalid toml: {message}", path.display(), location(*line, *column))]
    Toml {
        /// The file.
        path: PathBuf,
        /// 1-based line, if known.
        line: Option<u32>,
        /// 1-based column, if known.
        column: Option<u32>,
        /// The parser's description of the problem.
        message: String,
    },
    /// A key that scene format version 1 does not define.
    #[error(
        "{}: {}unknown key {key:?} in {table} (expected one of: {expected})",
        path.display(), location(*line, *column)
    )]
    UnknownKey {
        /// The file.
        path: PathBuf,
        /// 1-based line, if known.
        line: Option<u32>,
        /// 1-based column, if known.
        column: Option<u32>,
        /// The table, e.g. `[materials.white]` or `[[shapes]] #2`.
        table: String,
        /// The unknown key.
        key: String,
        /// The keys allowed there, comma separated.
        expected: String,
    },
    /// A required key is absent.
    #[error("{}: {}missing required key {key:?} in {table}", path.display(), location(*line, *column))]
    MissingKey {
        /// The file.
        path: PathBuf,
        /// 1-based line of the table, if known.
        line: Option<u32>,
        /// 1-based column, if known.
        column: Option<u32>,
        /// The table the key belongs in.
        table: String,
        /// The missing key.
        key: String,
    },
    /// A value has the wrong TOML type (a string where numbers belong, a 2-vector for a colour…).
    #[error(
        "{}: {}wrong type{} in {table}: {message}",
        path.display(), location(*line, *column), for_key(key)
    )]
    WrongType {
        /// The file.
        path: PathBuf,
        /// 1-based line, if known.
        line: Option<u32>,
        /// 1-based column, if known.
        column: Option<u32>,
        /// The table the key is in.
        table: String,
        /// The key (empty if not known).
        key: String,
        /// What was found and what was expected.
        message: String,
    },
    /// A material `type` (or shape/light `type`) that the format does not define.
    #[error(
        "{}: {}unknown type {found:?} in {table} (expected one of: {expected})",
        path.display(), location(*line, *column)
    )]
    UnknownType {
        /// The file.
        path: PathBuf,
        /// 1-based line, if known.
        line: Option<u32>,
        /// 1-based column, if known.
        column: Option<u32>,
        /// The table, e.g. `[materials.glass]`.
        table: String,
        /// The type given.
        found: String,
        /// The types allowed, comma separated.
        expected: String,
    },
    /// A shape refers to a material name that no `[materials.NAME]` table defines.
    #[error("{}: {context} refers to unknown material {name:?} (defined: {defined})", path.display())]
    UnknownMaterial {
        /// The file.
        path: PathBuf,
        /// Where the reference is, e.g. `[[shapes]] #3`.
        context: String,
        /// The name referred to.
        name: String,
        /// The names that are defined, comma separated.
        defined: String,
    },
    /// A value out of its allowed range: fov outside (0, 180), a non-positive radius or
    /// resolution, a negative radiance or albedo, a zero direction, a non-finite number…
    #[error("{}: {key} {message}", path.display())]
    InvalidValue {
        /// The file.
        path: PathBuf,
        /// Which value, e.g. `[camera] fov_y` or `material "lamp" emission`.
        key: String,
        /// What is wrong with it, e.g. `must be in (0, 180) degrees, got 180`.
        message: String,
    },
    /// A spectrum, a dispersion law or a named spectrum that cannot be used: a negative or
    /// decreasing wavelength, a negative value, an index of refraction below 1 in range, an
    /// unknown name. The CLI treats it as a usage error (exit 2).
    #[error("{}: {message}", path.display())]
    BadSpectrum {
        /// The file.
        path: PathBuf,
        /// Where (line, material, value) and what is wrong.
        message: String,
    },
    /// A participating medium that cannot be used: a negative or non-finite coefficient, g
    /// outside (−1, 1), a medium on a mesh that is not closed, an index out of range. The CLI
    /// treats it as a usage error (exit 2), as it does a bad density grid file
    /// ([`LoadError::VolumeFile`]).
    #[error("{}: {message}", path.display())]
    BadMedium {
        /// The file.
        path: PathBuf,
        /// Which value and what is wrong.
        message: String,
    },
    /// `format` is not 1.
    #[error("{}: unsupported scene format version {found} (this loader reads format = 1)", path.display())]
    UnsupportedVersion {
        /// The file.
        path: PathBuf,
        /// The version given, as written.
        found: String,
    },
    /// The OBJ text is malformed.
    #[error("{}: {}{message}", path.display(), location(*line, None))]
    Obj {
        /// The OBJ file.
        path: PathBuf,
        /// 1-based line, if it could be found.
        line: Option<u32>,
        /// What is wrong.
        message: String,
    },
    /// An MTL file exists but is malformed.
    #[error("{}: {}{message}", path.display(), location(*line, None))]
    Mtl {
        /// The MTL file.
        path: PathBuf,
        /// 1-based line, if it could be found.
        line: Option<u32>,
        /// What is wrong.
        message: String,
    },
    /// The glTF file (JSON, binary container or buffers) is malformed or unsupported.
    #[error("{}: invalid gltf: {message}", path.display())]
    Gltf {
        /// The glTF file.
        path: PathBuf,
        /// What the glTF reader said.
        message: String,
    },
    /// A vertex position is NaN or infinite.
    #[error("{}: {}vertex has a {what} coordinate", path.display(), location(*line, None))]
    NonFiniteVertex {
        /// The mesh file.
        path: PathBuf,
        /// 1-based line of the vertex (OBJ only).
        line: Option<u32>,
        /// `"nan"` or `"infinite"`.
        what: &'static str,
    },
    /// The scene has no geometry at all (no non-degenerate triangle, no sphere, no cylinder).
    #[error("{}: empty scene: no triangles, spheres or cylinders", path.display())]
    EmptyScene {
        /// The file.
        path: PathBuf,
    },
    /// Nothing emits light: no emissive material is used and there is no delta light.
    #[error(
        "{}: scene has no emitter (no emissive material in use and no point, spot or directional light)",
        path.display()
    )]
    NoEmitter {
        /// The file.
        path: PathBuf,
    },
    /// A Mitsuba XML scene is malformed, or uses something with no honest stand-in.
    #[error("{}: {}{}{message}", path.display(), location(*line, *column), element_prefix(element))]
    Xml {
        /// The XML file (the scene or the included fragment).
        path: PathBuf,
        /// 1-based line, if known.
        line: Option<u32>,
        /// 1-based column, if known.
        column: Option<u32>,
        /// The element, e.g. `<shape type="ply">` (empty if none).
        element: String,
        /// What is wrong.
        message: String,
    },
    /// A pbrt-v4 scene is malformed, or uses something with no honest stand-in.
    #[error("{}: {}{message}", path.display(), location(*line, *column))]
    Pbrt {
        /// The pbrt file (the scene or an included file).
        path: PathBuf,
        /// 1-based line, if known.
        line: Option<u32>,
        /// 1-based column, if known.
        column: Option<u32>,
        /// What is wrong.
        message: String,
    },
    /// A binary or ASCII mesh file (PLY, Mitsuba `.serialized`) is malformed.
    #[error("{}: invalid {format} file: {message}", path.display())]
    MeshFile {
        /// The mesh file.
        path: PathBuf,
        /// `"ply"` or `"serialized"`.
        format: &'static str,
        /// What is wrong.
        message: String,
    },
    /// A density grid file (Mitsuba's `.vol`) is malformed, too large or holds a negative or
    /// non-finite density.
    #[error("{}: invalid volume grid file: {message}", path.display())]
    VolumeFile {
        /// The grid file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// Nothing fppm can render emits light, but the file has emitters it had to skip
    /// (environment lights are not supported yet).
    #[error(
        "{}: scene has no emitter fppm can render (skipped: {skipped}; environment lights are not supported yet)",
        path.display()
    )]
    NoSupportedEmitter {
        /// The file.
        path: PathBuf,
        /// The skipped emitters, e.g. `<emitter type="envmap">`.
        skipped: String,
    },
    /// A texture image cannot be used: missing, unreadable, corrupt, of an unsupported format,
    /// empty, too large or with NaN or infinite texels.
    #[error("{}: {message}", path.display())]
    Texture {
        /// The image file.
        path: PathBuf,
        /// What is wrong, e.g. `texture has zero size (0x0)`.
        message: String,
    },
    /// An environment map cannot be used: unsupported format, undecodable, zero size, not
    /// 2:1, a non-finite texel, or black everywhere.
    #[error("{}: invalid environment map: {message}", path.display())]
    EnvironmentMap {
        /// The image file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// An emissive material is used only by degenerate (zero-area) triangles.
    #[error("{}: emissive material {material:?} has zero area (all its triangles are degenerate)", path.display())]
    ZeroAreaEmitter {
        /// The file.
        path: PathBuf,
        /// The material's name.
        material: String,
    },
}

/// The message with its first letter in lower case (OS and library messages start with a
/// capital).
pub(crate) fn lower_first(message: &str) -> String {
    let mut chars = message.chars();
    match chars.next() {
        Some(c) => c.to_lowercase().chain(chars).collect(),
        None => String::new(),
    }
}

/// `" for \"albedo\""`, or nothing for an unknown key.
fn for_key(key: &str) -> String {
    if key.is_empty() {
        String::new()
    } else {
        format!(" for {key:?}")
    }
}

/// `"<shape type=\"ply\">: "`, or nothing.
fn element_prefix(element: &str) -> String {
    if element.is_empty() {
        String::new()
    } else {
        format!("{element}: ")
    }
}

/// `"line 3, column 5: "`, `"line 3: "` or nothing.
fn location(line: Option<u32>, column: Option<u32>) -> String {
    match (line, column) {
        (Some(l), Some(c)) => format!("line {l}, column {c}: "),
        (Some(l), None) => format!("line {l}: "),
        _ => String::new(),
    }
}

impl LoadError {
    /// The same error as a [`LoadError::BadSpectrum`]: its message (after the file name) kept.
    #[must_use]
    pub fn into_bad_spectrum(self) -> Self {
        let (path, message) = self.into_path_and_message();
        Self::BadSpectrum { path, message }
    }

    /// Whether the error is a [`LoadError::BadSpectrum`].
    #[must_use]
    pub fn is_bad_spectrum(&self) -> bool {
        matches!(self, Self::BadSpectrum { .. })
    }

    /// The same error as a [`LoadError::BadMedium`]: its message (after the file name) kept.
    #[must_use]
    pub fn into_bad_medium(self) -> Self {
        let (path, message) = self.into_path_and_message();
        Self::BadMedium { path, message }
    }

    /// The file and the message after its name, to carry into another kind of error.
    fn into_path_and_message(self) -> (PathBuf, String) {
        let path = self.path().to_path_buf();
        let text = self.to_string();
        let prefix = format!("{}: ", path.display());
        let message = text.strip_prefix(&prefix).unwrap_or(&text).to_owned();
        (path, message)
    }

    /// Whether the error is a value the scene's author must change that the issues of spectra
    /// and media ask to be reported as a usage error (exit 2): a bad spectrum or dispersion law
    /// ([`LoadError::BadSpectrum`]), a bad medium ([`LoadError::BadMedium`]) or a bad density
    /// grid file ([`LoadError::VolumeFile`]).
    #[must_use]
    pub fn is_bad_value(&self) -> bool {
        matches!(
            self,
            Self::BadSpectrum { .. } | Self::BadMedium { .. } | Self::VolumeFile { .. }
        )
    }

    /// The file the error is about.
    #[must_use]
    pub fn path(&self) -> &std::path::Path {
        match self {
            Self::Io { path, .. }
            | Self::NotUtf8 { path }
            | Self::UnsupportedExtension { path, .. }
            | Self::Toml { path, .. }
            | Self::UnknownKey { path, .. }
            | Self::MissingKey { path, .. }
            | Self::WrongType { path, .. }
            | Self::UnknownType { path, .. }
            | Self::UnknownMaterial { path, .. }
            | Self::InvalidValue { path, .. }
            | Self::BadSpectrum { path, .. }
            | Self::BadMedium { path, .. }
            | Self::UnsupportedVersion { path, .. }
            | Self::Obj { path, .. }
            | Self::Mtl { path, .. }
            | Self::Gltf { path, .. }
            | Self::NonFiniteVertex { path, .. }
            | Self::EmptyScene { path }
            | Self::NoEmitter { path }
            | Self::ZeroAreaEmitter { path, .. }
            | Self::Xml { path, .. }
            | Self::Pbrt { path, .. }
            | Self::MeshFile { path, .. }
            | Self::VolumeFile { path, .. }
            | Self::Texture { path, .. }
            | Self::EnvironmentMap { path, .. }
            | Self::NoSupportedEmitter { path, .. } => path,
        }
    }
}

/// The glTF importer's error naming `path`, its message on one line in lower case.
pub(crate) fn gltf_error(path: &Path, message: impl std::fmt::Display) -> LoadError {
    LoadError::Gltf {
        path: path.to_path_buf(),
        message: lower_first(&message.to_string()),
    }
}
