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

/// Line colours of the plots, per method in `ppm::Method::ALL` order.
const COLOURS: [(u8, u8, u8); 5] = [
    (31, 119, 180),
    (255, 127, 14),
    (44, 160, 44),
    (214, 39, 40),
    (100, 100, 100),
];

struct Flags {
    scene: String,
    budgets: Vec<f64>,
    methods: Vec<ppm::Method>,
    photons: u32,
    seed: u64,
    out: Option<PathBuf>,
    quick: bool,
    sweep: bool,
    replot: bool,
    budget: f64,
    pointwise: Option<u32>,
    film: Option<(u32, u32)>,
    clock: Clock,
    overrides: Overrides,
}

/// What a budget's seconds measure.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Clock {
    /// Wall-clock seconds (the default).
    Wall,
    /// Process CPU seconds (user + system, from `/proc/self/stat`) divided by the number of
    /// rayon threads: on an idle machine the same as wall-clock, on a shared one what the
    /// method would have taken alone. For comparisons while other jobs run.
    Cpu,
}

impl Clock {
    fn now(self) -> (Instant, f64) {
        (
            Instant::now(),
            if self == Clock::Cpu {
                process_cpu_seconds()
            } else {
                0.0
            },
        )
    }

    fn since(self, (wall, cpu): (Instant, f64)) -> Duration {
        match self {
            Clock::Wall => wall.elapsed(),
            Clock::Cpu => {
                Duration::from_secs_f64(((process_cpu_seconds() - cpu) / threads()).max(0.0))
            }
        }
    }
}

/// The threads the renderer uses: rayon's default pool size.
fn threads() -> f64 {
    std::env::var("RAYON_NUM_THREADS")
        .ok()
        .and_then(|v| v.parse::<usize>().ok())
        .filter(|&n| n > 0)
        .or_else(|| std::thread::available_parallelism().ok().map(usize::from))
        .unwrap_or(1) as f64
}

/// CPU seconds (user + system) used by this process so far, from `/proc/self/stat`
/// (fields 14 and 15, in clock ticks of 10 ms); 0 where it cannot be read.
fn process_cpu_seconds() -> f64 {
    let Ok(stat) = std::fs::read_to_string("/proc/self/stat") else {
        return 0.0;
    };
    // The command name (field 2) may contain spaces: count fields after its closing ')'.
    let Some(rest) = stat.rsplit_once(')').map(|(_, r)| r) else {
        return 0.0;
    };
    let fields: Vec<&str> = rest.split_whitespace().collect();
    let ticks = |i: usize| {
        fields
            .get(i)
            .and_then(|f| f.parse::<f64>().ok())
            .unwrap_or(0.0)
    };
    // After ')': field 3 is index 0, so utime (14) is index 11 and stime (15) index 12.
    (ticks(11) + ticks(12)) / 100.0
}

