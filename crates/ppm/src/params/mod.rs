//! Render parameters: plain typed values, validated once; `names.rs` says how each is named,
//! read and shown.

mod names;

use std::fmt;

use spectrum::{K_STRICT, MergePolicy};

use crate::update::FrequencyFloor;

pub use self::names::{PARAMS, Param, ParamKind, param};

/// The integrators.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Method {
    /// Progressive photon mapping (Hachisuka, Ogaki & Jensen 2008): hitpoints traced once.
    Ppm,
    /// Stochastic progressive photon mapping (Hachisuka & Jensen 2009): hitpoints re-traced
    /// every pass, statistics kept per hitpoint slot.
    Sppm,
    /// PPM with frequency-guided kernels (Belcour & Soler 2011).
    FreqPpm,
    /// SPPM with frequency-guided kernels.
    FreqSppm,
    /// Pass-independent PPM (Knaus & Zwicker 2011) with per-slot kernels from a frequency
    /// pilot: every pass is an image of its own, so passes can be split into work units and
    /// merged exactly.
    Appm,
    /// Unidirectional path tracing with next-event estimation and MIS: the reference.
    Path,
}

impl Method {
    /// Every method, in the order reports list them.
    pub const ALL: [Method; 6] = [
        Method::Ppm,
        Method::Sppm,
        Method::FreqPpm,
        Method::FreqSppm,
        Method::Appm,
        Method::Path,
    ];

    /// The name used on the command line and in scene files.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Method::Ppm => "ppm",
            Method::Sppm => "sppm",
            Method::FreqPpm => "freq",
            Method::FreqSppm => "freq-sppm",
            Method::Appm => "appm",
            Method::Path => "path",
        }
    }

    /// The method called `name` (see [`Method::name`]).
    #[must_use]
    pub fn from_name(name: &str) -> Option<Method> {
        Method::ALL.into_iter().find(|m| m.name() == name)
    }

    /// Whether frequency photons guide the kernel radius.
    #[must_use]
    pub fn uses_frequency(self) -> bool {
        matches!(self, Method::FreqPpm | Method::FreqSppm)
    }

    /// Whether this is a photon mapper (everything but the path tracer).
    #[must_use]
    pub fn is_photon_mapper(self) -> bool {
        !matches!(self, Method::Path)
    }

    /// Whether hitpoints are re-traced every pass (SPPM).
    #[must_use]
    pub fn is_stochastic(self) -> bool {
        matches!(self, Method::Sppm | Method::FreqSppm | Method::Appm)
    }

    /// Whether passes are independent images, summed exactly (`appm`).
    #[must_use]
    pub fn is_pass_independent(self) -> bool {
        matches!(self, Method::Appm)
    }
}

