//! The one definition of the render parameters' names: how each is written on the command line
//! (`--photons-per-pass 200k`), in a scene's `[render]` table (`photons_per_pass = 200000`) and
//! in an image's metadata, how its text is read and shown, and its help line.
//!
//! Reading a value only converts it; ranges are checked by [`RenderParams::validate`], once the
//! values of every source (preset, scene, flags) are merged.

use spectrum::{K_POSTER, K_STRICT, MergePolicy};

use super::{CameraSequence, Method, ParamError, PoolMode, RenderParams};
use crate::update::FrequencyFloor;

/// One render parameter.
pub struct Param {
    /// The name: `snake_case` in scene tables and metadata.
    pub name: &'static str,
    /// The command-line flag without `--`: the name with `-` for `_`, or for a switch what it
    /// does (`no-freq-geometry`).
    pub flag: &'static str,
    /// One line of help, with the default.
    pub help: &'static str,
    /// How the command line gives it.
    pub kind: ParamKind,
    get: fn(&RenderParams) -> String,
    set: fn(&mut RenderParams, &str) -> Result<(), String>,
}

/// How a parameter is given on the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ParamKind {
    /// A flag with a value, e.g. `--alpha 0.5`; `choices` lists the accepted words with their
    /// meaning (empty for numbers).
    Value {
        /// The placeholder in the help, e.g. `N`.
        value_name: &'static str,
        /// Accepted words and what they mean (empty: any text the parser reads).
        choices: &'static [(&'static str, &'static str)],
    },
    /// A switch whose presence sets the parameter to `sets`, e.g. `--no-freq-geometry`.
    Switch {
        /// The value it sets.
        sets: bool,
    },
}

impl Param {
    /// The parameter's value in `params`, as text that [`RenderParams::set`] reads back.
    #[must_use]
    pub fn get(&self, params: &RenderParams) -> String {
        (self.get)(params)
    }
}

