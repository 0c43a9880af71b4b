//! A spatial hash grid over hitpoints, answering "which hitpoints' spheres contain p".

use glam::Vec3;

use crate::photon::within_radius;

#[cfg(test)]
mod tests;

/// How the grid picks its cell edge from the hitpoint radii at build time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CellSize {
    /// Cell edge = factor × largest radius (pbrt and smallppm use 2 × max). Every hitpoint spans
    /// at most 2 cells per axis, but one large radius makes every cell large.
    MaxRadius(f64),
    /// Cell edge = factor × mean radius. Robust to a few large radii: a hitpoint that would span
    /// more than [`HitPointGrid::MAX_CELLS_PER_HITPOINT`] cells goes to an overflow list that every
    /// query scans.
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
    /// The measured default: cell edge 2 × mean radius, rebuild when the mean radius has shrunk
    /// to 0.8 of its build value (see `benches/gather.rs`).
    pub const DEFAULT: Self = Self {
        cell_size: CellSize::MeanRadius(2.0),
        rebuild_below: 0.8,
    };
}

/// A hash grid over hitpoint spheres (centre, radius R), in compressed sparse row form.
///
/// Every hitpoint is inserted into each grid cell that its bounding box (slightly inflated to
/// absorb rounding) overlaps, so a query looks in exactly one cell: the one containing the query
/// point. Cells are hashed into a power-of-two table of about 2 × the number of hitpoints;
/// `cell_start[b]..cell_start[b + 1]` indexes the bucket's entries in `entries`. Each entry
/// copies the hitpoint's position and squared build-time radius, so a query reads one
/// contiguous run of memory and touches the caller's radius column only for true candidates.
///
/// The build is a serial two-pass counting sort: deterministic, entries within a bucket are in
/// increasing hitpoint index, no per-cell allocation and no locks. Queries take `&self` and run
/// in parallel freely.
///
/// Radii may shrink after the build (as in PPM) but must not grow: queries use the build-time
/// radius to find candidates. Positions must not change.
#[derive(Clone, Debug)]
pub struct HitPointGrid {
    origin: Vec3,
    inv_cell: f32,
    cell_edge: f32,
    hash_shift: u32,
    cell_start: Vec<u32>,
    entries: Vec<Entry>,
    overflow: Vec<Entry>,
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
    /// Cell edge length.
    pub cell_edge: f32,
    /// Heap bytes of the grid.
    pub bytes: usize,
}

/// One hitpoint in one bucket: 20 bytes.
#[derive(Clone, Copy, Debug)]
struct Entry {
    position: Vec3,
    /// Build-time R², rounded up to `f32`.
    radius_sq: f32,
    idx: u32,
}

impl HitPointGrid {
    /// A hitpoint whose bounding box overlaps more cells than this goes to the overflow list.
    pub const MAX_CELLS_PER_HITPOINT: usize = 64;

