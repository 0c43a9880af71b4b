//! Heterogeneous media's density: a grid of non-negative densities over an axis-aligned box
//! of a medium's local frame ([`DensityGrid`]), read by trilinear interpolation, as Mitsuba 3's
//! `gridvolume` (`filter_type = "trilinear"`) and pbrt-v4's `SampledGrid` define it.
//!
//! - Samples sit at voxel centres: the box is cut into `nx × ny × nz` cells and the value of
//!   cell (x, y, z) is `data[(z·ny + y)·nx + x]` (x fastest, Mitsuba's `.vol` order and pbrt's
//!   `density` order). A point's grid coordinate is `u·n − ½` per axis (u ∈ [0, 1] across the
//!   box) and its density the trilinear blend of the eight samples around it.
//! - Near the faces the two renderers differ, and [`GridEdge`] says which one a grid follows:
//!   Mitsuba clamps the sample indices to the grid (`wrap_mode = "clamp"`, its default), pbrt
//!   reads zero for samples outside it (so the density halves at a face).
//! - Outside the box the density is zero in both (Mitsuba's heterogeneous medium clips its
//!   rays to the volume's box, `intersect_aabb`; pbrt's `GridMedium` to its bounds).
//!
//! A grid is valid by construction ([`DensityGrid::new`]): at least one voxel per axis, at most
//! [`MAX_GRID_VOXELS`] (checked by [`check_grid_size`] before anything is allocated), finite
//! non-negative densities, a non-empty box and an invertible finite transform.

use glam::{Affine3A, Vec3};

use crate::fingerprint::{Fingerprint, Fingerprinter};

/// The most voxels a grid may have (2²⁸: 1 GiB of `f32`), so that an absurd header is refused
/// before anything is allocated.
pub const MAX_GRID_VOXELS: u64 = 1 << 28;

/// What a grid reads for sample indices outside it, near the faces of its box.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GridEdge {
    /// The nearest sample inside the grid (Mitsuba's `gridvolume`, `wrap_mode = "clamp"`).
    Clamp,
    /// Zero (pbrt-v4's `SampledGrid::Lookup`).
    Zero,
}

impl GridEdge {
    /// Its name in the TOML format and in summaries.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Clamp => "clamp",
            Self::Zero => "zero",
        }
    }
}

/// Why a grid cannot be built.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum GridError {
    /// An axis has no voxel.
    #[error("grid size {0}x{1}x{2} has a zero dimension")]
    ZeroSize(u64, u64, u64),
    /// More voxels than [`MAX_GRID_VOXELS`].
    #[error("grid size {0}x{1}x{2} exceeds the limit of {MAX_GRID_VOXELS} voxels")]
    TooLarge(u64, u64, u64),
    /// The number of values is not the product of the dimensions.
    #[error("grid size {nx}x{ny}x{nz} needs {expected} density values, got {found}")]
    Count {
        /// Voxels along x.
        nx: u32,
        /// Voxels along y.
        ny: u32,
        /// Voxels along z.
        nz: u32,
        /// nx·ny·nz.
        expected: u64,
        /// Values given.
        found: u64,
    },
    /// A density is negative, NaN or infinite.
    #[error("density value {index} is {value} (densities must be finite and >= 0)")]
    Density {
        /// Its index in x-fastest order.
        index: usize,
        /// The value.
        value: f32,
    },
    /// The box is empty or not finite.
    #[error("grid bounds {0:?} to {1:?} are not a finite box with min < max on every axis")]
    Bounds([f32; 3], [f32; 3]),
    /// The local-to-world transform is not finite or not invertible.
    #[error("the grid's transform is not finite and invertible")]
    Transform,
}

/// Checks grid dimensions before allocation: every axis at least one voxel, at most
/// [`MAX_GRID_VOXELS`] in all. Returns the voxel count.
///
/// # Errors
///
/// [`GridError::ZeroSize`] or [`GridError::TooLarge`].
pub fn check_grid_size(nx: u64, ny: u64, nz: u64) -> Result<usize, GridError> {
    if nx == 0 || ny == 0 || nz == 0 {
        return Err(GridError::ZeroSize(nx, ny, nz));
    }
    match nx
        .checked_mul(ny)
        .and_then(|n| n.checked_mul(nz))
        .filter(|&n| n <= MAX_GRID_VOXELS)
    {
        Some(n) => Ok(n as usize),
        None => Err(GridError::TooLarge(nx, ny, nz)),
    }
}

