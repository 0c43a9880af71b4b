//! A spatial hash grid over hitpoints, answering "which hitpoints' spheres contain p".

use glam::{Vec3, Vec4};
use rayon::prelude::*;

#[cfg(test)]
mod tests;

/// How the grid picks its cell edge from the hitpoint radii at build time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CellSize {
    /// Base cell edge = factor × largest radius (pbrt and smallppm use 2 × max). With factor ≥ 2
    /// every hitpoint is on level 0, but one large radius makes every cell large.
    MaxRadius(f64),
    /// Base cell edge = factor × mean radius. Hitpoints with R > edge/2 go to coarser levels, so
    /// a spread of radii (dark regions that never shrink next to bright ones that do) costs one
    /// extra bucket per level and query.
    MeanRadius(f64),
}

/// Build parameters of [`HitPointGrid`]. No `Default`: pick a preset.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GridParams {
    /// Cell edge rule.
    pub cell_size: CellSize,
    /// [`HitPointGrid::needs_rebuild`] says yes once the radius statistic of the cell rule (max or
    /// mean) falls below this fraction of its value at build time.
    pub rebuild_below: f64,
}

impl GridParams {
    /// The default: base cell edge 4 × mean radius, rebuild when the mean radius has shrunk to
    /// 0.8 of its build value (chosen with `benches/gather.rs`).
    pub const DEFAULT: Self = Self {
        cell_size: CellSize::MeanRadius(4.0),
        rebuild_below: 0.8,
    };
}

/// A hash grid over hitpoint spheres (centre x, radius R), in compressed sparse row form.
///
/// Every hitpoint is inserted into each grid cell that its bounding box (slightly inflated to
/// absorb rounding) overlaps, so a query looks in exactly one cell per level: the one containing
/// the query point. Level L has cell edge e·2^L and holds the hitpoints with
/// e·2^(L−2) < R ≤ e·2^(L−1) (level 0: all R ≤ e/2), so a hitpoint spans at most 2–3 cells per
/// axis; e comes from [`CellSize`]. Cells of all levels are hashed into one power-of-two table
/// of about 2 × the number of occupied cells (at most 2 × the number of hitpoints);
/// `cell_start[b]..cell_start[b + 1]` indexes bucket b's entries. Sized by the occupied cells
/// rather than the hitpoints, the table stays small while radii are large (tens of hitpoints
/// per cell). Only infinite radii (or R > e·2^47) go to an overflow list scanned by every
/// query.
/// An entry is a hitpoint index (4 bytes); the hitpoint's position and R² are stored once per
/// hitpoint (16 bytes, one quarter of a cache line) and read through the index. Hitpoints given
/// in a spatially coherent order (the Morton order of `morton_order`) keep those reads local:
/// a cell's entries are nearby hitpoints, hence nearby indices. Copying position and R² into
/// every entry instead takes more memory and gathers slower in Morton order
/// (docs/performance.md).
///
/// The stored R² is the largest `f32` not above the exact `f64` R², which makes the `f32` test
/// `|p − x|² ≤ R²_f32` equivalent to [`crate::within_radius`]: the results are exact.
///
/// Build: the (32-bit cell hash, hitpoint) pairs are generated in parallel over fixed chunks of
/// hitpoints, concatenated in chunk order and sorted by hash with a stable LSD radix sort; the
/// distinct hashes give the table size, a bucket being the top bits of the hash. Entries of a
/// bucket are in increasing hitpoint index (buckets holding several cells are sorted and
/// deduplicated) whatever the thread count. No per-cell allocation,
/// no locks. Queries take `&self` and run in parallel freely.
///
/// PPM radii shrink between passes: [`Self::refresh_radii`] copies the new radii into the
/// per-hitpoint records (the cells stay valid because the spheres only shrink), and
/// [`Self::needs_rebuild`] says when smaller cells would pay off. Positions must not change.
#[derive(Clone, Debug)]
pub struct HitPointGrid {
    origin: Vec3,
    /// Level-0 cell edge e.
    cell_edge: f32,
    /// 1 / (e·2^L) for every level L.
    level_inv_cell: Vec<f32>,
    /// Levels holding at least one hitpoint, in increasing order.
    occupied_levels: Vec<u32>,
    hash_shift: u32,
    cell_start: Vec<u32>,
    /// Per hitpoint: position and R² (rounded down to `f32`).
    points: Vec<Vec4>,
    /// Per hitpoint: its level, [`Self::OVERFLOW`], or [`Self::ABSENT`] if skipped at build. A
    /// bucket holds entries of several levels when cells of different levels collide in the
    /// table; a query reports only those of the level it looks up.
    level: Vec<u8>,
    /// Per entry: hitpoint index.
    entry_idx: Vec<u32>,
    /// Hitpoints spanning too many cells, scanned by every query.
    overflow_idx: Vec<u32>,
    reference_radius: f64,
    n_hitpoints: usize,
    params: GridParams,
}

