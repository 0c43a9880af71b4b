//! The per-hitpoint accumulator: `has_freq`, the two merge policies, the radius.

use proptest::prelude::*;
use spectrum::{Caps, FrequencyEstimate, K_POSTER, K_STRICT, Lobe, MergePolicy, Spectrum};

use crate::support::assert_valid;

#[test]
fn empty_estimate_has_no_radius() {
    let estimate = FrequencyEstimate::default();
    assert_eq!(estimate, FrequencyEstimate::EMPTY);
    assert!(!estimate.has_freq());
    assert_eq!(estimate.radius(1.0, K_POSTER), None);
    assert_eq!(estimate.spectrum(), None);
    assert_eq!(MergePolicy::default(), MergePolicy::MinRadius);
}

#[test]
fn estimate_is_tiny() {
    assert!(std::mem::size_of::<FrequencyEstimate>() <= 32);
}

/// The design's example of why a per-coefficient min of c would break PSD, and what the
/// two policies keep instead.
#[test]
fn policies_on_the_design_example() {
    let caps = Caps::UNBOUNDED;
    let first = Spectrum::new(1.0, 100.0, 9.0, &caps).unwrap();
    let second = Spectrum::new(100.0, 1.0, 9.0, &caps).unwrap();

    let mut min = FrequencyEstimate::default();
    min.deposit(first, MergePolicy::MinRadius);
    min.deposit(second, MergePolicy::MinRadius);
    let merged = min.spectrum().unwrap();
    assert_eq!((merged.a(), merged.b(), merged.c()), (1.0, 1.0, 0.0));
    let z = 2.0;
    let expected = (K_POSTER * 1.0).min(z * (K_POSTER * 1.0f64).tan());
    assert_close!(min.radius(z, K_POSTER).unwrap(), expected, 1e-15);

    let mut max = FrequencyEstimate::default();
    max.deposit(first, MergePolicy::PosterMax);
    max.deposit(second, MergePolicy::PosterMax);
    let merged = max.spectrum().unwrap();
    assert_eq!((merged.a(), merged.b(), merged.c()), (100.0, 100.0, 9.0));
    // The poster's merge predicts the larger kernel.
    assert!(max.radius(z, K_POSTER).unwrap() > min.radius(z, K_POSTER).unwrap());
}

#[test]
fn lambertian_hitpoints_are_limited_by_space_only() {
    let caps = Caps::for_scene_size(1.0);
    let mut estimate = FrequencyEstimate::default();
    for a in [0.3, 0.01, 2.0] {
        let q = Spectrum::new(a, 1.0, 0.05, &caps)
            .unwrap()
            .bandlimit(Lobe::Lambert, &caps);
        estimate.deposit(q, MergePolicy::MinRadius);
    }
    assert!(estimate.spectrum().unwrap().is_lambertian());
    assert_close!(
        estimate.radius(5.0, K_STRICT).unwrap(),
        K_STRICT * 0.1,
        1e-15
    );
    // One glossy deposit clears the flag.
    estimate.deposit(
        Spectrum::new(1.0, 1.0, 0.0, &caps).unwrap(),
        MergePolicy::MinRadius,
    );
    assert!(!estimate.spectrum().unwrap().is_lambertian());
}

fn deposits() -> impl Strategy<Value = Vec<Spectrum>> {
    let caps = Caps::for_scene_size(1.0);
    let one = (-6.0f64..1.3, -8.0f64..1.3, -0.99f64..0.99, prop::bool::ANY).prop_map(
        move |(la, lb, u, lambert)| {
            let (a, b) = (10f64.powf(la), 10f64.powf(lb));
            let q = Spectrum::new(a, b, u * (a * b).sqrt(), &caps).unwrap();
            if lambert {
                q.bandlimit(Lobe::Lambert, &caps)
            } else {
                q
            }
        },
    );
    prop::collection::vec(one, 1..8)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(1000))]

    /// MinRadius keeps exactly the smallest radius any deposit predicts; PosterMax never
    /// predicts less than any deposit.
    #[test]
    fn min_radius_is_the_smallest_prediction(spectra in deposits(), z in 0.01f64..10.0) {
        let caps = Caps::for_scene_size(1.0);
        for k in [K_POSTER, K_STRICT] {
            let mut min = FrequencyEstimate::default();
            let mut max = FrequencyEstimate::default();
            for q in &spectra {
                min.deposit(*q, MergePolicy::MinRadius);
                max.deposit(*q, MergePolicy::PosterMax);
            }
            let smallest = spectra.iter().map(|q| q.radius(z, k)).fold(f64::INFINITY, f64::min);
            let largest = spectra.iter().map(|q| q.radius(z, k)).fold(0.0, f64::max);
            assert_close!(min.radius(z, k).unwrap(), smallest, 1e-15);
            prop_assert!(max.radius(z, k).unwrap() >= largest);
            assert_valid(&min.spectrum().unwrap(), &caps);
            assert_valid(&max.spectrum().unwrap(), &caps);
        }
    }
}

#[test]
fn bits_round_trip_exactly_and_reject_invalid_values() {
    let caps = Caps::for_scene_size(2.0);
    let diffuse = Spectrum::point_light(&caps)
        .travel(1.3, &caps)
        .bandlimit(Lobe::Lambert, &caps);
    let glossy = Spectrum::area_light(0.2, 0.7, &caps)
        .travel(0.9, &caps)
        .reflect(0.8, 0.6, 0.5, Lobe::Ggx { roughness: 0.1 }, &caps);
    for spectrum in [diffuse, glossy] {
        let back = Spectrum::from_bits(spectrum.to_bits()).unwrap();
        assert_eq!(back, spectrum);
        assert_eq!(back.is_lambertian(), spectrum.is_lambertian());
        let estimate = FrequencyEstimate::from_spectrum(Some(back));
        assert_eq!(estimate.spectrum(), Some(spectrum));
    }
    let nan = [f64::NAN.to_bits(), 1f64.to_bits(), 0f64.to_bits(), 0];
    let not_psd = [1f64.to_bits(), 1f64.to_bits(), 2f64.to_bits(), 0];
    let bad_flag = [1f64.to_bits(), 1f64.to_bits(), 0f64.to_bits(), 7];
    for bits in [nan, not_psd, bad_flag] {
        assert_eq!(Spectrum::from_bits(bits), None);
    }
    assert_eq!(
        FrequencyEstimate::from_spectrum(None),
        FrequencyEstimate::EMPTY
    );
}
