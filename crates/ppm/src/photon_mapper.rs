//! The progressive loop shared by PPM, SPPM and their frequency-guided variants.
//!
//! One pass = four phases, each a private function that can be tested alone:
//! `camera_pass` (trace or re-trace the visible points), `build_index` (hash grid over the
//! hitpoint spheres), `photon_pass` (trace photons in fixed chunks, collect deposits) and
//! `update_hitpoints` (fold the deposits into R, N, τ with the keep-or-shrink rule).

use geometry::{
    Bsdf, EmitterShape, Hit, Lobe as MaterialLobe, MaterialKind, Ray, Rgb, Scene, TransportMode,
};
use glam::{Vec2, Vec3};
use photon::{
    AcceptParams, GatherScratch, GridParams, HitPointGrid, HitPoints, MortonScratch, NewHitPoint,
    Photon,
};
use std::time::Instant;

use rayon::prelude::*;
use spectrum::{Caps, FrequencyEstimate, Lobe, Spectrum};

use crate::params::{ParamError, RenderParams};
use crate::rng::Sampler;
use crate::update::{FrequencyRadius, GatherStats};

/// Photons per parallel work item. Fixed (not derived from the thread count) so that the
/// reduction order, hence the image, does not depend on the number of threads.
const PHOTON_CHUNK: u64 = 2048;
/// Hitpoint slots per parallel work item of the camera pass.
const SLOT_CHUNK: usize = 1024;
/// Camera streams live in their own half of the sampler's index space.
const CAMERA_STREAM: u64 = 1 << 63;
/// Share of an occlusion probe, at its far end, where blockers are ignored.
const CONTACT_FRACTION: f32 = 0.05;
/// Extra probes that locate a shadow edge found by the occlusion probe.
const OCCLUSION_BISECTIONS: u32 = 4;
/// Path depth from which Russian roulette may end a photon path.
const ROULETTE_DEPTH: u32 = 3;

/// Per-pass statistics returned by [`crate::Renderer::iterate`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PassStats {
    /// Index of the pass just finished (0-based).
    pub pass: u32,
    /// Camera paths traced in this pass (hitpoint slots for the photon mappers, which re-trace
    /// them every pass for SPPM and once for PPM; paths for the path tracer).
    pub camera_paths: u64,
    /// Photon paths started in this pass.
    pub photons_traced: u64,
    /// Of which frequency photons.
    pub frequency_photons: u64,
    /// Photon-hitpoint contributions accepted in this pass.
    pub photons_deposited: u64,
    /// Hitpoint slots that received at least one photon in this pass.
    pub hitpoints_hit: u64,
    /// Hitpoint slots with a visible point this pass.
    pub hitpoints_valid: u64,
    /// Mean gather radius over valid slots after the update.
    pub mean_radius: f64,
    /// Smallest gather radius over valid slots.
    pub min_radius: f64,
    /// Largest gather radius over valid slots.
    pub max_radius: f64,
    /// Share of valid slots whose radius is held by the frequency floor (R ≤ r_freq).
    pub frequency_held: f64,
    /// Photons stored on non-specular surfaces this pass: the gather queries.
    pub photons_stored: u64,
    /// Wall-clock time of each phase (the only field that differs between identical runs).
    pub timings: PassTimings,
}

/// Wall-clock seconds spent in each phase of a pass.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PassTimings {
    /// Camera paths (visible points, directly seen emission).
    pub camera: f64,
    /// Building or refreshing the hash grid.
    pub index: f64,
    /// Tracing photon paths (including the frequency bookkeeping and occlusion probes).
    pub trace: f64,
    /// Sorting and gathering photons into hitpoints, and the frequency deposits.
    pub gather: f64,
    /// Folding the pass into the hitpoint statistics.
    pub update: f64,
    /// The frequency bookkeeping inside `gather` and `update` (already counted there, not a
    /// phase of its own): folding the frequency photons' deposits from the flux gather's pairs,
    /// merging them into the slots, and the clear-disc probes (and, for passes too large to pack
    /// tags, tagging the photons). Zero for methods without frequency photons.
    /// The rest of the bookkeeping, spectra and occlusion probes along photon paths, is inside
    /// `trace`.
    pub frequency: f64,
}

impl PassTimings {
    /// The whole pass.
    #[must_use]
    pub fn total(&self) -> f64 {
        self.camera + self.index + self.trace + self.gather + self.update
    }
}

/// Frequency state of one hitpoint slot: the merged estimate plus what a deposit needs to
/// turn a photon's spectrum into the field seen by the camera.
///
/// 32 bytes: the merged spectrum's (a, b, c) and its flags are packed beside the distance (a
/// `FrequencyEstimate`, 32 bytes with its padding, next to an `f32` would take 40). The
/// estimate is stored bit for bit ([`Spectrum::to_bits`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct SlotFrequency {
    /// Bits of a, b, c of the merged spectrum; zero while `merged` is [`Self::EMPTY`].
    coefficients: [u64; 3],
    /// Distance to the camera (or last specular vertex) projected on the normal, z of §8.2.
    pub(crate) normal_distance: f32,
    /// [`Self::EMPTY`] until a frequency photon was merged, then 1 + the Lambertian flag.
    merged: u8,
    /// The clear radius of the gather disc at this visible point as a level of
    /// [`crate::disc::clear_level`] (the radius R₀·2^−level, none at `disc::LEVELS`), or
    /// [`GEOMETRY_UNKNOWN`] until it is probed: when the slot first becomes a candidate for
    /// holding, again after every new visible point.
    pub(crate) clear_level: u8,
}

/// [`SlotFrequency::clear_level`] before the probes ran.
pub(crate) const GEOMETRY_UNKNOWN: u8 = u8::MAX;

impl SlotFrequency {
    /// No frequency photon merged yet.
    const EMPTY: u8 = 0;

    /// The state holding `estimate` at `normal_distance`.
    pub(crate) fn new(estimate: FrequencyEstimate, normal_distance: f32) -> Self {
        let mut freq = Self {
            coefficients: [0; 3],
            normal_distance,
            merged: Self::EMPTY,
            clear_level: GEOMETRY_UNKNOWN,
        };
        freq.set_estimate(estimate);
        freq
    }

    /// The merged estimate.
    pub(crate) fn estimate(&self) -> FrequencyEstimate {
        if self.merged == Self::EMPTY {
            return FrequencyEstimate::EMPTY;
        }
        let [a, b, c] = self.coefficients;
        let spectrum = Spectrum::from_bits([a, b, c, u64::from(self.merged - 1)])
            .expect("the bits of a valid spectrum, stored by set_estimate");
        FrequencyEstimate::from_spectrum(Some(spectrum))
    }

    /// Replaces the merged estimate.
    pub(crate) fn set_estimate(&mut self, estimate: FrequencyEstimate) {
        match estimate.spectrum() {
            None => {
                self.coefficients = [0; 3];
                self.merged = Self::EMPTY;
            }
            Some(spectrum) => {
                let [a, b, c, lambertian] = spectrum.to_bits();
                self.coefficients = [a, b, c];
                // `to_bits` encodes the flag as 0 or 1.
                self.merged = 1 + u8::from(lambertian != 0);
            }
        }
    }

    /// The radius below which the slot holds its kernel: the frequency radius r_freq of its
    /// merged deposits (`None` before the first), bounded by the clear radius of its disc
    /// (levels of `r0`, the initial radius) once probed.
    pub(crate) fn hold_radius(&self, k: f64, r0: f64) -> Option<f64> {
        let r_freq = self.estimate().radius(f64::from(self.normal_distance), k)?;
        Some(if self.clear_level == GEOMETRY_UNKNOWN {
            r_freq
        } else {
            r_freq.min(crate::disc::level_radius(self.clear_level, r0))
        })
    }
}

