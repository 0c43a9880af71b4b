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
pub fn gather<T, A>(
    grid: &HitPointGrid,
    photons: &[Photon],
    n_hitpoints: usize,
    contribution: impl Fn(&Photon, u32) -> Option<T> + Sync,
    accumulate: impl Fn(&mut A, T) + Sync,
) -> Vec<A>
where
    T: Send,
    A: Default + Clone + Send,
{
    // Hitpoint ranges: a function of `n_hitpoints` only.
    let range_len = n_hitpoints.div_ceil(MAX_RANGES).max(MIN_RANGE_LEN);
    let n_ranges = n_hitpoints.div_ceil(range_len).max(1);
    let chunks: Vec<Vec<Vec<(u32, T)>>> = photons
        .par_chunks(GATHER_CHUNK)
        .map(|chunk| {
            let mut bins: Vec<Vec<(u32, T)>> = (0..n_ranges).map(|_| Vec::new()).collect();
            for photon in chunk {
                grid.for_each_containing(photon.position, |idx| {
                    if let Some(value) = contribution(photon, idx) {
                        bins[idx as usize / range_len].push((idx, value));
                    }
                });
            }
            bins
        })
        .collect();
    // Transpose to one list of bins per range, in chunk order (moves only the Vec headers).
    let mut per_range: Vec<Vec<Vec<(u32, T)>>> = (0..n_ranges)
        .map(|_| Vec::with_capacity(chunks.len()))
        .collect();
    for bins in chunks {
        for (range_bins, bin) in per_range.iter_mut().zip(bins) {
            range_bins.push(bin);
        }
    }
    let mut accumulators = vec![A::default(); n_hitpoints];
    accumulators
        .par_chunks_mut(range_len)
        .zip(per_range.into_par_iter())
        .enumerate()
        .for_each(|(range_idx, (accs, bins))| {
            let first = range_idx * range_len;
            for (idx, value) in bins.into_iter().flatten() {
                accumulate(&mut accs[idx as usize - first], value);
            }
        });
    accumulators
}
