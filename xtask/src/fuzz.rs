//! `cargo xtask fuzz`: builds the seed corpora, then runs the cargo-fuzz targets of `fuzz/` in
//! turn and reports executions, coverage and crashes per target (from libFuzzer's output).

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use anyhow::{Context, Result, bail};

/// The fuzz harness's stubs and checkpoint framing, shared with the targets so that the seeds
/// match what the `checkpoint` target takes and the normal test suite checks the stubs.
#[allow(unreachable_pub, dead_code)]
#[path = "../../fuzz/src/harness.rs"]
mod harness;

pub(crate) const HELP: &str = "\
cargo xtask fuzz [--seconds N] [--runs N] [--target T]... [--asan] [--dev] [--skip-missing] [--list]

Runs the fuzz targets of fuzz/ (cargo-fuzz, libFuzzer) one after the other, one process each,
and prints per target the executions, executions per second, coverage (libFuzzer's `cov` and
`ft`), corpus size and whether it crashed. Needs the nightly toolchain and cargo-fuzz
(`rustup toolchain install nightly`, `cargo install cargo-fuzz`).

Seeds are built at every run into target/fuzz-seeds/<target>/ from the repository's scenes,
tests/golden/ and ../shared/scenes (small files only, read in place), checkpoints (and their
columns) and work-unit parts of the checkpoint target's scene, and small images and environment
maps it writes; what the fuzzer finds accumulates in fuzz/corpus/<target>/, crashing
inputs in fuzz/artifacts/<target>/, libFuzzer's log in target/fuzz-logs/<target>.log.
Exit status 1 if a target crashed.

  --seconds N      time per target (default 60)
  --runs N         stop a target after N executions (whichever of --seconds and --runs comes first)
  --target T       run only T (repeatable); default all
  --asan           build with AddressSanitizer (default: no sanitizer, which runs faster; the
                   code under test is safe Rust, and debug assertions stay on)
  --dev            build the targets in the dev profile: quicker to build from cold, much slower
                   to run (for the CI smoke)
  --skip-missing   if nightly or cargo-fuzz is missing, say so and exit 0 (for CI)
  --list           print the targets and exit";

/// The targets: (name, dictionary in fuzz/dict/ or none).
const TARGETS: [(&str, Option<&str>); 15] = [
    ("toml_scene", Some("toml.dict")),
    ("obj", Some("obj.dict")),
    ("gltf", Some("gltf.dict")),
    ("glb", Some("gltf.dict")),
    ("mitsuba", Some("mitsuba.dict")),
    ("pbrt", Some("pbrt.dict")),
    ("ply", Some("ply.dict")),
    ("vol", None),
    ("checkpoint", None),
    ("exr", None),
    ("scene_render", None),
    ("part", None),
    ("texture", Some("image.dict")),
    ("envmap", Some("image.dict")),
    ("checkpoint_columns", None),
];

/// Largest seed file taken from the scenes: the fuzzer mutates small inputs much faster.
const MAX_SEED_BYTES: u64 = 64 << 10;

/// Largest image taken from the scenes as a texture seed: a few kilobytes of PNG can hold a
/// large image, whose decoding slows every execution.
const MAX_IMAGE_SEED_BYTES: u64 = 8 << 10;

struct Flags {
    seconds: u64,
    runs: Option<u64>,
    targets: Vec<String>,
    asan: bool,
    dev: bool,
    skip_missing: bool,
    list: bool,
}

impl Flags {
    fn parse(args: &[String]) -> Result<Self> {
        let mut flags = Flags {
            seconds: 60,
            runs: None,
            targets: Vec::new(),
            asan: false,
            dev: false,
            skip_missing: false,
            list: false,
        };
        let mut it = args.iter();
        while let Some(arg) = it.next() {
            let mut value = |name: &str| {
                it.next()
                    .with_context(|| format!("fuzz: {name} needs a value"))
            };
            match arg.as_str() {
                "--seconds" => {
                    flags.seconds = value("--seconds")?
                        .parse()
                        .context("fuzz: --seconds needs a whole number")?;
                }
                "--runs" => {
                    flags.runs = Some(
                        value("--runs")?
                            .parse()
                            .context("fuzz: --runs needs a whole number")?,
                    );
                }
                "--target" => {
                    let t = value("--target")?;
                    if !TARGETS.iter().any(|(name, _)| name == t) {
                        bail!("fuzz: no target `{t}` (see `cargo xtask fuzz --list`)");
                    }
                    flags.targets.push(t.clone());
                }
                "--asan" => flags.asan = true,
                "--dev" => flags.dev = true,
                "--skip-missing" => flags.skip_missing = true,
                "--list" => flags.list = true,
                other => bail!("fuzz: unknown flag `{other}`\n\n{HELP}"),
            }
        }
        Ok(flags)
    }
}

