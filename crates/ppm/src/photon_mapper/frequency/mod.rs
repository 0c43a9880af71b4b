//! The frequency extension of the photon mappers (Belcour and Soler 2011), in four files:
//! - this one: the state a hitpoint slot keeps (`SlotFrequency`) and the hold decision of the
//!   update;
//! - `transport.rs`: the spectrum steps along a photon path (emitter, travel with the
//!   partial-occlusion probe, scatter) and the record a frequency photon leaves where it lands
//!   (`FrequencyPhoton`);
//! - `deposits.rs`: how a photon's tag names its record (`TagLayout`) and the deposits of the
//!   records into the slots, riding the flux gather;
//! - `clear.rs`: the clear-disc probes that bound held kernels by their surface, and the
//!   growth of kernels after the pilot.
//!
//! The other phases call into it at five places: `trace` (start, travel, scatter and record a
//! frequency photon), `photon_pass` (tags and deposits), `update` (probes and the frequency
//! radius of each slot), and the AOVs.

mod clear;
mod deposits;
mod transport;

use spectrum::{Caps, FrequencyEstimate, Spectrum};

pub(super) use self::clear::BlockDisc;
pub(super) use self::deposits::FrequencyDeposits;
#[cfg(test)]
pub(super) use self::deposits::TagLayout;
#[cfg(test)]
pub(super) use self::transport::UNTAGGED;
pub(super) use self::transport::{FrequencyPhoton, arrived, scatter_spectrum};
use super::Setup;
use crate::update::FrequencyRadius;

/// Frequency state of one hitpoint slot: the merged estimate plus what a deposit needs to
/// turn a photon's spectrum into the field seen by the camera.
///
/// 32 bytes: the merged spectrum's (a, b, c) and its flags are packed beside the distance (a
/// `FrequencyEstimate`, 32 bytes with its padding, next to an `f32` would take 40). The
/// estimate is stored bit for bit ([`Spectrum::to_bits`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct SlotFrequency {
    /// Bits of a, b, c of the merged spectrum; zero while `merged` is [`Self::EMPTY`].
    coefficients: [u64; 3],
    /// Distance to the camera (or last specular vertex) projected on the normal, z of §8.2.
    normal_distance: f32,
    /// [`Self::EMPTY`] until a frequency photon was merged, then 1 + the Lambertian flag.
    merged: u8,
    /// The clear radius of the gather disc at this visible point as a level of
    /// [`crate::disc::clear_level`] (the radius R₀·2^−level, none at `disc::LEVELS`), or
    /// [`GEOMETRY_UNKNOWN`] until it is probed: when the slot first becomes a candidate for
    /// holding, again after every new visible point.
    clear_level: u8,
    /// |cos θo| toward the camera (or the last specular vertex), in units of 1/65535: with
    /// `normal_distance` it gives the camera distance of the camera-line radius.
    mu_o: u16,
}

/// A cosine in [0, 1] in units of 1/65535.
fn quantize_cosine(mu: f32) -> u16 {
    (mu.abs().min(1.0) * f32::from(u16::MAX)).round() as u16
}

/// [`SlotFrequency::clear_level`] before the probes ran.
const GEOMETRY_UNKNOWN: u8 = u8::MAX;

impl SlotFrequency {
    /// No frequency photon merged yet.
    const EMPTY: u8 = 0;

    /// The state of a new visible point at `normal_distance`, seen at cosine `mu_o`: nothing
    /// merged, not probed.
    pub(crate) fn new(normal_distance: f32, mu_o: f32) -> Self {
        Self::restored(
            FrequencyEstimate::EMPTY,
            normal_distance,
            GEOMETRY_UNKNOWN,
            mu_o,
        )
    }

    /// The state holding `estimate` at `normal_distance`, with the disc probed to
    /// `clear_level` (as [`Self::clear_level`] returned it).
    pub(crate) fn restored(
        estimate: FrequencyEstimate,
        normal_distance: f32,
        clear_level: u8,
        mu_o: f32,
    ) -> Self {
        let mut freq = Self {
            coefficients: [0; 3],
            normal_distance,
            merged: Self::EMPTY,
            clear_level,
            mu_o: quantize_cosine(mu_o),
        };
        freq.set_estimate(estimate);
        freq
    }

    /// Keeps the merged estimate for a new visible point at `normal_distance`, whose disc is
    /// not probed yet.
    pub(super) fn move_to(&mut self, normal_distance: f32, mu_o: f32) {
        self.normal_distance = normal_distance;
        self.mu_o = quantize_cosine(mu_o);
        self.clear_level = GEOMETRY_UNKNOWN;
    }

    /// Distance to the camera (or last specular vertex) projected on the normal.
    pub(crate) fn normal_distance(&self) -> f32 {
        self.normal_distance
    }

    /// The probed clear level of the gather disc, or `u8::MAX` before the probe.
    pub(crate) fn clear_level(&self) -> u8 {
        self.clear_level
    }

    /// The merged estimate.
    pub(crate) fn estimate(&self) -> FrequencyEstimate {
        if self.merged == Self::EMPTY {
            return FrequencyEstimate::EMPTY;
        }
        let [a, b, c] = self.coefficients;
        let spectrum = Spectrum::from_bits([a, b, c, u64::from(self.merged - 1)])
            .expect("the bits of a valid spectrum, stored by set_estimate");
        FrequencyEstimate::from_spectrum(Some(spectrum))
    }

