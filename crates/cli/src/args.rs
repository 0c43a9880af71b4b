//! Stage one: the flags as clap parses them, as close to the command line as possible.
//! Ranges are checked in `settings.rs`, where the flags meet the scene's `[render]` defaults.

// The doc comments below are clap's help text, shown as written: `[render]` there names the
// scene file's table, not an item to link.
#![allow(rustdoc::broken_intra_doc_links)]

use std::path::PathBuf;
use std::time::Duration;

use clap::{Args, Parser, Subcommand, ValueEnum};

/// Render scenes with progressive photon mapping (PPM, SPPM) and frequency-guided kernels.
///
/// With no subcommand, fppm renders the built-in default scene (a caustic inside a mirror
/// half-cylinder) with the flags below, and writes fppm.exr and fppm.png in the current
/// directory.
#[derive(Debug, Parser)]
#[command(
    name = "fppm",
    version,
    args_conflicts_with_subcommands = true,
    args_override_self = true,
    after_help = "Examples:\n  \
        fppm                                   render the default scene to fppm.exr and fppm.png\n  \
        fppm render scene.toml --time 30s -o out.exr\n  \
        fppm render model.obj --method sppm --passes 64 --png model.png\n  \
        fppm render scene.toml --checkpoint state.fppm --passes 16\n  \
        fppm resume state.fppm --passes 64\n  \
        fppm diff a.exr b.exr --out diff.png\n  \
        fppm info scene.toml\n  \
        fppm scene default > default.toml\n\n\
        Exit codes: 0 success, 1 load/render/IO error, 2 usage error, 130 interrupted (Ctrl-C)."
)]
pub(crate) struct Cli {
    #[command(subcommand)]
    pub(crate) command: Option<Command>,
    /// Flags for rendering the default scene (when no subcommand is given).
    #[command(flatten)]
    pub(crate) render: RenderArgs,
}

/// The subcommands.
// Parsed once per process: the size of the render variant does not matter.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Subcommand)]
pub(crate) enum Command {
    /// Render a scene file (.toml, .obj with its .mtl, .gltf, .glb, Mitsuba 3 .xml, pbrt-v4 .pbrt).
    Render {
        /// The scene file.
        #[arg(value_name = "SCENE")]
        scene: PathBuf,
        #[command(flatten)]
        args: RenderArgs,
    },
    /// Continue a render from a checkpoint written by --checkpoint.
    ///
    /// The scene is reloaded from the path stored in the checkpoint. With --passes N the render
    /// continues to N passes in total, and the image is bit-for-bit that of an uninterrupted
    /// N-pass run. The checkpoint file is updated after every pass.
    Resume(ResumeArgs),
    /// Compare two EXR images: RMSE, relative MSE and mean ratio of their RGB channels.
    Diff(DiffArgs),
    /// Print what a scene contains (triangles, materials, emitters, camera, bounds) without
    /// rendering; without SCENE, the built-in default scene.
    Info {
        /// The scene file.
        #[arg(value_name = "SCENE")]
        scene: Option<PathBuf>,
    },
    /// Print a built-in scene as TOML: `fppm scene default > default.toml`.
    Scene {
        /// Which built-in scene.
        #[arg(value_enum)]
        name: BuiltinScene,
    },
}

/// Built-in scenes.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub(crate) enum BuiltinScene {
    /// The caustic inside a mirror half-cylinder (rendered when fppm runs without arguments).
    Default,
}

/// Everything `fppm render` takes besides the scene.
#[derive(Debug, Args)]
pub(crate) struct RenderArgs {
    #[command(flatten)]
    pub(crate) params: ParamArgs,
    #[command(flatten)]
    pub(crate) budget: BudgetArgs,
    /// Film width in pixels (overrides the scene; alone, keeps the scene's aspect ratio).
    #[arg(long, value_name = "PIXELS", help_heading = "Image")]
    pub(crate) width: Option<u32>,
    /// Film height in pixels (overrides the scene; alone, keeps the scene's aspect ratio).
    #[arg(long, value_name = "PIXELS", help_heading = "Image")]
    pub(crate) height: Option<u32>,
    #[command(flatten)]
    pub(crate) output: OutputArgs,
    /// Auxiliary outputs written as extra EXR channels, comma separated.
    #[arg(
        long,
        value_enum,
        value_delimiter = ',',
        value_name = "LIST",
        help_heading = "Output"
    )]
    pub(crate) aov: Vec<AovArg>,
    /// Save the exact render state to this file after every pass and at exit (see `fppm resume`).
    #[arg(long, value_name = "FILE", help_heading = "Output")]
    pub(crate) checkpoint: Option<PathBuf>,
    #[command(flatten)]
    pub(crate) run: RunArgs,
}