/// Counters describing a built grid.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GridStats {
    /// Number of hitpoints the grid was built from.
    pub n_hitpoints: usize,
    /// Number of hash buckets.
    pub n_buckets: usize,
    /// Number of (bucket, hitpoint) entries.
    pub n_entries: usize,
    /// Hitpoints too large for the cells, scanned by every query.
    pub n_overflow: usize,
    /// Number of occupied levels.
    pub n_levels: usize,
    /// Level-0 cell edge length.
    pub cell_edge: f32,
    /// Heap bytes of the grid.
    pub bytes: usize,
}

/// Hitpoints per parallel work item of the build (fixed, so the result is thread-independent).
const BUILD_CHUNK: usize = 1 << 14;

impl HitPointGrid {
    /// A hitpoint whose bounding box overlaps more cells than this goes to the overflow list
    /// (never happens for finite radii: at most 27 cells plus rounding).
    pub const MAX_CELLS_PER_HITPOINT: usize = 64;

    /// Number of levels; larger radii go to the overflow list.
    const N_LEVELS: u32 = 48;

    /// `level` of a hitpoint in the overflow list.
    const OVERFLOW: u8 = u8::MAX - 1;

    /// `level` of a hitpoint skipped at build (invalid position or radius).
    const ABSENT: u8 = u8::MAX;

