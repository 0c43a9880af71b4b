//! The progressive photon mappers: PPM, SPPM and their frequency-guided variants.
//!
//! One pass is four phases, one file each:
//!
//! 1. `camera_pass.rs`: trace (the first pass, or every pass for SPPM) the visible points;
//! 2. `index.rs`: the hash grid over the hitpoint spheres;
//! 3. `photon_pass.rs`: trace photons in fixed chunks (`trace.rs`, one photon path) and gather
//!    them into the hitpoints;
//! 4. `update.rs`: fold the pass into R, N, τ, shrinking held slots by α_hold instead of α.
//!
//! `frequency/` holds the frequency extension, which those phases call into; `memory.rs` what
//! a render holds; `state.rs` what a checkpoint keeps of it. This file holds the state the
//! phases share, the pass that runs them ([`PhotonMapper::run_pass`], which the
//! pass-independent estimator of `crate::independent` runs with its own radii and image), and
//! the image.

mod camera_pass;
mod frequency;
mod index;
mod media;
mod memory;
mod photon_pass;
mod pool;
mod state;
#[cfg(test)]
mod tests;
mod trace;
mod update;
mod volume;

use std::sync::Arc;
use std::time::Instant;

use photon::HitPoints;
use rayon::prelude::*;
use scene::{Lobe, Scene};
use spectrum::Caps;

pub use self::memory::bytes_per_hitpoint;
pub(crate) use self::memory::estimate;
use self::photon_pass::PhotonPass;
use self::{frequency::FrequencyDeposits, frequency::SlotFrequency, index::Index};
use crate::aov::Aov;
use crate::checkpoint::codec::{Reader, StateError, Writer};
use crate::integrator::Integrator;
use crate::params::{Method, ParamError, RenderParams};
use crate::stats::{MemoryUse, PassStats};

/// Photons per parallel work item. Fixed (not derived from the thread count) so that the
/// reduction order, hence the image, does not depend on the number of threads.
const PHOTON_CHUNK: u64 = 2048;
/// Hitpoint slots per parallel work item of the camera pass.
const SLOT_CHUNK: usize = 1024;

/// What every phase reads and none changes: the scene, the parameters and what follows from
/// them.
struct Setup {
    scene: Arc<Scene>,
    params: RenderParams,
    caps: Caps,
    /// The initial gather radius R₀ (the largest kernel is [`Setup::kernel_max`]).
    kernel_scale: f64,
    width: u32,
    height: u32,
    /// The GGX α up to which camera paths pass through glossy surfaces (`glossy_continue`,
    /// where this render honours it; 0 otherwise): [`Setup::passes_through`].
    glossy_continue: f32,
}

/// The photon mappers' state: hitpoint slots with their statistics, the grid, the direct
/// emission seen by camera paths, and each phase's buffers.
pub(crate) struct PhotonMapper {
    setup: Setup,
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
    /// Per slot: the mean of its visible points' weights over the camera passes that placed
    /// them (zero for a pass without one). The photon radiance τ/(πR²N) is the mean over those
    /// passes of weight × irradiance, so this, not the last pass's weight, is what the pooling
    /// divides it by and multiplies it back with (`pool.rs`).
    mean_weight: Vec<glam::Vec3>,
    /// The camera passes that placed visible points (every pass for SPPM, the first for PPM).
    weight_passes: u32,
    /// Per slot: whether its visible point has ever moved to another surface from one camera
    /// pass to the next (`pool::same_surface`); such a slot is not pooled. Kept only by the
    /// renders that pool and move their visible points (empty otherwise).
    mixed: Vec<bool>,
    /// Phase 2's grid.
    index: Index,
    /// Phase 3's buffers, and M and Φ of the last pass for phase 4.
    photons: PhotonPass,
    /// The frequency deposits' buffers.
    frequency: FrequencyDeposits,
    /// Per 2 × 2 block of pixels, the clear disc its slots share ([`frequency::BlockDisc`]): a
    /// function of the scene, the parameters and the pass, recomputed where missing (after a
    /// restore), so that it is not part of a checkpoint.
    block_discs: Vec<Option<frequency::BlockDisc>>,
    /// The volume photons' gather, in a scene with media (`volume.rs`).
    volume: volume::Volume,
}

/// `photon_bounces` of a slot without a visible point (budgets are below `max_depth` ≤ 1024).
pub(crate) const NO_VISIBLE_POINT: u16 = u16::MAX;

/// The largest photon-bounce budget a slot can have.
const MAX_PHOTON_BUDGET: u16 = NO_VISIBLE_POINT - 1;