impl fmt::Display for Method {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Everything an integrator needs besides the scene. Plain data, no `Default`: start from a
/// preset ([`RenderParams::preview`]) and change fields.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderParams {
    /// Which integrator.
    pub method: Method,
    /// Photons traced per pass (> 0).
    pub photons_per_pass: u32,
    /// Radius reduction α ∈ (0, 1]: the fraction of new photons kept (0.7 in smallppm,
    /// 2/3 in pbrt-v4).
    pub alpha: f64,
    /// Initial gather radius in scene units; `None` picks it from the scene (see
    /// [`crate::auto_initial_radius`]).
    pub initial_radius: Option<f64>,
    /// Maximum number of scattering events on a light path from the emitter to the camera
    /// (≥ 1), as pbrt's `maxdepth`: paths have at most `max_depth + 1` segments. Every method
    /// bounds the same paths: a photon mapper counts the photon's bounces, the hitpoint's
    /// scattering and the camera path's specular bounces; the path tracer the bounces before
    /// an emitter is hit or sampled.
    pub max_depth: u32,
    /// The bounce from which Russian roulette may end a path (a photon's, or the path
    /// tracer's), ≥ 1: the first `rr_depth − 1` bounces always continue. Unbiased whatever the
    /// value; smaller values end dim paths sooner (faster passes, more noise per path). The
    /// Mitsuba importer carries the integrator's `rr_depth` here.
    pub rr_depth: u32,
    /// Hitpoint slots per pixel (jittered; ≥ 1); for the path tracer, paths per pixel per pass.
    pub samples_per_pixel: u32,
    /// Seed of every random number.
    pub seed: u64,
    /// Share of photons that are frequency photons, in [0, 1] (frequency methods only).
    pub freq_fraction: f64,
    /// How a hitpoint merges frequency deposits.
    pub freq_merge: MergePolicy,
    /// The kernel radius constant K: [`spectrum::K_STRICT`] (the 95 %-of-peak radius, the
    /// default chosen by the convergence study) or the poster's [`spectrum::K_POSTER`].
    pub kernel_k: f64,
    /// What happens once the PPM radius reaches the frequency radius.
    pub freq_floor: FrequencyFloor,
    /// Whether frequency photons probe for partial occlusion near their hits (one extra
    /// shadow ray per segment of a frequency photon), so that shadow edges raise the spatial
    /// frequency and keep hitpoints there shrinking.
    pub freq_occlusion: bool,
    /// Whether a hitpoint may hold its radius only where its gather disc lies on its own
    /// surface (probe rays when it first becomes a candidate, `crate::disc`), so that held
    /// kernels do not hang over edges and corners where no photon is accepted.
    pub freq_geometry: bool,
    /// Add direct lighting by light sampling at hitpoints instead of gathering photons that
    /// arrive straight from an emitter.
    pub direct_lighting: bool,
    /// The largest kernel a frequency method may give a hitpoint, as a multiple of the
    /// initial radius R₀, in [1, 64]. After the pilot (`freq_pilot`) every hitpoint whose
    /// frequency prediction and clear disc allow it starts over at min(r_freq, clear radius,
    /// `freq_grow`·R₀); 1 never grows a kernel beyond R₀ (the poster's rule).
    pub freq_grow: f64,
    /// α while a frequency method holds a hitpoint (R ≤ its frequency radius), in (0, 1]:
    /// 1 keeps the radius for ever (the poster's rule, biased in the limit); below 1 the held
    /// radius keeps shrinking slowly, R² ∝ N^−(1−α_hold)/α_hold, so that the estimate converges
    /// (for α_hold > 1/2, N·R² still grows).
    pub freq_hold_alpha: f64,
    /// Passes of a frequency method's pilot, in [0, 10⁶]: after them (and only if
    /// `freq_grow` > 1) the kernels are sized from the frequency prediction and every
    /// hitpoint's statistics restart; 0 skips the growth.
    pub freq_pilot: u32,
    /// Whether a frequency method caps *every* slot's radius at the clear radius of its
    /// gather disc (probed at every visible point), not only the held ones: near corners and
    /// edges the kernel then shrinks at once to the distance where the disc leaves the
    /// surface, which removes most of photon mapping's corner bias.
    pub freq_clear_cap: bool,
    /// Whether the candidates of a 2 × 2 block of pixels (every slot of it under
    /// `freq_clear_cap`) share one clear-disc probe for 16 passes where their visible points
    /// lie in one plane well inside the probed disc (`PhotonMapper::probe_clear_radii`);
    /// otherwise every candidate probes its own.
    pub freq_probe_share: bool,
    /// Whether the photon mappers also connect every stored photon to the camera (light
    /// tracing) and combine the two estimates of what the camera sees directly on a
    /// non-specular surface by multiple importance sampling, as vertex connection and merging
    /// does: a photon merged at a directly seen hitpoint of radius R counts with weight
    /// N/(1 + N) and its connection with 1/(1 + N), N = πR²·(camera samples per unit area).
    pub light_tracing: bool,
}

/// A parameter outside its domain.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ParamError {
    /// A parameter is outside its allowed range.
    #[error("{name} = {value} is outside {range}")]
    OutOfRange {
        /// Parameter name (see [`PARAMS`]).
        name: &'static str,
        /// The value given.
        value: String,
        /// The allowed range, as text.
        range: &'static str,
    },
    /// No render parameter has this name.
    #[error("{name} is not a render parameter")]
    Unknown {
        /// The name given.
        name: String,
    },
    /// The text is not a value of the parameter.
    #[error("{name} {value} {problem}")]
    Unreadable {
        /// Parameter name (see [`PARAMS`]).
        name: &'static str,
        /// The text given.
        value: String,
        /// What is wrong with it, e.g. `is not a number`.
        problem: String,
    },
    /// Kernels were given to a method whose passes are not independent.
    #[error("{method} does not render independent passes (only appm does)")]
    NotPassIndependent {
        /// The method asked for.
        method: Method,
    },
    /// The kernels of a pass-independent render are not one positive radius per slot.
    #[error("the kernels hold {found} radii for {expected} hitpoint slots, or one is not positive")]
    BadKernels {
        /// Hitpoint slots of the film.
        expected: usize,
        /// Radii given.
        found: usize,
    },
    /// The film has no pixels or more than the renderer can index.
    #[error(
        "film of {width}x{height} pixels with {samples_per_pixel} samples per pixel is too large"
    )]
    TooManyHitpoints {
        /// Film width.
        width: u32,
        /// Film height.
        height: u32,
        /// Samples per pixel.
        samples_per_pixel: u32,
    },
    /// A pointwise reference was asked for a method without fixed hitpoints, or with direct
    /// lighting at the hitpoints (whose estimate re-jitters every pass).
    #[error("a pointwise reference needs ppm or freq without direct lighting, not {method}")]
    NoFixedHitpoints {
        /// The method's name.
        method: &'static str,
    },
}

