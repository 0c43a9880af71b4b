//! `cargo xtask render-all`: renders every scene of `tests/scenes.toml` with every method at a
//! small budget, compares each image with the path-traced golden reference
//! `tests/golden/<name>.exr` and writes `target/render-all/report.html`.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result, bail};

use crate::suite::{self, SuiteScene, Tolerance};
use film::{Errors, Image};

/// Seed of the golden references; differs from every check and calibration seed so the
/// reference's noise is independent of the images compared with it.
const REFERENCE_SEED: u64 = 0x00C0_FFEE;
/// Seed of the checked renders.
const CHECK_SEED: u64 = 1;
/// How much longer `--full` renders than the check budget.
const FULL_FACTOR: u32 = 4;
/// Pixel enlargement of the report's PNGs.
const ZOOM: usize = 3;

/// Parsed flags.
#[derive(Debug, Default)]
pub(crate) struct Flags {
    quick: bool,
    full: bool,
    calibrate: bool,
    bless: Option<String>,
    filter: Option<String>,
    /// Only these methods (all if empty).
    methods: Vec<ppm::Method>,
}

impl Flags {
    /// The methods to render, in `Method::ALL`'s order.
    fn methods(&self) -> impl Iterator<Item = ppm::Method> + '_ {
        ppm::Method::ALL
            .into_iter()
            .filter(|m| self.methods.is_empty() || self.methods.contains(m))
    }
}

impl Flags {
    pub(crate) fn parse(args: &[String]) -> Result<Self> {
        let mut flags = Flags::default();
        let mut it = args.iter();
        while let Some(arg) = it.next() {
            match arg.as_str() {
                "--quick" => flags.quick = true,
                "--full" => flags.full = true,
                "--calibrate" => flags.calibrate = true,
                "--bless" => {
                    flags.bless = Some(
                        it.next()
                            .context("--bless needs a scene name or `all`")?
                            .clone(),
                    )
                }
                "--filter" => {
                    flags.filter = Some(it.next().context("--filter needs a scene name")?.clone())
                }
                "--methods" => {
                    let list = it.next().context("--methods needs a list of methods")?;
                    for name in list.split(',') {
                        flags.methods.push(
                            ppm::Method::from_name(name)
                                .with_context(|| format!("render-all: no method `{name}`"))?,
                        );
                    }
                }
                other => bail!("render-all: unknown flag `{other}`"),
            }
        }
        if flags.quick && flags.full {
            bail!("render-all: --quick and --full exclude each other");
        }
        Ok(flags)
    }
}

pub(crate) const HELP: &str = "\
cargo xtask render-all [--quick] [--full] [--bless NAME|all] [--filter NAME] [--methods a,b]
                       [--calibrate]

Renders every scene of tests/scenes.toml with every method (ppm, sppm, appm, freq, freq-sppm,
path) at the suite's small budgets, compares each with tests/golden/<name>.exr (path-traced) by
relative MSE and mean, and writes target/render-all/report.html. Exits 1 if a scene regresses.
  --quick      the CI run (the suite budgets; this is also the default)
  --full       4x the passes of every method (errors only shrink, same tolerances)
  --bless NAME re-render the golden reference of NAME (or `all`) with the path tracer
  --filter NAME  only scenes whose name contains NAME
  --methods a,b  only these methods (e.g. --methods light with --calibrate)
  --calibrate  render every method with each calibration seed and print suggested tolerances";

/// One method's result on one scene.
struct MethodResult {
    method: ppm::Method,
    errors: Errors,
    tolerance: Option<Tolerance>,
    seconds: f64,
    passes: u32,
    /// A deliberately broken copy (×1.1) checked against the same tolerance.
    perturbed_fails: bool,
}

impl MethodResult {
    fn pass(&self) -> bool {
        self.tolerance.is_some_and(|t| within(&self.errors, &t))
    }
}

pub(crate) fn within(errors: &Errors, tolerance: &Tolerance) -> bool {
    errors.rel_mse <= tolerance.rel_mse && (errors.mean_ratio - 1.0).abs() <= tolerance.mean
}

struct SceneReport {
    entry: SuiteScene,
    problem: Option<String>,
    methods: Vec<MethodResult>,
    reference_mean: f64,
    /// Exposed images for the contact sheet: reference, then each method.
    sheet_row: Vec<Image>,
}

