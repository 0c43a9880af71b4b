//! What a checkpoint keeps of a photon mapper: every hitpoint slot's record, its photon-bounce
//! budget, directly seen emission and mean visible-point weight, the photon and camera-pass
//! counts, in a scene with media the volume gather's sums, and which slots' visible points have
//! moved between surfaces.

use glam::Vec3;
use photon::{HitPoints, NewHitPoint};
use spectrum::{FrequencyEstimate, Spectrum};

use super::frequency::SlotFrequency;
use super::{MAX_PHOTON_BUDGET, NO_VISIBLE_POINT, PhotonMapper};
use crate::checkpoint::codec::{Reader, StateError, Writer};

/// Bytes of a slot's record in [`PhotonMapper::write_state`], with a spectrum.
const SLOT_RECORD_MAX: usize = 5 * 12 + 4 + 4 + 8 + 8 + 24 + 4 + 4 + 4 + 4 + 32 + 4 + 4 + 24 + 12;

/// The most bytes [`PhotonMapper::write_state`] writes for `n_slots` slots.
pub(super) fn bound(n_slots: usize) -> usize {
    8 + 4
        + 4
        + 8
        + n_slots.saturating_mul(SLOT_RECORD_MAX)
        + 4
        + 8
        + n_slots.saturating_mul(24)
        + 8
        + n_slots.saturating_mul(4)
}

impl PhotonMapper {
    /// The state that carries between passes: the photons emitted, the camera passes, and every
    /// slot's record with its budget and directly seen emission. The hash grid is not stored (it
    /// is rebuilt, and gathers do not depend on its layout), nor the block discs (recomputed).
    pub(super) fn write_state(&self, w: &mut Writer) {
        let p = self;
        w.u64(p.n_emitted);
        w.u32(p.camera_passes);
        w.u32(p.weight_passes);
        let s = &p.slots;
        let spp = p.setup.params.film.samples_per_pixel as usize;
        w.u64(s.len() as u64);
        for i in 0..s.len() {
            for v in [
                s.position()[i],
                s.shading_normal()[i],
                s.geometric_normal()[i],
                s.outgoing()[i],
                s.weight()[i],
            ] {
                v.to_array().iter().for_each(|&c| w.f32(c));
            }
            w.u32(s.material_idx()[i]);
            // The pixel is redundant (slot / spp) and checked on reading.
            w.u32((i / spp) as u32);
            w.f64(s.radius()[i]);
            w.f64(s.photon_count()[i]);
            s.flux()[i].iter().for_each(|&c| w.f64(c));
            let freq = s.freq()[i];
            let estimate = freq.estimate();
            w.u32(u32::from(estimate.has_freq()));
            w.f32(freq.normal_distance());
            w.u32(u32::from(freq.clear_level()));
            match estimate.spectrum() {
                None => w.u32(0),
                Some(spectrum) => {
                    w.u32(1);
                    spectrum.to_bits().iter().for_each(|&b| w.u64(b));
                }
            }
            // An invalid slot stores the budget of a camera path without bounces.
            let budget = p.photon_bounces[i];
            let valid = budget != NO_VISIBLE_POINT;
            w.u32(u32::from(valid));
            w.u32(if valid {
                u32::from(budget)
            } else {
                p.setup.params.budget.max_depth - 1
            });
            p.direct[i].iter().for_each(|&c| w.f64(c));
            p.mean_weight[i].to_array().iter().for_each(|&c| w.f32(c));
        }
        // The volume gather's sums (none without media); its radius follows from the count.
        w.u32(p.volume.gathers);
        w.u64(p.volume.sum.len() as u64);
        for sum in &p.volume.sum {
            sum.iter().for_each(|&c| w.f64(c));
        }
        // Which slots' visible points have moved between surfaces (none where not kept).
        w.u64(p.mixed.len() as u64);
        for &m in &p.mixed {
            w.u32(u32::from(m));
        }
    }

