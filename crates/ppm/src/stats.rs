//! What a pass reports (`PassStats`, `PassTimings`), what a render holds in memory
//! (`MemoryUse`), and what it will hold, estimated before anything is allocated
//! (`MemoryEstimate`; each integrator estimates its own and `methods.rs` picks the estimate).

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
    /// Stored photons connected to the camera (`light_tracing`): visible from the lens, on
    /// the film, with a non-zero BSDF toward it.
    pub light_connections: u64,
    /// Photons stored where they scattered in a participating medium this pass (zero in a scene
    /// without media).
    pub volume_photons: u64,
    /// Values dropped this pass because they were NaN or infinite where they would have entered
    /// a sum: photon powers (the path ends), photon–hitpoint fluxes, directly seen emission and
    /// camera weights (the visible point is dropped), path-tracer samples. Zero in a healthy
    /// scene; frequency spectra never need it (their coefficients are clamped into the caps,
    /// NaN included, when they are made).
    pub non_finite: u64,
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
    /// The volume photons' gather inside `gather` (already counted there): building their
    /// tree and gathering them along the camera rays' stretches through media. Zero in a scene
    /// without media.
    pub volume: f64,
}

impl PassStats {
    /// The report of pass `pass` before its phases fill it in.
    pub(crate) fn empty(pass: u32) -> Self {
        Self {
            pass,
            camera_paths: 0,
            photons_traced: 0,
            frequency_photons: 0,
            photons_deposited: 0,
            hitpoints_hit: 0,
            hitpoints_valid: 0,
            mean_radius: 0.0,
            min_radius: 0.0,
            max_radius: 0.0,
            frequency_held: 0.0,
            photons_stored: 0,
            light_connections: 0,
            volume_photons: 0,
            non_finite: 0,
            timings: PassTimings::default(),
        }
    }
}

impl PassTimings {
    /// The whole pass.
    #[must_use]
    pub fn total(&self) -> f64 {
        self.camera + self.index + self.trace + self.gather + self.update
    }
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

/// What a render will hold, in bytes, estimated from the film size and the parameters before
/// anything is allocated ([`MemoryEstimate::of`]), so that an absurd request is refused at
/// once instead of swapping or being killed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct MemoryEstimate {
    /// Hitpoint slots with their grid and per-pass buffers (photon mappers), or the per-pixel
    /// sums (path tracer). Set by the film size and `--spp`.
    pub hitpoints: u64,
    /// The photon buffers of a pass. Set by `--photons-per-pass`.
    pub photons: u64,
    /// The output image with its AOVs, as written.
    pub film: u64,
    /// A checkpoint while it is being written: the encoded state and its compressed copy.
    pub checkpoint: u64,
}

/// Photon-buffer bytes per photon emitted in a pass: the stored photons (traced, Morton-sorted,
/// their keys) and the gather's photon–hitpoint pairs. Measured 250–1,360 bytes on a caustic,
/// a Cornell box and an indirectly lit room (0.7–4.8 stored photons per emitted one; see
/// docs/reliability.md); the estimate takes the upper end, as deep paths store more.
const PHOTON_BYTES: u64 = 1536;
/// Output bytes per pixel: the image, its copy in the EXR writer, the PNG, and up to ten AOV
/// channels.
pub(crate) const FILM_BYTES_PER_PIXEL: u64 = 12 + 12 + 4 + 40;

impl MemoryEstimate {
    /// Photon-buffer bytes of a pass of `photons` photons.
    #[must_use]
    pub fn photon_bytes(photons: u64) -> u64 {
        photons.saturating_mul(PHOTON_BYTES)
    }

    /// Everything, with or without a checkpoint being written.
    #[must_use]
    pub fn total(&self, with_checkpoint: bool) -> u64 {
        let checkpoint = if with_checkpoint { self.checkpoint } else { 0 };
        self.hitpoints
            .saturating_add(self.photons)
            .saturating_add(self.film)
            .saturating_add(checkpoint)
    }
}
