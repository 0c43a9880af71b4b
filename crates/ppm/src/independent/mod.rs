//! The pass-independent estimator (`--method appm`): Knaus and Zwicker's probabilistic PPM
//! (2011), with per-slot kernels from a frequency pilot.
//!
//! Pass i (1-based) gathers with the radius r₀ · gᵢ, where r₀ is the slot's kernel, fixed
//! before the first pass, and gᵢ follows a global schedule, g₁ = 1,
//! gᵢ₊₁² = gᵢ² · (i + α)/(i + 1). Every pass makes a complete image on its own (new camera paths
//! as in SPPM, the emission they see, the photons within the pass's radius), and the render is
//! the mean of the pass images: its bias vanishes as gᵢ → 0 while its variance stays bounded in
//! the mean (Knaus and Zwicker, §4). Nothing carries from one pass to the next, so passes can be
//! rendered in any order, on any number of machines, and summed.
//!
//! The sums are exact (`sums.rs`), so the image of N passes is the same bits whatever passes
//! were rendered together, in what order, and however the sums were merged.
//!
//! The estimator runs the photon mappers' phases (`PhotonMapper::run_pass`) with its own radii
//! before the grid and its own pass image after the photons, in place of the progressive update.
//!
//! The kernels r₀ come from the pilot: `freq_pilot` passes of `freq-sppm` from the same seed,
//! after which each slot's radius is what the frequency analysis let it keep (smooth light holds
//! large kernels; caustics and shadow edges shrink theirs). With `freq_pilot = 0` every slot
//! starts from the automatic radius, which is Knaus and Zwicker's method as published.

pub(crate) mod sums;

use std::sync::Arc;

use rayon::prelude::*;
use scene::Scene;

use self::sums::FIXED_POINT;
pub use self::sums::{Part, PartError, PassSums};
use crate::aov::Aov;
use crate::checkpoint::codec::{Reader, StateError, Writer};
use crate::integrator::Integrator;
use crate::params::{Method, ParamError, RenderParams};
use crate::photon_mapper::{self, NO_VISIBLE_POINT, PhotonMapper, auto_initial_radius};
use crate::stats::{MemoryEstimate, MemoryUse, PassStats};
pub(crate) use crate::update::schedule_squared;

/// The pass-independent estimator: the photon mappers' phases, with kernels fixed by a pilot.
pub(crate) struct PassIndependent {
    mapper: PhotonMapper,
    /// The kernels and the sums, once the pilot has run or a plan gave the kernels.
    state: Option<Independent>,
}

/// The state of the pass-independent estimator: the kernels and the exact sums (nothing else
/// carries from pass to pass).
struct Independent {
    /// Per slot: r₀, the radius of the first pass.
    kernels: Vec<f64>,
    sums: PassSums,
}

/// The pilot: `params.frequency.pilot` passes of freq-sppm from the same seed; each slot's radius
/// after them (or the automatic radius everywhere without a pilot).
pub(crate) fn pilot_kernels(scene: &Arc<Scene>, params: RenderParams) -> Vec<f64> {
    let film = scene.description().film;
    let n_slots =
        film.width as usize * film.height as usize * params.film.samples_per_pixel as usize;
    let mut pilot_params = params;
    pilot_params.method = Method::FreqSppm;
    // The construction checks the same film and parameters as the caller's own renderer.
    let Ok(mut pilot) = PhotonMapper::new(Arc::clone(scene), pilot_params) else {
        return vec![auto_initial_radius(scene); n_slots];
    };
    let r0 = pilot.initial_radius();
    if params.frequency.pilot == 0 {
        return vec![r0; n_slots];
    }
    for _ in 0..params.frequency.pilot {
        pilot.iterate();
    }
    // A slot without a visible point in the pilot's last pass keeps its radius anyway: the
    // next pass may find one.
    pilot.pass_columns().0.to_vec()
}

/// What a render will hold: the photon mappers' estimate with the frequency buffers (the pilot
/// is a freq-sppm render), each slot's kernel and each pixel's exact sums (3 × i128).
pub(crate) fn estimate(pixels: u64, params: &RenderParams) -> MemoryEstimate {
    let mut estimate = photon_mapper::estimate(pixels, params, true);
    let slots = pixels.saturating_mul(u64::from(params.film.samples_per_pixel));
    estimate.hitpoints = estimate
        .hitpoints
        .saturating_add(slots.saturating_mul(8))
        .saturating_add(pixels.saturating_mul(48));
    estimate
}

