//! PLY meshes (ASCII and binary, little- or big-endian; gzip'd `.ply.gz` too) through the
//! ply-rs-bw crate, for Mitsuba's `ply` shape and pbrt's `plymesh`.
//!
//! Read: `vertex` x, y, z (any numeric type), nx, ny, nz when all three are present, texture
//! coordinates under the names Mitsuba and pbrt read (u/v, s/t, texture_u/texture_v,
//! texture_s/texture_t), kept as in the file, and `face` index lists (`vertex_indices` or
//! `vertex_index`; polygons become fans, as Mitsuba and pbrt do for quads). Other elements and
//! properties (colours) are ignored. Before the
//! payload is parsed the header's element counts are checked against the file's size, so a
//! header that lies about its size is an error rather than a huge allocation.

use std::io::{Cursor, Read};
use std::path::Path;

use glam::{Vec2, Vec3};
use ply_rs_bw::parser::Parser;
use ply_rs_bw::ply::{DefaultElement, Encoding, Property, PropertyType, ScalarType};

use super::builder::IndexedMesh;
use super::read_bytes;
use crate::error::LoadError;

fn ply_error(path: &Path, message: impl std::fmt::Display) -> LoadError {
    LoadError::MeshFile {
        path: path.to_path_buf(),
        format: "ply",
        message: crate::error::lower_first(&message.to_string()),
    }
}

/// Largest decompressed `.ply.gz` accepted (guards against a decompression bomb).
const MAX_GUNZIPPED_BYTES: u64 = 4 << 30;

/// Loads a PLY file (gunzipping it first if its name ends in `.gz`).
pub(crate) fn load_ply(path: &Path) -> Result<IndexedMesh, LoadError> {
    let mut bytes = read_bytes(path)?;
    let gz = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("gz"));
    if gz {
        let mut out = Vec::new();
        flate2::read::GzDecoder::new(bytes.as_slice())
            .take(MAX_GUNZIPPED_BYTES)
            .read_to_end(&mut out)
            .map_err(|e| ply_error(path, format_args!("cannot gunzip: {e}")))?;
        bytes = out;
    }
    parse_ply(path, &bytes)
}

fn scalar_size(t: &ScalarType) -> usize {
    match t {
        ScalarType::Char | ScalarType::UChar => 1,
        ScalarType::Short | ScalarType::UShort => 2,
        ScalarType::Int | ScalarType::UInt | ScalarType::Float => 4,
        ScalarType::Double => 8,
    }
}

/// Parses PLY bytes.
pub(crate) fn parse_ply(path: &Path, bytes: &[u8]) -> Result<IndexedMesh, LoadError> {
    let header_end = find_header_end(bytes)
        .ok_or_else(|| ply_error(path, "no `end_header` line (not a ply file?)"))?;
    let parser = Parser::<DefaultElement>::new();
    let mut cursor = Cursor::new(bytes);
    let header = parser
        .read_ply_header(&mut cursor)
        .map_err(|e| ply_error(path, format_args!("bad header: {e}")))?;
    // The header's promise against what the file holds.
    let payload = bytes.len().saturating_sub(header_end);
    let mut minimum: u128 = 0;
    for element in header.elements.values() {
        // An element without properties takes no bytes but still costs the parser one
        // record each: it is counted as one byte, so that its count is bounded too.
        let per_element: usize = match header.encoding {
            Encoding::Ascii => element.properties.len().max(1) * 2,
            Encoding::BinaryBigEndian | Encoding::BinaryLittleEndian => element
                .properties
                .values()
                .map(|p| match &p.data_type {
                    PropertyType::Scalar(t) => scalar_size(t),
                    PropertyType::List(count, _) => scalar_size(count),
                })
                .sum::<usize>()
                .max(1),
        };
        minimum += element.count as u128 * per_element as u128;
    }
    if minimum > payload as u128 {
        let counts: Vec<String> = header
            .elements
            .values()
            .map(|e| format!("{} {}", e.count, e.name))
            .collect();
        return Err(ply_error(
            path,
            format!(
                "the header declares {} (at least {minimum} bytes of data), but only {payload} bytes follow it",
                counts.join(", ")
            ),
        ));
    }
    let ply = parser
        .read_ply(&mut Cursor::new(bytes))
        .map_err(|e| ply_error(path, e))?;

    let mut mesh = IndexedMesh::default();
    if let Some(vertices) = ply.payload.get("vertex") {
        let has = |k: &str| {
            header
                .elements
                .get("vertex")
                .is_some_and(|e| e.properties.contains_key(k))
        };
        let has_normals = ["nx", "ny", "nz"].iter().all(|k| has(k));
        // The pairs Mitsuba (`src/shapes/ply.cpp`, `has_uv_fields`) and pbrt-v4
        // (`src/pbrt/util/mesh.cpp`, `TriQuadMesh::ReadPLY`) accept, in their order.
        let uv_names = [
            ("u", "v"),
            ("s", "t"),
            ("texture_u", "texture_v"),
            ("texture_s", "texture_t"),
        ]
        .into_iter()
        .find(|(u, v)| has(u) && has(v));
        let mut normals = Vec::with_capacity(if has_normals { vertices.len() } else { 0 });
        let mut uvs = Vec::with_capacity(if uv_names.is_some() {
            vertices.len()
        } else {
            0
        });
        mesh.positions.reserve(vertices.len());
        for (i, v) in vertices.iter().enumerate() {
            let get = |k: &str| -> Result<f32, LoadError> {
                v.get(k)
                    .and_then(scalar)
                    .ok_or_else(|| ply_error(path, format_args!("vertex {i} has no numeric {k}")))
            };
            mesh.positions
                .push(Vec3::new(get("x")?, get("y")?, get("z")?));
            if has_normals {
                normals.push(Vec3::new(get("nx")?, get("ny")?, get("nz")?));
            }
            if let Some((u, v)) = uv_names {
                uvs.push(Vec2::new(get(u)?, get(v)?));
            }
        }
        if has_normals {
            mesh.normals = Some(normals);
        }
        if uv_names.is_some() {
            mesh.uvs = Some(uvs);
        }
    } else {
        return Err(ply_error(path, "no `vertex` element"));
    }
    if let Some(faces) = ply.payload.get("face") {
        for (i, f) in faces.iter().enumerate() {
            let list = f
                .get("vertex_indices")
                .or_else(|| f.get("vertex_index"))
                .and_then(index_list)
                .ok_or_else(|| {
                    ply_error(path, format_args!("face {i} has no vertex_indices list"))
                })?;
            if list.len() < 3 {
                continue;
            }
            for k in 1..list.len() - 1 {
                mesh.indices.push([list[0], list[k], list[k + 1]]);
            }
        }
    }
    mesh.check_indices().map_err(|m| ply_error(path, m))?;
    Ok(mesh)
}

