//! The exact sums of the pass-independent estimator's pass images, and the parts in which work
//! units hand them back.
//!
//! The sums are exact: each pass image is rounded to fixed point (2⁻⁶⁴ of a unit of radiance)
//! and added as integers, which are associative. The image of N passes is therefore the same bits
//! whatever passes were rendered together, in what order, and however the sums were merged.

use crate::checkpoint::codec::checksum;

/// Fixed-point scale of the exact sums: 2⁶⁴ units per unit of radiance. With i128 sums this
/// holds pass images up to 9 · 10¹⁸ and 10⁹ passes of radiance 10⁹ without overflow.
pub(crate) const FIXED_POINT: f64 = 18_446_744_073_709_551_616.0;

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
        checksum(plan)
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
        let sum = checksum(&out);
        out.extend_from_slice(&sum.to_le_bytes());
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
        let (payload, sum) = bytes.split_at(bytes.len() - 8);
        let stored = u64::from_le_bytes(sum.try_into().map_err(|_| PartError::Corrupt)?);
        if checksum(payload) != stored {
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

#[cfg(test)]
mod tests {
    use super::*;

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
