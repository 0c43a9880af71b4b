//! A deterministic parallel photon gather: per-hitpoint accumulation without locks.

use rayon::prelude::*;

use crate::grid::HitPointGrid;
use crate::photon::Photon;

/// Photons per parallel work item. Fixed, so the work split does not depend on the thread count.
const GATHER_CHUNK: usize = 4096;

/// Gathers `photons` into per-hitpoint accumulators, in parallel and bit-reproducibly.
///
/// For every photon p (in slice order) and every hitpoint h whose sphere contains it
/// ([`HitPointGrid::for_each_containing`], in its fixed order), `contribution(p, h)` decides
/// whether the photon counts (e.g. [`crate::accepts`]) and what it brings (e.g. the BSDF-weighted
/// flux, a frequency estimate); `accumulate(&mut acc[h], value)` then folds it in.
///
/// `contribution` runs in parallel over fixed chunks of photons, each chunk recording its
/// `(hitpoint, value)` pairs in order. `accumulate` then runs on the calling thread, chunk by
/// chunk, so every accumulator sees its values in photon order whatever the thread count:
/// floating-point sums are identical for 1, 2 or 8 threads. There are no locks and no atomics.
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
    mut accumulate: impl FnMut(&mut A, T),
) -> Vec<A>
where
    T: Send,
    A: Default + Clone,
{
    let chunks: Vec<Vec<(u32, T)>> = photons
        .par_chunks(GATHER_CHUNK)
        .map(|chunk| {
            let mut pairs = Vec::new();
            for photon in chunk {
                grid.for_each_containing(photon.position, |idx| {
                    if let Some(value) = contribution(photon, idx) {
                        pairs.push((idx, value));
                    }
                });
            }
            pairs
        })
        .collect();
    let mut accumulators = vec![A::default(); n_hitpoints];
    for (idx, value) in chunks.into_iter().flatten() {
        accumulate(&mut accumulators[idx as usize], value);
    }
    accumulators
}