pub(crate) fn run(root: &Path, args: &[String]) -> Result<bool> {
    let flags = Flags::parse(args)?;
    let suite = suite::load_suite(root)?;
    let out_dir = root.join("target/render-all");
    std::fs::create_dir_all(&out_dir).with_context(|| format!("creating {}", out_dir.display()))?;
    let start = Instant::now();
    let scenes: Vec<&SuiteScene> = suite
        .scene
        .iter()
        .filter(|s| flags.filter.as_deref().is_none_or(|f| s.name.contains(f)))
        .collect();
    if scenes.is_empty() {
        bail!("render-all: no scene matches the filter");
    }
    if let Some(bless) = &flags.bless
        && bless != "all"
        && !scenes.iter().any(|s| &s.name == bless)
    {
        bail!("render-all: no scene named `{bless}` in tests/scenes.toml");
    }

    if flags.calibrate {
        for entry in &scenes {
            calibrate(root, entry, &suite.calibration_seeds, &flags)?;
        }
        return Ok(true);
    }

    let mut reports = Vec::new();
    for entry in scenes {
        let golden = golden_path(root, &entry.name);
        if flags
            .bless
            .as_deref()
            .is_some_and(|b| b == "all" || b == entry.name)
        {
            bless(root, entry, &golden)?;
        }
        reports.push(check_scene(root, entry, &golden, &flags, &out_dir)?);
    }
    let ok = reports
        .iter()
        .all(|r| r.problem.is_none() && r.methods.iter().all(MethodResult::pass));
    write_report(&out_dir, &reports, start.elapsed().as_secs_f64(), &flags)?;
    let rows: Vec<Vec<Image>> = reports
        .iter()
        .map(|r| r.sheet_row.clone())
        .filter(|r| !r.is_empty())
        .collect();
    film::write_sheet(&out_dir.join("sheet.png"), &rows, 2)?;
    println!(
        "render-all: {} scene(s) in {:.1} s; report: {}",
        reports.len(),
        start.elapsed().as_secs_f64(),
        out_dir.join("report.html").display()
    );
    for report in &reports {
        if let Some(problem) = &report.problem {
            eprintln!("render-all: {}: {problem}", report.entry.name);
        }
        let failed: Vec<&str> = report
            .methods
            .iter()
            .filter(|m| !m.pass())
            .map(|m| m.method.name())
            .collect();
        if report.problem.is_none() && !failed.is_empty() {
            eprintln!(
                "render-all: {} regressed ({}); look at target/render-all/report.html, then fix the \
                 renderer, or if the change is intended run `cargo xtask render-all --bless {}` after \
                 checking the images (and `cargo xtask render-all --calibrate --filter {}` for new tolerances)",
                report.entry.name,
                failed.join(", "),
                report.entry.name,
                report.entry.name
            );
        }
    }
    Ok(ok)
}

fn golden_path(root: &Path, name: &str) -> PathBuf {
    root.join("tests/golden").join(format!("{name}.exr"))
}

/// Renders the golden reference of `entry` with the path tracer (never a photon mapper).
fn bless(root: &Path, entry: &SuiteScene, golden: &Path) -> Result<()> {
    let scene = suite::load_scene(root, entry)?;
    let mut params = suite::params(entry, &scene, ppm::Method::Path, REFERENCE_SEED)?;
    params.film.samples_per_pixel = entry.reference_spp;
    let rendered = suite::render(&scene, params, entry.reference_passes)?;
    std::fs::create_dir_all(golden.parent().context("golden path has a parent")?)?;
    film::write_exr(golden, &film::Frame::new(rendered.image.clone()))?;
    println!(
        "render-all: blessed {} ({} paths/pixel, {:.1} s) -> {}",
        entry.name,
        entry.reference_passes * entry.reference_spp,
        rendered.time.as_secs_f64(),
        golden.display()
    );
    Ok(())
}