/// Integrator parameters; each overrides the scene's `[render]` table.
#[derive(Debug, Args)]
#[command(next_help_heading = "Integrator")]
pub(crate) struct ParamArgs {
    /// Integrator [default: scene's [render] method, else ppm].
    #[arg(long, value_enum)]
    pub(crate) method: Option<MethodArg>,
    /// Photons traced per pass, e.g. 200000, 200_000, 200k or 2M [default: scene, else 100k].
    #[arg(long, value_name = "N", allow_negative_numbers = true, value_parser = parse_count)]
    pub(crate) photons_per_pass: Option<i64>,
    /// Radius reduction α in (0, 1] [default: scene, else 0.7].
    #[arg(long, allow_negative_numbers = true)]
    pub(crate) alpha: Option<f64>,
    /// Initial gather radius in scene units [default: scene, else picked from the scene size].
    #[arg(long, value_name = "RADIUS", allow_negative_numbers = true)]
    pub(crate) initial_radius: Option<f64>,
    /// Share of photons that carry a light-field spectrum, in [0, 1] (frequency methods)
    /// [default: 0.1].
    #[arg(long, value_name = "SHARE", allow_negative_numbers = true)]
    pub(crate) freq_fraction: Option<f64>,
    /// How a hitpoint merges frequency estimates [default: min].
    #[arg(long, value_enum, value_name = "POLICY")]
    pub(crate) freq_merge: Option<MergeArg>,
    /// What happens once the PPM radius reaches the frequency radius [default: keep].
    #[arg(long, value_enum, value_name = "RULE")]
    pub(crate) freq_floor: Option<FloorArg>,
    /// Kernel radius constant K of the frequency estimate [default: 0.0720909, the strict
    /// 95 %-of-peak radius; the poster's is 0.7115].
    #[arg(long, value_name = "K", allow_negative_numbers = true)]
    pub(crate) kernel_k: Option<f64>,
    /// Largest kernel of a frequency method, as a multiple of the initial radius, in [1, 64]
    /// [default: 1, measured in docs/integrators.md; 1 never grows a kernel beyond R₀].
    #[arg(long, value_name = "G", allow_negative_numbers = true)]
    pub(crate) freq_grow: Option<f64>,
    /// α of a hitpoint held by its frequency radius, in (0, 1] [default: 0.9; 1 keeps the
    /// radius for ever, the poster's rule, which does not converge].
    #[arg(long, value_name = "A", allow_negative_numbers = true)]
    pub(crate) freq_hold_alpha: Option<f64>,
    /// Passes of the frequency pilot before the kernels are sized and the statistics restart
    /// [default: 4; 0 never grows kernels; only with --freq-grow above 1].
    #[arg(long, value_name = "N", allow_negative_numbers = true)]
    pub(crate) freq_pilot: Option<i64>,
    /// Cap every slot's radius of a frequency method at the clear radius of its gather disc
    /// (probed at every visible point), not only the held ones.
    #[arg(long)]
    pub(crate) freq_clear_cap: bool,
    /// Maximum number of scattering events on a light path, in [1, 1024] [default: scene,
    /// else 1024: in effect unlimited, paths end by Russian roulette].
    #[arg(long, value_name = "N", allow_negative_numbers = true)]
    pub(crate) max_depth: Option<i64>,
    /// Hitpoints per pixel (paths per pixel per pass for --method path), in [1, 1024]
    /// [default: 1].
    #[arg(long, value_name = "N", allow_negative_numbers = true)]
    pub(crate) spp: Option<i64>,
    /// Seed of every random number [default: scene, else 0].
    #[arg(long)]
    pub(crate) seed: Option<u64>,
    /// Add direct lighting by light sampling at hitpoints instead of gathering photons that
    /// arrive straight from an emitter.
    #[arg(long)]
    pub(crate) direct_lighting: bool,
    /// Let frequency methods hold a radius even where the gather disc hangs over an edge or a
    /// corner of the surface (no geometric bound on held kernels).
    #[arg(long)]
    pub(crate) no_freq_geometry: bool,
}

/// How long to render.
#[derive(Debug, Args)]
#[command(next_help_heading = "Budget")]
pub(crate) struct BudgetArgs {
    /// Stop after this many passes [default: scene's [render] passes, else 16]. With --time,
    /// whichever comes first.
    #[arg(long, value_name = "N", allow_negative_numbers = true)]
    pub(crate) passes: Option<i64>,
    /// Stop after the pass during which this much time has passed, e.g. 30s, 2m, 1h30m, 500ms.
    #[arg(long, value_name = "DURATION", value_parser = crate::duration::parse_positive)]
    pub(crate) time: Option<Duration>,
}

