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
        scene: Option<PathBuf>,
        #[command(flatten)]
        args: RenderArgs,
    },
    /// Continue a render from a checkpoint written by --checkpoint.
    ///
    /// The scene is reloaded from the path stored in the checkpoint. With --passes N the render
    /// continues to N passes in total, and the image is bit-for-bit that of an uninterrupted
    /// N-pass run. The checkpoint file is updated during the render as `render --checkpoint`
    /// does, and at exit.
    Resume(ResumeArgs),
    /// Compare two EXR images: RMSE, relative MSE and mean ratio of their RGB channels.
    Diff(DiffArgs),
    /// Print what a scene contains (triangles, materials, emitters, camera, bounds) without
    /// rendering; without SCENE, the built-in default scene.
    Info {
        /// The scene file.
        #[arg(value_name = "SCENE")]
        scene: Option<PathBuf>,
        /// Add this environment map (.exr or .hdr), as `fppm render --env` does.
        #[arg(long, value_name = "FILE")]
        env: Option<PathBuf>,
    },
    /// Cut a pass-independent render (--method appm, the default here, vcm or bdpt) into work
    /// units: runs appm's frequency pilot once and writes JOB/plan.fppm.
    ///
    /// Each unit is then rendered by `fppm unit JOB --index I` (on any machine that sees JOB
    /// and the scene, e.g. as a Slurm array task), and `fppm merge JOB` sums the parts. The
    /// merged image is bit for bit that of `fppm render SCENE --method M --passes N`, for
    /// any number of units and any order of completion.
    Plan(PlanArgs),
    /// Render one work unit of a plan into JOB/unit-I.part.
    Unit(UnitArgs),
    /// Sum the parts of a plan into the image (EXR and PNG).
    Merge(MergeArgs),
    /// Print a built-in scene as TOML: `fppm scene default > default.toml`.
    Scene {
        /// Which built-in scene.
        #[arg(value_enum)]
        name: BuiltinScene,
    },
}

/// `fppm plan`.
#[derive(Debug, Args)]
pub(crate) struct PlanArgs {
    /// The scene file.
    #[arg(value_name = "SCENE")]
    pub(crate) scene: PathBuf,
    /// The job folder (created if needed): the plan, then the units' parts, go there.
    #[arg(short = 'o', long = "job", value_name = "JOB")]
    pub(crate) job: PathBuf,
    /// Passes of the whole render.
    #[arg(long, value_name = "N", allow_negative_numbers = true)]
    pub(crate) passes: Option<i64>,
    /// Number of work units (each renders a contiguous share of the passes).
    #[arg(long, value_name = "K", allow_negative_numbers = true)]
    pub(crate) units: i64,
    /// Also write JOB/submit.sh: a Slurm array job of the K units and a merge job that runs
    /// after them (`sh JOB/submit.sh` submits both with sbatch).
    #[arg(long)]
    pub(crate) slurm: bool,
    #[command(flatten)]
    pub(crate) params: ParamArgs,
    #[command(flatten)]
    pub(crate) film: FilmArgs,
    #[command(flatten)]
    pub(crate) run: RunArgs,
}

/// `fppm unit`.
#[derive(Debug, Args)]
pub(crate) struct UnitArgs {
    /// The job folder written by `fppm plan`.
    #[arg(value_name = "JOB")]
    pub(crate) job: PathBuf,
    /// Which unit, from 0 [default: $SLURM_ARRAY_TASK_ID, else $JOB_COMPLETION_INDEX].
    #[arg(long, value_name = "I", allow_negative_numbers = true)]
    pub(crate) index: Option<i64>,
    #[command(flatten)]
    pub(crate) run: RunArgs,
}

