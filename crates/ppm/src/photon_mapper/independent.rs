//! The pass-independent estimator (`--method appm`): Knaus and Zwicker's probabilistic PPM
//! (2011), with per-slot kernels from a frequency pilot.
//!
//! Pass i (1-based) gathers with the radius r₀ · gᵢ, where r₀ is the slot's kernel, fixed
//! before the first pass, and gᵢ follows a global schedule, g₁ = 1,
//! gᵢ₊₁² = gᵢ² · (i + α)/(i + 1). Every pass makes a complete image on its own (new camera paths
//! as in SPPM, the emission they see, the photons within the pass's radius), and the render is
//! the mean of the pass images: its bias vanishes as gᵢ → 0 while its variance stays bounded in
//! the mean (Knaus and Zwicker, §4). Nothing carries from one pass to the next, so passes can be
//! rendered in any order, on any number of machines, and summed.
//!
//! The sums are exact: each pass image is rounded to fixed point (2⁻⁶⁴ of a unit of radiance)
//! and added as integers, which are associative. The image of N passes is therefore the same bits
//! whatever passes were rendered together, in what order, and however the sums were merged.
//!
//! The kernels r₀ come from the pilot: `freq_pilot` passes of `freq-sppm` from the same seed,
//! after which each slot's radius is what the frequency analysis let it keep (smooth light holds
//! large kernels; caustics and shadow edges shrink theirs). With `freq_pilot = 0` every slot
//! starts from the automatic radius, which is Knaus and Zwicker's method as published.

use rayon::prelude::*;

use super::{NO_VISIBLE_POINT, PassStats, PhotonMapper};
use crate::params::{Method, RenderParams};

/// Fixed-point scale of the exact sums: 2⁶⁴ units per unit of radiance. With i128 sums this
/// holds pass images up to 9 · 10¹⁸ and 10⁹ passes of radiance 10⁹ without overflow.
const FIXED_POINT: f64 = 18_446_744_073_709_551_616.0;

/// An exact sum of pass images, per pixel and channel, in fixed point.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct PassSums {
    /// Passes summed.
    pub passes: u64,
    /// Per pixel (row-major), per channel: the sum of the pass images, times 2⁶⁴.
    pub sums: Vec<[i128; 3]>,
}

impl PassSums {
    /// Empty sums for `pixels` pixels.
    #[must_use]
    pub fn new(pixels: usize) -> Self {
        Self {
            passes: 0,
            sums: vec![[0; 3]; pixels],
        }
    }

    /// Adds `other`'s passes (the order of additions does not matter: the sums are exact).
    /// `false`, and nothing added, if the pixel counts differ or a sum would overflow.
    pub fn add(&mut self, other: &PassSums) -> bool {
        if other.sums.len() != self.sums.len() {
            return false;
        }
        let Some(passes) = self.passes.checked_add(other.passes) else {
            return false;
        };
        // Check first, then add in place: nothing is added if anything would overflow.
        let fits = self
            .sums
            .iter()
            .zip(&other.sums)
            .all(|(a, b)| (0..3).all(|c| a[c].checked_add(b[c]).is_some()));
        if !fits {
            return false;
        }
        for (a, b) in self.sums.iter_mut().zip(&other.sums) {
            for c in 0..3 {
                a[c] += b[c];
            }
        }
        self.passes = passes;
        true
    }

    /// The mean of the pass images: linear RGB per pixel.
    #[must_use]
    pub fn image(&self) -> Vec<[f32; 3]> {
        let n = self.passes.max(1) as f64 * FIXED_POINT;
        self.sums
            .iter()
            .map(|s| s.map(|v| (v as f64 / n) as f32))
            .collect()
    }
}

/// The state of the pass-independent estimator: the kernels and the exact sums.
pub(super) struct Independent {
    /// Per slot: r₀, the radius of the first pass.
    pub(super) kernels: Vec<f64>,
    pub(super) sums: PassSums,
}