/// Output files.
#[derive(Debug, Args)]
#[command(next_help_heading = "Output")]
pub(crate) struct OutputArgs {
    /// The EXR image: linear RGB plus the --aov channels, with metadata [default: fppm.exr].
    #[arg(short = 'o', long = "output", value_name = "FILE.exr")]
    pub(crate) exr: Option<PathBuf>,
    /// The PNG preview [default: the EXR path with .png].
    #[arg(long, value_name = "FILE.png")]
    pub(crate) png: Option<PathBuf>,
    /// Exposure of the PNG in stops: pixels are scaled by 2^EV before tone mapping [default: 0].
    #[arg(long, value_name = "EV", allow_negative_numbers = true)]
    pub(crate) exposure: Option<f32>,
    /// Tone curve of the PNG: srgb clips at 1, filmic is the ACES fit of Narkowicz (2015)
    /// [default: srgb].
    #[arg(long, value_enum)]
    pub(crate) tonemap: Option<TonemapArg>,
}

/// Threads, progress and intermediate outputs.
#[derive(Debug, Args)]
#[command(next_help_heading = "Run")]
pub(crate) struct RunArgs {
    /// Worker threads [default: all cores]. The image does not depend on it.
    #[arg(long, value_name = "N", allow_negative_numbers = true)]
    pub(crate) threads: Option<i64>,
    /// Rewrite the outputs during the render, after the first pass that ends this long after
    /// the last write, e.g. 10s.
    #[arg(long, value_name = "DURATION", value_parser = crate::duration::parse_positive)]
    pub(crate) snapshot_every: Option<Duration>,
    /// Print nothing but errors.
    #[arg(short, long)]
    pub(crate) quiet: bool,
    /// Print one JSON object per pass and a final summary object on stdout.
    #[arg(long)]
    pub(crate) json: bool,
}

/// `fppm resume`.
#[derive(Debug, Args)]
pub(crate) struct ResumeArgs {
    /// The checkpoint written by `fppm render --checkpoint`.
    #[arg(value_name = "CHECKPOINT")]
    pub(crate) checkpoint: PathBuf,
    /// Continue to this many passes in total [default: the original render's --passes].
    #[arg(long, value_name = "N", allow_negative_numbers = true)]
    pub(crate) passes: Option<i64>,
    /// Render for this much more time, e.g. 30s (with --passes, whichever comes first).
    #[arg(long, value_name = "DURATION", value_parser = crate::duration::parse_positive)]
    pub(crate) time: Option<Duration>,
    /// Outputs [default: those of the original render].
    #[command(flatten)]
    pub(crate) output: OutputArgs,
    /// Auxiliary outputs [default: those of the original render].
    #[arg(
        long,
        value_enum,
        value_delimiter = ',',
        value_name = "LIST",
        help_heading = "Output"
    )]
    pub(crate) aov: Vec<AovArg>,
    #[command(flatten)]
    pub(crate) run: RunArgs,
}

/// `fppm diff`.
#[derive(Debug, Args)]
pub(crate) struct DiffArgs {
    /// The image to judge.
    #[arg(value_name = "A.exr")]
    pub(crate) a: PathBuf,
    /// The reference.
    #[arg(value_name = "B.exr")]
    pub(crate) b: PathBuf,
    /// Write a false-colour PNG of the per-pixel relative error |A−B|/(|B|+0.01), mapped from
    /// 0 (dark blue) to --max (yellow).
    #[arg(long, value_name = "FILE.png")]
    pub(crate) out: Option<PathBuf>,
    /// Relative error shown at the top of the colour ramp.
    #[arg(long, value_name = "ERROR", default_value_t = 1.0)]
    pub(crate) max: f64,
    /// Print the numbers as one JSON object.
    #[arg(long)]
    pub(crate) json: bool,
}

/// `--method`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub(crate) enum MethodArg {
    /// Progressive photon mapping (Hachisuka, Ogaki & Jensen 2008).
    Ppm,
    /// Stochastic progressive photon mapping (Hachisuka & Jensen 2009).
    Sppm,
    /// PPM with frequency-guided kernels (Belcour & Soler 2011).
    Freq,
    /// SPPM with frequency-guided kernels.
    FreqSppm,
    /// Path tracing with next-event estimation: the reference.
    Path,
}

