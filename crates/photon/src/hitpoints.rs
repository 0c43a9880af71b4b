//! Hitpoint storage: a structure of arrays, one column per field.

use glam::Vec3;

/// One hitpoint, as the camera pass produces it: the input of [`HitPoints::push`].
///
/// The progressive statistics start from the given radius, count 0 and zero flux.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NewHitPoint<F> {
    /// Surface position.
    pub position: Vec3,
    /// Unit shading normal (for the BSDF).
    pub shading_normal: Vec3,
    /// Unit geometric normal, faced toward `outgoing` (for the side test of [`crate::accepts`]).
    pub geometric_normal: Vec3,
    /// Unit direction toward the camera (where the eye path came from).
    pub outgoing: Vec3,
    /// Material index; the integrator re-creates the BSDF from it and the normals.
    pub material_idx: u32,
    /// Throughput weight of the eye path up to this hitpoint (RGB).
    pub weight: Vec3,
    /// Initial gather radius.
    pub radius: f64,
    /// Initial frequency state.
    pub freq: F,
}

/// Hitpoints in a structure of arrays: all columns have the same length.
///
/// Column types and why:
/// - geometry (`position`, normals, `outgoing`, `weight`) is `f32`, like the rest of the renderer;
/// - the progressive statistics are `f64`: the radius R, the accumulated photon count N and the
///   flux τ. Over millions of passes R² shrinks geometrically (R² ∝ N^(α−1)) and N grows without
///   bound; `f32` would lose N increments once N > 2²⁴ · M and would make the τ·R′²/R²
///   rescaling drift. The doubles cost 40 of the 136 bytes.
/// - the frequency state is a generic column `F` (the integrator plugs in the `spectrum`
///   accumulator, which itself knows whether a frequency photon was merged).
///
/// Nothing derivable is stored: the pixel of a hitpoint is a function of its index (the
/// integrator lays the slots out pixel by pixel), the "has a frequency photon" flag is part of
/// `F`. Use [`Self::bytes_per_hitpoint`] for the memory cost; with a 32-byte `F` it is 136 bytes.
#[derive(Clone, Debug, Default)]
pub struct HitPoints<F> {
    position: Vec<Vec3>,
    shading_normal: Vec<Vec3>,
    geometric_normal: Vec<Vec3>,
    outgoing: Vec<Vec3>,
    material_idx: Vec<u32>,
    weight: Vec<Vec3>,
    radius: Vec<f64>,
    photon_count: Vec<f64>,
    flux: Vec<[f64; 3]>,
    freq: Vec<F>,
}

/// Mutable views of the columns a pass updates, borrowed together from [`HitPoints::columns_mut`].
///
/// Slices, so the lengths cannot change and the columns stay aligned.
#[derive(Debug)]
pub struct HitPointColumnsMut<'a, F> {
    /// Gather radius R.
    pub radius: &'a mut [f64],
    /// Accumulated (α-weighted) photon count N.
    pub photon_count: &'a mut [f64],
    /// Accumulated flux τ (RGB).
    pub flux: &'a mut [[f64; 3]],
    /// Frequency state.
    pub freq: &'a mut [F],
    /// Throughput weight (SPPM rewrites it each pass).
    pub weight: &'a mut [Vec3],
}

impl<F: Copy + Default> HitPoints<F> {
    /// Empty storage with room for `n_hitpoints`.
    #[must_use]
    pub fn with_capacity(n_hitpoints: usize) -> Self {
        Self {
            position: Vec::with_capacity(n_hitpoints),
            shading_normal: Vec::with_capacity(n_hitpoints),
            geometric_normal: Vec::with_capacity(n_hitpoints),
            outgoing: Vec::with_capacity(n_hitpoints),
            material_idx: Vec::with_capacity(n_hitpoints),
            weight: Vec::with_capacity(n_hitpoints),
            radius: Vec::with_capacity(n_hitpoints),
            photon_count: Vec::with_capacity(n_hitpoints),
            flux: Vec::with_capacity(n_hitpoints),
            freq: Vec::with_capacity(n_hitpoints),
        }
    }

    /// Appends a hitpoint with count 0 and zero flux; returns its index.
    pub fn push(&mut self, hitpoint: NewHitPoint<F>) -> usize {
        debug_assert!(hitpoint.radius >= 0.0, "radius must be non-negative");
        let idx = self.position.len();
        self.position.push(hitpoint.position);
        self.shading_normal.push(hitpoint.shading_normal);
        self.geometric_normal.push(hitpoint.geometric_normal);
        self.outgoing.push(hitpoint.outgoing);
        self.material_idx.push(hitpoint.material_idx);
        self.weight.push(hitpoint.weight);
        self.radius.push(hitpoint.radius);
        self.photon_count.push(0.0);
        self.flux.push([0.0; 3]);
        self.freq.push(hitpoint.freq);
        idx
    }

