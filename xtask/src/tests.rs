//! Tests of the comparison logic: noise stays inside a seed-calibrated tolerance, a 10 %
//! regression does not.

use crate::render_all::within;
use crate::suite::Tolerance;
use film::{Errors, Image, errors};

/// A smooth test image with a bright "caustic" blob.
fn reference() -> Image {
    let (w, h) = (32, 32);
    let pixels = (0..w * h)
        .map(|i| {
            let (x, y) = ((i % w) as f32 / w as f32, (i / w) as f32 / h as f32);
            let blob = (-((x - 0.5).powi(2) + (y - 0.7).powi(2)) * 80.0).exp() * 4.0;
            [0.3 + 0.4 * x + blob, 0.2 + 0.3 * y + blob, 0.25 + blob]
        })
        .collect();
    Image::new(w, h, pixels)
}

/// `reference` with multiplicative noise of relative size `sigma` from a small LCG.
fn noisy(reference: &Image, sigma: f32, seed: u64) -> Image {
    let mut state = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
    let mut uniform = move || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        ((state >> 40) as f32 / (1u64 << 24) as f32) * 2.0 - 1.0
    };
    let pixels = reference
        .pixels
        .iter()
        .map(|p| p.map(|v| v * (1.0 + sigma * 1.7 * uniform())))
        .collect();
    Image::new(reference.width, reference.height, pixels)
}

/// The rule of `render-all --calibrate`.
fn calibrate(samples: &[Errors]) -> Tolerance {
    let max_rel = samples.iter().map(|e| e.rel_mse).fold(0.0, f64::max);
    let max_dev = samples
        .iter()
        .map(|e| (e.mean_ratio - 1.0).abs())
        .fold(0.0, f64::max);
    Tolerance {
        rel_mse: 1.5 * max_rel,
        mean: 1.5 * max_dev + 0.005,
    }
}

#[test]
fn identical_images_have_no_error() {
    let r = reference();
    let e = errors(&r, &r, None).unwrap();
    assert_eq!(e.rel_mse, 0.0);
    assert_eq!(e.rmse, 0.0);
    assert!((e.mean_ratio - 1.0).abs() < 1e-12);
}

#[test]
fn noise_passes_and_a_ten_percent_regression_fails() {
    let r = reference();
    let calibration: Vec<Errors> = (0..4)
        .map(|s| errors(&noisy(&r, 0.1, s), &r, None).unwrap())
        .collect();
    let tolerance = calibrate(&calibration);
    // Fresh seeds pass.
    for seed in 100..110 {
        let e = errors(&noisy(&r, 0.1, seed), &r, None).unwrap();
        assert!(
            within(&e, &tolerance),
            "seed {seed}: {e:?} outside {tolerance:?}"
        );
    }
    // A 10 % brighter render (e.g. a lost normalisation factor) fails.
    let broken = noisy(&r, 0.1, 100).scaled(1.1);
    let e = errors(&broken, &r, None).unwrap();
    assert!(!within(&e, &tolerance), "{e:?} inside {tolerance:?}");
    // So does doubled noise (e.g. a radius that stopped shrinking).
    let e = errors(&noisy(&r, 0.2, 100), &r, None).unwrap();
    assert!(!within(&e, &tolerance), "{e:?} inside {tolerance:?}");
}

#[test]
fn masks_restrict_the_error() {
    let r = reference();
    let mut broken = r.clone();
    broken.pixels[0] = [10.0, 10.0, 10.0];
    let mut mask = vec![true; r.pixels.len()];
    mask[0] = false;
    assert_eq!(errors(&broken, &r, Some(&mask)).unwrap().rel_mse, 0.0);
    assert!(errors(&broken, &r, None).unwrap().rel_mse > 0.0);
}

/// Two halves ref ± e: their mean is ref and the variance estimate e² per channel, which
/// `noise_rel_mse` turns into the relMSE a noise-free image would show against that reference.
#[test]
fn reference_noise_from_two_halves() {
    use crate::converge::{noise_rel_mse, reference_from_halves};
    let reference = reference();
    let e = 0.01f32;
    let plus: Vec<[f32; 3]> = reference.pixels.iter().map(|p| p.map(|v| v + e)).collect();
    let minus: Vec<[f32; 3]> = reference.pixels.iter().map(|p| p.map(|v| v - e)).collect();
    let (mean, variance) = reference_from_halves(&plus, &minus);
    for (m, r) in mean.iter().zip(&reference.pixels) {
        for c in 0..3 {
            assert!((m[c] - r[c]).abs() < 1e-6);
        }
    }
    let mask = vec![true; reference.pixels.len()];
    let mean = Image::new(reference.width, reference.height, mean);
    let noise = noise_rel_mse(&variance, &mean, &mask);
    // An image off the mean by e everywhere has the relMSE e² / (ref² + ε) the noise predicts.
    let plus = Image::new(reference.width, reference.height, plus);
    let expected = errors(&plus, &mean, None).unwrap().rel_mse;
    assert!(
        (noise - expected).abs() < 0.02 * expected,
        "noise {noise} vs relMSE {expected}"
    );
    let none = vec![false; reference.pixels.len()];
    assert_eq!(noise_rel_mse(&variance, &mean, &none), 0.0);
}
