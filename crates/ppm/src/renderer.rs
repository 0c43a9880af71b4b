//! The one progressive API over every integrator.

use glam::Vec2;
use rayon::prelude::*;
use scene::{Rgb, Scene};

use crate::params::{Method, ParamError, RenderParams};
use crate::path::PathTracer;
use crate::photon_mapper::{MemoryUse, PassStats, PassSums, PhotonMapper};

/// A progressive render in progress: create it, call [`Renderer::iterate`] as often as the
/// budget allows, read [`Renderer::image`] (and [`Renderer::aov`]) at any time, and save or
/// restore its exact state with [`Renderer::save_state`] / [`Renderer::restore`].
pub struct Renderer<'s> {
    pub(crate) scene: &'s Scene,
    pub(crate) engine: Engine<'s>,
}

pub(crate) enum Engine<'s> {
    Photons(Box<PhotonMapper<'s>>),
    Path(PathTracer<'s>),
}

/// Auxiliary images ("arbitrary output variables") besides the beauty image.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Aov {
    /// Gather radius R per pixel (mean over the pixel's hitpoint slots); photon mappers only.
    Radius,
    /// Accumulated photon count N per pixel (mean over the slots); photon mappers only.
    PhotonCount,
    /// Frequency radius r_freq per pixel (mean over the slots that have one; 0 where no
    /// frequency photon arrived); frequency methods only.
    FreqRadius,
    /// Share of the pixel's slots whose radius is held by the frequency floor (R ≤ r_freq);
    /// frequency methods only.
    FreqHeld,
    /// Albedo (reflectance) of the first surface seen through the pixel centre (RGB).
    Albedo,
    /// Shading normal of the first surface seen through the pixel centre, facing the camera
    /// (XYZ in [−1, 1]).
    Normal,
    /// Distance from the camera to the first surface seen through the pixel centre (0 if none).
    Depth,
}

impl Aov {
    /// Every AOV.
    pub const ALL: [Aov; 7] = [
        Aov::Radius,
        Aov::PhotonCount,
        Aov::FreqRadius,
        Aov::FreqHeld,
        Aov::Albedo,
        Aov::Normal,
        Aov::Depth,
    ];

    /// Channel names of this AOV in an image file, e.g. `["albedo.R", "albedo.G", "albedo.B"]`.
    #[must_use]
    pub fn channel_names(self) -> &'static [&'static str] {
        match self {
            Aov::Radius => &["radius"],
            Aov::PhotonCount => &["count"],
            Aov::FreqRadius => &["freq.radius"],
            Aov::FreqHeld => &["freq.held"],
            Aov::Albedo => &["albedo.R", "albedo.G", "albedo.B"],
            Aov::Normal => &["normal.X", "normal.Y", "normal.Z"],
            Aov::Depth => &["depth"],
        }
    }
}

impl<'s> Renderer<'s> {
    /// A renderer for `scene` with `params`; nothing is traced until the first
    /// [`Renderer::iterate`].
    ///
    /// # Errors
    ///
    /// [`ParamError`] if a parameter is outside its domain or the film is too large.
    pub fn new(scene: &'s Scene, params: RenderParams) -> Result<Self, ParamError> {
        params.validate()?;
        let engine = match params.method {
            Method::Path => Engine::Path(PathTracer::new(scene, params)),
            _ => Engine::Photons(Box::new(PhotonMapper::new(scene, params)?)),
        };
        Ok(Self { scene, engine })
    }

    /// The kernels r₀ of a pass-independent render (`appm`): the radius of each hitpoint slot
    /// in its first pass, from the frequency pilot (`freq_pilot` passes of freq-sppm). A plan
    /// computes them once, so that every work unit gathers with the same kernels.
    ///
    /// # Errors
    ///
    /// [`ParamError`] if a parameter is outside its domain or the film is too large.
    pub fn pass_independent_kernels(
        scene: &Scene,
        params: RenderParams,
    ) -> Result<Vec<f64>, ParamError> {
        params.validate()?;
        PhotonMapper::new(scene, params)?;
        Ok(crate::photon_mapper::pilot_kernels(scene, params))
    }

    /// A pass-independent render (`params.method` must be `appm`) with the given kernels (from
    /// [`Renderer::pass_independent_kernels`]), whose next pass is `first_pass` (0-based): a
    /// work unit renders its passes and hands back [`Renderer::pass_sums`].
    ///
    /// # Errors
    ///
    /// [`ParamError`] if the method is not pass-independent, a parameter is outside its
    /// domain, or the kernels are not one positive finite radius per hitpoint slot.
    pub fn with_kernels(
        scene: &'s Scene,
        params: RenderParams,
        kernels: Vec<f64>,
        first_pass: u32,
    ) -> Result<Self, ParamError> {
        if !params.method.is_pass_independent() {
            return Err(ParamError::NotPassIndependent {
                method: params.method,
            });
        }
        let mut mapper = PhotonMapper::new(scene, params)?;
        if kernels.len() != mapper.n_slots() || !kernels.iter().all(|r| r.is_finite() && *r > 0.0) {
            return Err(ParamError::BadKernels {
                expected: mapper.n_slots(),
                found: kernels.len(),
            });
        }
        let film = scene.description().film;
        let pixels = film.width as usize * film.height as usize;
        mapper.set_independent(kernels, PassSums::new(pixels), first_pass);
        Ok(Self {
            scene,
            engine: Engine::Photons(Box::new(mapper)),
        })
    }

