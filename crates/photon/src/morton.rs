//! Morton (Z-order) sorting of points, to make gather queries coherent.

use glam::Vec3;
use rayon::prelude::*;

/// Indices of `points` in Morton (Z-curve) order over their bounding box, 21 bits per axis.
///
/// Gathering photons in this order instead of emission order keeps consecutive queries in the
/// same grid buckets (several times faster, see `benches/gather.rs`). The order is a pure
/// function of the points (ties keep the index order); non-finite points go last. Keys and sort
/// run in parallel; the result does not depend on the thread count.
#[must_use]
pub fn morton_order(points: &[Vec3]) -> Vec<u32> {
    let mut scratch = MortonScratch::default();
    morton_keys(&[points], |&p| p, &mut scratch);
    scratch
        .keys
        .into_par_iter()
        .map(|(_, i)| i as u32)
        .collect()
}

/// Copies the items of `chunks` (concatenated in chunk order) into `out` in the Morton order of
/// their positions `position(item)`: the order of [`morton_order`] over the concatenated
/// positions, without concatenating them first.
///
/// `scratch` and `out` are buffers the caller keeps across calls: their capacity is reused, so
/// repeated sorts of similar sizes do not allocate.
///
/// # Panics
/// If there are 2³² chunks or more, or a chunk has 2³² items or more.
pub fn morton_sort<T, C>(
    chunks: &[C],
    position: impl Fn(&T) -> Vec3 + Sync,
    scratch: &mut MortonScratch,
    out: &mut Vec<T>,
) where
    T: Copy + Send + Sync,
    C: AsRef<[T]> + Sync,
{
    morton_keys(chunks, position, scratch);
    out.clear();
    out.par_extend(
        scratch
            .keys
            .par_iter()
            .map(|&(_, i)| chunks[(i >> 32) as usize].as_ref()[(i & 0xFFFF_FFFF) as usize]),
    );
}

/// The key buffers of [`morton_sort`], kept by the caller across calls.
#[derive(Clone, Debug, Default)]
pub struct MortonScratch {
    /// `(Morton key, chunk << 32 | index in chunk)`, sorted.
    keys: Vec<(u64, u64)>,
    /// The other buffer of the counting sort.
    spare: Vec<(u64, u64)>,
}

impl MortonScratch {
    /// Heap bytes of the key buffers (allocated capacities).
    #[must_use]
    pub fn heap_bytes(&self) -> usize {
        (self.keys.capacity() + self.spare.capacity()) * std::mem::size_of::<(u64, u64)>()
    }
}

/// `(Morton key, chunk << 32 | index in chunk)` of every item, sorted. The bounding box is a
/// min/max reduction (exact in any order) and the pairs are distinct, so the parallel unstable
/// sort has one result, which orders ties by position in the concatenation.
fn morton_keys<T, C>(
    chunks: &[C],
    position: impl Fn(&T) -> Vec3 + Sync,
    scratch: &mut MortonScratch,
) where
    T: Sync,
    C: AsRef<[T]> + Sync,
{
    assert!(
        u32::try_from(chunks.len()).is_ok()
            && chunks
                .iter()
                .all(|c| u32::try_from(c.as_ref().len()).is_ok()),
        "chunk counts and sizes must fit in u32"
    );
    let empty = || (Vec3::INFINITY, Vec3::NEG_INFINITY);
    let (lo, hi) = chunks
        .par_iter()
        .flat_map_iter(|c| c.as_ref().iter().map(&position))
        .filter(|p| p.is_finite())
        .fold(empty, |(lo, hi), p| (lo.min(p), hi.max(p)))
        .reduce(empty, |(lo_a, hi_a), (lo_b, hi_b)| {
            (lo_a.min(lo_b), hi_a.max(hi_b))
        });
    let scale = ((1 << 21) - 1) as f32 / (hi - lo).max_element().max(f32::MIN_POSITIVE);
    let key = |p: Vec3| {
        if p.is_finite() {
            let c = ((p - lo) * scale).as_uvec3();
            spread(c.x) | spread(c.y) << 1 | spread(c.z) << 2
        } else {
            u64::MAX
        }
    };
    let MortonScratch { keys, spare } = scratch;
    // One slice of `keys` per chunk, filled in parallel.
    keys.clear();
    keys.resize(chunks.iter().map(|c| c.as_ref().len()).sum(), (0, 0));
    let mut slices = Vec::with_capacity(chunks.len());
    let mut rest = &mut keys[..];
    for chunk in chunks {
        let (head, tail) = rest.split_at_mut(chunk.as_ref().len());
        slices.push(head);
        rest = tail;
    }
    slices
        .into_par_iter()
        .zip(chunks.par_iter())
        .enumerate()
        .for_each(|(c, (slice, chunk))| {
            for (j, (k, item)) in slice.iter_mut().zip(chunk.as_ref()).enumerate() {
                *k = (key(position(item)), (c as u64) << 32 | j as u64);
            }
        });
    sort_keys(keys, spare);
}