    /// Builds the grid over hitpoints `positions[i]` with radii `radii[i]`.
    ///
    /// Hitpoints with a non-finite position or a negative or NaN radius are skipped: they are
    /// never reported. An infinite radius contains every point.
    ///
    /// # Panics
    /// If `positions` and `radii` differ in length, or there are `u32::MAX` hitpoints or more.
    #[must_use]
    pub fn build(positions: &[Vec3], radii: &[f64], params: GridParams) -> Self {
        assert_eq!(positions.len(), radii.len(), "one radius per hitpoint");
        assert!(
            positions.len() < u32::MAX as usize,
            "hitpoint indices must fit in u32"
        );
        let n = positions.len();

        // Bounds and radius statistics of the valid hitpoints (serial: a fixed summation order).
        let mut lo = Vec3::splat(f32::INFINITY);
        let mut hi = Vec3::splat(f32::NEG_INFINITY);
        let (mut max_r, mut sum_r, mut n_finite) = (0.0_f64, 0.0_f64, 0_usize);
        for (&x, &r) in positions.iter().zip(radii) {
            if is_valid(x, r) {
                lo = lo.min(x);
                hi = hi.max(x);
                // Infinite radii go to the overflow list and must not set the cell size.
                if r.is_finite() {
                    max_r = max_r.max(r);
                    sum_r += r;
                    n_finite += 1;
                }
            }
        }
        if !lo.is_finite() {
            lo = Vec3::ZERO;
        }
        let mean_r = if n_finite == 0 {
            0.0
        } else {
            sum_r / n_finite as f64
        };
        let reference_radius = reference(params.cell_size, max_r, mean_r);
        let extent = lo.abs().max(hi.abs()).max_element();
        let extent = if extent.is_finite() { extent } else { 0.0 };
        let factor = match params.cell_size {
            CellSize::MaxRadius(k) | CellSize::MeanRadius(k) => k,
        };
        // Keep the cell edge positive and not absurdly small next to the scene.
        let min_edge = (extent * 2.0_f32.powi(-20)).max(f32::MIN_POSITIVE.sqrt());
        // Rounded up, so that the largest radius of `MaxRadius(2.0)` stays on level 0.
        let cell_edge = f32_at_least(reference_radius * factor).max(min_edge);
        // The largest table: about 2 buckets per hitpoint (see the type's documentation).
        let max_buckets = (2 * n).max(2).next_power_of_two().min(1 << 31);
        let mut grid = Self {
            origin: lo,
            cell_edge,
            level_inv_cell: (0..Self::N_LEVELS)
                .map(|level| 1.0 / cell_edge * 0.5_f32.powi(level as i32))
                .collect(),
            occupied_levels: Vec::new(),
            hash_shift: 32 - max_buckets.trailing_zeros(),
            cell_start: Vec::new(),
            points: Vec::new(),
            level: Vec::new(),
            entry_idx: Vec::new(),
            overflow_idx: Vec::new(),
            reference_radius,
            n_hitpoints: n,
            params,
        };
        // Absolute padding of the boxes: 4 ulps of the largest coordinate, covering the f32
        // rounding of `x ± r` and of `p − x` in the distance test. It stays below `min_edge`.
        let pad = extent * 2.0_f32.powi(-21);

        // (cell hash << 32 | hitpoint) keys in hitpoint order, and the overflow hitpoints.
        let chunks: Vec<(Vec<u64>, Vec<u32>, u64)> = positions
            .par_chunks(BUILD_CHUNK)
            .zip(radii.par_chunks(BUILD_CHUNK))
            .enumerate()
            .map(|(chunk_idx, (xs, rs))| {
                let mut keys = Vec::with_capacity(xs.len() * 4);
                let mut overflow = Vec::new();
                let mut level_mask = 0_u64;
                let mut buckets = [0_u32; Self::MAX_CELLS_PER_HITPOINT];
                for (j, (&x, &r)) in xs.iter().zip(rs).enumerate() {
                    let idx = (chunk_idx * BUILD_CHUNK + j) as u32;
                    if !is_valid(x, r) {
                        continue;
                    }
                    let cells = grid.level_of(r).and_then(|level| {
                        level_mask |= 1 << level;
                        grid.cell_hashes_of(x, r, level, pad, &mut buckets)
                    });
                    match cells {
                        Some(k) => keys.extend(
                            buckets[..k]
                                .iter()
                                .map(|&b| u64::from(b) << 32 | u64::from(idx)),
                        ),
                        None => overflow.push(idx),
                    }
                }
                (keys, overflow, level_mask)
            })
            .collect();
        let mut keys = Vec::with_capacity(chunks.iter().map(|c| c.0.len()).sum());
        let mut level_mask = 0;
        for (chunk_keys, chunk_overflow, chunk_levels) in &chunks {
            keys.extend_from_slice(chunk_keys);
            grid.overflow_idx.extend_from_slice(chunk_overflow);
            level_mask |= chunk_levels;
        }
        grid.occupied_levels = (0..Self::N_LEVELS)
            .filter(|l| level_mask >> l & 1 == 1)
            .collect();
        drop(chunks);
        radix_sort_by_bucket(&mut keys, 32);

        // Table size from the occupied cells (distinct hashes; cells whose hashes collide count
        // once, which only makes the table smaller), then entries and bucket starts.
        let n_cells = 1 + keys.windows(2).filter(|w| w[0] >> 32 != w[1] >> 32).count();
        let n_buckets = (2 * n_cells).next_power_of_two().clamp(2, max_buckets);
        grid.hash_shift = 32 - n_buckets.trailing_zeros();
        assert!(
            u32::try_from(keys.len()).is_ok(),
            "fewer than 2³² grid entries"
        );
        grid.cell_start = vec![0; n_buckets + 1];
        grid.entry_idx = Vec::with_capacity(keys.len());
        let mut i = 0;
        while i < keys.len() {
            let bucket = (keys[i] >> 32) as u32 >> grid.hash_shift;
            let (first_key, first_entry) = (i, grid.entry_idx.len());
            let mut several_cells = false;
            while i < keys.len() && (keys[i] >> 32) as u32 >> grid.hash_shift == bucket {
                several_cells |= keys[i] >> 32 != keys[first_key] >> 32;
                grid.entry_idx.push(keys[i] as u32);
                i += 1;
            }
            if several_cells {
                // Cells sharing the bucket: back to increasing hitpoint index, each once.
                let entries = &mut grid.entry_idx[first_entry..];
                entries.sort_unstable();
                let mut kept = 0;
                for j in 0..entries.len() {
                    if j == 0 || entries[j] != entries[kept - 1] {
                        entries[kept] = entries[j];
                        kept += 1;
                    }
                }
                grid.entry_idx.truncate(first_entry + kept);
            }
            grid.cell_start[bucket as usize + 1] = grid.entry_idx.len() as u32;
        }
        drop(keys);
        // Empty buckets start where the previous one ended.
        for b in 1..grid.cell_start.len() {
            grid.cell_start[b] = grid.cell_start[b].max(grid.cell_start[b - 1]);
        }
        grid.entry_idx.shrink_to_fit();

        // Per-hitpoint records, in parallel (pure maps).
        grid.points = positions
            .par_iter()
            .zip(radii)
            .map(|(&x, &r)| x.extend(radius_sq_down(r)))
            .collect();
        grid.level = positions
            .par_iter()
            .zip(radii)
            .map(|(&x, &r)| {
                if is_valid(x, r) {
                    grid.level_of(r).map_or(Self::OVERFLOW, |l| l as u8)
                } else {
                    Self::ABSENT
                }
            })
            .collect();
        grid
    }

