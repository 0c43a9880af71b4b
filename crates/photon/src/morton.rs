//! Morton (Z-order) sorting of points, to make gather queries coherent.
//!
//! Keys are 30-bit Morton codes (10 bits per axis over the points' bounding box, so cells of a
//! thousandth of the box: far finer than any gather radius, which is all the order is for),
//! packed with the point's place in the input as `key << 32 | item` and sorted by a stable
//! least-significant-digit radix sort on the key. Ties (points in one cell) therefore keep their
//! input order, and the order is a pure function of the points.
//!
//! A radix sort over all the keys, rather than buckets of a counting pass each sorted on its
//! own, keeps every pass parallel and its work even, however unevenly the photons fill space
//! (docs/performance.md has the figures).

use glam::Vec3;
use rayon::prelude::*;

/// Indices of `points` in Morton (Z-curve) order over their bounding box, 10 bits per axis.
///
/// Gathering photons in this order instead of emission order keeps consecutive queries in the
/// same grid buckets (several times faster, see `benches/gather.rs`). The order is a pure
/// function of the points (ties, points in one of the 2³⁰ cells, keep the index order);
/// non-finite points go last. Keys and sort run in parallel; the result does not depend on the
/// thread count.
///
/// # Panics
/// If there are 2³² points or more.
#[must_use]
pub fn morton_order(points: &[Vec3]) -> Vec<u32> {
    let mut scratch = MortonScratch::default();
    morton_keys(&[points], |&p| p, &mut scratch);
    scratch
        .keys
        .into_par_iter()
        // One chunk: the item is the index.
        .map(|packed| packed as u32)
        .collect()
}

/// Copies the items of `chunks` (concatenated in chunk order) into `out` in the Morton order of
/// their positions `position(item)`: the order of [`morton_order`] over the concatenated
/// positions, without concatenating them first.
///
/// `scratch` and `out` are buffers the caller keeps across calls: their capacity is reused, so
/// repeated sorts of similar sizes do not allocate.
///
/// The bounding box with the keys and the final copy each cost more than the sort itself
/// (docs/performance.md).
///
/// # Panics
/// If there are 2³² items or more.
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
    let MortonScratch {
        keys,
        starts,
        item_bits,
        ..
    } = scratch;
    out.clear();
    match *item_bits {
        Some(bits) => out.par_extend(keys.par_iter().map(|&packed| {
            let item = packed as u32;
            chunks[(item >> bits) as usize].as_ref()[(item & ((1 << bits) - 1)) as usize]
        })),
        None => out.par_extend(keys.par_iter().map(|&packed| {
            let index = packed as u32 as usize;
            // The last chunk starting at or before `index` (empty chunks share their start
            // with the next one, so the one found is never empty).
            let chunk = starts.partition_point(|&start| start <= index) - 1;
            chunks[chunk].as_ref()[index - starts[chunk]]
        })),
    }
}

/// The key buffers of [`morton_sort`], kept by the caller across calls.
#[derive(Clone, Debug, Default)]
pub struct MortonScratch {
    /// `Morton key << 32 | item`, sorted, where the item is `chunk << item_bits | index in the
    /// chunk` when that fits in 32 bits, else the index in the concatenation. Either way items
    /// increase along the concatenation.
    keys: Vec<u64>,
    /// The other buffer of the radix sort.
    spare: Vec<u64>,
    /// Index in the concatenation of the first item of each chunk.
    starts: Vec<usize>,
    /// Bits of the index in the chunk in an item, if chunk and index fit in 32 bits (the copy
    /// then reads an item's chunk from its bits instead of searching `starts`, which is
    /// several times slower).
    item_bits: Option<u32>,
}

impl MortonScratch {
    /// Heap bytes of the key buffers (allocated capacities).
    #[must_use]
    pub fn heap_bytes(&self) -> usize {
        (self.keys.capacity() + self.spare.capacity()) * std::mem::size_of::<u64>()
            + self.starts.capacity() * std::mem::size_of::<usize>()
    }
}

/// The key of non-finite points: after every Morton code.
const NON_FINITE: u64 = 1 << 30;