/// The photon mappers' state: hitpoint slots with their statistics, the grid, the direct
/// emission seen by camera paths.
pub(crate) struct PhotonMapper<'s> {
    pub(crate) scene: &'s Scene,
    pub(crate) params: RenderParams,
    pub(crate) caps: Caps,
    /// The initial gather radius: the scale of the occlusion probe.
    pub(crate) kernel_scale: f64,
    pub(crate) width: u32,
    pub(crate) height: u32,
    pub(crate) pass: u32,
    pub(crate) n_emitted: u64,
    pub(crate) slots: HitPoints<SlotFrequency>,
    /// Per slot: the most bounces a photon may have made and still count there,
    /// `max_depth − 1 − (specular bounces of the camera path)`, so that no light path has more
    /// than `max_depth` scattering events (the hitpoint's own scattering is the 1); or
    /// [`NO_VISIBLE_POINT`] if the slot holds no visible point in the current pass.
    pub(crate) photon_bounces: Vec<u16>,
    /// Per slot: sum of directly seen emission (and direct lighting) over camera passes.
    pub(crate) direct: Vec<[f64; 3]>,
    pub(crate) camera_passes: u32,
    pub(crate) grid: Option<HitPointGrid>,
    /// Slot index of each grid entry (the grid indexes the valid slots only, in the Morton
    /// order of their positions, so that the gather of Morton-sorted photons touches nearby
    /// entries).
    pub(crate) grid_slots: Vec<u32>,
    /// Buffers of the photon pass, kept across passes (not part of the render state).
    scratch: PhotonScratch,
}

/// `photon_bounces` of a slot without a visible point (budgets are below `max_depth` ≤ 1024).
pub(crate) const NO_VISIBLE_POINT: u16 = u16::MAX;

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

/// Heap memory of a render, in bytes, by part ([`crate::Renderer::memory`]): allocated
/// capacities, so what the process holds between passes, not a lower bound.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct MemoryUse {
    /// Hitpoint slots (the divisor of the per-hitpoint figures).
    pub hitpoints: usize,
    /// The hitpoint records: geometry, R, N, τ and the frequency state (`photon::HitPoints`).
    pub records: usize,
    /// The renderer's other per-slot columns: photon-bounce budget and direct-emission sum.
    pub slot_columns: usize,
    /// The hash grid (`photon::GridStats::bytes`) and the slot of each of its entries.
    pub grid: usize,
    /// Per-pass buffers sized by the hitpoints: the M, Φ and frequency accumulators of a pass.
    pub pass_hitpoint_buffers: usize,
    /// Per-pass buffers sized by the photons: traced photons, their Morton-sorted copies and
    /// keys, the gather bins. They scale with the photons per pass, not with the hitpoints.
    pub pass_photon_buffers: usize,
}

impl MemoryUse {
    /// The state a render keeps per hitpoint from pass to pass: records, columns and grid.
    #[must_use]
    pub fn persistent(&self) -> usize {
        self.records + self.slot_columns + self.grid
    }