    /// Calls `f(idx)` for exactly the hitpoints with `|p − x_idx|² ≤ R_idx²` (the predicate of
    /// [`crate::within_radius`]), R being the radius of the last build or
    /// [`Self::refresh_radii`]. Each hitpoint is reported once; the order is fixed: level by
    /// level, increasing hitpoint index within a level, then the overflow list.
    #[inline]
    pub fn for_each_containing(&self, p: Vec3, mut f: impl FnMut(u32)) {
        let p4 = p.extend(0.0);
        if let [level] = self.occupied_levels[..] {
            // One level (the common case): every entry of the bucket is of this level.
            for &idx in &self.entry_idx[self.bucket_range(p, level)] {
                if contains(p4, self.points[idx as usize]) {
                    f(idx);
                }
            }
        } else {
            for &level in &self.occupied_levels {
                for &idx in &self.entry_idx[self.bucket_range(p, level)] {
                    if contains(p4, self.points[idx as usize])
                        && u32::from(self.level[idx as usize]) == level
                    {
                        f(idx);
                    }
                }
            }
        }
        for &idx in &self.overflow_idx {
            if contains(p4, self.points[idx as usize]) {
                f(idx);
            }
        }
    }

    /// Copies shrunk radii into the grid; `radii` is indexed by hitpoint like at build time.
    ///
    /// Returns `false` if some radius grew since the last build or refresh (or the length
    /// differs): the grid then keeps the smaller radius for those hitpoints and must be rebuilt.
    /// A negative or NaN radius removes the hitpoint from the results; hitpoints skipped at
    /// build stay absent until the next build.
    #[must_use]
    pub fn refresh_radii(&mut self, radii: &[f64]) -> bool {
        if radii.len() != self.n_hitpoints {
            return false;
        }
        self.points
            .par_iter_mut()
            .zip(self.level.par_iter())
            .zip(radii.par_iter())
            .with_min_len(BUILD_CHUNK)
            .map(|((e, &level), &r)| {
                if level == Self::ABSENT {
                    return true;
                }
                let r2 = radius_sq_down(r);
                // A NaN R² (negative or NaN radius) never matches, as if skipped at build.
                let ok = r2.is_nan() || r2 <= e.w;
                if ok {
                    e.w = r2;
                }
                ok
            })
            .reduce(|| true, |a, b| a && b)
    }