/// A density grid over the box `[min, max]` of a local frame, placed in the world by an affine
/// transform (see the module's documentation for the interpolation).
#[derive(Clone, Debug, PartialEq)]
pub struct DensityGrid {
    size: [u32; 3],
    data: Vec<f32>,
    edge: GridEdge,
    min: Vec3,
    max: Vec3,
    to_world: Affine3A,
    to_local: Affine3A,
    max_density: f32,
    /// Majorant cells per axis (at most [`MAJORANT_CELLS`]).
    cells: [u32; 3],
    /// The largest density that trilinear lookups can return inside each majorant cell, x
    /// fastest.
    majorants: Vec<f32>,
}

/// Majorant cells per axis at most: a coarse grid of local maxima, so that free flights and
/// transmittances take short steps only where the medium is dense (pbrt-v4's 16³
/// `majorantGrid`).
pub const MAJORANT_CELLS: u32 = 16;

/// One stretch `[t0, t1]` of a ray inside one majorant cell, and that cell's largest density.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MajorantSegment {
    /// Where the ray enters the cell (or the box, or 0).
    pub t0: f32,
    /// Where it leaves it (or the box, or `t_max`).
    pub t1: f32,
    /// The largest density there.
    pub max_density: f32,
}

impl DensityGrid {
    /// A grid of `size` voxels with `data` in x-fastest order over the local box `[min, max]`,
    /// placed by `to_world` (local to world).
    ///
    /// # Errors
    ///
    /// A [`GridError`] for zero or too many voxels, a value count that is not nx·ny·nz, a
    /// negative or non-finite density, an empty box or a singular transform.
    pub fn new(
        size: [u32; 3],
        data: Vec<f32>,
        edge: GridEdge,
        min: Vec3,
        max: Vec3,
        to_world: Affine3A,
    ) -> Result<Self, GridError> {
        let [nx, ny, nz] = size;
        let expected = check_grid_size(u64::from(nx), u64::from(ny), u64::from(nz))?;
        if data.len() != expected {
            return Err(GridError::Count {
                nx,
                ny,
                nz,
                expected: expected as u64,
                found: data.len() as u64,
            });
        }
        let mut max_density = 0.0f32;
        for (index, &value) in data.iter().enumerate() {
            if !(value.is_finite() && value >= 0.0) {
                return Err(GridError::Density { index, value });
            }
            max_density = max_density.max(value);
        }
        if !(min.is_finite() && max.is_finite() && min.cmplt(max).all()) {
            return Err(GridError::Bounds(min.to_array(), max.to_array()));
        }
        let det = to_world.matrix3.determinant();
        if !to_world.is_finite() || det == 0.0 || !det.is_finite() {
            return Err(GridError::Transform);
        }
        let to_local = to_world.inverse();
        if !to_local.is_finite() {
            return Err(GridError::Transform);
        }
        let (cells, majorants) = majorant_cells(size, &data);
        Ok(Self {
            size,
            data,
            edge,
            min,
            max,
            to_world,
            to_local,
            max_density,
            cells,
            majorants,
        })
    }

    /// The same grid placed by `to_world` instead (an importer's change of frame).
    ///
    /// # Errors
    ///
    /// [`GridError::Transform`] if `to_world` is not finite and invertible.
    pub fn placed(&self, to_world: Affine3A) -> Result<Self, GridError> {
        Self::new(
            self.size,
            self.data.clone(),
            self.edge,
            self.min,
            self.max,
            to_world,
        )
    }

    /// Voxels along x, y and z.
    #[must_use]
    pub fn size(&self) -> [u32; 3] {
        self.size
    }

    /// The densities, x fastest.
    #[must_use]
    pub fn data(&self) -> &[f32] {
        &self.data
    }

    /// What samples outside the grid read.
    #[must_use]
    pub fn edge(&self) -> GridEdge {
        self.edge
    }

    /// The box in the local frame, (min, max).
    #[must_use]
    pub fn bounds(&self) -> (Vec3, Vec3) {
        (self.min, self.max)
    }

    /// Local to world.
    #[must_use]
    pub fn to_world(&self) -> Affine3A {
        self.to_world
    }

    /// The largest density of the grid (no interpolated value exceeds it).
    #[must_use]
    pub fn max_density(&self) -> f32 {
        self.max_density
    }

