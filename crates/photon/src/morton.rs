//! Morton (Z-order) sorting of points, to make gather queries coherent.

use glam::Vec3;

/// Indices of `points` in Morton (Z-curve) order over their bounding box, 21 bits per axis.
///
/// Gathering photons in this order instead of emission order keeps consecutive queries in the
/// same grid buckets (several times faster, see `benches/gather.rs`). The sort is stable, so
/// the order is a pure function of the points; non-finite points go last.
#[must_use]
pub fn morton_order(points: &[Vec3]) -> Vec<u32> {
    let (lo, hi) = points
        .iter()
        .filter(|p| p.is_finite())
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &p| {
            (lo.min(p), hi.max(p))
        });
    let scale = ((1 << 21) - 1) as f32 / (hi - lo).max_element().max(f32::MIN_POSITIVE);
    let mut keyed: Vec<(u64, u32)> = points
        .iter()
        .enumerate()
        .map(|(i, &p)| {
            let key = if p.is_finite() {
                let c = ((p - lo) * scale).as_uvec3();
                spread(c.x) | spread(c.y) << 1 | spread(c.z) << 2
            } else {
                u64::MAX
            };
            (key, i as u32)
        })
        .collect();
    keyed.sort_unstable();
    keyed.into_iter().map(|(_, i)| i).collect()
}

/// Spreads the low 21 bits of `v` to every third bit.
fn spread(v: u32) -> u64 {
    let mut x = u64::from(v) & 0x1F_FFFF;
    x = (x | x << 32) & 0x001F_0000_0000_FFFF;
    x = (x | x << 16) & 0x001F_0000_FF00_00FF;
    x = (x | x << 8) & 0x100F_00F0_0F00_F00F;
    x = (x | x << 4) & 0x10C3_0C30_C30C_30C3;
    x = (x | x << 2) & 0x1249_2492_4924_9249;
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spread_interleaves() {
        assert_eq!(spread(0b111), 0b1001001);
        assert_eq!(spread(0x1F_FFFF), 0x1249_2492_4924_9249);
    }

    #[test]
    fn order_is_a_permutation_following_the_curve() {
        let points = [
            Vec3::ONE,
            Vec3::ZERO,
            Vec3::new(f32::NAN, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
        ];
        assert_eq!(morton_order(&points), [1, 3, 0, 2]);
        assert!(morton_order(&[]).is_empty());
    }
}