    /// Overwrites where hitpoint `idx` is (position, normals, outgoing direction, material,
    /// weight) and keeps its progressive statistics (R, N, τ, frequency state): the SPPM camera pass, which re-traces the visible point of each slot every
    /// pass while the statistics carry over. `hitpoint.radius` and `hitpoint.freq` are ignored.
    ///
    /// # Panics
    ///
    /// If `idx` is out of range (an internal invariant of the caller).
    pub fn replace_visible_point(&mut self, idx: usize, hitpoint: &NewHitPoint<F>) {
        self.position[idx] = hitpoint.position;
        self.shading_normal[idx] = hitpoint.shading_normal;
        self.geometric_normal[idx] = hitpoint.geometric_normal;
        self.outgoing[idx] = hitpoint.outgoing;
        self.material_idx[idx] = hitpoint.material_idx;
        self.weight[idx] = hitpoint.weight;
    }

    /// Number of hitpoints.
    #[must_use]
    pub fn len(&self) -> usize {
        self.position.len()
    }

    /// Whether there are no hitpoints.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.position.is_empty()
    }

    /// Removes all hitpoints, keeping the allocations.
    pub fn clear(&mut self) {
        self.position.clear();
        self.shading_normal.clear();
        self.geometric_normal.clear();
        self.outgoing.clear();
        self.material_idx.clear();
        self.weight.clear();
        self.radius.clear();
        self.photon_count.clear();
        self.flux.clear();
        self.freq.clear();
    }

    /// Memory of one hitpoint: the sum of the element sizes of all columns.
    #[must_use]
    pub const fn bytes_per_hitpoint() -> usize {
        use std::mem::size_of;
        5 * size_of::<Vec3>()
            + size_of::<u32>()
            + 2 * size_of::<f64>()
            + size_of::<[f64; 3]>()
            + size_of::<F>()
    }

    /// Heap bytes of all columns: their allocated capacities times the element sizes.
    #[must_use]
    pub fn heap_bytes(&self) -> usize {
        use std::mem::size_of;
        (self.position.capacity()
            + self.shading_normal.capacity()
            + self.geometric_normal.capacity()
            + self.outgoing.capacity()
            + self.weight.capacity())
            * size_of::<Vec3>()
            + self.material_idx.capacity() * size_of::<u32>()
            + (self.radius.capacity() + self.photon_count.capacity()) * size_of::<f64>()
            + self.flux.capacity() * size_of::<[f64; 3]>()
            + self.freq.capacity() * size_of::<F>()
    }

    /// Positions.
    #[must_use]
    pub fn position(&self) -> &[Vec3] {
        &self.position
    }

    /// Unit shading normals.
    #[must_use]
    pub fn shading_normal(&self) -> &[Vec3] {
        &self.shading_normal
    }

    /// Unit geometric normals, faced toward the outgoing direction.
    #[must_use]
    pub fn geometric_normal(&self) -> &[Vec3] {
        &self.geometric_normal
    }

    /// Unit outgoing directions (toward the camera).
    #[must_use]
    pub fn outgoing(&self) -> &[Vec3] {
        &self.outgoing
    }

    /// Material indices.
    #[must_use]
    pub fn material_idx(&self) -> &[u32] {
        &self.material_idx
    }

    /// Throughput weights.
    #[must_use]
    pub fn weight(&self) -> &[Vec3] {
        &self.weight
    }

    /// Gather radii R.
    #[must_use]
    pub fn radius(&self) -> &[f64] {
        &self.radius
    }

    /// Accumulated photon counts N.
    #[must_use]
    pub fn photon_count(&self) -> &[f64] {
        &self.photon_count
    }

    /// Accumulated flux τ.
    #[must_use]
    pub fn flux(&self) -> &[[f64; 3]] {
        &self.flux
    }

    /// Frequency states.
    #[must_use]
    pub fn freq(&self) -> &[F] {
        &self.freq
    }

    /// The columns a pass updates, borrowed mutably together.
    pub fn columns_mut(&mut self) -> HitPointColumnsMut<'_, F> {
        HitPointColumnsMut {
            radius: &mut self.radius,
            photon_count: &mut self.photon_count,
            flux: &mut self.flux,
            freq: &mut self.freq,
            weight: &mut self.weight,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bytes_per_hitpoint_with_32_byte_state() {
        assert_eq!(HitPoints::<[f32; 8]>::bytes_per_hitpoint(), 136);
        assert!(HitPoints::<[f32; 8]>::bytes_per_hitpoint() < 200);
    }

    #[test]
    fn push_clear_and_columns() {
        let mut hits = HitPoints::<u8>::with_capacity(2);
        assert!(hits.is_empty());
        let idx = hits.push(NewHitPoint {
            position: Vec3::X,
            shading_normal: Vec3::Z,
            geometric_normal: Vec3::Z,
            outgoing: Vec3::Z,
            material_idx: 3,
            weight: Vec3::ONE,
            radius: 0.5,
            freq: 9,
        });
        assert_eq!(idx, 0);
        assert_eq!(hits.len(), 1);
        assert_eq!(hits.material_idx(), &[3]);
        assert_eq!(hits.photon_count(), &[0.0]);
        let cols = hits.columns_mut();
        cols.radius[0] = 0.25;
        cols.freq[0] = 4;
        assert_eq!(hits.radius(), &[0.25]);
        assert_eq!(hits.freq(), &[4]);
        hits.clear();
        assert!(hits.is_empty());
    }
}