fn check_scene(
    root: &Path,
    entry: &SuiteScene,
    golden: &Path,
    flags: &Flags,
    out_dir: &Path,
) -> Result<SceneReport> {
    let mut report = SceneReport {
        entry: entry.clone(),
        problem: None,
        methods: Vec::new(),
        reference_mean: 0.0,
        sheet_row: Vec::new(),
    };
    if !golden.exists() {
        report.problem = Some(format!(
            "golden reference {} is missing: run `cargo xtask render-all --bless {}` after checking the images",
            golden.display(),
            entry.name
        ));
        return Ok(report);
    }
    let reference = film::read_exr(golden)?;
    if (reference.width, reference.height) != (entry.width as usize, entry.height as usize) {
        report.problem = Some(format!(
            "golden reference is {}x{} but the suite asks for {}x{}: run `cargo xtask render-all --bless {}` after checking the images",
            reference.width, reference.height, entry.width, entry.height, entry.name
        ));
        return Ok(report);
    }
    report.reference_mean = reference.mean();
    let exposure = film::auto_exposure(&reference);
    film::write_preview(
        &out_dir.join(format!("{}-reference.png", entry.name)),
        &reference,
        film::Tonemap::linear(exposure),
        ZOOM,
    )?;
    report.sheet_row.push(scale(&reference, exposure));
    let scene = suite::load_scene(root, entry)?;
    let factor = if flags.full { FULL_FACTOR } else { 1 };
    for method in flags.methods() {
        let mask = suite::method_mask(&scene, method);
        let passes = suite::passes(entry, method) * factor;
        let rendered = suite::render(
            &scene,
            suite::params(entry, &scene, method, CHECK_SEED)?,
            passes,
        )?;
        let errors = film::errors(&rendered.image, &reference, Some(&mask))?;
        let tolerance = entry.tolerance.get(method.name()).copied();
        let perturbed = film::errors(&scale(&rendered.image, 1.1), &reference, Some(&mask))?;
        let stem = format!("{}-{}", entry.name, method.name());
        film::write_preview(
            &out_dir.join(format!("{stem}.png")),
            &rendered.image,
            film::Tonemap::linear(exposure),
            ZOOM,
        )?;
        report.sheet_row.push(scale(&rendered.image, exposure));
        let map = film::rel_mse_map(&rendered.image, &reference)?;
        film::write_false_colour(
            &out_dir.join(format!("{stem}-error.png")),
            entry.width as usize,
            &map,
            0.25,
            ZOOM,
        )?;
        let result = MethodResult {
            method,
            errors,
            tolerance,
            seconds: rendered.time.as_secs_f64(),
            passes,
            perturbed_fails: tolerance.is_some_and(|t| !within(&perturbed, &t)),
        };
        println!(
            "{:<20} {:<9} relMSE {:.5} (tol {}) mean ratio {:.4} {:>6.2} s  {}",
            entry.name,
            method.name(),
            errors.rel_mse,
            tolerance.map_or("none".to_string(), |t| format!(
                "{:.5}, mean ±{:.3}",
                t.rel_mse, t.mean
            )),
            errors.mean_ratio,
            result.seconds,
            if result.pass() { "ok" } else { "FAIL" }
        );
        report.methods.push(result);
    }
    Ok(report)
}

fn scale(image: &Image, factor: f32) -> Image {
    Image::new(
        image.width,
        image.height,
        image.pixels.iter().map(|p| p.map(|v| v * factor)).collect(),
    )
}

/// Renders every method with every calibration seed and prints suggested tolerances:
/// relMSE ≤ 1.5 × the largest seen, |mean ratio − 1| ≤ 1.5 × the largest seen + 0.005.
fn calibrate(root: &Path, entry: &SuiteScene, seeds: &[u64], flags: &Flags) -> Result<()> {
    let golden = golden_path(root, &entry.name);
    let reference = film::read_exr(&golden)
        .with_context(|| format!("run `cargo xtask render-all --bless {}` first", entry.name))?;
    let scene = suite::load_scene(root, entry)?;
    println!("# {}: calibration over seeds {seeds:?}", entry.name);
    let mut lines = Vec::new();
    for method in flags.methods() {
        let mask = suite::method_mask(&scene, method);
        let mut rel = Vec::new();
        let mut dev = Vec::new();
        for &seed in seeds {
            let rendered = suite::render(
                &scene,
                suite::params(entry, &scene, method, seed)?,
                suite::passes(entry, method),
            )?;
            let e = film::errors(&rendered.image, &reference, Some(&mask))?;
            rel.push(e.rel_mse);
            dev.push(e.mean_ratio - 1.0);
        }
        let max_rel = rel.iter().copied().fold(0.0, f64::max);
        let max_dev = dev.iter().map(|d| d.abs()).fold(0.0, f64::max);
        let (mean_rel, sd_rel) = mean_sd(&rel);
        println!(
            "#   {:<9} relMSE {} (mean {mean_rel:.5}, sd {sd_rel:.5}); mean ratio - 1: {}",
            method.name(),
            rel.iter()
                .map(|v| format!("{v:.5}"))
                .collect::<Vec<_>>()
                .join(" "),
            dev.iter()
                .map(|v| format!("{v:+.4}"))
                .collect::<Vec<_>>()
                .join(" ")
        );
        lines.push(format!(
            "tolerance.{} = {{ rel_mse = {:.4}, mean = {:.3} }}",
            quote_key(method.name()),
            1.5 * max_rel,
            1.5 * max_dev + 0.005
        ));
    }
    for line in lines {
        println!("{line}");
    }
    Ok(())
}

