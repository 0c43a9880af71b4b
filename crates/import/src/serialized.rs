//! Mitsuba's `.serialized` meshes (file versions 3 and 4, the ones Mitsuba 0.5–3 write), read
//! as Mitsuba 3's `serialized` shape does (`src/shapes/serialized.cpp`).
//!
//! A file is a sequence of meshes, each `u16 0x041C`, `u16 version`, then a zlib stream:
//! `u32 flags` (0x1 normals, 0x2 uv, 0x8 colours, 0x1000 single / 0x2000 double precision),
//! the mesh name as a NUL-terminated string (version 4 only), `u64` vertex and face counts,
//! positions, normals, uv, colours (when flagged) and `u32` triangle indices. The file ends
//! with the offset of every mesh (`u64` in version 4, `u32` in version 3) and the `u32` mesh
//! count, which `shape_index` selects from. Everything is little-endian.

use std::io::Read;
use std::path::Path;

use glam::Vec3;

use super::builder::IndexedMesh;
use super::read_bytes;
use crate::error::LoadError;

const MAGIC: u16 = 0x041C;
const HAS_NORMALS: u32 = 0x0001;
const HAS_TEXCOORDS: u32 = 0x0002;
const HAS_COLORS: u32 = 0x0008;
const DOUBLE_PRECISION: u32 = 0x2000;

fn error(path: &Path, message: impl Into<String>) -> LoadError {
    LoadError::MeshFile {
        path: path.to_path_buf(),
        format: "serialized",
        message: message.into(),
    }
}

/// Loads mesh number `shape_index` of a `.serialized` file.
pub(crate) fn load_serialized(path: &Path, shape_index: usize) -> Result<IndexedMesh, LoadError> {
    let bytes = read_bytes(path)?;
    parse_serialized(path, &bytes, shape_index)
}

fn u16_at(bytes: &[u8], at: usize) -> Option<u16> {
    Some(u16::from_le_bytes(bytes.get(at..at + 2)?.try_into().ok()?))
}
fn u32_at(bytes: &[u8], at: usize) -> Option<u32> {
    Some(u32::from_le_bytes(bytes.get(at..at + 4)?.try_into().ok()?))
}
fn u64_at(bytes: &[u8], at: usize) -> Option<u64> {
    Some(u64::from_le_bytes(bytes.get(at..at + 8)?.try_into().ok()?))
}