/// g² of pass `pass` (0-based): the product of (k + α)/(k + 1) for k = 1 … pass, taken in that
/// order so that every machine gets the same bits.
pub(super) fn schedule_squared(pass: u64, alpha: f64) -> f64 {
    let mut g2 = 1.0;
    for k in 1..=pass {
        let k = k as f64;
        g2 *= (k + alpha) / (k + 1.0);
    }
    g2
}

/// The pilot: `params.freq_pilot` passes of freq-sppm from the same seed; each slot's radius
/// after them (or the automatic radius everywhere without a pilot).
pub(crate) fn pilot_kernels(scene: &scene::Scene, params: RenderParams) -> Vec<f64> {
    let film = scene.description().film;
    let n_slots = film.width as usize * film.height as usize * params.samples_per_pixel as usize;
    let mut pilot_params = params;
    pilot_params.method = Method::FreqSppm;
    // The construction checks the same film and parameters as the caller's own renderer.
    let Ok(mut pilot) = PhotonMapper::new(scene, pilot_params) else {
        return vec![super::auto_initial_radius(scene); n_slots];
    };
    let r0 = pilot.setup.kernel_scale;
    if params.freq_pilot == 0 {
        return vec![r0; n_slots];
    }
    for _ in 0..params.freq_pilot {
        pilot.iterate();
    }
    // A slot without a visible point in the pilot's last pass keeps its radius anyway: the
    // next pass may find one.
    pilot.slots.radius().to_vec()
}

