//! A deterministic parallel photon gather: per-hitpoint accumulation without locks.

use rayon::prelude::*;

use crate::grid::HitPointGrid;
use crate::photon::Photon;

/// Photons per parallel work item. Fixed, so the work split does not depend on the thread count.
const GATHER_CHUNK: usize = 4096;

/// At most this many hitpoint ranges in the accumulation phase.
const MAX_RANGES: usize = 64;

/// At least this many hitpoints per range.
const MIN_RANGE_LEN: usize = 512;

/// Gathers `photons` into per-hitpoint accumulators, in parallel and bit-reproducibly.
///
/// The items are photons, or records that carry one (`AsRef<Photon>`, e.g. a photon with
/// extra state the contribution reads); the values are `Copy` (what a photon brings, e.g. a
/// flux or a frequency spectrum).
///
/// For every photon p (in slice order) and every hitpoint h whose sphere contains it
/// ([`HitPointGrid::for_each_containing`], in its fixed order), `contribution(p, h)` decides
/// whether the photon counts (e.g. [`crate::accepts`]) and what it brings (e.g. the BSDF-weighted
/// flux, a frequency estimate); `accumulate(&mut acc[h], value)` then folds it in.
///
/// Two lock-free parallel phases, both split independently of the thread count:
/// 1. `contribution` runs over fixed chunks of photons; each chunk records its
///    `(hitpoint, value)` pairs in photon order, binned by fixed ranges of hitpoint indices;
/// 2. `accumulate` runs over the hitpoint ranges (disjoint accumulators), reading the bins of
///    the chunks in chunk order.
///
/// Every accumulator therefore sees its values in photon order whatever the thread count:
/// floating-point sums are identical for 1, 2 or 8 threads. No locks, no atomics.
///
/// Returns one accumulator per hitpoint (`n_hitpoints`, starting from `A::default()`).
///
/// # Panics
/// If the grid reports a hitpoint index ≥ `n_hitpoints`.
pub fn gather<P, T, A>(
    grid: &HitPointGrid,
    photons: &[P],
    n_hitpoints: usize,
    contribution: impl Fn(&P, u32) -> Option<T> + Sync,
    accumulate: impl Fn(&mut A, T) + Sync,
) -> Vec<A>
where
    P: AsRef<Photon> + Sync,
    T: Copy + Send + Sync,
    A: Default + Clone + Send,
{
    let mut accumulators = Vec::new();
    gather_with(
        &mut GatherScratch::default(),
        grid,
        photons,
        &mut accumulators,
        n_hitpoints,
        contribution,
        accumulate,
    );
    accumulators
}

/// The buffers of [`gather_with`]: the `(hitpoint, value)` bins of every photon chunk. Kept by
/// the caller across passes, they are cleared but not freed, so a steady state of similar
/// passes neither allocates nor page-faults (the bins of a 1M-photon pass are tens of MB).
#[derive(Debug)]
pub struct GatherScratch<T> {
    /// Per photon chunk, per hitpoint range.
    bins: Vec<Vec<Vec<(u32, T)>>>,
}

/// The bins of a finished [`gather_with`], which folds its `(hitpoint, value)` pairs again with
/// [`Gathered::accumulate_again`]: only a gather makes one, so nothing can fold bins that no
/// gather filled.
#[derive(Debug)]
pub struct Gathered<'a, T> {
    scratch: &'a GatherScratch<T>,
    /// The gather's photon chunks.
    n_chunks: usize,
    /// Its hitpoint count.
    n_hitpoints: usize,
    /// Its hitpoint range length.
    range_len: usize,
}

impl<T> GatherScratch<T> {
    /// Heap bytes of the bins (allocated capacities).
    #[must_use]
    pub fn heap_bytes(&self) -> usize {
        use std::mem::size_of;
        self.bins
            .iter()
            .map(|ranges| {
                ranges.capacity() * size_of::<Vec<(u32, T)>>()
                    + ranges
                        .iter()
                        .map(|bin| bin.capacity() * size_of::<(u32, T)>())
                        .sum::<usize>()
            })
            .sum::<usize>()
            + self.bins.capacity() * size_of::<Vec<Vec<(u32, T)>>>()
    }
}