impl RenderParams {
    /// The pass (0-based) at whose start a frequency method sizes its kernels from the
    /// frequency prediction and restarts the statistics, if it grows kernels at all.
    #[must_use]
    pub fn growth_pass(&self) -> Option<u32> {
        (self.method.uses_frequency() && self.freq_grow > 1.0 && self.freq_pilot > 0)
            .then_some(self.freq_pilot)
    }

    /// The defaults: freq-sppm, 100 000 photons per pass, α = 0.7, one hitpoint per
    /// pixel; for the frequency methods 10 % frequency photons, K = K_STRICT, min-radius merge
    /// and occlusion probes (the defaults of `docs/convergence.md` and `docs/integrators.md`).
    #[must_use]
    pub fn preview() -> Self {
        Self {
            method: Method::FreqSppm,
            photons_per_pass: 100_000,
            alpha: 0.7,
            initial_radius: None,
            max_depth: 1024,
            rr_depth: 3,
            samples_per_pixel: 1,
            seed: 0,
            freq_fraction: 0.1,
            freq_merge: MergePolicy::MinRadius,
            kernel_k: K_STRICT,
            freq_floor: FrequencyFloor::Keep,
            freq_occlusion: true,
            freq_geometry: true,
            direct_lighting: false,
            freq_grow: 1.0,
            freq_hold_alpha: 0.9,
            freq_pilot: 4,
            freq_clear_cap: true,
            freq_probe_share: true,
            light_tracing: true,
        }
    }

    /// Checks every field's domain.
    ///
    /// # Errors
    ///
    /// [`ParamError::OutOfRange`] naming the first parameter outside its domain.
    pub fn validate(&self) -> Result<(), ParamError> {
        fn out(name: &'static str, value: impl fmt::Display, range: &'static str) -> ParamError {
            ParamError::OutOfRange {
                name,
                value: value.to_string(),
                range,
            }
        }
        if self.photons_per_pass == 0 {
            return Err(out("photons_per_pass", self.photons_per_pass, "[1, 2^32)"));
        }
        if !(self.alpha > 0.0 && self.alpha <= 1.0) {
            return Err(out("alpha", self.alpha, "(0, 1]"));
        }
        if let Some(r) = self.initial_radius
            && !(r > 0.0 && r.is_finite())
        {
            return Err(out("initial_radius", r, "(0, inf)"));
        }
        if self.max_depth == 0 || self.max_depth > 1024 {
            return Err(out("max_depth", self.max_depth, "[1, 1024]"));
        }
        if self.rr_depth == 0 || self.rr_depth > 1024 {
            return Err(out("rr_depth", self.rr_depth, "[1, 1024]"));
        }
        if self.samples_per_pixel == 0 || self.samples_per_pixel > 1024 {
            return Err(out("spp", self.samples_per_pixel, "[1, 1024]"));
        }
        if !(0.0..=1.0).contains(&self.freq_fraction) {
            return Err(out("freq_fraction", self.freq_fraction, "[0, 1]"));
        }
        if !(self.kernel_k > 0.0 && self.kernel_k.is_finite()) {
            return Err(out("kernel_k", self.kernel_k, "(0, inf)"));
        }
        if !(1.0..=64.0).contains(&self.freq_grow) {
            return Err(out("freq_grow", self.freq_grow, "[1, 64]"));
        }
        if !(self.freq_hold_alpha > 0.0 && self.freq_hold_alpha <= 1.0) {
            return Err(out("freq_hold_alpha", self.freq_hold_alpha, "(0, 1]"));
        }
        if self.freq_pilot > 1_000_000 {
            return Err(out("freq_pilot", self.freq_pilot, "[0, 1000000]"));
        }
        Ok(())
    }
}