fn quote_key(name: &str) -> String {
    if name.contains('-') {
        format!("\"{name}\"")
    } else {
        name.to_string()
    }
}

fn mean_sd(values: &[f64]) -> (f64, f64) {
    let n = values.len().max(1) as f64;
    let mean = values.iter().sum::<f64>() / n;
    let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0).max(1.0);
    (mean, var.sqrt())
}

fn write_report(
    out_dir: &Path,
    reports: &[SceneReport],
    seconds: f64,
    flags: &Flags,
) -> Result<()> {
    let mut html = String::new();
    let mode = if flags.full {
        "--full"
    } else {
        "--quick (suite budgets)"
    };
    let _ = write!(
        html,
        "<!doctype html><html><head><meta charset=\"utf-8\"><title>render-all</title><style>\
         body{{font-family:sans-serif}} td,th{{padding:2px 8px;text-align:right}} .fail{{color:#c00;font-weight:bold}} \
         .ok{{color:#080}} img{{image-rendering:pixelated;margin:2px}} figure{{display:inline-block;margin:4px}} \
         figcaption{{font-size:small;text-align:center}}</style></head><body>\
         <h1>cargo xtask render-all</h1><p>Mode {mode}; {} scene(s) in {seconds:.1} s. Golden references are \
         path-traced (NEE + MIS); relMSE = mean (x − ref)² / (ref² + {}); error maps show per-pixel relMSE, \
         0 (blue) to 0.25 (red). The figures leave out pixels that see an emitter directly (and their \
         neighbours): they measure light transport, not the lamp's outline. A method passes when relMSE ≤ tol and |mean ratio − 1| ≤ mean tol. \
         “×1.1 trips” says whether the same image scaled by 1.1 would fail (the check catches a 10 % regression).</p>",
        reports.len(),
        film::REL_MSE_EPSILON
    );
    for report in reports {
        let name = &report.entry.name;
        let _ = write!(
            html,
            "<h2>{name}</h2><p><code>{}</code>, {}×{}</p>",
            report.entry.path.display(),
            report.entry.width,
            report.entry.height
        );
        if let Some(problem) = &report.problem {
            let _ = write!(html, "<p class=\"fail\">{problem}</p>");
            continue;
        }
        let _ = write!(
            html,
            "<div><figure><img src=\"{name}-reference.png\"><figcaption>reference (path, mean {:.4})</figcaption></figure>",
            report.reference_mean
        );
        for m in &report.methods {
            let _ = write!(
                html,
                "<figure><img src=\"{name}-{0}.png\"><figcaption>{0}</figcaption></figure>",
                m.method.name()
            );
        }
        let _ = write!(
            html,
            "</div><div><figure style=\"width:{}px\"></figure>",
            report.entry.width as usize * ZOOM + 4
        );
        for m in &report.methods {
            let _ = write!(
                html,
                "<figure><img src=\"{name}-{0}-error.png\"><figcaption>{0} error</figcaption></figure>",
                m.method.name()
            );
        }
        html.push_str("</div><table><tr><th>method</th><th>passes</th><th>time s</th><th>RMSE</th><th>relMSE</th><th>tol</th><th>mean ratio</th><th>mean tol</th><th>×1.1 trips</th><th>result</th></tr>");
        for m in &report.methods {
            let (tol, mean_tol) = m
                .tolerance
                .map_or(("none".to_string(), "none".to_string()), |t| {
                    (format!("{:.5}", t.rel_mse), format!("±{:.3}", t.mean))
                });
            let _ = write!(
                html,
                "<tr><td>{}</td><td>{}</td><td>{:.2}</td><td>{:.5}</td><td>{:.5}</td><td>{tol}</td><td>{:.4}</td><td>{mean_tol}</td><td>{}</td><td class=\"{}\">{}</td></tr>",
                m.method.name(),
                m.passes,
                m.seconds,
                m.errors.rmse,
                m.errors.rel_mse,
                m.errors.mean_ratio,
                if m.perturbed_fails { "yes" } else { "no" },
                if m.pass() { "ok" } else { "fail" },
                if m.pass() { "pass" } else { "FAIL" }
            );
        }
        html.push_str("</table>");
    }
    html.push_str("</body></html>\n");
    let path = out_dir.join("report.html");
    std::fs::write(&path, html).with_context(|| format!("writing {}", path.display()))
}
