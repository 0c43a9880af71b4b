//! The merge radius at a point: the pass's global radius, or with frequency-sized merges
//! (`vcm_freq_radius`) the smaller of it and the frequency prediction there.
//!
//! The prediction is a function of position fixed for the whole render: a world-space hash grid
//! whose cells hold the smallest radius that the frequency analysis lets a kernel hold at the
//! visible points of a pilot (`freq_pilot` passes of freq-sppm from the render's seed, at least
//! one; the radius of `Aov::FreqRadius` bounded by the clear disc, as the photon mappers hold
//! it). Because r(x) is known before a pass traces anything, both ends of a path compute the
//! same η(x) = n_L·π·r(x)² at every vertex, and the MIS weights stay a function of the path;
//! because the pilot depends only on the scene and the parameters, every pass (and every work
//! unit, which runs the pilot again) sees the same field, so passes stay independent.

use std::collections::HashMap;
use std::sync::Arc;

use glam::Vec3;
use scene::Scene;

use crate::integrator::Integrator;
use crate::params::{Method, RenderParams};
use crate::photon_mapper::PhotonMapper;

/// The smallest predicted radius per cell of a world-space grid.
pub(crate) struct FrequencyField {
    /// 1 / the cells' edge.
    inverse_cell: f64,
    cells: HashMap<[i32; 3], f32>,
}

impl FrequencyField {
    /// The field of the predictions `(position, radius)` on cells of edge `cell`.
    pub(crate) fn new(predictions: &[(Vec3, f64)], cell: f64) -> Self {
        let mut field = Self {
            inverse_cell: 1.0 / cell,
            cells: HashMap::new(),
        };
        for &(p, r) in predictions {
            if !(r.is_finite() && r > 0.0) {
                continue;
            }
            let Some(key) = field.key(p) else {
                continue;
            };
            // A minimum per cell: the same field whatever the order of the predictions.
            let r = r as f32;
            field
                .cells
                .entry(key)
                .and_modify(|v| *v = v.min(r))
                .or_insert(r);
        }
        field
    }

    fn key(&self, p: Vec3) -> Option<[i32; 3]> {
        let cell = |x: f32| {
            let c = (f64::from(x) * self.inverse_cell).floor();
            (c.abs() < f64::from(i32::MAX)).then_some(c as i32)
        };
        Some([cell(p.x)?, cell(p.y)?, cell(p.z)?])
    }

    /// The predicted radius at `p`, if any visible point of its cell had one.
    pub(crate) fn at(&self, p: Vec3) -> Option<f64> {
        self.cells.get(&self.key(p)?).map(|&r| f64::from(r))
    }

    /// Cells holding a prediction.
    #[cfg(test)]
    pub(crate) fn len(&self) -> usize {
        self.cells.len()
    }

    /// Heap bytes, about (a hash map entry of 16 bytes and its control byte, at most 8/7 full).
    pub(crate) fn heap_bytes(&self) -> usize {
        self.cells.capacity() * 17
    }
}

/// The field of a render of `scene` with `params`: a pilot of `max(freq_pilot, 1)` passes of
/// freq-sppm from the render's seed, and cells of edge `cell` (the first pass's radius r₀).
pub(crate) fn pilot_field(scene: &Arc<Scene>, params: RenderParams, cell: f64) -> FrequencyField {
    let mut pilot_params = params;
    pilot_params.method = Method::FreqSppm;
    // The render's own parameters passed the same checks; a pilot that cannot start predicts
    // nothing, and every merge keeps the global radius.
    let Ok(mut pilot) = PhotonMapper::new(Arc::clone(scene), pilot_params) else {
        return FrequencyField::new(&[], cell);
    };
    for _ in 0..params.frequency.pilot.max(1) {
        pilot.iterate();
    }
    FrequencyField::new(&pilot.frequency_predictions(), cell)
}

/// The merge radius of a pass at any point.
#[derive(Clone, Copy)]
pub(crate) struct MergeRadius<'a> {
    /// The pass's radius r₀·gᵢ.
    pub(crate) global: f64,
    pub(crate) field: Option<&'a FrequencyField>,
}

impl MergeRadius<'_> {
    /// r(p) = min(global, prediction at p), or the global radius where nothing is predicted:
    /// never above the global radius, which shrinks to zero, so merging stays consistent.
    pub(crate) fn at(&self, p: Vec3) -> f64 {
        match self.field.and_then(|f| f.at(p)) {
            Some(r) => r.min(self.global),
            None => self.global,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_field_keeps_the_smallest_prediction_of_a_cell_and_the_global_radius_bounds_it() {
        let predictions = [
            (Vec3::new(0.1, 0.1, 0.1), 0.3),
            (Vec3::new(0.4, 0.2, 0.9), 0.02),
            (Vec3::new(1.5, 0.1, 0.1), 0.5),
            (Vec3::new(-0.5, 0.1, 0.1), f64::NAN),
        ];
        let field = FrequencyField::new(&predictions, 1.0);
        assert_eq!(field.len(), 2);
        assert_eq!(field.at(Vec3::new(0.9, 0.9, 0.5)), Some(f64::from(0.02f32)));
        assert_eq!(field.at(Vec3::new(-0.5, 0.1, 0.1)), None);
        let radius = MergeRadius {
            global: 0.1,
            field: Some(&field),
        };
        assert_eq!(radius.at(Vec3::new(0.5, 0.5, 0.5)), f64::from(0.02f32));
        assert_eq!(radius.at(Vec3::new(1.5, 0.5, 0.5)), 0.1);
        assert_eq!(radius.at(Vec3::new(-3.0, 0.5, 0.5)), 0.1);
        let mut reversed = predictions;
        reversed.reverse();
        let again = FrequencyField::new(&reversed, 1.0);
        assert_eq!(
            again.at(Vec3::new(0.5, 0.5, 0.5)),
            field.at(Vec3::new(0.5, 0.5, 0.5))
        );
    }
}