/// `fppm merge`.
#[derive(Debug, Args)]
pub(crate) struct MergeArgs {
    /// The job folder written by `fppm plan`, with the units' parts.
    #[arg(value_name = "JOB")]
    pub(crate) job: PathBuf,
    #[command(flatten)]
    pub(crate) output: OutputArgs,
    /// Write the image of the parts that are there (the mean of their passes) and list the
    /// missing units, instead of refusing.
    #[arg(long)]
    pub(crate) partial: bool,
    /// Print nothing but errors and warnings.
    #[arg(short, long)]
    pub(crate) quiet: bool,
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
    #[command(flatten)]
    pub(crate) film: FilmArgs,
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
    /// Save the exact render state to this file (zstd-compressed) after the first pass, then as
    /// often as keeps writing under about 5 % of the render time, and at exit (see `fppm resume`).
    #[arg(long, value_name = "FILE", help_heading = "Output")]
    pub(crate) checkpoint: Option<PathBuf>,
    #[command(flatten)]
    pub(crate) run: RunArgs,
    #[command(flatten)]
    pub(crate) live: LiveArgs,
}

/// The film and the light around it: what `render` and `plan` share.
#[derive(Debug, Args)]
#[command(next_help_heading = "Image")]
pub(crate) struct FilmArgs {
    /// Film width in pixels (overrides the scene; alone, keeps the scene's aspect ratio).
    #[arg(long, value_name = "PIXELS", help_heading = "Image")]
    pub(crate) width: Option<u32>,
    /// Film height in pixels (overrides the scene; alone, keeps the scene's aspect ratio).
    #[arg(long, value_name = "PIXELS", help_heading = "Image")]
    pub(crate) height: Option<u32>,
    /// Light the scene with this equirectangular environment map (.exr or .hdr, Mitsuba's
    /// orientation: +y up), replacing the scene's own environment if it has one.
    #[arg(long, value_name = "FILE", help_heading = "Image")]
    pub(crate) env: Option<PathBuf>,
}

/// Integrator parameters, one flag per entry of `ppm::PARAMS` (names, help and parsing are
/// defined there once); each overrides the scene's `[render]` table.
#[derive(Debug, Default)]
pub(crate) struct ParamArgs {
    /// (parameter name, text) of the flags given, in the order of `ppm::PARAMS`.
    pub(crate) values: Vec<(&'static str, String)>,
}

impl clap::FromArgMatches for ParamArgs {
    fn from_arg_matches(matches: &clap::ArgMatches) -> Result<Self, clap::Error> {
        let mut args = Self::default();
        args.update_from_arg_matches(matches)?;
        Ok(args)
    }

    fn update_from_arg_matches(&mut self, matches: &clap::ArgMatches) -> Result<(), clap::Error> {
        for param in ppm::PARAMS {
            let value = match param.kind {
                ppm::ParamKind::Value { .. } => matches.get_one::<String>(param.name).cloned(),
                ppm::ParamKind::Switch { sets } => matches
                    .get_flag(param.name)
                    .then(|| if sets { "on" } else { "off" }.to_owned()),
            };
            if let Some(value) = value {
                self.values.retain(|(name, _)| *name != param.name);
                self.values.push((param.name, value));
            }
        }
        Ok(())
    }
}

impl Args for ParamArgs {
    fn augment_args(cmd: clap::Command) -> clap::Command {
        let mut cmd = cmd.next_help_heading("Integrator");
        for param in ppm::PARAMS {
            let arg = clap::Arg::new(param.name).long(param.flag).help(param.help);
            let arg = match param.kind {
                ppm::ParamKind::Value {
                    value_name,
                    choices: [],
                } => arg
                    .value_name(value_name)
                    .allow_negative_numbers(true)
                    .action(clap::ArgAction::Set),
                ppm::ParamKind::Value {
                    value_name,
                    choices,
                } => arg
                    .value_name(value_name)
                    .value_parser(clap::builder::PossibleValuesParser::new(
                        choices.iter().map(|&(name, help)| {
                            clap::builder::PossibleValue::new(name).help(help)
                        }),
                    ))
                    .action(clap::ArgAction::Set),
                ppm::ParamKind::Switch { .. } => arg.action(clap::ArgAction::SetTrue),
            };
            cmd = cmd.arg(arg);
        }
        cmd
    }

