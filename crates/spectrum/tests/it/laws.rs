//! Algebraic laws and invariants over random PSD inputs (design §9.2), 1000 cases each.
//!
//! Exact laws (composition, inverses, determinants, additivity, Q/Σ agreement) run under
//! [`Caps::UNBOUNDED`], whose bounds no input here reaches, so the caps cannot break them;
//! only the PSD repair c² ≤ ab(1 − 10⁻¹²) stays active, and the inputs keep
//! |c| ≤ 0.95·√(ab), well inside it. Validity (PSD, caps, finiteness) and monotonicity
//! run under realistic scene caps.

use proptest::prelude::*;
use spectrum::{Caps, Covariance, Lobe, Spectrum, refracted_cosine};

use crate::support::{abc, assert_valid};

const U: &Caps = &Caps::UNBOUNDED;
const TOL: f64 = 1e-9;

/// Random PSD forms with a, b ∈ [10⁻², 10²] and c = u·√(ab), |u| ≤ 0.95.
fn psd() -> impl Strategy<Value = Spectrum> {
    (-2.0f64..2.0, -2.0f64..2.0, -0.95f64..0.95).prop_map(|(la, lb, u)| {
        let (a, b) = (10f64.powf(la), 10f64.powf(lb));
        abc(a, b, u * (a * b).sqrt())
    })
}

/// Random glossy lobes (finite variance).
fn glossy() -> impl Strategy<Value = Lobe> {
    prop_oneof![
        Just(Lobe::Mirror),
        (1.0f64..1000.0).prop_map(|exponent| Lobe::Phong { exponent }),
        (1.0f64..1000.0).prop_map(|exponent| Lobe::BlinnPhong { exponent }),
        (0.01f64..1.0).prop_map(|roughness| Lobe::Beckmann { roughness }),
        (0.01f64..1.0).prop_map(|roughness| Lobe::Ggx { roughness }),
        (0.0f64..0.5).prop_map(|variance| Lobe::Gaussian { variance }),
    ]
}

/// Any lobe, Lambert included.
fn lobe() -> impl Strategy<Value = Lobe> {
    prop_oneof![4 => glossy(), 1 => Just(Lobe::Lambert)]
}

/// Asserts two spectra agree: a and b relative to their size, c relative to √(ab).
#[track_caller]
fn assert_same(got: Spectrum, expected: Spectrum, tol: f64) {
    let scale_a = got.a().abs().max(expected.a().abs());
    let scale_b = got.b().abs().max(expected.b().abs());
    let scale_c = (scale_a * scale_b).sqrt();
    let ok = (got.a() - expected.a()).abs() <= tol * scale_a
        && (got.b() - expected.b()).abs() <= tol * scale_b
        && (got.c() - expected.c()).abs() <= tol * scale_c;
    assert!(ok, "got {got:?}\nexpected {expected:?}");
}

/// [`assert_same`] with the tolerance scaled by the condition a·b/det of `expected`: a
/// round trip through Σ = (2Q)⁻¹ amplifies rounding by it.
#[track_caller]
fn assert_same_conditioned(got: Spectrum, expected: Spectrum, tol: f64) {
    let cond = (expected.a() * expected.b() / expected.determinant()).max(1.0);
    assert_same(got, expected, tol * cond);
}

/// Asserts two determinants agree relative to the larger a·b involved.
#[track_caller]
fn assert_det(got: &Spectrum, expected: f64, reference: &Spectrum, tol: f64) {
    let scale = (got.a() * got.b()).max(reference.a() * reference.b());
    let diff = got.determinant() - expected;
    assert!(
        diff.abs() <= tol * scale,
        "det {} expected {expected}: difference {diff:e} (scale {scale:e})",
        got.determinant()
    );
}

/// Q form → Σ form → back, for comparing the two operator families.
fn via_sigma(q: Spectrum, op: impl FnOnce(Covariance) -> Covariance) -> Spectrum {
    let sigma = q.covariance().expect("input is regular");
    Spectrum::from_covariance(op(sigma), U).expect("output is regular")
}

