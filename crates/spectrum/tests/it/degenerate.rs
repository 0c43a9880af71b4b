//! Degenerate and wild inputs: μ = 0, d = 0, capped values, zero-size lights, huge
//! distances and curvatures, NaN and infinite parameters. Every operator must return a
//! finite, PSD, capped spectrum and never panic.

use proptest::prelude::*;
use spectrum::{Caps, FrequencyEstimate, K_POSTER, K_STRICT, Lobe, MergePolicy, Spectrum};

use crate::support::assert_valid;

/// Any f64 at all: zeros, subnormals, huge, infinite and NaN values of both signs.
fn wild() -> impl Strategy<Value = f64> {
    prop_oneof![
        3 => proptest::num::f64::ANY,
        1 => Just(0.0),
        1 => Just(-0.0),
        1 => Just(f64::INFINITY),
        1 => Just(f64::NEG_INFINITY),
        1 => Just(f64::NAN),
        1 => Just(1e300),
        1 => Just(-1e300),
        1 => Just(f64::MIN_POSITIVE),
    ]
}

/// Positive magnitudes over the whole f64 range (including 0 and +∞).
fn magnitude() -> impl Strategy<Value = f64> {
    prop_oneof![
        4 => (-300.0f64..300.0).prop_map(|e| 10f64.powf(e)),
        1 => Just(0.0),
        1 => Just(f64::INFINITY),
    ]
}

fn caps() -> impl Strategy<Value = Caps> {
    prop_oneof![
        Just(Caps::UNBOUNDED),
        wild().prop_map(Caps::for_scene_size),
        (-30.0f64..30.0).prop_map(|e| Caps::for_scene_size(10f64.powf(e))),
    ]
}

fn lobe() -> impl Strategy<Value = Lobe> {
    prop_oneof![
        Just(Lobe::Mirror),
        Just(Lobe::Lambert),
        wild().prop_map(|exponent| Lobe::Phong { exponent }),
        wild().prop_map(|exponent| Lobe::BlinnPhong { exponent }),
        wild().prop_map(|roughness| Lobe::Beckmann { roughness }),
        wild().prop_map(|roughness| Lobe::Ggx { roughness }),
        wild().prop_map(|variance| Lobe::Gaussian { variance }),
    ]
}

/// Spectra over the whole range, from the PSD boundary (|c| = √(ab)) inwards, and the
/// emitters with wild parameters.
fn spectrum(caps: Caps) -> impl Strategy<Value = Spectrum> {
    prop_oneof![
        (magnitude(), magnitude(), -1.0f64..=1.0).prop_map(move |(a, b, u)| {
            let c = u * (a * b).sqrt();
            Spectrum::new(a, b, if c.is_nan() { 0.0 } else { c }, &caps)
                .unwrap_or_else(|| Spectrum::point_light(&caps))
        }),
        (wild(), wild()).prop_map(move |(s, mu)| Spectrum::area_light(s, mu, &caps)),
        Just(Spectrum::point_light(&caps)),
        wild().prop_map(move |t| Spectrum::spot_light(t, &caps)),
        wild().prop_map(move |m| Spectrum::spot_light_falloff(m, &caps)),
        Just(Spectrum::directional_light(&caps)),
        wild().prop_map(move |d| Spectrum::sun(d, &caps)),
    ]
}

fn caps_and_spectrum() -> impl Strategy<Value = (Caps, Spectrum)> {
    caps().prop_flat_map(|caps| (Just(caps), spectrum(caps)))
}