    /// The exact sums of the pass images of a pass-independent render (`appm`) so far; `None`
    /// for the other methods, or before the first pass.
    #[must_use]
    pub fn pass_sums(&self) -> Option<&PassSums> {
        match &self.engine {
            Engine::Photons(p) => p.pass_sums(),
            Engine::Path(_) => None,
        }
    }

    /// The kernels r₀ of a pass-independent render (`appm`), once the pilot has run (or they
    /// were given); `None` for the other methods.
    #[must_use]
    pub fn kernels(&self) -> Option<&[f64]> {
        match &self.engine {
            Engine::Photons(p) => p.kernels(),
            Engine::Path(_) => None,
        }
    }

    /// The scene being rendered.
    #[must_use]
    pub fn scene(&self) -> &'s Scene {
        self.scene
    }

    /// The parameters this renderer runs with.
    #[must_use]
    pub fn params(&self) -> &RenderParams {
        match &self.engine {
            Engine::Photons(p) => p.params(),
            Engine::Path(p) => &p.params,
        }
    }

    /// Passes completed so far.
    #[must_use]
    pub fn passes(&self) -> u32 {
        match &self.engine {
            Engine::Photons(p) => p.passes(),
            Engine::Path(p) => p.passes,
        }
    }

    /// Photons emitted over all passes so far (0 for the path tracer).
    #[must_use]
    pub fn photons_emitted(&self) -> u64 {
        match &self.engine {
            Engine::Photons(p) => p.photons_emitted(),
            Engine::Path(_) => 0,
        }
    }

    /// Film width and height in pixels.
    #[must_use]
    pub fn resolution(&self) -> (u32, u32) {
        let film = self.scene.description().film;
        (film.width, film.height)
    }

    /// Runs one pass and returns its statistics.
    pub fn iterate(&mut self) -> PassStats {
        match &mut self.engine {
            Engine::Photons(p) => p.iterate(),
            Engine::Path(p) => {
                let pass = p.passes;
                let clock = std::time::Instant::now();
                let (paths, non_finite) = p.iterate();
                let mut stats = PassStats::empty(pass);
                stats.camera_paths = paths;
                stats.non_finite = non_finite;
                stats.timings.camera = clock.elapsed().as_secs_f64();
                stats
            }
        }
    }

    /// The current estimate: linear RGB radiance per pixel (the average over the pixel's
    /// square), row-major from the top-left, `width × height` entries.
    #[must_use]
    pub fn image(&self) -> Vec<[f32; 3]> {
        match &self.engine {
            Engine::Photons(p) => p.image(),
            Engine::Path(p) => p.image(),
        }
    }

    /// Heap memory of the photon mappers' state and pass buffers, by part; `None` for the path
    /// tracer (one `[f64; 3]` sum per pixel).
    #[must_use]
    pub fn memory(&self) -> Option<MemoryUse> {
        match &self.engine {
            Engine::Photons(p) => Some(p.memory()),
            Engine::Path(_) => None,
        }
    }

    /// An auxiliary image, `width × height × channels` values (channels as in
    /// [`Aov::channel_names`]), or `None` if this integrator has no such quantity (e.g. a
    /// radius for the path tracer, a frequency radius for classical PPM).
    #[must_use]
    pub fn aov(&self, aov: Aov) -> Option<Vec<f32>> {
        match aov {
            Aov::Albedo | Aov::Normal | Aov::Depth => Some(self.first_hit_aov(aov)),
            Aov::Radius | Aov::PhotonCount | Aov::FreqRadius | Aov::FreqHeld => {
                let Engine::Photons(mapper) = &self.engine else {
                    return None;
                };
                mapper.slot_aov(aov)
            }
        }
    }

    /// Albedo, normal or depth of the first surface seen through each pixel centre.
    fn first_hit_aov(&self, aov: Aov) -> Vec<f32> {
        let (width, height) = self.resolution();
        let channels = aov.channel_names().len();
        let mut out = vec![0.0f32; width as usize * height as usize * channels];
        out.par_chunks_mut(channels)
            .enumerate()
            .for_each(|(pixel, values)| {
                let (x, y) = (pixel as u32 % width, pixel as u32 / width);
                let film = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
                let ray = self.scene.camera().generate_ray(film, Vec2::splat(0.5));
                let Some(hit) = self.scene.intersect(&ray) else {
                    return;
                };
                match aov {
                    Aov::Depth => values[0] = hit.t,
                    Aov::Normal => values.copy_from_slice(&hit.shading_normal.to_array()),
                    _ => {
                        let albedo = self
                            .scene
                            .material(hit.material)
                            .map_or(Rgb::ZERO, |m| m.kind.albedo())
                            * self.scene.scattering_tint(&hit);
                        values.copy_from_slice(&albedo.to_array());
                    }
                }
            });
        out
    }
}
