//! The image PPM converges to, for measuring its convergence.
//!
//! PPM (and its frequency-guided variant) keeps the hitpoints of its first camera pass: each
//! slot's reflected radiance converges to the radiance leaving that one point, not to the
//! average over the pixel. Against a pixel-averaged reference its error therefore stops at a
//! floor set by the in-pixel variation, and its rate of convergence cannot be read. The
//! pointwise reference removes that floor: for each slot, path-traced reflected radiance at
//! exactly the slot's hitpoint, plus the emission its camera paths see directly, which PPM
//! re-jitters every pass and so averages over the pixel.

use std::sync::Arc;

use rayon::prelude::*;
use scene::{Rgb, Scene};

use crate::params::{ParamError, RenderParams};
use crate::path::PathTracer;
use crate::photon_mapper::PhotonMapper;
use crate::rng::Sampler;

/// Stream of the reference paths (distinct from the camera and photon streams).
const REFERENCE_STREAM: u64 = 1 << 62;
/// Slots per parallel work item; fixed so the work split does not depend on the thread count.
const SLOT_CHUNK: usize = 64;

/// The image a PPM render with `params` converges to (linear RGB per pixel, row-major): at
/// every hitpoint slot of its first camera pass, the reflected radiance estimated by
/// `paths_per_point` path-traced paths (light sampling and MIS, the same path limit), weighted
/// as PPM weights the slot, plus the directly seen emission averaged over `emission_passes`
/// camera passes with PPM's own jitter (those of its passes 0, 1, …).
///
/// Deterministic for any thread count. Cost: `paths_per_point` paths per slot. It is what
/// PPM converges to when it only gathers: with `light_tracing` the connections converge to
/// the pixel's average instead, so compare renders made without them.
///
/// # Errors
///
/// [`ParamError`] if `params` are invalid, or their method re-traces its hitpoints (SPPM, the
/// path tracer) or direct lighting is on: those converge to the pixel average already.
pub fn pointwise_reference(
    scene: &Arc<Scene>,
    params: RenderParams,
    paths_per_point: u32,
    emission_passes: u32,
) -> Result<Vec<[f32; 3]>, ParamError> {
    pointwise_reference_paths(scene, params, 0..paths_per_point, emission_passes)
}

/// [`pointwise_reference`] with the reference paths of indices `paths` only (the full reference
/// of `n` paths uses `0..n`). Disjoint ranges give independent estimates of the same image, so
/// the noise of a reference can be measured: with A from `0..n/2` and B from `n/2..n`, (A + B)/2
/// is the reference of `n` paths (up to rounding) and (A − B)²/4 estimates its variance per pixel.
///
/// # Errors
///
/// As [`pointwise_reference`].
pub fn pointwise_reference_paths(
    scene: &Arc<Scene>,
    params: RenderParams,
    paths: std::ops::Range<u32>,
    emission_passes: u32,
) -> Result<Vec<[f32; 3]>, ParamError> {
    if params.method.is_stochastic()
        || !params.method.is_photon_mapper()
        || params.connections.direct_lighting
    {
        return Err(ParamError::NoFixedHitpoints {
            method: params.method.name(),
        });
    }
    let mapper = PhotonMapper::new(Arc::clone(scene), params)?;
    let tracer = PathTracer::new(Arc::clone(scene), params);
    let film = scene.description().film;
    let spp = params.film.samples_per_pixel as usize;
    let n_slots = film.width as usize * film.height as usize * spp;
    let slot_radiance = |slot: usize| -> [f64; 3] {
        let slot = slot as u32;
        let mut sum = [0.0f64; 3];
        let mut add = |l: Rgb, scale: f64| {
            sum[0] += f64::from(l.x) * scale;
            sum[1] += f64::from(l.y) * scale;
            sum[2] += f64::from(l.z) * scale;
        };
        let passes = emission_passes.max(1);
        let first = mapper.camera_chain(slot, 0);
        add(first.direct, 1.0 / f64::from(passes));
        for pass in 1..passes {
            add(
                mapper.camera_chain(slot, pass).direct,
                1.0 / f64::from(passes),
            );
        }
        if let Some(end) = first.end {
            let scale = 1.0 / paths.len().max(1) as f64;
            for path in paths.clone() {
                let mut sampler =
                    Sampler::new(params.seed, path, REFERENCE_STREAM | u64::from(slot));
                let l = tracer.scattered(end.hit, end.outgoing, end.bounces, &mut sampler);
                add(end.throughput * l, scale);
            }
        }
        sum.map(|v| v / spp as f64)
    };
    let slots: Vec<[f64; 3]> = (0..n_slots)
        .into_par_iter()
        .with_min_len(SLOT_CHUNK)
        .map(slot_radiance)
        .collect();
    Ok(slots
        .chunks(spp)
        .map(|pixel| {
            let mut sum = [0.0f64; 3];
            for slot in pixel {
                for c in 0..3 {
                    sum[c] += slot[c];
                }
            }
            sum.map(|v| v as f32)
        })
        .collect())
}
