//! Phase 2 of a pass: the spatial index over the hitpoint spheres. PPM keeps its grid from
//! pass to pass while the radii only shrink within their levels; SPPM, with new visible points
//! every pass, rebuilds it.

use glam::Vec3;
use photon::{GridParams, HitPointGrid, HitPoints};

use super::frequency::SlotFrequency;

/// The grid entry of a slot the grid does not index (no visible point this pass).
pub(super) const NOT_IN_GRID: u32 = u32::MAX;

/// The hash grid over the valid slots and the slot of each of its entries.
#[derive(Default)]
pub(super) struct Index {
    grid: Option<HitPointGrid>,
    /// Slot index of each grid entry (the grid indexes the valid slots only, in the Morton
    /// order of their positions, so that the gather of Morton-sorted photons touches nearby
    /// entries).
    grid_slots: Vec<u32>,
}

impl Index {
    /// Brings the index up to date with `slots`, of which those with `is_valid` hold a visible
    /// point: refreshes the radii of the grid if `keep_entries` (the visible points did not
    /// move) and the grid allows it, else rebuilds it.
    pub(super) fn update(
        &mut self,
        slots: &HitPoints<SlotFrequency>,
        is_valid: impl Fn(usize) -> bool,
        keep_entries: bool,
    ) {
        let radii = self.radii(slots);
        let keep = keep_entries
            && match self.grid.as_mut() {
                None => false,
                Some(grid) => grid.refresh_radii(&radii) && !grid.needs_rebuild(&radii),
            };
        if keep {
            return;
        }
        let valid: Vec<u32> = (0..slots.len() as u32)
            .filter(|&s| is_valid(s as usize))
            .collect();
        let positions: Vec<Vec3> = valid
            .iter()
            .map(|&s| slots.position()[s as usize])
            .collect();
        self.grid_slots = photon::morton_order(&positions)
            .into_iter()
            .map(|i| valid[i as usize])
            .collect();
        let positions: Vec<Vec3> = self
            .grid_slots
            .iter()
            .map(|&s| slots.position()[s as usize])
            .collect();
        let radii = self.radii(slots);
        self.grid = Some(HitPointGrid::build(&positions, &radii, GridParams::DEFAULT));
    }

    /// The grid, if built.
    pub(super) fn grid(&self) -> Option<&HitPointGrid> {
        self.grid.as_ref()
    }

    /// The slot of each grid entry.
    pub(super) fn grid_slots(&self) -> &[u32] {
        &self.grid_slots
    }

    /// Heap bytes of the grid and its slot map.
    pub(super) fn heap_bytes(&self) -> usize {
        self.grid.as_ref().map_or(0, |g| g.stats().bytes)
            + self.grid_slots.capacity() * std::mem::size_of::<u32>()
    }

    /// Current radius of each grid entry.
    fn radii(&self, slots: &HitPoints<SlotFrequency>) -> Vec<f64> {
        self.grid_slots
            .iter()
            .map(|&s| slots.radius()[s as usize])
            .collect()
    }
}
