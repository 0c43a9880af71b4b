//! Mitsuba's binary volume grid files (`.vol`, the format of Mitsuba 0.6 and 3's `gridvolume`),
//! read as one density per voxel for a heterogeneous medium's grid (`docs/media.md`).
//!
//! Layout (little-endian): the bytes `V`, `O`, `L`, the version byte 3, an `i32` encoding (1:
//! `f32` values, the only one Mitsuba defines), `i32` resolutions x, y, z, an `i32` channel
//! count, six `f32` of the data's box (xmin, ymin, zmin, xmax, ymax, zmax), then the values,
//! `data[((z·yres + y)·xres + x)·channels + c]`. Only one channel is read (a density or a scalar
//! extinction); the dimensions are checked against [`scene::MAX_GRID_VOXELS`] and the file's
//! size before anything is allocated.

use std::path::Path;

use glam::Vec3;
use scene::{GridError, check_grid_size};

use super::read_bytes;
use crate::error::LoadError;

/// Bytes before the values.
const HEADER_BYTES: usize = 48;

/// The contents of a `.vol` file.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct VolGrid {
    /// Voxels along x, y and z.
    pub(crate) size: [u32; 3],
    /// One value per voxel, x fastest (checked finite and non-negative).
    pub(crate) data: Vec<f32>,
    /// The box the file states (Mitsuba ignores it unless `use_grid_bbox` is set).
    pub(crate) min: Vec3,
    /// Its far corner.
    pub(crate) max: Vec3,
}

/// The error of a grid read from `path`.
pub(crate) fn vol_error(path: &Path, message: impl std::fmt::Display) -> LoadError {
    LoadError::VolumeFile {
        path: path.to_path_buf(),
        message: message.to_string(),
    }
}

/// Reads and checks the `.vol` file `path`.
pub(crate) fn load_vol(path: &Path) -> Result<VolGrid, LoadError> {
    let bytes = read_bytes(path)?;
    parse_vol(&bytes).map_err(|message| vol_error(path, message))
}

/// Parses a `.vol` file's bytes; the error is one line without the file's name.
pub(crate) fn parse_vol(bytes: &[u8]) -> Result<VolGrid, String> {
    if bytes.len() < HEADER_BYTES {
        return Err(format!(
            "{} bytes is shorter than the {HEADER_BYTES}-byte header",
            bytes.len()
        ));
    }
    if &bytes[..3] != b"VOL" {
        return Err("does not start with \"VOL\"".into());
    }
    if bytes[3] != 3 {
        return Err(format!("version {} is not supported (only 3)", bytes[3]));
    }
    let word = |i: usize| -> [u8; 4] {
        let at = 4 + 4 * i;
        [bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]]
    };
    let int = |i: usize| i32::from_le_bytes(word(i));
    let float = |i: usize| f32::from_le_bytes(word(i));
    let encoding = int(0);
    if encoding != 1 {
        return Err(format!(
            "encoding {encoding} is not supported (only 1, 32-bit floats)"
        ));
    }
    let (xres, yres, zres, channels) = (int(1), int(2), int(3), int(4));
    if xres < 0 || yres < 0 || zres < 0 {
        return Err(format!("negative resolution {xres}x{yres}x{zres}"));
    }
    let voxels = check_grid_size(xres as u64, yres as u64, zres as u64)
        .map_err(|e: GridError| e.to_string())?;
    if channels != 1 {
        return Err(format!(
            "{channels} channels: only one-channel (density) grids are supported"
        ));
    }
    let expected = HEADER_BYTES as u64 + voxels as u64 * 4;
    if bytes.len() as u64 != expected {
        return Err(format!(
            "the header's {xres}x{yres}x{zres} grid of 1 channel needs {expected} bytes, the file has {}",
            bytes.len()
        ));
    }
    let min = Vec3::new(float(5), float(6), float(7));
    let max = Vec3::new(float(8), float(9), float(10));
    let mut data = Vec::with_capacity(voxels);
    for (index, chunk) in bytes[HEADER_BYTES..].chunks_exact(4).enumerate() {
        let value = f32::from_le_bytes([chunk[0], chunk[1], chunk[2], chunk[3]]);
        if !(value.is_finite() && value >= 0.0) {
            return Err(format!(
                "density value {index} is {value} (densities must be finite and >= 0)"
            ));
        }
        data.push(value);
    }
    Ok(VolGrid {
        size: [xres as u32, yres as u32, zres as u32],
        data,
        min,
        max,
    })
}

/// The bytes of a one-channel `.vol` file (for tests and for exporting grids to Mitsuba).
#[must_use]
pub fn write_vol(size: [u32; 3], min: Vec3, max: Vec3, data: &[f32]) -> Vec<u8> {
    let mut out = Vec::with_capacity(HEADER_BYTES + 4 * data.len());
    out.extend_from_slice(b"VOL");
    out.push(3);
    for v in [1, size[0] as i32, size[1] as i32, size[2] as i32, 1] {
        out.extend_from_slice(&v.to_le_bytes());
    }
    for v in min.to_array().into_iter().chain(max.to_array()) {
        out.extend_from_slice(&v.to_le_bytes());
    }
    for v in data {
        out.extend_from_slice(&v.to_le_bytes());
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip() {
        let data: Vec<f32> = (0..24).map(|i| i as f32 * 0.5).collect();
        let bytes = write_vol([2, 3, 4], Vec3::ZERO, Vec3::new(1.0, 2.0, 3.0), &data);
        let grid = parse_vol(&bytes).unwrap();
        assert_eq!(grid.size, [2, 3, 4]);
        assert_eq!(grid.data, data);
        assert_eq!(grid.max, Vec3::new(1.0, 2.0, 3.0));
    }

    #[test]
    fn bad_files_are_refused_in_one_line() {
        let good = write_vol([2, 2, 2], Vec3::ZERO, Vec3::ONE, &[1.0; 8]);
        let cases: Vec<(Vec<u8>, &str)> = vec![
            (good[..40].to_vec(), "shorter than"),
            (
                good[..good.len() - 4].to_vec(),
                "needs 80 bytes, the file has 76",
            ),
            ([good.clone(), vec![0; 4]].concat(), "the file has 84"),
            (
                write_vol(
                    [2, 2, 2],
                    Vec3::ZERO,
                    Vec3::ONE,
                    &[1.0, -1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0],
                ),
                "density value 1 is -1",
            ),
            (
                write_vol([1, 1, 1], Vec3::ZERO, Vec3::ONE, &[f32::NAN]),
                "density value 0 is NaN",
            ),
            (
                write_vol([0, 2, 2], Vec3::ZERO, Vec3::ONE, &[]),
                "zero dimension",
            ),
            (
                write_vol([100_000, 100_000, 100_000], Vec3::ZERO, Vec3::ONE, &[]),
                "exceeds the limit",
            ),
            ([b"VOX".as_slice(), &good[3..]].concat(), "does not start"),
        ];
        for (bytes, expected) in cases {
            let message = parse_vol(&bytes).unwrap_err();
            assert!(message.contains(expected), "{message:?} lacks {expected:?}");
            assert!(!message.contains('\n'));
        }
        let mut three = good.clone();
        three[20] = 3;
        assert!(parse_vol(&three).unwrap_err().contains("3 channels"));
        let mut version = good;
        version[3] = 2;
        assert!(parse_vol(&version).unwrap_err().contains("version 2"));
    }
}