/// Fills `scratch.keys` with `key << 32 | item` of every item (see [`MortonScratch::keys`]),
/// sorted, `scratch.starts` with the chunks' first indices and `scratch.item_bits`. The bounding box is a min/max reduction (exact in any
/// order).
fn morton_keys<T, C>(
    chunks: &[C],
    position: impl Fn(&T) -> Vec3 + Sync,
    scratch: &mut MortonScratch,
) where
    T: Sync,
    C: AsRef<[T]> + Sync,
{
    let MortonScratch {
        keys,
        spare,
        starts,
        item_bits,
    } = scratch;
    starts.clear();
    let (mut n, mut longest) = (0_usize, 0_usize);
    for chunk in chunks {
        starts.push(n);
        n += chunk.as_ref().len();
        longest = longest.max(chunk.as_ref().len());
    }
    assert!(
        u32::try_from(n).is_ok(),
        "at most 2³² - 1 items can be sorted"
    );
    let bits = usize::BITS - longest.leading_zeros();
    *item_bits = (bits + (usize::BITS - chunks.len().leading_zeros()) <= 32).then_some(bits);
    let item_bits = *item_bits;
    let empty = (Vec3::INFINITY, Vec3::NEG_INFINITY);
    let (lo, hi) = chunks
        .par_iter()
        .map(|chunk| {
            chunk
                .as_ref()
                .iter()
                .map(&position)
                .fold(empty, |(lo, hi), p| {
                    if p.is_finite() {
                        (lo.min(p), hi.max(p))
                    } else {
                        (lo, hi)
                    }
                })
        })
        .reduce(
            || empty,
            |(lo_a, hi_a), (lo_b, hi_b)| (lo_a.min(lo_b), hi_a.max(hi_b)),
        );
    let scale = 1023.0 / (hi - lo).max_element().max(f32::MIN_POSITIVE);
    let key = |p: Vec3| {
        if p.is_finite() {
            // At most 1023 (and at least 0) per axis: `as` saturates.
            let c = ((p - lo) * scale).as_uvec3().min(glam::UVec3::splat(1023));
            spread(c.x) | spread(c.y) << 1 | spread(c.z) << 2
        } else {
            NON_FINITE
        }
    };
    // One slice of `keys` per chunk, filled in parallel.
    keys.clear();
    keys.resize(n, 0);
    let mut slices = Vec::with_capacity(chunks.len());
    let mut rest = &mut keys[..];
    for chunk in chunks {
        let (head, tail) = rest.split_at_mut(chunk.as_ref().len());
        slices.push(head);
        rest = tail;
    }
    slices
        .into_par_iter()
        .zip(chunks.par_iter().zip(starts.par_iter()))
        .enumerate()
        .for_each(|(c, (slice, (chunk, &start)))| {
            let first = match item_bits {
                Some(bits) => (c as u64) << bits,
                None => start as u64,
            };
            for (j, (k, item)) in slice.iter_mut().zip(chunk.as_ref()).enumerate() {
                *k = key(position(item)) << 32 | (first + j as u64);
            }
        });
    sort_keys(keys, spare);
}

/// Bits of one radix digit: three passes cover the 31-bit keys (8-bit digits need four, and
/// measure slower).
const DIGIT_BITS: u32 = 11;
const RADIX: usize = 1 << DIGIT_BITS;
/// Blocks of a radix pass at most (the same for any thread count, so the result is too).
const BLOCKS: usize = 32;
/// Keys per block at least: a block's histogram, cursors and runs cost a few steps per digit
/// (`RADIX` of them), which smaller blocks do not earn back.
const MIN_BLOCK_LEN: usize = 1 << 16;

/// Sorts `packed = key << 32 | item` values, given in increasing item order, by key with ties
/// in item order (so in increasing order of `packed`): three stable least-significant-digit
/// radix passes over the key's 31 bits, with `spare` as the other buffer.
fn sort_keys(keys: &mut Vec<u64>, spare: &mut Vec<u64>) {
    let n = keys.len();
    spare.clear();
    spare.resize(n, 0);
    let blocks = (n / MIN_BLOCK_LEN).clamp(1, BLOCKS);
    let block_len = n.div_ceil(blocks).max(1);
    for pass in 0..3 {
        if radix_pass(keys, spare, 32 + pass * DIGIT_BITS, block_len) {
            std::mem::swap(keys, spare);
        }
    }
}

/// One stable counting pass of `src` into `dst` on the digit at bit `shift`: each block of
/// `block_len` values counts its digits, the counts give every (digit, block) pair its own
/// range of `dst` (digits in order, blocks in order within a digit), and the blocks scatter
/// into their ranges in parallel. Returns false, writing nothing, when every value has the same
/// digit (the pass would not move anything).
fn radix_pass(src: &[u64], dst: &mut [u64], shift: u32, block_len: usize) -> bool {
    let digit = |packed: u64| (packed >> shift) as usize & (RADIX - 1);
    let counts: Vec<Vec<usize>> = src
        .par_chunks(block_len)
        .map(|block| {
            let mut count = vec![0_usize; RADIX];
            for &packed in block {
                count[digit(packed)] += 1;
            }
            count
        })
        .collect();
    if (0..RADIX).any(|d| counts.iter().map(|c| c[d]).sum::<usize>() == src.len()) {
        return false;
    }
    let mut ranges: Vec<Vec<&mut [u64]>> =
        counts.iter().map(|_| Vec::with_capacity(RADIX)).collect();
    let mut rest = dst;
    for d in 0..RADIX {
        for (block, count) in counts.iter().enumerate() {
            let (range, tail) = std::mem::take(&mut rest).split_at_mut(count[d]);
            ranges[block].push(range);
            rest = tail;
        }
    }
    src.par_chunks(block_len)
        .zip(ranges.into_par_iter().zip(counts.par_iter()))
        .for_each(|(block, (ranges, count))| {
            // The block sorted by digit on its own (a counting sort into a buffer of its size,
            // with plain indices), then each digit's run copied to its range of `dst`: twice the
            // writes of scattering straight into `dst`, but without a cursor per digit to load
            // and store back, which costs more than the extra writes.
            let mut next = [0_usize; RADIX];
            let mut run_start = 0;
            for (d, &c) in count.iter().enumerate() {
                next[d] = run_start;
                run_start += c;
            }
            let mut sorted = vec![0_u64; block.len()];
            for &packed in block {
                let d = digit(packed);
                sorted[next[d]] = packed;
                next[d] += 1;
            }
            let mut runs = &sorted[..];
            for (range, &c) in ranges.into_iter().zip(count) {
                let (run, rest) = runs.split_at(c);
                range.copy_from_slice(run);
                runs = rest;
            }
        });
    true
}