fn cosines() -> impl Strategy<Value = f64> {
    0.05f64..=1.0
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(1000))]

    #[test]
    fn every_operator_keeps_psd_and_caps(
        q in psd(),
        scene in 0.01f64..100.0,
        d in -50.0f64..50.0,
        g in -20.0f64..20.0,
        mu_i in 0.0f64..=1.0,
        mu_o in 0.0f64..=1.0,
        kappa in -20.0f64..20.0,
        eta in 0.5f64..2.5,
        o in 0.0f64..100.0,
        theta in 0.0f64..1.6,
        lobe in lobe(),
    ) {
        let caps = Caps::for_scene_size(scene);
        let q = q.capped(&caps);
        assert_valid(&q, &caps);
        let results = [
            q.travel(d, &caps),
            q.kick(g, &caps),
            q.flip(&caps),
            q.project_in(mu_i, &caps),
            q.project_out(mu_o, &caps),
            q.reflect(mu_i, mu_o, kappa, lobe, &caps),
            q.reflect_isotropic(mu_i, mu_o, kappa, lobe, &caps),
            q.refract(1.0, eta, mu_i, refracted_cosine(1.0, eta, mu_i).unwrap_or(0.0), kappa, &caps),
            q.bandlimit(lobe, &caps),
            q.occlude(o, &caps),
            q.cosine(theta, &caps),
        ];
        for r in results {
            assert_valid(&r, &caps);
            // Capping is idempotent.
            prop_assert_eq!(r.capped(&caps), r);
        }
    }

    #[test]
    fn travel_inverse_and_composition(q in psd(), d1 in -3.0f64..3.0, d2 in -3.0f64..3.0) {
        assert_same(q.travel(d1, U).travel(-d1, U), q, TOL);
        assert_same(q.travel(d1, U).travel(d2, U), q.travel(d1 + d2, U), TOL);
    }

    #[test]
    fn kick_and_flip_are_involutions(q in psd(), g in -3.0f64..3.0) {
        assert_same(q.kick(g, U).kick(-g, U), q, TOL);
        prop_assert_eq!(q.flip(U).flip(U), q);
    }

    #[test]
    fn reflect_is_the_chain_of_elementary_maps(
        q in psd(), mu_i in cosines(), mu_o in cosines(), kappa in -3.0f64..3.0,
    ) {
        // R = D(−μo,1)·K(κ)·F·K(−κ)·D(1/μi,1) = −F·[D(μo,1)·K(κ)·F·K(−κ)·D(1/μi,1)]:
        // the overall sign is irrelevant (M and −M act the same), the F is not.
        let chain = q
            .project_in(mu_i, U)
            .kick(-kappa, U)
            .flip(U)
            .kick(kappa, U)
            .project_out(mu_o, U)
            .flip(U);
        assert_same(q.reflect(mu_i, mu_o, kappa, Lobe::Mirror, U), chain, 1e-8);
    }

    #[test]
    fn determinants(
        q in psd(),
        d in -3.0f64..3.0,
        g in -3.0f64..3.0,
        mu_i in cosines(),
        mu_o in cosines(),
        kappa in -3.0f64..3.0,
        eta_i in 1.0f64..2.5,
        eta_t in 1.0f64..2.5,
    ) {
        let det = q.determinant();
        let t = q.travel(d, U);
        assert_det(&t, det, &q, TOL);
        let k = q.kick(g, U);
        assert_det(&k, det, &q, TOL);
        // Mirror with m = 1, flat or curved.
        let m = q.reflect(mu_i, mu_i, kappa, Lobe::Mirror, U);
        assert_det(&m, det, &q, TOL);
        // General mirror: det·m².
        let r = q.reflect(mu_i, mu_o, kappa, Lobe::Mirror, U);
        assert_det(&r, det * (mu_o / mu_i).powi(2), &q, TOL);
        // Projections scale det by 1/μ² and μ².
        let p_in = q.project_in(mu_i, U);
        assert_det(&p_in, det / (mu_i * mu_i), &q, TOL);
        let p_out = q.project_out(mu_o, U);
        assert_det(&p_out, det * mu_o * mu_o, &q, TOL);
        // Refraction scales det by (ηi/ηt)².
        if let Some(mu_t) = refracted_cosine(eta_i, eta_t, mu_i) {
            let rt = q.refract(eta_i, eta_t, mu_i, mu_t, kappa, U);
            assert_det(&rt, det * (eta_i / eta_t).powi(2), &q, 1e-8);
        }
    }

    #[test]
    fn bandlimit_and_occlusion_are_additive(
        q in psd(), v1 in 0.0f64..1.0, v2 in 0.0f64..1.0, o1 in 0.0f64..10.0, o2 in 0.0f64..10.0,
    ) {
        let twice = q
            .bandlimit(Lobe::Gaussian { variance: v1 }, U)
            .bandlimit(Lobe::Gaussian { variance: v2 }, U);
        assert_same(twice, q.bandlimit(Lobe::Gaussian { variance: v1 + v2 }, U), TOL);
        assert_same(q.occlude(o1, U).occlude(o2, U), q.occlude(o1 + o2, U), TOL);
    }

    #[test]
    fn q_form_and_sigma_form_agree(
        q in psd(),
        d in -3.0f64..3.0,
        g in -3.0f64..3.0,
        mu_i in cosines(),
        mu_o in cosines(),
        kappa in -3.0f64..3.0,
        eta_i in 1.0f64..2.5,
        eta_t in 1.0f64..2.5,
        lobe in glossy(),
        o in 0.0f64..10.0,
        theta in 0.0f64..1.5,
    ) {
        let tol = 1e-10;
        assert_same_conditioned(q.travel(d, U), via_sigma(q, |s| s.travel(d)), tol);
        assert_same_conditioned(q.kick(g, U), via_sigma(q, |s| s.kick(g)), tol);
        assert_same_conditioned(q.flip(U), via_sigma(q, Covariance::flip), tol);
        assert_same_conditioned(q.project_in(mu_i, U), via_sigma(q, |s| s.project_in(mu_i)), tol);
        assert_same_conditioned(q.project_out(mu_o, U), via_sigma(q, |s| s.project_out(mu_o)), tol);
        assert_same_conditioned(
            q.reflect(mu_i, mu_o, kappa, lobe, U),
            via_sigma(q, |s| s.reflect(mu_i, mu_o, kappa, lobe)),
            tol,
        );
        if let Some(mu_t) = refracted_cosine(eta_i, eta_t, mu_i) {
            assert_same_conditioned(
                q.refract(eta_i, eta_t, mu_i, mu_t, kappa, U),
                via_sigma(q, |s| s.refract(eta_i, eta_t, mu_i, mu_t, kappa)),
                tol,
            );
        }
        assert_same_conditioned(q.bandlimit(lobe, U), via_sigma(q, |s| s.bandlimit(lobe)), tol);
        assert_same_conditioned(q.occlude(o, U), via_sigma(q, |s| s.occlude(o)), tol);
        assert_same_conditioned(q.cosine(theta, U), via_sigma(q, |s| s.cosine(theta)), tol);
    }

    /// Lambert in Σ form is singular (r' = 0), so compare in Σ form: the Q-form result
    /// has b = 10¹⁵⁰ (the unbounded cap) and c = 0, i.e. Σ = diag(1/(2a), ≈0).
    #[test]
    fn lambert_agrees_in_sigma_form(q in psd(), mu_i in cosines(), mu_o in cosines(), kappa in -3.0f64..3.0) {
        let sigma = q.covariance().unwrap();
        for (q_form, sigma_form) in [
            (q.bandlimit(Lobe::Lambert, U), sigma.bandlimit(Lobe::Lambert)),
            (
                q.reflect(mu_i, mu_o, kappa, Lobe::Lambert, U),
                sigma.reflect(mu_i, mu_o, kappa, Lobe::Lambert),
            ),
        ] {
            let from_q = q_form.covariance().unwrap();
            // The Σ-form p + 2g·q + g²·r and p − q²/r both cancel for strong kicks
            // (g = 2κ/μi up to 120 here), hence the looser tolerance.
            assert_close!(from_q.p(), sigma_form.p(), 1e-7);
            prop_assert_eq!(sigma_form.q(), 0.0);
            prop_assert_eq!(sigma_form.r(), 0.0);
            prop_assert!(from_q.q().abs() < 1e-100 && from_q.r().abs() < 1e-100);
        }
    }

    #[test]
    fn conversions_round_trip(q in psd()) {
        let back = Spectrum::from_covariance(q.covariance().unwrap(), U).unwrap();
        assert_same(back, q, 1e-12);
        let primal = Spectrum::from_primal_covariance(q.primal_covariance(), U).unwrap();
        assert_same(primal, q, 1e-15);
        let p = q.primal_covariance();
        assert_close!(p.xx * 2.0 * std::f64::consts::PI.powi(2), q.a(), 1e-15);
    }

    #[test]
    fn monotonicity(
        q in psd(), scene in 0.1f64..10.0, lobe in lobe(), o in 0.0f64..1e6,
    ) {
        let caps = Caps::for_scene_size(scene);
        let q = q.capped(&caps);
        prop_assert!(q.bandlimit(lobe, &caps).b() >= q.b());
        prop_assert!(q.occlude(o, &caps).a() <= q.a());
        prop_assert!(q.occlude(o, U).a() <= q.a());
        prop_assert_eq!(q.capped(&caps).capped(&caps), q.capped(&caps));
    }
}