    fn augment_args_for_update(cmd: clap::Command) -> clap::Command {
        Self::augment_args(cmd)
    }
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
    /// Refuse a render whose estimated memory exceeds this, e.g. 8G, 512M or none [default: 80 %
    /// of physical memory].
    #[arg(long, value_name = "SIZE")]
    pub(crate) max_memory: Option<String>,
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
    #[command(flatten)]
    pub(crate) live: LiveArgs,
}

/// Watching a render while it runs: the preview page and the tev stream (`live/`). Options of
/// the command, not render parameters: they never change the image.
#[derive(Debug, Args)]
#[command(next_help_heading = "Live view")]
pub(crate) struct LiveArgs {
    /// Serve a page that shows the image as it renders, with pass count, time left, the error
    /// trend and a stop button, at http://HOST:PORT/ [default: 127.0.0.1:8700, or a free port
    /// if that one is taken; the address is printed on stderr].
    #[arg(long, value_name = "HOST:PORT", num_args = 0..=1, default_missing_value = "")]
    pub(crate) preview: Option<String>,
    /// Stream the image (R, G, B and the --aov channels) to the tev viewer listening at
    /// HOST:PORT, as pbrt-v4's --display-server does (tev's default is 127.0.0.1:14158).
    #[arg(long, value_name = "HOST:PORT")]
    pub(crate) display_server: Option<String>,
}

impl LiveArgs {
    /// The scene of `fppm render`. `--preview` takes an optional address, so in
    /// `fppm render --preview scene.toml` the parser hands the scene to it: a value that cannot
    /// be a HOST:PORT, with no scene given apart, is the scene and the preview takes its
    /// default address.
    pub(crate) fn scene_of_render(&mut self, scene: Option<PathBuf>) -> anyhow::Result<PathBuf> {
        if let Some(scene) = scene {
            return Ok(scene);
        }
        let ends_in_port = |text: &str| {
            text.rsplit_once(':')
                .is_some_and(|(_, port)| port.parse::<u16>().is_ok())
        };
        match self.preview.take() {
            Some(value) if !value.is_empty() && !ends_in_port(&value) => {
                self.preview = Some(String::new());
                Ok(PathBuf::from(value))
            }
            preview => {
                self.preview = preview;
                crate::usage!(
                    "fppm render needs a SCENE file (fppm alone renders the built-in default scene)"
                )
            }
        }
    }
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
    /// Standard deviation of the pooling Gaussian per pixel (photon mappers with `--pool`):
    /// channel `pool.width`.
    #[value(name = "pool.width")]
    #[serde(rename = "pool.width")]
    PoolWidth,
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
            AovArg::PoolWidth => &[ppm::Aov::PoolWidth],
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
            AovArg::PoolWidth => "pool.width",
            AovArg::Albedo => "albedo",
            AovArg::Normal => "normal",
            AovArg::Depth => "depth",
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn aov_names() {
        for a in AovArg::value_variants() {
            let name = a.to_possible_value().map(|v| v.get_name().to_string());
            assert_eq!(name.as_deref(), Some(a.name()));
        }
    }

    #[test]
    fn every_render_parameter_has_its_flag() {
        use clap::CommandFactory;
        let cli = Cli::command();
        let render = cli
            .find_subcommand("render")
            .expect("the render subcommand");
        for param in ppm::PARAMS {
            assert!(
                render
                    .get_arguments()
                    .any(|a| a.get_long() == Some(param.flag)),
                "--{}",
                param.flag
            );
        }
    }

    #[test]
    fn clap_definition_is_consistent() {
        use clap::CommandFactory;
        Cli::command().debug_assert();
    }
}
