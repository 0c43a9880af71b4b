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
    /// Light tracing (Mitsuba's `ptracer`): light paths connected to the lens at every
    /// non-specular vertex, no merging; blind to what is seen only through specular surfaces.
    Light,
    /// Vertex connection and merging (Georgiev, Křivánek, Davidovič & Slusallek 2012): light
    /// and camera subpaths, connected and merged at every camera vertex, weighted by MIS.
    Vcm,
    /// Bidirectional path tracing: `Vcm`'s connections without merging.
    Bdpt,
}

impl Method {
    /// Every method, in the order reports list them.
    pub const ALL: [Method; 9] = [
        Method::Ppm,
        Method::Sppm,
        Method::FreqPpm,
        Method::FreqSppm,
        Method::Appm,
        Method::Path,
        Method::Light,
        Method::Vcm,
        Method::Bdpt,
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
            Method::Light => "light",
            Method::Vcm => "vcm",
            Method::Bdpt => "bdpt",
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

    /// Whether this is a photon mapper (everything but the path tracer, the light tracer and
    /// the bidirectional methods): it has hitpoints with gather radii.
    #[must_use]
    pub fn is_photon_mapper(self) -> bool {
        !matches!(
            self,
            Method::Path | Method::Light | Method::Vcm | Method::Bdpt
        )
    }

    /// Whether it traces paths from the emitters (the photon mappers, the light tracer and the
    /// bidirectional methods).
    #[must_use]
    pub fn traces_light_paths(self) -> bool {
        !matches!(self, Method::Path)
    }

    /// Whether hitpoints are re-traced every pass (SPPM).
    #[must_use]
    pub fn is_stochastic(self) -> bool {
        matches!(self, Method::Sppm | Method::FreqSppm | Method::Appm)
    }

    /// Whether passes are independent images, summed exactly (`appm`, `vcm`, `bdpt`), so
    /// that a render can be cut into work units.
    #[must_use]
    pub fn is_pass_independent(self) -> bool {
        matches!(self, Method::Appm | Method::Vcm | Method::Bdpt)
    }
}

impl fmt::Display for Method {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Everything an integrator needs besides the scene, grouped by what it controls. Plain data,
/// no `Default`: start from a preset ([`RenderParams::preview`]) and change fields. Each field
/// is named once, in [`PARAMS`], as flags, `[render]` tables and image metadata spell it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderParams {
    /// Which integrator.
    pub method: Method,
    /// Seed of every random number.
    pub seed: u64,
    /// What a pass spends: photons and path length.
    pub budget: Budget,
    /// How the film is sampled.
    pub film: FilmSampling,
    /// The progressive gather radius of the photon mappers.
    pub kernel: Kernel,
    /// The estimators combined with merging: connections to the camera and to the lights.
    pub connections: Connections,
    /// The frequency analysis of the frequency-guided methods.
    pub frequency: FrequencyParams,
    /// The image-space reconstruction of the photon mappers' estimate.
    pub pool: Pooling,
}

/// What a pass spends.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Budget {
    /// Photons traced per pass (> 0); the light subpaths of a pass for the bidirectional
    /// methods.
    pub photons_per_pass: u32,
    /// Whether `photons_per_pass` is still the automatic choice (`photons_per_pass = auto`, the
    /// default): [`RenderParams::resolve_photons_per_pass`] then raises it for the photon
    /// mappers to one photon per hitpoint slot where a film has more slots, so that the passes'
    /// per-slot work (camera paths, grid, update) stays a minor part of a pass on large films.
    /// The resolved value is written back and this turns false, so that images, checkpoints and
    /// work units record the number used.
    pub photons_auto: bool,
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
}

/// How the film is sampled.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FilmSampling {
    /// Hitpoint slots per pixel (jittered; ≥ 1); for the path tracer and the bidirectional
    /// methods, camera paths per pixel per pass.
    pub samples_per_pixel: u32,
    /// Where the photon mappers' camera paths sample the pixel, the lens and their first
    /// specular choice, pass after pass.
    pub sequence: CameraSequence,
    /// Whether a photon mapper's camera path, where glass makes it choose between reflection
    /// and refraction (outside media), also traces the branch it did not take one segment for
    /// the emission seen there, weighting each branch's emission by its Fresnel share.
    pub glass_split: bool,
}

