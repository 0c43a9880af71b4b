//! Output files: atomic writes, the EXR image with AOV channels and metadata, the PNG preview.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use anyhow::Context;
use exr::prelude::{
    AnyChannel, AnyChannels, AttributeValue, Encoding, FlatSamples, Image, Layer, LayerAttributes,
    SmallVec, Text, WritableImage,
};

use crate::args::TonemapArg;

/// The directory a file goes to (`.` for a bare file name).
fn parent_dir(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

/// The temporary sibling `name.tmp-<pid>` a file is written to before the rename.
fn temporary_path(path: &Path) -> PathBuf {
    let mut name = path
        .file_name()
        .map(|n| n.to_os_string())
        .unwrap_or_default();
    name.push(format!(".tmp-{}", std::process::id()));
    parent_dir(path).join(name)
}

/// Checks, before any rendering, that `path` can be written: its directory exists and accepts a
/// new file (created and removed again). `what` names the flag, e.g. `-o`.
pub(crate) fn check_writable(path: &Path, what: &str) -> anyhow::Result<()> {
    if path.file_name().is_none() {
        anyhow::bail!(
            "{}: {what} needs a file name, not a directory",
            path.display()
        );
    }
    if path.is_dir() {
        anyhow::bail!("{}: {what} names a directory, not a file", path.display());
    }
    let dir = parent_dir(path);
    let probe = temporary_path(path);
    match File::create(&probe) {
        Ok(_) => {
            let _ = std::fs::remove_file(&probe);
            Ok(())
        }
        Err(e) => Err(anyhow::anyhow!(
            "{}: cannot write {what} output in directory {}: {}",
            path.display(),
            dir.display(),
            lower_first(&e.to_string())
        )),
    }
}

/// Writes a file atomically: `write` fills a temporary sibling, which is then renamed over
/// `path`, so a killed process never leaves a truncated file.
pub(crate) fn write_atomically(
    path: &Path,
    write: impl FnOnce(&mut BufWriter<File>) -> anyhow::Result<()>,
) -> anyhow::Result<()> {
    let temporary = temporary_path(path);
    let result = (|| -> anyhow::Result<()> {
        let file = File::create(&temporary)
            .with_context(|| format!("{}: cannot create file", temporary.display()))?;
        let mut writer = BufWriter::new(file);
        write(&mut writer)?;
        writer.flush()?;
        let file = writer.into_inner().map_err(|e| e.into_error())?;
        file.sync_all()?;
        std::fs::rename(&temporary, path)?;
        Ok(())
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&temporary);
    }
    result.with_context(|| format!("{}: cannot write file", path.display()))
}

/// A rendered image with its auxiliary channels, ready to be written.
pub(crate) struct Frame {
    pub(crate) width: usize,
    pub(crate) height: usize,
    /// Linear RGB, row-major from the top-left.
    pub(crate) beauty: Vec<[f32; 3]>,
    /// `(channel name, width × height values)`.
    pub(crate) channels: Vec<(&'static str, Vec<f32>)>,
    /// `(key, value)` pairs stored as EXR text attributes under `fppm.<key>`.
    pub(crate) metadata: Vec<(String, String)>,
}

impl Frame {
    /// Adds an interleaved AOV (`width × height × names.len()` values) as one channel per name.
    pub(crate) fn add_aov(&mut self, names: &'static [&'static str], values: &[f32]) {
        let n = names.len();
        for (c, name) in names.iter().enumerate() {
            let plane = values.iter().skip(c).step_by(n).copied().collect();
            self.channels.push((name, plane));
        }
    }
}

/// Writes the EXR: one layer with channels R, G, B and the AOV channels, 32-bit float, ZIP.
pub(crate) fn write_exr(path: &Path, frame: &Frame) -> anyhow::Result<()> {
    let mut list: SmallVec<[AnyChannel<FlatSamples>; 4]> = SmallVec::new();
    for (c, name) in ["R", "G", "B"].into_iter().enumerate() {
        let plane = frame.beauty.iter().map(|p| p[c]).collect();
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
        (frame.width, frame.height),
        attributes,
        Encoding::SMALL_LOSSLESS,
        AnyChannels::sort(list),
    );
    let image = Image::from_layer(layer);
    write_atomically(path, |w| {
        // Not exr's own thread pool: the render may run inside a rayon pool of a chosen size.
        image.write().non_parallel().to_buffered(&mut *w)?;
        Ok(())
    })
}

/// Exposure and tone curve of the PNG preview.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Tonemap {
    /// Stops: linear values are scaled by 2^exposure.
    pub(crate) exposure: f32,
    pub(crate) curve: TonemapArg,
}

