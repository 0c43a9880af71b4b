//! The progressive loop shared by PPM, SPPM and their frequency-guided variants.
//!
//! One pass is four phases, one file each:
//!
//! 1. `camera_pass.rs`: trace (the first pass, or every pass for SPPM) the visible points;
//! 2. `index.rs`: the hash grid over the hitpoint spheres;
//! 3. `photon_pass.rs`: trace photons in fixed chunks (`trace.rs`, one photon path) and gather
//!    them into the hitpoints;
//! 4. `update.rs`: fold the pass into R, N, τ, shrinking held slots by α_hold instead of α.
//!
//! `frequency.rs` holds the whole frequency extension, which those phases call into.
//! `stats.rs` holds what a pass reports. This file holds the state they share and the image.

mod camera_pass;
mod frequency;
mod independent;
mod index;
mod photon_pass;
mod stats;
#[cfg(test)]
mod tests;
mod trace;
mod update;

use std::time::Instant;

use photon::HitPoints;
use rayon::prelude::*;
use scene::Scene;
use spectrum::Caps;

pub(crate) use self::frequency::SlotFrequency;
pub(crate) use self::independent::pilot_kernels;
pub use self::independent::{Part, PartError, PassSums};
pub use self::stats::{MemoryEstimate, MemoryUse, PassStats, PassTimings};
use self::{frequency::FrequencyDeposits, index::Index, photon_pass::PhotonPass};
use crate::params::{ParamError, RenderParams};
use crate::renderer::Aov;
use crate::update::GatherStats;

/// Photons per parallel work item. Fixed (not derived from the thread count) so that the
/// reduction order, hence the image, does not depend on the number of threads.
const PHOTON_CHUNK: u64 = 2048;
/// Hitpoint slots per parallel work item of the camera pass.
const SLOT_CHUNK: usize = 1024;

/// What every phase reads and none changes: the scene, the parameters and what follows from
/// them.
struct Setup<'s> {
    scene: &'s Scene,
    params: RenderParams,
    caps: Caps,
    /// The initial gather radius R₀ (the largest kernel is [`Setup::kernel_max`]).
    kernel_scale: f64,
    width: u32,
    height: u32,
}

/// The photon mappers' state: hitpoint slots with their statistics, the grid, the direct
/// emission seen by camera paths, and each phase's buffers.
pub(crate) struct PhotonMapper<'s> {
    setup: Setup<'s>,
    pass: u32,
    n_emitted: u64,
    slots: HitPoints<SlotFrequency>,
    /// Per slot: the most bounces a photon may have made and still count there,
    /// `max_depth − 1 − (specular bounces of the camera path)`, so that no light path has more
    /// than `max_depth` scattering events (the hitpoint's own scattering is the 1); or
    /// [`NO_VISIBLE_POINT`] if the slot holds no visible point in the current pass.
    photon_bounces: Vec<u16>,
    /// Per slot: sum of directly seen emission (and direct lighting) over camera passes.
    direct: Vec<[f64; 3]>,
    camera_passes: u32,
    /// Phase 2's grid.
    index: Index,
    /// Phase 3's buffers, and M and Φ of the last pass for phase 4.
    photons: PhotonPass,
    /// The frequency deposits' buffers.
    frequency: FrequencyDeposits,
    /// The pass-independent estimator's kernels and sums (`appm` only; set before its first
    /// pass).
    independent: Option<independent::Independent>,
    /// Per 2 × 2 block of pixels, the clear disc its slots share ([`frequency::BlockDisc`]): a
    /// function of the scene, the parameters and the pass, recomputed where missing (after a
    /// restore), so that it is not part of a checkpoint.
    block_discs: Vec<Option<frequency::BlockDisc>>,
}

/// `photon_bounces` of a slot without a visible point (budgets are below `max_depth` ≤ 1024).
const NO_VISIBLE_POINT: u16 = u16::MAX;