/// How the photon mappers draw a slot's camera samples over the passes: the sub-pixel
/// position, the lens position and the first specular vertex's lobe (reflect or refract) and
/// direction.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CameraSequence {
    /// Independent random numbers in every pass.
    Independent,
    /// The passes of a pixel walk an Owen-scrambled Sobol sequence (Burley 2020), seeded per
    /// pixel: any 2^k successive passes stratify those dimensions, so a pixel's average over
    /// its footprint, its lens and the split of a glass surface's reflection and refraction
    /// converges faster than at random; each pass's sample is still uniform, so the estimate
    /// stays unbiased.
    Sobol,
}

impl CameraSequence {
    /// The name in parameters and metadata.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            CameraSequence::Independent => "independent",
            CameraSequence::Sobol => "sobol",
        }
    }
}

/// The progressive gather radius of the photon mappers.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Kernel {
    /// Radius reduction α ∈ (0, 1]: the fraction of new photons kept (0.7 in smallppm,
    /// 2/3 in pbrt-v4); `vcm` shrinks its merge radius by Knaus and Zwicker's schedule with
    /// the same α.
    pub alpha: f64,
    /// Initial gather radius in scene units; `None` picks it from the scene (see
    /// [`crate::auto_initial_radius`]).
    pub initial_radius: Option<f64>,
    /// `vcm`: merge with r(x) = min(the pass's radius, the frequency prediction at x), the
    /// prediction coming from a freq-sppm pilot (`vcm/radius.rs`); off, every merge of a pass
    /// has the pass's radius.
    pub freq_radius: bool,
    /// The photon mappers' volume gather in participating media (`docs/media.md`): its initial
    /// radius as a multiple of the initial gather radius.
    pub volume_radius: f64,
}

/// The estimators the photon mappers combine with merging.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Connections {
    /// Whether the photon mappers also connect every stored photon to the camera (light
    /// tracing) and combine the two estimates of what the camera sees directly on a
    /// non-specular surface by multiple importance sampling, as vertex connection and merging
    /// does: a photon merged at a directly seen hitpoint of radius R counts with weight
    /// N/(1 + N) and its connection with 1/(1 + N), N = πR²·(camera samples per unit area).
    pub light_tracing: bool,
    /// With `light_tracing`: a photon is connected to the camera where the kernels of the
    /// pixel it projects to cover at most this many camera samples (N = πR²ρ); elsewhere
    /// merging alone estimates what the camera sees. 0 connects only where N is 0, infinity
    /// everywhere.
    pub connect_below: f64,
    /// With `light_tracing`: light paths traced in each pass only for their connections to
    /// the camera (not stored, not merged), as a multiple of `photons_per_pass`. They give the
    /// connection strategy more samples than merging has photons, which pays where a light
    /// tracer is efficient (every surface diffuse and directly lit); the weights count them.
    pub extra_light_paths: f64,
    /// Estimate the light arriving straight from emitters at the photon mappers' visible points
    /// by a light sample and a BSDF sample per camera pass, combined by multiple importance
    /// sampling, instead of gathering (and connecting) the photons that arrive straight from an
    /// emitter. Off by default: with the light tree and 4 sample pairs it wins or ties at equal
    /// time on twelve scenes of docs/convergence.md but reads 1.7 times the error on one lit by
    /// emitters close to what they light.
    pub direct_lighting: bool,
    /// With `direct_lighting`: light and BSDF sample pairs per visible point and camera pass,
    /// averaged. More pays where next-event estimation is noisy (many emitters, emitters close
    /// to what they light) and the camera pass is cheap beside the photons: 4 against 1 gave
    /// 0.50–1.07× the error at equal time on thirteen scenes (docs/convergence.md).
    pub direct_samples: u32,
    /// SPPM and `freq-sppm`: camera paths pass through glossy surfaces whose GGX α is at most
    /// this (0: none), as through mirrors, instead of leaving a visible point there; at each
    /// such vertex the direct light is estimated by a light sample and a BSDF sample combined
    /// by multiple importance sampling (the path tracer's next-event estimation) and the path
    /// goes on along the BSDF sample to a rougher surface. Photons are neither stored nor
    /// connected to the camera on those surfaces: the camera path accounts for all their
    /// light. A sharp lobe seen through merging blurs and a connection to the camera rarely
    /// lands in it; see docs/integrators.md for the measurement that chose the default.
    pub glossy_continue: f64,
}

