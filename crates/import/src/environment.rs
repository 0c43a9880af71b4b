//! Environment maps from files: equirectangular OpenEXR and Radiance HDR images (`--env`, the
//! TOML `[environment]`, Mitsuba's `envmap`) and pbrt-v4's square equal-area maps, decoded and
//! checked into the runtime's [`EnvironmentMap`].

use std::path::Path;
use std::sync::Arc;

use glam::{Mat3, Vec3};
use scene::{Environment, EnvironmentMap, EnvironmentRadiance, luminance};

use crate::error::LoadError;

/// Reads an equirectangular map from an OpenEXR (`.exr`) or Radiance (`.hdr`) file.
/// Negative texels (filter ringing in some tools) become zero; the count of them is returned
/// for a warning.
///
/// # Errors
/// [`LoadError::Io`] when the file cannot be read, [`LoadError::EnvironmentMap`] when it has
/// another extension, cannot be decoded, has zero size, is not 2:1, holds a NaN or infinite
/// texel, or is black everywhere.
pub fn load_environment_map(path: &Path) -> Result<(EnvironmentMap, usize), LoadError> {
    read(path, false)
}

/// Reads a square equal-area octahedral map (pbrt-v4's `infinite` light, `.exr` or `.hdr`)
/// and resamples it into an equirectangular map ([`EnvironmentMap::from_equal_area`]), whose
/// frame is pbrt's light frame with its x axis negated when `mirror_x` (for a light transform
/// with a reflection: see `pbrt/build.rs`).
///
/// # Errors
/// As [`load_environment_map`], with "not square" in place of "not 2:1".
pub(crate) fn load_equal_area(
    path: &Path,
    mirror_x: bool,
) -> Result<(EnvironmentMap, usize), LoadError> {
    let (square, negative) = read(path, true)?;
    Ok((
        EnvironmentMap::from_equal_area(square.path, square.width, &square.texels, mirror_x),
        negative,
    ))
}

/// The environment of `file` (`.exr` or `.hdr`), unscaled and unrotated, with the count of
/// negative texels set to zero.
///
/// # Errors
/// As [`load_environment_map`].
pub fn environment_from_file(path: &Path) -> Result<(Environment, usize), LoadError> {
    let (map, negative) = load_environment_map(path)?;
    Ok((
        Environment {
            radiance: EnvironmentRadiance::Map(Arc::new(map)),
            scale: 1.0,
            to_world: Mat3::IDENTITY,
        },
        negative,
    ))
}

/// Decodes `path` and checks it: 2:1, or square when `square`.
fn read(path: &Path, square: bool) -> Result<(EnvironmentMap, usize), LoadError> {
    let bad = |message: String| LoadError::EnvironmentMap {
        path: path.to_path_buf(),
        message,
    };
    let extension = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    let format = match extension.as_str() {
        "exr" => image::ImageFormat::OpenExr,
        "hdr" => image::ImageFormat::Hdr,
        _ => {
            return Err(bad(format!(
                "unsupported image format {extension:?} (expected .exr or .hdr)"
            )));
        }
    };
    let bytes = crate::read_bytes(path)?;
    let cannot_decode = |e: String| {
        bad(format!(
            "cannot decode image: {}",
            crate::error::lower_first(&e)
        ))
    };
    // The size the header declares is checked before anything is decoded: a file of a few
    // hundred bytes can declare a billion texels.
    // `image` reports an EXR's display window, so the data windows (what is decoded) are
    // read with `exr`.
    if format == image::ImageFormat::OpenExr {
        let meta = exr::meta::MetaData::read_from_buffered(std::io::Cursor::new(&bytes), false)
            .map_err(|e| cannot_decode(e.to_string()))?;
        for header in &meta.headers {
            let size = header.layer_size;
            let (w, h) = (
                u32::try_from(size.0).unwrap_or(u32::MAX),
                u32::try_from(size.1).unwrap_or(u32::MAX),
            );
            check_size(w, h, square).map_err(bad)?;
        }
        crate::image_file::check_exr_header(&bytes, MAX_MAP_TEXELS).map_err(bad)?;
    }
    let (width, height) = image::ImageReader::with_format(std::io::Cursor::new(&bytes), format)
        .into_dimensions()
        .map_err(|e| cannot_decode(e.to_string()))?;
    check_size(width, height, square).map_err(bad)?;
    if format == image::ImageFormat::Hdr {
        crate::image_file::check_hdr_size(&bytes, width, height).map_err(bad)?;
    }
    let (width, height, rgb) = decode_hdr_image(&bytes, format).map_err(cannot_decode)?;
    drop(bytes);
    check_size(width, height, square).map_err(bad)?;
    // The decoded floats become the texels in place (a map may hold 64 M texels: a copy
    // would double the peak memory).
    let mut texels: Vec<Vec3> = bytemuck::allocation::try_cast_vec(rgb)
        .unwrap_or_else(|(_, rgb)| rgb.chunks_exact(3).map(Vec3::from_slice).collect());
    let mut negative = 0;
    for (i, texel) in texels.iter_mut().enumerate() {
        let t = *texel;
        if !t.is_finite() {
            let (x, y) = (i as u32 % width, i as u32 / width);
            return Err(bad(format!(
                "texel ({x}, {y}) is not finite ({}, {}, {})",
                t.x, t.y, t.z
            )));
        }
        if t.cmplt(Vec3::ZERO).any() {
            negative += 1;
        }
        *texel = t.max(Vec3::ZERO);
    }
    if texels.iter().all(|&t| luminance(t) <= 0.0) {
        return Err(bad(
            "every texel is black: the environment emits nothing".into()
        ));
    }
    Ok((
        EnvironmentMap {
            path: path.to_path_buf(),
            width,
            height,
            texels,
        },
        negative,
    ))
}

/// Whether a map of `width` × `height` texels can be used: not empty, 2:1 (square when
/// `square`), and at most [`MAX_MAP_TEXELS`] texels once resampled (a square map of side n
/// becomes 4n × 2n).
fn check_size(width: u32, height: u32, square: bool) -> Result<(), String> {
    if width == 0 || height == 0 {
        return Err(format!("image has zero size ({width}×{height})"));
    }
    if !(if square {
        width == height
    } else {
        width == 2 * height
    }) {
        return Err(if square {
            format!("image is {width}×{height}, not square (an equal-area octahedral map)")
        } else {
            format!(
                "image is {width}×{height}, not 2:1 (an equirectangular map is twice as wide as high)"
            )
        });
    }
    let texels = u64::from(width) * u64::from(height) * if square { 8 } else { 1 };
    if texels > MAX_MAP_TEXELS {
        return Err(format!(
            "image of {width}×{height} texels is larger than the {MAX_MAP_TEXELS} texels accepted{}",
            if square {
                " once resampled to 4n × 2n"
            } else {
                ""
            }
        ));
    }
    Ok(())
}

/// Largest environment map accepted, in texels (the image textures' bound: 8192 × 8192).
const MAX_MAP_TEXELS: u64 = 64 << 20;

/// Decodes an HDR image file into linear RGB floats (width, height, 3 values per texel).
/// The one place this module touches an image decoder.
fn decode_hdr_image(
    bytes: &[u8],
    format: image::ImageFormat,
) -> Result<(u32, u32, Vec<f32>), String> {
    let image = image::load_from_memory_with_format(bytes, format).map_err(|e| e.to_string())?;
    let rgb = image.into_rgb32f();
    Ok((rgb.width(), rgb.height(), rgb.into_raw()))
}
