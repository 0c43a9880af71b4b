//! `cargo xtask converge`: error versus wall-clock time (and versus photons) of every method on
//! one scene of the suite, against its golden path-traced reference; error restricted to
//! regional masks; radius and frequency-floor maps; and a one-at-a-time sweep of the
//! frequency-method parameters for choosing defaults.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use anyhow::{Context, Result, bail};
use glam::Vec2;

use crate::suite::{self, SuiteScene};
use film::{Errors, Image};

pub(crate) const HELP: &str = "\
cargo xtask converge --scene NAME [--budgets 2,4,8,16,32] [--methods ppm,sppm,freq,freq-sppm,path]
                     [--photons N] [--seed S] [--out DIR] [--quick]
                     [--pointwise PATHS] [--replot] [--alpha A] [--freq-fraction F] [--kernel-k poster|strict|K] [--freq-merge min|poster-max]
                     [--freq-geometry on|off] [--clock wall|cpu] [--film WxH]
cargo xtask converge --scene NAME --sweep [--budget SECONDS] [--methods freq]

Runs each method alone (one after another) on the suite scene NAME at its suite film size and
snapshots the image whenever the measured wall-clock time passes a budget. Every snapshot's
RMSE, relMSE and mean ratio against tests/golden/NAME.exr, over the whole image and over three
masks (low-frequency diffuse, caustic / high-frequency diffuse, glossy or specular first hit),
goes to DIR/NAME.csv; DIR/NAME-time.svg and DIR/NAME-photons.svg plot relMSE on log-log axes
(error versus seconds, and versus photons emitted: the equal-photon-count comparison). The
masks and, for each photon mapper, the final radius map (and for the frequency methods the
map of the share of hitpoints held by the frequency floor) are written as PNGs. DIR defaults
to docs/convergence. --quick uses budgets 1,2 and writes to target/converge.
--pointwise PATHS measures ppm and freq (the fixed-hitpoint methods, the only ones allowed
with it) against the image they converge to instead of the golden pixel average: the
path-traced radiance at each hitpoint of their first camera pass (PATHS paths per hitpoint,
ppm::pointwise_reference), so that their rate of convergence can be read. Write it to its
own --out DIR.
--replot redraws the SVGs from DIR/NAME.csv.
--clock cpu measures budgets in process CPU seconds divided by the thread count instead of
wall-clock seconds: the same on an idle machine, and what each method would have taken alone
when other jobs share the machine.
--film WxH renders at another film size (with --pointwise only; masks then come from the
pointwise reference).
--freq-geometry off lets frequency methods hold radii over edges and corners (no clear-disc
probes).
--sweep renders the methods (default freq and ppm) at one budget (default 8 s) with one
parameter varied at a time around the defaults (alpha, freq-fraction, kernel-k, freq-merge,
freq-geometry) and writes DIR/NAME-sweep.csv.";

/// Camera passes averaged for the directly seen emission of the pointwise reference.
const POINTWISE_EMISSION_PASSES: u32 = 256;

mod flags;
mod masks;
mod reference;
mod report;
mod sweep;

use self::flags::*;
use self::masks::*;
pub(crate) use self::reference::{noise_rel_mse, reference_from_halves};
use self::report::*;
use self::sweep::*;