/// What libFuzzer reported for one target.
#[derive(Debug, Default, PartialEq)]
pub(crate) struct Stats {
    pub(crate) executions: Option<u64>,
    pub(crate) exec_per_sec: Option<u64>,
    pub(crate) coverage: Option<u64>,
    pub(crate) features: Option<u64>,
    pub(crate) corpus: Option<String>,
    pub(crate) new_units: Option<u64>,
    pub(crate) peak_rss_mb: Option<u64>,
    /// The crashing input libFuzzer wrote, and the first line saying why.
    pub(crate) crash: Option<(String, String)>,
}

/// Parses libFuzzer's output: the `stat::` lines of `-print_final_stats=1`, the last status
/// line (`#N ... cov: C ft: F corp: U/S ...`) and, after a crash, the artifact it wrote.
pub(crate) fn parse_stats(log: &str) -> Stats {
    let mut stats = Stats::default();
    let mut reason: Option<String> = None;
    let mut artifact: Option<String> = None;
    for line in log.lines() {
        let number = |s: &str| s.trim().parse::<u64>().ok();
        if let Some((key, value)) = line
            .strip_prefix("stat::")
            .and_then(|rest| rest.split_once(':'))
        {
            match key {
                "number_of_executed_units" => stats.executions = number(value),
                "average_exec_per_sec" => stats.exec_per_sec = number(value),
                "new_units_added" => stats.new_units = number(value),
                "peak_rss_mb" => stats.peak_rss_mb = number(value),
                _ => {}
            }
            continue;
        }
        if line.starts_with('#') && line.contains(" cov: ") {
            let mut words = line.split_whitespace();
            while let Some(w) = words.next() {
                match w {
                    "cov:" => stats.coverage = words.next().and_then(number),
                    "ft:" => stats.features = words.next().and_then(number),
                    "corp:" => stats.corpus = words.next().map(str::to_owned),
                    _ => {}
                }
            }
        }
        if reason.is_none()
            && (line.contains("panicked at")
                || line.contains("ERROR: libFuzzer:")
                || line.contains("ERROR: AddressSanitizer:"))
        {
            reason = Some(line.trim().to_owned());
        }
        if let Some(rest) = line.split_once("Test unit written to ") {
            artifact = Some(rest.1.trim().to_owned());
        }
    }
    if let Some(artifact) = artifact {
        stats.crash = Some((artifact, reason.unwrap_or_else(|| "crash".to_owned())));
    }
    stats
}

pub(crate) fn run(root: &Path, args: &[String]) -> Result<bool> {
    let flags = Flags::parse(args)?;
    if flags.list {
        for (name, _) in TARGETS {
            println!("{name}");
        }
        return Ok(true);
    }
    if let Err(missing) = check_tools() {
        if flags.skip_missing {
            println!("fuzz: skipped: {missing}");
            return Ok(true);
        }
        bail!("fuzz: {missing}");
    }
    let fuzz_dir = root.join("fuzz");
    let seeds_dir = root.join("target/fuzz-seeds");
    let logs_dir = root.join("target/fuzz-logs");
    std::fs::create_dir_all(&logs_dir)?;
    let targets: Vec<(&str, Option<&str>)> = TARGETS
        .into_iter()
        .filter(|(name, _)| flags.targets.is_empty() || flags.targets.iter().any(|t| t == name))
        .collect();
    for (name, _) in &targets {
        let n = seeds::build(root, name, &seeds_dir.join(name))?;
        println!("fuzz: {name}: {n} seed(s)");
    }

    let sanitizer = if flags.asan { "address" } else { "none" };
    let mut build_flags = vec!["-s", sanitizer];
    if flags.dev {
        build_flags.push("--dev");
    }
    println!(
        "fuzz: building the targets (cargo +nightly fuzz build {})",
        build_flags.join(" ")
    );
    let status = Command::new("cargo")
        .current_dir(&fuzz_dir)
        .args(["+nightly", "fuzz", "build"])
        .args(&build_flags)
        .status()
        .context("running cargo +nightly fuzz build")?;
    if !status.success() {
        bail!("fuzz: building the fuzz targets failed ({status})");
    }

    let mut results = Vec::new();
    for (name, dict) in &targets {
        let corpus = fuzz_dir.join("corpus").join(name);
        let artifacts = fuzz_dir.join("artifacts").join(name);
        std::fs::create_dir_all(&corpus)?;
        std::fs::create_dir_all(&artifacts)?;
        let mut command = Command::new("cargo");
        command
            .current_dir(&fuzz_dir)
            .args(["+nightly", "fuzz", "run"])
            .args(&build_flags)
            .arg(name)
            .arg(&corpus)
            .arg(seeds_dir.join(name))
            .arg("--")
            .arg(format!("-max_total_time={}", flags.seconds))
            .arg("-print_final_stats=1")
            .arg("-timeout=10")
            .arg("-rss_limit_mb=2048")
            .arg(format!("-artifact_prefix={}/", artifacts.display()));
        if let Some(runs) = flags.runs {
            command.arg(format!("-runs={runs}"));
        }
        if let Some(dict) = dict {
            command.arg(format!(
                "-dict={}",
                fuzz_dir.join("dict").join(dict).display()
            ));
        }
        println!("fuzz: {name}: running for up to {} s", flags.seconds);
        let output = command
            .stdin(Stdio::null())
            .output()
            .with_context(|| format!("running cargo fuzz run {name}"))?;
        let mut log = String::from_utf8_lossy(&output.stdout).into_owned();
        log.push_str(&String::from_utf8_lossy(&output.stderr));
        let log_path = logs_dir.join(format!("{name}.log"));
        std::fs::write(&log_path, &log)?;
        let mut stats = parse_stats(&log);
        if !output.status.success() && stats.crash.is_none() {
            stats.crash = Some((
                log_path.display().to_string(),
                format!("cargo fuzz run failed ({}), see the log", output.status),
            ));
        }
        println!("{}", report_line(name, &stats));
        results.push((name.to_string(), stats));
    }

    println!("\n{}", table(&results));
    let crashed: Vec<&str> = results
        .iter()
        .filter(|(_, s)| s.crash.is_some())
        .map(|(n, _)| n.as_str())
        .collect();
    if crashed.is_empty() {
        println!("fuzz: no crash in {} target(s)", results.len());
        Ok(true)
    } else {
        println!(
            "fuzz: {} crashed; reproduce with `cd fuzz && cargo +nightly fuzz run {} <target> <artifact>`",
            crashed.join(", "),
            build_flags.join(" ")
        );
        Ok(false)
    }
}

