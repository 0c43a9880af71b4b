//! The rough dielectric against what does not share its code: the energy it scatters by
//! quadrature of `eval` (at most what arrives, all of it for a sharp lobe up to GGX's known
//! single-scattering loss), the smooth dielectric's Fresnel split in the limit of small
//! roughness, the generalized reciprocity of refraction, and sample weights in both transport
//! modes against `eval` and `pdf`. The densities (forward, reverse, χ² of the sampler) are
//! checked with every other model's in `pdf_tests.rs`.

use glam::Vec3;

use super::pdf_tests::{bsdf, direction, integrate, mirrored, normal};
use super::{Bsdf, MaterialKind, RoughDielectric, TransportMode, fresnel_dielectric};
use crate::test_util::Rng;

fn rough(ior: f32, roughness: f32) -> MaterialKind {
    MaterialKind::RoughDielectric(RoughDielectric { ior, roughness })
}

/// η of the medium that `w` lies in, for a boundary whose front face (outside, η = 1) is on the
/// side of `normal()`.
fn medium(ior: f32, w: Vec3) -> f32 {
    if w.dot(normal()) > 0.0 { 1.0 } else { ior }
}

/// Light arriving along −`a` leaves through the smooth boundary along this direction: the
/// refraction of `a` about the macro normal, or its mirror image under total internal reflection.
fn refracted(ior: f32, a: Vec3) -> Vec3 {
    let n = if a.dot(normal()) > 0.0 {
        normal()
    } else {
        -normal()
    };
    let eta = medium(ior, -a) / medium(ior, a);
    let cos_i = a.dot(n);
    let sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
    if sin2_t >= 1.0 {
        return mirrored(a);
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    (-a / eta + (cos_i / eta - cos_t) * n).normalize()
}

/// Of the power arriving along −`a`, the fractions leaving on the same side (R) and through
/// the boundary (T): ∫ f(a → b)|cos θ_b| dω_b with f(a → b) = `eval(b, a)`, each side
/// integrated about the axis of its lobe with `n_t` × `n_phi` points.
fn reflected_and_transmitted(b: &Bsdf, ior: f32, a: Vec3, n_t: usize, n_phi: usize) -> (f64, f64) {
    let n = normal();
    let side = a.dot(n).signum();
    let part = |axis: Vec3, same: bool| {
        integrate(axis, n_t, n_phi, |w| {
            let cos = w.dot(n);
            if (cos * side > 0.0) == same {
                f64::from(b.eval(w, a).x * cos.abs())
            } else {
                0.0
            }
        })
    };
    (part(mirrored(a), true), part(refracted(ior, a), false))
}

/// The GGX conductor of the same roughness that reflects everything its microfacets receive.
fn conductor(alpha: f32) -> Bsdf {
    bsdf(
        MaterialKind::Glossy(super::Glossy {
            reflectance: Vec3::ONE,
            roughness: alpha,
            diffuse: Vec3::ZERO,
        }),
        true,
    )
}

/// Mean importance weight of `count` samples from `a`: the Monte Carlo estimate of R + T.
fn mean_importance_weight(b: &Bsdf, a: Vec3, count: u32) -> (f64, f64) {
    let mut rng = Rng::new(17);
    let (mut sum, mut sum2) = (0.0f64, 0.0f64);
    for _ in 0..count {
        if let Some(s) = b.sample(a, rng.f32(), rng.vec2(), TransportMode::Importance) {
            let w = f64::from(s.weight.x);
            sum += w;
            sum2 += w * w;
        }
    }
    let mean = sum / f64::from(count);
    let variance = (sum2 / f64::from(count) - mean * mean).max(0.0);
    (mean, (variance / f64::from(count)).sqrt())
}

/// The white furnace: whatever arrives, at most all of it leaves (R + T ≤ 1), nearly all of it
/// for a sharp lobe (up to GGX's single-scattering loss, measured on the conductor), and what
/// the sampler's importance weights average agrees with the quadrature. Single scattering loses
/// much more at high roughness, as the conductor does (from outside at normal incidence
/// R + T = 1.00 at α = 0.05, 0.93 at α = 0.8; from inside 0.997 and 0.53).
#[test]
fn scatters_at_most_what_arrives_and_nearly_all_when_sharp() {
    for ior in [1.5, 1.1] {
        for alpha in [0.05, 0.3, 0.8] {
            let b = bsdf(rough(ior, alpha), true);
            for theta in [0.0, 40.0, 70.0, 85.0] {
                for side in [1.0, -1.0] {
                    let a = direction(&b, theta, side);
                    let (r, t) = reflected_and_transmitted(&b, ior, a, 1500, 384);
                    let what =
                        format!("ior {ior} α {alpha} θ {theta} side {side}: R {r:.4} T {t:.4}");
                    assert!(r + t <= 1.0 + 2e-3, "{what}");
                    // A sharp lobe loses little: at most 2.5 times what the GGX conductor
                    // (F = 1) loses to single scattering at that angle, which is under 1.5 %
                    // up to 70° (the dielectric loses more from inside, where light exits
                    // near the critical angle toward grazing and is masked).
                    if alpha == 0.05 && theta <= 70.0 {
                        let (c, _) =
                            reflected_and_transmitted(&conductor(alpha), 1.0, a, 1500, 384);
                        assert!(
                            1.0 - (r + t) <= 2.5 * (1.0 - c) + 2e-3,
                            "{what}, conductor {c:.4}"
                        );
                        assert!(r + t >= 0.97, "{what}");
                    }
                    if alpha == 0.3 {
                        let (mean, error) = mean_importance_weight(&b, a, 100_000);
                        assert!(
                            (mean - (r + t)).abs() <= 5.0 * error + 2e-3,
                            "{what}: sampled {mean:.4} ± {error:.4}"
                        );
                    }
                }
            }
        }
    }
}

/// Toward zero roughness the lobes split what arrives as the smooth dielectric does: Fresnel's
/// R reflected and 1 − R refracted (all reflected under total internal reflection), both by
/// quadrature of `eval` and by the share of samples of each lobe; below the threshold the
/// material is the smooth dielectric, sample for sample.
#[test]
fn small_roughness_splits_like_the_smooth_dielectric() {
    let ior = 1.5;
    let b = bsdf(rough(ior, 0.01), true);
    let n = 40_000;
    for theta in [0.0, 30.0, 60.0, 75.0] {
        for side in [1.0, -1.0] {
            let a = direction(&b, theta, side);
            let eta = medium(ior, -a) / medium(ior, a);
            let fresnel = f64::from(fresnel_dielectric(theta.to_radians().cos(), eta));
            let (r, t) = reflected_and_transmitted(&b, ior, a, 2500, 384);
            let what = format!("θ {theta} side {side}: R {r:.4} T {t:.4}, Fresnel {fresnel:.4}");
            assert!((r - fresnel).abs() < 0.01, "{what}");
            assert!((t - (1.0 - fresnel)).abs() < 0.01, "{what}");
            let mut rng = Rng::new(3);
            let mut reflected = 0u32;
            for _ in 0..n {
                let s = b.sample(a, rng.f32(), rng.vec2(), TransportMode::Radiance);
                reflected += u32::from(s.is_some_and(|s| !s.is_transmission));
            }
            let share = f64::from(reflected) / f64::from(n);
            let tolerance = 5.0 * (fresnel * (1.0 - fresnel) / f64::from(n)).sqrt() + 0.005;
            assert!((share - fresnel).abs() < tolerance, "{what}: share {share}");
        }
    }
    let nearly_smooth = bsdf(rough(ior, 5e-4), false);
    let smooth = bsdf(MaterialKind::Dielectric(super::Dielectric { ior }), false);
    assert!(nearly_smooth.is_specular() && !nearly_smooth.kind().transmits());
    let mut rng = Rng::new(5);
    for _ in 0..1000 {
        let (wo, u_lobe, u) = (rng.unit(), rng.f32(), rng.vec2());
        for mode in [TransportMode::Radiance, TransportMode::Importance] {
            assert_eq!(
                nearly_smooth.sample_with_pdfs(wo, u_lobe, u, mode),
                smooth.sample_with_pdfs(wo, u_lobe, u, mode)
            );
        }
    }
}

/// The generalized reciprocity of refraction (Veach 1997, eq. 5.14): f(a → c)/η_c² =
/// f(c → a)/η_a², with f(a → c) = `eval(c, a)` the radiance BSDF; for reflection plain symmetry.
#[test]
fn eval_obeys_the_reciprocity_of_refraction() {
    let mut rng = Rng::new(11);
    for (ior, alpha) in [(1.5, 0.2), (1.5, 0.7), (2.4, 0.1), (1.33, 0.4)] {
        let b = bsdf(rough(ior, alpha), true);
        let mut transmitted = 0;
        for _ in 0..20_000 {
            let (a, c) = (rng.unit(), rng.unit());
            let forward = f64::from(b.eval(c, a).x) / f64::from(medium(ior, c)).powi(2);
            let backward = f64::from(b.eval(a, c).x) / f64::from(medium(ior, a)).powi(2);
            // The two ways round compute the half vector from ηa + c and a + c/η: far in the
            // tails, where f is 10⁻⁵ of its peak, they differ by a few per cent in f32.
            assert!(
                (forward - backward).abs() <= 2e-3 * forward.max(backward) + 1e-4,
                "ior {ior} α {alpha}: {forward} vs {backward}"
            );
            transmitted += usize::from(forward > 0.0 && a.dot(normal()) * c.dot(normal()) < 0.0);
        }
        // The pairs did test refraction, not only reflection.
        assert!(transmitted > 1000, "{transmitted}");
    }
}

/// A sample's weight is f·|cos θi|/pdf with the radiance BSDF for radiance and its adjoint
/// f(wi, wo) for light paths, and its density is `pdf`: the η′² between the two modes.
#[test]
fn sample_weights_are_f_cos_over_pdf_in_both_modes() {
    let mut rng = Rng::new(23);
    for (ior, alpha) in [(1.5, 0.05), (1.5, 0.4), (1.33, 0.9)] {
        for front_face in [true, false] {
            let b = bsdf(rough(ior, alpha), front_face);
            let mut counts = [0u32; 2];
            for _ in 0..20_000 {
                let (wo, u_lobe, u) = (rng.unit(), rng.f32(), rng.vec2());
                for mode in [TransportMode::Radiance, TransportMode::Importance] {
                    let Some(s) = b.sample(wo, u_lobe, u, mode) else {
                        continue;
                    };
                    assert!(!s.is_specular);
                    let crossed = wo.dot(normal()) * s.incoming.dot(normal()) < 0.0;
                    assert_eq!(crossed, s.is_transmission);
                    counts[usize::from(s.is_transmission)] += 1;
                    let pdf = b.pdf(wo, s.incoming);
                    assert!((pdf - s.pdf).abs() <= 2e-3 * pdf, "{pdf} vs {}", s.pdf);
                    let f = match mode {
                        TransportMode::Radiance => b.eval(wo, s.incoming),
                        TransportMode::Importance => b.eval(s.incoming, wo),
                    };
                    let expected = f.x * s.incoming.dot(normal()).abs() / s.pdf;
                    assert!(
                        (expected - s.weight.x).abs() <= 2e-3 * expected,
                        "{mode:?} {}: {expected} vs {}",
                        s.is_transmission,
                        s.weight.x
                    );
                }
            }
            assert!(counts.iter().all(|&c| c > 1000), "{counts:?}");
        }
    }
}