/// The state of a photon mapper between passes, as a checkpoint restores it
/// ([`PhotonMapper::restore`]).
pub(crate) struct SavedState {
    /// Photons emitted so far.
    pub(crate) n_emitted: u64,
    /// Camera passes so far.
    pub(crate) camera_passes: u32,
    /// The hitpoint records.
    pub(crate) slots: HitPoints<SlotFrequency>,
    /// Per slot: the photon-bounce budget of its visible point, `None` without one.
    pub(crate) photon_budget: Vec<Option<u16>>,
    /// Per slot: the directly seen emission summed over camera passes.
    pub(crate) direct: Vec<[f64; 3]>,
}

/// The largest photon-bounce budget a slot can have.
pub(crate) const MAX_PHOTON_BUDGET: u16 = NO_VISIBLE_POINT - 1;

/// Memory per hitpoint slot of the photon mappers' fixed columns: the hitpoint record
/// (`photon::HitPoints` with the frequency state) plus the renderer's per-slot photon-bounce
/// budget (which also says whether the slot is valid) and direct-emission sum. The hash grid
/// and its slot map come on top; [`crate::Renderer::memory`] measures everything.
#[must_use]
pub fn bytes_per_hitpoint() -> usize {
    HitPoints::<SlotFrequency>::bytes_per_hitpoint()
        + std::mem::size_of::<u16>()
        + std::mem::size_of::<[f64; 3]>()
}

/// The smallppm choice of initial radius: twice the mean extent of the scene's bounding box
/// divided by the mean film size in pixels, about a two-pixel footprint.
#[must_use]
pub fn auto_initial_radius(scene: &Scene) -> f64 {
    let bounds = scene.bounds();
    let extent = bounds.max - bounds.min;
    let mean_extent = f64::from(extent.x + extent.y + extent.z) / 3.0;
    let film = scene.description().film;
    let mean_pixels = (f64::from(film.width) + f64::from(film.height)) / 2.0;
    let r = 2.0 * mean_extent / mean_pixels;
    if r > 0.0 && r.is_finite() { r } else { 1e-3 }
}

impl<'s> PhotonMapper<'s> {
    /// A renderer for `scene` with `params`; nothing is traced until the first
    /// [`crate::Renderer::iterate`].
    ///
    /// # Errors
    ///
    /// [`ParamError`] if a parameter is outside its domain or the film is too large.
    pub(crate) fn new(scene: &'s Scene, params: RenderParams) -> Result<Self, ParamError> {
        params.validate()?;
        let film = scene.description().film;
        let n_slots =
            u64::from(film.width) * u64::from(film.height) * u64::from(params.samples_per_pixel);
        if n_slots == 0 || n_slots > u64::from(u32::MAX) {
            return Err(ParamError::TooManyHitpoints {
                width: film.width,
                height: film.height,
                samples_per_pixel: params.samples_per_pixel,
            });
        }
        let bounds = scene.bounds();
        let scene_size = f64::from((bounds.max - bounds.min).length()).max(1e-6);
        Ok(Self {
            setup: Setup {
                scene,
                params,
                caps: Caps::for_scene_size(scene_size),
                kernel_scale: params
                    .initial_radius
                    .unwrap_or_else(|| auto_initial_radius(scene)),
                width: film.width,
                height: film.height,
            },
            pass: 0,
            n_emitted: 0,
            slots: HitPoints::with_capacity(0),
            photon_bounces: Vec::new(),
            direct: Vec::new(),
            camera_passes: 0,
            index: Index::default(),
            photons: PhotonPass::default(),
            frequency: FrequencyDeposits::default(),
            independent: None,
            block_discs: Vec::new(),
        })
    }

    /// The parameters this renderer runs with.
    #[must_use]
    pub(crate) fn params(&self) -> &RenderParams {
        &self.setup.params
    }

    /// Passes completed so far.
    #[must_use]
    pub(crate) fn passes(&self) -> u32 {
        self.pass
    }

    /// Photons emitted over all passes so far.
    #[must_use]
    pub(crate) fn photons_emitted(&self) -> u64 {
        self.n_emitted
    }