/// Whether `cargo +nightly` and cargo-fuzz run; the message says what is missing and how to
/// install it.
fn check_tools() -> Result<(), String> {
    let works = |args: &[&str]| {
        Command::new("cargo")
            .args(args)
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .status()
            .is_ok_and(|s| s.success())
    };
    if !works(&["+nightly", "--version"]) {
        return Err(
            "the nightly toolchain is missing (`cargo +nightly` fails); \
                    install it with `rustup toolchain install nightly`"
                .to_owned(),
        );
    }
    if !works(&["+nightly", "fuzz", "--version"]) {
        return Err("cargo-fuzz is missing; install it with `cargo install cargo-fuzz`".to_owned());
    }
    Ok(())
}

fn report_line(name: &str, s: &Stats) -> String {
    let opt = |v: Option<u64>| v.map_or_else(|| "?".to_owned(), |v| v.to_string());
    let mut line = format!(
        "fuzz: {name}: {} executions ({} exec/s), cov {}, ft {}, corpus {}",
        opt(s.executions),
        opt(s.exec_per_sec),
        opt(s.coverage),
        opt(s.features),
        s.corpus.as_deref().unwrap_or("?"),
    );
    match &s.crash {
        Some((artifact, why)) => {
            let _ = write!(line, ", CRASH: {why} (input: {artifact})");
        }
        None => line.push_str(", no crash"),
    }
    line
}

fn table(results: &[(String, Stats)]) -> String {
    let opt = |v: Option<u64>| v.map_or_else(|| "?".to_owned(), |v| v.to_string());
    let mut out = format!(
        "{:<18} {:>12} {:>8} {:>7} {:>8} {:>12} {:>8}\n",
        "target", "executions", "exec/s", "cov", "ft", "corpus", "crashes"
    );
    for (name, s) in results {
        let _ = writeln!(
            out,
            "{:<18} {:>12} {:>8} {:>7} {:>8} {:>12} {:>8}",
            name,
            opt(s.executions),
            opt(s.exec_per_sec),
            opt(s.coverage),
            opt(s.features),
            s.corpus.as_deref().unwrap_or("?"),
            usize::from(s.crash.is_some()),
        );
    }
    out.trim_end().to_owned()
}

/// The seed corpora, built at run time from files read in place.
mod seeds {
    use super::*;