    /// Whether the radii have shrunk enough that a rebuild pays off (or the hitpoint count
    /// changed): the statistic of the cell rule (max or mean radius) is below
    /// `params.rebuild_below` × its build-time value.
    #[must_use]
    pub fn needs_rebuild(&self, radii: &[f64]) -> bool {
        if radii.len() != self.n_hitpoints {
            return true;
        }
        let (mut max_r, mut sum_r, mut n_finite) = (0.0_f64, 0.0_f64, 0_usize);
        for &r in radii {
            if r.is_finite() && r >= 0.0 {
                max_r = max_r.max(r);
                sum_r += r;
                n_finite += 1;
            }
        }
        let mean_r = if n_finite == 0 {
            0.0
        } else {
            sum_r / n_finite as f64
        };
        reference(self.params.cell_size, max_r, mean_r)
            < self.params.rebuild_below * self.reference_radius
    }

    /// Counters and memory of the grid.
    #[must_use]
    pub fn stats(&self) -> GridStats {
        GridStats {
            n_hitpoints: self.n_hitpoints,
            n_buckets: self.cell_start.len() - 1,
            n_entries: self.entry_idx.len(),
            n_overflow: self.overflow_idx.len(),
            n_levels: self.occupied_levels.len(),
            cell_edge: self.cell_edge,
            bytes: (self.cell_start.len() + self.entry_idx.len() + self.overflow_idx.len())
                * size_of::<u32>()
                + self.points.len() * size_of::<Vec4>()
                + self.level.len(),
        }
    }

    /// The entry range of the bucket of `p`'s cell on `level`.
    #[inline]
    fn bucket_range(&self, p: Vec3, level: u32) -> std::ops::Range<usize> {
        let [x, y, z] = self.cell_of(p, level);
        let b = self.bucket(x, y, z, level);
        self.cell_start[b] as usize..self.cell_start[b + 1] as usize
    }

    /// Integer cell coordinates: floor, saturated to the `i32` range (a monotone map).
    #[inline]
    fn cell_of(&self, p: Vec3, level: u32) -> [i32; 3] {
        let c = (p - self.origin) * self.level_inv_cell[level as usize];
        [floor_i32(c.x), floor_i32(c.y), floor_i32(c.z)]
    }

    #[inline]
    fn bucket(&self, x: i32, y: i32, z: i32, level: u32) -> usize {
        (cell_hash(x, y, z, level) >> self.hash_shift) as usize
    }

    /// The level of a hitpoint of radius `r`: the smallest L with 2r ≤ e·2^L; `None` (overflow
    /// list) past the last level.
    fn level_of(&self, r: f64) -> Option<u32> {
        let mut edge = f64::from(self.cell_edge);
        for level in 0..Self::N_LEVELS {
            if 2.0 * r <= edge {
                return Some(level);
            }
            edge *= 2.0;
        }
        None
    }

    /// The distinct hashes of the cells overlapped by the padded box of sphere (x, r) in
    /// `out[..k]`; `None` if it spans more than `MAX_CELLS_PER_HITPOINT` cells.
    fn cell_hashes_of(
        &self,
        x: Vec3,
        r: f64,
        level: u32,
        pad: f32,
        out: &mut [u32; Self::MAX_CELLS_PER_HITPOINT],
    ) -> Option<usize> {
        // Relative padding covers the f32 distance test, absolute padding the coordinates.
        let half = (r * (1.0 + 1e-5)) as f32 + pad;
        let lo = self.cell_of(x - Vec3::splat(half), level);
        let hi = self.cell_of(x + Vec3::splat(half), level);
        let span = |a: usize| (i64::from(hi[a]) - i64::from(lo[a]) + 1) as u64;
        let n_cells = span(0).saturating_mul(span(1)).saturating_mul(span(2));
        if n_cells > Self::MAX_CELLS_PER_HITPOINT as u64 {
            return None;
        }
        // Cells that collide in the table must not list the hitpoint twice: a linear scan, as
        // k is small (8 for most hitpoints).
        let mut k = 0;
        for cz in lo[2]..=hi[2] {
            for cy in lo[1]..=hi[1] {
                for cx in lo[0]..=hi[0] {
                    let b = cell_hash(cx, cy, cz, level);
                    if !out[..k].contains(&b) {
                        out[k] = b;
                        k += 1;
                    }
                }
            }
        }
        Some(k)
    }
}