    /// The sample (x, y, z), by the edge rule outside the grid.
    #[inline]
    fn sample(&self, x: i64, y: i64, z: i64) -> f32 {
        let [nx, ny, nz] = self.size.map(i64::from);
        let (x, y, z) = match self.edge {
            GridEdge::Clamp => (x.clamp(0, nx - 1), y.clamp(0, ny - 1), z.clamp(0, nz - 1)),
            GridEdge::Zero => {
                if x < 0 || y < 0 || z < 0 || x >= nx || y >= ny || z >= nz {
                    return 0.0;
                }
                (x, y, z)
            }
        };
        self.data[((z * ny + y) * nx + x) as usize]
    }

    /// The density at `p` of the local frame: trilinear between voxel centres, zero outside
    /// the box.
    #[must_use]
    pub fn density_local(&self, p: Vec3) -> f32 {
        let u = (p - self.min) / (self.max - self.min);
        if !(u.cmpge(Vec3::ZERO).all() && u.cmple(Vec3::ONE).all()) {
            return 0.0;
        }
        let n = Vec3::new(
            self.size[0] as f32,
            self.size[1] as f32,
            self.size[2] as f32,
        );
        let s = u * n - 0.5;
        let i = s.floor();
        let f = s - i;
        let (x, y, z) = (i.x as i64, i.y as i64, i.z as i64);
        let lerp = |a: f32, b: f32, t: f32| a + (b - a) * t;
        let row = |y: i64, z: i64| lerp(self.sample(x, y, z), self.sample(x + 1, y, z), f.x);
        let plane = |z: i64| lerp(row(y, z), row(y + 1, z), f.y);
        lerp(plane(z), plane(z + 1), f.z).max(0.0)
    }

    /// The density at the world point `p`.
    #[inline]
    #[must_use]
    pub fn density(&self, p: Vec3) -> f32 {
        self.density_local(self.to_local.transform_point3(p))
    }

    /// The stretch `[t0, t1]` of the ray `origin + t·direction`, `0 ≤ t ≤ t_max`, inside the
    /// box (outside it the density is zero); `None` if the ray misses it. An affine map keeps
    /// the ray's parameter, so the interval is found in the local frame.
    #[must_use]
    pub fn clip(&self, origin: Vec3, direction: Vec3, t_max: f32) -> Option<(f32, f32)> {
        let o = self.to_local.transform_point3(origin);
        let d = self.to_local.transform_vector3(direction);
        let (mut t0, mut t1) = (0.0f32, t_max);
        for axis in 0..3 {
            let (lo, hi) = (self.min[axis], self.max[axis]);
            if d[axis] == 0.0 {
                if o[axis] < lo || o[axis] > hi {
                    return None;
                }
                continue;
            }
            let inv = 1.0 / d[axis];
            let (a, b) = ((lo - o[axis]) * inv, (hi - o[axis]) * inv);
            let (near, far) = if a <= b { (a, b) } else { (b, a) };
            t0 = t0.max(near);
            t1 = t1.min(far);
            // (A NaN bound fails too.)
            if t0.is_nan() || t1.is_nan() || t0 > t1 {
                return None;
            }
        }
        Some((t0, t1))
    }
}

/// The majorant grid of a density grid of `size` voxels: per axis min(n, [`MAJORANT_CELLS`])
/// cells, each the maximum of every sample whose trilinear footprint can reach it, widened by one
/// sample on each side (so that a point that rounding puts just outside its cell is still
/// bounded). Samples outside the grid are zero or clamped copies, neither larger than this.
fn majorant_cells(size: [u32; 3], data: &[f32]) -> ([u32; 3], Vec<f32>) {
    let cells = size.map(|n| n.min(MAJORANT_CELLS));
    // The samples each cell of each axis depends on: cell c covers u ∈ [c/m, (c+1)/m], i.e.
    // grid coordinates s = u·n − ½ in [c·n/m − ½, (c+1)·n/m − ½], read from samples
    // floor(s_lo) to floor(s_hi) + 1.
    let ranges = |axis: usize| -> Vec<(usize, usize)> {
        let (n, m) = (f64::from(size[axis]), f64::from(cells[axis]));
        (0..cells[axis])
            .map(|c| {
                let lo = (f64::from(c) * n / m - 0.5).floor() - 1.0;
                let hi = (f64::from(c + 1) * n / m - 0.5).floor() + 2.0;
                (
                    lo.clamp(0.0, n - 1.0) as usize,
                    hi.clamp(0.0, n - 1.0) as usize,
                )
            })
            .collect()
    };
    let (rx, ry, rz) = (ranges(0), ranges(1), ranges(2));
    let (nx, ny) = (size[0] as usize, size[1] as usize);
    let mut majorants = Vec::with_capacity(rx.len() * ry.len() * rz.len());
    for &(z0, z1) in &rz {
        for &(y0, y1) in &ry {
            for &(x0, x1) in &rx {
                let mut peak = 0.0f32;
                for z in z0..=z1 {
                    for y in y0..=y1 {
                        let row = (z * ny + y) * nx;
                        for &v in &data[row + x0..=row + x1] {
                            peak = peak.max(v);
                        }
                    }
                }
                majorants.push(peak);
            }
        }
    }
    (cells, majorants)
}