    /// Fills `dir` (emptied first) with the seeds of `target`; returns how many.
    pub(super) fn build(root: &Path, target: &str, dir: &Path) -> Result<usize> {
        if dir.exists() {
            std::fs::remove_dir_all(dir)?;
        }
        std::fs::create_dir_all(dir)?;
        let shared = root.join("../shared/scenes");
        let mut seeds: BTreeMap<String, Vec<u8>> = BTreeMap::new();
        let add_files = |seeds: &mut BTreeMap<String, Vec<u8>>, files: Vec<PathBuf>| {
            for f in files {
                if let Ok(bytes) = std::fs::read(&f) {
                    seeds.insert(seed_name(&f), bytes);
                }
            }
        };
        match target {
            "toml_scene" => {
                let mut files = find(&root.join("scenes"), &["toml"]);
                files.extend(find(&root.join("tests"), &["toml"]));
                files.push(root.join("crates/cli/src/default_scene.toml"));
                files.extend(find(&shared, &["toml"]));
                add_files(&mut seeds, files);
            }
            "obj" => {
                for obj in find(&shared, &["obj"]) {
                    let Ok(text) = std::fs::read(&obj) else {
                        continue;
                    };
                    let mut seed = text.clone();
                    if let Some(mtl) = mtllib(&obj, &text)
                        && let Ok(m) = std::fs::read(mtl)
                        && m.len() as u64 <= MAX_SEED_BYTES
                    {
                        seed.push(0);
                        seed.extend_from_slice(&m);
                    }
                    seeds.insert(seed_name(&obj), seed);
                }
            }
            "gltf" => {
                for gltf in find(&shared, &["gltf"]) {
                    let Ok(mut seed) = std::fs::read(&gltf) else {
                        continue;
                    };
                    let dir = gltf.parent().unwrap_or(Path::new("."));
                    if let Some(bin) = find(dir, &["bin"]).into_iter().next()
                        && let Ok(b) = std::fs::read(bin)
                    {
                        seed.push(0);
                        seed.extend_from_slice(&b);
                    }
                    seeds.insert(seed_name(&gltf), seed);
                }
            }
            "glb" => add_files(&mut seeds, find(&shared, &["glb"])),
            "mitsuba" => add_files(&mut seeds, find(&shared.join("mitsuba3"), &["xml"])),
            "pbrt" => add_files(&mut seeds, find(&shared, &["pbrt"])),
            "ply" => add_files(&mut seeds, find(&shared, &["ply"])),
            "vol" => seeds.extend(vol_grids(root)),
            "exr" => {
                add_files(&mut seeds, find(&root.join("tests/golden"), &["exr"]));
                seeds.insert("tiny.exr".to_owned(), tiny_exr(root)?);
            }
            "checkpoint" => {
                for (name, bytes) in checkpoints()? {
                    seeds.insert(name, bytes);
                }
            }
            "part" => seeds.extend(parts()?),
            "texture" => {
                seeds.extend(images()?);
                for f in find(&shared, &["png", "jpg", "jpeg", "exr", "hdr"]) {
                    if std::fs::metadata(&f).is_ok_and(|m| m.len() <= MAX_IMAGE_SEED_BYTES)
                        && let Ok(bytes) = std::fs::read(&f)
                    {
                        seeds.insert(seed_name(&f), bytes);
                    }
                }
            }
            "envmap" => seeds.extend(environment_maps(root)?),
            "checkpoint_columns" => {
                let scene = harness::checkpoint_scene();
                for (i, (name, _, columns)) in
                    harness::column_checkpoints(&scene).into_iter().enumerate()
                {
                    let mut seed = vec![i as u8];
                    seed.extend_from_slice(&columns);
                    seeds.insert(name, seed);
                }
            }
            _ => {}
        }
        seeds.retain(|_, bytes| bytes.len() as u64 <= MAX_SEED_BYTES);
        for (name, bytes) in &seeds {
            std::fs::write(dir.join(name), bytes)?;
        }
        Ok(seeds.len())
    }

    /// A file name for a seed: its path with separators flattened.
    fn seed_name(path: &Path) -> String {
        let parts: Vec<String> = path
            .components()
            .rev()
            .take(3)
            .map(|c| c.as_os_str().to_string_lossy().into_owned())
            .collect();
        parts.into_iter().rev().collect::<Vec<_>>().join("_")
    }

    /// Files under `dir` (recursively, sorted) with one of the extensions, at most
    /// [`MAX_SEED_BYTES`] long.
    pub(super) fn find(dir: &Path, extensions: &[&str]) -> Vec<PathBuf> {
        let mut out = Vec::new();
        let mut stack = vec![dir.to_path_buf()];
        while let Some(d) = stack.pop() {
            let Ok(entries) = std::fs::read_dir(&d) else {
                continue;
            };
            for entry in entries.flatten() {
                let path = entry.path();
                let Ok(meta) = entry.metadata() else {
                    continue;
                };
                if meta.is_dir() {
                    stack.push(path);
                } else if meta.len() <= MAX_SEED_BYTES
                    && path
                        .extension()
                        .is_some_and(|e| extensions.iter().any(|x| e.eq_ignore_ascii_case(x)))
                {
                    out.push(path);
                }
            }
        }
        out.sort();
        out
    }

    /// The MTL file an OBJ names in its first `mtllib` line.
    fn mtllib(obj: &Path, text: &[u8]) -> Option<PathBuf> {
        let text = String::from_utf8_lossy(text);
        let name = text
            .lines()
            .find_map(|l| l.trim().strip_prefix("mtllib "))?
            .trim();
        Some(obj.parent()?.join(name))
    }