/// Render parameters given on the command line or varied by the sweep: `(name, text)` pairs
/// that `ppm::RenderParams::set` reads (names, parsing and ranges are defined there).
#[derive(Clone, Debug, Default)]
struct Overrides(Vec<(&'static str, String)>);

impl Overrides {
    /// One parameter.
    fn one(name: &str, value: impl ToString) -> Self {
        let mut o = Self::default();
        o.push(name, value.to_string())
            .expect("a parameter of ppm::PARAMS");
        o
    }

    /// Adds (or replaces) the parameter called `name` (with `-` or `_`).
    fn push(&mut self, name: &str, value: String) -> Result<()> {
        let param = ppm::param(name).with_context(|| format!("unknown parameter `{name}`"))?;
        self.0.retain(|(n, _)| *n != param.name);
        self.0.push((param.name, value));
        Ok(())
    }

    fn apply(&self, params: &mut ppm::RenderParams) -> Result<()> {
        for (name, value) in &self.0 {
            params.set(name, value)?;
        }
        Ok(())
    }

    /// Whether every parameter given is one of `names`.
    fn only(&self, names: &[&str]) -> bool {
        self.0.iter().all(|(n, _)| names.contains(n))
    }

    fn label(&self, defaults: &ppm::RenderParams) -> Result<String> {
        let mut p = *defaults;
        self.apply(&mut p)?;
        Ok(format!(
            "alpha={:.3} ff={} k={} merge={} geometry={}",
            p.alpha,
            p.freq_fraction,
            k_name(p.kernel_k),
            value_of("freq_merge", &p),
            value_of("freq_geometry", &p),
        ))
    }
}

/// The text of the parameter called `name` in `params`.
fn value_of(name: &str, params: &ppm::RenderParams) -> String {
    ppm::param(name).map_or_else(String::new, |p| p.get(params))
}

/// K by the name of its constant where it has one.
fn k_name(k: f64) -> String {
    if (k - ppm::K_POSTER).abs() < 1e-12 {
        "poster".to_string()
    } else if (k - ppm::K_STRICT).abs() < 1e-12 {
        "strict".to_string()
    } else {
        format!("{k}")
    }
}

fn parse_list<T>(text: &str, f: impl Fn(&str) -> Result<T>) -> Result<Vec<T>> {
    text.split(',')
        .filter(|s| !s.is_empty())
        .map(|s| f(s.trim()))
        .collect()
}

impl Flags {
    fn parse(args: &[String]) -> Result<Self> {
        let mut flags = Flags {
            scene: String::new(),
            budgets: vec![2.0, 4.0, 8.0, 16.0, 32.0],
            methods: ppm::Method::ALL.to_vec(),
            photons: 100_000,
            seed: 1,
            out: None,
            quick: false,
            sweep: false,
            replot: false,
            budget: 8.0,
            clock: Clock::Wall,
            film: None,
            pointwise: None,
            overrides: Overrides::default(),
        };
        let mut methods_given = false;
        let mut it = args.iter();
        while let Some(arg) = it.next() {
            let mut value = || it.next().with_context(|| format!("{arg} needs a value"));
            match arg.as_str() {
                "--scene" => flags.scene = value()?.clone(),
                "--budgets" => flags.budgets = parse_list(value()?, |s| Ok(s.parse::<f64>()?))?,
                "--budget" => flags.budget = value()?.parse()?,
                "--methods" => {
                    methods_given = true;
                    flags.methods = parse_list(value()?, |s| {
                        ppm::Method::from_name(s).with_context(|| format!("unknown method `{s}`"))
                    })?;
                }
                "--photons" => flags.photons = value()?.parse()?,
                "--seed" => flags.seed = value()?.parse()?,
                "--out" => flags.out = Some(PathBuf::from(value()?)),
                "--quick" => flags.quick = true,
                "--sweep" => flags.sweep = true,
                "--replot" => flags.replot = true,
                "--pointwise" => flags.pointwise = Some(value()?.parse()?),
                "--film" => {
                    let v = value()?;
                    let (w, h) = v
                        .split_once('x')
                        .with_context(|| format!("--film takes WIDTHxHEIGHT, not `{v}`"))?;
                    let (w, h): (u32, u32) = (w.parse()?, h.parse()?);
                    if w == 0 || h == 0 || w > 4096 || h > 4096 {
                        bail!("--film {v}: each side must be in [1, 4096]");
                    }
                    flags.film = Some((w, h));
                }
                "--clock" => {
                    flags.clock = match value()?.as_str() {
                        "wall" => Clock::Wall,
                        "cpu" => Clock::Cpu,
                        other => bail!("--clock takes wall or cpu, not `{other}`"),
                    };
                }
                // Any render parameter by its name, e.g. --alpha 0.5, --kernel-k poster,
                // --freq-geometry off.
                other if other.starts_with("--") && ppm::param(&other[2..]).is_some() => {
                    flags.overrides.push(&other[2..], value()?.clone())?;
                }
                other => bail!("converge: unknown flag `{other}`"),
            }
        }
        if flags.scene.is_empty() {
            bail!("converge: --scene NAME is required (a name from tests/scenes.toml)");
        }
        if flags.quick {
            flags.budgets = vec![1.0, 2.0];
            flags.budget = 1.0;
        }
        if flags.sweep && !methods_given {
            flags.methods = vec![ppm::Method::FreqPpm, ppm::Method::Ppm];
        }
        if flags
            .budgets
            .iter()
            .any(|b| b.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater))
        {
            bail!("converge: budgets must be positive seconds");
        }
        flags.budgets.sort_by(f64::total_cmp);
        if flags.film.is_some() && flags.pointwise.is_none() {
            bail!(
                "converge: --film needs --pointwise (the golden references have the suite's film size)"
            );
        }
        if flags.pointwise.is_some()
            && flags
                .methods
                .iter()
                .any(|m| !matches!(m, ppm::Method::Ppm | ppm::Method::FreqPpm))
        {
            bail!("converge: --pointwise needs --methods ppm,freq (the fixed-hitpoint methods)");
        }
        Ok(flags)
    }
}

/// Error restricted to each mask.
struct Masks {
    names: [&'static str; 3],
    masks: [Vec<bool>; 3],
}

/// One snapshot of one method.
struct Row {
    method: ppm::Method,
    budget: f64,
    seconds: f64,
    passes: u32,
    photons: u64,
    all: Errors,
    masked: [Errors; 3],
    /// The pointwise reference's own noise in relMSE units (whole image, then the three masks;
    /// NaN against a golden reference): the part of `all.rel_mse` and `masked[i].rel_mse` that
    /// the reference, not the method, contributes.
    noise: [f64; 4],
}

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
        let mut renderer = ppm::Renderer::new(&scene, params).context("render parameters")?;
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
    scene: &geometry::Scene,
    method: ppm::Method,
    flags: &Flags,
) -> Result<ppm::RenderParams> {
    let mut params = suite::params(entry, scene, method, flags.seed)?;
    params.photons_per_pass = flags.photons;
    flags.overrides.apply(&mut params)?;
    Ok(params)
}

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

/// Least-squares slope of y over x.
fn slope(points: &[(f64, f64)]) -> f64 {
    let n = points.len() as f64;
    if n < 2.0 {
        return f64::NAN;
    }
    let mx = points.iter().map(|p| p.0).sum::<f64>() / n;
    let my = points.iter().map(|p| p.1).sum::<f64>() / n;
    let sxy: f64 = points.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let sxx: f64 = points.iter().map(|p| (p.0 - mx).powi(2)).sum();
    sxy / sxx
}

/// The three masks, from a camera ray through each pixel centre and the reference image:
/// - glossy: the first surface is glossy, a mirror or a dielectric;
/// - caustic (high-frequency diffuse): the first surface is diffuse and the reference's
///   luminance differs from its 5×5 box blur by more than 25 % (caustics, and also shadow and
///   contact edges);
/// - low-frequency: every other diffuse pixel (smoothly lit, directly or indirectly).
///
/// Pixels that see no surface or an emitter (or neighbour one, see
/// [`suite::transport_mask`]) belong to no mask.
fn build_masks(scene: &geometry::Scene, reference: &Image) -> Masks {
    let (w, h) = (reference.width, reference.height);
    let lum: Vec<f64> = reference
        .pixels
        .iter()
        .map(|p| 0.2126 * f64::from(p[0]) + 0.7152 * f64::from(p[1]) + 0.0722 * f64::from(p[2]))
        .collect();
    let mut low = vec![false; w * h];
    let mut caustic = vec![false; w * h];
    let mut glossy = vec![false; w * h];
    for y in 0..h {
        for x in 0..w {
            let idx = y * w + x;
            let ray = scene
                .camera()
                .generate_ray(Vec2::new(x as f32 + 0.5, y as f32 + 0.5), Vec2::splat(0.5));
            let Some(hit) = scene.intersect(&ray) else {
                continue;
            };
            let Some(material) = scene.material(hit.material) else {
                continue;
            };
            if material.emission.max_element() > 0.0 {
                continue;
            }
            match material.kind {
                geometry::MaterialKind::Diffuse { .. } => {
                    let (mut sum, mut n) = (0.0, 0.0);
                    for yy in y.saturating_sub(2)..(y + 3).min(h) {
                        for xx in x.saturating_sub(2)..(x + 3).min(w) {
                            sum += lum[yy * w + xx];
                            n += 1.0;
                        }
                    }
                    let blur = sum / n;
                    if (lum[idx] - blur).abs() > 0.25 * blur.max(1e-6) {
                        caustic[idx] = true;
                    } else {
                        low[idx] = true;
                    }
                }
                _ => glossy[idx] = true,
            }
        }
    }
    let transport = suite::transport_mask(scene);
    for mask in [&mut low, &mut caustic, &mut glossy] {
        for (m, t) in mask.iter_mut().zip(&transport) {
            *m &= *t;
        }
    }
    Masks {
        names: ["low", "caustic", "glossy"],
        masks: [low, caustic, glossy],
    }
}

/// The masks as one PNG: green = low-frequency, red = caustic / high-frequency, blue = glossy.
fn write_masks(path: &Path, masks: &Masks, width: usize) -> Result<()> {
    let n = masks.masks[0].len();
    let pixels = (0..n)
        .map(|i| {
            let f = |m: usize| if masks.masks[m][i] { 1.0 } else { 0.0 };
            [f(1), 0.6 * f(0), f(2)]
        })
        .collect();
    film::write_preview(
        path,
        &Image::new(width, n / width, pixels),
        film::Tonemap::linear(1.0),
        3,
    )?;
    Ok(())
}

/// Radius map (all photon mappers), frequency radius and held-by-floor maps (frequency methods).
fn write_maps(renderer: &ppm::Renderer<'_>, out: &Path, stem: &str, width: usize) -> Result<()> {
    if let Some(radius) = renderer.aov(ppm::Aov::Radius) {
        let max = percentile(&radius, 0.99);
        film::write_false_colour(
            &out.join(format!("{stem}-radius.png")),
            width,
            &radius,
            max,
            3,
        )?;
        println!("  radius map: 99th percentile {max:.5} (red)");
    }
    if let Some(held) = renderer.aov(ppm::Aov::FreqHeld) {
        film::write_false_colour(&out.join(format!("{stem}-held.png")), width, &held, 1.0, 3)?;
        let share = held.iter().map(|&v| f64::from(v)).sum::<f64>() / held.len().max(1) as f64;
        println!(
            "  held by the frequency floor: {:.1} % of hitpoints",
            100.0 * share
        );
    }
    if let Some(freq) = renderer.aov(ppm::Aov::FreqRadius) {
        let max = percentile(&freq, 0.99);
        film::write_false_colour(
            &out.join(format!("{stem}-freq-radius.png")),
            width,
            &freq,
            max,
            3,
        )?;
    }
    Ok(())
}

fn percentile(values: &[f32], q: f64) -> f32 {
    let mut v: Vec<f32> = values
        .iter()
        .copied()
        .filter(|x| x.is_finite() && *x > 0.0)
        .collect();
    if v.is_empty() {
        return 1.0;
    }
    v.sort_by(f32::total_cmp);
    v[((v.len() as f64 * q) as usize).min(v.len() - 1)]
}

fn write_csv(path: &Path, entry: &SuiteScene, masks: &Masks, rows: &[Row]) -> Result<()> {
    let mut csv =
        String::from("scene,method,budget_s,seconds,passes,photons,rmse,rel_mse,mean_ratio");
    for name in masks.names {
        let _ = write!(csv, ",rmse_{name},rel_mse_{name}");
    }
    csv.push_str(",ref_noise_rel_mse");
    for name in masks.names {
        let _ = write!(csv, ",ref_noise_rel_mse_{name}");
    }
    csv.push('\n');
    for r in rows {
        let _ = write!(
            csv,
            "{},{},{},{:.3},{},{},{:.6e},{:.6e},{:.5}",
            entry.name,
            r.method.name(),
            r.budget,
            r.seconds,
            r.passes,
            r.photons,
            r.all.rmse,
            r.all.rel_mse,
            r.all.mean_ratio
        );
        for m in &r.masked {
            let _ = write!(csv, ",{:.6e},{:.6e}", m.rmse, m.rel_mse);
        }
        for n in r.noise {
            let _ = write!(csv, ",{n:.6e}");
        }
        csv.push('\n');
    }
    std::fs::write(path, csv).with_context(|| format!("writing {}", path.display()))
}

/// Reads the rows back from a CSV written by [`write_csv`] (for `--replot`).
fn read_csv(path: &Path) -> Result<Vec<Row>> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let none = Errors {
        rmse: f64::NAN,
        rel_mse: f64::NAN,
        mean_ratio: f64::NAN,
    };
    let mut rows = Vec::new();
    for line in text.lines().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        if f.len() < 9 {
            continue;
        }
        rows.push(Row {
            method: ppm::Method::from_name(f[1])
                .with_context(|| format!("unknown method `{}`", f[1]))?,
            budget: f[2].parse()?,
            seconds: f[3].parse()?,
            passes: f[4].parse()?,
            photons: f[5].parse()?,
            all: Errors {
                rmse: f[6].parse()?,
                rel_mse: f[7].parse()?,
                mean_ratio: f[8].parse()?,
            },
            masked: [none; 3],
            noise: [f64::NAN; 4],
        });
    }
    Ok(rows)
}