impl Tonemap {
    /// One linear channel value to an 8-bit sRGB value.
    pub(crate) fn apply(self, linear: f32) -> u8 {
        let v = if linear.is_finite() {
            linear.max(0.0)
        } else {
            0.0
        } * self.exposure.exp2();
        let mapped = match self.curve {
            TonemapArg::Srgb => v,
            TonemapArg::Filmic => aces_narkowicz(v),
        };
        (srgb_encode(mapped.clamp(0.0, 1.0)) * 255.0 + 0.5) as u8
    }
}

/// The ACES filmic curve fitted by Krzysztof Narkowicz (2015):
/// f(x) = x(2.51x + 0.03) / (x(2.43x + 0.59) + 0.14), applied per channel.
fn aces_narkowicz(x: f32) -> f32 {
    (x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14)
}

/// The sRGB transfer function (IEC 61966-2-1) of a linear value in [0, 1].
fn srgb_encode(v: f32) -> f32 {
    if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

/// Writes an 8-bit RGB PNG.
pub(crate) fn write_png(
    path: &Path,
    width: usize,
    height: usize,
    rgb8: Vec<u8>,
) -> anyhow::Result<()> {
    let image = image::RgbImage::from_raw(width as u32, height as u32, rgb8)
        .context("internal error: PNG buffer size does not match the image")?;
    write_atomically(path, |w| {
        image.write_to(w, image::ImageFormat::Png)?;
        Ok(())
    })
}

/// Writes the tone-mapped preview of linear RGB pixels.
pub(crate) fn write_preview(path: &Path, frame: &Frame, tonemap: Tonemap) -> anyhow::Result<()> {
    let bytes = frame
        .beauty
        .iter()
        .flat_map(|p| p.map(|c| tonemap.apply(c)))
        .collect();
    write_png(path, frame.width, frame.height, bytes)
}

/// An EXR's RGB channels (of its first layer), with its size.
pub(crate) struct RgbImage {
    pub(crate) width: usize,
    pub(crate) height: usize,
    pub(crate) pixels: Vec<[f32; 3]>,
}

/// Reads the R, G and B channels of an EXR's first layer.
pub(crate) fn read_exr_rgb(path: &Path) -> anyhow::Result<RgbImage> {
    use exr::prelude::{ReadChannels, ReadLayers};
    let image = exr::prelude::read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .non_parallel()
        .from_file(path)
        .map_err(|e| {
            anyhow::anyhow!(
                "{}: cannot read exr: {}",
                path.display(),
                lower_first(&e.to_string())
            )
        })?;
    let layer = &image.layer_data;
    let size = layer.size;
    let channel = |name: &str| {
        layer
            .channel_data
            .list
            .iter()
            .find(|c| c.name.to_string() == name)
            .map(|c| c.sample_data.values_as_f32().collect::<Vec<f32>>())
            .ok_or_else(|| anyhow::anyhow!("{}: exr has no {name} channel", path.display()))
    };
    let (r, g, b) = (channel("R")?, channel("G")?, channel("B")?);
    let pixels = (0..size.0 * size.1).map(|i| [r[i], g[i], b[i]]).collect();
    Ok(RgbImage {
        width: size.0,
        height: size.1,
        pixels,
    })
}

/// An EXR text: Latin-1 only, other characters become `?`.
fn latin1(s: &str) -> Text {
    let cleaned: String = s
        .chars()
        .map(|c| if (c as u32) < 256 { c } else { '?' })
        .collect();
    Text::new_or_none(&cleaned).unwrap_or_else(|| Text::from("?"))
}

/// The message with its first letter in lower case (OS messages start with a capital).
pub(crate) fn lower_first(message: &str) -> String {
    let mut chars = message.chars();
    match chars.next() {
        Some(c) => c.to_lowercase().chain(chars).collect(),
        None => String::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_curve_end_points() {
        let t = Tonemap {
            exposure: 0.0,
            curve: TonemapArg::Srgb,
        };
        assert_eq!(t.apply(0.0), 0);
        assert_eq!(t.apply(1.0), 255);
        assert_eq!(t.apply(7.0), 255);
        assert_eq!(t.apply(f32::NAN), 0);
        assert_eq!(t.apply(-1.0), 0);
        // Mid grey 0.18 is sRGB 118.
        assert_eq!(t.apply(0.18), 118);
        let brighter = Tonemap { exposure: 1.0, ..t };
        assert_eq!(brighter.apply(0.5), 255);
    }

    #[test]
    fn filmic_is_monotone_and_saturates() {
        let t = Tonemap {
            exposure: 0.0,
            curve: TonemapArg::Filmic,
        };
        let values: Vec<u8> = [0.0, 0.1, 0.5, 1.0, 4.0, 100.0]
            .iter()
            .map(|&v| t.apply(v))
            .collect();
        assert!(values.windows(2).all(|w| w[0] <= w[1]), "{values:?}");
        assert_eq!(values[0], 0);
        assert_eq!(values[5], 255);
        assert!(values[3] < 255, "filmic keeps 1.0 below white: {values:?}");
    }
}
