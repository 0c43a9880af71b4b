//! What the photon mappers hold in memory: measured ([`PhotonMapper::memory`]) and estimated
//! before anything is allocated ([`estimate`]).

use photon::HitPoints;

use super::PhotonMapper;
use super::frequency::SlotFrequency;
use crate::params::RenderParams;
use crate::stats::{MemoryEstimate, MemoryUse};

/// Hash-grid bytes per hitpoint slot (cells and entries; measured 35–40).
const GRID_BYTES_PER_SLOT: u64 = 48;
/// Per-pass buffers per slot: M and Φ per grid entry and the slot's entry (36 bytes).
const PASS_BYTES_PER_SLOT: u64 = 36;
/// A frequency estimate per grid entry, for the frequency-guided methods.
const FREQUENCY_PASS_BYTES_PER_SLOT: u64 = 32;
/// Light tracing's buffers per slot: the pass's connected radiance (24 bytes) and the camera
/// sample density at the visible point (4).
const LIGHT_BYTES_PER_SLOT: u64 = 28;
/// Light tracing's buffers per photon emitted and slot per pixel: one 16-byte contribution per
/// slot of the pixel per connected photon, for up to the 4.8 stored photons per emitted one
/// (rounded up).
const LIGHT_BYTES_PER_PHOTON: u64 = 80;
/// Checkpoint bytes per slot while writing: the encoded record (at most 200, 24 for the volume
/// sums and 4 for whether the visible point moved between surfaces) and its compressed copy
/// (about a third).
const CHECKPOINT_BYTES_PER_SLOT: u64 = 312;

/// Memory per hitpoint slot of the photon mappers' fixed columns: the hitpoint record
/// (`photon::HitPoints` with the frequency state) plus the renderer's per-slot photon-bounce
/// budget (which also says whether the slot is valid), direct-emission sum, mean visible-point
/// weight and whether its visible point has moved between surfaces. The hash grid and its slot
/// map come on top; [`crate::Renderer::memory`] measures everything.
#[must_use]
pub fn bytes_per_hitpoint() -> usize {
    HitPoints::<SlotFrequency>::bytes_per_hitpoint()
        + std::mem::size_of::<u16>()
        + std::mem::size_of::<[f64; 3]>()
        + std::mem::size_of::<[f32; 3]>()
        + std::mem::size_of::<bool>()
}

/// What a render of `pixels` pixels with `params` will hold (the film aside), with the
/// frequency buffers if `frequency` (the frequency methods, and `appm`'s pilot).
pub(crate) fn estimate(pixels: u64, params: &RenderParams, frequency: bool) -> MemoryEstimate {
    let slots = pixels.saturating_mul(u64::from(params.film.samples_per_pixel));
    let light_tracing = params.connections.light_tracing;
    let per_slot = bytes_per_hitpoint() as u64
        + GRID_BYTES_PER_SLOT
        + PASS_BYTES_PER_SLOT
        + if frequency {
            FREQUENCY_PASS_BYTES_PER_SLOT
        } else {
            0
        }
        + if light_tracing {
            LIGHT_BYTES_PER_SLOT
        } else {
            0
        };
    let photons_per_pass = u64::from(params.budget.photons_per_pass);
    MemoryEstimate {
        hitpoints: slots.saturating_mul(per_slot),
        photons: MemoryEstimate::photon_bytes(photons_per_pass).saturating_add(if light_tracing {
            // The connection-only paths' splats come on top of the photons'.
            photons_per_pass
                .saturating_add(params.connect_only_paths())
                .saturating_mul(LIGHT_BYTES_PER_PHOTON)
                .saturating_mul(u64::from(params.film.samples_per_pixel))
        } else {
            0
        }),
        film: 0,
        checkpoint: slots.saturating_mul(CHECKPOINT_BYTES_PER_SLOT),
    }
}

impl PhotonMapper {
    /// Heap memory by part (capacities of the buffers).
    #[must_use]
    pub(crate) fn memory(&self) -> MemoryUse {
        use std::mem::size_of;
        let (photon_buffers, hitpoint_buffers) = self.photons.heap_bytes();
        let (frequency_records, frequency_per_entry) = self.frequency.heap_bytes();
        let (volume_pass, volume_sums) = self.volume.heap_bytes();
        MemoryUse {
            hitpoints: self.slots.len(),
            records: self.slots.heap_bytes(),
            slot_columns: self.photon_bounces.capacity() * size_of::<u16>()
                + self.direct.capacity() * size_of::<[f64; 3]>()
                + self.mixed.capacity()
                + self.mean_weight.capacity() * size_of::<glam::Vec3>()
                + volume_sums,
            grid: self.index.heap_bytes(),
            pass_hitpoint_buffers: hitpoint_buffers + frequency_per_entry,
            pass_photon_buffers: photon_buffers + frequency_records + volume_pass,
        }
    }
}
