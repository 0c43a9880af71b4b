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
    let mut keys = Vec::new();
    morton_keys(&[points], |&p| p, &mut keys);
    keys.into_par_iter().map(|(_, i)| i as u32).collect()
}

/// Copies the items of `chunks` (concatenated in chunk order) into `out` in the Morton order of
/// their positions `position(item)`: the order of [`morton_order`] over the concatenated
/// positions, without concatenating them first.
///
/// `keys` and `out` are scratch buffers the caller keeps across calls: their capacity is
/// reused, so repeated sorts of similar sizes do not allocate.
///
/// # Panics
/// If there are 2³² chunks or more, or a chunk has 2³² items or more.
pub fn morton_sort<T, C>(
    chunks: &[C],
    position: impl Fn(&T) -> Vec3 + Sync,
    keys: &mut Vec<(u64, u64)>,
    out: &mut Vec<T>,
) where
    T: Copy + Send + Sync,
    C: AsRef<[T]> + Sync,
{
    morton_keys(chunks, position, keys);
    out.clear();
    out.par_extend(
        keys.par_iter()
            .map(|&(_, i)| chunks[(i >> 32) as usize].as_ref()[(i & 0xFFFF_FFFF) as usize]),
    );
}

/// `(Morton key, chunk << 32 | index in chunk)` of every item, sorted. The bounding box is a
/// min/max reduction (exact in any order) and the pairs are distinct, so the parallel unstable
/// sort has one result, which orders ties by position in the concatenation.
fn morton_keys<T, C>(chunks: &[C], position: impl Fn(&T) -> Vec3 + Sync, keys: &mut Vec<(u64, u64)>)
where
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
    keys.par_sort_unstable();
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
        let (mut keys, mut out) = (Vec::new(), Vec::new());
        // The same order over chunks, ties in concatenation order.
        let chunks = [
            vec![points[0], points[1]],
            vec![],
            vec![points[2], points[3], points[1]],
        ];
        morton_sort(&chunks, |&p| p, &mut keys, &mut out);
        assert_eq!(out[..4], [points[1], points[1], points[3], points[0]]);
        assert!(out[4].x.is_nan());
    }
}
