//! `fppm diff A.exr B.exr`: error metrics of A against the reference B.
//!
//! Over every pixel and RGB channel (n values in all):
//! - RMSE = √(Σ (a − b)² / n);
//! - relative MSE = Σ (a − b)² / (b² + 0.01) / n, the usual denoising metric (the 0.01 keeps
//!   dark pixels from dominating);
//! - mean ratio = mean(A) / mean(B), which shows a brightness bias (1 is unbiased).
//!
//! The false-colour image shows the per-pixel relative error |ā − b̄| / (|b̄| + 0.01) of the
//! channel means ā, b̄, on a viridis-like ramp from 0 (dark blue) to `--max` (yellow).

use crate::args::DiffArgs;
use crate::output::{self, RgbImage};
use crate::{Outcome, usage};

/// The numbers `fppm diff` prints.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Metrics {
    pub(crate) rmse: f64,
    pub(crate) rel_mse: f64,
    pub(crate) mean_ratio: f64,
}

pub(crate) fn diff(args: &DiffArgs) -> anyhow::Result<Outcome> {
    if !(args.max > 0.0 && args.max.is_finite()) {
        usage!("--max {} must be positive", args.max);
    }
    if let Some(out) = &args.out {
        if !out
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("png"))
        {
            usage!("--out {} must name a .png file", out.display());
        }
        output::check_writable(out, "--out")?;
    }
    let a = output::read_exr_rgb(&args.a)?;
    let b = output::read_exr_rgb(&args.b)?;
    if (a.width, a.height) != (b.width, b.height) {
        anyhow::bail!(
            "{}: image is {}x{} but {} is {}x{}",
            args.a.display(),
            a.width,
            a.height,
            args.b.display(),
            b.width,
            b.height
        );
    }
    let m = metrics(&a, &b);
    if args.json {
        let line = serde_json::json!({
            "rmse": m.rmse, "rel_mse": m.rel_mse, "mean_ratio": m.mean_ratio,
            "width": a.width, "height": a.height,
        });
        crate::print_stdout(&format!("{line}\n"))?;
    } else {
        crate::print_stdout(&format!(
            "rmse        {:.6e}\nrel_mse     {:.6e}\nmean_ratio  {:.6}\n",
            m.rmse, m.rel_mse, m.mean_ratio
        ))?;
    }
    if let Some(out) = &args.out {
        let bytes = a
            .pixels
            .iter()
            .zip(&b.pixels)
            .flat_map(|(pa, pb)| {
                let (ma, mb) = (mean3(pa), mean3(pb));
                let error = (ma - mb).abs() / (mb.abs() + 0.01);
                ramp(if error.is_finite() {
                    error / args.max
                } else {
                    1.0
                })
            })
            .collect();
        output::write_png(out, a.width, a.height, bytes)?;
        eprintln!("wrote {}", out.display());
    }
    Ok(Outcome::Done)
}

/// RMSE, relative MSE and mean ratio of `a` against the reference `b` (same size).
pub(crate) fn metrics(a: &RgbImage, b: &RgbImage) -> Metrics {
    let (mut squared, mut relative, mut sum_a, mut sum_b) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for (pa, pb) in a.pixels.iter().zip(&b.pixels) {
        for c in 0..3 {
            let (x, y) = (f64::from(pa[c]), f64::from(pb[c]));
            let d2 = (x - y) * (x - y);
            squared += d2;
            relative += d2 / (y * y + 0.01);
            sum_a += x;
            sum_b += y;
        }
    }
    let n = (a.pixels.len() * 3).max(1) as f64;
    Metrics {
        rmse: (squared / n).sqrt(),
        rel_mse: relative / n,
        mean_ratio: sum_a / sum_b,
    }
}

fn mean3(p: &[f32; 3]) -> f64 {
    (f64::from(p[0]) + f64::from(p[1]) + f64::from(p[2])) / 3.0
}

/// A viridis-like ramp: t in [0, 1] → 8-bit RGB, piecewise linear through five of viridis'
/// colours.
fn ramp(t: f64) -> [u8; 3] {
    const STOPS: [[f64; 3]; 5] = [
        [68.0, 1.0, 84.0],
        [59.0, 82.0, 139.0],
        [33.0, 145.0, 140.0],
        [94.0, 201.0, 98.0],
        [253.0, 231.0, 37.0],
    ];
    let t = t.clamp(0.0, 1.0) * (STOPS.len() - 1) as f64;
    let i = (t.floor() as usize).min(STOPS.len() - 2);
    let f = t - i as f64;
    let (lo, hi) = (STOPS[i], STOPS[i + 1]);
    [0, 1, 2].map(|c| (lo[c] + (hi[c] - lo[c]) * f).round() as u8)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn metrics_by_hand() {
        let a = RgbImage {
            width: 2,
            height: 1,
            pixels: vec![[1.0, 1.0, 1.0], [0.0, 0.0, 0.0]],
        };
        let b = RgbImage {
            width: 2,
            height: 1,
            pixels: vec![[0.5, 0.5, 0.5], [0.0, 0.0, 0.0]],
        };
        let m = metrics(&a, &b);
        // Three differences of 0.5, three of 0: MSE = 0.75 / 6 = 0.125.
        assert!((m.rmse - 0.125f64.sqrt()).abs() < 1e-12);
        assert!((m.rel_mse - 3.0 * 0.25 / 0.26 / 6.0).abs() < 1e-12);
        assert!((m.mean_ratio - 2.0).abs() < 1e-12);
    }

    #[test]
    fn ramp_ends() {
        assert_eq!(ramp(0.0), [68, 1, 84]);
        assert_eq!(ramp(1.0), [253, 231, 37]);
        assert_eq!(ramp(7.0), [253, 231, 37]);
        assert_eq!(ramp(-1.0), [68, 1, 84]);
    }
}