    /// A 3 × 2 EXR written by `film` (with an auxiliary channel and metadata).
    fn tiny_exr(root: &Path) -> Result<Vec<u8>> {
        let path = root.join("target/fuzz-seeds/tiny.exr");
        let pixels = (0..6)
            .map(|i| [i as f32, 0.5, 1.0 / (1.0 + i as f32)])
            .collect();
        let mut frame = film::Frame::new(film::Image::new(3, 2, pixels));
        frame.add_aov(&["depth"], &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
        film::write_exr(&path, &frame)?;
        let bytes = std::fs::read(&path)?;
        std::fs::remove_file(&path)?;
        Ok(bytes)
    }

    /// Parts for the `part` target (its mode 2, fields and decompressed sums, and the same parts
    /// as files in modes 0 and 1): the exact sums of two `appm` passes of the checkpoint
    /// target's scene, and hand-made parts with zero, negative and extreme sums.
    pub(super) fn parts() -> Result<Vec<(String, Vec<u8>)>> {
        let scene = harness::checkpoint_scene();
        let mut params = ppm::RenderParams::preview();
        params.method = ppm::Method::Appm;
        params.budget.photons_per_pass = 64;
        params.budget.photons_auto = false;
        params.budget.max_depth = 8;
        let mut renderer = ppm::Renderer::new(std::sync::Arc::clone(&scene), params)?;
        renderer.iterate();
        renderer.iterate();
        let rendered = renderer
            .pass_sums()
            .context("an appm renderer has pass sums")?
            .clone();
        let part = |unit, first_pass, passes, sums: Vec<[i128; 3]>| ppm::Part {
            plan: harness::PART_PLAN,
            unit,
            first_pass,
            sums: ppm::PassSums { passes, sums },
        };
        let parts = [
            (
                "rendered",
                part(1, 2, rendered.passes, rendered.sums.clone()),
            ),
            ("zero", part(0, 0, 0, vec![[0; 3]])),
            ("small", part(3, 7, 2, vec![[1, -1, 1 << 64]; 4])),
            (
                "extreme",
                part(
                    u32::MAX,
                    u32::MAX,
                    u64::MAX,
                    vec![[i128::MAX, i128::MIN, -1]; 2],
                ),
            ),
        ];
        let mut out = Vec::new();
        for (name, p) in parts {
            let pixels = u8::try_from(p.sums.sums.len() - 1)?;
            out.push((format!("{name}-fields"), harness::part_input(&p, pixels)));
            let file = p.to_bytes();
            let mut raw = vec![0, pixels];
            raw.extend_from_slice(&file);
            out.push((format!("{name}-file"), raw));
            // Mode 1: the file without its magic, version, plan and checksum.
            let mut framed = vec![1, pixels];
            framed.extend_from_slice(&file[20..file.len() - 8]);
            out.push((format!("{name}-compressed"), framed));
        }
        Ok(out)
    }

    /// Small images of every kind the texture loader reads: 8- and 16-bit PNG (grey, RGB,
    /// RGBA with a mask), JPEG, OpenEXR (half and float) and Radiance HDR. The JPEG, EXR and HDR
    /// encoders are the `image` features `import` enables (Cargo unifies them).
    /// The `vol` target's seeds: the `.vol` grids of `scenes/` and a small ramp written by
    /// `import::write_vol`.
    pub(super) fn vol_grids(root: &Path) -> Vec<(String, Vec<u8>)> {
        let mut seeds = BTreeMap::new();
        for f in find(&root.join("scenes"), &["vol"]) {
            if let Ok(bytes) = std::fs::read(&f) {
                seeds.insert(seed_name(&f), bytes);
            }
        }
        let ramp: Vec<f32> = (0..4 * 3 * 2).map(|i| (i % 4) as f32 * 0.5).collect();
        seeds.insert(
            "ramp.vol".to_owned(),
            import::write_vol([4, 3, 2], glam::Vec3::ZERO, glam::Vec3::ONE, &ramp),
        );
        seeds.into_iter().collect()
    }

    pub(super) fn images() -> Result<Vec<(String, Vec<u8>)>> {
        use image::{DynamicImage, ImageBuffer, ImageFormat, Luma, Rgb, Rgb32FImage, Rgba};
        let encode = |img: DynamicImage, format: ImageFormat| -> Result<Vec<u8>> {
            let mut out = std::io::Cursor::new(Vec::new());
            img.write_to(&mut out, format)?;
            Ok(out.into_inner())
        };
        let rgb8 = ImageBuffer::from_fn(3, 2, |x, y| Rgb([(x * 80) as u8, (y * 200) as u8, 30]));
        let rgba8 = ImageBuffer::from_fn(2, 2, |x, y| {
            Rgba([200, 100, 50, if x == y { 255 } else { 0 }])
        });
        let grey = ImageBuffer::from_fn(4, 4, |x, y| Luma([((x + y) * 30) as u8]));
        let rgb16: ImageBuffer<Rgb<u16>, Vec<u16>> =
            ImageBuffer::from_fn(2, 1, |x, _| Rgb([x as u16 * 40000, 1000, 65535]));
        let float = Rgb32FImage::from_fn(3, 2, |x, y| Rgb([x as f32 * 0.5, y as f32 * 2.0, 0.25]));
        Ok(vec![
            (
                "rgb8.png".into(),
                encode(DynamicImage::ImageRgb8(rgb8.clone()), ImageFormat::Png)?,
            ),
            (
                "rgba8.png".into(),
                encode(DynamicImage::ImageRgba8(rgba8), ImageFormat::Png)?,
            ),
            (
                "grey.png".into(),
                encode(DynamicImage::ImageLuma8(grey), ImageFormat::Png)?,
            ),
            (
                "rgb16.png".into(),
                encode(DynamicImage::ImageRgb16(rgb16), ImageFormat::Png)?,
            ),
            (
                "rgb8.jpg".into(),
                encode(DynamicImage::ImageRgb8(rgb8), ImageFormat::Jpeg)?,
            ),
            (
                "float.exr".into(),
                encode(
                    DynamicImage::ImageRgb32F(float.clone()),
                    ImageFormat::OpenExr,
                )?,
            ),
            (
                "float.hdr".into(),
                encode(DynamicImage::ImageRgb32F(float), ImageFormat::Hdr)?,
            ),
        ])
    }

    /// Inputs of the `envmap` target: 2:1 maps as OpenEXR (mode 0) and Radiance HDR (mode 1),
    /// one written by `film` as `fppm` writes its images, raw texels (mode 2) with zero,
    /// negative, subnormal, huge and NaN values, and a square map of a pbrt `infinite` light
    /// (mode 3).
    pub(super) fn environment_maps(root: &Path) -> Result<Vec<(String, Vec<u8>)>> {
        use image::{DynamicImage, ImageFormat, Rgb, Rgb32FImage};
        let sky = Rgb32FImage::from_fn(8, 4, |x, y| {
            Rgb([
                1.0 + x as f32,
                0.5 * (y as f32),
                if x == 3 && y == 1 { 50.0 } else { 0.2 },
            ])
        });
        let encode = |format: ImageFormat| -> Result<Vec<u8>> {
            let mut out = std::io::Cursor::new(Vec::new());
            DynamicImage::ImageRgb32F(sky.clone()).write_to(&mut out, format)?;
            Ok(out.into_inner())
        };
        let square = {
            let mut out = std::io::Cursor::new(Vec::new());
            let map = Rgb32FImage::from_fn(4, 4, |x, y| Rgb([x as f32, y as f32, 0.5]));
            DynamicImage::ImageRgb32F(map).write_to(&mut out, ImageFormat::OpenExr)?;
            out.into_inner()
        };
        let with_mode = |mode: u8, bytes: Vec<u8>| {
            let mut seed = vec![mode];
            seed.extend(bytes);
            seed
        };
        let raw = |rows: u8, scale: f32, texels: &[f32]| {
            let mut seed = vec![2, rows];
            for v in [scale, 0.0, 30.0, 0.0].iter().chain(texels) {
                seed.extend_from_slice(&v.to_le_bytes());
            }
            seed
        };
        Ok(vec![
            (
                "sky-exr".into(),
                with_mode(0, encode(ImageFormat::OpenExr)?),
            ),
            ("sky-hdr".into(), with_mode(1, encode(ImageFormat::Hdr)?)),
            ("film-exr".into(), with_mode(0, tiny_exr_2to1(root)?)),
            ("pbrt-square-exr".into(), with_mode(3, square)),
            (
                "raw-sun".into(),
                raw(1, 1.0, &[0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1e4, 1e4, 1e4]),
            ),
            (
                "raw-mixed".into(),
                raw(2, 2.0, &[0.0, -1.0, 1e-40, 3e38, 1.0, f32::NAN, 0.5]),
            ),
            ("raw-huge".into(), raw(0, 1e30, &[1e30, 2e30, 3e30])),
        ])
    }

    /// A 4 × 2 EXR written by `film` (half the texels black).
    fn tiny_exr_2to1(root: &Path) -> Result<Vec<u8>> {
        let dir = root.join("target/fuzz-seeds");
        std::fs::create_dir_all(&dir)?;
        let path = dir.join("sky.exr");
        let pixels = (0..8)
            .map(|i| {
                if i % 2 == 0 {
                    [0.0; 3]
                } else {
                    [i as f32, 1.0, 0.5]
                }
            })
            .collect();
        film::write_exr(&path, &film::Frame::new(film::Image::new(4, 2, pixels)))?;
        let bytes = std::fs::read(&path)?;
        std::fs::remove_file(&path)?;
        Ok(bytes)
    }

    /// Bodies of checkpoints of the checkpoint target's scene (what the target takes: without
    /// the header and the checksum it writes itself), one per method, after one and two passes.
    pub(super) fn checkpoints() -> Result<Vec<(String, Vec<u8>)>> {
        let scene = harness::checkpoint_scene();
        let mut out = Vec::new();
        for method in ppm::Method::ALL {
            let mut renderer = ppm::Renderer::new(
                std::sync::Arc::clone(&scene),
                harness::checkpoint_params(method),
            )?;
            for pass in 1..=2 {
                renderer.iterate();
                let saved = renderer.save_state("seed");
                let body = harness::checkpoint_body(&saved).to_vec();
                out.push((format!("{}-{pass}", method.name()), body));
            }
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use import::{LoadOptions, load_from};

    use super::{harness, parse_stats, seeds};

    /// The stubs the fuzz targets serve are real files: a harness serving broken stubs would
    /// only ever fuzz error paths.
    #[test]
    fn the_fuzz_stubs_load() {
        let toml = "format = 1\n[[shapes]]\ntype = \"mesh\"\nfile = \"a.obj\"\n\
                    [[shapes]]\ntype = \"mesh\"\nfile = \"b.gltf\"\n";
        let path = harness::fuzzed("scene.toml");
        let files = harness::with_stubs(path.clone(), toml.into());
        let d = load_from(&path, files, &LoadOptions::default()).unwrap();
        assert_eq!(
            d.triangles.len(),
            2 + 1,
            "the OBJ quad and the glTF triangle"
        );
        assert_eq!(
            d.materials
                .iter()
                .filter(|m| m.emission.max_element() > 0.0)
                .count(),
            1
        );

        let path = harness::fuzzed("scene.pbrt");
        let files = harness::with_stubs(path.clone(), harness::PLY_SCENE.into());
        let d = load_from(&path, files, &LoadOptions::default()).unwrap();
        assert_eq!((d.triangles.len(), d.lights.len()), (1, 1));

        let xml = r#"<scene version="3.0.0"><shape type="ply"><string name="filename" value="m.ply"/></shape></scene>"#;
        let path = harness::fuzzed("scene.xml");
        let files = harness::with_stubs(path.clone(), xml.into());
        let d = load_from(&path, files, &LoadOptions::allow_no_emitter()).unwrap();
        assert_eq!(d.triangles.len(), 1);
        assert!(harness::split_nul(b"obj\0mtl") == (&b"obj"[..], &b"mtl"[..]));
    }

    /// The checkpoint seeds, framed again by the harness, are the checkpoints that were saved,
    /// and restore.
    #[test]
    fn checkpoint_seeds_restore_through_the_harness_framing() {
        let scene = harness::checkpoint_scene();
        let seeds = seeds::checkpoints().unwrap();
        assert_eq!(seeds.len(), 2 * ppm::Method::ALL.len());
        for (name, body) in &seeds {
            let bytes = harness::checkpoint_bytes(&scene, body);
            let restored = ppm::Renderer::restore(std::sync::Arc::clone(&scene), &bytes);
            assert!(restored.is_ok(), "{name}: {:?}", restored.err());
        }
    }

    /// Every `.vol` seed loads as the grid of the `vol` target's scene and builds.
    #[test]
    fn vol_seeds_load_as_grids() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
        let seeds = seeds::vol_grids(&root);
        assert!(
            seeds.len() >= 2,
            "{:?}",
            seeds.iter().map(|s| &s.0).collect::<Vec<_>>()
        );
        for (name, bytes) in seeds {
            let path = harness::fuzzed("scene.toml");
            let grid = harness::fuzzed("smoke.vol");
            let files = import::MemoryFiles::new()
                .with(&path, harness::VOL_SCENE)
                .with(&grid, bytes);
            let d = load_from(&path, files, &LoadOptions::default())
                .unwrap_or_else(|e| panic!("{name}: {e}"));
            assert!(d.media.list[0].density.is_some(), "{name}");
            scene::Scene::new(d).unwrap_or_else(|e| panic!("{name}: {e}"));
        }
    }

    /// Every texture seed loads through the `texture` target's scene: a harness whose seeds
    /// failed to load would only fuzz the decoders' error paths.
    #[test]
    fn texture_seeds_load_as_textures() {
        let seeds = seeds::images().unwrap();
        assert_eq!(seeds.len(), 7);
        for (name, bytes) in seeds {
            let (path, files) = harness::texture_files(bytes);
            let d = load_from(&path, files, &LoadOptions::default())
                .unwrap_or_else(|e| panic!("{name}: {e}"));
            let textured = d.materials.iter().filter(|m| m.textures.is_some()).count();
            assert_eq!(textured, 2, "{name}: the floor and the sign are textured");
            scene::Scene::new(d).unwrap_or_else(|e| panic!("{name}: {e}"));
        }
    }

    /// The file seeds of the `envmap` target load as the scene's environment; the raw-texel
    /// seeds are what the target decodes (mode byte 2).
    #[test]
    fn environment_map_seeds_load() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
        let seeds = seeds::environment_maps(&root).unwrap();
        let mut files = 0;
        for (name, seed) in &seeds {
            let (mode, bytes) = seed.split_first().unwrap();
            if *mode == 2 {
                continue;
            }
            files += 1;
            let d = if *mode == 3 {
                let (path, files) = harness::envmap_pbrt_files(bytes.to_vec());
                load_from(&path, files, &LoadOptions::default())
            } else {
                let (path, files) = harness::envmap_files(bytes.to_vec(), *mode == 1);
                load_from(&path, files, &LoadOptions::default())
            }
            .unwrap_or_else(|e| panic!("{name}: {e}"));
            let scene = scene::Scene::new(d).unwrap_or_else(|e| panic!("{name}: {e}"));
            assert!(scene.lights().has_environment(), "{name}");
        }
        assert_eq!(files, 4);
    }

    /// The part seeds decode through the `part` target's framing, each as the part it was made
    /// from, in all three modes.
    #[test]
    fn part_seeds_decode_through_the_harness_framing() {
        let seeds = seeds::parts().unwrap();
        assert_eq!(seeds.len(), 4 * 3);
        for (name, seed) in &seeds {
            let (bytes, pixels) = harness::part_bytes(seed);
            let part = ppm::Part::from_bytes(&bytes, harness::PART_PLAN, pixels)
                .unwrap_or_else(|e| panic!("{name}: {e}"));
            assert_eq!(part.sums.sums.len(), pixels, "{name}");
            assert_eq!(part.to_bytes(), bytes, "{name}: the same part");
        }
    }

    /// The column seeds, joined to their heads as the `checkpoint_columns` target does,
    /// restore.
    #[test]
    fn checkpoint_column_seeds_restore() {
        let scene = harness::checkpoint_scene();
        let split = harness::column_checkpoints(&scene);
        assert_eq!(split.len(), 2 * ppm::Method::ALL.len());
        for (name, head, columns) in &split {
            let bytes = ppm::checkpoint_surgery::join(head, columns);
            let restored = ppm::Renderer::restore(std::sync::Arc::clone(&scene), &bytes);
            assert!(restored.is_ok(), "{name}: {:?}", restored.err());
        }
    }

    /// The end of a real libFuzzer run (the toml_scene target, 10 s).
    #[test]
    fn final_stats_and_coverage_are_read() {
        let log = "\
#32768\tpulse  cov: 3787 ft: 10166 corp: 989/2967Kb lim: 9652 exec/s: 4681 rss: 54Mb
#58122\tDONE   cov: 3879 ft: 10890 corp: 1205/3583Kb lim: 9652 exec/s: 5283 rss: 54Mb
Done 58122 runs in 11 second(s)
stat::number_of_executed_units: 58122
stat::average_exec_per_sec:     5283
stat::new_units_added:          2261
stat::slowest_unit_time_sec:    0
stat::peak_rss_mb:              54
";
        let s = parse_stats(log);
        assert_eq!(s.executions, Some(58122));
        assert_eq!(s.exec_per_sec, Some(5283));
        assert_eq!(s.new_units, Some(2261));
        assert_eq!(s.peak_rss_mb, Some(54));
        assert_eq!(s.coverage, Some(3879));
        assert_eq!(s.features, Some(10890));
        assert_eq!(s.corpus.as_deref(), Some("1205/3583Kb"));
        assert_eq!(s.crash, None);
    }

    /// A real crash (the checkpoint target before its fix), abridged.
    #[test]
    fn a_crash_gives_its_reason_and_input() {
        let log = "\
#80\tNEW    cov: 1563 ft: 2225 corp: 38/82Kb lim: 2773 exec/s: 0 rss: 54Mb L: 517/2773 MS: 1 InsertByte-

thread '<unnamed>' (17628) panicked at /work/wt-fuzz/crates/ppm/src/update.rs:102:9:
radius must be positive, got 0
==17621== ERROR: libFuzzer: deadly signal
SUMMARY: libFuzzer: deadly signal
artifact_prefix='/w/fuzz/artifacts/checkpoint/'; Test unit written to /w/fuzz/artifacts/checkpoint/crash-7091
stat::number_of_executed_units: 81
";
        let s = parse_stats(log);
        assert_eq!(s.executions, Some(81));
        assert_eq!(s.coverage, Some(1563));
        let (input, why) = s.crash.unwrap();
        assert_eq!(input, "/w/fuzz/artifacts/checkpoint/crash-7091");
        assert!(why.contains("update.rs:102:9"), "{why}");
    }
}