impl<T> Default for GatherScratch<T> {
    fn default() -> Self {
        Self { bins: Vec::new() }
    }
}

/// [`gather`] with caller-kept buffers: the bins in `scratch`, and the accumulators in
/// `accumulators`, which is overwritten with `n_hitpoints` accumulators (reusing its
/// allocation). Same results as [`gather`], bit for bit. The bins stay in `scratch`, and the
/// returned [`Gathered`] can fold them again into other accumulators.
///
/// # Panics
/// If the grid reports a hitpoint index ≥ `n_hitpoints`.
pub fn gather_with<'a, P, T, A>(
    scratch: &'a mut GatherScratch<T>,
    grid: &HitPointGrid,
    photons: &[P],
    accumulators: &mut Vec<A>,
    n_hitpoints: usize,
    contribution: impl Fn(&P, u32) -> Option<T> + Sync,
    accumulate: impl Fn(&mut A, T) + Sync,
) -> Gathered<'a, T>
where
    P: AsRef<Photon> + Sync,
    T: Copy + Send + Sync,
    A: Default + Clone + Send,
{
    // Hitpoint ranges: a function of `n_hitpoints` only.
    let range_len = n_hitpoints.div_ceil(MAX_RANGES).max(MIN_RANGE_LEN);
    let n_ranges = n_hitpoints.div_ceil(range_len).max(1);
    let n_chunks = photons.len().div_ceil(GATHER_CHUNK);
    if scratch.bins.len() < n_chunks {
        scratch.bins.resize_with(n_chunks, Vec::new);
    }
    let bins = &mut scratch.bins[..n_chunks];
    bins.par_iter_mut()
        .zip(photons.par_chunks(GATHER_CHUNK))
        .for_each(|(bins, chunk)| {
            bins.resize_with(n_ranges, Vec::new);
            for bin in bins.iter_mut() {
                bin.clear();
            }
            for photon in chunk {
                grid.for_each_containing(photon.as_ref().position, |idx| {
                    if let Some(value) = contribution(photon, idx) {
                        bins[idx as usize / range_len].push((idx, value));
                    }
                });
            }
        });
    let gathered = Gathered {
        scratch,
        n_chunks,
        n_hitpoints,
        range_len,
    };
    gathered.accumulate_again(accumulators, |acc, _, value| accumulate(acc, value));
    gathered
}

impl<T: Copy + Send + Sync> Gathered<'_, T> {
    /// Folds the `(hitpoint, value)` pairs of this gather into a second set of accumulators,
    /// in the same order (photon order for every hitpoint) and as deterministically, without
    /// querying the grid again.
    ///
    /// For a second quantity carried by some of the photons: the contribution of the gather
    /// returns both (e.g. a flux and a tag naming a record with more state, see
    /// [`Photon::tag`]), its accumulation folds the first, and this folds the second, with the
    /// hitpoint's index at hand (`accumulate(&mut acc[h], h, value)`) for whatever the
    /// hitpoint's side of it needs. `accumulators` is overwritten with one `B::default()` per
    /// hitpoint of the gather. ([`gather_with`] folds its own accumulators with this, ignoring
    /// the index.)
    pub fn accumulate_again<B>(
        &self,
        accumulators: &mut Vec<B>,
        accumulate: impl Fn(&mut B, u32, T) + Sync,
    ) where
        B: Default + Clone + Send,
    {
        let Self {
            scratch,
            n_chunks,
            n_hitpoints,
            range_len,
        } = *self;
        accumulators.clear();
        // Exactly: the default growth would double the capacity when the count grows a little.
        accumulators.reserve_exact(n_hitpoints);
        accumulators.resize(n_hitpoints, B::default());
        let bins = &scratch.bins[..n_chunks];
        accumulators
            .par_chunks_mut(range_len)
            .enumerate()
            .for_each(|(range_idx, accs)| {
                let first = range_idx * range_len;
                for chunk_bins in bins {
                    for &(idx, value) in &chunk_bins[range_idx] {
                        accumulate(&mut accs[idx as usize - first], idx, value);
                    }
                }
            });
    }
}
