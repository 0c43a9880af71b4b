//! EXR and PNG files, written atomically.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use exr::prelude::{
    AnyChannel, AnyChannels, AttributeValue, Encoding, FlatSamples, Layer, LayerAttributes,
    ReadChannels, ReadLayers, SmallVec, Text, WritableImage,
};

use crate::{FilmError, Image, Tonemap, lower_first};

/// An image with its auxiliary channels and metadata, ready to be written as an EXR.
#[derive(Clone, Debug, PartialEq)]
pub struct Frame {
    /// The R, G and B channels.
    pub image: Image,
    /// `(channel name, width × height values)`.
    pub channels: Vec<(&'static str, Vec<f32>)>,
    /// `(key, value)` pairs stored as EXR text attributes under `fppm.<key>`.
    pub metadata: Vec<(String, String)>,
}

impl Frame {
    /// `image` alone, without auxiliary channels or metadata.
    #[must_use]
    pub fn new(image: Image) -> Self {
        Self {
            image,
            channels: Vec::new(),
            metadata: Vec::new(),
        }
    }

    /// Adds an interleaved auxiliary image (`width × height × names.len()` values) as one
    /// channel per name.
    pub fn add_aov(&mut self, names: &'static [&'static str], values: &[f32]) {
        let n = names.len();
        for (c, name) in names.iter().enumerate() {
            let plane = values.iter().skip(c).step_by(n).copied().collect();
            self.channels.push((name, plane));
        }
    }
}

/// The temporary sibling `name.tmp-<pid>` a file is written to before the rename.
fn temporary_path(path: &Path) -> PathBuf {
    let mut name = path
        .file_name()
        .map(|n| n.to_os_string())
        .unwrap_or_default();
    name.push(format!(".tmp-{}", std::process::id()));
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.join(name),
        _ => PathBuf::from(name),
    }
}

/// Checks that `path` can be written, before the work that produces it: a file can be
/// created beside it (and is removed again).
///
/// # Errors
///
/// [`FilmError::Write`] if no file can be created in its directory.
pub fn check_writable(path: &Path) -> Result<(), FilmError> {
    let probe = temporary_path(path);
    match File::create(&probe) {
        Ok(_) => {
            let _ = std::fs::remove_file(&probe);
            Ok(())
        }
        Err(e) => Err(FilmError::Write {
            path: path.to_path_buf(),
            message: format!(
                "cannot create a file in its directory: {}",
                lower_first(&e.to_string())
            ),
        }),
    }
}

/// Writes a file atomically: `write` fills a temporary sibling, which is then renamed over
/// `path`, so that a killed process never leaves a truncated file.
///
/// # Errors
///
/// [`FilmError::Write`] if the file cannot be created, written or renamed.
pub fn write_atomically(
    path: &Path,
    write: impl FnOnce(&mut BufWriter<File>) -> Result<(), String>,
) -> Result<(), FilmError> {
    let temporary = temporary_path(path);
    let result = (|| -> Result<(), String> {
        let file = File::create(&temporary).map_err(|e| {
            format!(
                "cannot create {}: {}",
                temporary.display(),
                lower_first(&e.to_string())
            )
        })?;
        let mut writer = BufWriter::new(file);
        write(&mut writer)?;
        let io = |e: std::io::Error| lower_first(&e.to_string());
        writer.flush().map_err(io)?;
        let file = writer.into_inner().map_err(|e| io(e.into_error()))?;
        file.sync_all().map_err(io)?;
        std::fs::rename(&temporary, path).map_err(io)?;
        Ok(())
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&temporary);
    }
    result.map_err(|message| FilmError::Write {
        path: path.to_path_buf(),
        message,
    })
}

/// Writes the EXR: one layer with channels R, G, B and the auxiliary channels, 32-bit float,
/// ZIP-compressed, with the metadata as text attributes.
///
/// # Errors
///
/// [`FilmError::Write`] if the file cannot be written.
pub fn write_exr(path: &Path, frame: &Frame) -> Result<(), FilmError> {
    let mut list: SmallVec<[AnyChannel<FlatSamples>; 4]> = SmallVec::new();
    for (c, name) in ["R", "G", "B"].into_iter().enumerate() {
        let plane = frame.image.pixels.iter().map(|p| p[c]).collect();
        list.push(AnyChannel::new(name, FlatSamples::F32(plane)));
    }
    for (name, plane) in &frame.channels {
        list.push(AnyChannel::new(*name, FlatSamples::F32(plane.clone())));
    }
    let mut attributes = LayerAttributes::named("");
    attributes.layer_name = None;
    attributes.owner = None;
    attributes.software_name = Some(Text::from("fppm"));
    for (key, value) in &frame.metadata {
        attributes.other.insert(
            latin1(&format!("fppm.{key}")),
            AttributeValue::Text(latin1(value)),
        );
    }
    let layer = Layer::new(
        (frame.image.width, frame.image.height),
        attributes,
        Encoding::SMALL_LOSSLESS,
        AnyChannels::sort(list),
    );
    let image = exr::image::Image::from_layer(layer);
    write_atomically(path, |w| {
        // Not exr's own thread pool: the caller may run inside a rayon pool of a chosen size.
        image
            .write()
            .non_parallel()
            .to_buffered(&mut *w)
            .map_err(|e| lower_first(&e.to_string()))
    })
}

