//! A glTF or GLB file's document and buffers, read defensively: gltf 1.4.1 panics on some
//! malformed files in its validation and binary header parsing, and its buffer importer reads
//! the file system directly, so the loader checks those inputs first and reads buffers itself
//! (through [`super::files`]), and checks each accessor's layout against its buffer before
//! reading it. The mesh walk is in `gltf.rs`, the materials in `gltf_material.rs`.

use std::path::{Path, PathBuf};

use crate::error::LoadError;
use crate::error::gltf_error;

/// Parses and validates a glTF or GLB file's JSON.
///
/// gltf-json 1.4.1's validation indexes the accessor list with a primitive's `POSITION`
/// accessor before checking that it exists (`mesh.rs`, `primitive_validate_hook`), so a file
/// whose `"accessors"` key is misspelt panics there; those indices are checked first. The
/// validation also runs under `catch_unwind`, the only way to contain a panic of the
/// dependency that this check does not foresee: the user gets one line, not a crash.
///
/// Images are checked for what gltf's `Image::source` unwraps (below).
///
/// A GLB header whose total length is shorter than the header itself makes gltf 1.4.1
/// subtract with overflow (`binary.rs`, `Glb::from_slice`); it is refused first.
pub(super) fn parse(path: &Path, bytes: &[u8]) -> Result<gltf::Gltf, LoadError> {
    if let Some(length) = bytes
        .strip_prefix(b"glTF")
        .and_then(|rest| rest.get(4..8))
        .and_then(|l| <[u8; 4]>::try_from(l).ok())
        .map(u32::from_le_bytes)
        && length < 12
    {
        return Err(gltf_error(
            path,
            format!(
                "GLB header gives a total length of {length} bytes, less than the 12-byte header"
            ),
        ));
    }
    let unchecked =
        gltf::Gltf::from_slice_without_validation(bytes).map_err(|e| gltf_error(path, e))?;
    let blob = unchecked.blob;
    let json = unchecked.document.into_json();
    let accessors = json.accessors.len();
    for (m, mesh) in json.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            let position = gltf::json::validation::Checked::Valid(gltf::Semantic::Positions);
            if let Some(index) = primitive.attributes.get(&position)
                && index.value() >= accessors
            {
                return Err(gltf_error(
                    path,
                    format!(
                        "mesh {m} primitive {p}: POSITION accessor {} does not exist (the file has {accessors} accessors)",
                        index.value()
                    ),
                ));
            }
        }
    }
    // gltf 1.4.1's `Image::source` unwraps the mime type of an image in a buffer view, and
    // the URI of one that has no buffer view; its validation checks neither.
    for (i, image) in json.images.iter().enumerate() {
        let problem = match (&image.buffer_view, &image.uri, &image.mime_type) {
            (Some(_), _, None) => "is stored in a buffer view but has no mimeType",
            (None, None, _) => "has neither a uri nor a bufferView",
            _ => continue,
        };
        return Err(gltf_error(
            path,
            format!("image {i} {problem} (glTF 2.0 requires one)"),
        ));
    }
    let document = crate::guard::contain(move || gltf::Document::from_json(json))
        .map_err(|()| gltf_error(path, "the gltf crate failed while validating this file"))?
        .map_err(|e| gltf_error(path, e))?;
    Ok(gltf::Gltf { document, blob })
}

/// The data of every buffer of `doc`: the GLB binary chunk, a base64 `data:` URI, or a file
/// relative to the glTF file read through [`super::files`] (not gltf's own importer, which
/// reads the file system directly and panics on a percent-escape that is not UTF-8).
/// Buffers are padded with zeros to a multiple of four bytes, as gltf's importer does.
pub(super) fn import_buffers(
    path: &Path,
    doc: &gltf::Document,
    mut blob: Option<Vec<u8>>,
) -> Result<Vec<gltf::buffer::Data>, LoadError> {
    let mut out = Vec::new();
    for buffer in doc.buffers() {
        let index = buffer.index();
        let mut data = match buffer.source() {
            gltf::buffer::Source::Bin => blob.take().ok_or_else(|| {
                gltf_error(
                    path,
                    format!("buffer {index} refers to a missing GLB binary chunk"),
                )
            })?,
            gltf::buffer::Source::Uri(uri) => buffer_uri(path, index, uri)?,
        };
        if data.len() < buffer.length() {
            return Err(gltf_error(
                path,
                format!(
                    "buffer {index} holds {} bytes, the file says {}",
                    data.len(),
                    buffer.length()
                ),
            ));
        }
        data.resize(data.len().next_multiple_of(4), 0);
        out.push(gltf::buffer::Data(data));
    }
    Ok(out)
}

/// Reads a buffer URI: `data:[<media type>];base64,<data>` or a relative file name with
/// percent-escapes. Other schemes (`file:`, `http:`) are refused.
fn buffer_uri(path: &Path, index: usize, uri: &str) -> Result<Vec<u8>, LoadError> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let encoded = rest.split_once(";base64,").map_or(rest, |(_, data)| data);
        return base64::decode(encoded).map_err(|e| {
            gltf_error(
                path,
                format!("buffer {index}: data URI is not valid base64 ({e})"),
            )
        });
    }
    if uri.contains(':') {
        return Err(gltf_error(
            path,
            format!("buffer {index}: unsupported URI scheme in {uri:?}"),
        ));
    }
    let name = urlencoding::decode(uri).map_err(|_| {
        gltf_error(
            path,
            format!("buffer {index}: URI {uri:?} has percent-escapes that are not UTF-8"),
        )
    })?;
    let file: PathBuf = path.parent().unwrap_or(Path::new("")).join(&*name);
    super::files::read(&file).map_err(|e| {
        gltf_error(
            path,
            format!("buffer {index}: cannot read {}: {e}", file.display()),
        )
    })
}

