//! The per-hitpoint frequency accumulator and its merge policies (design §8.1).

use crate::spectrum::Spectrum;

/// How a hitpoint merges the spectra of the frequency photons it collects.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum MergePolicy {
    /// Keep the smallest predicted radius: per-coefficient min of a and b (c is not
    /// merged and is stored as 0). The default.
    ///
    /// r_x grows with a and r_θ with b, so the smallest a and b give the smallest, i.e.
    /// most conservative, kernel. (A per-coefficient min of c would not keep Q PSD; since
    /// the radii do not read c it is dropped.)
    #[default]
    MinRadius,
    /// The poster's rule as written: per-coefficient max of (a, b, c).
    ///
    /// It keeps Q PSD, but under the poster's own radius formulas it picks the
    /// *smoothest* photon, the least conservative choice. Offered for reproduction.
    PosterMax,
}

/// The frequency information a hitpoint stores: nothing until the first frequency photon
/// arrives (`has_freq` is false and the hitpoint behaves as standard PPM), then the merged
/// spectrum. 32 bytes.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FrequencyEstimate {
    merged: Option<Spectrum>,
}

impl FrequencyEstimate {
    /// No frequency photon deposited yet.
    pub const EMPTY: FrequencyEstimate = FrequencyEstimate { merged: None };

    /// The estimate holding exactly `merged` (e.g. restored from a checkpoint); `None` is
    /// [`FrequencyEstimate::EMPTY`].
    #[must_use]
    pub fn from_spectrum(merged: Option<Spectrum>) -> Self {
        Self { merged }
    }

    /// True once a frequency photon has been deposited.
    #[must_use]
    pub fn has_freq(&self) -> bool {
        self.merged.is_some()
    }

    /// The merged spectrum, if any photon has been deposited.
    #[must_use]
    pub fn spectrum(&self) -> Option<Spectrum> {
        self.merged
    }

    /// Merges a frequency photon's spectrum under `policy`.
    ///
    /// Deposit the field the hitpoint will use for its radius: the photon's spectrum
    /// reflected with the hitpoint's lobe and curvature, `reflect(μi, 1.0, κ, lobe)`, so
    /// that a is in surface units (for a Lambertian hitpoint b = b_max and the angular
    /// radius is +∞). The Lambertian flag (b = +∞) merges like
    /// b: under [`MergePolicy::MinRadius`] it survives only if every deposit had it, under
    /// [`MergePolicy::PosterMax`] one flagged deposit sets it (and c = 0). Values are
    /// assumed to share one set of caps.
    pub fn deposit(&mut self, spectrum: Spectrum, policy: MergePolicy) {
        let incoming = match policy {
            MergePolicy::MinRadius => spectrum.without_correlation(),
            MergePolicy::PosterMax => spectrum,
        };
        self.merged = Some(match self.merged {
            None => incoming,
            Some(old) => match policy {
                MergePolicy::MinRadius => old.merge_min(incoming),
                MergePolicy::PosterMax => old.merge_max(incoming),
            },
        });
    }

    /// The frequency radius `r_freq = min(r_x, r_θ)` \[m\] of the merged spectrum (see
    /// [`Spectrum::radius`]), or `None` before the first deposit.
    #[must_use]
    pub fn radius(&self, normal_distance: f64, k: f64) -> Option<f64> {
        self.merged.map(|s| s.radius(normal_distance, k))
    }
}
