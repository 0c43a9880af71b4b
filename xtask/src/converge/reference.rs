//! A reference from two independent halves, and its own noise in relMSE.

use super::*;

/// The reference of two independent halves A and B (pixels of linear RGB): their mean, and
/// per pixel and channel the unbiased estimate (A − B)²/4 of that mean's variance.
pub(crate) fn reference_from_halves(
    a: &[[f32; 3]],
    b: &[[f32; 3]],
) -> (Vec<[f32; 3]>, Vec<[f64; 3]>) {
    a.iter()
        .zip(b)
        .map(|(a, b)| {
            let mean = [0, 1, 2].map(|c| 0.5 * (a[c] + b[c]));
            let variance = [0, 1, 2].map(|c| {
                let d = f64::from(a[c]) - f64::from(b[c]);
                d * d / 4.0
            });
            (mean, variance)
        })
        .unzip()
}

/// The expected contribution of the reference's noise to a relMSE over `mask`: E[(x − ref)²] =
/// (x − L)² + Var(ref) for an image x independent of the reference, so this is the mean of
/// Var(ref) / (ref² + ε) with the relMSE's own normalisation (`film::errors`).
pub(crate) fn noise_rel_mse(variance: &[[f64; 3]], reference: &Image, mask: &[bool]) -> f64 {
    let (mut sum, mut n) = (0.0f64, 0usize);
    for ((v, r), &inside) in variance.iter().zip(&reference.pixels).zip(mask) {
        if !inside {
            continue;
        }
        for c in 0..3 {
            let y = f64::from(r[c]);
            sum += v[c] / (y * y + film::REL_MSE_EPSILON);
            n += 1;
        }
    }
    sum / n.max(1) as f64
}