/// Whether a slot's photon-bounce budget says the camera sees its visible point directly (no
/// specular bounce before it), where a photon can be connected to the camera: the budget of a
/// direct hit is `max_depth` − 1.
pub(crate) fn seen_directly(budget: u16, max_depth: u32) -> bool {
    let direct = u16::try_from(max_depth - 1).unwrap_or(u16::MAX);
    budget != NO_VISIBLE_POINT && budget >= direct
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

impl Setup {
    /// Whether camera paths pass through `material` (a glossy lobe no rougher than
    /// `glossy_continue`) rather than leave a visible point on it; photons are then neither
    /// stored nor connected to the camera there.
    #[inline]
    fn passes_through(&self, material: &scene::Material) -> bool {
        self.glossy_continue > 0.0
            && matches!(material.kind.lobe(), Lobe::Ggx { alpha } if alpha <= self.glossy_continue)
    }
}

impl PhotonMapper {
    /// A renderer for `scene` with `params`; nothing is traced until the first pass.
    ///
    /// # Errors
    ///
    /// [`ParamError`] if a parameter is outside its domain or the film is too large.
    pub(crate) fn new(scene: Arc<Scene>, params: RenderParams) -> Result<Self, ParamError> {
        params.validate()?;
        let film = scene.description().film;
        let n_slots = u64::from(film.width)
            * u64::from(film.height)
            * u64::from(params.film.samples_per_pixel);
        if n_slots == 0 || n_slots > u64::from(u32::MAX) {
            return Err(ParamError::TooManyHitpoints {
                width: film.width,
                height: film.height,
                samples_per_pixel: params.film.samples_per_pixel,
            });
        }
        let bounds = scene.bounds();
        let scene_size = f64::from((bounds.max - bounds.min).length()).max(1e-6);
        let kernel_scale = params
            .kernel
            .initial_radius
            .unwrap_or_else(|| auto_initial_radius(&scene));
        // Only the methods that trace new camera paths every pass can pass through a glossy
        // lobe (a fixed visible point behind it would keep one direction of the lobe for
        // ever), and the light samples at those vertices do not render media.
        let glossy_continue =
            if matches!(params.method, Method::Sppm | Method::FreqSppm) && !scene.has_media() {
                params.connections.glossy_continue as f32
            } else {
                0.0
            };
        Ok(Self {
            setup: Setup {
                scene,
                params,
                caps: Caps::for_scene_size(scene_size),
                kernel_scale,
                width: film.width,
                height: film.height,
                glossy_continue,
            },
            pass: 0,
            n_emitted: 0,
            slots: HitPoints::with_capacity(0),
            photon_bounces: Vec::new(),
            direct: Vec::new(),
            camera_passes: 0,
            mean_weight: Vec::new(),
            weight_passes: 0,
            mixed: Vec::new(),
            index: Index::default(),
            photons: PhotonPass::default(),
            frequency: FrequencyDeposits::default(),
            block_discs: Vec::new(),
            volume: volume::Volume::default(),
        })
    }

    /// The scene being rendered.
    pub(crate) fn scene(&self) -> &Arc<Scene> {
        &self.setup.scene
    }

    /// The parameters this renderer runs with.
    pub(crate) fn params(&self) -> &RenderParams {
        &self.setup.params
    }

    /// Passes completed so far.
    pub(crate) fn passes(&self) -> u32 {
        self.pass
    }

    /// Photons emitted over all passes so far.
    pub(crate) fn photons_emitted(&self) -> u64 {
        self.n_emitted
    }

    /// Photons the statistics count: all that were emitted, less those of the pilot once the
    /// kernels were sized and the statistics restarted (every pass emits `photons_per_pass`).
    fn photons_counted(&self) -> u64 {
        match self.setup.params.growth_pass() {
            Some(p) if self.pass > p => {
                self.n_emitted - u64::from(p) * u64::from(self.setup.params.budget.photons_per_pass)
            }
            _ => self.n_emitted,
        }
    }

    /// Whether `slot` holds a visible point in the current pass.
    fn is_valid(&self, slot: usize) -> bool {
        self.photon_bounces[slot] != NO_VISIBLE_POINT
    }

    /// The number of hitpoint slots of a full film.
    pub(crate) fn n_slots(&self) -> usize {
        self.setup.width as usize
            * self.setup.height as usize
            * self.setup.params.film.samples_per_pixel as usize
    }

    /// Continues at pass `passes`, as if that many passes of `photons_per_pass` photons had
    /// run (a pass-independent render's next pass; its slots carry nothing between passes).
    pub(crate) fn start_at(&mut self, passes: u32) {
        self.pass = passes;
        self.n_emitted = u64::from(passes) * u64::from(self.setup.params.budget.photons_per_pass);
    }

    /// The initial gather radius R₀.
    pub(crate) fn initial_radius(&self) -> f64 {
        self.setup.kernel_scale
    }

    /// The slots' radii, to be set before the grid is built.
    pub(crate) fn radii_mut(&mut self) -> &mut [f64] {
        self.slots.columns_mut().radius
    }

    /// After a photon pass: each slot's radius, directly seen emission, photon-bounce budget
    /// ([`NO_VISIBLE_POINT`] without a visible point), and the pass's photon deposits.
    pub(crate) fn pass_columns(&self) -> (&[f64], &[[f64; 3]], &[u16], &PhotonPass) {
        (
            self.slots.radius(),
            &self.direct,
            &self.photon_bounces,
            &self.photons,
        )
    }

    /// Each visible point of the current pass that has a frequency prediction: its position
    /// and the radius its kernel may hold there (the frequency radius, bounded by the clear
    /// radius of its disc once probed), in slot order.
    pub(crate) fn frequency_predictions(&self) -> Vec<(glam::Vec3, f64)> {
        let k = self.setup.params.frequency.kernel_k;
        let r_top = self.setup.kernel_max();
        let (positions, freq) = (self.slots.position(), self.slots.freq());
        (0..self.slots.len())
            .filter(|&slot| self.is_valid(slot))
            .filter_map(|slot| {
                let r = freq[slot].hold_radius(k, r_top)?;
                (r.is_finite() && r > 0.0).then_some((positions[slot], r))
            })
            .collect()
    }

    /// Slot `slot`'s in-scattered radiance estimated by the last pass alone (weighted by
    /// 1/spp; zero in a scene without media).
    pub(crate) fn volume_of_pass(&self, slot: usize) -> [f64; 3] {
        self.volume.last.get(slot).copied().unwrap_or([0.0; 3])
    }

    /// Forgets the directly seen emission summed so far.
    pub(crate) fn clear_direct(&mut self) {
        for d in &mut self.direct {
            *d = [0.0; 3];
        }
    }

    /// Runs one pass: the camera pass (the first time, or every time for SPPM), then
    /// `before_grid` (which sets the radii a pass gathers with, and says whether it changed
    /// them), the hash grid, the photon pass, and `after_photons` (which folds the pass into
    /// the estimate).
    pub(crate) fn run_pass(
        &mut self,
        before_grid: impl FnOnce(&mut Self) -> bool,
        after_photons: impl FnOnce(&mut Self, &mut PassStats),
    ) -> PassStats {
        let mut stats = PassStats::empty(self.pass);
        let clock = Instant::now();
        let stochastic = self.setup.params.method.is_stochastic();
        let retrace = self.slots.is_empty() || stochastic;
        stats.non_finite += self.camera_pass(retrace);
        let radii_changed = before_grid(self);
        stats.camera_paths = self.slots.len() as u64;
        let camera = clock.elapsed().as_secs_f64();
        let photon_bounces = &self.photon_bounces;
        self.index.update(
            &self.slots,
            |slot| photon_bounces[slot] != NO_VISIBLE_POINT,
            !stochastic && !radii_changed,
        );
        let index = clock.elapsed().as_secs_f64() - camera;
        self.photon_pass(&mut stats);
        if self.setup.scene.has_media() {
            let volume_clock = Instant::now();
            stats.volume_photons = self
                .photons
                .traced
                .iter()
                .map(|t| t.volume.len() as u64)
                .sum();
            stats.non_finite += self.volume_gather();
            stats.timings.volume = volume_clock.elapsed().as_secs_f64();
        }
        let photons_done = clock.elapsed().as_secs_f64();
        after_photons(self, &mut stats);
        let timings = &mut stats.timings;
        timings.camera = camera;
        timings.index = index;
        timings.gather = photons_done - camera - index - timings.trace;
        timings.update = clock.elapsed().as_secs_f64() - photons_done;
        self.pass += 1;
        stats
    }

    /// Gathers the pass's volume photons into the camera paths' stretches through media;
    /// returns the contributions dropped for being NaN or infinite.
    fn volume_gather(&mut self) -> u64 {
        let setup = &self.setup;
        self.volume.gather_pass(
            &setup.scene,
            &self
                .photons
                .traced
                .iter()
                .map(|t| t.volume.as_slice())
                .collect::<Vec<_>>(),
            (
                setup.kernel_scale * setup.params.kernel.volume_radius,
                setup.params.kernel.alpha,
            ),
            self.pass,
            u64::from(setup.params.budget.photons_per_pass),
            setup.params.film.samples_per_pixel,
            self.n_slots(),
        )
    }

    /// A per-slot quantity averaged over each pixel's valid slots: radius, photon count,
    /// frequency radius, whether the radius is held or the pooling width (`Aov::Radius`,
    /// `PhotonCount`, `FreqRadius`, `FreqHeld`, `PoolWidth`); `None` for the frequency AOVs of
    /// a classical method.
    pub(crate) fn slot_aov(&self, aov: Aov) -> Option<Vec<f32>> {
        let params = &self.setup.params;
        if matches!(aov, Aov::FreqRadius | Aov::FreqHeld) && !params.method.uses_frequency() {
            return None;
        }
        let pool_width = (aov == Aov::PoolWidth && !self.slots.is_empty()).then(|| {
            let mut widths = vec![0.0f32; self.slots.len()];
            let per_row = self.setup.width as usize * params.film.samples_per_pixel as usize;
            self.pool_bands(&mut widths, per_row, |_, out, _, width| {
                out.copy_from_slice(width);
            });
            widths
        });
        let spp = params.film.samples_per_pixel as usize;
        let n_pixels = self.setup.width as usize * self.setup.height as usize;
        let slots = &self.slots;
        if slots.is_empty() {
            return Some(vec![0.0; n_pixels]);
        }
        let k = params.frequency.kernel_k;
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
                        Aov::PoolWidth => pool_width.as_ref().map(|w| f64::from(w[slot])),
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

impl Integrator for PhotonMapper {
    fn params(&self) -> &RenderParams {
        &self.setup.params
    }

    fn passes(&self) -> u32 {
        self.pass
    }

    fn photons_emitted(&self) -> u64 {
        self.n_emitted
    }

    /// A progressive pass: after the camera pass a frequency method may grow its kernels
    /// (once, after its pilot), and after the photons every slot folds the pass into R, N, τ.
    fn iterate(&mut self) -> PassStats {
        self.run_pass(
            |m| {
                let grow = m.setup.params.growth_pass() == Some(m.pass);
                if grow {
                    m.grow_kernels();
                }
                grow
            },
            Self::update_hitpoints,
        )
    }

    /// The current estimate: linear RGB radiance per pixel, row-major from the top-left,
    /// `width × height` entries.
    fn image(&self) -> Vec<[f32; 3]> {
        let spp = self.setup.params.film.samples_per_pixel as usize;
        let n_pixels = self.setup.width as usize * self.setup.height as usize;
        let mut image = vec![[0.0f32; 3]; n_pixels];
        if self.slots.is_empty() {
            return image;
        }
        // Times a reciprocal: three f64 quotients a pixel were a tenth of a pooled read-out.
        let per_camera_pass = 1.0 / f64::from(self.camera_passes.max(1));
        let width = self.setup.width as usize;
        let has_media = self.setup.scene.has_media();
        // Band by band, each pixel's slots summed in f64: the image is the only image-sized
        // buffer a read-out writes.
        self.pool_bands(&mut image, width, |first_slot, band, photons, _| {
            let direct = &self.direct[first_slot..];
            for (pixel, out) in band.iter_mut().enumerate() {
                let slots = pixel * spp..(pixel + 1) * spp;
                let mut sum = [0.0f64; 3];
                for (photons, direct) in photons[slots.clone()].iter().zip(&direct[slots.clone()]) {
                    for c in 0..3 {
                        sum[c] += photons[c] + direct[c] * per_camera_pass;
                    }
                }
                if has_media {
                    for slot in slots {
                        let volume = self.volume.radiance(first_slot + slot);
                        for c in 0..3 {
                            sum[c] += volume[c];
                        }
                    }
                }
                *out = sum.map(|v| v as f32);
            }
        });
        image
    }

    fn aov(&self, aov: Aov) -> Option<Vec<f32>> {
        self.slot_aov(aov)
    }

    fn memory(&self) -> Option<MemoryUse> {
        Some(PhotonMapper::memory(self))
    }

    fn save(&self, w: &mut Writer) {
        self.write_state(w);
    }

    fn saved_bound(&self) -> usize {
        state::bound(self.n_slots())
    }

    fn restore(&mut self, r: &mut Reader<'_>, passes: u32) -> Result<(), StateError> {
        self.read_state(r, passes)
    }
}
