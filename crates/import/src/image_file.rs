//! Reading image files into the runtime's [`Image`]s, once per file, and the size checks of
//! image headers that come before any decoding.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use image::{DynamicImage, ImageFormat, ImageReader};

use crate::error::LoadError;
use scene::texture::{Image, Texels};

/// Largest image accepted, in texels (a 8192 × 8192 image).
pub(crate) const MAX_TEXELS: u64 = 64 << 20;

/// The images a loader has read, by file: a texture used by several materials (or twice by
/// one) is decoded once and shared.
#[derive(Debug, Default)]
pub(crate) struct TextureCache {
    images: HashMap<PathBuf, Arc<Image>>,
}

/// The error naming `path`, its message on one line (decoders' messages may span several).
fn texture_error(path: &Path, message: impl Into<String>) -> LoadError {
    let message: String = message.into();
    LoadError::Texture {
        path: path.to_path_buf(),
        message: message
            .lines()
            .map(str::trim)
            .filter(|l| !l.is_empty())
            .collect::<Vec<_>>()
            .join("; "),
    }
}

impl TextureCache {
    /// The image in file `path`, read and decoded on first use.
    ///
    /// # Errors
    /// [`LoadError::Texture`] naming the file when it is missing, unreadable, of an unsupported
    /// format, corrupt, empty, too large or has NaN or infinite texels.
    pub(crate) fn load(&mut self, path: &Path) -> Result<Arc<Image>, LoadError> {
        if let Some(image) = self.images.get(path) {
            return Ok(Arc::clone(image));
        }
        // Through the loader's file source, so that scenes loaded from memory
        // (`import::load_from`) find their textures there too.
        let bytes = crate::files::read(path).map_err(|e| {
            texture_error(
                path,
                format!(
                    "cannot read texture: {}",
                    crate::error::lower_first(&e.to_string())
                ),
            )
        })?;
        let image = Arc::new(decode(path, &bytes)?);
        self.images.insert(path.to_path_buf(), Arc::clone(&image));
        Ok(image)
    }

    /// An image held in memory (a glTF buffer view), decoded once under the name `key`.
    ///
    /// # Errors
    /// As [`TextureCache::load`], naming `key`.
    pub(crate) fn load_bytes(&mut self, key: &Path, bytes: &[u8]) -> Result<Arc<Image>, LoadError> {
        if let Some(image) = self.images.get(key) {
            return Ok(Arc::clone(image));
        }
        let image = Arc::new(decode(key, bytes)?);
        self.images.insert(key.to_path_buf(), Arc::clone(&image));
        Ok(image)
    }
}

/// Largest ratio of pixel data to file size an EXR can have (as `film`'s EXR reader bounds it:
/// deflate expands at most 1032 times, RLE 64 times, B44 is fixed-rate).
const MAX_EXR_COMPRESSION_RATIO: u64 = 2048;

/// Checks an EXR's headers before `image` decodes it: `image` allocates the display window and
/// decodes the data windows, either of which a file of a few hundred bytes can declare a billion texels
/// large. Each window must hold at most `max_texels` texels, and no more sample bytes (and
/// no more texels) than the file's size allows at the largest compression ratio of EXR.
pub(crate) fn check_exr_header(bytes: &[u8], max_texels: u64) -> Result<(), String> {
    let meta = exr::meta::MetaData::read_from_buffered(std::io::Cursor::new(bytes), false)
        .map_err(|e| {
            format!(
                "corrupt exr image: {}",
                crate::error::lower_first(&e.to_string())
            )
        })?;
    for header in &meta.headers {
        let (w, h) = (header.layer_size.0 as u64, header.layer_size.1 as u64);
        let display = header.shared_attributes.display_window.size;
        for (w, h) in [(w, h), (display.0 as u64, display.1 as u64)] {
            if w * h > max_texels {
                return Err(format!(
                    "image of {w}x{h} texels is larger than the {max_texels} accepted"
                ));
            }
        }
        let samples: u64 = header.channels.list.iter().fold(0, |sum, c| {
            let n = (w / c.sampling.0.max(1) as u64) * (h / c.sampling.1.max(1) as u64);
            sum.saturating_add(n.saturating_mul(c.sample_type.bytes_per_sample() as u64))
        });
        // Subsampled channels hold fewer samples, but `image` decodes every texel of the
        // window: at least one byte each counts too.
        let display = header.shared_attributes.display_window.size;
        let samples = samples.max(w * h).max(display.0 as u64 * display.1 as u64);
        if samples / MAX_EXR_COMPRESSION_RATIO > bytes.len() as u64 {
            return Err(format!(
                "its header declares a {w}x{h} image ({samples} bytes of samples), more than a {}-byte file can hold",
                bytes.len()
            ));
        }
    }
    Ok(())
}

