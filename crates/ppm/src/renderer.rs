//! The one progressive API over every integrator.

use std::sync::Arc;

use glam::Vec2;
use rayon::prelude::*;
use scene::{Rgb, Scene};

use crate::aov::Aov;
use crate::independent::{PassIndependent, PassSums};
use crate::integrator::Integrator;
use crate::params::{Method, ParamError, RenderParams};
use crate::stats::{MemoryUse, PassStats};
use crate::vcm::Vcm;

/// A progressive render in progress: create it, call [`Renderer::iterate`] as often as the
/// budget allows, read [`Renderer::image`] (and [`Renderer::aov`]) at any time, and save or
/// restore its exact state with [`Renderer::save_state`] / [`Renderer::restore`].
///
/// It owns its scene (shared through an [`Arc`]), so that it can be stored, sent to another
/// thread or wrapped by a binding on its own.
pub struct Renderer {
    scene: Arc<Scene>,
    /// The method's integrator (`methods.rs`).
    pub(crate) integrator: Box<dyn Integrator>,
}

impl Renderer {
    /// A renderer for `scene` (a [`Scene`] or an `Arc` of one) with `params`; nothing is traced
    /// until the first [`Renderer::iterate`].
    ///
    /// # Errors
    ///
    /// [`ParamError`] if a parameter is outside its domain or the film is too large.
    pub fn new(scene: impl Into<Arc<Scene>>, params: RenderParams) -> Result<Self, ParamError> {
        let scene = scene.into();
        let integrator = crate::methods::integrator(Arc::clone(&scene), params)?;
        Ok(Self { scene, integrator })
    }

    /// The kernels r₀ of a pass-independent render: for `appm`, the radius of each hitpoint slot
    /// in its first pass, from the frequency pilot (`freq_pilot` passes of freq-sppm); for `vcm`
    /// and `bdpt`, none (their merge radius is a function of the pass index). A plan computes
    /// them once, so that every work unit gathers with the same kernels.
    ///
    /// # Errors
    ///
    /// [`ParamError`] if a parameter is outside its domain or the film is too large.
    pub fn pass_independent_kernels(
        scene: impl Into<Arc<Scene>>,
        params: RenderParams,
    ) -> Result<Vec<f64>, ParamError> {
        let scene = scene.into();
        params.validate()?;
        crate::methods::check_media(&scene, &params)?;
        if matches!(params.method, Method::Vcm | Method::Bdpt) {
            return Ok(Vec::new());
        }
        PassIndependent::new(Arc::clone(&scene), params)?;
        Ok(crate::independent::pilot_kernels(&scene, params))
    }

    /// A pass-independent render (`params.method` is `appm`, `vcm` or `bdpt`) with the given
    /// kernels (from [`Renderer::pass_independent_kernels`]), whose next pass is `first_pass`
    /// (0-based): a work unit renders its passes and hands back [`Renderer::pass_sums`].
    ///
    /// # Errors
    ///
    /// [`ParamError`] if the method is not pass-independent, a parameter is outside its
    /// domain, or the kernels are not one positive finite radius per hitpoint slot (none for
    /// `vcm` and `bdpt`).
    pub fn with_kernels(
        scene: impl Into<Arc<Scene>>,
        params: RenderParams,
        kernels: Vec<f64>,
        first_pass: u32,
    ) -> Result<Self, ParamError> {
        let scene = scene.into();
        crate::methods::check_media(&scene, &params)?;
        let integrator: Box<dyn Integrator> = if matches!(params.method, Method::Vcm | Method::Bdpt)
        {
            if !kernels.is_empty() {
                return Err(ParamError::BadKernels {
                    expected: 0,
                    found: kernels.len(),
                });
            }
            Box::new(Vcm::starting_at(Arc::clone(&scene), params, first_pass)?)
        } else {
            Box::new(PassIndependent::with_kernels(
                Arc::clone(&scene),
                params,
                kernels,
                first_pass,
            )?)
        };
        Ok(Self { scene, integrator })
    }

