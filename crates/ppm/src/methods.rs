//! The one list of integrators: which module renders each [`Method`], and what its render
//! will hold in memory. A new integrator is a module implementing [`Integrator`], its variant
//! of [`Method`] (with its name and help in `params/`), and its line in [`entry`].

use std::sync::Arc;

use scene::Scene;

use crate::independent::{self, PassIndependent};
use crate::integrator::Integrator;
use crate::light_tracer::{self, LightTracer};
use crate::params::{Method, ParamError, RenderParams};
use crate::path::{self, PathTracer};
use crate::photon_mapper::{self, PhotonMapper};
use crate::stats::{FILM_BYTES_PER_PIXEL, MemoryEstimate};
use crate::vcm::{self, Vcm};

/// Starts a render of a scene with parameters whose method is this one.
type Build = fn(Arc<Scene>, RenderParams) -> Result<Box<dyn Integrator>, ParamError>;

/// How to start one method's render, and estimate its memory before anything is allocated.
struct Entry {
    build: Build,
    /// What the render holds for a film of this many pixels, the film itself aside.
    estimate: fn(u64, &RenderParams) -> MemoryEstimate,
    /// Whether it renders participating media (`docs/media.md`); a scene with media is refused
    /// by every other method rather than rendered wrongly.
    media: bool,
}

fn entry(method: Method) -> Entry {
    match method {
        Method::Ppm | Method::Sppm | Method::FreqPpm | Method::FreqSppm => Entry {
            build: |scene, params| Ok(Box::new(PhotonMapper::new(scene, params)?)),
            estimate: |pixels, params| {
                photon_mapper::estimate(pixels, params, params.method.uses_frequency())
            },
            media: true,
        },
        Method::Appm => Entry {
            build: |scene, params| Ok(Box::new(PassIndependent::new(scene, params)?)),
            estimate: independent::estimate,
            media: true,
        },
        Method::Path => Entry {
            build: |scene, params| Ok(Box::new(PathTracer::new(scene, params))),
            estimate: path::estimate,
            media: true,
        },
        Method::Light => Entry {
            build: |scene, params| Ok(Box::new(LightTracer::new(scene, params))),
            estimate: light_tracer::estimate,
            media: false,
        },
        Method::Vcm | Method::Bdpt => Entry {
            build: |scene, params| Ok(Box::new(Vcm::new(scene, params))),
            estimate: vcm::estimate,
            media: false,
        },
    }
}

/// The integrator of `params.method` for `scene`, before its first pass.
///
/// # Errors
///
/// [`ParamError`] if a parameter is outside its domain, the film is too large, or the scene
/// has media that the method does not render.
pub(crate) fn integrator(
    scene: Arc<Scene>,
    mut params: RenderParams,
) -> Result<Box<dyn Integrator>, ParamError> {
    let film = scene.description().film;
    params.resolve_photons_per_pass(
        (u64::from(film.width) * u64::from(film.height))
            .saturating_mul(u64::from(params.film.samples_per_pixel)),
    );
    params.validate()?;
    check_media(&scene, &params)?;
    (entry(params.method).build)(scene, params)
}

/// Refuses a scene with participating media (or interface materials) for a method that does
/// not render them.
///
/// # Errors
///
/// [`ParamError::MediaUnsupported`] for such a scene and method, and
/// [`ParamError::MediaDirectLighting`] for the photon mappers' `direct_lighting` in it (its
/// light samples do not yet weigh the transmittance).
pub(crate) fn check_media(scene: &Scene, params: &RenderParams) -> Result<(), ParamError> {
    let method = params.method;
    if scene.has_media() && !entry(method).media {
        return Err(ParamError::MediaUnsupported { method });
    }
    if scene.has_media() && method != Method::Path && params.connections.direct_lighting {
        return Err(ParamError::MediaDirectLighting);
    }
    Ok(())
}

impl MemoryEstimate {
    /// The estimate for a `width × height` film rendered with `params`: the integrator's own
    /// (`methods.rs` picks it by method) plus the output image with its AOVs.
    #[must_use]
    pub fn of(width: u32, height: u32, params: &RenderParams) -> Self {
        let pixels = u64::from(width) * u64::from(height);
        let mut params = *params;
        params.resolve_photons_per_pass(
            pixels.saturating_mul(u64::from(params.film.samples_per_pixel)),
        );
        let mut estimate = (entry(params.method).estimate)(pixels, &params);
        estimate.film = pixels.saturating_mul(FILM_BYTES_PER_PIXEL);
        estimate
    }
}