impl PassIndependent {
    /// A render with `params` (whose method is `appm`); its first pass runs the pilot.
    ///
    /// # Errors
    ///
    /// [`ParamError`] if a parameter is outside its domain or the film is too large.
    pub(crate) fn new(scene: Arc<Scene>, params: RenderParams) -> Result<Self, ParamError> {
        Ok(Self {
            mapper: PhotonMapper::new(scene, params)?,
            state: None,
        })
    }

    /// A render whose kernels are given (from [`pilot_kernels`], or a plan) and whose next pass
    /// is `first_pass`.
    ///
    /// # Errors
    ///
    /// [`ParamError`] if the method is not pass-independent, a parameter is outside its
    /// domain, or the kernels are not one positive finite radius per hitpoint slot.
    pub(crate) fn with_kernels(
        scene: Arc<Scene>,
        params: RenderParams,
        kernels: Vec<f64>,
        first_pass: u32,
    ) -> Result<Self, ParamError> {
        if params.method != Method::Appm {
            return Err(ParamError::NotPassIndependent {
                method: params.method,
            });
        }
        let mut render = Self::new(scene, params)?;
        let n_slots = render.mapper.n_slots();
        if kernels.len() != n_slots || !kernels.iter().all(|r| r.is_finite() && *r > 0.0) {
            return Err(ParamError::BadKernels {
                expected: n_slots,
                found: kernels.len(),
            });
        }
        render.set(kernels, PassSums::new(render.pixels()), first_pass);
        Ok(render)
    }

    fn pixels(&self) -> usize {
        self.mapper.n_slots() / self.mapper.params().film.samples_per_pixel as usize
    }

    /// Takes the kernels and the sums so far, before pass `passes`.
    fn set(&mut self, kernels: Vec<f64>, sums: PassSums, passes: u32) {
        self.mapper.start_at(passes);
        self.state = Some(Independent { kernels, sums });
    }

    /// The most bytes [`Integrator::save`] writes.
    fn body_bound(&self) -> usize {
        8 + 8 + self.pixels().saturating_mul(48) + 8 + self.mapper.n_slots().saturating_mul(8)
    }
}

/// Before the grid is built: every slot's radius for pass `pass`, r₀ · gᵢ.
fn schedule_radii(kernels: &[f64], mapper: &mut PhotonMapper, pass: u32) {
    let g = schedule_squared(u64::from(pass), mapper.params().kernel.alpha).sqrt();
    mapper
        .radii_mut()
        .par_iter_mut()
        .zip(kernels.par_iter())
        .for_each(|(radius, &r0)| *radius = r0 * g);
}

/// After the photon pass: the pass image (emission seen by this pass's camera paths, the
/// photons each slot gathered within its radius, and in media the volume photons gathered along
/// its stretches through them), added to the exact sums.
fn add_pass_image(
    sums: &mut PassSums,
    kernels: &[f64],
    mapper: &mut PhotonMapper,
    stats: &mut PassStats,
) {
    let params = *mapper.params();
    let spp = params.film.samples_per_pixel as usize;
    let photons = f64::from(params.budget.photons_per_pass);
    let pass = mapper.passes();
    let (radius, direct, bounces, deposits) = mapper.pass_columns();
    let non_finite: u64 = sums
        .sums
        .par_iter_mut()
        .enumerate()
        .map(|(pixel, sum)| {
            let mut image = [0.0f64; 3];
            for slot in pixel * spp..(pixel + 1) * spp {
                let (_, flux) = deposits.deposit_of(slot);
                let light = deposits.light_of(slot);
                let volume = mapper.volume_of_pass(slot);
                let area = std::f64::consts::PI * radius[slot] * radius[slot];
                let gathered = bounces[slot] != NO_VISIBLE_POINT && area > 0.0;
                for c in 0..3 {
                    image[c] += direct[slot][c] + light[c] / photons + volume[c];
                    if gathered {
                        image[c] += flux[c] / (area * photons);
                    }
                }
            }
            if !image.iter().all(|v| v.is_finite()) {
                return 1;
            }
            for c in 0..3 {
                // `as` saturates: a pass image beyond 9 · 10¹⁸ is clamped, never wrapped.
                sum[c] = sum[c].saturating_add((image[c] * FIXED_POINT).round() as i128);
            }
            0
        })
        .sum();
    sums.passes += 1;
    stats.non_finite += non_finite;
    stats.hitpoints_valid = bounces.iter().filter(|&&b| b != NO_VISIBLE_POINT).count() as u64;
    let g = schedule_squared(u64::from(pass), params.kernel.alpha).sqrt();
    let mean = kernels.iter().sum::<f64>() / kernels.len().max(1) as f64;
    stats.mean_radius = mean * g;
    stats.min_radius = kernels.iter().copied().fold(f64::INFINITY, f64::min) * g;
    stats.max_radius = kernels.iter().copied().fold(0.0, f64::max) * g;
    // The camera pass adds each pass's emission to the slots' direct sums; this estimator
    // takes it per pass.
    mapper.clear_direct();
}

