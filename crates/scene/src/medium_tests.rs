//! The Henyey–Greenstein phase function against its definition: normalisation by quadrature,
//! the mean cosine g, the sampled directions' χ² against the density, and the homogeneous
//! medium's transmittance.

use std::f64::consts::PI as PI64;

use glam::Vec3;

use super::{HenyeyGreenstein, Medium};
use crate::Frame;
use crate::material::pdf_tests::{integrate, warped};
use crate::test_util::{Rng, pearson_chi_square};

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
    const N_T: usize = 24;
    const N_PHI: usize = 24;
    const SUB: usize = 8;
    const N: u32 = 200_000;
    let wo = outgoing();
    for (k, g) in GS.into_iter().enumerate() {
        let hg = HenyeyGreenstein { g };
        let frame = Frame::from_normal(peak(wo, g));
        let mut observed = vec![0.0f64; N_T * N_PHI];
        let mut rng = Rng::new(40 + k as u64);
        for _ in 0..N {
            let s = hg.sample(wo, rng.vec2());
            assert!((s.incoming.length() - 1.0).abs() < 1e-4);
            let eval = hg.eval(wo, s.incoming);
            assert!(
                (s.pdf - eval).abs() <= 2e-3 * eval.max(1.0),
                "g {g}: pdf {} against eval {eval}",
                s.pdf
            );
            let l = frame.to_local(s.incoming);
            let t = (f64::from(l.z.clamp(-1.0, 1.0)).acos() / PI64).sqrt();
            let phi = f64::from(l.y).atan2(f64::from(l.x)).rem_euclid(2.0 * PI64);
            let i = ((t * N_T as f64) as usize).min(N_T - 1);
            let j = ((phi / (2.0 * PI64) * N_PHI as f64) as usize).min(N_PHI - 1);
            observed[i * N_PHI + j] += 1.0;
        }
        let mut expected = vec![0.0f64; N_T * N_PHI];
        for i in 0..N_T {
            for j in 0..N_PHI {
                let mut sum = 0.0;
                for a in 0..SUB {
                    let t = (i as f64 + (a as f64 + 0.5) / SUB as f64) / N_T as f64;
                    let jacobian = 2.0 * PI64 * t * (PI64 * t * t).sin();
                    for c in 0..SUB {
                        let phi =
                            2.0 * PI64 * (j as f64 + (c as f64 + 0.5) / SUB as f64) / N_PHI as f64;
                        sum += f64::from(hg.eval(wo, warped(&frame, t, phi))) * jacobian;
                    }
                }
                let cell = (1.0 / (N_T * SUB) as f64) * (2.0 * PI64 / (N_PHI * SUB) as f64);
                expected[i * N_PHI + j] = sum * cell * f64::from(N);
            }
        }
        let (chi2, dof) = pearson_chi_square(&observed, &expected, "phase samples");
        let dof = dof as f64;
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
    };
    let t = m.transmittance(2.0);
    assert!((t.x - (-2.0f32).exp()).abs() < 1e-6);
    assert_eq!(t.y, 1.0);
    assert!((t.z - (-6.0f32).exp()).abs() < 1e-6);
    assert_eq!(m.transmittance(f32::INFINITY), Vec3::new(0.0, 1.0, 0.0));
}