    /// Replaces the merged estimate.
    fn set_estimate(&mut self, estimate: FrequencyEstimate) {
        match estimate.spectrum() {
            None => {
                self.coefficients = [0; 3];
                self.merged = Self::EMPTY;
            }
            Some(spectrum) => {
                let [a, b, c, lambertian] = spectrum.to_bits();
                self.coefficients = [a, b, c];
                // `to_bits` encodes the flag as 0 or 1.
                self.merged = 1 + u8::from(lambertian != 0);
            }
        }
    }

    /// The frequency radius r_freq of the merged deposits with kernel constant `k` (`None`
    /// before the first): min(r_x, r_θ) of the poster, where each deposit's a already holds
    /// the camera-line radius ([`Self::seen_from_camera`]).
    pub(super) fn frequency_radius(&self, k: f64) -> Option<f64> {
        self.estimate().radius(f64::from(self.normal_distance), k)
    }

    /// A deposit's field as this slot reads it: for a glossy field, the camera-line radius
    /// r_cam of design §8.2 folded into a ([`Spectrum::seen_along_camera_line`]), which sees
    /// how a highlight narrows along the rays that reach the camera.
    pub(super) fn seen_from_camera(&self, field: Spectrum, caps: &Caps) -> Spectrum {
        if field.is_lambertian() {
            return field;
        }
        let mu_o = f64::from(self.mu_o.max(1)) / f64::from(u16::MAX);
        let camera_distance = f64::from(self.normal_distance) / mu_o;
        field.seen_along_camera_line(camera_distance, mu_o, caps)
    }

    /// The clear radius of the slot's gather disc, once probed (levels of `r_top`).
    pub(super) fn clear_radius(&self, r_top: f64) -> Option<f64> {
        (self.clear_level != GEOMETRY_UNKNOWN)
            .then(|| crate::disc::level_radius(self.clear_level, r_top))
    }

    /// The radius below which the slot holds its kernel: the frequency radius r_freq of its
    /// merged deposits (`None` before the first), bounded by the clear radius of its disc
    /// (levels of `r_top`, the largest kernel, [`Setup::kernel_max`]) once probed.
    pub(super) fn hold_radius(&self, k: f64, r_top: f64) -> Option<f64> {
        let r_freq = self.frequency_radius(k)?;
        Some(if self.clear_level == GEOMETRY_UNKNOWN {
            r_freq
        } else {
            r_freq.min(crate::disc::level_radius(self.clear_level, r_top))
        })
    }
}

/// The hold decision of the update: the frequency radius a slot's update sees (none for the
/// classical methods), and whether the slot holds its radius R this pass.
pub(super) fn hold(
    freq: &SlotFrequency,
    radius: f64,
    uses_frequency: bool,
    k: f64,
    r_top: f64,
) -> (FrequencyRadius, bool) {
    let r_freq = if uses_frequency {
        freq.hold_radius(k, r_top)
            .map_or(FrequencyRadius::None, FrequencyRadius::Predicted)
    } else {
        FrequencyRadius::None
    };
    let held = matches!(r_freq, FrequencyRadius::Predicted(r) if radius <= r);
    (r_freq, held)
}

impl Setup {
    /// The largest gather radius a slot can have: the initial radius, times `freq_grow` for a
    /// frequency method that grows kernels.
    pub(super) fn kernel_max(&self) -> f64 {
        match self.params.growth_pass() {
            Some(_) => self.kernel_scale * self.params.frequency.grow,
            None => self.kernel_scale,
        }
    }
}

#[cfg(test)]
mod radius_tests {
    use spectrum::Lobe;

    use super::*;

    #[test]
    fn glossy_deposits_carry_the_camera_line_radius() {
        // A point light 1 m from a sharp glossy surface, seen from 3 m (design §8.2's example
        // of what the slices miss): the slices a and b are both wide, yet the highlight is
        // narrow along the camera's rays. The slot must predict the camera-line radius, far
        // below the poster's min(r_x, r_θ) of the same field.
        let caps = Caps::for_scene_size(10.0);
        let field = Spectrum::point_light(&caps).travel(1.0, &caps).reflect(
            1.0,
            1.0,
            0.0,
            Lobe::Ggx { roughness: 0.1 },
            &caps,
        );
        let (z, mu_o, k) = (3.0f32, 1.0f32, spectrum::K_STRICT);
        let slot = SlotFrequency::new(z, mu_o);
        let mut estimate = FrequencyEstimate::EMPTY;
        estimate.deposit(
            slot.seen_from_camera(field, &caps),
            spectrum::MergePolicy::MinRadius,
        );
        let slot = SlotFrequency::restored(estimate, z, GEOMETRY_UNKNOWN, mu_o);
        let poster = field.radius(f64::from(z), k);
        let r_cam = field.camera_line_radius(f64::from(z), 1.0, k);
        let got = slot.frequency_radius(k).unwrap();
        assert!(r_cam < 0.5 * poster, "{r_cam} vs {poster}");
        // (A point light's field is perfectly correlated, a_cam = 0: the caps' finest detail
        // a_min bounds it.)
        let expected = r_cam.max(spectrum::spatial_radius(caps.a_min(), k));
        assert!(
            (got - expected).abs() <= 1e-9 * expected,
            "{got} vs {expected}"
        );
        // A Lambertian field is read as it is.
        let lambert = field.bandlimit(Lobe::Lambert, &caps);
        assert!(lambert.is_lambertian());
        assert_eq!(slot.seen_from_camera(lambert, &caps), lambert);
    }
}