/// Checks a Radiance HDR's declared size against its file's: every scanline takes at least 4
/// bytes (one RGBE texel, then run-length markers), so a file of n bytes holds at most n / 4
/// scanlines. `image` allocates the whole image before it reads the first scanline, and a
/// header of a few dozen bytes can declare 64 M texels.
pub(crate) fn check_hdr_size(bytes: &[u8], width: u32, height: u32) -> Result<(), String> {
    if u64::from(height) * 4 > bytes.len() as u64 {
        return Err(format!(
            "its header declares a {width}x{height} image, more scanlines than a {}-byte file can hold",
            bytes.len()
        ));
    }
    Ok(())
}

/// Decodes an image file's bytes (PNG, JPEG, EXR, Radiance HDR, told apart by their contents).
pub(crate) fn decode(path: &Path, bytes: &[u8]) -> Result<Image, LoadError> {
    let reader = ImageReader::new(std::io::Cursor::new(bytes))
        .with_guessed_format()
        .map_err(|e| texture_error(path, format!("cannot read texture: {e}")))?;
    let format = match reader.format() {
        Some(
            f @ (ImageFormat::Png | ImageFormat::Jpeg | ImageFormat::OpenExr | ImageFormat::Hdr),
        ) => f,
        Some(other) => {
            return Err(texture_error(
                path,
                format!(
                    "unsupported texture format {} (expected png, jpeg, exr or hdr)",
                    other.extensions_str().first().copied().unwrap_or("?")
                ),
            ));
        }
        None => {
            return Err(texture_error(
                path,
                "unsupported texture format: not a png, jpeg, exr or hdr image",
            ));
        }
    };
    let corrupt = |e: image::ImageError| {
        texture_error(
            path,
            format!(
                "corrupt {} texture: {}",
                format.extensions_str().first().copied().unwrap_or("image"),
                crate::error::lower_first(&e.to_string())
            ),
        )
    };
    if format == ImageFormat::OpenExr {
        check_exr_header(bytes, MAX_TEXELS).map_err(|e| texture_error(path, e))?;
    }
    let (width, height) = reader.into_dimensions().map_err(corrupt)?;
    if format == ImageFormat::Hdr {
        check_hdr_size(bytes, width, height).map_err(|e| texture_error(path, e))?;
    }
    if width == 0 || height == 0 {
        return Err(texture_error(
            path,
            format!("texture has zero size ({width}x{height})"),
        ));
    }
    if u64::from(width) * u64::from(height) > MAX_TEXELS {
        return Err(texture_error(
            path,
            format!("texture of {width}x{height} texels is larger than the {MAX_TEXELS} accepted"),
        ));
    }
    let img = image::load_from_memory_with_format(bytes, format).map_err(corrupt)?;
    from_dynamic(path, img)
}

/// An [`Image`] from decoded pixels: 8-bit images keep their bytes, float images become linear
/// RGBA floats (checked for NaN and infinities by [`Image::new`]).
pub(crate) fn from_dynamic(path: &Path, img: DynamicImage) -> Result<Image, LoadError> {
    let (width, height) = (img.width(), img.height());
    let alpha_channel = img.color().has_alpha();
    let float = matches!(
        img,
        DynamicImage::ImageRgb32F(_) | DynamicImage::ImageRgba32F(_)
    );
    let texels = if float {
        Texels::Floats(img.into_rgba32f().pixels().map(|p| p.0).collect())
    } else {
        Texels::Bytes(img.into_rgba8().pixels().map(|p| p.0).collect())
    };
    Image::new(path.to_path_buf(), width, height, texels, alpha_channel)
        .map_err(|e| texture_error(path, e.to_string()))
}