    /// Builds the grid over hitpoints `positions[i]` with radii `radii[i]`.
    ///
    /// Hitpoints with a non-finite position or a negative or NaN radius are skipped: they are
    /// never reported. An infinite radius contains every point.
    ///
    /// # Panics
    /// If `positions` and `radii` differ in length, or there are more than `u32::MAX` hitpoints.
    #[must_use]
    pub fn build(positions: &[Vec3], radii: &[f64], params: GridParams) -> Self {
        assert_eq!(positions.len(), radii.len(), "one radius per hitpoint");
        assert!(
            u32::try_from(positions.len()).is_ok(),
            "hitpoint indices must fit in u32"
        );
        let n = positions.len();

        // Bounds and radius statistics of the valid hitpoints.
        let mut lo = Vec3::splat(f32::INFINITY);
        let mut hi = Vec3::splat(f32::NEG_INFINITY);
        let (mut max_r, mut sum_r, mut n_valid) = (0.0_f64, 0.0_f64, 0_usize);
        for (&x, &r) in positions.iter().zip(radii) {
            if is_valid(x, r) {
                lo = lo.min(x);
                hi = hi.max(x);
                // Infinite radii go to the overflow list and must not set the cell size.
                if r.is_finite() {
                    max_r = max_r.max(r);
                    sum_r += r;
                    n_valid += 1;
                }
            }
        }
        if n_valid == 0 {
            lo = Vec3::ZERO;
        }
        let mean_r = if n_valid == 0 {
            0.0
        } else {
            sum_r / n_valid as f64
        };
        let reference_radius = reference(params.cell_size, max_r, mean_r);
        let extent = lo.abs().max(hi.abs()).max_element();
        let extent = if extent.is_finite() { extent } else { 0.0 };
        let factor = match params.cell_size {
            CellSize::MaxRadius(k) | CellSize::MeanRadius(k) => k,
        };
        // Keep the cell edge positive and not absurdly small next to the scene.
        let min_edge = (extent * 2.0_f32.powi(-20)).max(f32::MIN_POSITIVE.sqrt());
        let cell_edge = ((reference_radius * factor) as f32).max(min_edge);
        let n_buckets = (2 * n).max(2).next_power_of_two();
        let mut grid = Self {
            origin: lo,
            inv_cell: 1.0 / cell_edge,
            cell_edge,
            hash_shift: 32 - n_buckets.trailing_zeros(),
            cell_start: vec![0; n_buckets + 1],
            entries: Vec::new(),
            overflow: Vec::new(),
            reference_radius,
            n_hitpoints: n,
            params,
        };
        // Absolute padding of the boxes: 4 ulps of the largest coordinate, covering the f32
        // rounding of `x ± r` and of `p − x` in the distance test. It stays below `min_edge`.
        let pad = extent * 2.0_f32.powi(-21);

        // Pass 1: count entries per bucket.
        let mut buckets = [0_u32; Self::MAX_CELLS_PER_HITPOINT];
        let mut counts = vec![0_u32; n_buckets];
        let mut overflow = Vec::new();
        for (i, (&x, &r)) in positions.iter().zip(radii).enumerate() {
            if !is_valid(x, r) {
                continue;
            }
            match grid.buckets_of(x, r, pad, &mut buckets) {
                Some(k) => buckets[..k].iter().for_each(|&b| counts[b as usize] += 1),
                None => overflow.push(i),
            }
        }

        // Exclusive prefix sum into `cell_start`, then pass 2 fills the entries in index order.
        let mut total = 0_u32;
        for (start, &count) in grid.cell_start.iter_mut().zip(&counts) {
            *start = total;
            total += count;
        }
        grid.cell_start[n_buckets] = total;
        let mut cursor = grid.cell_start[..n_buckets].to_vec();
        let placeholder = Entry {
            position: Vec3::ZERO,
            radius_sq: 0.0,
            idx: u32::MAX,
        };
        grid.entries = vec![placeholder; total as usize];
        for (i, (&x, &r)) in positions.iter().zip(radii).enumerate() {
            if !is_valid(x, r) {
                continue;
            }
            if let Some(k) = grid.buckets_of(x, r, pad, &mut buckets) {
                let entry = Entry {
                    position: x,
                    radius_sq: radius_sq_up(r),
                    idx: i as u32,
                };
                for &b in &buckets[..k] {
                    grid.entries[cursor[b as usize] as usize] = entry;
                    cursor[b as usize] += 1;
                }
            }
        }
        grid.overflow = overflow
            .into_iter()
            .map(|i| Entry {
                position: positions[i],
                radius_sq: radius_sq_up(radii[i]),
                idx: i as u32,
            })
            .collect();
        grid
    }

    /// Calls `f(idx)` for every hitpoint whose **build-time** sphere contains `p`, with R² rounded
    /// up to `f32`: a superset of [`Self::for_each_containing`]. Order: bucket order (increasing
    /// index), then the overflow list (increasing index).
    #[inline]
    pub fn for_each_candidate(&self, p: Vec3, mut f: impl FnMut(u32)) {
        self.for_each_entry(p, |e| {
            if within_radius(p, e.position, f64::from(e.radius_sq)) {
                f(e.idx);
            }
        });
    }

    /// Calls `f(idx)` for exactly the hitpoints with `|p − x_idx|² ≤ radii[idx]²` (the predicate
    /// of [`crate::within_radius`]), each once, in the order of [`Self::for_each_candidate`].
    /// Hitpoints skipped at build (see [`Self::build`]) are never reported.
    ///
    /// `radii` is the current radius column; each radius must be at most its build-time value.
    #[inline]
    pub fn for_each_containing(&self, p: Vec3, radii: &[f64], mut f: impl FnMut(u32)) {
        debug_assert_eq!(
            radii.len(),
            self.n_hitpoints,
            "radius column of the built hitpoints"
        );
        self.for_each_entry(p, |e| {
            if within_radius(p, e.position, f64::from(e.radius_sq)) {
                let r = radii[e.idx as usize];
                debug_assert!(
                    f64::from(e.radius_sq) >= r * r,
                    "radii must not grow after build"
                );
                if within_radius(p, e.position, r * r) {
                    f(e.idx);
                }
            }
        });
    }

