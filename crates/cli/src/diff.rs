//! `fppm diff A.exr B.exr`: error metrics of A against the reference B.
//!
//! Over every pixel and RGB channel (n values in all):
//! - RMSE = √(Σ (a − b)² / n);
//! - relative MSE = Σ (a − b)² / (b² + 0.01) / n, the usual denoising metric (the 0.01 keeps
//!   dark pixels from dominating);
//! - mean ratio = mean(A) / mean(B), which shows a brightness bias (1 is unbiased; NaN for a
//!   black reference).
//!
//! The metrics are `film::errors`.
//!
//! The false-colour image shows the per-pixel relative error |ā − b̄| / (|b̄| + 0.01) of the
//! channel means ā, b̄, on a viridis-like ramp from 0 (dark blue) to `--max` (yellow).

use crate::args::DiffArgs;
use crate::output;
use crate::{Outcome, usage};

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
    let a = film::read_exr(&args.a)?;
    let b = film::read_exr(&args.b)?;
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
    let m = film::errors(&a, &b, None)?;
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
        let bytes = film::relative_error_map(&a, &b)?
            .iter()
            .flat_map(|&error| film::ramp(f64::from(error) / args.max))
            .collect();
        film::write_png(out, a.width, a.height, bytes)?;
        eprintln!("wrote {}", out.display());
    }
    Ok(Outcome::Done)
}
