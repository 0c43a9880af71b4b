//! Linear RGB images: EXR in and out, PNG previews, false-colour error maps and error metrics.

use std::path::Path;

use anyhow::{Context, Result, bail};

/// A linear RGB image, row-major from the top-left.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Image {
    pub(crate) width: usize,
    pub(crate) height: usize,
    pub(crate) pixels: Vec<[f32; 3]>,
}

impl Image {
    pub(crate) fn new(width: usize, height: usize, pixels: Vec<[f32; 3]>) -> Self {
        assert_eq!(pixels.len(), width * height, "pixel count matches the film");
        Self {
            width,
            height,
            pixels,
        }
    }

    /// Mean over pixels and channels.
    pub(crate) fn mean(&self) -> f64 {
        let sum: f64 = self
            .pixels
            .iter()
            .map(|p| p.iter().map(|&v| f64::from(v)).sum::<f64>())
            .sum();
        sum / (3 * self.pixels.len()).max(1) as f64
    }

    /// Every channel multiplied by `factor`.
    #[cfg(test)]
    pub(crate) fn scaled(&self, factor: f32) -> Self {
        let pixels = self.pixels.iter().map(|p| p.map(|v| v * factor)).collect();
        Self::new(self.width, self.height, pixels)
    }
}

/// Writes `image` as a ZIP-compressed (ZIP16 scanlines) 32-bit float EXR.
pub(crate) fn write_exr(path: &Path, image: &Image) -> Result<()> {
    use exr::prelude::*;
    let width = image.width;
    let layer = Layer::new(
        (image.width, image.height),
        LayerAttributes::named("beauty"),
        Encoding::SMALL_LOSSLESS,
        SpecificChannels::rgb(|Vec2(x, y): Vec2<usize>| {
            let p = image.pixels[y * width + x];
            (p[0], p[1], p[2])
        }),
    );
    exr::image::Image::from_layer(layer)
        .write()
        .non_parallel()
        .to_file(path)
        .with_context(|| format!("writing {}", path.display()))
}

/// Reads the first RGB layer of an EXR file.
pub(crate) fn read_exr(path: &Path) -> Result<Image> {
    use exr::prelude::*;
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .rgb_channels(
            |resolution, _| self::Image {
                width: resolution.width(),
                height: resolution.height(),
                pixels: vec![[0.0; 3]; resolution.width() * resolution.height()],
            },
            |image: &mut self::Image, position, (r, g, b): (f32, f32, f32)| {
                let idx = position.y() * image.width + position.x();
                image.pixels[idx] = [r, g, b];
            },
        )
        .first_valid_layer()
        .all_attributes()
        .non_parallel()
        .from_file(path)
        .with_context(|| format!("reading {}", path.display()))?;
    Ok(image.layer_data.channel_data.pixels)
}

/// sRGB encoding of a linear value in [0, 1].
fn srgb(v: f32) -> u8 {
    let v = v.clamp(0.0, 1.0);
    let e = if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    };
    (e * 255.0 + 0.5) as u8
}

/// Writes an sRGB PNG of `image` after multiplying by `exposure`, enlarged `zoom` times
/// (nearest neighbour) so small films are easy to look at.
pub(crate) fn write_png(path: &Path, image: &Image, exposure: f32, zoom: usize) -> Result<()> {
    let (w, h) = (image.width * zoom, image.height * zoom);
    let mut buffer = image::RgbImage::new(w as u32, h as u32);
    for (x, y, px) in buffer.enumerate_pixels_mut() {
        let p = image.pixels[(y as usize / zoom) * image.width + x as usize / zoom];
        *px = image::Rgb(p.map(|v| srgb(v * exposure)));
    }
    buffer
        .save(path)
        .with_context(|| format!("writing {}", path.display()))
}

/// Writes a scalar map as a PNG in false colour (0 → dark blue, `max` → red), enlarged `zoom`
/// times.
pub(crate) fn write_false_colour(
    path: &Path,
    width: usize,
    values: &[f32],
    max: f32,
    zoom: usize,
) -> Result<()> {
    let height = values.len() / width.max(1);
    let pixels = values
        .iter()
        .map(|&v| false_colour(if max > 0.0 { v / max } else { 0.0 }))
        .collect();
    let image = Image::new(width, height, pixels);
    write_png(path, &image, 1.0, zoom)
}

/// A blue–cyan–green–yellow–red ramp for t in [0, 1] (linear RGB).
fn false_colour(t: f32) -> [f32; 3] {
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        1.0
    };
    let stops: [[f32; 3]; 5] = [
        [0.0, 0.0, 0.15],
        [0.0, 0.35, 0.8],
        [0.0, 0.7, 0.1],
        [0.9, 0.8, 0.0],
        [0.9, 0.0, 0.0],
    ];
    let s = t * 4.0;
    let i = (s.floor() as usize).min(3);
    let f = s - i as f32;
    [0, 1, 2].map(|c| stops[i][c] * (1.0 - f) + stops[i + 1][c] * f)
}