    /// Whether the radii have shrunk enough that a rebuild pays off (or the hitpoint count
    /// changed): the statistic of the cell rule (max or mean radius) is below
    /// `params.rebuild_below` × its build-time value.
    #[must_use]
    pub fn needs_rebuild(&self, radii: &[f64]) -> bool {
        if radii.len() != self.n_hitpoints {
            return true;
        }
        let (mut max_r, mut sum_r, mut n_valid) = (0.0_f64, 0.0_f64, 0_usize);
        for &r in radii {
            if r.is_finite() && r >= 0.0 {
                max_r = max_r.max(r);
                sum_r += r;
                n_valid += 1;
            }
        }
        let mean_r = if n_valid == 0 {
            0.0
        } else {
            sum_r / n_valid as f64
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
            n_entries: self.entries.len(),
            n_overflow: self.overflow.len(),
            cell_edge: self.cell_edge,
            bytes: self.cell_start.len() * size_of::<u32>()
                + (self.entries.len() + self.overflow.len()) * size_of::<Entry>(),
        }
    }

    /// Visits the entries of `p`'s bucket, then the overflow list.
    #[inline]
    fn for_each_entry(&self, p: Vec3, mut f: impl FnMut(&Entry)) {
        let [x, y, z] = self.cell_of(p);
        let b = self.bucket(x, y, z);
        let (start, end) = (self.cell_start[b] as usize, self.cell_start[b + 1] as usize);
        self.entries[start..end].iter().for_each(&mut f);
        self.overflow.iter().for_each(f);
    }

    /// Integer cell coordinates; `as` saturates, which keeps the map monotone.
    #[inline]
    fn cell_of(&self, p: Vec3) -> [i32; 3] {
        let c = ((p - self.origin) * self.inv_cell).floor();
        [c.x as i32, c.y as i32, c.z as i32]
    }

    #[inline]
    fn bucket(&self, x: i32, y: i32, z: i32) -> usize {
        // Teschner et al. 2003 primes, then a Fibonacci multiply keeps the high bits.
        let h = (x as u32).wrapping_mul(73_856_093)
            ^ (y as u32).wrapping_mul(19_349_663)
            ^ (z as u32).wrapping_mul(83_492_791);
        (h.wrapping_mul(0x9E37_79B1) >> self.hash_shift) as usize
    }

    /// The distinct buckets of the cells overlapped by the padded box of sphere (x, r), sorted,
    /// in `out[..k]`; `None` if it spans more than `MAX_CELLS_PER_HITPOINT` cells.
    fn buckets_of(
        &self,
        x: Vec3,
        r: f64,
        pad: f32,
        out: &mut [u32; Self::MAX_CELLS_PER_HITPOINT],
    ) -> Option<usize> {
        // Relative padding covers the f32 distance test, absolute padding the coordinates.
        let half = (r * (1.0 + 1e-5)) as f32 + pad;
        let lo = self.cell_of(x - Vec3::splat(half));
        let hi = self.cell_of(x + Vec3::splat(half));
        let span = |a: usize| (i64::from(hi[a]) - i64::from(lo[a]) + 1) as u64;
        let n_cells = span(0).saturating_mul(span(1)).saturating_mul(span(2));
        if n_cells > Self::MAX_CELLS_PER_HITPOINT as u64 {
            return None;
        }
        let mut k = 0;
        for cz in lo[2]..=hi[2] {
            for cy in lo[1]..=hi[1] {
                for cx in lo[0]..=hi[0] {
                    out[k] = self.bucket(cx, cy, cz) as u32;
                    k += 1;
                }
            }
        }
        // Cells that collide in the table must not list the hitpoint twice.
        let cells = &mut out[..k];
        cells.sort_unstable();
        let mut n_distinct = 0;
        for j in 0..k {
            if j == 0 || cells[j] != cells[n_distinct - 1] {
                cells[n_distinct] = cells[j];
                n_distinct += 1;
            }
        }
        Some(n_distinct)
    }
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

/// R² as an `f32` that is not below the exact `f64` value.
fn radius_sq_up(r: f64) -> f32 {
    let r2 = r * r;
    let r2_f32 = r2 as f32;
    if f64::from(r2_f32) < r2 {
        r2_f32.next_up()
    } else {
        r2_f32
    }
}