impl PhotonMapper<'_> {
    /// Hands the estimator its kernels (from [`pilot_kernels`], or a plan) and the sums so far.
    pub(crate) fn set_independent(&mut self, kernels: Vec<f64>, sums: PassSums, passes: u32) {
        self.pass = passes;
        self.n_emitted = u64::from(passes) * u64::from(self.setup.params.photons_per_pass);
        self.independent = Some(Independent { kernels, sums });
    }

    /// The exact sums of the pass-independent estimator, if this is one.
    pub(crate) fn pass_sums(&self) -> Option<&PassSums> {
        self.independent.as_ref().map(|i| &i.sums)
    }

    /// The kernels r₀ of the pass-independent estimator, if this is one.
    pub(crate) fn kernels(&self) -> Option<&[f64]> {
        self.independent.as_ref().map(|i| i.kernels.as_slice())
    }

    /// Before the grid is built: every slot's radius for this pass, r₀ · gᵢ.
    pub(super) fn schedule_radii(&mut self) {
        let g = schedule_squared(u64::from(self.pass), self.setup.params.alpha).sqrt();
        let Some(independent) = self.independent.as_ref() else {
            return;
        };
        let columns = self.slots.columns_mut();
        columns
            .radius
            .par_iter_mut()
            .zip(independent.kernels.par_iter())
            .for_each(|(radius, &r0)| *radius = r0 * g);
    }

    /// After the photon pass: the pass image (emission seen by this pass's camera paths, plus
    /// the photons each slot gathered within its radius), added to the exact sums.
    pub(super) fn add_pass_image(&mut self, stats: &mut PassStats) {
        let spp = self.setup.params.samples_per_pixel as usize;
        let photons = f64::from(self.setup.params.photons_per_pass);
        let radius = self.slots.radius();
        let (direct, bounces, deposits) = (&self.direct, &self.photon_bounces, &self.photons);
        let Some(independent) = self.independent.as_mut() else {
            return;
        };
        let non_finite: u64 = independent
            .sums
            .sums
            .par_iter_mut()
            .enumerate()
            .map(|(pixel, sum)| {
                let mut image = [0.0f64; 3];
                for slot in pixel * spp..(pixel + 1) * spp {
                    let (_, flux) = deposits.deposit_of(slot);
                    let light = deposits.light_of(slot);
                    let area = std::f64::consts::PI * radius[slot] * radius[slot];
                    let gathered = bounces[slot] != NO_VISIBLE_POINT && area > 0.0;
                    for c in 0..3 {
                        image[c] += direct[slot][c] + light[c] / photons;
                        if gathered {
                            image[c] += flux[c] / (area * photons);
                        }
                    }
                }
                if !image.iter().all(|v| v.is_finite()) {
                    return 1;
                }
                for c in 0..3 {
                    // `as` saturates: a pass image beyond 9 · 10¹⁸ is clamped, never wrapped.
                    sum[c] = sum[c].saturating_add((image[c] * FIXED_POINT).round() as i128);
                }
                0
            })
            .sum();
        independent.sums.passes += 1;
        stats.non_finite += non_finite;
        stats.hitpoints_valid = bounces.iter().filter(|&&b| b != NO_VISIBLE_POINT).count() as u64;
        let g = schedule_squared(u64::from(self.pass), self.setup.params.alpha).sqrt();
        let kernels = &independent.kernels;
        let mean = kernels.iter().sum::<f64>() / kernels.len().max(1) as f64;
        stats.mean_radius = mean * g;
        stats.min_radius = kernels.iter().copied().fold(f64::INFINITY, f64::min) * g;
        stats.max_radius = kernels.iter().copied().fold(0.0, f64::max) * g;
        // The camera pass adds each pass's emission to `direct`; this estimator takes it per
        // pass.
        for d in &mut self.direct {
            *d = [0.0; 3];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_schedule_is_knaus_and_zwicker_s() {
        // g₂² = (1 + α)/2, g₃² = g₂² (2 + α)/3.
        let alpha = 2.0 / 3.0;
        assert_eq!(schedule_squared(0, alpha), 1.0);
        assert!((schedule_squared(1, alpha) - (1.0 + alpha) / 2.0).abs() < 1e-15);
        let g3 = (1.0 + alpha) / 2.0 * (2.0 + alpha) / 3.0;
        assert!((schedule_squared(2, alpha) - g3).abs() < 1e-15);
        // The area shrinks as i^(α−1) (their eq. 16): at i = 10⁴ the ratio of
        // g²(i) · i^(1−α) to its value at 10³ is near 1.
        let tail = |i: u64| schedule_squared(i, alpha) * (i as f64).powf(1.0 - alpha);
        assert!((tail(10_000) / tail(1_000) - 1.0).abs() < 0.01);
    }

    #[test]
    fn sums_add_exactly_in_any_order() {
        let pass = |v: f64| PassSums {
            passes: 1,
            sums: vec![[(v * FIXED_POINT) as i128; 3]; 2],
        };
        let parts = [pass(0.1), pass(1e-9), pass(3.7), pass(1e6)];
        let mut forward = PassSums::new(2);
        for p in &parts {
            assert!(forward.add(p));
        }
        let mut backward = PassSums::new(2);
        for p in parts.iter().rev() {
            assert!(backward.add(p));
        }
        assert_eq!(forward, backward);
        assert_eq!(forward.passes, 4);
        let mean = (0.1 + 1e-9 + 3.7 + 1e6) / 4.0;
        assert!((f64::from(forward.image()[0][0]) / mean - 1.0).abs() < 1e-6);
        // Mismatched sizes are refused.
        assert!(!forward.add(&PassSums::new(3)));
    }
}

/// The magic of a work unit's part file.
const PART_MAGIC: &[u8; 8] = b"FPPMPART";
/// Version of the part layout.
const PART_VERSION: u32 = 1;

/// Why a part file could not be read.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum PartError {
    /// Not a part file, or one of another version.
    #[error("not an fppm work-unit part (or one of another version)")]
    NotAPart,
    /// The part belongs to another plan.
    #[error("the part was rendered for another plan")]
    OtherPlan,
    /// Truncated, corrupt, or sized for another film.
    #[error("the part is truncated or corrupt")]
    Corrupt,
}

/// What a work unit hands back: its passes' exact sums, tied to its plan.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Part {
    /// Fingerprint of the plan the unit rendered (any hash of the plan file the caller likes).
    pub plan: u64,
    /// The unit's index in the plan.
    pub unit: u32,
    /// First pass rendered (0-based).
    pub first_pass: u32,
    /// The sums of its passes (`sums.passes` of them, from `first_pass` on).
    pub sums: PassSums,
}