/// The bytes of an image embedded as a data URI, `rest` being what follows `data:`:
/// `[<media type>];base64,<data>` (glTF 2.0 allows only base64 for images). The media type is
/// not checked: the decoder tells the format from the bytes, as for image files.
pub(super) fn image_data_uri(path: &Path, index: usize, rest: &str) -> Result<Vec<u8>, LoadError> {
    let Some((_, encoded)) = rest.split_once(";base64,") else {
        return Err(gltf_error(
            path,
            format!("image {index}: data URI is not base64-encoded (no \";base64,\")"),
        ));
    };
    base64::decode(encoded).map_err(|e| {
        gltf_error(
            path,
            format!("image {index}: data URI is not valid base64 ({e})"),
        )
    })
}

/// Whether `count` items of `size` bytes, `stride` bytes apart from `offset`, end at an
/// address that fits in a `usize`.
pub(crate) fn range_fits(offset: usize, stride: usize, count: usize, size: usize) -> bool {
    count
        .checked_sub(1)
        .and_then(|c| stride.checked_mul(c))
        .and_then(|x| x.checked_add(offset))
        .and_then(|x| x.checked_add(size))
        .is_some()
}

/// Checks what gltf 1.4.1's accessor reader computes without checking (`accessor/util.rs`,
/// `Iter::new`): at least one item, a stride no smaller than an item, and byte ranges
/// (`offset + stride · (count − 1) + size`, a view's `offset + length`) that do not overflow;
/// the same for a sparse accessor's indices and values. A range past the end of its buffer is
/// the reader's to report.
pub(crate) fn layout(accessor: &gltf::Accessor<'_>) -> Result<(), String> {
    let view_fits =
        |view: &gltf::buffer::View<'_>| view.offset().checked_add(view.length()).is_some();
    let strided = |view: &gltf::buffer::View<'_>, offset: usize, count: usize, size: usize| {
        let stride = view.stride().unwrap_or(size);
        if stride < size {
            return Err(format!(
                "buffer view {} has a stride of {stride} bytes, less than its {size}-byte items",
                view.index()
            ));
        }
        if !view_fits(view) || !range_fits(offset, stride, count, size) {
            return Err(format!(
                "its byte range in buffer view {} overflows",
                view.index()
            ));
        }
        Ok(())
    };
    let (count, size) = (accessor.count(), accessor.size());
    if count == 0 {
        return Err("it has no items (count 0)".to_owned());
    }
    if let Some(view) = accessor.view() {
        strided(&view, accessor.offset(), count, size)?;
    }
    if let Some(sparse) = accessor.sparse() {
        let n = sparse.count();
        if n == 0 {
            return Err("its sparse storage has no items (count 0)".to_owned());
        }
        let indices = sparse.indices();
        strided(
            &indices.view(),
            indices.offset(),
            n,
            indices.index_type().size(),
        )?;
        let values = sparse.values();
        strided(&values.view(), values.offset(), n, size)?;
    }
    Ok(())
}

/// What glTF 2.0 allows for an accessor the loader reads.
pub(crate) struct AccessorRule {
    pub(crate) what: &'static str,
    pub(crate) dimensions: gltf::accessor::Dimensions,
    pub(crate) types: &'static [gltf::accessor::DataType],
    /// Whether integer components may be normalized (texture coordinates).
    pub(crate) normalized: bool,
}

pub(crate) const POSITION_RULE: AccessorRule = AccessorRule {
    what: "POSITION",
    dimensions: gltf::accessor::Dimensions::Vec3,
    types: &[gltf::accessor::DataType::F32],
    normalized: false,
};
pub(crate) const NORMAL_RULE: AccessorRule = AccessorRule {
    what: "NORMAL",
    dimensions: gltf::accessor::Dimensions::Vec3,
    types: &[gltf::accessor::DataType::F32],
    normalized: false,
};
pub(crate) const TANGENT_RULE: AccessorRule = AccessorRule {
    what: "TANGENT",
    dimensions: gltf::accessor::Dimensions::Vec4,
    types: &[gltf::accessor::DataType::F32],
    normalized: false,
};
pub(crate) const INDICES_RULE: AccessorRule = AccessorRule {
    what: "indices",
    dimensions: gltf::accessor::Dimensions::Scalar,
    types: &[
        gltf::accessor::DataType::U8,
        gltf::accessor::DataType::U16,
        gltf::accessor::DataType::U32,
    ],
    normalized: false,
};
pub(crate) const TEXCOORD_RULE: AccessorRule = AccessorRule {
    what: "TEXCOORD",
    dimensions: gltf::accessor::Dimensions::Vec2,
    types: &[
        gltf::accessor::DataType::F32,
        gltf::accessor::DataType::U8,
        gltf::accessor::DataType::U16,
    ],
    normalized: true,
};
