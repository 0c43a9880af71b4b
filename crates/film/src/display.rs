//! Display: tone mapping to 8-bit sRGB, the false-colour ramp, exposure and contact sheets.

use std::path::Path;

use crate::{FilmError, Image, write_png};

/// The tone curve applied after the exposure.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Curve {
    /// Clip at 1.
    #[default]
    Srgb,
    /// The ACES filmic fit of Narkowicz (2015).
    Filmic,
}

/// How linear values become 8-bit sRGB: scaled, tone-mapped, clipped to [0, 1], encoded.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tonemap {
    /// Linear values are multiplied by this.
    pub scale: f32,
    /// The tone curve.
    pub curve: Curve,
}

impl Tonemap {
    /// An exposure of `stops` (linear values are scaled by 2^stops) and `curve`.
    #[must_use]
    pub fn with_stops(stops: f32, curve: Curve) -> Self {
        Self {
            scale: stops.exp2(),
            curve,
        }
    }

    /// Linear values scaled by `scale`, clipped at 1.
    #[must_use]
    pub fn linear(scale: f32) -> Self {
        Self {
            scale,
            curve: Curve::Srgb,
        }
    }

    /// One linear channel value to an 8-bit sRGB value; negative and non-finite values are
    /// black.
    #[must_use]
    pub fn apply(self, linear: f32) -> u8 {
        let v = if linear.is_finite() {
            linear.max(0.0)
        } else {
            0.0
        } * self.scale;
        let mapped = match self.curve {
            Curve::Srgb => v,
            Curve::Filmic => aces_narkowicz(v),
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
#[must_use]
pub fn srgb_encode(v: f32) -> f32 {
    if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

/// The 8-bit sRGB bytes of `image` under `tonemap`, three a pixel.
#[must_use]
pub fn to_srgb8(image: &Image, tonemap: Tonemap) -> Vec<u8> {
    image
        .pixels
        .iter()
        .flat_map(|p| p.map(|c| tonemap.apply(c)))
        .collect()
}

/// The false-colour ramp of error and radius maps: t in [0, 1] (clamped; non-finite is the
/// top) to 8-bit RGB, piecewise linear through five of viridis' colours, from dark blue to
/// yellow.
#[must_use]
pub fn ramp(t: f64) -> [u8; 3] {
    const STOPS: [[f64; 3]; 5] = [
        [68.0, 1.0, 84.0],
        [59.0, 82.0, 139.0],
        [33.0, 145.0, 140.0],
        [94.0, 201.0, 98.0],
        [253.0, 231.0, 37.0],
    ];
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        1.0
    } * (STOPS.len() - 1) as f64;
    let i = (t.floor() as usize).min(STOPS.len() - 2);
    let f = t - i as f64;
    let (lo, hi) = (STOPS[i], STOPS[i + 1]);
    [0, 1, 2].map(|c| (lo[c] + (hi[c] - lo[c]) * f).round() as u8)
}

/// Writes a scalar map (`width` values a row) as a false-colour PNG, `max` at the top of the
/// [`ramp`], enlarged `zoom` times.
///
/// # Errors
///
/// [`FilmError::Write`] if the file cannot be written.
pub fn write_false_colour(
    path: &Path,
    width: usize,
    values: &[f32],
    max: f32,
    zoom: usize,
) -> Result<(), FilmError> {
    let (width, zoom) = (width.max(1), zoom.max(1));
    let height = values.len() / width;
    let mut bytes = Vec::with_capacity(values.len() * zoom * zoom * 3);
    for y in 0..height * zoom {
        for x in 0..width * zoom {
            let v = values[(y / zoom) * width + x / zoom];
            bytes.extend(ramp(if max > 0.0 { f64::from(v / max) } else { 0.0 }));
        }
    }
    write_png(path, width * zoom, height * zoom, bytes)
}

/// A linear scale that maps the 99th percentile of the image's luminance to about 0.9.
#[must_use]
pub fn auto_exposure(image: &Image) -> f32 {
    let mut lum: Vec<f32> = image
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

/// Writes a contact sheet: one row per entry of `rows`, images side by side, clipped sRGB,
/// enlarged `zoom` times, with a 2-pixel gap.
///
/// # Errors
///
/// [`FilmError::Write`] if the file cannot be written.
pub fn write_sheet(path: &Path, rows: &[Vec<Image>], zoom: usize) -> Result<(), FilmError> {
    const GAP: usize = 2;
    let zoom = zoom.max(1);
    let row_width = |row: &Vec<Image>| row.iter().map(|i| i.width * zoom + GAP).sum::<usize>();
    let row_height = |row: &Vec<Image>| row.iter().map(|i| i.height).max().unwrap_or(0) * zoom;
    let width = rows.iter().map(row_width).max().unwrap_or(1).max(1);
    let height = rows
        .iter()
        .map(|r| row_height(r) + GAP)
        .sum::<usize>()
        .max(1);
    let mut bytes = vec![0u8; width * height * 3];
    let tonemap = Tonemap::linear(1.0);
    let mut y0 = 0;
    for row in rows {
        let mut x0 = 0;
        for image in row {
            for y in 0..image.height * zoom {
                for x in 0..image.width * zoom {
                    let p = image.pixels[(y / zoom) * image.width + x / zoom];
                    let at = ((y0 + y) * width + x0 + x) * 3;
                    bytes[at..at + 3].copy_from_slice(&p.map(|c| tonemap.apply(c)));
                }
            }
            x0 += image.width * zoom + GAP;
        }
        y0 += row_height(row) + GAP;
    }
    write_png(path, width, height, bytes)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_curve_end_points() {
        let t = Tonemap::with_stops(0.0, Curve::Srgb);
        assert_eq!(t.apply(0.0), 0);
        assert_eq!(t.apply(1.0), 255);
        assert_eq!(t.apply(7.0), 255);
        assert_eq!(t.apply(f32::NAN), 0);
        assert_eq!(t.apply(-1.0), 0);
        // Mid grey 0.18 is sRGB 118 (IEC 61966-2-1: 1.055·0.18^(1/2.4) − 0.055 = 0.4614).
        assert_eq!(t.apply(0.18), 118);
        let brighter = Tonemap::with_stops(1.0, Curve::Srgb);
        assert_eq!(brighter.apply(0.5), 255);
    }

    #[test]
    fn filmic_is_monotone_and_saturates() {
        let t = Tonemap::with_stops(0.0, Curve::Filmic);
        let values: Vec<u8> = [0.0, 0.1, 0.5, 1.0, 4.0, 100.0]
            .iter()
            .map(|&v| t.apply(v))
            .collect();
        assert!(values.windows(2).all(|w| w[0] <= w[1]), "{values:?}");
        assert_eq!(values[0], 0);
        assert_eq!(values[5], 255);
        assert!(values[3] < 255, "filmic keeps 1.0 below white: {values:?}");
    }

    #[test]
    fn ramp_ends() {
        assert_eq!(ramp(0.0), [68, 1, 84]);
        assert_eq!(ramp(1.0), [253, 231, 37]);
        assert_eq!(ramp(7.0), [253, 231, 37]);
        assert_eq!(ramp(f64::NAN), [253, 231, 37]);
        assert_eq!(ramp(-1.0), [68, 1, 84]);
    }
}