/// The frequency analysis of the frequency-guided methods (`freq`, `freq-sppm`, and `appm`'s
/// pilot).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrequencyParams {
    /// Share of photons that are frequency photons, in [0, 1].
    pub fraction: f64,
    /// How a hitpoint merges frequency deposits.
    pub merge: MergePolicy,
    /// The kernel radius constant K: [`spectrum::K_STRICT`] (the 95 %-of-peak radius, the
    /// default chosen by the convergence study) or the poster's [`spectrum::K_POSTER`].
    pub kernel_k: f64,
    /// What happens once the PPM radius reaches the frequency radius.
    pub floor: FrequencyFloor,
    /// Whether frequency photons probe for partial occlusion near their hits (one extra
    /// shadow ray per segment of a frequency photon), so that shadow edges raise the spatial
    /// frequency and keep hitpoints there shrinking.
    pub occlusion: bool,
    /// Whether a hitpoint may hold its radius only where its gather disc lies on its own
    /// surface (probe rays when it first becomes a candidate, `crate::disc`), so that held
    /// kernels do not hang over edges and corners where no photon is accepted.
    pub geometry: bool,
    /// The largest kernel a frequency method may give a hitpoint, as a multiple of the
    /// initial radius R₀, in [1, 64]. After the pilot (`pilot`) every hitpoint whose
    /// frequency prediction and clear disc allow it starts over at min(r_freq, clear radius,
    /// `grow`·R₀); 1 never grows a kernel beyond R₀ (the poster's rule).
    pub grow: f64,
    /// α while a frequency method holds a hitpoint (R ≤ its frequency radius), in (0, 1]:
    /// 1 keeps the radius for ever (the poster's rule, biased in the limit); below 1 the held
    /// radius keeps shrinking slowly, R² ∝ N^−(1−α_hold)/α_hold, so that the estimate converges
    /// (for α_hold > 1/2, N·R² still grows).
    pub hold_alpha: f64,
    /// Passes of the pilot, in [0, 10⁶]: after them (and only if `grow` > 1) the kernels are
    /// sized from the frequency prediction and every hitpoint's statistics restart; 0 skips
    /// the growth.
    pub pilot: u32,
    /// Whether *every* slot's radius is capped at the clear radius of its gather disc (probed
    /// at every visible point), not only the held ones: near corners and edges the kernel then
    /// shrinks at once to the distance where the disc leaves the surface, which removes most of
    /// photon mapping's corner bias.
    pub clear_cap: bool,
    /// Where the frequency prediction is smaller than a slot's radius, cap the radius there
    /// (rescaling N and τ as a PPM shrink), never below this fraction of R₀; `None` leaves
    /// such slots to the PPM schedule. A directly seen slot whose kernel shrinks below a camera
    /// sample or two is then estimated by its connections to the camera (light tracing), so the
    /// floor can lie far below `clear_cap`'s R₀/4. R₀/16 by default (docs/integrators.md).
    pub cap_floor: Option<f64>,
    /// The cap is this multiple of the frequency radius, in [1, 64] (4 by default): the prediction is made to
    /// stop shrinking where the light is smooth, and a cap at a multiple of it shrinks only where
    /// the light is much sharper than the kernel.
    pub cap_scale: f64,
    /// Whether the candidates of a 2 × 2 block of pixels (every slot of it under `clear_cap`)
    /// share one clear-disc probe for 16 passes where their visible points lie in one plane
    /// well inside the probed disc (`PhotonMapper::probe_clear_radii`); otherwise every
    /// candidate probes its own.
    pub probe_share: bool,
}

/// How a photon mapper's image pools the estimates of neighbouring pixels whose visible points
/// lie on the same surface (`photon_mapper::pool`), when the image is read.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PoolMode {
    /// Every pixel reads its own slots only.
    Off,
    /// The pooling width follows the frequency prediction of the light; methods without
    /// frequency photons do not pool.
    Frequency,
    /// The pooling width is the window's alone, whatever the light: a cross-bilateral filter on
    /// position, normal, material and texture, the control for `Frequency`.
    Geometry,
}

impl PoolMode {
    /// The name in parameters and metadata.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            PoolMode::Off => "off",
            PoolMode::Frequency => "freq",
            PoolMode::Geometry => "geometry",
        }
    }
}