impl Part {
    /// The fingerprint of a plan file's bytes, which ties parts to their plan.
    #[must_use]
    pub fn plan_fingerprint(plan: &[u8]) -> u64 {
        crate::state::fnv1a(crate::state::FNV_OFFSET, plan)
    }

    /// The part as bytes: a small header, the sums zstd-compressed, a checksum.
    #[must_use]
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut body = Vec::with_capacity(self.sums.sums.len() * 48);
        for s in &self.sums.sums {
            for v in s {
                body.extend_from_slice(&v.to_le_bytes());
            }
        }
        let compressed = zstd::bulk::compress(&body, 1)
            .unwrap_or_else(|e| unreachable!("zstd cannot compress a part held in memory: {e}"));
        let mut out = Vec::with_capacity(compressed.len() + 64);
        out.extend_from_slice(PART_MAGIC);
        out.extend_from_slice(&PART_VERSION.to_le_bytes());
        out.extend_from_slice(&self.plan.to_le_bytes());
        out.extend_from_slice(&self.unit.to_le_bytes());
        out.extend_from_slice(&self.first_pass.to_le_bytes());
        out.extend_from_slice(&self.sums.passes.to_le_bytes());
        out.extend_from_slice(&(self.sums.sums.len() as u64).to_le_bytes());
        out.extend_from_slice(&compressed);
        let checksum = crate::state::fnv1a(crate::state::FNV_OFFSET, &out);
        out.extend_from_slice(&checksum.to_le_bytes());
        out
    }

    /// Reads a part of the plan `plan` for a film of `pixels` pixels.
    ///
    /// # Errors
    ///
    /// [`PartError`] if the bytes are not a part, belong to another plan, or are corrupt.
    pub fn from_bytes(bytes: &[u8], plan: u64, pixels: usize) -> Result<Self, PartError> {
        const HEADER: usize = 8 + 4 + 8 + 4 + 4 + 8 + 8;
        if bytes.len() < HEADER + 8
            || &bytes[..8] != PART_MAGIC
            || bytes[8..12] != PART_VERSION.to_le_bytes()
        {
            return Err(PartError::NotAPart);
        }
        let (payload, checksum) = bytes.split_at(bytes.len() - 8);
        let stored = u64::from_le_bytes(checksum.try_into().map_err(|_| PartError::Corrupt)?);
        if crate::state::fnv1a(crate::state::FNV_OFFSET, payload) != stored {
            return Err(PartError::Corrupt);
        }
        let u64_at = |at: usize| {
            payload
                .get(at..at + 8)
                .and_then(|b| b.try_into().ok())
                .map(u64::from_le_bytes)
                .ok_or(PartError::Corrupt)
        };
        let u32_at = |at: usize| {
            payload
                .get(at..at + 4)
                .and_then(|b| b.try_into().ok())
                .map(u32::from_le_bytes)
                .ok_or(PartError::Corrupt)
        };
        if u64_at(12)? != plan {
            return Err(PartError::OtherPlan);
        }
        let unit = u32_at(20)?;
        let first_pass = u32_at(24)?;
        let passes = u64_at(28)?;
        if u64_at(36)? != pixels as u64 {
            return Err(PartError::Corrupt);
        }
        let length = pixels.checked_mul(48).ok_or(PartError::Corrupt)?;
        let body =
            zstd::bulk::decompress(&payload[HEADER..], length).map_err(|_| PartError::Corrupt)?;
        if body.len() != length {
            return Err(PartError::Corrupt);
        }
        let sums = body
            .chunks_exact(48)
            .map(|pixel| {
                let mut s = [0i128; 3];
                for (c, bytes) in pixel.chunks_exact(16).enumerate() {
                    s[c] = i128::from_le_bytes(bytes.try_into().unwrap_or([0; 16]));
                }
                s
            })
            .collect();
        Ok(Self {
            plan,
            unit,
            first_pass,
            sums: PassSums { passes, sums },
        })
    }
}
