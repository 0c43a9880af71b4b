//! Linear RGB images as fppm writes and compares them: the one image stack of the `fppm`
//! command and of xtask.
//!
//! The principal type is [`Image`], linear RGB pixels row-major from the top-left. Around it:
//!
//! - files ([`read_exr`], [`read_exr_bytes`], [`write_exr`] with auxiliary channels and metadata, [`write_png`];
//!   [`encode_png`], a PNG in memory),
//!   written atomically (a temporary sibling renamed over the target, [`write_atomically`]),
//!   so that a killed process never leaves a truncated file;
//! - display ([`Tonemap`]: exposure, the sRGB or filmic curve, the sRGB transfer function;
//!   [`ramp`], the false-colour ramp of error and radius maps; [`auto_exposure`];
//!   [`write_sheet`], a contact sheet);
//! - error metrics against a reference ([`errors`]: RMSE, relative MSE
//!   (x − ref)² / (ref² + ε) with ε = [`REL_MSE_EPSILON`], mean ratio), with one guard against
//!   a black reference.
//!
//! Errors are a [`FilmError`] naming the file; nothing here prints or exits.

mod display;
mod files;
mod metrics;

use std::path::PathBuf;

pub use crate::display::{
    Curve, Tonemap, auto_exposure, ramp, srgb_encode, to_srgb8, write_false_colour, write_sheet,
};
pub use crate::files::{
    Frame, check_writable, encode_png, read_exr, read_exr_bytes, write_atomically, write_exr,
    write_png, write_preview,
};
pub use crate::metrics::{Errors, REL_MSE_EPSILON, errors, rel_mse_map, relative_error_map};

/// A linear RGB image, row-major from the top-left.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// `width × height` pixels.
    pub pixels: Vec<[f32; 3]>,
}

impl Image {
    /// An image of `width × height` `pixels`.
    ///
    /// # Panics
    ///
    /// If the number of pixels is not `width × height`.
    #[must_use]
    pub fn new(width: usize, height: usize, pixels: Vec<[f32; 3]>) -> Self {
        assert_eq!(pixels.len(), width * height, "pixel count matches the film");
        Self {
            width,
            height,
            pixels,
        }
    }

    /// Mean over pixels and channels.
    #[must_use]
    pub fn mean(&self) -> f64 {
        let sum: f64 = self
            .pixels
            .iter()
            .map(|p| p.iter().map(|&v| f64::from(v)).sum::<f64>())
            .sum();
        sum / (3 * self.pixels.len()).max(1) as f64
    }

    /// Every channel multiplied by `factor`.
    #[must_use]
    pub fn scaled(&self, factor: f32) -> Self {
        let pixels = self.pixels.iter().map(|p| p.map(|v| v * factor)).collect();
        Self::new(self.width, self.height, pixels)
    }
}

/// What can go wrong reading or writing an image, or comparing two.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum FilmError {
    /// The file cannot be read as an EXR.
    #[error("{}: cannot read exr: {message}", path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// What went wrong, lower case.
        message: String,
    },
    /// The EXR lacks a colour channel.
    #[error("{}: exr has no {channel} channel", path.display())]
    MissingChannel {
        /// The file.
        path: PathBuf,
        /// `R`, `G` or `B`.
        channel: &'static str,
    },
    /// The file cannot be written.
    #[error("{}: cannot write file: {message}", path.display())]
    Write {
        /// The file.
        path: PathBuf,
        /// What went wrong, lower case.
        message: String,
    },
    /// Two images to compare differ in size.
    #[error("image is {}x{} but the reference is {}x{}", size.0, size.1, reference.0, reference.1)]
    SizeMismatch {
        /// The image's width and height.
        size: (usize, usize),
        /// The reference's.
        reference: (usize, usize),
    },
}

/// The message with its first letter in lower case (OS and library messages start with a
/// capital).
#[must_use]
pub fn lower_first(message: &str) -> String {
    let mut chars = message.chars();
    match chars.next() {
        Some(c) => c.to_lowercase().chain(chars).collect(),
        None => String::new(),
    }
}
