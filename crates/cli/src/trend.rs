//! The error trend: how noisy the image still is, estimated from the image itself, for renders
//! that have no reference to compare with.
//!
//! Let I_n be the image after n passes (every integrator's image is the mean of its passes'
//! estimates). Snapshots of the image are kept at passes n₀, 2n₀, 4n₀, … (n₀ the first pass of
//! this run). At pass n, with m the latest snapshot pass such that m ≤ n/2,
//!
//! ```text
//! trend(n) = √(m / (n − m)) · RMS(I_n − I_m) / RMS(I_n)
//! ```
//!
//! over the RGB values of the pixels (of a fixed subset of at most [`SAMPLED_PIXELS`] pixels,
//! every k-th, on larger films). If the passes' estimates were independent with one variance
//! σ² per value, I_n − I_m would have the variance σ²(1/m − 1/n), and the factor turns its RMS
//! into σ/√n, the noise of I_n: the trend is then the relative RMS noise of the image, and it
//! falls as 1/√n. The progressive photon mappers' passes are not identically distributed (their
//! radii shrink), so there it is an estimate of the same scale rather than an exact one; it
//! never sees bias, only what still changes.

/// At most this many pixels enter the trend (every k-th pixel on larger films), which bounds
/// its memory (two snapshots of 3 MiB) and its time.
pub(crate) const SAMPLED_PIXELS: usize = 1 << 18;

/// The snapshots the trend needs.
#[derive(Debug, Default)]
pub(crate) struct Trend {
    /// `(pass, sampled values)`, oldest first: at most two are kept between passes.
    kept: Vec<(u32, Vec<f32>)>,
}

impl Trend {
    /// Whether the image after `passes` passes must be seen: a snapshot is due.
    pub(crate) fn wants(&self, passes: u32) -> bool {
        self.kept
            .last()
            .is_none_or(|&(p, _)| passes >= p.saturating_mul(2))
    }

    /// Sees the image after `passes` passes; returns the trend, or `None` before there is a
    /// snapshot from half as many passes or where the image is black.
    pub(crate) fn observe(&mut self, passes: u32, image: &[[f32; 3]]) -> Option<f64> {
        let values = sampled(image);
        let value = self
            .kept
            .iter()
            .rev()
            .find(|&&(m, _)| m > 0 && m.saturating_mul(2) <= passes)
            .and_then(|(m, old)| estimate(*m, passes, old, &values));
        if self.wants(passes) {
            self.kept.push((passes, values));
        }
        // Passes only grow: a snapshot older than the latest one with 2m ≤ n is never used again.
        while self.kept.len() >= 2 && self.kept[1].0.saturating_mul(2) <= passes {
            self.kept.remove(0);
        }
        value
    }
}

/// The RGB values of every k-th pixel, at most [`SAMPLED_PIXELS`] pixels.
fn sampled(image: &[[f32; 3]]) -> Vec<f32> {
    let step = image.len().div_ceil(SAMPLED_PIXELS).max(1);
    image.iter().step_by(step).flatten().copied().collect()
}

/// √(m/(n − m)) · RMS(now − then) / RMS(now).
fn estimate(m: u32, n: u32, then: &[f32], now: &[f32]) -> Option<f64> {
    if then.len() != now.len() || n <= m {
        return None;
    }
    let (mut change, mut level) = (0.0f64, 0.0f64);
    for (&a, &b) in now.iter().zip(then) {
        let (a, b) = (f64::from(a), f64::from(b));
        change += (a - b) * (a - b);
        level += a * a;
    }
    let scale = f64::from(m) / f64::from(n - m);
    let value = (scale * change / level).sqrt();
    (level > 0.0 && value.is_finite()).then_some(value)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A deterministic noise in [-1, 1) per (pass, index).
    fn noise(pass: u32, index: usize) -> f32 {
        let mut x = (u64::from(pass) << 32) ^ index as u64 ^ 0x9e37_79b9_7f4a_7c15;
        x ^= x >> 33;
        x = x.wrapping_mul(0xff51_afd7_ed55_8ccd);
        x ^= x >> 33;
        x = x.wrapping_mul(0xc4ce_b9fe_1a85_ec53);
        x ^= x >> 33;
        (x >> 40) as f32 / (1u64 << 23) as f32 - 1.0
    }

    /// The trend of a mean of passes with independent noise is the relative noise of the mean:
    /// a uniform noise in [-1, 1) around 1 has σ = 1/√3.
    #[test]
    fn the_trend_of_independent_passes_is_the_noise_of_their_mean() {
        let pixels = 64 * 64;
        let mut sum = vec![[0.0f64; 3]; pixels];
        let mut trend = Trend::default();
        let mut seen = Vec::new();
        for n in 1..=64u32 {
            for (i, p) in sum.iter_mut().enumerate() {
                for (c, v) in p.iter_mut().enumerate() {
                    *v += 1.0 + f64::from(noise(n, 3 * i + c));
                }
            }
            let mean: Vec<[f32; 3]> = sum
                .iter()
                .map(|p| p.map(|v| (v / f64::from(n)) as f32))
                .collect();
            seen.push((n, trend.observe(n, &mean)));
        }
        assert_eq!(seen[0].1, None, "no snapshot from half as many passes yet");
        for &(n, value) in &seen[1..] {
            let value = value.expect("a trend from pass 2 on");
            // σ/√n, relative to the RMS of the mean, √(1 + σ²/n).
            let noise = (1.0 / 3.0 / f64::from(n)).sqrt();
            let expected = noise / (1.0 + noise * noise).sqrt();
            assert!(
                (value / expected - 1.0).abs() < 0.05,
                "pass {n}: {value} against {expected}"
            );
        }
        assert!(trend.kept.len() <= 2);
    }

    #[test]
    fn a_settled_image_has_no_trend_and_a_black_one_none() {
        let mut trend = Trend::default();
        let image = vec![[0.5f32, 0.25, 1.0]; 100];
        assert_eq!(trend.observe(1, &image), None);
        assert_eq!(trend.observe(2, &image), Some(0.0));
        let mut black = Trend::default();
        black.observe(1, &[[0.0; 3]; 4]);
        assert_eq!(black.observe(2, &[[0.0; 3]; 4]), None);
    }

    /// A resumed render starts at pass n₀ and keeps its snapshots at n₀, 2n₀, 4n₀.
    #[test]
    fn snapshots_double_from_the_first_pass_seen() {
        let mut trend = Trend::default();
        let image = vec![[1.0f32; 3]; 4];
        for n in 10..=45 {
            let value = trend.observe(n, &image);
            assert_eq!(value.is_some(), n >= 20, "pass {n}");
        }
        let passes: Vec<u32> = trend.kept.iter().map(|(p, _)| *p).collect();
        assert_eq!(passes, [20, 40]);
    }

    #[test]
    fn large_films_are_sampled() {
        let image = vec![[1.0f32; 3]; SAMPLED_PIXELS * 2 + 1];
        assert!(sampled(&image).len() <= 3 * SAMPLED_PIXELS);
        assert_eq!(sampled(&image[..10]).len(), 30);
    }
}
