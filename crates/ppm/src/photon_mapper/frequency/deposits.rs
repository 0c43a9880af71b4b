//! Where frequency photons' records go: how a photon's tag names its record ([`TagLayout`]),
//! and the deposits of the records into the hitpoint slots, which ride the flux gather
//! ([`FrequencyDeposits::deposit`]).

use photon::{Gathered, HitPoints};
use rayon::prelude::*;
use scene::Rgb;
use spectrum::FrequencyEstimate;

use super::super::index::NOT_IN_GRID;
use super::super::trace::TracedPhotons;
use super::super::{PHOTON_CHUNK, SLOT_CHUNK, Setup};
use super::SlotFrequency;
use super::transport::{FrequencyPhoton, UNTAGGED};

/// How a frequency photon's [`photon::Photon::tag`] names its record.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum TagLayout {
    /// `chunk << local_bits | index in the chunk's records`, set while tracing: the records
    /// stay where the chunks stored them.
    Packed { local_bits: u32 },
    /// The index in the concatenation of the chunks' records ([`tag_frequency_photons`]), for
    /// passes with too many chunks or too deep paths to pack both indices in 31 bits (more than
    /// 2²⁰ chunks, i.e. 2·10⁹ photons per pass, at the default depth).
    Global,
}

impl TagLayout {
    pub(crate) fn new(n_chunks: usize, max_depth: u32) -> Self {
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
    pub(crate) fn chunk_base(self, chunk: usize) -> u32 {
        match self {
            Self::Packed { local_bits } => (chunk as u32) << local_bits,
            Self::Global => 0,
        }
    }
}

/// For [`TagLayout::Global`]: gathers the frequency records of all chunks into `records`, in
/// chunk order, and tags each record's photon with the record's index there, in parallel over
/// the chunks. (With [`TagLayout::Packed`], the default, nothing to do.)
///
/// A pass would need 2³² frequency records (256 GiB of them) before an index reached
/// [`UNTAGGED`]; photons past that are left untagged (their flux counts, their spectrum not).
fn tag_frequency_photons(traced: &mut [TracedPhotons], records: &mut Vec<FrequencyPhoton>) {
    // The copy is serial: a plain memcpy, small next to the tag writes.
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

/// The frequency phase's buffers, kept from one pass to the next (none of it carries state
/// between passes).
#[derive(Default)]
pub(crate) struct FrequencyDeposits {
    /// With [`TagLayout::Global`], the frequency records of all chunks, in chunk order:
    /// [`photon::Photon::tag`] indexes them.
    records: Vec<FrequencyPhoton>,
    /// Per grid entry: the merged frequency deposits of the pass.
    per_entry: Vec<FrequencyEstimate>,
    /// Tests: tag as [`TagLayout::Global`] whatever the pass size.
    #[cfg(test)]
    pub(crate) force_global_tags: bool,
}

impl FrequencyDeposits {
    /// The tag layout of a pass of `n_chunks` chunks.
    pub(crate) fn layout(&self, n_chunks: usize, max_depth: u32) -> TagLayout {
        let layout = TagLayout::new(n_chunks, max_depth);
        #[cfg(test)]
        let layout = if self.force_global_tags {
            TagLayout::Global
        } else {
            layout
        };
        layout
    }

    /// After tracing: makes the tags name the records ([`TagLayout::Global`] only).
    pub(crate) fn tag(&mut self, layout: TagLayout, traced: &mut [TracedPhotons]) {
        if layout == TagLayout::Global {
            tag_frequency_photons(traced, &mut self.records);
        }
    }

    /// Heap bytes of the buffers sized by the photons, and of those sized by the hitpoints.
    pub(crate) fn heap_bytes(&self) -> (usize, usize) {
        use std::mem::size_of;
        (
            self.records.capacity() * size_of::<FrequencyPhoton>(),
            self.per_entry.capacity() * size_of::<FrequencyEstimate>(),
        )
    }

    /// The frequency deposits of a pass. A frequency photon counts for exactly the hitpoints
    /// its flux counts for, so they ride the flux gather: its pairs carry the photon's tag, and
    /// each grid entry merges the fields of its tagged pairs, in photon order (the merges, a
    /// min or max per coefficient, do not depend on the order anyway). Then each slot merges
    /// its entry's estimate.
    pub(crate) fn deposit(
        &mut self,
        setup: &Setup,
        traced: &[TracedPhotons],
        tagged_gather: &Gathered<'_, (Rgb, u32)>,
        grid_slots: &[u32],
        slot_entry: &[u32],
        slots: &mut HitPoints<SlotFrequency>,
    ) {
        let policy = setup.params.frequency.merge;
        let layout = self.layout(traced.len(), setup.params.budget.max_depth);
        let concatenated = &self.records;
        let record = |tag: u32| match layout {
            TagLayout::Packed { local_bits } => {
                &traced[(tag >> local_bits) as usize].frequency
                    [(tag & ((1 << local_bits) - 1)) as usize]
            }
            TagLayout::Global => &concatenated[tag as usize],
        };
        let material_idx = slots.material_idx();
        let slot_freq = slots.freq();
        tagged_gather.accumulate_again(
            &mut self.per_entry,
            |acc: &mut FrequencyEstimate, entry, (_, tag)| {
                if tag == UNTAGGED {
                    return;
                }
                let slot = grid_slots[entry as usize] as usize;
                if let Some(material) = setup.scene.material(material_idx[slot]) {
                    let field = record(tag).field(material.kind.lobe(), &setup.caps);
                    acc.deposit(slot_freq[slot].seen_from_camera(field, &setup.caps), policy);
                }
            },
        );
        let per_entry = &self.per_entry;
        slots
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
    }
}