impl MethodArg {
    pub(crate) fn method(self) -> ppm::Method {
        match self {
            MethodArg::Ppm => ppm::Method::Ppm,
            MethodArg::Sppm => ppm::Method::Sppm,
            MethodArg::Freq => ppm::Method::FreqPpm,
            MethodArg::FreqSppm => ppm::Method::FreqSppm,
            MethodArg::Path => ppm::Method::Path,
        }
    }
}

/// `--freq-merge`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub(crate) enum MergeArg {
    /// Keep the smallest radius (the most conservative estimate).
    Min,
    /// Merge as on the poster (the largest frequency content).
    PosterMax,
}

/// `--freq-floor`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub(crate) enum FloorArg {
    /// Keep the radius once it reaches the frequency radius.
    Keep,
    /// Clamp the shrinking radius at the frequency radius.
    Clamp,
}

/// `--tonemap`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub(crate) enum TonemapArg {
    /// Clip at 1, then the sRGB transfer curve.
    Srgb,
    /// ACES filmic fit (Narkowicz 2015), then the sRGB transfer curve.
    Filmic,
}

/// `--aov`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub(crate) enum AovArg {
    /// Gather radius per pixel (photon mappers): channel `radius`.
    Radius,
    /// Accumulated photon count per pixel (photon mappers): channel `count`.
    Count,
    /// Frequency radius and share of hitpoints held by it (freq, freq-sppm): channels
    /// `freq.radius`, `freq.held`.
    Freq,
    /// Albedo of the first surface: `albedo.R`, `albedo.G`, `albedo.B`.
    Albedo,
    /// Shading normal of the first surface: `normal.X`, `normal.Y`, `normal.Z`.
    Normal,
    /// Distance to the first surface: `depth`.
    Depth,
}

impl AovArg {
    /// The library's AOVs behind this flag value.
    pub(crate) fn aovs(self) -> &'static [ppm::Aov] {
        match self {
            AovArg::Radius => &[ppm::Aov::Radius],
            AovArg::Count => &[ppm::Aov::PhotonCount],
            AovArg::Freq => &[ppm::Aov::FreqRadius, ppm::Aov::FreqHeld],
            AovArg::Albedo => &[ppm::Aov::Albedo],
            AovArg::Normal => &[ppm::Aov::Normal],
            AovArg::Depth => &[ppm::Aov::Depth],
        }
    }

    /// The flag value, as typed.
    pub(crate) fn name(self) -> &'static str {
        match self {
            AovArg::Radius => "radius",
            AovArg::Count => "count",
            AovArg::Freq => "freq",
            AovArg::Albedo => "albedo",
            AovArg::Normal => "normal",
            AovArg::Depth => "depth",
        }
    }
}

/// A count with optional `_` separators and a `k` (10³) or `M` (10⁶) suffix; negative values
/// parse (and are refused later with a message naming the flag).
fn parse_count(text: &str) -> Result<i64, String> {
    let cleaned: String = text.chars().filter(|&c| c != '_').collect();
    let (digits, factor) = if let Some(d) = cleaned.strip_suffix(['k', 'K']) {
        (d, 1_000)
    } else if let Some(d) = cleaned.strip_suffix('M') {
        (d, 1_000_000)
    } else {
        (cleaned.as_str(), 1)
    };
    digits
        .parse::<i64>()
        .ok()
        .and_then(|n| n.checked_mul(factor))
        .ok_or_else(|| "expected a whole number such as 200000, 200_000, 200k or 2M".to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn method_names_match_the_library() {
        for m in MethodArg::value_variants() {
            let name = m.to_possible_value().map(|v| v.get_name().to_string());
            assert_eq!(name.as_deref(), Some(m.method().name()));
        }
        assert_eq!(MethodArg::value_variants().len(), ppm::Method::ALL.len());
    }

    #[test]
    fn counts() {
        assert_eq!(parse_count("200000"), Ok(200_000));
        assert_eq!(parse_count("200_000"), Ok(200_000));
        assert_eq!(parse_count("200k"), Ok(200_000));
        assert_eq!(parse_count("2M"), Ok(2_000_000));
        assert_eq!(parse_count("-5"), Ok(-5));
        assert!(parse_count("lots").is_err());
        assert!(parse_count("1.5").is_err());
    }

    #[test]
    fn aov_names() {
        for a in AovArg::value_variants() {
            let name = a.to_possible_value().map(|v| v.get_name().to_string());
            assert_eq!(name.as_deref(), Some(a.name()));
        }
    }

    #[test]
    fn clap_definition_is_consistent() {
        use clap::CommandFactory;
        Cli::command().debug_assert();
    }
}