/// The image-space reconstruction of the photon mappers (`photon_mapper::pool`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pooling {
    /// Which width pools neighbouring pixels.
    pub mode: PoolMode,
    /// The blur budget as a multiple of the frequency radius r_freq, in (0, 64]: a pixel pools
    /// with a Gaussian of standard deviation √((scale·r_freq)² − R²)/2, so that its gather disc
    /// and the pooling together blur no more than a disc of radius scale·r_freq.
    pub scale: f64,
    /// The pooling window's radius in pixels, in [0, 32]; the Gaussian's standard deviation is
    /// at most half of it (in world units, measured from the neighbours' visible points).
    pub max_pixels: u32,
    /// How the width shrinks with the photons counted n: by (n₀/n)^decay once n > n₀ = 10⁷,
    /// in [0, 1], so that the image converges to the unpooled estimator's limit.
    pub decay: f64,
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
    #[error("{method} does not render independent passes (only appm, vcm and bdpt do)")]
    NotPassIndependent {
        /// The method asked for.
        method: Method,
    },
    /// The scene has participating media, which this method does not render (`docs/media.md`).
    #[error(
        "the scene has participating media, which {method} does not render: use the default method, sppm, ppm, appm or path"
    )]
    MediaUnsupported {
        /// The method asked for.
        method: Method,
    },
    /// `direct_lighting` in a scene with media, which its light samples do not render.
    #[error(
        "direct_lighting is not available in a scene with participating media: leave it off (photons carry the direct light)"
    )]
    MediaDirectLighting,
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
    /// Settles an automatic `photons_per_pass` for a film of `slots` hitpoint slots (pixels
    /// times `samples_per_pixel`): for the photon mappers the larger of 100 000 and one photon per
    /// slot (at most `u32::MAX`), for every other method 100 000; then `photons_auto` is false.
    /// A number given by the user is kept. Measured on pbrt-v4's Veach MIS scene (1152 × 864,
    /// 30 s): 100 000 photons a pass left 95 % of each pass to the per-slot phases and read 3.7
    /// times the error of 1.5 M (docs/convergence.md); at 256² (65 536 slots) nothing changes.
    pub fn resolve_photons_per_pass(&mut self, slots: u64) {
        if !self.budget.photons_auto {
            return;
        }
        if self.method.is_photon_mapper() {
            let per_slot = u32::try_from(slots).unwrap_or(u32::MAX);
            self.budget.photons_per_pass = self.budget.photons_per_pass.max(per_slot);
        }
        self.budget.photons_auto = false;
    }

    /// The connection-only light paths a photon mapper traces per pass
    /// (`extra_light_paths` × `photons_per_pass`, rounded; none without `light_tracing`).
    #[must_use]
    pub fn connect_only_paths(&self) -> u64 {
        if !self.connections.light_tracing {
            return 0;
        }
        // In [0, 64 × 2³²): exact in an f64 and in a u64.
        (self.connections.extra_light_paths * f64::from(self.budget.photons_per_pass)).round()
            as u64
    }

    /// The pass (0-based) at whose start a frequency method sizes its kernels from the
    /// frequency prediction and restarts the statistics, if it grows kernels at all.
    #[must_use]
    pub fn growth_pass(&self) -> Option<u32> {
        let f = &self.frequency;
        (self.method.uses_frequency() && f.grow > 1.0 && f.pilot > 0).then_some(f.pilot)
    }

    /// The defaults: freq-sppm, 100 000 photons per pass, α = 0.7, one hitpoint per
    /// pixel; for the frequency methods 10 % frequency photons, K = K_STRICT, min-radius merge
    /// and occlusion probes (the defaults of `docs/convergence.md` and `docs/integrators.md`).
    #[must_use]
    pub fn preview() -> Self {
        Self {
            method: Method::FreqSppm,
            seed: 0,
            budget: Budget {
                photons_per_pass: 100_000,
                photons_auto: true,
                max_depth: 1024,
                rr_depth: 3,
            },
            film: FilmSampling {
                samples_per_pixel: 1,
                sequence: CameraSequence::Sobol,
                glass_split: true,
            },
            kernel: Kernel {
                alpha: 0.7,
                volume_radius: 1.0,
                initial_radius: None,
                freq_radius: false,
            },
            connections: Connections {
                light_tracing: true,
                connect_below: 2.0,
                extra_light_paths: 0.0,
                direct_lighting: false,
                direct_samples: 4,
                glossy_continue: 0.3,
            },
            frequency: FrequencyParams {
                fraction: 0.1,
                merge: MergePolicy::MinRadius,
                kernel_k: K_STRICT,
                floor: FrequencyFloor::Keep,
                occlusion: true,
                geometry: true,
                grow: 1.0,
                hold_alpha: 0.9,
                pilot: 4,
                clear_cap: true,
                cap_floor: Some(1.0 / 16.0),
                cap_scale: 4.0,
                probe_share: true,
            },
            pool: Pooling {
                mode: PoolMode::Frequency,
                scale: 0.5,
                max_pixels: 4,
                decay: 1.0 / 6.0,
            },
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
        if self.budget.photons_per_pass == 0 {
            return Err(out(
                "photons_per_pass",
                self.budget.photons_per_pass,
                "[1, 2^32)",
            ));
        }
        if !(self.kernel.alpha > 0.0 && self.kernel.alpha <= 1.0) {
            return Err(out("alpha", self.kernel.alpha, "(0, 1]"));
        }
        if !(self.kernel.volume_radius > 0.0 && self.kernel.volume_radius <= 64.0) {
            return Err(out("volume_radius", self.kernel.volume_radius, "(0, 64]"));
        }
        if let Some(r) = self.kernel.initial_radius
            && !(r > 0.0 && r.is_finite())
        {
            return Err(out("initial_radius", r, "(0, inf)"));
        }
        if self.budget.max_depth == 0 || self.budget.max_depth > 1024 {
            return Err(out("max_depth", self.budget.max_depth, "[1, 1024]"));
        }
        if self.budget.rr_depth == 0 || self.budget.rr_depth > 1024 {
            return Err(out("rr_depth", self.budget.rr_depth, "[1, 1024]"));
        }
        if self.film.samples_per_pixel == 0 || self.film.samples_per_pixel > 1024 {
            return Err(out("spp", self.film.samples_per_pixel, "[1, 1024]"));
        }
        if !(0.0..=1.0).contains(&self.frequency.fraction) {
            return Err(out("freq_fraction", self.frequency.fraction, "[0, 1]"));
        }
        if !(self.frequency.kernel_k > 0.0 && self.frequency.kernel_k.is_finite()) {
            return Err(out("kernel_k", self.frequency.kernel_k, "(0, inf)"));
        }
        if !(1.0..=64.0).contains(&self.frequency.grow) {
            return Err(out("freq_grow", self.frequency.grow, "[1, 64]"));
        }
        if let Some(f) = self.frequency.cap_floor
            && !(f > 0.0 && f <= 1.0)
        {
            return Err(out("freq_cap", f, "(0, 1] or off"));
        }
        if !(1.0..=64.0).contains(&self.frequency.cap_scale) {
            return Err(out("freq_cap_scale", self.frequency.cap_scale, "[1, 64]"));
        }
        if !(self.frequency.hold_alpha > 0.0 && self.frequency.hold_alpha <= 1.0) {
            return Err(out("freq_hold_alpha", self.frequency.hold_alpha, "(0, 1]"));
        }
        if !(self.pool.scale > 0.0 && self.pool.scale <= 64.0) {
            return Err(out("pool_scale", self.pool.scale, "(0, 64]"));
        }
        if self.pool.max_pixels > 32 {
            return Err(out("pool_max", self.pool.max_pixels, "[0, 32]"));
        }
        if !(0.0..=1.0).contains(&self.pool.decay) {
            return Err(out("pool_decay", self.pool.decay, "[0, 1]"));
        }
        if self.connections.connect_below.is_nan() || self.connections.connect_below < 0.0 {
            return Err(out(
                "connect_below",
                self.connections.connect_below,
                "[0, inf]",
            ));
        }
        if !(0.0..=64.0).contains(&self.connections.extra_light_paths) {
            return Err(out(
                "extra_light_paths",
                self.connections.extra_light_paths,
                "[0, 64]",
            ));
        }
        if !(1..=64).contains(&self.connections.direct_samples) {
            return Err(out(
                "direct_samples",
                self.connections.direct_samples,
                "[1, 64]",
            ));
        }
        if !(0.0..=1.0).contains(&self.connections.glossy_continue) {
            return Err(out(
                "glossy_continue",
                self.connections.glossy_continue,
                "[0, 1]",
            ));
        }
        if self.frequency.pilot > 1_000_000 {
            return Err(out("freq_pilot", self.frequency.pilot, "[0, 1000000]"));
        }
        Ok(())
    }
}