/// Byte offset just after the `end_header` line.
fn find_header_end(bytes: &[u8]) -> Option<usize> {
    let needle = b"end_header";
    let limit = bytes.len().min(1 << 20);
    let at = bytes[..limit]
        .windows(needle.len())
        .position(|w| w == needle)?;
    let mut end = at + needle.len();
    while end < bytes.len() && bytes[end] != b'\n' {
        end += 1;
    }
    Some((end + 1).min(bytes.len()))
}

fn scalar(p: &Property) -> Option<f32> {
    Some(match *p {
        Property::Char(v) => f32::from(v),
        Property::UChar(v) => f32::from(v),
        Property::Short(v) => f32::from(v),
        Property::UShort(v) => f32::from(v),
        Property::Int(v) => v as f32,
        Property::UInt(v) => v as f32,
        Property::Float(v) => v,
        Property::Double(v) => v as f32,
        _ => return None,
    })
}

fn index_list(p: &Property) -> Option<Vec<u32>> {
    fn conv<T: Copy + TryInto<u32>>(v: &[T]) -> Option<Vec<u32>> {
        v.iter().map(|&x| x.try_into().ok()).collect()
    }
    match p {
        Property::ListChar(v) => conv(v),
        Property::ListUChar(v) => conv(v),
        Property::ListShort(v) => conv(v),
        Property::ListUShort(v) => conv(v),
        Property::ListInt(v) => conv(v),
        Property::ListUInt(v) => conv(v),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const ASCII_QUAD: &str = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n";

    #[test]
    fn ascii_quad_becomes_two_triangles() {
        let mesh = parse_ply(Path::new("q.ply"), ASCII_QUAD.as_bytes()).unwrap();
        assert_eq!(mesh.positions.len(), 4);
        assert_eq!(mesh.indices, vec![[0, 1, 2], [0, 2, 3]]);
        assert!(mesh.normals.is_none());
    }

    #[test]
    fn texture_coordinates_are_read_under_each_name() {
        for (u, v) in [
            ("u", "v"),
            ("s", "t"),
            ("texture_u", "texture_v"),
            ("texture_s", "texture_t"),
        ] {
            let text = ASCII_QUAD
                .replace(
                    "property float z\n",
                    &format!("property float z\nproperty float {u}\nproperty float {v}\n"),
                )
                .replace(
                    "0 0 0\n1 0 0\n1 1 0\n0 1 0\n",
                    "0 0 0 0 0\n1 0 0 1 0\n1 1 0 1 0.5\n0 1 0 0 0.5\n",
                );
            let mesh = parse_ply(Path::new("q.ply"), text.as_bytes()).unwrap();
            assert_eq!(
                mesh.uvs,
                Some(vec![
                    Vec2::new(0.0, 0.0),
                    Vec2::new(1.0, 0.0),
                    Vec2::new(1.0, 0.5),
                    Vec2::new(0.0, 0.5)
                ]),
                "{u}/{v}"
            );
        }
        let plain = parse_ply(Path::new("q.ply"), ASCII_QUAD.as_bytes()).unwrap();
        assert!(plain.uvs.is_none());
    }

    #[test]
    fn lying_header_is_an_error() {
        let lie = ASCII_QUAD.replace("element vertex 4", "element vertex 4000000000");
        let err = parse_ply(Path::new("lie.ply"), lie.as_bytes()).unwrap_err();
        let text = err.to_string();
        assert!(
            text.starts_with("lie.ply: invalid ply file: the header declares"),
            "{text}"
        );
    }

    #[test]
    fn out_of_range_index_is_an_error() {
        let bad = ASCII_QUAD.replace("4 0 1 2 3", "4 0 1 2 9");
        let err = parse_ply(Path::new("bad.ply"), bad.as_bytes()).unwrap_err();
        assert!(err.to_string().contains("refers to vertex 9"), "{err}");
    }

    #[test]
    fn gzipped_ply_is_read() {
        use std::io::Write;
        let dir = std::env::temp_dir().join(format!("fppm-ply-gz-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("quad.ply.gz");
        let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
        gz.write_all(ASCII_QUAD.as_bytes()).unwrap();
        std::fs::write(&path, gz.finish().unwrap()).unwrap();
        let mesh = load_ply(&path).unwrap();
        assert_eq!(mesh.indices.len(), 2);
    }
}