pub(crate) fn run(root: &Path, args: &[String]) -> Result<bool> {
    let flags = Flags::parse(args)?;
    let suite = suite::load_suite(root)?;
    let entry = suite
        .scene
        .iter()
        .find(|s| s.name == flags.scene)
        .with_context(|| format!("no scene named `{}` in tests/scenes.toml", flags.scene))?;
    let golden = root
        .join("tests/golden")
        .join(format!("{}.exr", entry.name));
    let reference = film::read_exr(&golden)
        .with_context(|| format!("run `cargo xtask render-all --bless {}` first", entry.name))?;
    let out = flags.out.clone().map_or_else(
        || {
            root.join(if flags.quick {
                "target/converge"
            } else {
                "docs/convergence"
            })
        },
        |o| if o.is_absolute() { o } else { root.join(o) },
    );
    std::fs::create_dir_all(&out).with_context(|| format!("creating {}", out.display()))?;
    if flags.replot {
        let rows = read_csv(&out.join(format!("{}.csv", entry.name)))?;
        plot_error_curves(&out, &entry.name, &rows)?;
        return Ok(true);
    }
    let (scene, reference) = match flags.film {
        None => (suite::load_scene(root, entry)?, reference),
        Some((width, height)) => {
            // Masks below come from the reference; the pointwise reference replaces this
            // placeholder before anything is measured (`--film` requires `--pointwise`).
            let scene = suite::load_scene_sized(root, &entry.path, width, height)?;
            let (w, h) = (width as usize, height as usize);
            let blank = Image::new(w, h, vec![[0.0; 3]; w * h]);
            (scene, blank)
        }
    };
    let golden_masks = build_masks(&scene, &reference);
    let (reference, reference_variance) = match flags.pointwise {
        None => (reference, None),
        Some(paths) => {
            let params = base_params(entry, &scene, ppm::Method::Ppm, &flags)?;
            let start = Instant::now();
            // Two independent halves: their mean is the reference, their difference measures
            // its noise.
            let half = paths.div_ceil(2);
            let [a, b] = [0..half, half..paths.max(half + 1)].map(|range| {
                ppm::pointwise_reference_paths(&scene, params, range, POINTWISE_EMISSION_PASSES)
                    .context("pointwise reference")
            });
            let (a, b) = (a?, b?);
            println!(
                "converge: pointwise reference, {paths} paths per hitpoint, {:.1} s",
                start.elapsed().as_secs_f64()
            );
            let (w, h) = (reference.width, reference.height);
            let (mean, variance) = reference_from_halves(&a, &b);
            (Image::new(w, h, mean), Some(variance))
        }
    };
    let masks = if flags.film.is_some() {
        build_masks(&scene, &reference)
    } else {
        golden_masks
    };
    if flags.sweep {
        return sweep(&scene, entry, &reference, &masks, &flags, &out);
    }
    let transport = suite::transport_mask(&scene);
    let noise = match &reference_variance {
        None => [f64::NAN; 4],
        Some(variance) => {
            let all = noise_rel_mse(variance, &reference, &transport);
            let [low, caustic, glossy] =
                [0, 1, 2].map(|i| noise_rel_mse(variance, &reference, &masks.masks[i]));
            println!(
                "converge: the reference's own noise, in relMSE: {all:.5} [low {low:.5} caustic {caustic:.5} glossy {glossy:.5}] (from the difference of its two halves; subtracted in the \"net\" figures)"
            );
            [all, low, caustic, glossy]
        }
    };
    write_masks(
        &out.join(format!("{}-masks.png", entry.name)),
        &masks,
        reference.width,
    )?;

    let mut rows = Vec::new();
    for &method in &flags.methods {
        let params = base_params(entry, &scene, method, &flags)?;
        println!(
            "converge: {} {} ({})",
            entry.name,
            method,
            flags.overrides.label(&params)?
        );
        let mut renderer = ppm::Renderer::new(std::sync::Arc::clone(&scene), params)
            .context("render parameters")?;
        let mut elapsed = Duration::ZERO;
        for &budget in &flags.budgets {
            while elapsed.as_secs_f64() < budget {
                let start = flags.clock.now();
                renderer.iterate();
                elapsed += flags.clock.since(start);
            }
            let image = Image::new(reference.width, reference.height, renderer.image());
            let all = film::errors(&image, &reference, Some(&transport))?;
            let masked = [0, 1, 2].map(|i| {
                film::errors(&image, &reference, Some(&masks.masks[i])).expect("sizes match")
            });
            println!(
                "  {:>6.1} s ({:>5} passes): relMSE {:.5}  RMSE {:.5}  mean ratio {:.4}  [low {:.5} caustic {:.5} glossy {:.5}] [mean ratio low {:.4} caustic {:.4} glossy {:.4}]",
                elapsed.as_secs_f64(),
                renderer.passes(),
                all.rel_mse,
                all.rmse,
                all.mean_ratio,
                masked[0].rel_mse,
                masked[1].rel_mse,
                masked[2].rel_mse,
                masked[0].mean_ratio,
                masked[1].mean_ratio,
                masked[2].mean_ratio
            );
            if reference_variance.is_some() {
                println!(
                    "  {:>6} net of the reference's noise: relMSE {:.5}  [low {:.5} caustic {:.5} glossy {:.5}]",
                    "",
                    all.rel_mse - noise[0],
                    masked[0].rel_mse - noise[1],
                    masked[1].rel_mse - noise[2],
                    masked[2].rel_mse - noise[3]
                );
            }
            rows.push(Row {
                method,
                budget,
                seconds: elapsed.as_secs_f64(),
                passes: renderer.passes(),
                photons: renderer.photons_emitted(),
                all,
                masked,
                noise,
            });
        }
        let stem = format!("{}-{}", entry.name, method.name());
        let image = Image::new(reference.width, reference.height, renderer.image());
        film::write_preview(
            &out.join(format!("{stem}.png")),
            &image,
            film::Tonemap::linear(film::auto_exposure(&reference)),
            3,
        )?;
        write_maps(&renderer, &out, &stem, reference.width)?;
    }
    film::write_preview(
        &out.join(format!("{}-reference.png", entry.name)),
        &reference,
        film::Tonemap::linear(film::auto_exposure(&reference)),
        3,
    )?;
    write_csv(
        &out.join(format!("{}.csv", entry.name)),
        entry,
        &masks,
        &rows,
    )?;
    plot_error_curves(&out, &entry.name, &rows)?;
    println!("converge: slopes of log relMSE versus log seconds (least squares over the budgets):");
    for &method in &flags.methods {
        // log relMSE, less `floor`, against log seconds.
        let points = |floor: f64| -> Vec<(f64, f64)> {
            rows.iter()
                .filter(|r| r.method == method)
                .map(|r| (r.seconds.ln(), (r.all.rel_mse - floor).ln()))
                .collect()
        };
        let raw = slope(&points(0.0));
        if reference_variance.is_some() {
            let net = slope(&points(noise[0]));
            println!(
                "  {:<9} {raw:+.3} ({net:+.3} net of the reference's noise)",
                method.name()
            );
        } else {
            println!("  {:<9} {raw:+.3}", method.name());
        }
    }
    println!("converge: wrote {}", out.display());
    Ok(true)
}

