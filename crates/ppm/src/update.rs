//! The progressive radius and flux update of Hachisuka, Ogaki & Jensen (2008), with the
//! frequency keep-or-shrink rule of the poster (design doc `frequency-algebra.md` §8.3).
//!
//! Symbols (glossary of ARCHITECTURE.md): R gather radius, N accumulated photon count, τ
//! accumulated flux, M photons found in this pass, Φ their BSDF-weighted flux, α ∈ (0, 1] the
//! fraction of new photons kept, r_freq the radius predicted by the frequency analysis.

/// Progressive statistics of one hitpoint: R, N and τ, in `f64` (see `photon::HitPoints`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GatherStats {
    /// Gather radius R.
    pub radius: f64,
    /// Accumulated photon count N (α-weighted, hence fractional).
    pub photon_count: f64,
    /// Accumulated flux τ (RGB).
    pub flux: [f64; 3],
}

/// What the frequency rule does once the PPM radius has reached the frequency radius r_freq.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum FrequencyFloor {
    /// The poster's rule (the seed's): shrink as PPM while R > r_freq, then keep the radius
    /// (the update of α = 1). The last shrink may step below r_freq.
    #[default]
    Keep,
    /// Variant \[UNV\] of §8.3: as `Keep`, but a shrink never goes below r_freq:
    /// R′ = max(R_PPM′, r_freq) and N′ = (N + M)·R′²/R², which keeps the photon density N/R²
    /// consistent.
    Clamp,
}

/// The frequency side of one hitpoint, as the update sees it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FrequencyRadius {
    /// No frequency photon merged yet (`has_freq = false`): plain PPM.
    None,
    /// The radius r_freq predicted from the merged frequency photons.
    Predicted(f64),
}

impl GatherStats {
    /// The initial state: radius `radius`, no photons, no flux.
    #[must_use]
    pub fn new(radius: f64) -> Self {
        Self {
            radius,
            photon_count: 0.0,
            flux: [0.0; 3],
        }
    }

    /// Folds one pass into the statistics: `n_new` = M photons accepted in the radius with
    /// BSDF-weighted flux `flux_new` = Φ.
    ///
    /// Hachisuka, Ogaki & Jensen (2008), eqs. 5–7 (pbrt-v4 SPPM, smallppm), with the poster's
    /// keep-or-shrink rule (§8.3):
    ///
    /// ```text
    /// if M = 0:                        τ′ = τ + Φ (Φ is then light-traced flux, or zero)
    /// keep = has_freq ∧ R ≤ r_freq
    /// if ¬keep (shrink, as PPM):       N′ = N + αM
    ///                                  R′ = R·√((N + αM)/(N + M))
    ///                                  τ′ = (τ + Φ)·R′²/R²
    /// if keep (≡ α = 1):               N′ = N + M,  R′ = R,  τ′ = τ + Φ
    /// ```
    ///
    /// With [`FrequencyFloor::Clamp`] a shrink of a hitpoint with a frequency radius ends at
    /// R′ = max(R′, r_freq), N′ = (N + M)·R′²/R² (identical to the above when R′ is not clamped).
    ///
    /// The flux rescaling τ′ = (τ + Φ)·R′²/R² assumes the photons are uniform over the disc,
    /// which keeps the estimate of [`Self::radiance`] unbiased for a locally constant density.
    pub fn update(
        &mut self,
        n_new: u32,
        flux_new: [f64; 3],
        alpha: f64,
        freq: FrequencyRadius,
        floor: FrequencyFloor,
    ) {
        self.update_with_hold(n_new, flux_new, alpha, freq, floor, 1.0);
    }

    /// [`Self::update`] with a held slot shrinking by `hold_alpha` instead of keeping its
    /// radius: where `keep` holds, N′ = N + α_hold·M, R′ = R·√((N + α_hold·M)/(N + M)),
    /// τ′ = (τ + Φ)·R′²/R² (exactly the keep rule for α_hold = 1). With 1/2 < α ≤ α_hold < 1
    /// every slot shrinks as a PPM slot with an α in [α, α_hold]: for a steady M per pass,
    /// R² ∝ N^−(1−α)/α → 0 while N·R² → ∞ (Hachisuka et al. 2008; Knaus and Zwicker 2011), so
    /// bias and variance both vanish and the estimate converges.
    #[inline]
    pub fn update_with_hold(
        &mut self,
        n_new: u32,
        flux_new: [f64; 3],
        alpha: f64,
        freq: FrequencyRadius,
        floor: FrequencyFloor,
        hold_alpha: f64,
    ) {
        debug_assert!(
            alpha > 0.0 && alpha <= 1.0,
            "α must be in (0, 1], got {alpha}"
        );
        debug_assert!(
            self.radius > 0.0,
            "radius must be positive, got {}",
            self.radius
        );
        if n_new == 0 {
            // Flux without photons (light-traced contributions) counts at the current radius.
            self.flux = add(self.flux, flux_new);
            return;
        }
        let (r, n, m) = (self.radius, self.photon_count, f64::from(n_new));
        let keep = match freq {
            FrequencyRadius::None => false,
            FrequencyRadius::Predicted(r_freq) => r <= r_freq,
        };
        if keep && hold_alpha >= 1.0 {
            self.photon_count = n + m;
            self.flux = add(self.flux, flux_new);
            return;
        }
        // A held slot shrinks by α_hold, and the floor applies only to a shrinking one.
        let alpha = if keep { hold_alpha } else { alpha };
        let mut n_next = n + alpha * m;
        let mut r_next = r * (n_next / (n + m)).sqrt();
        if let (false, FrequencyFloor::Clamp, FrequencyRadius::Predicted(r_freq)) =
            (keep, floor, freq)
            && r_next < r_freq
        {
            r_next = r_freq;
            n_next = (n + m) * (r_next * r_next) / (r * r);
        }
        let scale = (r_next * r_next) / (r * r);
        self.photon_count = n_next;
        self.radius = r_next;
        self.flux = add(self.flux, flux_new).map(|c| c * scale);
    }

    /// Shrinks the radius to at most `radius` at once, keeping the photon density N/R² and
    /// the flux density τ/R² (the rescaling of the PPM update with M = 0): the estimate is
    /// unchanged for a locally constant density.
    pub fn cap_radius(&mut self, radius: f64) {
        if radius > 0.0 && radius < self.radius {
            let scale = (radius * radius) / (self.radius * self.radius);
            self.photon_count *= scale;
            self.flux = self.flux.map(|c| c * scale);
            self.radius = radius;
        }
    }

    /// Radiance estimate L = τ / (π R² N_emitted), with N_emitted the number of photons emitted
    /// over all passes so far (Hachisuka et al. 2008, eq. 8).
    ///
    /// `None` if R = 0 or no photon was emitted.
    #[must_use]
    pub fn radiance(&self, n_emitted: f64) -> Option<[f64; 3]> {
        let denominator = std::f64::consts::PI * self.radius * self.radius * n_emitted;
        (denominator > 0.0).then(|| self.flux.map(|c| c / denominator))
    }
}

fn add(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// Knaus and Zwicker's (2011) global radius schedule, shared by the pass-independent estimator,
/// `vcm`'s merge radius and the volume gather: g² of pass `pass` (0-based), the product of
/// (k + α)/(k + 1) for k = 1 … pass, taken in that order so that every machine gets the same
/// bits.
pub(crate) fn schedule_squared(pass: u64, alpha: f64) -> f64 {
    let mut g2 = 1.0;
    for k in 1..=pass {
        let k = k as f64;
        g2 *= (k + alpha) / (k + 1.0);
    }
    g2
}

#[cfg(test)]
mod tests;