/// Spreads the low 10 bits of `v` to every third bit.
fn spread(v: u32) -> u64 {
    let mut x = u64::from(v) & 0x3FF;
    x = (x | x << 16) & 0x0300_00FF;
    x = (x | x << 8) & 0x0300_F00F;
    x = (x | x << 4) & 0x030C_30C3;
    x = (x | x << 2) & 0x0924_9249;
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Packed values in index order with clustered keys, duplicate keys and the non-finite key,
    /// enough of them for several blocks.
    fn packed(n: u64) -> Vec<u64> {
        let mut state = 0x2545_F491_4F6C_DD1D_u64;
        (0..n)
            .map(|i| {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                let key = match i % 7 {
                    0 => NON_FINITE,
                    1 => 12345,
                    _ => (state >> 34) >> (i % 20),
                };
                key << 32 | i
            })
            .collect()
    }

    #[test]
    fn radix_sort_equals_a_plain_sort() {
        // One block up to 131 071 values, four for 300 001 (the last one short), 32 (the most)
        // for 2 500 003.
        for n in [0, 1, 5, 1000, 70_000, 300_001, 2_500_003] {
            let mut keys = packed(n);
            let mut expected = keys.clone();
            expected.sort_unstable();
            sort_keys(&mut keys, &mut Vec::new());
            assert_eq!(keys, expected, "{n} values");
        }
    }

    #[test]
    fn a_pass_with_one_digit_moves_nothing() {
        let src: Vec<u64> = (0..100).map(|i| 7 << 32 | i).collect();
        let mut dst = vec![0; 100];
        assert!(!radix_pass(&src, &mut dst, 32, 10));
        assert!(radix_pass(&src, &mut dst, 0, 10));
    }

    #[test]
    fn spread_interleaves() {
        assert_eq!(spread(0b111), 0b1001001);
        assert_eq!(spread(0x3FF), 0x0924_9249);
        assert_eq!(
            spread(0x3FF) | spread(0x3FF) << 1 | spread(0x3FF) << 2,
            (1 << 30) - 1
        );
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
            vec![],
        ];
        morton_sort(&chunks, |&p| p, &mut scratch, &mut out);
        assert_eq!(out[..4], [points[1], points[1], points[3], points[0]]);
        assert!(out[4].x.is_nan());
    }

    #[test]
    fn items_that_do_not_fit_in_32_bits_are_found_by_their_index() {
        // 2²² + 1 chunks (23 bits) and a chunk of 1500 items (11 bits): no room for both.
        let points: Vec<Vec3> = (0..1500).map(|i| Vec3::new(i as f32, 0.0, 0.0)).collect();
        let mut chunks: Vec<&[Vec3]> = vec![&[]; 1 << 22];
        chunks.push(&points);
        chunks.swap(0, 1 << 21);
        let (mut scratch, mut out) = (MortonScratch::default(), Vec::new());
        morton_sort(&chunks, |&p| p, &mut scratch, &mut out);
        assert_eq!(scratch.item_bits, None);
        assert_eq!(out, points);
    }

    #[test]
    fn sort_over_chunks_matches_the_order_of_the_concatenation() {
        let mut state = 1_u32;
        let mut next = || {
            state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (state >> 8) as f32 / (1 << 24) as f32
        };
        // Many points on few distinct positions (ties), in chunks of uneven sizes.
        let points: Vec<Vec3> = (0..100_000)
            .map(|_| (Vec3::new(next(), next(), next()) * 8.0).floor())
            .collect();
        let order = morton_order(&points);
        let mut seen = vec![false; points.len()];
        for &i in &order {
            assert!(!std::mem::replace(&mut seen[i as usize], true));
        }
        let chunks: Vec<&[Vec3]> = points.chunks(777).collect();
        let (mut scratch, mut out) = (MortonScratch::default(), Vec::new());
        morton_sort(&chunks, |&p| p, &mut scratch, &mut out);
        let expected: Vec<Vec3> = order.iter().map(|&i| points[i as usize]).collect();
        assert_eq!(out, expected);
        // Ties keep the index order.
        for pair in order.windows(2) {
            let (a, b) = (points[pair[0] as usize], points[pair[1] as usize]);
            if a == b {
                assert!(pair[0] < pair[1]);
            }
        }
    }
}
