//! Phase 4 of a pass: the hitpoint update. Every slot folds the pass's M and Φ into its R, N
//! and τ by [`GatherStats::update_with_hold`], with the frequency radius `frequency::hold` gives it.

use std::time::Instant;

use rayon::prelude::*;
use scene::MaterialKind;

use super::{PassStats, PhotonMapper, frequency, seen_directly};
use crate::update::{FrequencyRadius, GatherStats};

impl PhotonMapper {
    /// Folds the last photon pass into every slot, and reports the radii and the share of
    /// slots that hold theirs in `stats`.
    pub(super) fn update_hitpoints(&mut self, stats: &mut PassStats) {
        let params = self.setup.params;
        let alpha = params.kernel.alpha;
        let k = params.frequency.kernel_k;
        let floor = params.frequency.floor;
        let uses_frequency = params.method.uses_frequency();
        let probe_clock = Instant::now();
        if uses_frequency && params.frequency.geometry {
            self.probe_clear_radii(params.frequency.clear_cap, params.frequency.probe_share);
        }
        let probe_seconds = probe_clock.elapsed().as_secs_f64();
        let r_top = self.setup.kernel_max();
        let hold_alpha = params.frequency.hold_alpha;
        let clear_cap = uses_frequency && params.frequency.geometry && params.frequency.clear_cap;
        // The cap never goes below a quarter of the initial radius: a smaller disc collects
        // too few photons per pass for its bias gain to pay (measured, docs/integrators.md).
        let r_min = 0.25 * self.setup.kernel_scale;
        // The frequency cap, only where the camera sees the slot directly and connections to
        // the camera take over as its kernel shrinks below a camera sample or two: a slot seen
        // through mirrors or glass has no other estimate than its merges.
        let freq_cap = params
            .frequency
            .cap_floor
            .filter(|_| uses_frequency && params.connections.light_tracing)
            .map(|f| (f * self.setup.kernel_scale, params.frequency.cap_scale));
        // Which slots it caps: a diffuse visible point seen directly (seen on a glossy surface
        // or through mirrors and glass, a connection is a poor estimate or none).
        let capped: Vec<bool> = if freq_cap.is_some() {
            let max_depth = params.budget.max_depth;
            let scene = &self.setup.scene;
            let materials = self.slots.material_idx();
            self.photon_bounces
                .par_iter()
                .zip(materials.par_iter())
                .map(|(&budget, &material)| {
                    seen_directly(budget, max_depth)
                        && scene
                            .material(material)
                            .is_some_and(|m| matches!(m.kind, MaterialKind::Diffuse(_)))
                })
                .collect()
        } else {
            Vec::new()
        };
        let photons = &self.photons;
        let n_slots = self.slots.len();
        let columns = self.slots.columns_mut();
        let held: Vec<bool> = columns
            .radius
            .par_iter_mut()
            .zip(columns.photon_count.par_iter_mut())
            .zip(columns.flux.par_iter_mut())
            .zip(columns.freq.par_iter())
            .zip(
                (0..n_slots)
                    .into_par_iter()
                    .map(|s| (s, photons.deposit_of(s))),
            )
            .map(
                |((((radius, photon_count), tau), freq), (slot, (m, mut phi)))| {
                    // Light-traced radiance enters τ as the flux that radiance is at this radius.
                    let light = photons.light_of(slot);
                    let area = std::f64::consts::PI * *radius * *radius;
                    for c in 0..3 {
                        phi[c] += light[c] * area;
                    }
                    let (r_freq, held) = frequency::hold(freq, *radius, uses_frequency, k, r_top);
                    let mut stats = GatherStats {
                        radius: *radius,
                        photon_count: *photon_count,
                        flux: *tau,
                    };
                    stats.update_with_hold(m, phi, alpha, r_freq, floor, hold_alpha);
                    if clear_cap && let Some(clear) = freq.clear_radius(r_top) {
                        stats.cap_radius(clear.max(r_min));
                    }
                    if let (Some((floor, scale)), FrequencyRadius::Predicted(r)) =
                        (freq_cap, r_freq)
                        && capped.get(slot).copied().unwrap_or(false)
                    {
                        stats.cap_radius((scale * r).max(floor));
                    }
                    *radius = stats.radius;
                    *photon_count = stats.photon_count;
                    *tau = stats.flux;
                    held
                },
            )
            .collect();

        stats.timings.frequency += probe_seconds;
        stats.min_radius = f64::INFINITY;
        let mut sum = 0.0;
        let mut n_held = 0u64;
        for (slot, &r) in self.slots.radius().iter().enumerate() {
            if !self.is_valid(slot) {
                continue;
            }
            stats.hitpoints_valid += 1;
            sum += r;
            stats.min_radius = stats.min_radius.min(r);
            stats.max_radius = stats.max_radius.max(r);
            n_held += u64::from(held[slot]);
        }
        if stats.hitpoints_valid > 0 {
            stats.mean_radius = sum / stats.hitpoints_valid as f64;
            stats.frequency_held = n_held as f64 / stats.hitpoints_valid as f64;
        } else {
            stats.min_radius = 0.0;
        }
    }
}
