//! The Henyey–Greenstein phase function against its definition: normalisation by quadrature,
//! the mean cosine g, the sampled directions' χ² against the density, and the homogeneous
//! medium's transmittance.

use glam::Vec3;

use super::{HenyeyGreenstein, Medium};
use crate::material::pdf_tests::{directional_chi_square, integrate};
use crate::test_util::Rng;

const GS: [f32; 5] = [0.0, 0.3, -0.5, 0.85, -0.95];

fn outgoing() -> Vec3 {
    Vec3::new(0.3, -0.5, 0.8).normalize()
}

/// The direction of `incoming` where the phase function of asymmetry `g` peaks.
fn peak(outgoing: Vec3, g: f32) -> Vec3 {
    if g >= 0.0 { -outgoing } else { outgoing }
}

/// ∫ p dω = 1 and ∫ p cos θ dω = g, with cos θ = −outgoing·incoming (the scattering angle).
#[test]
fn phase_integrates_to_one_with_mean_cosine_g() {
    let wo = outgoing();
    for g in GS {
        let hg = HenyeyGreenstein { g };
        // Integrate about where the lobe peaks: −wo forward (incoming ≈ −outgoing), wo back.
        let axis = peak(wo, g);
        let total = integrate(axis, 400, 64, |wi| f64::from(hg.eval(wo, wi)));
        let mean = integrate(axis, 400, 64, |wi| {
            f64::from(hg.eval(wo, wi)) * f64::from(-wo.dot(wi))
        });
        assert!((total - 1.0).abs() < 2e-3, "g {g}: ∫p = {total}");
        assert!(
            (mean - f64::from(g)).abs() < 2e-3,
            "g {g}: ∫p cosθ = {mean}"
        );
        // The density is the value.
        let wi = Vec3::new(0.1, 0.7, -0.2).normalize();
        assert_eq!(hg.pdf(wo, wi), hg.eval(wo, wi));
    }
}

/// Pearson χ² of 200 000 sampled directions against the density integrated over bins of
/// (t, φ) about the lobe's peak (θ = π t²), and the pdf each sample reports against `eval`.
#[test]
fn sampling_matches_the_density_chi_square() {
    let wo = outgoing();
    for (k, g) in GS.into_iter().enumerate() {
        let hg = HenyeyGreenstein { g };
        let mut rng = Rng::new(40 + k as u64);
        let draw = || {
            let s = hg.sample(wo, rng.vec2());
            assert!((s.incoming.length() - 1.0).abs() < 1e-4);
            let eval = hg.eval(wo, s.incoming);
            assert!(
                (s.pdf - eval).abs() <= 2e-3 * eval.max(1.0),
                "g {g}: pdf {} against eval {eval}",
                s.pdf
            );
            Some(s.incoming)
        };
        let (chi2, dof) =
            directional_chi_square(peak(wo, g), draw, |wi| hg.eval(wo, wi), "phase samples");
        // Mean dof, standard deviation √(2 dof): allow 5 of them.
        let limit = dof + 5.0 * (2.0 * dof).sqrt();
        assert!(chi2 < limit, "g {g}: χ² {chi2:.1} with {dof} dof");
    }
}

#[test]
fn transmittance_is_beer_lambert_per_channel() {
    let m = Medium {
        name: "fog".into(),
        sigma_a: Vec3::new(0.5, 0.0, 2.0),
        sigma_s: Vec3::new(0.5, 0.0, 1.0),
        g: 0.0,
        density: None,
    };
    let t = m.transmittance(2.0);
    assert!((t.x - (-2.0f32).exp()).abs() < 1e-6);
    assert_eq!(t.y, 1.0);
    assert!((t.z - (-6.0f32).exp()).abs() < 1e-6);
    assert_eq!(m.transmittance(f32::INFINITY), Vec3::new(0.0, 1.0, 0.0));
}