impl DensityGrid {
    /// The stretches of the ray `origin + t·direction`, `0 ≤ t ≤ t_max`, inside the box, one
    /// per majorant cell it crosses in order, each with the cell's largest density (a 3D DDA
    /// over the majorant grid, as pbrt-v4's `DDAMajorantIterator`). Empty if the ray misses
    /// the box.
    #[must_use]
    pub fn majorant_segments(
        &self,
        origin: Vec3,
        direction: Vec3,
        t_max: f32,
    ) -> Vec<MajorantSegment> {
        let mut out = Vec::new();
        let Some((t_in, t_out)) = self.clip(origin, direction, t_max) else {
            return out;
        };
        let m = Vec3::new(
            self.cells[0] as f32,
            self.cells[1] as f32,
            self.cells[2] as f32,
        );
        // The ray in majorant-cell coordinates (the box is [0, m]).
        let extent = self.max - self.min;
        let o = (self.to_local.transform_point3(origin) - self.min) / extent * m;
        let d = self.to_local.transform_vector3(direction) / extent * m;
        let entry = o + d * t_in;
        let mut cell = [0i64; 3];
        let mut next = [f32::INFINITY; 3];
        let mut delta = [f32::INFINITY; 3];
        let mut step = [0i64; 3];
        for a in 0..3 {
            let last = i64::from(self.cells[a]) - 1;
            cell[a] = (entry[a].floor() as i64).clamp(0, last);
            if d[a] > 0.0 {
                next[a] = t_in + ((cell[a] + 1) as f32 - entry[a]) / d[a];
                delta[a] = 1.0 / d[a];
                step[a] = 1;
            } else if d[a] < 0.0 {
                next[a] = t_in + (cell[a] as f32 - entry[a]) / d[a];
                delta[a] = -1.0 / d[a];
                step[a] = -1;
            }
        }
        let (cx, cy) = (i64::from(self.cells[0]), i64::from(self.cells[1]));
        let mut t = t_in;
        // Every crossing moves one cell along one axis: at most the sum of the cells.
        let most = self.cells.iter().map(|&c| c as usize).sum::<usize>() + 3;
        for _ in 0..most {
            let axis = if next[0] <= next[1] && next[0] <= next[2] {
                0
            } else if next[1] <= next[2] {
                1
            } else {
                2
            };
            let t1 = next[axis].min(t_out).max(t);
            let index = ((cell[2] * cy + cell[1]) * cx + cell[0]) as usize;
            out.push(MajorantSegment {
                t0: t,
                t1,
                max_density: self.majorants[index],
            });
            if t1 >= t_out {
                break;
            }
            t = t1;
            cell[axis] += step[axis];
            if cell[axis] < 0 || cell[axis] >= i64::from(self.cells[axis]) {
                break;
            }
            next[axis] += delta[axis];
        }
        // The DDA's last crossing and the box's exit differ by rounding: the last cell runs to
        // the exit (its majorant is widened by a sample, which covers the difference).
        if let Some(last) = out.last_mut() {
            last.t1 = t_out;
        }
        out
    }
}

impl Fingerprint for DensityGrid {
    /// Size, edge rule, box, placement and every density.
    fn fingerprint(&self, h: &mut Fingerprinter) {
        for n in self.size {
            h.u32(n);
        }
        h.str(self.edge.name());
        h.vec3(self.min);
        h.vec3(self.max);
        for column in self.to_world.to_cols_array() {
            h.f32(column);
        }
        for &v in &self.data {
            h.f32(v);
        }
    }
}

#[cfg(test)]
#[path = "density_grid_tests.rs"]
mod tests;