    /// Everything.
    #[must_use]
    pub fn total(&self) -> usize {
        self.persistent() + self.pass_hitpoint_buffers + self.pass_photon_buffers
    }
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
            scene,
            params,
            caps: Caps::for_scene_size(scene_size),
            kernel_scale: params
                .initial_radius
                .unwrap_or_else(|| auto_initial_radius(scene)),
            width: film.width,
            height: film.height,
            pass: 0,
            n_emitted: 0,
            slots: HitPoints::with_capacity(0),
            photon_bounces: Vec::new(),
            direct: Vec::new(),
            camera_passes: 0,
            grid: None,
            grid_slots: Vec::new(),
            scratch: PhotonScratch::default(),
        })
    }

    /// The parameters this renderer runs with.
    #[must_use]
    pub(crate) fn params(&self) -> &RenderParams {
        &self.params
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

    /// Whether `slot` holds a visible point in the current pass.
    #[must_use]
    pub(crate) fn is_valid(&self, slot: usize) -> bool {
        self.photon_bounces[slot] != NO_VISIBLE_POINT
    }

    /// Heap memory by part (capacities of the buffers).
    #[must_use]
    pub(crate) fn memory(&self) -> MemoryUse {
        use std::mem::size_of;
        let s = &self.scratch;
        let traced: usize = s
            .traced
            .iter()
            .map(|t| {
                t.photons.capacity() * size_of::<Photon>()
                    + t.frequency.capacity() * size_of::<FrequencyPhoton>()
            })
            .sum::<usize>()
            + s.traced.capacity() * size_of::<TracedPhotons>();
        MemoryUse {
            hitpoints: self.slots.len(),
            records: self.slots.heap_bytes(),
            slot_columns: self.photon_bounces.capacity() * size_of::<u16>()
                + self.direct.capacity() * size_of::<[f64; 3]>(),
            grid: self.grid.as_ref().map_or(0, |g| g.stats().bytes)
                + self.grid_slots.capacity() * size_of::<u32>(),
            pass_hitpoint_buffers: s.per_entry.capacity() * size_of::<(u32, [f64; 3])>()
                + s.frequency_per_entry.capacity() * size_of::<FrequencyEstimate>()
                + s.slot_entry.capacity() * size_of::<u32>(),
            pass_photon_buffers: traced
                + s.frequency.capacity() * size_of::<FrequencyPhoton>()
                + s.sorted.capacity() * size_of::<Photon>()
                + s.keys.heap_bytes()
                + s.gather.heap_bytes()
                + s.tagged_gather.heap_bytes(),
        }
    }

    /// Runs one pass: camera pass (the first time, or every time for SPPM), hash grid,
    /// photon pass, hitpoint update.
    pub(crate) fn iterate(&mut self) -> PassStats {
        let clock = Instant::now();
        let retrace = self.slots.is_empty() || self.params.method.is_stochastic();
        self.camera_pass(retrace);
        let camera_paths = self.slots.len() as u64;
        let camera = clock.elapsed().as_secs_f64();
        self.build_index();
        let index = clock.elapsed().as_secs_f64() - camera;
        let deposits = self.photon_pass();
        let photons_done = clock.elapsed().as_secs_f64();
        let mut stats = self.update_hitpoints(&deposits);
        stats.camera_paths = camera_paths;
        stats.photons_stored = deposits.photons_stored;
        let trace_seconds = deposits.trace_seconds;
        // Hand the accumulators back for the next pass.
        self.scratch.per_entry = deposits.per_entry;
        self.scratch.slot_entry = deposits.slot_entry;
        stats.timings = PassTimings {
            camera,
            index,
            trace: trace_seconds,
            gather: photons_done - camera - index - trace_seconds,
            update: clock.elapsed().as_secs_f64() - photons_done,
            frequency: stats.timings.frequency + deposits.frequency_seconds,
        };
        self.pass += 1;
        stats
    }

    /// The current estimate: linear RGB radiance per pixel, row-major from the top-left,
    /// `width × height` entries.
    #[must_use]
    pub(crate) fn image(&self) -> Vec<[f32; 3]> {
        let spp = self.params.samples_per_pixel as usize;
        let n_pixels = self.width as usize * self.height as usize;
        let mut image = vec![[0.0f32; 3]; n_pixels];
        if self.slots.is_empty() {
            return image;
        }
        let radius = self.slots.radius();
        let count = self.slots.photon_count();
        let flux = self.slots.flux();
        let n_emitted = self.n_emitted as f64;
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

    // ------------------------------------------------------------------------------------
    // Phase 1: camera pass.

    /// Traces one camera path per slot with this pass's jitter. The emission they see
    /// directly (and the direct lighting, if enabled) is always accumulated, so that emitters
    /// seen through a pixel are antialiased progressively even by PPM; the visible points
    /// replace the slots' only when `update_hitpoints` (the first pass, and every SPPM pass):
    /// otherwise only the emission sums are updated, in place.
    fn camera_pass(&mut self, update_hitpoints: bool) {
        let spp = self.params.samples_per_pixel;
        let n_slots = self.width as usize * self.height as usize * spp as usize;
        let initial_radius = self.kernel_scale;
        let first = self.slots.is_empty();
        let pass = self.pass;
        if !update_hitpoints && !first {
            // Only the directly seen emission changes: accumulate it in place, in parallel.
            let mut direct = std::mem::take(&mut self.direct);
            direct
                .par_iter_mut()
                .enumerate()
                .with_min_len(SLOT_CHUNK)
                .for_each(|(slot, sum)| {
                    let sample = self.trace_camera_path(slot as u32, pass);
                    for (c, sum) in sum.iter_mut().enumerate() {
                        *sum += f64::from(sample.direct[c]);
                    }
                });
            self.direct = direct;
            self.camera_passes += 1;
            return;
        }
        let traced: Vec<CameraSample> = (0..n_slots)
            .into_par_iter()
            .with_min_len(SLOT_CHUNK)
            .map(|slot| self.trace_camera_path(slot as u32, pass))
            .collect();
        if first {
            self.slots = HitPoints::with_capacity(n_slots);
            self.direct = vec![[0.0; 3]; n_slots];
            self.photon_bounces = vec![NO_VISIBLE_POINT; n_slots];
        }
        for (slot, sample) in traced.into_iter().enumerate() {
            for c in 0..3 {
                self.direct[slot][c] += f64::from(sample.direct[c]);
            }
            let point = sample.visible.unwrap_or(VisiblePoint {
                position: Vec3::ZERO,
                shading_normal: Vec3::Z,
                geometric_normal: Vec3::Z,
                outgoing: Vec3::Z,
                material: 0,
                weight: Vec3::ZERO,
                normal_distance: 0.0,
                bounces: 0,
            });
            // Visible points have bounces < max_depth ≤ 1024 (`trace_camera_path`).
            let budget = (self.params.max_depth - 1).saturating_sub(point.bounces);
            self.photon_bounces[slot] = match sample.visible {
                Some(_) => u16::try_from(budget).unwrap_or(NO_VISIBLE_POINT - 1),
                None => NO_VISIBLE_POINT,
            };
            let freq = SlotFrequency::new(FrequencyEstimate::EMPTY, point.normal_distance);
            let new = NewHitPoint {
                position: point.position,
                shading_normal: point.shading_normal,
                geometric_normal: point.geometric_normal,
                outgoing: point.outgoing,
                material_idx: point.material,
                weight: point.weight,
                radius: initial_radius,
                freq,
            };
            if first {
                self.slots.push(new);
            } else {
                self.slots.replace_visible_point(slot, &new);
                let slot_freq = &mut self.slots.columns_mut().freq[slot];
                slot_freq.normal_distance = point.normal_distance;
                slot_freq.clear_level = GEOMETRY_UNKNOWN;
            }
        }
        self.camera_passes += 1;
    }

    fn trace_camera_path(&self, slot: u32, pass: u32) -> CameraSample {
        let weight_scale = 1.0 / self.params.samples_per_pixel as f32;
        let chain = self.camera_chain(slot, pass);
        let mut direct = chain.direct;
        let visible = chain.end.map(|mut end| {
            let hit = &end.hit;
            if self.params.direct_lighting
                && let Some(bsdf) = self.scene.bsdf(hit)
            {
                direct += end.throughput
                    * self.direct_lighting(hit, &bsdf, end.outgoing, &mut end.sampler);
            }
            let mu = end.outgoing.dot(hit.shading_normal).abs();
            VisiblePoint {
                position: hit.position,
                shading_normal: hit.shading_normal,
                geometric_normal: hit.geometric_normal,
                outgoing: end.outgoing,
                material: hit.material,
                weight: end.throughput * weight_scale,
                normal_distance: hit.t * mu,
                bounces: end.bounces,
            }
        });
        CameraSample {
            direct: direct * weight_scale,
            visible,
        }
    }

    /// The camera path of `slot` in `pass` through specular bounces to its first non-specular
    /// hit, with the emission it sees on the way (unweighted by 1/spp).
    pub(crate) fn camera_chain(&self, slot: u32, pass: u32) -> CameraChain {
        let spp = self.params.samples_per_pixel;
        let pixel = slot / spp;
        let (x, y) = (pixel % self.width, pixel / self.width);
        let mut sampler = Sampler::new(self.params.seed, pass, CAMERA_STREAM | u64::from(slot));
        let film = Vec2::new(x as f32, y as f32) + sampler.next_2d();
        let mut ray = self.scene.camera().generate_ray(film, sampler.next_2d());
        let mut throughput = Rgb::ONE;
        let mut direct = Rgb::ZERO;
        // `bounces`: scattering events of the camera path before this hit. Emission seen here
        // ends a light path with that many; a hitpoint adds one (its own scattering) to the
        // photon's, so it needs bounces < max_depth.
        for bounces in 0..=self.params.max_depth {
            let Some(hit) = self.scene.intersect(&ray) else {
                break;
            };
            direct += throughput * self.scene.emitted(&hit);
            if bounces == self.params.max_depth {
                break;
            }
            let Some(material) = self.scene.material(hit.material) else {
                break;
            };
            let bsdf = Bsdf::new(material, &hit);
            let outgoing = -ray.direction;
            if bsdf.is_specular() {
                let u_lobe = sampler.next_f32();
                let u = sampler.next_2d();
                let Some(sample) = bsdf.sample(outgoing, u_lobe, u, TransportMode::Radiance) else {
                    break;
                };
                throughput *= sample.weight;
                if throughput == Rgb::ZERO {
                    break;
                }
                ray = hit.spawn_ray(sample.incoming);
                continue;
            }
            return CameraChain {
                direct,
                end: Some(ChainEnd {
                    hit,
                    outgoing,
                    throughput,
                    bounces,
                    sampler,
                }),
            };
        }
        CameraChain { direct, end: None }
    }

    /// One light sample of next-event estimation at a non-specular camera hit.
    fn direct_lighting(
        &self,
        hit: &Hit,
        bsdf: &Bsdf,
        outgoing: Vec3,
        sampler: &mut Sampler,
    ) -> Rgb {
        let u_light = sampler.next_f32();
        let u = sampler.next_2d();
        let Some(sample) = self.scene.lights().sample_direct(hit.position, u_light, u) else {
            return Rgb::ZERO;
        };
        if sample.pdf <= 0.0 || !self.scene.light_visible(hit, &sample) {
            return Rgb::ZERO;
        }
        let cos = sample.incoming.dot(hit.shading_normal).abs();
        bsdf.eval(outgoing, sample.incoming) * sample.radiance * (cos / sample.pdf)
    }

    // ------------------------------------------------------------------------------------
    // Phase 2: spatial index.

    fn build_index(&mut self) {
        let radii = self.grid_radii();
        let keep = !self.params.method.is_stochastic()
            && match self.grid.as_mut() {
                None => false,
                Some(grid) => grid.refresh_radii(&radii) && !grid.needs_rebuild(&radii),
            };
        if keep {
            return;
        }
        let valid: Vec<u32> = (0..self.slots.len() as u32)
            .filter(|&s| self.is_valid(s as usize))
            .collect();
        let positions: Vec<Vec3> = valid
            .iter()
            .map(|&s| self.slots.position()[s as usize])
            .collect();
        self.grid_slots = photon::morton_order(&positions)
            .into_iter()
            .map(|i| valid[i as usize])
            .collect();
        let positions: Vec<Vec3> = self
            .grid_slots
            .iter()
            .map(|&s| self.slots.position()[s as usize])
            .collect();
        let radii = self.grid_radii();
        self.grid = Some(HitPointGrid::build(&positions, &radii, GridParams::DEFAULT));
    }

    /// Current radius of each grid entry.
    fn grid_radii(&self) -> Vec<f64> {
        self.grid_slots
            .iter()
            .map(|&s| self.slots.radius()[s as usize])
            .collect()
    }

    // ------------------------------------------------------------------------------------
    // Phase 3: photon pass.

    /// Traces this pass's photons (in parallel, fixed chunks), then gathers them into the
    /// hitpoints in Morton order with `photon::gather`, which sums every hitpoint's
    /// contributions in photon order whatever the thread count.
    fn photon_pass(&mut self) -> PassDeposits {
        let n = u64::from(self.params.photons_per_pass);
        let first_index = self.n_emitted;
        let clock = Instant::now();
        let mut scratch = std::mem::take(&mut self.scratch);
        let n_chunks = usize::try_from(n.div_ceil(PHOTON_CHUNK)).unwrap_or(usize::MAX);
        scratch.traced.resize_with(n_chunks, TracedPhotons::default);
        let layout = TagLayout::new(n_chunks, self.params.max_depth);
        #[cfg(test)]
        let layout = if scratch.force_global_tags {
            TagLayout::Global
        } else {
            layout
        };
        scratch
            .traced
            .par_iter_mut()
            .enumerate()
            .for_each(|(chunk, out)| {
                out.clear();
                let start = chunk as u64 * PHOTON_CHUNK;
                let end = (start + PHOTON_CHUNK).min(n);
                let tag_base = layout.chunk_base(chunk);
                for idx in start..end {
                    self.trace_photon(first_index + idx, tag_base, out);
                }
            });
        self.n_emitted += n;
        let frequency_photons = scratch.traced.iter().map(|c| c.frequency_photons).sum();
        let trace_seconds = clock.elapsed().as_secs_f64();
        let uses_frequency = self.params.method.uses_frequency();
        let frequency_clock = Instant::now();
        if uses_frequency && layout == TagLayout::Global {
            tag_frequency_photons(&mut scratch.traced, &mut scratch.frequency);
        }
        let mut frequency_seconds = frequency_clock.elapsed().as_secs_f64();
        let n_slots = self.slots.len();
        let mut deposits = PassDeposits {
            per_entry: Vec::new(),
            slot_entry: std::mem::take(&mut scratch.slot_entry),
            photons_deposited: 0,
            hitpoints_hit: 0,
            frequency_photons,
            photons_stored: 0,
            trace_seconds,
            frequency_seconds,
        };
        // Slot → grid entry (`NOT_IN_GRID` for slots the grid does not index).
        deposits.slot_entry.clear();
        deposits.slot_entry.resize(n_slots, NOT_IN_GRID);
        for (entry, &slot) in self.grid_slots.iter().enumerate() {
            deposits.slot_entry[slot as usize] = entry as u32;
        }
        let Some(grid) = &self.grid else {
            self.scratch = scratch;
            return deposits;
        };
        // Morton order (of the photons' positions, ties in trace order).
        photon::morton_sort(
            &scratch.traced,
            |p: &Photon| p.position,
            &mut scratch.keys,
            &mut scratch.sorted,
        );

        let slots = &self.slots;
        let grid_slots = &self.grid_slots;
        let flux = |photon: &Photon, entry: u32| {
            let slot = grid_slots[entry as usize] as usize;
            self.accepts(photon, slot).then(|| {
                let material = self.scene.material(slots.material_idx()[slot])?;
                let (normal, outgoing) = (slots.shading_normal()[slot], slots.outgoing()[slot]);
                let f = match material.kind {
                    // `Bsdf::eval` of a Lambertian without building the shading frame: the
                    // same hemisphere test on the same dot products (the frame's z is the
                    // normal), the same value.
                    MaterialKind::Diffuse { albedo } => {
                        if outgoing.dot(normal) * photon.incoming.dot(normal) <= 0.0 {
                            Rgb::ZERO
                        } else {
                            albedo * std::f32::consts::FRAC_1_PI
                        }
                    }
                    kind => Bsdf::from_normal(kind, normal, true).eval(outgoing, photon.incoming),
                };
                Some(f * photon.power * slots.weight()[slot])
            })?
        };
        let add = |acc: &mut (u32, [f64; 3]), flux: Rgb| {
            acc.0 += 1;
            acc.1[0] += f64::from(flux.x);
            acc.1[1] += f64::from(flux.y);
            acc.1[2] += f64::from(flux.z);
        };
        if uses_frequency {
            // The flux pairs carry the photon's tag, for the frequency deposits below.
            photon::gather_with(
                &mut scratch.tagged_gather,
                grid,
                &scratch.sorted,
                &mut scratch.per_entry,
                grid_slots.len(),
                |photon, entry| flux(photon, entry).map(|f| (f, photon.tag)),
                |acc, (f, _)| add(acc, f),
            );
        } else {
            photon::gather_with(
                &mut scratch.gather,
                grid,
                &scratch.sorted,
                &mut scratch.per_entry,
                grid_slots.len(),
                flux,
                add,
            );
        }
        deposits.photons_stored = scratch.sorted.len() as u64;
        for &(m, _) in &scratch.per_entry {
            deposits.photons_deposited += u64::from(m);
            deposits.hitpoints_hit += u64::from(m > 0);
        }
        deposits.per_entry = std::mem::take(&mut scratch.per_entry);
        if !uses_frequency {
            self.scratch = scratch;
            return deposits;
        }

        // Frequency deposits: a frequency photon counts for exactly the hitpoints its flux
        // counts for, so they ride the flux gather: its pairs carry the photon's tag, and each
        // grid entry merges the fields of its tagged pairs, in photon order (the merges, a min
        // or max per coefficient, do not depend on the order anyway). Then each slot merges its
        // entry's estimate. (Before, the frequency photons had their own Morton sort of
        // 128-byte records and their own grid queries; with the merge and the clear-disc
        // probes, the frequency phase of a 2-thread pass of a million photons took 0.036–0.055 s,
        // now 0.026–0.040 s. See docs/performance.md.)
        let frequency_clock = Instant::now();
        let policy = self.params.freq_merge;
        let (traced, concatenated) = (&scratch.traced, &scratch.frequency);
        let record = |tag: u32| match layout {
            TagLayout::Packed { local_bits } => {
                &traced[(tag >> local_bits) as usize].frequency
                    [(tag & ((1 << local_bits) - 1)) as usize]
            }
            TagLayout::Global => &concatenated[tag as usize],
        };
        photon::accumulate_again(
            &scratch.tagged_gather,
            &mut scratch.frequency_per_entry,
            |acc: &mut FrequencyEstimate, entry, (_, tag)| {
                if tag == UNTAGGED {
                    return;
                }
                let slot = grid_slots[entry as usize] as usize;
                if let Some(material) = self.scene.material(slots.material_idx()[slot]) {
                    let field = record(tag).field(material.kind.lobe(), &self.caps);
                    acc.deposit(field, policy);
                }
            },
        );
        let per_entry = &scratch.frequency_per_entry;
        let slot_entry = &deposits.slot_entry;
        self.slots
            .columns_mut()
            .freq
            .par_iter_mut()
            .with_min_len(SLOT_CHUNK)
            .enumerate()
            .for_each(|(slot, freq)| {
                let entry = slot_entry[slot];
                if entry == NOT_IN_GRID {
                    return;
                }
                if let Some(spectrum) = per_entry[entry as usize].spectrum() {
                    let mut merged = freq.estimate();
                    merged.deposit(spectrum, policy);
                    freq.set_estimate(merged);
                }
            });
        frequency_seconds += frequency_clock.elapsed().as_secs_f64();
        deposits.frequency_seconds = frequency_seconds;
        self.scratch = scratch;
        deposits
    }

    /// Whether `photon`, which the grid reported for `slot` (so it lies within the slot's
    /// radius: the grid's test is exactly that of `photon::accepts`), counts for it: the light
    /// path they make has at most `max_depth` bounces, and the photon is on the hitpoint's
    /// side, with agreeing normals (see `photon::faces`).
    fn accepts(&self, photon: &Photon, slot: usize) -> bool {
        photon.bounces <= u32::from(self.photon_bounces[slot])
            && photon::faces(
                photon,
                self.slots.geometric_normal()[slot],
                AcceptParams::COS_60,
            )
    }

    fn is_frequency_photon(&self, index: u64) -> bool {
        if !self.params.method.uses_frequency() || self.params.freq_fraction <= 0.0 {
            return false;
        }
        // Evenly spaced in the global photon index: exactly the requested share (up to
        // rounding), with no random draw.
        let f = self.params.freq_fraction;
        ((index + 1) as f64 * f).floor() > (index as f64 * f).floor()
    }

    /// Traces photon path `index` of this pass and stores its non-specular hits in `out`.
    ///
    /// Cost (callgrind, `passes` bench, CornellBox-Sphere: 2188 triangles, the two spheres are
    /// tessellated meshes with vertex normals; 100 000 photons, 3 passes, 1 thread), in
    /// instructions per photon path, 2.9 hits each: 4485 before the tracing-speed round of
    /// December 2026, of which the BVH traversal (`Accel::intersect`, 3.4 calls) 1501,
    /// `Scene::triangle_hit` 672, `Bsdf::sample` 522, `sample_emission` 272 + 95 for its ray,
    /// `Bsdf::new` 139 (an outlined call), the random numbers about 257 (about 16 draws and the
    /// seeding; seeding itself is about 50); 4270 after it. In time (perf, cpu-clock) the
    /// traversal is about 43 % of the tracing phase and `triangle_hit` about 14 %.
    ///
    /// What paid: inlining `Scene::intersect` with `triangle_hit` (forced: a plain `#[inline]`
    /// on `triangle_hit` made LLVM outline `Scene::intersect` instead, +1.5 % instructions and
    /// 1.86 against 1.64 pass CPU s in 3 alternated runs), `Bsdf::new` and the origin offset
    /// into this loop, so that the `Hit` is not returned through memory; hoisting the
    /// per-triangle centroid and bounds (`Scene::triangle_hit`, 232 → 203 instructions per
    /// hit) and the emitter frame and corners (`sample_emission`, 272 → 257 per photon).
    /// Not worth it: the seeding of the sampler. All exact: the images are bit for
    /// bit those of before. Not inlined itself (one call per path), so that it stays visible in
    /// profiles. In time (1 thread, 10⁶ photons, old and new binaries alternated, 2 × 3 runs on
    /// the shared machine): trace paths/s median 0.99 → 1.02 M and 0.92 → 0.96 M, pass CPU s
    /// median 1.55 → 1.54 and 1.70 → 1.62, i.e. about +4 %, far from the +22 % of issue #4: with
    /// the meshed spheres, what remains is mostly the traversal and the hit itself.
    ///
    /// Second round: 4229 → 3578 instructions and 21.6 → 14.0 simulated mispredictions per
    /// path, about ×1.2 in time; what paid and what did not is in `docs/performance.md`.
    #[inline(never)]
    fn trace_photon(&self, index: u64, tag_base: u32, out: &mut TracedPhotons) {
        let mut sampler = Sampler::new(self.params.seed, self.pass, index);
        let u_light = sampler.next_f32();
        let u_pos = sampler.next_2d();
        let u_dir = sampler.next_2d();
        let Some(emission) = self.scene.lights().sample_emission(u_light, u_pos, u_dir) else {
            return;
        };
        let mut power = emission.power;
        let mut ray = emission.ray();
        let mut spectrum = self
            .is_frequency_photon(index)
            .then(|| emitter_spectrum(emission.emitter, &self.caps));
        if spectrum.is_some() {
            out.frequency_photons += 1;
        }
        // `depth`: the photon's bounces before this hit. A hitpoint adds one more, so hits at
        // depth max_depth − 1 are the last that can count.
        for depth in 0..self.params.max_depth {
            let Some(hit) = self.scene.intersect_inlined(&ray) else {
                break;
            };
            let Some(material) = self.scene.material(hit.material) else {
                break;
            };
            let incoming = -ray.direction;
            if let Some(s) = spectrum.as_mut() {
                *s = self.travel_spectrum(*s, &ray, &hit, &mut sampler);
            }
            let bsdf = Bsdf::new(material, &hit);
            // With direct lighting by light sampling, photons straight from an emitter are
            // already accounted for at the hitpoints.
            let counted_by_light_sampling = self.params.direct_lighting && depth == 0;
            if !bsdf.is_specular() && !counted_by_light_sampling {
                // A frequency photon's tag names its record (see `TagLayout`); a chunk stores
                // at most PHOTON_CHUNK × max_depth ≤ 2²¹ records, so the index fits.
                let tag = match spectrum {
                    Some(s) => {
                        let tag = tag_base | out.frequency.len() as u32;
                        out.frequency.push(FrequencyPhoton::new(
                            out.photons.len() as u32,
                            hit.curvature,
                            ray.direction.dot(hit.shading_normal).abs(),
                            material.kind.lobe(),
                            s,
                            &self.caps,
                        ));
                        tag
                    }
                    None => UNTAGGED,
                };
                out.photons.push(Photon {
                    position: hit.position,
                    incoming,
                    power,
                    normal: hit.geometric_normal,
                    bounces: depth,
                    tag,
                });
            }
            // Scatter, unless no later hit could count.
            if depth + 1 == self.params.max_depth {
                break;
            }
            let u_lobe = sampler.next_f32();
            let u = sampler.next_2d();
            let u_roulette = sampler.next_f32();
            // Russian roulette (pbrt-v4 SPPM): keep the photon's power roughly constant, killing
            // it with probability q = 1 − lum(scattered power) / lum(power) and dividing the
            // survivor by 1 − q. On a Lambertian surface the scattered power is power × albedo
            // whatever the direction (up to the shading-normal correction, which the roulette
            // leaves out there), so the roulette runs before the direction is drawn and a killed
            // photon costs no BSDF sample; elsewhere it needs the sampled weight. Either way q
            // is fixed before `u_roulette` is compared with it: unbiased.
            let roulette = depth + 1 >= ROULETTE_DEPTH;
            let kill_probability = |scattered: Rgb| {
                let ratio = luminance(scattered) / luminance(power).max(f32::MIN_POSITIVE);
                (1.0 - ratio).max(0.0)
            };
            // The survival probability, when the roulette is decided before sampling.
            let decided = match material.kind {
                MaterialKind::Diffuse { albedo } if roulette => {
                    let q = kill_probability(power * albedo);
                    if u_roulette < q {
                        break;
                    }
                    Some(1.0 - q)
                }
                _ => None,
            };
            let Some(sample) = bsdf.sample(incoming, u_lobe, u, TransportMode::Importance) else {
                break;
            };
            let new_power =
                power * sample.weight * shading_normal_correction(&hit, incoming, sample.incoming);
            let survive = match decided {
                Some(survive) => survive,
                None if roulette => {
                    let q = kill_probability(new_power);
                    if u_roulette < q {
                        break;
                    }
                    1.0 - q
                }
                None => 1.0,
            };
            power = new_power / survive;
            if power == Rgb::ZERO || !power.is_finite() {
                break;
            }
            if let Some(s) = spectrum.as_mut() {
                *s = scatter_spectrum(*s, &hit, incoming, &sample, &bsdf, material, &self.caps);
            }
            ray = hit.spawn_ray(sample.incoming);
        }
    }

    /// A frequency photon's spectrum after the segment `ray` → `hit`: travel (design §4.1),
    /// plus partial occlusion (§4.7) when the occlusion probe finds a shadow edge nearby.
    ///
    /// The occlusion estimate \[UNV\] (the poster does not say how it detected partial
    /// occlusion): a probe ray from the segment's origin to a point beside the hit, offset
    /// perpendicular to the segment by w = 2·R₀ (R₀ the initial gather radius, the largest
    /// kernel a hitpoint can have, so w covers every hitpoint the photon can reach). If the
    /// probe is blocked while the photon went through, a shadow edge passes within w of the hit;
    /// [`OCCLUSION_BISECTIONS`] more probes bisect the offset to the distance δ of the edge.
    /// The visibility window at the blocker (distance t_b along the segment of length d) is
    /// modelled as a Gaussian of width w_b = δ·t_b/d, the gap between the photon and the edge
    /// there, i.e. spectral variance o = 1/(4π²·w_b²), applied as T(d − t_b)·O(o)·T(t_b).
    /// Cost: one shadow ray per segment of a frequency photon, a few more near shadow edges.
    fn travel_spectrum(
        &self,
        s: Spectrum,
        ray: &Ray,
        hit: &Hit,
        sampler: &mut Sampler,
    ) -> Spectrum {
        let distance = f64::from(hit.t);
        if !self.params.freq_occlusion {
            return s.travel(distance, &self.caps);
        }
        let u = sampler.next_2d();
        // Offsets in the receiver's tangent plane, so that the probe's target lies on the
        // receiving surface and the surface itself cannot block it; blockers in the last
        // [`CONTACT_FRACTION`] of the probe (contact shadows, a curving receiver) are ignored.
        let frame = geometry::Frame::from_normal(hit.geometric_normal);
        let phi = std::f32::consts::TAU * u.x;
        let side = frame.to_world(Vec3::new(phi.cos(), phi.sin(), 0.0));
        let probe = |offset: f32| -> Ray {
            let to_target = hit.position + side * offset - ray.origin;
            let length = to_target.length();
            Ray::new(ray.origin, to_target, length * (1.0 - CONTACT_FRACTION))
        };
        let w = (2.0 * self.kernel_scale) as f32;
        if !self.scene.occluded(&probe(w)) {
            return s.travel(distance, &self.caps);
        }
        // Bisect the offset of the shadow edge: unblocked at `lo`, blocked at `hi`. The probes
        // only ask whether they are blocked (`Scene::occluded`, any hit, no `Hit` built); the
        // blocker's distance is that of the last blocked probe, the one at the final `hi`, so a
        // single closest-hit query there gives the same t as keeping the t of every blocked
        // probe did. Measured (callgrind, `passes` bench, 100 000 photons, 10 % frequency
        // photons, 3 passes): 2723 → 2519 instructions of tracing per frequency photon over a
        // classical one. The traversal work hardly changes (about 1 probe per segment, nearly
        // all unblocked: 373 occlusions in 88 667 probes); the saving is the `Hit` that
        // `Scene::intersect` built for every blocked probe.
        let (mut lo, mut hi) = (0.0f32, w);
        for _ in 0..OCCLUSION_BISECTIONS {
            let mid = 0.5 * (lo + hi);
            if self.scene.occluded(&probe(mid)) {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        // `occluded` and `hit_distance` agree on whether a ray is blocked (tested in geometry);
        // `None` cannot happen, and would mean no occlusion.
        let Some(t_blocker) = self.scene.hit_distance(&probe(hi)) else {
            return s.travel(distance, &self.caps);
        };
        let t_b = f64::from(t_blocker).clamp(0.0, distance);
        let delta = f64::from(lo.max(w / 64.0));
        let gap = (delta * t_b / distance).max(1e-9);
        let o = 1.0 / (4.0 * std::f64::consts::PI.powi(2) * gap * gap);
        s.travel(t_b, &self.caps)
            .occlude(o, &self.caps)
            .travel(distance - t_b, &self.caps)
    }

    // ------------------------------------------------------------------------------------
    // Phase 4: hitpoint update.

    /// Probes the clear radius ([`crate::disc::clear_level`]) of every valid slot that has
    /// become a candidate for holding (R ≤ r_freq) and has not been probed at its visible
    /// point, in parallel. Deterministic: the probes use no random numbers.
    fn probe_clear_radii(&mut self) {
        let k = self.params.kernel_k;
        let r0 = self.kernel_scale as f32;
        let slots = &self.slots;
        let scene = self.scene;
        let probed: Vec<(usize, u8)> = (0..slots.len())
            .into_par_iter()
            .with_min_len(SLOT_CHUNK)
            .filter_map(|slot| {
                let freq = slots.freq()[slot];
                if !self.is_valid(slot) || freq.clear_level != GEOMETRY_UNKNOWN {
                    return None;
                }
                // Not probed yet, so this is the unbounded frequency radius.
                let r_freq = freq.hold_radius(k, self.kernel_scale)?;
                if slots.radius()[slot] > r_freq {
                    return None;
                }
                let level = crate::disc::clear_level(
                    scene,
                    slots.position()[slot],
                    slots.geometric_normal()[slot],
                    r0,
                );
                Some((slot, level))
            })
            .collect();
        let columns = self.slots.columns_mut();
        for (slot, level) in probed {
            columns.freq[slot].clear_level = level;
        }
    }

    fn update_hitpoints(&mut self, deposits: &PassDeposits) -> PassStats {
        let alpha = self.params.alpha;
        let k = self.params.kernel_k;
        let floor = self.params.freq_floor;
        let uses_frequency = self.params.method.uses_frequency();
        let probe_clock = Instant::now();
        if uses_frequency && self.params.freq_geometry {
            self.probe_clear_radii();
        }
        let probe_seconds = probe_clock.elapsed().as_secs_f64();
        let r0 = self.kernel_scale;
        let columns = self.slots.columns_mut();
        let held: Vec<bool> = columns
            .radius
            .par_iter_mut()
            .zip(columns.photon_count.par_iter_mut())
            .zip(columns.flux.par_iter_mut())
            .zip(columns.freq.par_iter())
            .zip(
                (0..deposits.slot_entry.len())
                    .into_par_iter()
                    .map(|s| deposits.of(s)),
            )
            .map(|((((radius, photon_count), tau), freq), (m, phi))| {
                let r_freq = if uses_frequency {
                    freq.hold_radius(k, r0)
                        .map_or(FrequencyRadius::None, FrequencyRadius::Predicted)
                } else {
                    FrequencyRadius::None
                };
                let held = matches!(r_freq, FrequencyRadius::Predicted(r) if *radius <= r);
                let mut stats = GatherStats {
                    radius: *radius,
                    photon_count: *photon_count,
                    flux: *tau,
                };
                stats.update(m, phi, alpha, r_freq, floor);
                *radius = stats.radius;
                *photon_count = stats.photon_count;
                *tau = stats.flux;
                held
            })
            .collect();

        let mut stats = PassStats {
            pass: self.pass,
            camera_paths: 0,
            photons_traced: u64::from(self.params.photons_per_pass),
            frequency_photons: deposits.frequency_photons,
            photons_deposited: deposits.photons_deposited,
            hitpoints_hit: deposits.hitpoints_hit,
            hitpoints_valid: 0,
            mean_radius: 0.0,
            min_radius: f64::INFINITY,
            max_radius: 0.0,
            frequency_held: 0.0,
            photons_stored: 0,
            timings: PassTimings {
                frequency: probe_seconds,
                ..PassTimings::default()
            },
        };
        let mut sum = 0.0;
        let mut n_held = 0u64;
        for (slot, &r) in self.slots.radius().iter().enumerate() {
            if !self.is_valid(slot) {
                continue;
            }
            stats.hitpoints_valid += 1;
            sum += r;
            stats.min_radius = stats.min_radius.min(r);
            stats.max_radius = stats.max_radius.max(r);
            n_held += u64::from(held[slot]);
        }
        if stats.hitpoints_valid > 0 {
            stats.mean_radius = sum / stats.hitpoints_valid as f64;
            stats.frequency_held = n_held as f64 / stats.hitpoints_valid as f64;
        } else {
            stats.min_radius = 0.0;
        }
        stats
    }
}

/// A camera path up to its first non-specular hit ([`PhotonMapper::camera_chain`]).
pub(crate) struct CameraChain {
    /// Emission seen along the path (not divided by the slots per pixel).
    pub(crate) direct: Rgb,
    /// The first non-specular hit, if the path reached one within `max_depth`.
    pub(crate) end: Option<ChainEnd>,
}

/// Where a camera path meets its first non-specular surface.
pub(crate) struct ChainEnd {
    pub(crate) hit: Hit,
    /// Unit direction back toward the camera (or the last specular vertex).
    pub(crate) outgoing: Vec3,
    /// Product of the specular weights along the way.
    pub(crate) throughput: Rgb,
    /// Specular bounces before `hit`.
    pub(crate) bounces: u32,
    /// The path's sampler, positioned after the chain's draws.
    pub(crate) sampler: Sampler,
}

/// What one camera path produced.
#[derive(Clone, Copy, Debug)]
struct CameraSample {
    /// Emission seen along the path (and direct lighting), already weighted by 1/spp.
    direct: Rgb,
    visible: Option<VisiblePoint>,
}

#[derive(Clone, Copy, Debug)]
struct VisiblePoint {
    position: Vec3,
    shading_normal: Vec3,
    geometric_normal: Vec3,
    outgoing: Vec3,
    material: u32,
    weight: Rgb,
    normal_distance: f32,
    /// Specular bounces of the camera path before this point.
    bounces: u32,
}

/// Photons of one chunk, in trace order.
#[derive(Default)]
struct TracedPhotons {
    photons: Vec<Photon>,
    /// The frequency records of the chunk's frequency photons, in trace order.
    frequency: Vec<FrequencyPhoton>,
    frequency_photons: u64,
}

impl TracedPhotons {
    /// Empties the chunk for the next pass, keeping the allocations.
    fn clear(&mut self) {
        self.photons.clear();
        self.frequency.clear();
        self.frequency_photons = 0;
    }
}

impl AsRef<[Photon]> for TracedPhotons {
    fn as_ref(&self) -> &[Photon] {
        &self.photons
    }
}

/// What a frequency photon brings to the hitpoints its flux counts for (its [`Photon`], whose
/// `tag` names this record, is stored with the others): its spectrum on arrival, the curvature
/// at its hit, and that spectrum already reflected by the lobe of the surface it landed on
/// (`field`, for `field_lobe`). 80 bytes.
///
/// A hitpoint that accepts the photon nearly always lies on the same surface, so the reflection
/// a deposit needs (design §8.1) is computed once per photon instead of once per photon and
/// hitpoint; a hitpoint of another lobe recomputes it from `spectrum` and `curvature`, with the
/// same result either way.
#[derive(Clone, Copy)]
struct FrequencyPhoton {
    field: Spectrum,
    field_lobe: MaterialLobe,
    curvature: f32,
    /// |cos θi| of the photon's arrival, for the tangential projection of the deposit.
    mu_i: f32,
    /// Index of its photon in the chunk's `photons`.
    photon: u32,
    spectrum: Spectrum,
}

impl FrequencyPhoton {
    fn new(
        photon: u32,
        curvature: f32,
        mu_i: f32,
        lobe: MaterialLobe,
        spectrum: Spectrum,
        caps: &Caps,
    ) -> Self {
        Self {
            field: deposit_field(spectrum, curvature, mu_i, lobe, caps),
            field_lobe: lobe,
            curvature,
            mu_i,
            photon,
            spectrum,
        }
    }

    /// The field a hitpoint of lobe `lobe` reads from this photon.
    fn field(&self, lobe: MaterialLobe, caps: &Caps) -> Spectrum {
        if lobe == self.field_lobe {
            self.field
        } else {
            deposit_field(self.spectrum, self.curvature, self.mu_i, lobe, caps)
        }
    }
}

/// The field a hitpoint's radius reads (design §8.1): the photon's spectrum reflected by the
/// hitpoint's lobe, with μo = 1 so that a stays in surface units (b does not depend on μo),
/// under the conservative 3D collapse of §8.5 (the per-coefficient minimum of the tangential
/// and sagittal reflections at the arrival cosine μi).
fn deposit_field(
    spectrum: Spectrum,
    curvature: f32,
    mu_i: f32,
    lobe: MaterialLobe,
    caps: &Caps,
) -> Spectrum {
    spectrum.reflect_isotropic(
        f64::from(mu_i),
        1.0,
        f64::from(curvature),
        spectrum_lobe(lobe),
        caps,
    )
}

/// [`Photon::tag`] of a photon without a frequency record.
const UNTAGGED: u32 = u32::MAX;

/// How a frequency photon's [`Photon::tag`] names its record.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum TagLayout {
    /// `chunk << local_bits | index in the chunk's records`, set while tracing: the records
    /// stay where the chunks stored them.
    Packed { local_bits: u32 },
    /// The index in the concatenation of the chunks' records ([`tag_frequency_photons`]), for
    /// passes with too many chunks or too deep paths to pack both indices in 31 bits (more than
    /// 2²⁰ chunks, i.e. 2·10⁹ photons per pass, at the default depth).
    Global,
}

impl TagLayout {
    fn new(n_chunks: usize, max_depth: u32) -> Self {
        // Bits for indices below n.
        let bits = |n: u64| u64::BITS - n.saturating_sub(1).leading_zeros();
        let local_bits = bits(PHOTON_CHUNK * u64::from(max_depth));
        let chunk_bits = bits(n_chunks as u64);
        // At most 31 bits in all: no packed tag is UNTAGGED.
        if local_bits + chunk_bits <= 31 {
            Self::Packed { local_bits }
        } else {
            Self::Global
        }
    }

    /// What a chunk's tags start from: its index in the high bits, or 0 (the chunk's own
    /// record indices, which `tag_frequency_photons` makes global after tracing).
    fn chunk_base(self, chunk: usize) -> u32 {
        match self {
            Self::Packed { local_bits } => (chunk as u32) << local_bits,
            Self::Global => 0,
        }
    }
}

/// For [`TagLayout::Global`]: gathers the frequency records of all chunks into `records`, in
/// chunk order, and tags each record's photon with the record's index there, in parallel over
/// the chunks. (With [`TagLayout::Packed`], the default, nothing to do: for 10⁶ photons this
/// took 5–6 ms, mostly the scattered writes of the tags, on one thread or two.)
///
/// A pass would need 2³² frequency records (256 GiB of them) before an index reached
/// [`UNTAGGED`]; photons past that are left untagged (their flux counts, their spectrum not).
fn tag_frequency_photons(traced: &mut [TracedPhotons], records: &mut Vec<FrequencyPhoton>) {
    // The copy is serial: a memcpy of 8 MB per 10⁵ frequency records, about a millisecond.
    records.clear();
    let mut offsets = Vec::with_capacity(traced.len());
    for chunk in traced.iter() {
        offsets.push(records.len());
        records.extend_from_slice(&chunk.frequency);
    }
    traced
        .par_iter_mut()
        .zip(offsets)
        .for_each(|(chunk, offset)| {
            for (k, record) in chunk.frequency.iter().enumerate() {
                chunk.photons[record.photon as usize].tag =
                    u32::try_from(offset + k).unwrap_or(UNTAGGED);
            }
        });
}

/// The photon pass's buffers, kept from one pass to the next: a pass of a million photons
/// fills about a hundred megabytes of them, which freshly allocated would cost page faults
/// (10 % of a pass in the profile) and serial copies. None of it carries state between passes.
#[derive(Default)]
struct PhotonScratch {
    /// Per chunk of [`PHOTON_CHUNK`] photon paths, what they stored.
    traced: Vec<TracedPhotons>,
    /// With [`TagLayout::Global`], the frequency records of all chunks, in chunk order:
    /// [`Photon::tag`] indexes them.
    frequency: Vec<FrequencyPhoton>,
    /// Tests: tag as [`TagLayout::Global`] whatever the pass size.
    #[cfg(test)]
    force_global_tags: bool,
    /// Morton keys of the stored photons.
    keys: MortonScratch,
    /// The stored photons in Morton order.
    sorted: Vec<Photon>,
    gather: GatherScratch<Rgb>,
    /// The flux gather of the frequency-guided methods: each pair with its photon's tag.
    tagged_gather: GatherScratch<(Rgb, u32)>,
    /// Per grid entry: M and Φ of the pass.
    per_entry: Vec<(u32, [f64; 3])>,
    /// Per grid entry: the merged frequency deposits of the pass.
    frequency_per_entry: Vec<FrequencyEstimate>,
    /// Per slot, its grid entry; lent to [`PassDeposits`] during a pass.
    slot_entry: Vec<u32>,
}

/// `PassDeposits::slot_entry` of a slot the grid does not index.
const NOT_IN_GRID: u32 = u32::MAX;

/// What one photon pass brings to each hitpoint slot: M and Φ, per grid entry (no per-slot
/// copy: [`Self::of`] looks a slot's entry up).
struct PassDeposits {
    /// Per grid entry: M and Φ.
    per_entry: Vec<(u32, [f64; 3])>,
    /// Per slot: its grid entry, or [`NOT_IN_GRID`].
    slot_entry: Vec<u32>,
    photons_deposited: u64,
    hitpoints_hit: u64,
    frequency_photons: u64,
    photons_stored: u64,
    trace_seconds: f64,
    /// Seconds spent on the frequency deposits (sort, gather, merge).
    frequency_seconds: f64,
}

impl PassDeposits {
    /// M and Φ of `slot` in this pass.
    fn of(&self, slot: usize) -> (u32, [f64; 3]) {
        match self.slot_entry[slot] {
            NOT_IN_GRID => (0, [0.0; 3]),
            entry => self.per_entry[entry as usize],
        }
    }
}

/// Veach's correction for shading normals on light paths (thesis §5.3; pbrt's
/// `CorrectShadingNormal`): the BSDF is not symmetric once the shading normal differs from the
/// geometric one, and flux carried by photons must be multiplied by
/// |ωo·n_s|·|ωi·n_g| / (|ωo·n_g|·|ωi·n_s|) at every bounce (ωo toward where the photon came
/// from, ωi the new direction). Without it photons through smooth-shaded meshes (the water
/// surface of the Cornell box) carry a few per cent too much or too little light.
fn shading_normal_correction(hit: &Hit, from: Vec3, to: Vec3) -> f32 {
    let (ns, ng) = (hit.shading_normal, hit.geometric_normal);
    let numerator = from.dot(ns).abs() * to.dot(ng).abs();
    let denominator = from.dot(ng).abs() * to.dot(ns).abs();
    if denominator > 0.0 {
        numerator / denominator
    } else {
        0.0
    }
}

fn luminance(c: Rgb) -> f32 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}

/// The lobe of a material as the frequency operators see it (design §7).
fn spectrum_lobe(lobe: MaterialLobe) -> Lobe {
    match lobe {
        MaterialLobe::Specular => Lobe::Mirror,
        MaterialLobe::Lambert => Lobe::Lambert,
        MaterialLobe::Ggx { alpha } => Lobe::Ggx {
            roughness: f64::from(alpha),
        },
    }
}

/// The spectrum of the light field leaving an emitter (design §6).
fn emitter_spectrum(shape: EmitterShape, caps: &Caps) -> Spectrum {
    match shape {
        EmitterShape::Area { size, cos_theta } => {
            Spectrum::area_light(f64::from(size), f64::from(cos_theta), caps)
        }
        EmitterShape::Point => Spectrum::point_light(caps),
        // The falloff's own variance: narrower than the hard cone's, so the conservative one.
        EmitterShape::Spot {
            cone_angle,
            falloff_start,
        } => Spectrum::spot_light_smoothstep(f64::from(falloff_start), f64::from(cone_angle), caps),
        EmitterShape::Directional => Spectrum::directional_light(caps),
    }
}

/// The photon's spectrum after scattering at `hit` into `sample.incoming` (the new travel
/// direction), under the conservative isotropic 3D collapse of design §8.5.
fn scatter_spectrum(
    spectrum: Spectrum,
    hit: &Hit,
    arrived_from: Vec3,
    sample: &geometry::BsdfSample,
    bsdf: &Bsdf,
    material: &geometry::Material,
    caps: &Caps,
) -> Spectrum {
    let normal = hit.shading_normal;
    let mu_i = f64::from(arrived_from.dot(normal).abs());
    let mu_o = f64::from(sample.incoming.dot(normal).abs());
    let curvature = f64::from(hit.curvature);
    if sample.is_transmission {
        let ior = match material.kind {
            geometry::MaterialKind::Dielectric { ior } => f64::from(ior),
            _ => 1.0,
        };
        let (eta_i, eta_t) = if hit.front_face {
            (1.0, ior)
        } else {
            (ior, 1.0)
        };
        return spectrum.refract(eta_i, eta_t, mu_i, mu_o, curvature, caps);
    }
    let lobe = if sample.is_specular {
        Lobe::Mirror
    } else {
        spectrum_lobe(bsdf.lobe())
    };
    spectrum.reflect_isotropic(mu_i, mu_o, curvature, lobe, caps)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Method;

    #[test]
    fn tags_pack_chunk_and_record_indices_when_they_fit() {
        // 489 chunks (10⁶ photons), depth 8: 9 + 14 bits.
        assert_eq!(TagLayout::new(489, 8), TagLayout::Packed { local_bits: 14 });
        assert_eq!(TagLayout::new(1, 1), TagLayout::Packed { local_bits: 11 });
        // Depth 1024: 21 bits per chunk leave 10 for 1024 chunks, not for 1025.
        assert_eq!(
            TagLayout::new(1024, 1024),
            TagLayout::Packed { local_bits: 21 }
        );
        assert_eq!(TagLayout::new(1025, 1024), TagLayout::Global);
        // The largest packed tag is below UNTAGGED.
        let TagLayout::Packed { local_bits } = TagLayout::new(1024, 1024) else {
            unreachable!()
        };
        let last = TagLayout::new(1024, 1024).chunk_base(1023) | ((1 << local_bits) - 1);
        assert!(last < UNTAGGED);
    }

    #[test]
    fn global_tags_deposit_exactly_what_packed_tags_do() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../../shared/scenes/cornell_box/CornellBox-Sphere.obj");
        let mut description = geometry::load(&path).unwrap();
        description.film = geometry::Film {
            width: 24,
            height: 24,
        };
        let scene = Scene::new(description).unwrap();
        let mut params = RenderParams::preview();
        params.method = Method::FreqPpm;
        params.photons_per_pass = 5_000;
        let render = |force_global_tags| {
            let mut mapper = PhotonMapper::new(&scene, params).unwrap();
            mapper.scratch.force_global_tags = force_global_tags;
            let stats: Vec<PassStats> = (0..3).map(|_| mapper.iterate()).collect();
            (mapper.image(), mapper.slots.freq().to_vec(), stats)
        };
        let (packed, global) = (render(false), render(true));
        assert!(packed.1.iter().any(|f| f.estimate().has_freq()));
        assert_eq!(packed.1, global.1, "frequency states differ");
        let bits = |image: &[[f32; 3]]| {
            image
                .iter()
                .map(|p| p.map(f32::to_bits))
                .collect::<Vec<_>>()
        };
        assert_eq!(bits(&packed.0), bits(&global.0));
        for (a, b) in packed.2.iter().zip(&global.2) {
            assert_eq!(a.photons_deposited, b.photons_deposited);
            assert_eq!(a.frequency_held.to_bits(), b.frequency_held.to_bits());
        }
    }
}