/// Radii are non-negative and never NaN (+∞ allowed for the angular radius).
#[track_caller]
fn assert_radii(q: &Spectrum, z: f64) {
    for k in [K_POSTER, K_STRICT] {
        let r_x = q.spatial_radius(k);
        assert!(r_x.is_finite() && r_x >= 0.0, "r_x = {r_x} for {q:?}");
        let r_t = q.angular_radius(z, k);
        assert!(!r_t.is_nan() && r_t >= 0.0, "r_θ = {r_t} for {q:?}");
        let r = q.radius(z, k);
        assert!(r.is_finite() && r >= 0.0, "r = {r} for {q:?}");
        let r_cam = q.camera_line_radius(z, 0.5, k);
        assert!(
            r_cam.is_finite() && r_cam >= 0.0,
            "r_cam = {r_cam} for {q:?}"
        );
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    #[test]
    fn every_operator_is_finite_and_psd_on_wild_inputs(
        (caps, q) in caps_and_spectrum(),
        d in wild(),
        g in wild(),
        mu_i in wild(),
        mu_o in wild(),
        kappa in wild(),
        eta_i in wild(),
        eta_t in wild(),
        o in wild(),
        theta in wild(),
        lobe in lobe(),
        z in 0.0f64..1e6,
    ) {
        assert_valid(&q, &caps);
        let results = [
            q.travel(d, &caps),
            q.kick(g, &caps),
            q.flip(&caps),
            q.project_in(mu_i, &caps),
            q.project_out(mu_o, &caps),
            q.reflect(mu_i, mu_o, kappa, lobe, &caps),
            q.reflect_isotropic(mu_i, mu_o, kappa, lobe, &caps),
            q.refract(eta_i, eta_t, mu_i, mu_o, kappa, &caps),
            q.bandlimit(lobe, &caps),
            q.occlude(o, &caps),
            q.cosine(theta, &caps),
        ];
        for r in results {
            assert_valid(&r, &caps);
            assert_radii(&r, z);
        }
        // A long chain with the same wild parameters.
        let chained = q
            .travel(d, &caps)
            .occlude(o, &caps)
            .project_in(mu_i, &caps)
            .kick(-kappa, &caps)
            .reflect(mu_i, mu_o, kappa, lobe, &caps)
            .refract(eta_i, eta_t, mu_i, mu_o, kappa, &caps)
            .cosine(theta, &caps)
            .travel(g, &caps);
        assert_valid(&chained, &caps);
        let mut estimate = FrequencyEstimate::default();
        estimate.deposit(chained, MergePolicy::PosterMax);
        estimate.deposit(q, MergePolicy::PosterMax);
        let merged = estimate.spectrum().unwrap();
        assert_valid(&merged, &caps);
        assert!(estimate.radius(z, K_POSTER).unwrap().is_finite());
    }

    #[test]
    fn covariance_round_trip_never_panics((caps, q) in caps_and_spectrum()) {
        if let Some(sigma) = q.covariance() {
            prop_assert!(sigma.p().is_finite() && sigma.q().is_finite() && sigma.r().is_finite());
            if let Some(back) = Spectrum::from_covariance(sigma, &caps) {
                assert_valid(&back, &caps);
            }
        }
    }

    #[test]
    fn constructors_reject_or_cap(a in wild(), b in wild(), c in wild(), (caps, _) in caps_and_spectrum()) {
        if let Some(q) = Spectrum::new(a, b, c, &caps) {
            assert_valid(&q, &caps);
        }
        let _ = Caps::new(a, b, c, a);
    }
}

#[test]
fn named_degenerate_cases() {
    let caps = Caps::for_scene_size(1.0);
    let q = Spectrum::new(1.0, 2.0, 0.5, &caps).unwrap();
    // d = 0 is the identity, also for a Lambertian field (the flag survives).
    assert_eq!(q.travel(0.0, &caps), q);
    let lambert = q.bandlimit(Lobe::Lambert, &caps);
    assert!(lambert.travel(0.0, &caps).is_lambertian());
    assert!(!lambert.travel(1e-3, &caps).is_lambertian());
    // μ = 0 is raised to MU_MIN: a/μ² lands on the cap.
    assert_eq!(q.project_in(0.0, &caps).a(), caps.a_max());
    assert_eq!(q.project_out(0.0, &caps).a(), caps.a_min());
    // Zero-size area light and huge travel.
    let dot = Spectrum::area_light(0.0, 1.0, &caps);
    assert_eq!(dot.a(), caps.a_min());
    let far = dot.travel(1e300, &caps);
    assert_eq!(far.a(), caps.a_max());
    let far_back = far.travel(-1e300, &caps);
    assert_valid(&far_back, &caps);
    // Singular inputs.
    assert!(Spectrum::new(1.0, 1.0, 2.0, &caps).is_none());
    assert!(Spectrum::new(-1.0, 1.0, 0.0, &caps).is_none());
    assert!(Spectrum::new(f64::NAN, 1.0, 0.0, &caps).is_none());
    let capped = Spectrum::new(f64::INFINITY, f64::INFINITY, 0.0, &caps).unwrap();
    assert_eq!((capped.a(), capped.b()), (caps.a_max(), caps.b_max()));
    // Covariance of a singular form under unbounded caps.
    let singular = Spectrum::new(0.0, 1.0, 0.0, &Caps::UNBOUNDED).unwrap();
    assert!(singular.covariance().is_none());
}