fn base_params(
    entry: &SuiteScene,
    scene: &scene::Scene,
    method: ppm::Method,
    flags: &Flags,
) -> Result<ppm::RenderParams> {
    let mut params = suite::params(entry, scene, method, flags.seed)?;
    params.budget.photons_per_pass = flags.photons;
    params.budget.photons_auto = false;
    // Against the pointwise reference (the radiance at PPM's fixed hitpoints) the renders
    // gather only: light-traced connections and direct lighting (a light sample per camera
    // pass, at jittered points) converge to the pixel's average instead.
    if flags.pointwise.is_some() {
        params.connections.light_tracing = false;
        params.connections.direct_lighting = false;
    }
    flags.overrides.apply(&mut params)?;
    Ok(params)
}

#[cfg(test)]
mod tests {
    /// The README's `cargo xtask converge --scene cornell-original`, with every method of the
    /// default list and budgets short enough for the test suite: it renders, plots and writes
    /// its table.
    #[test]
    fn the_readme_command_runs_end_to_end_with_short_budgets() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
        let out = std::env::temp_dir().join(format!("fppm-converge-test-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&out);
        let args: Vec<String> = [
            "--scene",
            "cornell-original",
            "--budgets",
            "0.01,0.02",
            "--photons",
            "2000",
            "--out",
        ]
        .iter()
        .map(|s| (*s).to_owned())
        .chain([out.display().to_string()])
        .collect();
        assert!(super::run(&root, &args).unwrap());
        let csv = std::fs::read_to_string(out.join("cornell-original.csv")).unwrap();
        for method in ppm::Method::ALL {
            assert!(
                csv.lines()
                    .any(|l| l.split(',').any(|f| f == method.name())),
                "no row of {method} in\n{csv}"
            );
        }
        assert!(out.join("cornell-original-time.svg").exists());
        std::fs::remove_dir_all(&out).unwrap();
    }
}