impl Integrator for PassIndependent {
    fn params(&self) -> &RenderParams {
        self.mapper.params()
    }

    fn passes(&self) -> u32 {
        self.mapper.passes()
    }

    fn photons_emitted(&self) -> u64 {
        self.mapper.photons_emitted()
    }

    fn iterate(&mut self) -> PassStats {
        if self.state.is_none() {
            let kernels = pilot_kernels(self.mapper.scene(), *self.mapper.params());
            let (pixels, pass) = (self.pixels(), self.mapper.passes());
            self.set(kernels, PassSums::new(pixels), pass);
        }
        let Self { mapper, state } = self;
        let Some(state) = state.as_mut() else {
            unreachable!("the pilot has just given the kernels")
        };
        let Independent { kernels, sums } = state;
        let kernels: &[f64] = kernels;
        let pass = mapper.passes();
        mapper.run_pass(
            |m| {
                schedule_radii(kernels, m, pass);
                false
            },
            |m, stats| add_pass_image(sums, kernels, m, stats),
        )
    }

    fn image(&self) -> Vec<[f32; 3]> {
        match &self.state {
            Some(state) => state.sums.image(),
            None => vec![[0.0; 3]; self.pixels()],
        }
    }

    fn aov(&self, aov: Aov) -> Option<Vec<f32>> {
        self.mapper.slot_aov(aov)
    }

    fn memory(&self) -> Option<MemoryUse> {
        Some(self.mapper.memory())
    }

    /// Its exact sums and its kernels. Before the first pass (no kernels yet) both are empty.
    fn save(&self, w: &mut Writer) {
        let (passes, sums, kernels): (u64, &[[i128; 3]], &[f64]) = match &self.state {
            Some(s) => (s.sums.passes, &s.sums.sums, &s.kernels),
            None => (0, &[], &[]),
        };
        w.u64(passes);
        w.u64(sums.len() as u64);
        for s in sums {
            for v in s {
                w.bytes(&v.to_le_bytes());
            }
        }
        w.u64(kernels.len() as u64);
        kernels.iter().for_each(|&r| w.f64(r));
    }

    fn saved_bound(&self) -> usize {
        self.body_bound()
    }

    fn restore(&mut self, r: &mut Reader<'_>, passes: u32) -> Result<(), StateError> {
        let summed = r.u64()?;
        let n = r.len()?;
        let mut sums = Vec::with_capacity(n.min(r.rest.len() / 48));
        for _ in 0..n {
            let mut s = [0i128; 3];
            for v in &mut s {
                *v = i128::from_le_bytes(r.array()?);
            }
            sums.push(s);
        }
        let k = r.len()?;
        let mut kernels = Vec::with_capacity(k.min(r.rest.len() / 8));
        for _ in 0..k {
            kernels.push(r.f64()?);
        }
        if k == 0 && n == 0 && summed == 0 {
            return Ok(());
        }
        if k != self.mapper.n_slots()
            || summed != u64::from(passes)
            || !kernels.iter().all(|r| r.is_finite() && *r > 0.0)
            || n != self.pixels()
        {
            return Err(StateError::Corrupt);
        }
        self.set(
            kernels,
            PassSums {
                passes: summed,
                sums,
            },
            passes,
        );
        Ok(())
    }

    fn pass_sums(&self) -> Option<&PassSums> {
        self.state.as_ref().map(|s| &s.sums)
    }

    fn kernels(&self) -> Option<&[f64]> {
        self.state.as_ref().map(|s| s.kernels.as_slice())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_schedule_is_knaus_and_zwicker_s() {
        // g₂² = (1 + α)/2, g₃² = g₂² (2 + α)/3.
        let alpha = 2.0 / 3.0;
        assert_eq!(schedule_squared(0, alpha), 1.0);
        assert!((schedule_squared(1, alpha) - (1.0 + alpha) / 2.0).abs() < 1e-15);
        let g3 = (1.0 + alpha) / 2.0 * (2.0 + alpha) / 3.0;
        assert!((schedule_squared(2, alpha) - g3).abs() < 1e-15);
        // The area shrinks as i^(α−1) (their eq. 16): at i = 10⁴ the ratio of
        // g²(i) · i^(1−α) to its value at 10³ is near 1.
        let tail = |i: u64| schedule_squared(i, alpha) * (i as f64).powf(1.0 - alpha);
        assert!((tail(10_000) / tail(1_000) - 1.0).abs() < 0.01);
    }
}