/// The 32-bit hash of a cell; a bucket is its top bits.
#[inline]
fn cell_hash(x: i32, y: i32, z: i32, level: u32) -> u32 {
    // Teschner et al. 2003 primes, then a Fibonacci multiply keeps the high bits.
    let h = (x as u32).wrapping_mul(73_856_093)
        ^ (y as u32).wrapping_mul(19_349_663)
        ^ (z as u32).wrapping_mul(83_492_791)
        ^ level.wrapping_mul(0x2545_F491);
    h.wrapping_mul(0x9E37_79B1)
}

/// Stable LSD radix sort of `keys` by the `bucket_bits` bits above bit 32 (11 bits per pass).
fn radix_sort_by_bucket(keys: &mut Vec<u64>, bucket_bits: u32) {
    const DIGIT: u32 = 11;
    let mut scratch = vec![0_u64; keys.len()];
    let mut shift = 32;
    while shift < 32 + bucket_bits {
        let mut offsets = vec![0_usize; 1 << DIGIT];
        for &k in keys.iter() {
            offsets[((k >> shift) & ((1 << DIGIT) - 1)) as usize] += 1;
        }
        let mut total = 0;
        for o in &mut offsets {
            (*o, total) = (total, total + *o);
        }
        for &k in keys.iter() {
            let d = ((k >> shift) & ((1 << DIGIT) - 1)) as usize;
            scratch[offsets[d]] = k;
            offsets[d] += 1;
        }
        std::mem::swap(keys, &mut scratch);
        shift += DIGIT;
    }
}

/// The smallest `f32` not below `v`.
fn f32_at_least(v: f64) -> f32 {
    let v32 = v as f32;
    if f64::from(v32) < v {
        v32.next_up()
    } else {
        v32
    }
}

/// `floor(v)` saturated to `i32` (NaN → 0). `f32::floor` is a libm call on baseline x86-64.
#[inline]
fn floor_i32(v: f32) -> i32 {
    let t = v as i32;
    if (t as f32) > v {
        t.saturating_sub(1)
    } else {
        t
    }
}

/// `|p − x|² ≤ R²` for an entry (x, R²), with the rounding of [`distance_sq`]: the lanes
/// compute x − p (the negation of p − x, exactly) and its squares, summed as (x² + y²) + z².
#[inline]
fn contains(p4: Vec4, entry: Vec4) -> bool {
    let d = entry - p4;
    let sq = d * d;
    sq.x + sq.y + sq.z <= entry.w
}

/// The squared distance of [`crate::within_radius`], shared so both round identically.
#[inline]
pub(crate) fn distance_sq(p: Vec3, x: Vec3) -> f32 {
    (p - x).length_squared()
}

fn is_valid(x: Vec3, r: f64) -> bool {
    x.is_finite() && r >= 0.0
}

fn reference(cell_size: CellSize, max_r: f64, mean_r: f64) -> f64 {
    match cell_size {
        CellSize::MaxRadius(_) => max_r,
        CellSize::MeanRadius(_) => mean_r,
    }
}

/// The largest `f32` not above the exact `f64` R², or NaN (never matches) if R is negative or
/// NaN.
///
/// For any `f32` d², `d² ≤ R²_f32` ⟺ `f64(d²) ≤ R²`, so the grid's `f32` test is exact.
fn radius_sq_down(r: f64) -> f32 {
    if r.is_nan() || r < 0.0 {
        return f32::NAN;
    }
    let r2 = r * r;
    let r2_f32 = r2 as f32;
    if f64::from(r2_f32) > r2 {
        r2_f32.next_down()
    } else {
        r2_f32
    }
}