/// Every render parameter, in the order help and metadata list them.
pub const PARAMS: &[Param] = &[
    Param {
        name: "method",
        flag: "method",
        help: "Integrator [default: scene's [render] method, else freq-sppm]",
        kind: ParamKind::Value {
            value_name: "METHOD",
            choices: &[
                (
                    "ppm",
                    "Progressive photon mapping (Hachisuka, Ogaki & Jensen 2008)",
                ),
                (
                    "sppm",
                    "Stochastic progressive photon mapping (Hachisuka & Jensen 2009)",
                ),
                (
                    "freq",
                    "PPM with frequency-guided kernels (Belcour & Soler 2011)",
                ),
                ("freq-sppm", "SPPM with frequency-guided kernels"),
                (
                    "appm",
                    "Pass-independent PPM (Knaus & Zwicker 2011), kernels from a frequency pilot: passes split into work units (fppm plan/unit/merge) and merge exactly",
                ),
                (
                    "path",
                    "Path tracing with next-event estimation: the reference",
                ),
                (
                    "light",
                    "Light tracing (Mitsuba's ptracer): light paths connected to the lens, no merging; black where only mirrors or glass are seen",
                ),
                (
                    "vcm",
                    "Vertex connection and merging (Georgiev et al. 2012): bidirectional connections and merging at every camera vertex, MIS-weighted",
                ),
                (
                    "bdpt",
                    "Bidirectional path tracing: vcm's connections without merging",
                ),
            ],
        },
        get: |p| p.method.name().to_owned(),
        set: |p, v| {
            p.method = Method::from_name(v).ok_or_else(|| {
                let names: Vec<&str> = Method::ALL.iter().map(|m| m.name()).collect();
                format!("is not one of {}", names.join(", "))
            })?;
            Ok(())
        },
    },
    Param {
        name: "photons_per_pass",
        flag: "photons-per-pass",
        help: "Photons traced per pass, e.g. 200000, 200_000, 200k or 2M, or auto: for the photon mappers the larger of 100k and one per hitpoint slot (pixels times samples per pixel) [default: scene, else auto]",
        kind: ParamKind::Value {
            value_name: "N",
            choices: &[],
        },
        get: |p| {
            if p.budget.photons_auto {
                "auto".to_owned()
            } else {
                p.budget.photons_per_pass.to_string()
            }
        },
        set: |p, v| {
            if v == "auto" {
                p.budget.photons_per_pass = 100_000;
                p.budget.photons_auto = true;
                return Ok(());
            }
            p.budget.photons_auto = false;
            let n = parse_count(v)?;
            if n <= 0 {
                return Err("must be positive".to_owned());
            }
            p.budget.photons_per_pass = u32::try_from(n).map_err(|_| {
                format!(
                    "is too large: a pass of {n} photons would need about {:.1} TiB of photon buffers (at most {} photons per pass)",
                    crate::MemoryEstimate::photon_bytes(u64::try_from(n).unwrap_or(0)) as f64
                        / (1u64 << 40) as f64,
                    u32::MAX
                )
            })?;
            Ok(())
        },
    },
    Param {
        name: "alpha",
        flag: "alpha",
        help: "Radius reduction α in (0, 1] of the photon mappers' kernels and vcm's merge radius [default: scene, else 0.7]",
        kind: ParamKind::Value {
            value_name: "ALPHA",
            choices: &[],
        },
        get: |p| p.kernel.alpha.to_string(),
        set: |p, v| {
            p.kernel.alpha = parse_number(v)?;
            Ok(())
        },
    },
    Param {
        name: "initial_radius",
        flag: "initial-radius",
        help: "Initial gather radius (vcm: merge radius) in scene units, or auto [default: scene, else auto: picked from the scene size, about two pixels' footprint; a quarter of that for vcm]",
        kind: ParamKind::Value {
            value_name: "RADIUS",
            choices: &[],
        },
        get: |p| {
            p.kernel
                .initial_radius
                .map_or_else(|| "auto".to_owned(), |r| r.to_string())
        },
        set: |p, v| {
            p.kernel.initial_radius = if v == "auto" {
                None
            } else {
                Some(parse_number(v)?)
            };
            Ok(())
        },
    },
    Param {
        name: "volume_radius",
        flag: "volume-radius",
        help: "Photon mappers in participating media: the volume gather's initial radius as a multiple of the initial gather radius, in (0, 64] [default: scene, else 1]",
        kind: ParamKind::Value {
            value_name: "SCALE",
            choices: &[],
        },
        get: |p| p.kernel.volume_radius.to_string(),
        set: |p, v| {
            p.kernel.volume_radius = parse_number(v)?;
            Ok(())
        },
    },
    Param {
        name: "vcm_freq_radius",
        flag: "vcm-freq-radius",
        help: "vcm: merge with the frequency prediction's radius where it is below the pass's radius (a freq-sppm pilot of --freq-pilot passes, at least one, predicts it; MIS weights use the radius used)",
        kind: ParamKind::Switch { sets: true },
        get: |p| on_off(p.kernel.freq_radius),
        set: |p, v| {
            p.kernel.freq_radius = parse_switch(v)?;
            Ok(())
        },
    },
    Param {
        name: "freq_fraction",
        flag: "freq-fraction",
        help: "Share of photons that carry a light-field spectrum, in [0, 1] (frequency methods) [default: 0.1]",
        kind: ParamKind::Value {
            value_name: "SHARE",
            choices: &[],
        },
        get: |p| p.frequency.fraction.to_string(),
        set: |p, v| {
            p.frequency.fraction = parse_number(v)?;
            Ok(())
        },
    },
    Param {
        name: "freq_merge",
        flag: "freq-merge",
        help: "How a hitpoint merges frequency estimates [default: min]",
        kind: ParamKind::Value {
            value_name: "POLICY",
            choices: &[
                (
                    "min",
                    "Keep the smallest radius (the most conservative estimate)",
                ),
                (
                    "poster-max",
                    "Merge as on the poster (the largest frequency content)",
                ),
            ],
        },
        get: |p| {
            match p.frequency.merge {
                MergePolicy::MinRadius => "min",
                MergePolicy::PosterMax => "poster-max",
            }
            .to_owned()
        },
        set: |p, v| {
            p.frequency.merge = match v {
                "min" => MergePolicy::MinRadius,
                "poster-max" => MergePolicy::PosterMax,
                _ => return Err("is not one of min, poster-max".to_owned()),
            };
            Ok(())
        },
    },
    Param {
        name: "freq_floor",
        flag: "freq-floor",
        help: "What happens once the PPM radius reaches the frequency radius [default: keep]",
        kind: ParamKind::Value {
            value_name: "RULE",
            choices: &[
                (
                    "keep",
                    "Keep the radius once it reaches the frequency radius",
                ),
                (
                    "clamp",
                    "Clamp the shrinking radius at the frequency radius",
                ),
            ],
        },
        get: |p| {
            match p.frequency.floor {
                FrequencyFloor::Keep => "keep",
                FrequencyFloor::Clamp => "clamp",
            }
            .to_owned()
        },
        set: |p, v| {
            p.frequency.floor = match v {
                "keep" => FrequencyFloor::Keep,
                "clamp" => FrequencyFloor::Clamp,
                _ => return Err("is not one of keep, clamp".to_owned()),
            };
            Ok(())
        },
    },
    Param {
        name: "kernel_k",
        flag: "kernel-k",
        help: "Kernel radius constant K of the frequency estimate, a number, strict or poster [default: strict = 0.0720909, the 95 %-of-peak radius; the poster's is 0.7115]",
        kind: ParamKind::Value {
            value_name: "K",
            choices: &[],
        },
        get: |p| p.frequency.kernel_k.to_string(),
        set: |p, v| {
            p.frequency.kernel_k = match v {
                "strict" => K_STRICT,
                "poster" => K_POSTER,
                _ => parse_number(v)?,
            };
            Ok(())
        },
    },
    Param {
        name: "freq_grow",
        flag: "freq-grow",
        help: "Largest kernel of a frequency method, as a multiple of the initial radius, in [1, 64] [default: 1, measured in docs/integrators.md; 1 never grows a kernel beyond R₀]",
        kind: ParamKind::Value {
            value_name: "G",
            choices: &[],
        },
        get: |p| p.frequency.grow.to_string(),
        set: |p, v| {
            p.frequency.grow = parse_number(v)?;
            Ok(())
        },
    },
    Param {
        name: "freq_hold_alpha",
        flag: "freq-hold-alpha",
        help: "α of a hitpoint held by its frequency radius, in (0, 1] [default: 0.9; 1 keeps the radius for ever, the poster's rule, which does not converge]",
        kind: ParamKind::Value {
            value_name: "A",
            choices: &[],
        },
        get: |p| p.frequency.hold_alpha.to_string(),
        set: |p, v| {
            p.frequency.hold_alpha = parse_number(v)?;
            Ok(())
        },
    },
    Param {
        name: "freq_pilot",
        flag: "freq-pilot",
        help: "Passes of the frequency pilot before the kernels are sized and the statistics restart [default: 4; 0 never grows kernels; only with --freq-grow above 1]",
        kind: ParamKind::Value {
            value_name: "N",
            choices: &[],
        },
        get: |p| p.frequency.pilot.to_string(),
        set: |p, v| {
            let n: i64 = v.parse().map_err(|_| "is not a whole number".to_owned())?;
            p.frequency.pilot =
                u32::try_from(n).map_err(|_| "is outside [0, 1000000]".to_owned())?;
            Ok(())
        },
    },
    Param {
        name: "freq_clear_cap",
        flag: "no-freq-clear-cap",
        help: "Cap only the held slots of a frequency method at the clear radius of their gather disc (by default every slot's radius is capped there, which removes most of the bias at corners and edges)",
        kind: ParamKind::Switch { sets: false },
        get: |p| on_off(p.frequency.clear_cap),
        set: |p, v| {
            p.frequency.clear_cap = parse_switch(v)?;
            Ok(())
        },
    },
    Param {
        name: "freq_cap",
        flag: "freq-cap",
        help: "Cap every slot of a frequency method at its frequency radius where that is smaller, at a diffuse point seen directly (where connections to the camera take over), never below FLOOR times the initial radius, FLOOR in (0, 1]; off leaves such slots to the SPPM schedule [default: 0.0625, measured in docs/integrators.md]",
        kind: ParamKind::Value {
            value_name: "FLOOR",
            choices: &[],
        },
        get: |p| {
            p.frequency
                .cap_floor
                .map_or_else(|| "off".to_owned(), |f| f.to_string())
        },
        set: |p, v| {
            p.frequency.cap_floor = if v == "off" {
                None
            } else {
                Some(parse_number(v)?)
            };
            Ok(())
        },
    },
    Param {
        name: "freq_cap_scale",
        flag: "freq-cap-scale",
        help: "With --freq-cap: cap at this multiple of the frequency radius, in [1, 64] [default: 4]",
        kind: ParamKind::Value {
            value_name: "C",
            choices: &[],
        },
        get: |p| p.frequency.cap_scale.to_string(),
        set: |p, v| {
            p.frequency.cap_scale = parse_number(v)?;
            Ok(())
        },
    },
    Param {
        name: "freq_probe_share",
        flag: "no-freq-probe-share",
        help: "Let every candidate of a frequency method probe its own clear disc (by default the candidates of a 2x2 block of pixels share one probe for 16 passes where their points lie in one plane inside it)",
        kind: ParamKind::Switch { sets: false },
        get: |p| on_off(p.frequency.probe_share),
        set: |p, v| {
            p.frequency.probe_share = parse_switch(v)?;
            Ok(())
        },
    },
    Param {
        name: "light_tracing",
        flag: "no-light-tracing",
        help: "Photon mappers: do not connect stored photons to the camera (by default they are, where kernels cover at most two camera samples, and weighted against merging by multiple importance sampling)",
        kind: ParamKind::Switch { sets: false },
        get: |p| on_off(p.connections.light_tracing),
        set: |p, v| {
            p.connections.light_tracing = parse_switch(v)?;
            Ok(())
        },
    },
    Param {
        name: "connect_below",
        flag: "connect-below",
        help: "Photon mappers with light tracing: connect a photon to the camera where the kernels of its pixel cover at most this many camera samples (pi R^2 times the samples per unit area), in [0, inf] [default: 2]",
        kind: ParamKind::Value {
            value_name: "N",
            choices: &[],
        },
        get: |p| p.connections.connect_below.to_string(),
        set: |p, v| {
            p.connections.connect_below = parse_number(v)?;
            Ok(())
        },
    },
    Param {
        name: "extra_light_paths",
        flag: "extra-light-paths",
        help: "Photon mappers with light tracing: light paths traced per pass only for their connections to the camera, as a multiple of photons_per_pass, in [0, 64] [default: 0]",
        kind: ParamKind::Value {
            value_name: "R",
            choices: &[],
        },
        get: |p| p.connections.extra_light_paths.to_string(),
        set: |p, v| {
            p.connections.extra_light_paths = parse_number(v)?;
            Ok(())
        },
    },
    Param {
        name: "max_depth",
        flag: "max-depth",
        help: "Maximum number of scattering events on a light path, in [1, 1024] [default: scene, else 1024: in effect unlimited, paths end by Russian roulette]",
        kind: ParamKind::Value {
            value_name: "N",
            choices: &[],
        },
        get: |p| p.budget.max_depth.to_string(),
        set: |p, v| {
            p.budget.max_depth = parse_small(v)?;
            Ok(())
        },
    },
    Param {
        name: "rr_depth",
        flag: "rr-depth",
        help: "The bounce from which Russian roulette may end a path, in [1, 1024] [default: scene, else 3]; unbiased whatever the value",
        kind: ParamKind::Value {
            value_name: "N",
            choices: &[],
        },
        get: |p| p.budget.rr_depth.to_string(),
        set: |p, v| {
            p.budget.rr_depth = parse_small(v)?;
            Ok(())
        },
    },
    Param {
        name: "spp",
        flag: "spp",
        help: "Hitpoints per pixel (paths per pixel per pass for --method path), in [1, 1024] [default: 1]",
        kind: ParamKind::Value {
            value_name: "N",
            choices: &[],
        },
        get: |p| p.film.samples_per_pixel.to_string(),
        set: |p, v| {
            p.film.samples_per_pixel = parse_small(v)?;
            Ok(())
        },
    },
    Param {
        name: "camera_samples",
        flag: "camera-samples",
        help: "Photon mappers: how a pixel's camera samples (sub-pixel and lens position, first glass or mirror choice) follow one another over the passes [default: sobol]",
        kind: ParamKind::Value {
            value_name: "SEQUENCE",
            choices: &[
                (
                    "sobol",
                    "An Owen-scrambled Sobol sequence per pixel: the passes stratify the pixel, the lens and the first specular choice",
                ),
                ("independent", "Independent random numbers every pass"),
            ],
        },
        get: |p| p.film.sequence.name().to_owned(),
        set: |p, v| {
            p.film.sequence = match v {
                "sobol" => CameraSequence::Sobol,
                "independent" => CameraSequence::Independent,
                _ => return Err("is not one of sobol, independent".to_owned()),
            };
            Ok(())
        },
    },
    Param {
        name: "glass_split",
        flag: "no-glass-split",
        help: "Photon mappers: where a camera path meets glass, follow only the branch (reflection or refraction) chosen by Fresnel; by default the other branch is traced one segment for the emission it sees",
        kind: ParamKind::Switch { sets: false },
        get: |p| on_off(p.film.glass_split),
        set: |p, v| {
            p.film.glass_split = parse_switch(v)?;
            Ok(())
        },
    },
    Param {
        name: "seed",
        flag: "seed",
        help: "Seed of every random number [default: scene, else 0]",
        kind: ParamKind::Value {
            value_name: "SEED",
            choices: &[],
        },
        get: |p| p.seed.to_string(),
        set: |p, v| {
            p.seed = v
                .parse()
                .map_err(|_| "is not a whole number in [0, 2^64)".to_owned())?;
            Ok(())
        },
    },
    Param {
        name: "direct_lighting",
        flag: "direct-lighting",
        help: "Photon mappers: estimate the light arriving straight from emitters at each visible point by a light sample and a BSDF sample combined by multiple importance sampling, instead of gathering (and connecting) the photons that arrive straight from an emitter",
        kind: ParamKind::Switch { sets: true },
        get: |p| on_off(p.connections.direct_lighting),
        set: |p, v| {
            p.connections.direct_lighting = parse_switch(v)?;
            Ok(())
        },
    },
    Param {
        name: "direct_samples",
        flag: "direct-samples",
        help: "Photon mappers with direct lighting: light and BSDF sample pairs per visible point and pass, in [1, 64] [default: 4]",
        kind: ParamKind::Value {
            value_name: "N",
            choices: &[],
        },
        get: |p| p.connections.direct_samples.to_string(),
        set: |p, v| {
            p.connections.direct_samples = parse_small(v)?;
            Ok(())
        },
    },
    Param {
        name: "glossy_continue",
        flag: "glossy-continue",
        help: "sppm and freq-sppm: camera paths go on through glossy surfaces of GGX alpha up to ALPHA, in [0, 1], with light and BSDF sampling there, instead of merging photons on them; off (or 0) merges on every non-specular surface [default: 0.3, measured in docs/integrators.md]",
        kind: ParamKind::Value {
            value_name: "ALPHA",
            choices: &[],
        },
        get: |p| {
            if p.connections.glossy_continue == 0.0 {
                "off".to_owned()
            } else {
                p.connections.glossy_continue.to_string()
            }
        },
        set: |p, v| {
            p.connections.glossy_continue = if v == "off" { 0.0 } else { parse_number(v)? };
            Ok(())
        },
    },
    Param {
        name: "pool",
        flag: "pool",
        help: "Photon mappers: pool the estimates of neighbouring pixels on the same surface when the image is read [default: freq]",
        kind: ParamKind::Value {
            value_name: "MODE",
            choices: &[
                ("off", "Every pixel reads its own estimate"),
                (
                    "freq",
                    "Pool as far as the frequency prediction of the light allows (frequency methods; others do not pool)",
                ),
                (
                    "geometry",
                    "Pool over the whole window on the same surface, whatever the light (the control for freq)",
                ),
            ],
        },
        get: |p| p.pool.mode.name().to_owned(),
        set: |p, v| {
            p.pool.mode = match v {
                "off" => PoolMode::Off,
                "freq" => PoolMode::Frequency,
                "geometry" => PoolMode::Geometry,
                _ => return Err("is not one of off, freq, geometry".to_owned()),
            };
            Ok(())
        },
    },
    Param {
        name: "pool_scale",
        flag: "pool-scale",
        help: "Pooling: the blur budget of pixel and pooling together, as a multiple of the frequency radius, in (0, 64] [default: 0.5]",
        kind: ParamKind::Value {
            value_name: "S",
            choices: &[],
        },
        get: |p| p.pool.scale.to_string(),
        set: |p, v| {
            p.pool.scale = parse_number(v)?;
            Ok(())
        },
    },
    Param {
        name: "pool_max",
        flag: "pool-max",
        help: "Pooling: the window's radius in pixels, in [0, 32] [default: 4]",
        kind: ParamKind::Value {
            value_name: "PIXELS",
            choices: &[],
        },
        get: |p| p.pool.max_pixels.to_string(),
        set: |p, v| {
            p.pool.max_pixels = parse_small(v)?;
            Ok(())
        },
    },
    Param {
        name: "pool_decay",
        flag: "pool-decay",
        help: "Pooling: the width shrinks as (n0/n)^decay beyond n0 = 1e7 photons, so that the image converges, in [0, 1] [default: 1/6]",
        kind: ParamKind::Value {
            value_name: "D",
            choices: &[],
        },
        get: |p| p.pool.decay.to_string(),
        set: |p, v| {
            p.pool.decay = parse_number(v)?;
            Ok(())
        },
    },
    Param {
        name: "freq_geometry",
        flag: "no-freq-geometry",
        help: "Let frequency methods hold a radius even where the gather disc hangs over an edge or a corner of the surface (no geometric bound on held kernels)",
        kind: ParamKind::Switch { sets: false },
        get: |p| on_off(p.frequency.geometry),
        set: |p, v| {
            p.frequency.geometry = parse_switch(v)?;
            Ok(())
        },
    },
    Param {
        name: "freq_occlusion",
        flag: "no-freq-occlusion",
        help: "Let frequency photons travel without probing for partial occlusion near their hits (no shadow edges in their spectra)",
        kind: ParamKind::Switch { sets: false },
        get: |p| on_off(p.frequency.occlusion),
        set: |p, v| {
            p.frequency.occlusion = parse_switch(v)?;
            Ok(())
        },
    },
];