/// The two error plots of a scene: relMSE against seconds (`NAME-time.svg`) and against photons
/// emitted (`NAME-photons.svg`, the equal-photon-count comparison).
fn plot_error_curves(out: &Path, name: &str, rows: &[Row]) -> Result<()> {
    plot(
        &out.join(format!("{name}-time.svg")),
        rows,
        |r| r.seconds,
        false,
    )?;
    plot(
        &out.join(format!("{name}-photons.svg")),
        rows,
        |r| r.photons as f64,
        true,
    )
}

/// relMSE against `x(row)` on log-log axes, one line per method; `photon_mappers_only` drops
/// the path tracer (which emits no photons).
fn plot(
    path: &Path,
    rows: &[Row],
    x: impl Fn(&Row) -> f64,
    photon_mappers_only: bool,
) -> Result<()> {
    use plotters::prelude::*;
    let x_label = if photon_mappers_only {
        "photons emitted"
    } else {
        "seconds"
    };
    let pts = |m: ppm::Method| -> Vec<(f64, f64)> {
        rows.iter()
            .filter(|r| r.method == m && x(r) > 0.0 && r.all.rel_mse > 0.0)
            .map(|r| (x(r).log10(), r.all.rel_mse.log10()))
            .collect()
    };
    let methods: Vec<ppm::Method> = ppm::Method::ALL
        .into_iter()
        .filter(|m| !(photon_mappers_only && *m == ppm::Method::Path))
        .filter(|m| !pts(*m).is_empty())
        .collect();
    let all: Vec<(f64, f64)> = methods.iter().flat_map(|m| pts(*m)).collect();
    if all.is_empty() {
        return Ok(());
    }
    let (x0, x1) = bounds(all.iter().map(|p| p.0));
    let (y0, y1) = bounds(all.iter().map(|p| p.1));
    // Text is added to the SVG by hand afterwards: plotters' text needs a font backend, and
    // the workspace builds plotters without fonts.
    let mut texts: Vec<(i32, i32, &'static str, String, String)> = Vec::new();
    let root = SVGBackend::new(path, (640, 480)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| anyhow::anyhow!("{e:?}"))?;
    let area = root.margin(20, 50, 70, 20);
    let mut chart = ChartBuilder::on(&area)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(|e| anyhow::anyhow!("{e:?}"))?;
    // Decade grid lines (no text: the SVG backend is built without fonts; the axes are
    // described in docs/convergence.md).
    for d in (x0.floor() as i32)..=(x1.ceil() as i32) {
        let d = f64::from(d);
        if d >= x0 && d <= x1 {
            chart
                .draw_series(LineSeries::new([(d, y0), (d, y1)], BLACK.mix(0.25)))
                .map_err(|e| anyhow::anyhow!("{e:?}"))?;
            let (px, py) = chart.backend_coord(&(d, y0));
            texts.push((px, py + 16, "middle", "#000".into(), format!("1e{d}")));
        }
    }
    for d in (y0.floor() as i32)..=(y1.ceil() as i32) {
        let d = f64::from(d);
        if d >= y0 && d <= y1 {
            chart
                .draw_series(LineSeries::new([(x0, d), (x1, d)], BLACK.mix(0.25)))
                .map_err(|e| anyhow::anyhow!("{e:?}"))?;
            let (px, py) = chart.backend_coord(&(x0, d));
            texts.push((px - 4, py + 4, "end", "#000".into(), format!("1e{d}")));
        }
    }
    chart
        .draw_series(LineSeries::new(
            [(x0, y0), (x1, y0), (x1, y1), (x0, y1), (x0, y0)],
            BLACK,
        ))
        .map_err(|e| anyhow::anyhow!("{e:?}"))?;
    let (bx, by) = chart.backend_coord(&(x1, y0));
    texts.push((
        bx,
        by + 34,
        "end",
        "#000".into(),
        format!("{x_label} (log scale)"),
    ));
    let (tx, ty) = chart.backend_coord(&(x0, y1));
    texts.push((
        tx + 4,
        ty - 6,
        "start",
        "#000".into(),
        "relMSE (log scale)".into(),
    ));
    for (i, m) in methods.iter().copied().enumerate() {
        let (r, g, b) = COLOURS[ppm::Method::ALL.iter().position(|x| *x == m).unwrap_or(0)];
        let (lx, ly) = chart.backend_coord(&(x1, y1));
        texts.push((
            lx - 8,
            ly + 18 + 16 * i as i32,
            "end",
            format!("#{r:02x}{g:02x}{b:02x}"),
            m.name().to_string(),
        ));
        let colour = RGBColor(r, g, b);
        chart
            .draw_series(LineSeries::new(pts(m), colour.stroke_width(2)))
            .map_err(|e| anyhow::anyhow!("{e:?}"))?;
        chart
            .draw_series(
                pts(m)
                    .into_iter()
                    .map(|p| Circle::new(p, 3, colour.filled())),
            )
            .map_err(|e| anyhow::anyhow!("{e:?}"))?;
    }
    root.present().map_err(|e| anyhow::anyhow!("{e:?}"))?;
    drop(chart);
    drop(root);
    let svg =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let mut text = String::new();
    for (x, y, anchor, colour, label) in texts {
        let _ = writeln!(
            text,
            "<text x=\"{x}\" y=\"{y}\" font-family=\"sans-serif\" font-size=\"13\" text-anchor=\"{anchor}\" fill=\"{colour}\">{label}</text>"
        );
    }
    let svg = svg.replace("</svg>", &format!("{text}</svg>"));
    std::fs::write(path, svg).with_context(|| format!("writing {}", path.display()))
}

/// Padded bounds of log values.
fn bounds(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
        (a.min(v), b.max(v))
    });
    let pad = ((hi - lo) * 0.05).max(0.05);
    (lo - pad, hi + pad)
}