/// Reads the R, G and B channels of an EXR's first layer.
///
/// # Errors
///
/// [`FilmError::Read`] if the file is not a readable EXR, [`FilmError::MissingChannel`] if it
/// lacks R, G or B.
pub fn read_exr(path: &Path) -> Result<Image, FilmError> {
    let io_error = |e: std::io::Error| FilmError::Read {
        path: path.to_path_buf(),
        message: lower_first(&e.to_string()),
    };
    let file = std::fs::File::open(path).map_err(io_error)?;
    let length = file.metadata().map_err(io_error)?.len();
    read_exr_from(std::io::BufReader::new(file), length, path)
}

/// Reads an EXR held in memory like [`read_exr`]; errors name `path`.
///
/// # Errors
///
/// As [`read_exr`].
pub fn read_exr_bytes(bytes: &[u8], path: &Path) -> Result<Image, FilmError> {
    read_exr_from(std::io::Cursor::new(bytes), bytes.len() as u64, path)
}

/// Largest ratio of pixel data to file size an EXR can have. Deflate (ZIP, PXR24, DWA)
/// expands at most 1032 times; PIZ's Huffman code with its run-length symbol less than that;
/// RLE at most 64 times; B44 is fixed-rate. A header that declares more pixel data than this
/// allows for the file's size is refused before anything is allocated for it.
const MAX_COMPRESSION_RATIO: u64 = 2048;

/// Checks the image sizes an EXR's headers declare against the file's length (`length`
/// bytes), then rewinds `reader`.
fn check_declared_size(
    mut reader: impl std::io::Read + std::io::Seek,
    length: u64,
    path: &Path,
) -> Result<(), FilmError> {
    let read_error = |message: String| FilmError::Read {
        path: path.to_path_buf(),
        message,
    };
    let meta = exr::meta::MetaData::read_from_buffered(&mut reader, false)
        .map_err(|e| read_error(lower_first(&e.to_string())))?;
    for header in &meta.headers {
        let size = header.layer_size;
        let bytes = header.channels.list.iter().fold(0u64, |sum, c| {
            let samples =
                (size.0 / c.sampling.0.max(1)) as u64 * (size.1 / c.sampling.1.max(1)) as u64;
            sum.saturating_add(samples.saturating_mul(c.sample_type.bytes_per_sample() as u64))
        });
        if bytes / MAX_COMPRESSION_RATIO > length {
            return Err(read_error(format!(
                "its header declares a {} × {} image ({bytes} bytes of samples), more than a {length}-byte file can hold",
                size.0, size.1
            )));
        }
    }
    reader
        .seek(std::io::SeekFrom::Start(0))
        .map_err(|e| read_error(lower_first(&e.to_string())))?;
    Ok(())
}

fn read_exr_from(
    mut reader: impl std::io::Read + std::io::Seek + Send,
    length: u64,
    path: &Path,
) -> Result<Image, FilmError> {
    check_declared_size(&mut reader, length, path)?;
    let image = exr::prelude::read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .non_parallel()
        .from_buffered(reader)
        .map_err(|e| FilmError::Read {
            path: path.to_path_buf(),
            message: lower_first(&e.to_string()),
        })?;
    let layer = &image.layer_data;
    let size = layer.size;
    let channel = |name: &'static str| {
        layer
            .channel_data
            .list
            .iter()
            .find(|c| c.name.to_string() == name)
            .map(|c| c.sample_data.values_as_f32().collect::<Vec<f32>>())
            .ok_or_else(|| FilmError::MissingChannel {
                path: path.to_path_buf(),
                channel: name,
            })
    };
    let (r, g, b) = (channel("R")?, channel("G")?, channel("B")?);
    if [&r, &g, &b].iter().any(|c| c.len() != size.0 * size.1) {
        return Err(FilmError::Read {
            path: path.to_path_buf(),
            message: "its R, G or B channel is subsampled (one sample per pixel is needed)"
                .to_owned(),
        });
    }
    let pixels = (0..size.0 * size.1).map(|i| [r[i], g[i], b[i]]).collect();
    Ok(Image::new(size.0, size.1, pixels))
}