/// The parameter called `name` (`snake_case`, or with `-` for `_`).
#[must_use]
pub fn param(name: &str) -> Option<&'static Param> {
    let name = name.replace('-', "_");
    PARAMS.iter().find(|p| p.name == name)
}

impl RenderParams {
    /// Sets the parameter called `name` (see [`PARAMS`]) from its text, as a flag or a scene
    /// table gives it. Only the conversion is checked; ranges are checked by
    /// [`Self::validate`].
    ///
    /// # Errors
    ///
    /// [`ParamError::Unknown`] if no parameter has that name, [`ParamError::Unreadable`] if
    /// the text is not a value of the parameter.
    pub fn set(&mut self, name: &str, value: &str) -> Result<(), ParamError> {
        let param = param(name).ok_or_else(|| ParamError::Unknown {
            name: name.to_owned(),
        })?;
        (param.set)(self, value.trim()).map_err(|problem| ParamError::Unreadable {
            name: param.name,
            value: value.to_owned(),
            problem,
        })
    }

    /// These parameters with a scene's `[render]` table over them.
    ///
    /// # Errors
    ///
    /// As [`Self::set`], for the first key of the table that is not a render parameter or
    /// whose value does not read.
    pub fn with_scene_defaults(
        mut self,
        defaults: &scene::RenderDefaults,
    ) -> Result<Self, ParamError> {
        for (name, value) in &defaults.params {
            self.set(name, value)?;
        }
        Ok(self)
    }