    /// Takes back the state [`PhotonMapper::write_state`] wrote after `passes` passes.
    pub(super) fn read_state(&mut self, r: &mut Reader<'_>, passes: u32) -> Result<(), StateError> {
        let p = self;
        let n_emitted = r.u64()?;
        let camera_passes = r.u32()?;
        let weight_passes = r.u32()?;
        // Every pass emits `photons_per_pass` and runs at most one camera pass; the photon indices
        // of the next pass start at `n_emitted`.
        if n_emitted != u64::from(passes) * u64::from(p.setup.params.budget.photons_per_pass)
            || camera_passes > passes
            || weight_passes > camera_passes
        {
            return Err(StateError::Corrupt);
        }
        let n = r.len()?;
        if n != p.n_slots() && n != 0 {
            return Err(StateError::Corrupt);
        }
        let spp = p.setup.params.film.samples_per_pixel as usize;
        let mut slots = HitPoints::with_capacity(n);
        let mut stats = Vec::with_capacity(n);
        let mut photon_budget = Vec::with_capacity(n);
        let mut direct = Vec::with_capacity(n);
        let mut mean_weight = Vec::with_capacity(n);
        for i in 0..n {
            let mut v = [Vec3::ZERO; 5];
            for item in &mut v {
                *item = Vec3::new(r.f32()?, r.f32()?, r.f32()?);
            }
            let material_idx = r.u32()?;
            if r.u32()? as usize != i / spp {
                return Err(StateError::Corrupt);
            }
            let radius = r.f64()?;
            // Every slot of a saved renderer has a positive radius (the update rule divides by it).
            if !(radius.is_finite() && radius > 0.0) {
                return Err(StateError::Corrupt);
            }
            let photon_count = r.f64()?;
            let flux = [r.f64()?, r.f64()?, r.f64()?];
            let has_freq = r.bool()?;
            let normal_distance = r.f32()?;
            let clear_level = u8::try_from(r.u32()?).map_err(|_| StateError::Corrupt)?;
            let spectrum = match r.u32()? {
                0 => None,
                1 => Some(
                    Spectrum::from_bits([r.u64()?, r.u64()?, r.u64()?, r.u64()?])
                        .ok_or(StateError::Corrupt)?,
                ),
                _ => return Err(StateError::Corrupt),
            };
            if has_freq != spectrum.is_some() {
                return Err(StateError::Corrupt);
            }
            let valid = r.bool()?;
            let budget = u16::try_from(r.u32()?)
                .ok()
                .filter(|&b| b <= MAX_PHOTON_BUDGET)
                .ok_or(StateError::Corrupt)?;
            photon_budget.push(if valid { budget } else { NO_VISIBLE_POINT });
            direct.push([r.f64()?, r.f64()?, r.f64()?]);
            mean_weight.push(Vec3::new(r.f32()?, r.f32()?, r.f32()?));
            slots.push(NewHitPoint {
                position: v[0],
                shading_normal: v[1],
                geometric_normal: v[2],
                outgoing: v[3],
                weight: v[4],
                material_idx,
                radius,
                freq: SlotFrequency::restored(
                    FrequencyEstimate::from_spectrum(spectrum),
                    normal_distance,
                    clear_level,
                    v[3].dot(v[1]).abs(),
                ),
            });
            stats.push((photon_count, flux));
        }
        let columns = slots.columns_mut();
        for (i, (photon_count, flux)) in stats.into_iter().enumerate() {
            columns.photon_count[i] = photon_count;
            columns.flux[i] = flux;
        }
        let gathers = r.u32()?;
        let n_volume = r.len()?;
        if gathers > passes || (n_volume != 0 && n_volume != n) {
            return Err(StateError::Corrupt);
        }
        let mut volume_sum = Vec::with_capacity(n_volume);
        for _ in 0..n_volume {
            volume_sum.push([r.f64()?, r.f64()?, r.f64()?]);
        }
        let n_mixed = r.len()?;
        let kept = p.setup.pools() && p.setup.params.method.is_stochastic();
        if (n_mixed != 0 || kept) && n_mixed != n {
            return Err(StateError::Corrupt);
        }
        let mut mixed = Vec::with_capacity(n_mixed);
        for _ in 0..n_mixed {
            mixed.push(r.bool()?);
        }
        p.volume.gathers = gathers;
        p.volume.sum = volume_sum;
        p.mixed = mixed;
        p.pass = passes;
        p.n_emitted = n_emitted;
        p.camera_passes = camera_passes;
        p.slots = slots;
        p.photon_bounces = photon_budget;
        p.direct = direct;
        p.mean_weight = mean_weight;
        p.weight_passes = weight_passes;
        Ok(())
    }
}