/// Writes an 8-bit RGB PNG of `width × height` pixels (`rgb8`, three bytes a pixel).
///
/// # Errors
///
/// [`FilmError::Write`] if the file cannot be written.
///
/// # Panics
///
/// If `rgb8` does not hold `width × height` pixels.
pub fn write_png(path: &Path, width: usize, height: usize, rgb8: Vec<u8>) -> Result<(), FilmError> {
    let image = image::RgbImage::from_raw(width as u32, height as u32, rgb8)
        .expect("the PNG buffer holds width x height pixels");
    write_atomically(path, |w| {
        image
            .write_to(w, image::ImageFormat::Png)
            .map_err(|e| lower_first(&e.to_string()))
    })
}

/// The tone-mapped 8-bit RGB PNG of `image`, in memory, with fast compression: what a live
/// view sends many times during a render rather than a file kept afterwards.
///
/// # Panics
///
/// If the image is wider or taller than 2³² pixels (a film cannot be).
#[must_use]
pub fn encode_png(image: &Image, tonemap: Tonemap) -> Vec<u8> {
    use image::ImageEncoder;
    let rgb8 = crate::to_srgb8(image, tonemap);
    let mut bytes = Vec::new();
    image::codecs::png::PngEncoder::new_with_quality(
        &mut bytes,
        image::codecs::png::CompressionType::Fast,
        image::codecs::png::FilterType::Sub,
    )
    .write_image(
        &rgb8,
        image.width as u32,
        image.height as u32,
        image::ExtendedColorType::Rgb8,
    )
    .expect("a PNG encodes into memory");
    bytes
}

/// Writes the tone-mapped PNG of `image`, enlarged `zoom` times (nearest neighbour) so that
/// small films are easy to look at.
///
/// # Errors
///
/// [`FilmError::Write`] if the file cannot be written.
pub fn write_preview(
    path: &Path,
    image: &Image,
    tonemap: Tonemap,
    zoom: usize,
) -> Result<(), FilmError> {
    let zoom = zoom.max(1);
    let (width, height) = (image.width * zoom, image.height * zoom);
    let mut bytes = Vec::with_capacity(width * height * 3);
    for y in 0..height {
        for x in 0..width {
            let p = image.pixels[(y / zoom) * image.width + x / zoom];
            bytes.extend(p.map(|c| tonemap.apply(c)));
        }
    }
    write_png(path, width, height, bytes)
}

/// An EXR text: Latin-1 only, other characters become `?`.
fn latin1(s: &str) -> Text {
    let cleaned: String = s
        .chars()
        .map(|c| if (c as u32) < 256 { c } else { '?' })
        .collect();
    Text::new_or_none(&cleaned).unwrap_or_else(|| Text::from("?"))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Found by the `exr` fuzz target: an 827-byte file whose data window is 771 751 939 × 2
    /// pixels made the reader allocate for all of them (11 s, gigabytes); it is refused from
    /// its header.
    #[test]
    fn exr_declaring_more_pixels_than_its_size_allows_is_refused() {
        let bytes = include_bytes!("../tests/fuzz/huge-data-window.exr");
        let path = Path::new("huge.exr");
        let err = read_exr_bytes(bytes, path).unwrap_err();
        assert!(matches!(err, FilmError::Read { .. }), "{err:?}");
        let message = err.to_string();
        assert!(
            message.contains("header declares a 771751939 × 2 image"),
            "{message}"
        );
        assert!(message.starts_with("huge.exr"), "{message}");
    }

    #[test]
    fn exr_bytes_read_as_the_file() {
        let pixels = (0..6).map(|i| [i as f32, 0.5, -2.0]).collect();
        let frame = Frame::new(Image::new(3, 2, pixels));
        let dir = std::env::temp_dir().join(format!("film-test-bytes-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("bytes.exr");
        write_exr(&path, &frame).unwrap();
        let from_bytes = read_exr_bytes(&std::fs::read(&path).unwrap(), &path).unwrap();
        assert_eq!(from_bytes.pixels, read_exr(&path).unwrap().pixels);
        assert_eq!(from_bytes.pixels, frame.image.pixels);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn exr_round_trip_is_exact() {
        let pixels = (0..12)
            .map(|i| [i as f32 * 0.25, -1.5e-3 * i as f32, 1e6 / (i + 1) as f32])
            .collect();
        let mut frame = Frame::new(Image::new(4, 3, pixels));
        frame.add_aov(&["depth"], &[2.0; 12]);
        frame
            .metadata
            .push(("method".to_owned(), "freq".to_owned()));
        let dir = std::env::temp_dir().join(format!("film-test-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("round-trip.exr");
        write_exr(&path, &frame).unwrap();
        let back = read_exr(&path).unwrap();
        let missing = read_exr(&dir.join("none.exr"));
        std::fs::remove_dir_all(&dir).unwrap();
        assert_eq!(back, frame.image);
        assert!(
            matches!(missing, Err(FilmError::Read { .. })),
            "{missing:?}"
        );
    }
}