    /// Every parameter with its value, as `(name, text)` in the order of [`PARAMS`]: what an
    /// image's metadata records.
    #[must_use]
    pub fn entries(&self) -> Vec<(&'static str, String)> {
        PARAMS.iter().map(|p| (p.name, p.get(self))).collect()
    }
}

/// `on` or `off`.
fn on_off(value: bool) -> String {
    if value { "on" } else { "off" }.to_owned()
}

fn parse_switch(text: &str) -> Result<bool, String> {
    match text {
        "on" | "true" => Ok(true),
        "off" | "false" => Ok(false),
        _ => Err("is not one of on, off, true, false".to_owned()),
    }
}

fn parse_number(text: &str) -> Result<f64, String> {
    text.parse().map_err(|_| "is not a number".to_owned())
}

/// A count whose range `validate` knows; values that do not fit a `u32` are refused here.
fn parse_small(text: &str) -> Result<u32, String> {
    let n: i64 = text
        .parse()
        .map_err(|_| "is not a whole number".to_owned())?;
    u32::try_from(n).map_err(|_| "is outside [1, 1024]".to_owned())
}

/// A whole number written as 200000, 200_000, 200k, 2M or 1G.
fn parse_count(text: &str) -> Result<i64, String> {
    let cleaned: String = text.chars().filter(|&c| c != '_').collect();
    let (digits, factor) = if let Some(d) = cleaned.strip_suffix(['k', 'K']) {
        (d, 1_000)
    } else if let Some(d) = cleaned.strip_suffix('M') {
        (d, 1_000_000)
    } else if let Some(d) = cleaned.strip_suffix('G') {
        (d, 1_000_000_000)
    } else {
        (cleaned.as_str(), 1)
    };
    digits
        .parse::<i64>()
        .ok()
        .and_then(|n| n.checked_mul(factor))
        .ok_or_else(|| "is not a whole number such as 200000, 200_000, 200k, 2M or 1G".to_owned())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_value_reads_back_as_itself() {
        let mut params = RenderParams::preview();
        params.method = Method::FreqSppm;
        params.kernel.initial_radius = Some(0.125);
        params.kernel.volume_radius = 2.5;
        params.frequency.merge = MergePolicy::PosterMax;
        params.frequency.floor = FrequencyFloor::Clamp;
        params.frequency.geometry = false;
        params.connections.direct_lighting = true;
        params.connections.direct_samples = 6;
        params.kernel.alpha = 2.0 / 3.0;
        params.frequency.grow = 2.5;
        params.frequency.hold_alpha = 1.0;
        params.frequency.pilot = 0;
        params.frequency.clear_cap = false;
        params.frequency.cap_floor = None;
        params.frequency.cap_scale = 2.0;
        params.connections.light_tracing = false;
        params.frequency.probe_share = false;
        for base in [RenderParams::preview(), params] {
            let mut copy = RenderParams::preview();
            copy.method = Method::Path;
            copy.seed = 99;
            for (name, value) in base.entries() {
                copy.set(name, &value).unwrap();
            }
            assert_eq!(copy, base);
        }
    }

    #[test]
    fn names_are_unique_and_flags_follow_them() {
        for (i, p) in PARAMS.iter().enumerate() {
            assert!(PARAMS[..i].iter().all(|q| q.name != p.name), "{}", p.name);
            assert!(!p.name.contains('-'), "{}", p.name);
            if let ParamKind::Value { .. } = p.kind {
                assert_eq!(p.flag, p.name.replace('_', "-"));
            }
        }
        assert_eq!(
            param("photons-per-pass").map(|p| p.name),
            Some("photons_per_pass")
        );
    }

    /// `auto` photons per pass: the larger of 100 000 and one per slot for the photon mappers,
    /// 100 000 for the other methods; a number given is kept; the resolved number is what the
    /// parameters then show.
    #[test]
    fn automatic_photons_per_pass() {
        let shown = |p: &RenderParams| param("photons_per_pass").unwrap().get(p);
        assert_eq!(shown(&RenderParams::preview()), "auto");
        let resolved = |method: Method, text: &str, slots: u64| {
            let mut p = RenderParams::preview();
            p.method = method;
            p.set("photons_per_pass", text).unwrap();
            p.resolve_photons_per_pass(slots);
            (p.budget.photons_per_pass, shown(&p))
        };
        assert_eq!(
            resolved(Method::FreqSppm, "auto", 256 * 256),
            (100_000, "100000".to_owned())
        );
        assert_eq!(
            resolved(Method::Sppm, "auto", 1152 * 864),
            (995_328, "995328".to_owned())
        );
        assert_eq!(resolved(Method::Ppm, "auto", 1 << 40).0, u32::MAX);
        assert_eq!(resolved(Method::Vcm, "auto", 1152 * 864).0, 100_000);
        assert_eq!(resolved(Method::FreqSppm, "50k", 1152 * 864).0, 50_000);
    }

    #[test]
    fn counts() {
        for (text, n) in [
            ("200000", 200_000),
            ("200_000", 200_000),
            ("200k", 200_000),
            ("2M", 2_000_000),
            ("2G", 2_000_000_000),
        ] {
            assert_eq!(parse_count(text), Ok(n));
        }
        assert!(parse_count("2T").is_err());
        let mut p = RenderParams::preview();
        let Err(ParamError::Unreadable { problem, .. }) = p.set("photons_per_pass", "10G") else {
            panic!("10G photons per pass accepted");
        };
        assert!(problem.contains("TiB of photon buffers"), "{problem}");
        let mut p = RenderParams::preview();
        assert!(matches!(
            p.set("photons_per_pass", "0"),
            Err(ParamError::Unreadable { .. })
        ));
        assert!(matches!(
            p.set("colour", "red"),
            Err(ParamError::Unknown { .. })
        ));
        p.set("kernel-k", "poster").unwrap();
        assert_eq!(p.frequency.kernel_k, K_POSTER);
    }
}