    /// The exact sums of the pass images of a pass-independent render (`appm`, `vcm`, `bdpt`)
    /// so far; `None` for the other methods, or before `appm`'s first pass.
    #[must_use]
    pub fn pass_sums(&self) -> Option<&PassSums> {
        self.integrator.pass_sums()
    }

    /// The kernels r₀ of a pass-independent render (`appm`), once the pilot has run (or they
    /// were given); empty for `vcm` and `bdpt`; `None` for the other methods.
    #[must_use]
    pub fn kernels(&self) -> Option<&[f64]> {
        self.integrator.kernels()
    }

    /// The scene being rendered.
    #[must_use]
    pub fn scene(&self) -> &Arc<Scene> {
        &self.scene
    }

    /// The parameters this renderer runs with.
    #[must_use]
    pub fn params(&self) -> &RenderParams {
        self.integrator.params()
    }

    /// Passes completed so far.
    #[must_use]
    pub fn passes(&self) -> u32 {
        self.integrator.passes()
    }

    /// Photons emitted over all passes so far (0 for the path tracer).
    #[must_use]
    pub fn photons_emitted(&self) -> u64 {
        self.integrator.photons_emitted()
    }

    /// Film width and height in pixels.
    #[must_use]
    pub fn resolution(&self) -> (u32, u32) {
        let film = self.scene.description().film;
        (film.width, film.height)
    }

    /// Runs one pass and returns its statistics.
    pub fn iterate(&mut self) -> PassStats {
        self.integrator.iterate()
    }

    /// The current estimate: linear RGB radiance per pixel (the average over the pixel's
    /// square), row-major from the top-left, `width × height` entries.
    #[must_use]
    pub fn image(&self) -> Vec<[f32; 3]> {
        self.integrator.image()
    }

    /// Heap memory of the photon mappers' state and pass buffers, by part; `None` for the path
    /// tracer (one `[f64; 3]` sum per pixel).
    #[must_use]
    pub fn memory(&self) -> Option<MemoryUse> {
        self.integrator.memory()
    }

    /// An auxiliary image, `width × height × channels` values (channels as in
    /// [`Aov::channel_names`]), or `None` if this integrator has no such quantity (e.g. a
    /// radius for the path tracer, a frequency radius for classical PPM).
    #[must_use]
    pub fn aov(&self, aov: Aov) -> Option<Vec<f32>> {
        match aov {
            Aov::Albedo | Aov::Normal | Aov::Depth => Some(self.first_hit_aov(aov)),
            Aov::Radius | Aov::PhotonCount | Aov::FreqRadius | Aov::FreqHeld | Aov::PoolWidth => {
                self.integrator.aov(aov)
            }
        }
    }

    /// Albedo, normal or depth of the first surface seen through each pixel centre.
    fn first_hit_aov(&self, aov: Aov) -> Vec<f32> {
        let (width, height) = self.resolution();
        let channels = aov.channel_names().len();
        let scene = &*self.scene;
        let mut out = vec![0.0f32; width as usize * height as usize * channels];
        out.par_chunks_mut(channels)
            .enumerate()
            .for_each(|(pixel, values)| {
                let (x, y) = (pixel as u32 % width, pixel as u32 / width);
                let film = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
                let ray = scene.camera().generate_ray(film, Vec2::splat(0.5));
                let Some(hit) = scene.intersect(&ray) else {
                    return;
                };
                match aov {
                    Aov::Depth => values[0] = hit.t,
                    Aov::Normal => values.copy_from_slice(&hit.shading_normal.to_array()),
                    _ => {
                        let albedo = scene
                            .material(hit.material)
                            .map_or(Rgb::ZERO, |m| m.kind.albedo())
                            * scene.scattering_tint(&hit);
                        values.copy_from_slice(&albedo.to_array());
                    }
                }
            });
        out
    }
}
