//! Error metrics of an image against a reference.

use crate::{FilmError, Image};

/// The offset ε in the relative MSE's denominator: keeps dark pixels from dominating.
pub const REL_MSE_EPSILON: f64 = 1e-2;

/// Error figures of an image against a reference, over pixels and RGB channels (n values).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Errors {
    /// Root mean squared error √(Σ (x − ref)² / n).
    pub rmse: f64,
    /// Relative MSE Σ (x − ref)² / (ref² + ε) / n, the usual denoising metric.
    pub rel_mse: f64,
    /// Mean of the image over mean of the reference (1 is unbiased); NaN if the reference's
    /// sum is not positive.
    pub mean_ratio: f64,
}

/// Error figures of `image` against `reference` over the pixels where `mask` is true (all
/// pixels without a mask).
///
/// # Errors
///
/// [`FilmError::SizeMismatch`] if the two images differ in size.
///
/// # Panics
///
/// If `mask` has fewer entries than the images have pixels.
pub fn errors(
    image: &Image,
    reference: &Image,
    mask: Option<&[bool]>,
) -> Result<Errors, FilmError> {
    check_sizes(image, reference)?;
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

/// Per pixel, the relative MSE over its three channels: mean of (x − ref)² / (ref² + ε).
///
/// # Errors
///
/// [`FilmError::SizeMismatch`] if the two images differ in size.
pub fn rel_mse_map(image: &Image, reference: &Image) -> Result<Vec<f32>, FilmError> {
    check_sizes(image, reference)?;
    Ok(image
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
        .collect())
}

/// Per pixel, the relative error of the channel means ā, b̄: |ā − b̄| / (|b̄| + ε).
///
/// # Errors
///
/// [`FilmError::SizeMismatch`] if the two images differ in size.
pub fn relative_error_map(image: &Image, reference: &Image) -> Result<Vec<f32>, FilmError> {
    check_sizes(image, reference)?;
    let mean = |p: &[f32; 3]| (f64::from(p[0]) + f64::from(p[1]) + f64::from(p[2])) / 3.0;
    Ok(image
        .pixels
        .iter()
        .zip(&reference.pixels)
        .map(|(p, r)| {
            let (a, b) = (mean(p), mean(r));
            ((a - b).abs() / (b.abs() + REL_MSE_EPSILON)) as f32
        })
        .collect())
}

fn check_sizes(image: &Image, reference: &Image) -> Result<(), FilmError> {
    if (image.width, image.height) == (reference.width, reference.height) {
        Ok(())
    } else {
        Err(FilmError::SizeMismatch {
            size: (image.width, image.height),
            reference: (reference.width, reference.height),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn metrics_by_hand() {
        let a = Image::new(2, 1, vec![[1.0, 1.0, 1.0], [0.0, 0.0, 0.0]]);
        let b = Image::new(2, 1, vec![[0.5, 0.5, 0.5], [0.0, 0.0, 0.0]]);
        let m = errors(&a, &b, None).unwrap();
        // Three differences of 0.5, three of 0: MSE = 0.75 / 6 = 0.125.
        assert!((m.rmse - 0.125f64.sqrt()).abs() < 1e-12);
        assert!((m.rel_mse - 3.0 * 0.25 / 0.26 / 6.0).abs() < 1e-12);
        assert!((m.mean_ratio - 2.0).abs() < 1e-12);
        // Only the second pixel: no error, and a black reference has no mean ratio.
        let masked = errors(&a.scaled(0.0), &b.scaled(0.0), Some(&[false, true])).unwrap();
        assert_eq!((masked.rmse, masked.rel_mse), (0.0, 0.0));
        assert!(masked.mean_ratio.is_nan());
        assert_eq!(rel_mse_map(&a, &b).unwrap()[0], (0.25 / 0.26) as f32);
        assert_eq!(relative_error_map(&a, &b).unwrap()[0], (0.5 / 0.51) as f32);
        assert!(errors(&a, &Image::new(1, 1, vec![[0.0; 3]]), None).is_err());
    }
}