/// One-at-a-time parameter sweep at one budget.
fn sweep(
    scene: &geometry::Scene,
    entry: &SuiteScene,
    reference: &Image,
    masks: &Masks,
    flags: &Flags,
    out: &Path,
) -> Result<bool> {
    let transport = suite::transport_mask(scene);
    let mut variants: Vec<Overrides> = vec![Overrides::default()];
    for alpha in [0.5, 2.0 / 3.0, 0.8] {
        variants.push(Overrides::one("alpha", alpha));
    }
    for ff in [0.05, 0.2] {
        variants.push(Overrides::one("freq_fraction", ff));
    }
    for k in [
        ppm::K_POSTER,
        4.0 * ppm::K_STRICT,
        2.0 * ppm::K_STRICT,
        0.5 * ppm::K_STRICT,
    ] {
        variants.push(Overrides::one("kernel_k", k));
    }
    variants.push(Overrides::one("freq_geometry", "off"));
    variants.push(Overrides::one("freq_merge", "poster-max"));
    let mut csv = String::from(
        "scene,method,budget_s,alpha,freq_fraction,kernel_k,freq_merge,freq_geometry,seconds,passes,rel_mse,rmse,mean_ratio,rel_mse_low,rel_mse_caustic,rel_mse_glossy\n",
    );
    for &method in &flags.methods {
        for v in &variants {
            if !method.uses_frequency() && !v.only(&["alpha"]) {
                continue;
            }
            let mut params = base_params(entry, scene, method, flags)?;
            v.apply(&mut params)?;
            let mut renderer = ppm::Renderer::new(scene, params).context("render parameters")?;
            let mut elapsed = Duration::ZERO;
            while elapsed.as_secs_f64() < flags.budget {
                let start = flags.clock.now();
                renderer.iterate();
                elapsed += flags.clock.since(start);
            }
            let image = Image::new(reference.width, reference.height, renderer.image());
            let e = film::errors(&image, reference, Some(&transport))?;
            let m = [0, 1, 2].map(|i| {
                film::errors(&image, reference, Some(&masks.masks[i])).expect("sizes match")
            });
            println!(
                "sweep {} {:<9} {:<48} relMSE {:.5} [low {:.5} caustic {:.5} glossy {:.5}] mean {:.4} ({} passes)",
                entry.name,
                method.name(),
                v.label(&params)?,
                e.rel_mse,
                m[0].rel_mse,
                m[1].rel_mse,
                m[2].rel_mse,
                e.mean_ratio,
                renderer.passes()
            );
            let _ = writeln!(
                csv,
                "{},{},{},{:.4},{},{},{},{},{:.3},{},{:.6e},{:.6e},{:.5},{:.6e},{:.6e},{:.6e}",
                entry.name,
                method.name(),
                flags.budget,
                params.alpha,
                params.freq_fraction,
                k_name(params.kernel_k),
                value_of("freq_merge", &params),
                value_of("freq_geometry", &params),
                elapsed.as_secs_f64(),
                renderer.passes(),
                e.rel_mse,
                e.rmse,
                e.mean_ratio,
                m[0].rel_mse,
                m[1].rel_mse,
                m[2].rel_mse
            );
        }
    }
    let path = out.join(format!("{}-sweep.csv", entry.name));
    std::fs::write(&path, csv).with_context(|| format!("writing {}", path.display()))?;
    println!("converge: wrote {}", path.display());
    Ok(true)
}