/// Parses mesh `shape_index` of `.serialized` bytes.
pub(crate) fn parse_serialized(
    path: &Path,
    bytes: &[u8],
    shape_index: usize,
) -> Result<IndexedMesh, LoadError> {
    let truncated = || error(path, "file is truncated");
    if u16_at(bytes, 0).ok_or_else(truncated)? != MAGIC {
        return Err(error(
            path,
            "not a mitsuba .serialized file (bad magic number)",
        ));
    }
    let version = u16_at(bytes, 2).ok_or_else(truncated)?;
    if version != 3 && version != 4 {
        return Err(error(
            path,
            format!("file version {version} is not supported (versions 3 and 4 are)"),
        ));
    }
    let start = if shape_index == 0 {
        0
    } else {
        let count = u32_at(bytes, bytes.len().checked_sub(4).ok_or_else(truncated)?)
            .ok_or_else(truncated)? as usize;
        if shape_index >= count {
            return Err(error(
                path,
                format!(
                    "shape_index {shape_index} is out of range (the file holds {count} meshes)"
                ),
            ));
        }
        let offset = if version == 4 {
            let at = bytes
                .len()
                .checked_sub(8 * (count - shape_index) + 4)
                .ok_or_else(truncated)?;
            usize::try_from(u64_at(bytes, at).ok_or_else(truncated)?).map_err(|_| truncated())?
        } else {
            let at = bytes
                .len()
                .checked_sub(4 * (count - shape_index + 1))
                .ok_or_else(truncated)?;
            u32_at(bytes, at).ok_or_else(truncated)? as usize
        };
        if u16_at(bytes, offset) != Some(MAGIC) {
            return Err(error(
                path,
                format!(
                    "mesh {shape_index} does not start with the magic number at its offset {offset}"
                ),
            ));
        }
        offset
    };
    let compressed = bytes.get(start + 4..).ok_or_else(truncated)?;
    let mut z = Stream {
        inner: flate2::read::ZlibDecoder::new(compressed),
        path,
    };
    let flags = z.u32()?;
    if version == 4 {
        // The mesh name, NUL-terminated.
        let mut len = 0usize;
        while z.u8()? != 0 {
            len += 1;
            if len > 1 << 16 {
                return Err(error(path, "mesh name is not terminated"));
            }
        }
    }
    let vertex_count = z.u64()?;
    let face_count = z.u64()?;
    // Every vertex needs at least 12 bytes and every face 12; a zlib stream expands at most
    // about 1032 times, which bounds what a file of this size can really hold.
    let budget = (compressed.len() as u64).saturating_mul(1100);
    if vertex_count
        .saturating_mul(12)
        .saturating_add(face_count.saturating_mul(12))
        > budget
    {
        return Err(error(
            path,
            format!(
                "mesh {shape_index} declares {vertex_count} vertices and {face_count} faces, more than the file can hold"
            ),
        ));
    }
    let (vertex_count, face_count) = (vertex_count as usize, face_count as usize);
    let double = flags & DOUBLE_PRECISION != 0;
    let positions = z.vec3s(vertex_count, double)?;
    let normals = if flags & HAS_NORMALS != 0 {
        Some(z.vec3s(vertex_count, double)?)
    } else {
        None
    };
    // Mitsuba reads these texture coordinates as they are (no flip), with v = 0 at the image's
    // top row: fppm's convention.
    let uvs = if flags & HAS_TEXCOORDS != 0 {
        Some(z.vec2s(vertex_count, double)?)
    } else {
        None
    };
    if flags & HAS_COLORS != 0 {
        z.skip(vertex_count * 3 * if double { 8 } else { 4 })?;
    }
    let mut indices = Vec::with_capacity(face_count);
    for _ in 0..face_count {
        indices.push([z.u32()?, z.u32()?, z.u32()?]);
    }
    let mesh = IndexedMesh {
        positions,
        normals,
        uvs,
        indices,
    };
    mesh.check_indices()
        .map_err(|m| error(path, format!("mesh {shape_index}: {m}")))?;
    Ok(mesh)
}

struct Stream<'a, R> {
    inner: R,
    path: &'a Path,
}

impl<R: Read> Stream<'_, R> {
    fn bytes<const N: usize>(&mut self) -> Result<[u8; N], LoadError> {
        let mut b = [0u8; N];
        self.inner.read_exact(&mut b).map_err(|e| {
            error(
                self.path,
                format!("compressed mesh data ends early or is corrupt: {e}"),
            )
        })?;
        Ok(b)
    }
    fn u8(&mut self) -> Result<u8, LoadError> {
        Ok(self.bytes::<1>()?[0])
    }
    fn u32(&mut self) -> Result<u32, LoadError> {
        Ok(u32::from_le_bytes(self.bytes()?))
    }
    fn u64(&mut self) -> Result<u64, LoadError> {
        Ok(u64::from_le_bytes(self.bytes()?))
    }
    fn float(&mut self, double: bool) -> Result<f32, LoadError> {
        Ok(if double {
            f64::from_le_bytes(self.bytes()?) as f32
        } else {
            f32::from_le_bytes(self.bytes()?)
        })
    }
    fn vec3s(&mut self, n: usize, double: bool) -> Result<Vec<Vec3>, LoadError> {
        let mut out = Vec::with_capacity(n.min(1 << 24));
        for _ in 0..n {
            out.push(Vec3::new(
                self.float(double)?,
                self.float(double)?,
                self.float(double)?,
            ));
        }
        Ok(out)
    }
    fn vec2s(&mut self, n: usize, double: bool) -> Result<Vec<glam::Vec2>, LoadError> {
        let mut out = Vec::with_capacity(n.min(1 << 24));
        for _ in 0..n {
            out.push(glam::Vec2::new(self.float(double)?, self.float(double)?));
        }
        Ok(out)
    }
    fn skip(&mut self, n: usize) -> Result<(), LoadError> {
        let copied = std::io::copy(&mut (&mut self.inner).take(n as u64), &mut std::io::sink())
            .map_err(|e| error(self.path, format!("compressed mesh data is corrupt: {e}")))?;
        if copied == n as u64 {
            Ok(())
        } else {
            Err(error(self.path, "compressed mesh data ends early"))
        }
    }
}