    /// Photons the statistics count: all that were emitted, less those of the pilot once the
    /// kernels were sized and the statistics restarted (every pass emits `photons_per_pass`).
    fn photons_counted(&self) -> u64 {
        match self.setup.params.growth_pass() {
            Some(p) if self.pass > p => {
                self.n_emitted - u64::from(p) * u64::from(self.setup.params.photons_per_pass)
            }
            _ => self.n_emitted,
        }
    }

    /// Whether `slot` holds a visible point in the current pass.
    #[must_use]
    fn is_valid(&self, slot: usize) -> bool {
        self.photon_bounces[slot] != NO_VISIBLE_POINT
    }

    /// The hitpoint records, for the checkpoint codec.
    pub(crate) fn slots(&self) -> &HitPoints<SlotFrequency> {
        &self.slots
    }

    /// The photon-bounce budget of `slot`'s visible point, `None` without one.
    pub(crate) fn photon_budget(&self, slot: usize) -> Option<u16> {
        let budget = self.photon_bounces[slot];
        (budget != NO_VISIBLE_POINT).then_some(budget)
    }

    /// The directly seen emission of `slot`, summed over camera passes.
    pub(crate) fn direct(&self, slot: usize) -> [f64; 3] {
        self.direct[slot]
    }

    /// Camera passes so far.
    pub(crate) fn camera_passes(&self) -> u32 {
        self.camera_passes
    }

    /// Takes back the state of a checkpoint after `passes` passes. The caller checked that
    /// the columns have one entry per slot (or none, before the first pass) and that every
    /// budget is at most [`MAX_PHOTON_BUDGET`].
    pub(crate) fn restore(&mut self, passes: u32, state: SavedState) {
        self.pass = passes;
        self.n_emitted = state.n_emitted;
        self.camera_passes = state.camera_passes;
        self.slots = state.slots;
        self.photon_bounces = state
            .photon_budget
            .into_iter()
            .map(|b| b.unwrap_or(NO_VISIBLE_POINT))
            .collect();
        self.direct = state.direct;
    }

    /// The number of hitpoint slots of a full film.
    pub(crate) fn n_slots(&self) -> usize {
        self.setup.width as usize
            * self.setup.height as usize
            * self.setup.params.samples_per_pixel as usize
    }

    /// Heap memory by part (capacities of the buffers).
    #[must_use]
    pub(crate) fn memory(&self) -> MemoryUse {
        use std::mem::size_of;
        let (photon_buffers, hitpoint_buffers) = self.photons.heap_bytes();
        let (frequency_records, frequency_per_entry) = self.frequency.heap_bytes();
        MemoryUse {
            hitpoints: self.slots.len(),
            records: self.slots.heap_bytes(),
            slot_columns: self.photon_bounces.capacity() * size_of::<u16>()
                + self.direct.capacity() * size_of::<[f64; 3]>(),
            grid: self.index.heap_bytes(),
            pass_hitpoint_buffers: hitpoint_buffers + frequency_per_entry,
            pass_photon_buffers: photon_buffers + frequency_records,
        }
    }

    /// Runs one pass: camera pass (the first time, or every time for SPPM), hash grid,
    /// photon pass, hitpoint update.
    pub(crate) fn iterate(&mut self) -> PassStats {
        let mut stats = PassStats::empty(self.pass);
        let clock = Instant::now();
        let stochastic = self.setup.params.method.is_stochastic();
        let retrace = self.slots.is_empty() || stochastic;
        if self.setup.params.method.is_pass_independent() && self.independent.is_none() {
            let kernels = independent::pilot_kernels(self.setup.scene, self.setup.params);
            let pixels = self.setup.width as usize * self.setup.height as usize;
            self.set_independent(kernels, PassSums::new(pixels), self.pass);
        }
        stats.non_finite += self.camera_pass(retrace);
        self.schedule_radii();
        let grow = self.setup.params.growth_pass() == Some(self.pass);
        if grow {
            self.grow_kernels();
        }
        stats.camera_paths = self.slots.len() as u64;
        let camera = clock.elapsed().as_secs_f64();
        let photon_bounces = &self.photon_bounces;
        self.index.update(
            &self.slots,
            |slot| photon_bounces[slot] != NO_VISIBLE_POINT,
            !stochastic && !grow,
        );
        let index = clock.elapsed().as_secs_f64() - camera;
        self.photon_pass(&mut stats);
        let photons_done = clock.elapsed().as_secs_f64();
        if self.independent.is_some() {
            self.add_pass_image(&mut stats);
        } else {
            self.update_hitpoints(&mut stats);
        }
        let timings = &mut stats.timings;
        timings.camera = camera;
        timings.index = index;
        timings.gather = photons_done - camera - index - timings.trace;
        timings.update = clock.elapsed().as_secs_f64() - photons_done;
        self.pass += 1;
        stats
    }