/// The offset in the relative MSE's denominator: keeps black pixels from dominating.
pub(crate) const REL_MSE_EPSILON: f64 = 1e-2;

/// Error figures of an image against a reference.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Errors {
    /// Root mean squared error over pixels and channels.
    pub(crate) rmse: f64,
    /// Relative MSE: mean of (x − ref)² / (ref² + ε) over pixels and channels.
    pub(crate) rel_mse: f64,
    /// Mean of the image over mean of the reference.
    pub(crate) mean_ratio: f64,
}

/// Error figures of `image` against `reference` over the pixels where `mask` is true (all pixels
/// without a mask).
pub(crate) fn errors(image: &Image, reference: &Image, mask: Option<&[bool]>) -> Result<Errors> {
    if (image.width, image.height) != (reference.width, reference.height) {
        bail!(
            "image is {}x{} but the reference is {}x{}",
            image.width,
            image.height,
            reference.width,
            reference.height
        );
    }
    let (mut se, mut rel, mut sum, mut sum_ref, mut n) = (0.0f64, 0.0f64, 0.0f64, 0.0f64, 0usize);
    for (idx, (p, r)) in image.pixels.iter().zip(&reference.pixels).enumerate() {
        if mask.is_some_and(|m| !m[idx]) {
            continue;
        }
        for c in 0..3 {
            let (x, y) = (f64::from(p[c]), f64::from(r[c]));
            let d = x - y;
            se += d * d;
            rel += d * d / (y * y + REL_MSE_EPSILON);
            sum += x;
            sum_ref += y;
            n += 1;
        }
    }
    let n = n.max(1) as f64;
    Ok(Errors {
        rmse: (se / n).sqrt(),
        rel_mse: rel / n,
        mean_ratio: if sum_ref > 0.0 {
            sum / sum_ref
        } else {
            f64::NAN
        },
    })
}

/// Per-pixel relative squared error, averaged over channels (for the false-colour error map).
pub(crate) fn rel_error_map(image: &Image, reference: &Image) -> Vec<f32> {
    image
        .pixels
        .iter()
        .zip(&reference.pixels)
        .map(|(p, r)| {
            let mut e = 0.0f64;
            for c in 0..3 {
                let d = f64::from(p[c]) - f64::from(r[c]);
                e += d * d / (f64::from(r[c]).powi(2) + REL_MSE_EPSILON);
            }
            (e / 3.0) as f32
        })
        .collect()
}

/// An exposure that maps the 99th percentile of the reference's luminance to about 0.9.
pub(crate) fn auto_exposure(reference: &Image) -> f32 {
    let mut lum: Vec<f32> = reference
        .pixels
        .iter()
        .map(|p| 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2])
        .filter(|v| v.is_finite())
        .collect();
    if lum.is_empty() {
        return 1.0;
    }
    lum.sort_by(f32::total_cmp);
    let p99 = lum[(lum.len() * 99 / 100).min(lum.len() - 1)];
    if p99 > 0.0 { 0.9 / p99 } else { 1.0 }
}

/// Writes a contact sheet: one row per entry of `rows`, images side by side (all of a row's
/// images must have the same size), enlarged `zoom` times, with a 2-pixel gap.
pub(crate) fn write_sheet(path: &Path, rows: &[Vec<Image>], zoom: usize) -> Result<()> {
    const GAP: usize = 2;
    let row_width = |row: &Vec<Image>| row.iter().map(|i| i.width * zoom + GAP).sum::<usize>();
    let width = rows.iter().map(row_width).max().unwrap_or(1).max(1);
    let height = rows
        .iter()
        .map(|r| r.iter().map(|i| i.height).max().unwrap_or(0) * zoom + GAP)
        .sum::<usize>()
        .max(1);
    let mut buffer = image::RgbImage::new(width as u32, height as u32);
    let mut y0 = 0;
    for row in rows {
        let mut x0 = 0;
        for image in row {
            for y in 0..image.height * zoom {
                for x in 0..image.width * zoom {
                    let p = image.pixels[(y / zoom) * image.width + x / zoom];
                    buffer.put_pixel((x0 + x) as u32, (y0 + y) as u32, image::Rgb(p.map(srgb)));
                }
            }
            x0 += image.width * zoom + GAP;
        }
        y0 += row.iter().map(|i| i.height).max().unwrap_or(0) * zoom + GAP;
    }
    buffer
        .save(path)
        .with_context(|| format!("writing {}", path.display()))
}