/// Sorts distinct `(key, index)` pairs: one stable counting-sort pass on the top bits of the
/// key (into `scratch`), then each bucket sorted on its own, in parallel. The pairs are
/// distinct, so the order is the one of a plain sort; it is 2–3× faster than
/// `par_sort_unstable` on a million pairs because the bucket sorts stay in cache.
fn sort_keys(keys: &mut Vec<(u64, u64)>, scratch: &mut Vec<(u64, u64)>) {
    /// Bits of the counting pass: the top 11 of the 63-bit Morton keys, plus 1 for the
    /// non-finite key `u64::MAX`.
    const BITS: u32 = 12;
    const SHIFT: u32 = 64 - BITS;
    if keys.len() < 1 << 12 {
        keys.sort_unstable();
        return;
    }
    let mut starts = vec![0_usize; (1 << BITS) + 1];
    for &(key, _) in keys.iter() {
        starts[(key >> SHIFT) as usize + 1] += 1;
    }
    for b in 1..starts.len() {
        starts[b] += starts[b - 1];
    }
    scratch.clear();
    scratch.resize(keys.len(), (0, 0));
    let mut next = starts.clone();
    for &pair in keys.iter() {
        let b = (pair.0 >> SHIFT) as usize;
        scratch[next[b]] = pair;
        next[b] += 1;
    }
    let mut buckets = Vec::with_capacity(1 << BITS);
    let mut rest = &mut scratch[..];
    for b in 0..1 << BITS {
        let (bucket, tail) = rest.split_at_mut(starts[b + 1] - starts[b]);
        buckets.push(bucket);
        rest = tail;
    }
    buckets
        .into_par_iter()
        .with_min_len(16)
        .for_each(|bucket| bucket.sort_unstable());
    std::mem::swap(keys, scratch);
}

/// Spreads the low 21 bits of `v` to every third bit.
fn spread(v: u32) -> u64 {
    let mut x = u64::from(v) & 0x1F_FFFF;
    x = (x | x << 32) & 0x001F_0000_0000_FFFF;
    x = (x | x << 16) & 0x001F_0000_FF00_00FF;
    x = (x | x << 8) & 0x100F_00F0_0F00_F00F;
    x = (x | x << 4) & 0x10C3_0C30_C30C_30C3;
    x = (x | x << 2) & 0x1249_2492_4924_9249;
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bucketed_sort_equals_a_plain_sort() {
        // Enough pairs for the counting pass, with clustered keys, duplicates keys (distinct
        // indices) and the non-finite key.
        let mut state = 0x2545_F491_4F6C_DD1D_u64;
        let mut keys: Vec<(u64, u64)> = (0..50_000_u64)
            .map(|i| {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                let key = match i % 7 {
                    0 => u64::MAX,
                    1 => 12345,
                    _ => state >> (1 + i % 40),
                };
                (key, i)
            })
            .collect();
        let mut expected = keys.clone();
        expected.sort_unstable();
        sort_keys(&mut keys, &mut Vec::new());
        assert_eq!(keys, expected);
    }

    #[test]
    fn spread_interleaves() {
        assert_eq!(spread(0b111), 0b1001001);
        assert_eq!(spread(0x1F_FFFF), 0x1249_2492_4924_9249);
    }

    #[test]
    fn order_is_a_permutation_following_the_curve() {
        let points = [
            Vec3::ONE,
            Vec3::ZERO,
            Vec3::new(f32::NAN, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
        ];
        assert_eq!(morton_order(&points), [1, 3, 0, 2]);
        assert!(morton_order(&[]).is_empty());
        let (mut scratch, mut out) = (MortonScratch::default(), Vec::new());
        // The same order over chunks, ties in concatenation order.
        let chunks = [
            vec![points[0], points[1]],
            vec![],
            vec![points[2], points[3], points[1]],
        ];
        morton_sort(&chunks, |&p| p, &mut scratch, &mut out);
        assert_eq!(out[..4], [points[1], points[1], points[3], points[0]]);
        assert!(out[4].x.is_nan());
    }
}