    /// The current estimate: linear RGB radiance per pixel, row-major from the top-left,
    /// `width × height` entries.
    #[must_use]
    pub(crate) fn image(&self) -> Vec<[f32; 3]> {
        let spp = self.setup.params.samples_per_pixel as usize;
        let n_pixels = self.setup.width as usize * self.setup.height as usize;
        if let Some(sums) = self.pass_sums() {
            return sums.image();
        }
        let mut image = vec![[0.0f32; 3]; n_pixels];
        if self.slots.is_empty() {
            return image;
        }
        let radius = self.slots.radius();
        let count = self.slots.photon_count();
        let flux = self.slots.flux();
        let n_emitted = self.photons_counted() as f64;
        let camera_passes = f64::from(self.camera_passes.max(1));
        image.par_iter_mut().enumerate().for_each(|(pixel, out)| {
            let mut sum = [0.0f64; 3];
            for slot in pixel * spp..(pixel + 1) * spp {
                let stats = GatherStats {
                    radius: radius[slot],
                    photon_count: count[slot],
                    flux: flux[slot],
                };
                let photons = stats.radiance(n_emitted).unwrap_or([0.0; 3]);
                for c in 0..3 {
                    sum[c] += photons[c] + self.direct[slot][c] / camera_passes;
                }
            }
            *out = sum.map(|v| v as f32);
        });
        image
    }

    /// A per-slot quantity averaged over each pixel's valid slots: radius, photon count,
    /// frequency radius or whether the radius is held (`Aov::Radius`, `PhotonCount`,
    /// `FreqRadius`, `FreqHeld`); `None` for the frequency AOVs of a classical method.
    pub(crate) fn slot_aov(&self, aov: Aov) -> Option<Vec<f32>> {
        let params = &self.setup.params;
        if matches!(aov, Aov::FreqRadius | Aov::FreqHeld) && !params.method.uses_frequency() {
            return None;
        }
        let spp = params.samples_per_pixel as usize;
        let n_pixels = self.setup.width as usize * self.setup.height as usize;
        let slots = &self.slots;
        if slots.is_empty() {
            return Some(vec![0.0; n_pixels]);
        }
        let k = params.kernel_k;
        let aov = (0..n_pixels)
            .into_par_iter()
            .map(|pixel| {
                let (mut sum, mut n) = (0.0f64, 0u32);
                for slot in pixel * spp..(pixel + 1) * spp {
                    if !self.is_valid(slot) {
                        continue;
                    }
                    let freq = slots.freq()[slot];
                    let value = match aov {
                        Aov::Radius => Some(slots.radius()[slot]),
                        Aov::PhotonCount => Some(slots.photon_count()[slot]),
                        Aov::FreqRadius => freq.frequency_radius(k),
                        _ => Some(
                            freq.hold_radius(k, self.setup.kernel_max())
                                .map_or(0.0, |r| f64::from(u8::from(slots.radius()[slot] <= r))),
                        ),
                    };
                    if let Some(v) = value {
                        sum += v.min(f64::from(f32::MAX));
                        n += 1;
                    }
                }
                if n == 0 {
                    0.0
                } else {
                    (sum / f64::from(n)) as f32
                }
            })
            .collect();
        Some(aov)
    }
}
