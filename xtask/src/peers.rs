//! `cargo xtask peers`: equal-time comparison of fppm's methods with Mitsuba 3 (`path`, and
//! `ptracer`, a light tracer) on the scenes of `scenes/peers/`, scored against a pixel-averaged
//! Mitsuba `path` reference whose own noise is measured from two independent halves.
//!
//! Mitsuba runs from a Python venv this command creates (`target/peers-venv`, `pip install
//! mitsuba drjit numpy`); nothing in the normal test suite needs it. Each scene is exported to
//! Mitsuba XML from fppm's own loaded description ([`write_mitsuba`]), so both renderers read
//! the same geometry, materials and camera.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use anyhow::{Context, Result, bail};
use glam::Vec3;

use crate::converge::{noise_rel_mse, reference_from_halves};
use film::Image;

pub(crate) const HELP: &str = "\
cargo xtask peers [--scenes a,b,...] [--seconds 60] [--film WxH] [--threads 2]
                  [--methods freq-sppm,sppm,freq,ppm] [--peers path,ptracer]
                  [--reference-seconds 1200] [--out DIR] [--fppm-args \"...\"] [--paths N]
                  [--fppm FILE] [--reference mitsuba|luxcore]

Renders every scene of scenes/peers/ (or those named: a name of scenes/peers/, `veach-mis` for
../shared/scenes/pbrt-v4/veach-mis/veach-mis.pbrt, or the path of any scene file fppm reads,
e.g. ../shared/scenes/cornell_box/CornellBox-Water.obj) with each fppm method and each Mitsuba 3
integrator for the same wall-clock time, one renderer at a time, all with --threads threads,
and scores them against a Mitsuba `path` reference (`volpath` for a scene with participating
media; max_depth the scene's own, as fppm renders it, else unlimited) rendered as two
independent halves of --reference-seconds / 2 each (kept in DIR/SCENE/ and reused; delete them
to re-render). Reports relMSE (mean of (x - ref)^2 / (ref^2 + 0.01)) over all pixels, over
the pixels whose first hit is diffuse and over those whose first hit is a mirror or glass, the
reference's own noise in the same units, and the image mean over the reference's. A method may
carry switches of its own after `+`: `sppm+no-light-tracing` renders `--method sppm
--no-light-tracing`, `freq-sppm+photons-per-pass=400k` `--photons-per-pass=400k`. Writes
DIR/SCENE/*.exr and DIR/table.md; DIR defaults to target/peers. The Mitsuba venv is created in target/peers-venv on first use (pip install
mitsuba drjit numpy; the llvm_ad_rgb variant needs Debian's libllvm19).

--paths N (e.g. 117M) compares at an equal path count instead of equal time: each fppm method
traces N light paths (--passes and --photons-per-pass, at most 10^6 per pass) and each Mitsuba
integrator renders N / (width x height) samples per pixel (for `ptracer`, N light paths); use it
with --methods light --peers ptracer to compare the two light tracers' variance.

--fppm FILE runs that fppm binary instead of building this checkout's: another build scored
against the same references (copy DIR/SCENE/ of the first run into the second's --out to reuse
them).

--reference luxcore renders the reference's halves with LuxCore's path tracer and its PhotonGI
caustic cache (pip install pyluxcore into the venv on first use) as DIR/SCENE/lux-a.exr and
lux-b.exr: the reference of caustics seen in a mirror or through water, which Mitsuba's `path`
does not resolve. `--peers luxcore` adds the same LuxCore renderer as an equal-time peer. The LuxCore export
(xtask/src/luxcore.rs) carries diffuse, mirror and dielectric materials and emissive surfaces,
and refuses anything else by name.";

/// The scenes of the comparison, in `scenes/peers/`.
const SCENES: [&str; 4] = [
    "box-glass-mirror",
    "ring-caustic",
    "room-indirect",
    "pool-caustic",
];

struct Flags {
    scenes: Vec<String>,
    seconds: f64,
    film: Option<(u32, u32)>,
    threads: u32,
    methods: Vec<String>,
    peers: Vec<String>,
    reference_seconds: f64,
    out: Option<PathBuf>,
    fppm_args: Vec<String>,
    /// Light paths per renderer, instead of equal time.
    paths: Option<u64>,
    /// Another fppm binary to run instead of this checkout's.
    fppm: Option<PathBuf>,
    /// Who renders the reference: Mitsuba's `path` (or `volpath`), or LuxCore.
    reference: Reference,
}

/// The renderer of a comparison's reference.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Reference {
    /// Mitsuba 3 `path` (`volpath` with media), halves `ref-a.exr` and `ref-b.exr`.
    Mitsuba,
    /// LuxCore's path tracer with its caustic cache (`crate::luxcore`), halves `lux-a.exr`
    /// and `lux-b.exr`: the reference of caustics seen through specular surfaces, which
    /// Mitsuba's path tracer does not resolve.
    Luxcore,
}

impl Flags {
    fn parse(args: &[String]) -> Result<Self> {
        let mut flags = Flags {
            scenes: SCENES.iter().map(|s| (*s).to_owned()).collect(),
            seconds: 60.0,
            film: None,
            threads: 2,
            methods: ["freq-sppm", "sppm", "freq", "ppm"]
                .map(str::to_owned)
                .to_vec(),
            peers: ["path", "ptracer"].map(str::to_owned).to_vec(),
            reference_seconds: 1200.0,
            out: None,
            fppm_args: Vec::new(),
            paths: None,
            fppm: None,
            reference: Reference::Mitsuba,
        };
        let mut it = args.iter();
        while let Some(flag) = it.next() {
            let mut value = || {
                it.next()
                    .cloned()
                    .with_context(|| format!("{flag} needs a value"))
            };
            let list = |v: String| v.split(',').map(str::to_owned).collect::<Vec<_>>();
            match flag.as_str() {
                "--scenes" => flags.scenes = list(value()?),
                "--seconds" => flags.seconds = value()?.parse().context("--seconds")?,
                "--film" => {
                    let v = value()?;
                    let (w, h) = v.split_once('x').context("--film WxH")?;
                    flags.film = Some((w.parse()?, h.parse()?));
                }
                "--threads" => flags.threads = value()?.parse().context("--threads")?,
                "--methods" => flags.methods = list(value()?),
                "--peers" => {
                    let v = value()?;
                    flags.peers = if v.is_empty() { Vec::new() } else { list(v) };
                }
                "--reference-seconds" => {
                    flags.reference_seconds = value()?.parse().context("--reference-seconds")?;
                }
                "--out" => flags.out = Some(PathBuf::from(value()?)),
                "--fppm-args" => {
                    flags.fppm_args = value()?.split_whitespace().map(str::to_owned).collect();
                }
                "--paths" => flags.paths = Some(parse_count(&value()?)?),
                "--fppm" => flags.fppm = Some(PathBuf::from(value()?)),
                "--reference" => {
                    flags.reference = match value()?.as_str() {
                        "mitsuba" => Reference::Mitsuba,
                        "luxcore" => Reference::Luxcore,
                        other => bail!("--reference {other}: mitsuba or luxcore"),
                    }
                }
                other => bail!("unknown flag {other} (see cargo xtask peers --help)"),
            }
        }
        if !(flags.seconds > 0.0 && flags.reference_seconds > 0.0) {
            bail!("--seconds and --reference-seconds must be positive");
        }
        Ok(flags)
    }
}

/// A scene of the comparison: a name of `scenes/peers/`, or the path of any scene file fppm
/// reads (named by its file stem in the table and the output folder).
fn scene_file(root: &Path, arg: &str) -> (String, PathBuf) {
    if arg == "veach-mis" {
        // Veach's MIS plates, read in place from the shared pbrt-v4 scenes.
        return (
            arg.to_owned(),
            root.join("../shared/scenes/pbrt-v4/veach-mis/veach-mis.pbrt"),
        );
    }
    if arg.contains('/') || arg.contains('.') {
        let path = root.join(arg);
        let stem = path
            .file_stem()
            .map_or_else(|| arg.to_owned(), |s| s.to_string_lossy().into_owned());
        (stem, path)
    } else {
        (
            arg.to_owned(),
            root.join("scenes/peers").join(format!("{arg}.toml")),
        )
    }
}

/// A count written as `117000000`, `117M` or `500k`.
fn parse_count(text: &str) -> Result<u64> {
    let (digits, scale) = match text.strip_suffix(['M', 'm']) {
        Some(d) => (d, 1_000_000.0),
        None => match text.strip_suffix(['k', 'K']) {
            Some(d) => (d, 1_000.0),
            None => (text, 1.0),
        },
    };
    let value: f64 = digits.parse().with_context(|| format!("--paths {text}"))?;
    let count = (value * scale).round();
    if !(1.0..1e15).contains(&count) {
        bail!("--paths {text} must be a positive count");
    }
    Ok(count as u64)
}

/// `--passes` and `--photons-per-pass` for `paths` light paths, at most 10⁶ per pass: the
/// passes and the paths they really trace.
fn passes_for(paths: u64) -> (u64, u64) {
    let passes = paths.div_ceil(1_000_000);
    let per_pass = paths.div_ceil(passes);
    (passes, per_pass)
}

/// One scored render.
struct Row {
    scene: String,
    renderer: String,
    seconds: f64,
    rel_mse: f64,
    rel_mse_diffuse: f64,
    /// Over the pixels whose first hit is a mirror or glass (NaN where there are none).
    rel_mse_specular: f64,
    mean_ratio: f64,
    note: String,
}

pub(crate) fn run(root: &Path, args: &[String]) -> Result<bool> {
    let flags = Flags::parse(args)?;
    let out = flags
        .out
        .clone()
        .unwrap_or_else(|| root.join("target/peers"));
    std::fs::create_dir_all(&out).with_context(|| format!("creating {}", out.display()))?;
    let python = ensure_venv(root)?;
    let script = root.join("xtask/peers/render_mitsuba.py");
    let fppm = match &flags.fppm {
        Some(path) => path.clone(),
        None => build_fppm(root)?,
    };

    let mut rows = Vec::new();
    let mut noise_lines = Vec::new();
    for scene_arg in &flags.scenes {
        let (name, scene_path) = scene_file(root, scene_arg);
        let name = &name;
        let mut description = import::load(&scene_path)
            .with_context(|| format!("loading {}", scene_path.display()))?;
        if let Some((w, h)) = flags.film {
            description.film.width = w;
            description.film.height = h;
        }
        let (width, height) = (description.film.width, description.film.height);
        let dir = out.join(name);
        let xml = write_mitsuba(&description, &dir.join("mitsuba"))?;
        // LuxCore's scene, where it renders the reference or is a peer.
        let luxcore = (flags.reference == Reference::Luxcore
            || flags.peers.iter().any(|p| p == LUXCORE_PEER))
        .then(|| crate::luxcore::write_luxcore(&description, &dir.join("luxcore")))
        .transpose()
        .with_context(|| format!("exporting {name} to LuxCore"))?;
        let luxcore_script = root.join("xtask/peers/render_luxcore.py");
        if luxcore.is_some() {
            ensure_luxcore(&python)?;
        }

        // Mitsuba's `path` and `ptracer` ignore media: a scene with media is scored against
        // `volpath` and only `volpath` is a fair peer.
        let reference_integrator = reference_integrator(&description);
        if reference_integrator == "volpath"
            && let Some(blind) = flags.peers.iter().find(|p| *p != "volpath")
        {
            bail!("{name} has media, which Mitsuba's {blind} ignores: use --peers volpath");
        }
        let scene = scene::Scene::new(description)?;
        let diffuse = crate::suite::first_hits(&scene, |m| {
            m.emission.max_element() == 0.0 && matches!(m.kind, scene::MaterialKind::Diffuse(_))
        });
        let specular = crate::suite::first_hits(&scene, |m| m.kind.is_specular());
        let masks = Masks {
            diffuse: &diffuse,
            specular: &specular,
        };

        // The reference: two independent halves.
        let stems = match flags.reference {
            Reference::Mitsuba => ["ref-a", "ref-b"],
            Reference::Luxcore => ["lux-a", "lux-b"],
        };
        let halves = stems.map(|h| dir.join(format!("{h}.exr")));
        for (seed, half) in halves.iter().enumerate() {
            if half.exists() {
                continue;
            }
            if let Some(scn) = luxcore
                .as_ref()
                .filter(|_| flags.reference == Reference::Luxcore)
            {
                eprintln!(
                    "{name}: LuxCore path + caustic cache reference half {} ({} s)",
                    seed + 1,
                    flags.reference_seconds / 2.0
                );
                run_luxcore(
                    &python,
                    &luxcore_script,
                    scn,
                    flags.reference_seconds / 2.0,
                    half,
                    flags.threads,
                    1000 + seed as u32,
                )?;
            } else {
                eprintln!(
                    "{name}: Mitsuba {reference_integrator} reference half {} ({} s)",
                    seed + 1,
                    flags.reference_seconds / 2.0
                );
                run_mitsuba(
                    &python,
                    &script,
                    &xml,
                    reference_integrator,
                    &(flags.reference_seconds / 2.0).to_string(),
                    half,
                    flags.threads,
                    1000 + seed as u32,
                )?;
            }
        }
        let (a, b) = (film::read_exr(&halves[0])?, film::read_exr(&halves[1])?);
        let (pixels, variance) = reference_from_halves(&a.pixels, &b.pixels);
        let reference = Image::new(a.width, a.height, pixels);
        let all = vec![true; diffuse.len()];
        noise_lines.push(format!(
            "| {name} | {:.6} | {:.6} | {:.6} | {:.4} |",
            noise_rel_mse(&variance, &reference, &all),
            noise_rel_mse(&variance, &reference, &diffuse),
            noise_rel_mse(&variance, &reference, &specular),
            reference.mean()
        ));

        for method in &flags.methods {
            let file = dir.join(format!("fppm-{method}.exr"));
            eprintln!("{name}: fppm {method} for {} s", flags.seconds);
            // `sppm+no-light-tracing`: the method, then switches of its own.
            let mut parts = method.split('+');
            let method_name = parts.next().unwrap_or(method);
            let switches: Vec<String> = parts.map(|s| format!("--{s}")).collect();
            let budget: Vec<String> = match flags.paths {
                Some(paths) => {
                    let (passes, per_pass) = passes_for(paths);
                    vec![
                        "--passes".into(),
                        passes.to_string(),
                        "--photons-per-pass".into(),
                        per_pass.to_string(),
                    ]
                }
                None => vec![
                    "--time".into(),
                    format!("{}ms", (flags.seconds * 1000.0) as u64),
                ],
            };
            let clock = Instant::now();
            let status = Command::new(&fppm)
                .arg("render")
                .arg(&scene_path)
                .args(["--method", method_name])
                .args(&switches)
                .args(&budget)
                .args(["--threads", &flags.threads.to_string()])
                .args([
                    "--width",
                    &width.to_string(),
                    "--height",
                    &height.to_string(),
                ])
                .args(&flags.fppm_args)
                .arg("--quiet")
                .arg("-o")
                .arg(&file)
                .status()
                .context("running fppm")?;
            if !status.success() {
                bail!("fppm render of {name} with {method} failed");
            }
            let seconds = clock.elapsed().as_secs_f64();
            rows.push(score(
                name,
                &format!("fppm {method}"),
                seconds,
                &file,
                &reference,
                masks,
                "",
            )?);
        }
        for integrator in &flags.peers {
            if let Some(scn) = luxcore.as_ref().filter(|_| integrator == LUXCORE_PEER) {
                let file = dir.join("luxcore.exr");
                eprintln!(
                    "{name}: LuxCore path + caustic cache for {} s",
                    flags.seconds
                );
                if flags.paths.is_some() {
                    bail!("--paths: LuxCore renders for a time only");
                }
                let clock = Instant::now();
                let report = run_luxcore(
                    &python,
                    &luxcore_script,
                    scn,
                    flags.seconds,
                    &file,
                    flags.threads,
                    7,
                )?;
                let seconds = clock.elapsed().as_secs_f64();
                rows.push(score(
                    name,
                    "LuxCore path + caustic cache",
                    seconds,
                    &file,
                    &reference,
                    masks,
                    &report,
                )?);
                continue;
            }
            let file = dir.join(format!("mitsuba-{integrator}.exr"));
            eprintln!("{name}: Mitsuba {integrator} for {} s", flags.seconds);
            let clock = Instant::now();
            // The driver's budget: seconds, or `spp=N` for a fixed sample count.
            let budget = match flags.paths {
                Some(paths) => {
                    let pixels = u64::from(width) * u64::from(height);
                    format!("spp={}", paths.div_ceil(pixels))
                }
                None => flags.seconds.to_string(),
            };
            let report = run_mitsuba(
                &python,
                &script,
                &xml,
                integrator,
                &budget,
                &file,
                flags.threads,
                7,
            )?;
            let seconds = clock.elapsed().as_secs_f64();
            rows.push(score(
                name,
                &format!("Mitsuba {integrator}"),
                seconds,
                &file,
                &reference,
                masks,
                &report,
            )?);
        }
    }

    let mut table = String::new();
    writeln!(
        table,
        "| scene | renderer | wall s | relMSE | relMSE diffuse-seen | relMSE specular-seen | mean / ref | notes |"
    )?;
    writeln!(table, "|---|---|---|---|---|---|---|---|")?;
    for r in &rows {
        writeln!(
            table,
            "| {} | {} | {:.1} | {:.6} | {:.6} | {:.6} | {:.4} | {} |",
            r.scene,
            r.renderer,
            r.seconds,
            r.rel_mse,
            r.rel_mse_diffuse,
            r.rel_mse_specular,
            r.mean_ratio,
            r.note
        )?;
    }
    writeln!(table)?;
    writeln!(
        table,
        "Reference noise (relMSE units; subtract from the figures above for the net error):"
    )?;
    writeln!(table)?;
    writeln!(
        table,
        "| scene | all pixels | diffuse-seen | specular-seen | reference mean |"
    )?;
    writeln!(table, "|---|---|---|---|---|")?;
    for line in &noise_lines {
        writeln!(table, "{line}")?;
    }
    std::fs::write(out.join("table.md"), &table)?;
    println!("{table}");
    Ok(true)
}

fn score(
    scene: &str,
    renderer: &str,
    seconds: f64,
    file: &Path,
    reference: &Image,
    masks: Masks<'_>,
    note: &str,
) -> Result<Row> {
    let image = film::read_exr(file)?;
    let all = film::errors(&image, reference, None)?;
    let on_diffuse = film::errors(&image, reference, Some(masks.diffuse))?;
    let on_specular = if masks.specular.contains(&true) {
        film::errors(&image, reference, Some(masks.specular))?.rel_mse
    } else {
        f64::NAN
    };
    Ok(Row {
        scene: scene.to_owned(),
        renderer: renderer.to_owned(),
        seconds,
        rel_mse: all.rel_mse,
        rel_mse_diffuse: on_diffuse.rel_mse,
        rel_mse_specular: on_specular,
        mean_ratio: all.mean_ratio,
        note: note.to_owned(),
    })
}

/// The pixel classes the table scores apart.
#[derive(Clone, Copy)]
struct Masks<'a> {
    /// First hit diffuse and not emitting.
    diffuse: &'a [bool],
    /// First hit a mirror or glass.
    specular: &'a [bool],
}

/// The venv's Python with Mitsuba 3, created on first use.
fn ensure_venv(root: &Path) -> Result<PathBuf> {
    let venv = root.join("target/peers-venv");
    let python = venv.join("bin/python");
    let has_mitsuba = |python: &Path| {
        Command::new(python)
            .args(["-c", "import mitsuba, drjit, numpy"])
            .status()
            .is_ok_and(|s| s.success())
    };
    if python.exists() && has_mitsuba(&python) {
        return Ok(python);
    }
    eprintln!(
        "creating {} (pip install mitsuba drjit numpy)",
        venv.display()
    );
    let status = Command::new("python3")
        .args(["-m", "venv"])
        .arg(&venv)
        .status()
        .context("running python3 -m venv")?;
    if !status.success() {
        bail!("python3 -m venv {} failed", venv.display());
    }
    let status = Command::new(&python)
        .args([
            "-m", "pip", "install", "--quiet", "mitsuba", "drjit", "numpy",
        ])
        .status()
        .context("running pip")?;
    if !status.success() || !has_mitsuba(&python) {
        bail!("installing mitsuba into {} failed", venv.display());
    }
    Ok(python)
}

/// The `--peers` name of LuxCore (its path tracer with the caustic cache).
const LUXCORE_PEER: &str = "luxcore";

/// Installs LuxCore's Python module into the peers' venv if it is not there.
fn ensure_luxcore(python: &Path) -> Result<()> {
    let has = Command::new(python)
        .args(["-c", "import pyluxcore"])
        .output()
        .is_ok_and(|o| o.status.success());
    if has {
        return Ok(());
    }
    eprintln!("pip install pyluxcore");
    let status = Command::new(python)
        .args(["-m", "pip", "install", "--quiet", "pyluxcore"])
        .status()
        .context("running pip")?;
    if !status.success() {
        bail!("installing pyluxcore failed");
    }
    Ok(())
}

/// Runs the LuxCore driver script for `seconds`; returns its report line.
fn run_luxcore(
    python: &Path,
    script: &Path,
    scn: &Path,
    seconds: f64,
    out: &Path,
    threads: u32,
    seed: u32,
) -> Result<String> {
    let args = [
        scn.as_os_str().to_owned(),
        seconds.to_string().into(),
        out.as_os_str().to_owned(),
        threads.to_string().into(),
        seed.to_string().into(),
    ];
    run_driver(
        python,
        script,
        &args,
        &format!("LuxCore on {}", scn.display()),
    )
}

/// Runs a peer's Python driver script with `args`; returns the last line it printed (its
/// report), or an error naming `what` with the last line of its errors.
fn run_driver(
    python: &Path,
    script: &Path,
    args: &[std::ffi::OsString],
    what: &str,
) -> Result<String> {
    let output = Command::new(python)
        .arg(script)
        .args(args)
        .output()
        .with_context(|| format!("running {what}"))?;
    if !output.status.success() {
        bail!(
            "{what} failed: {}",
            String::from_utf8_lossy(&output.stderr)
                .lines()
                .last()
                .unwrap_or("")
        );
    }
    Ok(String::from_utf8_lossy(&output.stdout)
        .lines()
        .last()
        .unwrap_or("")
        .trim()
        .to_owned())
}

/// Builds the release `fppm` binary and returns its path.
pub(crate) fn build_fppm(root: &Path) -> Result<PathBuf> {
    let status = Command::new(std::env::var("CARGO").unwrap_or_else(|_| "cargo".to_owned()))
        .args(["build", "--release", "-p", "cli", "--quiet"])
        .current_dir(root)
        .status()
        .context("running cargo build")?;
    if !status.success() {
        bail!("cargo build --release -p cli failed");
    }
    Ok(root.join("target/release/fppm"))
}

/// Runs the Mitsuba driver script for `budget` (seconds, or `spp=N`); returns its report
/// line.
#[allow(clippy::too_many_arguments)]
fn run_mitsuba(
    python: &Path,
    script: &Path,
    xml: &Path,
    integrator: &str,
    budget: &str,
    out: &Path,
    threads: u32,
    seed: u32,
) -> Result<String> {
    let args = [
        xml.as_os_str().to_owned(),
        integrator.into(),
        budget.into(),
        out.as_os_str().to_owned(),
        threads.to_string().into(),
        seed.to_string().into(),
    ];
    run_driver(
        python,
        script,
        &args,
        &format!("Mitsuba {integrator} on {}", xml.display()),
    )
}

/// Writes `description` as a Mitsuba 3 scene (`scene.xml` and one PLY per material group) in
/// `dir` and returns the XML's path.
///
/// Conventions: fppm's diffuse and mirror materials scatter on both sides, so they are wrapped
/// in `twosided`; a mirror is a `conductor` of material `none` (a perfect reflector) scaled by
/// its reflectance; a dielectric is `dielectric` with `int_ior` = ior against vacuum; emission
/// is an `area` emitter (one-sided, front = counter-clockwise side, as in fppm); cylinders are
/// tessellated (512 segments around the kept arc) with exact vertex normals; the camera is a
/// `perspective` sensor with `fov_axis = y` and a box-filtered `hdrfilm`; a diffuse colour
/// texture (with albedo 1) is a `bitmap` reflectance (sRGB-decoded by Mitsuba for 8-bit files,
/// bilinear, with the same wrap mode), a cut-out a `mask` BSDF with the alpha as opacity
/// (`raw`); a homogeneous medium is a `homogeneous` medium ([`medium_xml`]), a grid medium a
/// `heterogeneous` one with its `.vol` beside the XML ([`grid_medium_xml`]), that shapes refer
/// to as `interior` and `exterior` and the sensor as its `medium`, the interface material a
/// `null` BSDF; the integrator is `$integrator` with the scene's depth, else unlimited (by default `volpath`
/// for a scene with media, else `path`); the environment is Mitsuba's
/// `constant` or `envmap` ([`environment_emitter`]); a rough dielectric is `roughdielectric`
/// (GGX), a glossy conductor a two-sided `roughconductor` of the η whose exact Fresnel fppm's
/// Schlick approximates, a glossy coat over a diffuse base fppm's own model as the Python BSDF
/// `fppmglossy` (`xtask/peers/fppm_glossy.py`, which `render_mitsuba.py` registers). Lights
/// other than emissive surfaces, point and directional lights and the environment are refused:
/// the peer scenes do not use them.
pub(crate) fn write_mitsuba(description: &scene::SceneDescription, dir: &Path) -> Result<PathBuf> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let mut xml = String::new();
    writeln!(xml, "<scene version=\"3.0.0\">")?;
    writeln!(
        xml,
        "  <default name=\"integrator\" value=\"{}\"/>",
        reference_integrator(description)
    )?;
    writeln!(xml, "  <default name=\"spp\" value=\"16\"/>")?;
    // The depth fppm renders: a scene's own `max_depth` (read from a Mitsuba or pbrt file)
    // counts scattering events, Mitsuba's path segments, one more; else unlimited.
    let max_depth = description
        .render
        .get("max_depth")
        .and_then(|d| d.parse::<i64>().ok())
        .map_or(-1, |d| d + 1);
    writeln!(
        xml,
        "  <integrator type=\"$integrator\"><integer name=\"max_depth\" value=\"{max_depth}\"/></integrator>"
    )?;
    let c = &description.camera;
    if c.aperture_radius > 0.0 {
        bail!("thin-lens cameras are not exported");
    }
    let v = |p: Vec3| format!("{}, {}, {}", p.x, p.y, p.z);
    writeln!(xml, "  <sensor type=\"perspective\">")?;
    writeln!(xml, "    <string name=\"fov_axis\" value=\"y\"/>")?;
    writeln!(
        xml,
        "    <float name=\"fov\" value=\"{}\"/>",
        c.fov_y.to_degrees()
    )?;
    writeln!(
        xml,
        "    <transform name=\"to_world\"><lookat origin=\"{}\" target=\"{}\" up=\"{}\"/></transform>",
        v(c.position),
        v(c.look_at),
        v(c.up)
    )?;
    writeln!(
        xml,
        "    <sampler type=\"independent\"><integer name=\"sample_count\" value=\"$spp\"/></sampler>"
    )?;
    writeln!(
        xml,
        "    <film type=\"hdrfilm\"><integer name=\"width\" value=\"{}\"/><integer name=\"height\" value=\"{}\"/><rfilter type=\"box\"/><string name=\"pixel_format\" value=\"rgb\"/></film>",
        description.film.width, description.film.height
    )?;
    if let Some(m) = description.media.camera {
        writeln!(xml, "    <ref name=\"medium\" id=\"{}\"/>", medium_id(m))?;
    }
    writeln!(xml, "  </sensor>")?;
    for (index, medium) in description.media.list.iter().enumerate() {
        let element = if medium.is_homogeneous() {
            medium_xml(medium, index as u32)
        } else {
            grid_medium_xml(medium, index as u32, dir)?
        };
        writeln!(xml, "  {element}")?;
    }

    let rgb = |c: [f32; 3]| format!("{}, {}, {}", c[0], c[1], c[2]);
    let mut bsdfs = Vec::new();
    for m in &description.materials {
        let textures = m.textures.as_deref();
        let color = textures.and_then(|t| t.color.as_ref());
        if textures.is_some_and(|t| t.emission.is_some() || t.normal.is_some()) {
            bail!(
                "material {}: emission and normal textures are not exported",
                m.name
            );
        }
        let bsdf = match m.kind {
            scene::MaterialKind::Diffuse(scene::Diffuse { albedo }) if color.is_some() => {
                let texture = color.context("checked")?;
                if albedo != Vec3::ONE {
                    bail!(
                        "material {}: a texture times an albedo other than 1 is not exported",
                        m.name
                    );
                }
                format!(
                    "<bsdf type=\"twosided\"><bsdf type=\"diffuse\">{}</bsdf></bsdf>",
                    bitmap("reflectance", texture)?
                )
            }
            _ if color.is_some() => {
                bail!("material {}: only diffuse textures are exported", m.name)
            }
            scene::MaterialKind::Diffuse(scene::Diffuse { albedo }) => format!(
                "<bsdf type=\"twosided\"><bsdf type=\"diffuse\"><rgb name=\"reflectance\" value=\"{}\"/></bsdf></bsdf>",
                rgb(albedo.to_array())
            ),
            scene::MaterialKind::Mirror(scene::Mirror { reflectance }) => format!(
                "<bsdf type=\"twosided\"><bsdf type=\"conductor\"><string name=\"material\" value=\"none\"/><rgb name=\"specular_reflectance\" value=\"{}\"/></bsdf></bsdf>",
                rgb(reflectance.to_array())
            ),
            scene::MaterialKind::Dielectric(scene::Dielectric { ior }) => format!(
                "<bsdf type=\"dielectric\"><float name=\"int_ior\" value=\"{ior}\"/><float name=\"ext_ior\" value=\"1.0\"/></bsdf>"
            ),
            scene::MaterialKind::RoughDielectric(scene::RoughDielectric { ior, roughness }) => {
                format!(
                    "<bsdf type=\"roughdielectric\"><string name=\"distribution\" value=\"ggx\"/><float name=\"alpha\" value=\"{roughness}\"/><float name=\"int_ior\" value=\"{ior}\"/><float name=\"ext_ior\" value=\"1.0\"/></bsdf>"
                )
            }
            // A conductor: fppm's Schlick Fresnel of F₀ = `reflectance`, which Mitsuba's
            // `roughconductor` evaluates exactly for the (η, k) that [`schlick_conductor`] fits.
            scene::MaterialKind::Glossy(scene::Glossy {
                reflectance,
                roughness,
                diffuse,
            }) if diffuse == Vec3::ZERO => {
                let fits = reflectance.to_array().map(schlick_conductor);
                format!(
                    "<bsdf type=\"twosided\"><bsdf type=\"roughconductor\"><string name=\"distribution\" value=\"ggx\"/><float name=\"alpha\" value=\"{roughness}\"/><rgb name=\"eta\" value=\"{}\"/><rgb name=\"k\" value=\"{}\"/></bsdf></bsdf>",
                    rgb(fits.map(|f| f.0)),
                    rgb(fits.map(|f| f.1))
                )
            }
            // A coat over a diffuse base: fppm's own model, a Python BSDF of the peers'
            // script (no built-in Mitsuba BSDF is it: `roughplastic` scatters its base inside
            // the coat and put CornellBox-Glossy's mean 3.7 % away).
            scene::MaterialKind::Glossy(scene::Glossy {
                reflectance,
                roughness,
                diffuse,
            }) => {
                let c = |name: &str, v: Vec3| {
                    format!(
                        "<float name=\"{name}_r\" value=\"{}\"/><float name=\"{name}_g\" value=\"{}\"/><float name=\"{name}_b\" value=\"{}\"/>",
                        v.x, v.y, v.z
                    )
                };
                format!(
                    "<bsdf type=\"fppmglossy\">{}{}<float name=\"alpha\" value=\"{roughness}\"/></bsdf>",
                    c("ks", reflectance),
                    c("kd", diffuse)
                )
            }
            // The conductor with its RGB η and k, as Mitsuba's RGB variants render it.
            scene::MaterialKind::Conductor(c) => {
                let kind = if c.is_smooth() {
                    "<bsdf type=\"conductor\">".to_owned()
                } else {
                    format!(
                        "<bsdf type=\"roughconductor\"><string name=\"distribution\" value=\"ggx\"/><float name=\"alpha\" value=\"{}\"/>",
                        c.roughness
                    )
                };
                format!(
                    "<bsdf type=\"twosided\">{kind}<rgb name=\"eta\" value=\"{}\"/><rgb name=\"k\" value=\"{}\"/><rgb name=\"specular_reflectance\" value=\"{}\"/></bsdf></bsdf>",
                    rgb(c.eta.to_array()),
                    rgb(c.k.to_array()),
                    rgb(c.specular_reflectance.to_array())
                )
            }
            // Bounds media without scattering: Mitsuba's `null` BSDF (media are attached to
            // the shape, below).
            scene::MaterialKind::Interface(_) => "<bsdf type=\"null\"/>".to_owned(),
        };
        // A cut-out: Mitsuba's `mask` keeps the surface with probability = opacity (a stochastic
        // cut-out); fppm's `MASK` thresholds it, which agrees where the mask is 0 or 1.
        let bsdf = match textures.and_then(|t| t.alpha.as_ref()) {
            None => bsdf,
            Some(alpha) => {
                let texture = alpha
                    .texture
                    .as_ref()
                    .context("a constant alpha is not exported")?;
                if alpha.factor != 1.0 {
                    bail!(
                        "material {}: an alpha factor other than 1 is not exported",
                        m.name
                    );
                }
                format!(
                    "<bsdf type=\"mask\">{}{bsdf}</bsdf>",
                    bitmap("opacity", texture)?
                )
            }
        };
        let emission = m.emission.to_array();
        let emitter = (emission.iter().any(|&e| e > 0.0)).then(|| {
            format!(
                "<emitter type=\"area\"><rgb name=\"radiance\" value=\"{}\"/></emitter>",
                rgb(emission)
            )
        });
        bsdfs.push((bsdf, emitter));
    }

    // The media entry (index into `media.shapes`) of each triangle and sphere, if any.
    let mut triangle_media = vec![None; description.triangles.len()];
    let mut sphere_media = vec![None; description.spheres.len()];
    for (entry, shape) in description.media.shapes.iter().enumerate() {
        match shape.shape {
            scene::MediumShape::Triangles { start, end } => {
                let range = triangle_media
                    .get_mut(start as usize..end as usize)
                    .context("a media entry names triangles that do not exist")?;
                range.fill(Some(entry));
            }
            scene::MediumShape::Sphere(i) => {
                *sphere_media
                    .get_mut(i as usize)
                    .context("a media entry names a sphere that does not exist")? = Some(entry);
            }
        }
    }
    let media_refs = |entry: Option<usize>| -> String {
        let Some(shape) = entry.map(|e| description.media.shapes[e]) else {
            return String::new();
        };
        let mut refs = String::new();
        for (name, side) in [("interior", shape.interior), ("exterior", shape.exterior)] {
            if let Some(m) = side {
                refs += &format!("<ref name=\"{name}\" id=\"{}\"/>", medium_id(m));
            }
        }
        refs
    };

    // Triangles, one PLY per material and media entry.
    let mut groups: Vec<(usize, Option<usize>)> = description
        .triangles
        .iter()
        .zip(&triangle_media)
        .map(|(t, &media)| (t.material as usize, media))
        .collect();
    groups.sort_unstable();
    groups.dedup();
    for (index, media) in groups {
        let (bsdf, emitter) = &bsdfs[index];
        let triangles: Vec<_> = description
            .triangles
            .iter()
            .zip(&triangle_media)
            .filter(|(t, m)| t.material as usize == index && **m == media)
            .map(|(t, _)| t)
            .collect();
        let file = match media {
            None => format!("material-{index}.ply"),
            Some(entry) => format!("material-{index}-media-{entry}.ply"),
        };
        let ply = crate::meshes::triangles_ply(&triangles);
        std::fs::write(dir.join(&file), ply)?;
        writeln!(
            xml,
            "  <shape type=\"ply\"><string name=\"filename\" value=\"{file}\"/>{bsdf}{}{}</shape>",
            emitter.as_deref().unwrap_or(""),
            media_refs(media)
        )?;
    }
    for (s, &media) in description.spheres.iter().zip(&sphere_media) {
        let (bsdf, emitter) = &bsdfs[s.material as usize];
        writeln!(
            xml,
            "  <shape type=\"sphere\"><point name=\"center\" value=\"{}\"/><float name=\"radius\" value=\"{}\"/>{bsdf}{}{}</shape>",
            v(s.center),
            s.radius,
            emitter.as_deref().unwrap_or(""),
            media_refs(media)
        )?;
    }
    for (index, cylinder) in description.cylinders.iter().enumerate() {
        let (bsdf, emitter) = &bsdfs[cylinder.material as usize];
        let file = format!("cylinder-{index}.ply");
        std::fs::write(dir.join(&file), crate::meshes::cylinder_ply(cylinder, 512))?;
        writeln!(
            xml,
            "  <shape type=\"ply\"><string name=\"filename\" value=\"{file}\"/>{bsdf}{}</shape>",
            emitter.as_deref().unwrap_or("")
        )?;
    }
    for light in &description.lights {
        match *light {
            scene::Light::Point {
                position,
                intensity,
            } => writeln!(
                xml,
                "  <emitter type=\"point\"><point name=\"position\" value=\"{}\"/><rgb name=\"intensity\" value=\"{}\"/></emitter>",
                v(position),
                rgb(intensity.to_array())
            )?,
            scene::Light::Directional {
                direction,
                irradiance,
            } => writeln!(
                xml,
                "  <emitter type=\"directional\"><vector name=\"direction\" value=\"{}\"/><rgb name=\"irradiance\" value=\"{}\"/></emitter>",
                v(direction),
                rgb(irradiance.to_array())
            )?,
            ref other => bail!("light {other:?} is not exported"),
        }
    }
    if let Some(env) = &description.environment {
        writeln!(xml, "  {}", environment_emitter(env))?;
    }
    writeln!(xml, "</scene>")?;
    let path = dir.join("scene.xml");
    std::fs::write(&path, xml)?;
    Ok(path)
}

/// The Mitsuba integrator of a scene's references: `volpath` if some path can be in a medium
/// (Mitsuba's `path` ignores media), else `path`.
pub(crate) fn reference_integrator(description: &scene::SceneDescription) -> &'static str {
    if description.media.are_used() {
        "volpath"
    } else {
        "path"
    }
}

/// The XML id of medium `index`.
fn medium_id(index: u32) -> String {
    format!("medium-{index}")
}

/// A homogeneous medium as Mitsuba 3's `homogeneous`: extinction σt = σa + σs and single-scattering
/// albedo σs / σt per channel (0 in a channel with σt = 0, where it does not matter: nothing
/// scatters there), and the Henyey–Greenstein phase function of the same g. Mitsuba's RGB
/// variants read an `<rgb>` as a reflectance and refuse values above 1, so σt is written as its
/// largest channel (`scale`) times σt / that channel (each in [0, 1]).
pub(crate) fn medium_xml(medium: &scene::Medium, index: u32) -> String {
    let largest = medium.sigma_t().max_element();
    let scale = if largest > 0.0 { largest } else { 1.0 };
    let sigma_t = medium.sigma_t() / scale;
    let albedo = |c: usize| {
        let sigma_t = medium.sigma_t();
        if sigma_t[c] > 0.0 {
            medium.sigma_s[c] / sigma_t[c]
        } else {
            0.0
        }
    };
    format!(
        "<medium type=\"homogeneous\" id=\"{}\"><rgb name=\"sigma_t\" value=\"{}, {}, {}\"/><rgb name=\"albedo\" value=\"{}, {}, {}\"/><float name=\"scale\" value=\"{scale}\"/><phase type=\"hg\"><float name=\"g\" value=\"{}\"/></phase></medium>",
        medium_id(index),
        sigma_t.x,
        sigma_t.y,
        sigma_t.z,
        albedo(0),
        albedo(1),
        albedo(2),
        medium.g
    )
}

/// A grid medium as Mitsuba 3's `heterogeneous`: its densities written to `medium-INDEX.vol` in
/// `dir`, read by a `gridvolume` (trilinear, clamped: fppm's [`scene::GridEdge::Clamp`]) whose
/// `to_world` maps the unit cube onto the grid's box in the world, `scale` the extinction at
/// density 1, `albedo` σs / σt and the same `hg` phase function. Mitsuba's heterogeneous
/// extinction is a scalar grid times `scale`, so a grid medium with chromatic σt (or pbrt's zero
/// edges) is refused.
fn grid_medium_xml(medium: &scene::Medium, index: u32, dir: &Path) -> Result<String> {
    let Some(grid) = &medium.density else {
        bail!("medium {:?} has no grid", medium.name);
    };
    let sigma_t = medium.sigma_t();
    if sigma_t.max_element() != sigma_t.min_element() {
        bail!(
            "grid medium {:?}: Mitsuba's heterogeneous medium needs the same extinction in every channel, got {sigma_t}",
            medium.name
        );
    }
    if grid.edge() != scene::GridEdge::Clamp {
        bail!(
            "grid medium {:?}: only grids clamped at the faces (Mitsuba's gridvolume) are exported",
            medium.name
        );
    }
    let file = format!("medium-{index}.vol");
    let (min, max) = grid.bounds();
    std::fs::write(
        dir.join(&file),
        import::write_vol(grid.size(), min, max, grid.data()),
    )?;
    // Unit cube → the box → the world; Mitsuba's `matrix` is row-major.
    let to_world = glam::Mat4::from(grid.to_world())
        * glam::Mat4::from_translation(min)
        * glam::Mat4::from_scale(max - min);
    let m = to_world.transpose().to_cols_array();
    let matrix = m.iter().map(f32::to_string).collect::<Vec<_>>().join(" ");
    let scale = sigma_t.x;
    let albedo = if scale > 0.0 {
        medium.sigma_s / scale
    } else {
        glam::Vec3::ZERO
    };
    Ok(format!(
        "<medium type=\"heterogeneous\" id=\"{}\"><volume name=\"sigma_t\" type=\"gridvolume\"><string name=\"filename\" value=\"{file}\"/><transform name=\"to_world\"><matrix value=\"{matrix}\"/></transform></volume><rgb name=\"albedo\" value=\"{}, {}, {}\"/><float name=\"scale\" value=\"{scale}\"/><phase type=\"hg\"><float name=\"g\" value=\"{}\"/></phase></medium>",
        medium_id(index),
        albedo.x,
        albedo.y,
        albedo.z,
        medium.g
    ))
}

/// The environment as a Mitsuba emitter: `constant` (scale folded into the radiance) or
/// `envmap` of the same file (absolute path), `scale`, and the rotation as its `to_world`
/// matrix. Both read the map in Mitsuba's orientation (`scene::Environment`).
fn environment_emitter(env: &scene::Environment) -> String {
    match &env.radiance {
        scene::EnvironmentRadiance::Constant(c) => {
            let c = *c * env.scale;
            format!(
                "<emitter type=\"constant\"><rgb name=\"radiance\" value=\"{}, {}, {}\"/></emitter>",
                c.x, c.y, c.z
            )
        }
        scene::EnvironmentRadiance::Map(map) => {
            let path = std::path::absolute(&map.path).unwrap_or_else(|_| map.path.clone());
            // Mitsuba's `matrix` is row-major.
            let m = env.to_world.transpose().to_cols_array();
            format!(
                "<emitter type=\"envmap\"><string name=\"filename\" value=\"{}\"/><float name=\"scale\" value=\"{}\"/><transform name=\"to_world\"><matrix value=\"{} {} {} 0 {} {} {} 0 {} {} {} 0 0 0 0 1\"/></transform></emitter>",
                path.display(),
                env.scale,
                m[0],
                m[1],
                m[2],
                m[3],
                m[4],
                m[5],
                m[6],
                m[7],
                m[8]
            )
        }
    }
}

/// A Mitsuba `bitmap` texture parameter reading `texture`'s image file: colour textures as
/// Mitsuba decodes them by default (sRGB for 8-bit files), data (alpha) `raw`.
fn bitmap(name: &str, texture: &scene::texture::TextureRef) -> Result<String> {
    if texture.transform != scene::texture::TextureRef::IDENTITY {
        bail!("texture transforms are not exported");
    }
    let wrap = |w: scene::texture::Wrap| match w {
        scene::texture::Wrap::Repeat => "repeat",
        scene::texture::Wrap::Mirror => "mirror",
        scene::texture::Wrap::Clamp => "clamp",
    };
    if texture.wrap[0] != texture.wrap[1] {
        bail!("different wrap modes along u and v are not exported");
    }
    let path = texture
        .image
        .path()
        .canonicalize()
        .with_context(|| format!("texture {}", texture.image.path().display()))?;
    Ok(format!(
        "<texture type=\"bitmap\" name=\"{name}\"><string name=\"filename\" value=\"{}\"/><string name=\"wrap_mode\" value=\"{}\"/><boolean name=\"raw\" value=\"{}\"/></texture>",
        path.display(),
        wrap(texture.wrap[0]),
        !texture.srgb
    ))
}

/// The unpolarised Fresnel reflectance of a conductor of complex index η + ik at incidence
/// cosine `cos` (pbrt-v3's `FrConductor`, real arithmetic).
pub(crate) fn conductor_fresnel(cos: f64, eta: f64, k: f64) -> f64 {
    let cos2 = cos * cos;
    let sin2 = 1.0 - cos2;
    let t0 = eta * eta - k * k - sin2;
    let a2_plus_b2 = (t0 * t0 + 4.0 * eta * eta * k * k).sqrt();
    let t1 = a2_plus_b2 + cos2;
    let a = (0.5 * (a2_plus_b2 + t0)).max(0.0).sqrt();
    let t2 = 2.0 * cos * a;
    let rs = (t1 - t2) / (t1 + t2);
    let t3 = cos2 * a2_plus_b2 + sin2 * sin2;
    let t4 = t2 * sin2;
    let rp = rs * (t3 - t4) / (t3 + t4);
    0.5 * (rs + rp)
}

/// The (η, k) whose exact conductor Fresnel is closest to Schlick's F₀ + (1 − F₀)(1 − cos)⁵,
/// fppm's glossy Fresnel, so that Mitsuba's `roughconductor` renders fppm's material: Gulbrandsen's
/// (2014) map from (F₀, edge tint g) to (η, k), with g chosen by the least cosine-weighted squared
/// difference over the hemisphere. An absorption-free boundary with the same F₀ (k = 0) dips where
/// Schlick rises (at F₀ = 0.6: 0.47 against 0.75 at 80°), and read a glossy floor 5 % darker.
pub(crate) fn schlick_conductor(f0: f32) -> (f32, f32) {
    let r = f64::from(f0).clamp(1e-4, 0.999);
    let map = |g: f64| {
        let sr = r.sqrt();
        let eta = g * (1.0 - r) / (1.0 + r) + (1.0 - g) * (1.0 + sr) / (1.0 - sr);
        let k = ((r * (eta + 1.0).powi(2) - (eta - 1.0).powi(2)) / (1.0 - r))
            .max(0.0)
            .sqrt();
        (eta, k)
    };
    let error = |(eta, k): (f64, f64)| {
        (0..128)
            .map(|i| {
                let cos = (f64::from(i) + 0.5) / 128.0;
                let schlick = r + (1.0 - r) * (1.0 - cos).powi(5);
                (conductor_fresnel(cos, eta, k) - schlick).powi(2) * cos
            })
            .sum::<f64>()
    };
    let best = (0..=200)
        .map(|i| map(f64::from(i) / 200.0))
        .min_by(|a, b| error(*a).total_cmp(&error(*b)))
        .unwrap_or((1.5, 0.0));
    (best.0 as f32, best.1 as f32)
}
