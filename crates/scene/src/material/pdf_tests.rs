//! The forward and reverse densities of every model ([`Bsdf::pdfs`], [`Bsdf::sample_with_pdfs`],
//! [`Bsdf::specular_probability`]) against what [`Bsdf::sample`] does: quadrature of the
//! densities against the share of samples of each kind, χ² of sampled directions against the
//! densities, the lobe choices of delta events counted from both sides.

use std::f64::consts::PI as PI64;

use glam::{Vec2, Vec3};

use super::{Bsdf, BsdfPdfs, TransportMode};
use crate::test_util::{Rng, pearson_chi_square};
use crate::{Frame, MaterialKind, Rgb};

/// A tilted normal, so that the local frame is not the world frame.
pub(super) fn normal() -> Vec3 {
    Vec3::new(0.3, -0.2, 0.9).normalize()
}

pub(super) fn bsdf(kind: MaterialKind, front_face: bool) -> Bsdf {
    Bsdf::from_normal(kind, normal(), front_face)
}

/// The direction at polar angle `theta_deg` from the normal, on the side `side` (±1).
pub(super) fn direction(b: &Bsdf, theta_deg: f32, side: f32) -> Vec3 {
    let t = theta_deg.to_radians();
    side * b
        .frame()
        .to_world(Vec3::new(t.sin() * 0.6, t.sin() * 0.8, t.cos()))
}

/// The models with lobes of finite density: Lambert, GGX from sharp to rough, GGX over a
/// diffuse base, rough dielectrics.
fn finite_models() -> Vec<MaterialKind> {
    let glossy = |roughness, reflectance, diffuse| {
        MaterialKind::Glossy(crate::Glossy {
            reflectance: Rgb::splat(reflectance),
            roughness,
            diffuse: Rgb::splat(diffuse),
        })
    };
    vec![
        MaterialKind::Diffuse(crate::Diffuse {
            albedo: Rgb::new(0.8, 0.5, 0.2),
        }),
        glossy(0.08, 0.9, 0.0),
        glossy(0.3, 0.5, 0.4),
        glossy(0.8, 0.6, 0.0),
        glossy(0.15, 0.04, 0.8),
        MaterialKind::RoughDielectric(crate::RoughDielectric {
            ior: 1.5,
            roughness: 0.3,
        }),
        MaterialKind::RoughDielectric(crate::RoughDielectric {
            ior: 1.33,
            roughness: 0.7,
        }),
        gold(0.2),
        gold(0.6),
    ]
}

/// A conductor with Mitsuba's RGB η and k of gold and GGX roughness `roughness` (zero: smooth).
fn gold(roughness: f32) -> MaterialKind {
    MaterialKind::Conductor(crate::Conductor {
        eta: Rgb::new(0.143_119, 0.374_957, 1.442_48),
        k: Rgb::new(3.983_16, 2.385_72, 1.603_22),
        specular_reflectance: Rgb::new(1.0, 0.9, 0.8),
        roughness,
    })
}

/// The models with delta lobes, each on both faces (a dielectric's inside is behind its front).
fn delta_models() -> Vec<(MaterialKind, bool)> {
    let mirror = MaterialKind::Mirror(crate::Mirror {
        reflectance: Rgb::new(0.9, 0.8, 0.7),
    });
    let mut models = vec![(mirror, true), (gold(0.0), true), (gold(5e-4), false)];
    for ior in [1.5, 2.4] {
        for front_face in [true, false] {
            models.push((
                MaterialKind::Dielectric(crate::Dielectric { ior }),
                front_face,
            ));
        }
    }
    // A rough dielectric below `SMOOTH_ROUGHNESS` is the smooth one.
    let nearly_smooth = MaterialKind::RoughDielectric(crate::RoughDielectric {
        ior: 1.5,
        roughness: 5e-4,
    });
    models.extend([(nearly_smooth, true), (nearly_smooth, false)]);
    models
}

/// Polar angles (degrees) of the fixed direction, from normal to grazing.
const THETAS: [f32; 5] = [0.0, 30.0, 60.0, 85.0, 89.5];

/// The mirror image of `w` about the normal: where a glossy lobe peaks.
pub(super) fn mirrored(w: Vec3) -> Vec3 {
    2.0 * w.dot(normal()) * normal() - w
}

/// ∫ f dω over the sphere by the midpoint rule in (t, φ) about `axis`, with the polar angle
/// θ = π t²: dω = 2π t sin(π t²) dt dφ, so the steps in θ are fine near the axis, where the
/// sharp lobes are, and the rule is exact in φ for a lobe symmetric about the axis.
pub(crate) fn integrate(
    axis: Vec3,
    n_t: usize,
    n_phi: usize,
    mut f: impl FnMut(Vec3) -> f64,
) -> f64 {
    let frame = Frame::from_normal(axis);
    let mut sum = 0.0;
    for i in 0..n_t {
        let t = (i as f64 + 0.5) / n_t as f64;
        let theta = PI64 * t * t;
        let jacobian = 2.0 * PI64 * t * theta.sin();
        let mut ring = 0.0;
        for j in 0..n_phi {
            let phi = 2.0 * PI64 * (j as f64 + 0.5) / n_phi as f64;
            ring += f(warped(&frame, t, phi));
        }
        sum += ring * jacobian;
    }
    sum * (1.0 / n_t as f64) * (2.0 * PI64 / n_phi as f64)
}

/// The world direction of (t, φ) about the frame's normal (θ = π t²).
pub(crate) fn warped(frame: &Frame, t: f64, phi: f64) -> Vec3 {
    let theta = PI64 * t * t;
    let (s, c) = theta.sin_cos();
    let local = Vec3::new((s * phi.cos()) as f32, (s * phi.sin()) as f32, c as f32);
    frame.to_world(local).normalize()
}

/// Shares of `n` samples from `from` that are of a finite lobe, delta reflections and delta
/// refractions.
fn sample_shares(b: &Bsdf, from: Vec3, n: u32, seed: u64) -> (f64, f64, f64) {
    let mut rng = Rng::new(seed);
    let (mut finite, mut reflect, mut refract) = (0u32, 0u32, 0u32);
    for _ in 0..n {
        let Some(s) = b.sample(from, rng.f32(), rng.vec2(), TransportMode::Radiance) else {
            continue;
        };
        match (s.is_specular, s.is_transmission) {
            (false, _) => finite += 1,
            (true, false) => reflect += 1,
            (true, true) => refract += 1,
        }
    }
    let share = |k: u32| f64::from(k) / f64::from(n);
    (share(finite), share(reflect), share(refract))
}

/// Five binomial standard deviations of a share `p` of `n` samples, plus `slack`.
fn binomial_tolerance(p: f64, n: u32, slack: f64) -> f64 {
    5.0 * (p * (1.0 - p) / f64::from(n)).sqrt() + slack
}

/// (a) and (b): over the sphere, the forward density from `wo` (a function of `wi`) and the
/// reverse density toward `wi` (a function of `wo`) both integrate to the probability that
/// a sample from that fixed direction comes from a finite lobe, which is counted.
#[test]
fn densities_integrate_to_the_share_of_finite_samples() {
    let n = 200_000;
    for kind in finite_models() {
        let b = bsdf(kind, true);
        for theta in THETAS {
            for side in [1.0, -1.0] {
                let fixed = direction(&b, theta, side);
                let (finite, ..) = sample_shares(&b, fixed, n, 3);
                let forward = integrate(mirrored(fixed), 1200, 384, |wi| {
                    f64::from(b.pdfs(fixed, wi).forward)
                });
                let reverse = integrate(mirrored(fixed), 1200, 384, |wo| {
                    f64::from(b.pdfs(wo, fixed).reverse)
                });
                let tolerance = binomial_tolerance(finite, n, 3e-3);
                for (what, integral) in [("forward", forward), ("reverse", reverse)] {
                    assert!(
                        (integral - finite).abs() < tolerance,
                        "{kind:?} θ {theta} side {side}: ∫ {what} = {integral:.5}, \
                         share of finite samples {finite:.5}"
                    );
                }
                if let MaterialKind::Diffuse(_) = kind {
                    assert_eq!(finite, 1.0);
                }
            }
        }
    }
    // Delta lobes have no density: nothing to integrate, and no finite sample.
    for (kind, front_face) in delta_models() {
        let b = bsdf(kind, front_face);
        for theta in THETAS {
            for side in [1.0, -1.0] {
                let fixed = direction(&b, theta, side);
                let (finite, ..) = sample_shares(&b, fixed, 2000, 4);
                assert_eq!(finite, 0.0);
                let integral = integrate(mirrored(fixed), 60, 60, |w| {
                    let p = b.pdfs(fixed, w);
                    f64::from(p.forward + p.reverse)
                });
                assert_eq!(integral, 0.0, "{kind:?}");
            }
        }
    }
}

/// Pearson χ² of the directions `sample` draws from `from` against `density`, over bins of
/// (t, φ) about `axis` (θ = π t²) whose expectations integrate `density` by a midpoint rule;
/// bins expecting fewer than 5 samples are pooled. Returns (χ², degrees of freedom).
pub(super) fn chi_square(
    b: &Bsdf,
    from: Vec3,
    axis: Vec3,
    seed: u64,
    density: impl Fn(Vec3) -> f32,
) -> (f64, f64) {
    let mut rng = Rng::new(seed);
    let draw = || {
        let s = b.sample(from, rng.f32(), rng.vec2(), TransportMode::Importance)?;
        (!s.is_specular).then_some(s.incoming)
    };
    directional_chi_square(axis, draw, density, "sampled directions")
}

/// Pearson χ² of 200 000 draws of `draw` (a direction, or `None` for a draw that counts but
/// lands nowhere, such as a delta lobe's) against `density`, over bins of (t, φ) about `axis`
/// (θ = π t², 24 × 24) whose expectations integrate `density` by a midpoint rule of 8 × 8
/// points; bins expecting fewer than 5 samples are pooled. Returns (χ², degrees of freedom).
pub(crate) fn directional_chi_square(
    axis: Vec3,
    mut draw: impl FnMut() -> Option<Vec3>,
    density: impl Fn(Vec3) -> f32,
    what: &str,
) -> (f64, f64) {
    const N_T: usize = 24;
    const N_PHI: usize = 24;
    const SUB: usize = 8;
    const N: u32 = 200_000;
    let frame = Frame::from_normal(axis);
    let mut observed = vec![0.0f64; N_T * N_PHI];
    for _ in 0..N {
        let Some(incoming) = draw() else {
            continue;
        };
        let l = frame.to_local(incoming);
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
                    sum += f64::from(density(warped(&frame, t, phi))) * jacobian;
                }
            }
            let cell = (1.0 / (N_T * SUB) as f64) * (2.0 * PI64 / (N_PHI * SUB) as f64);
            expected[i * N_PHI + j] = sum * cell * f64::from(N);
        }
    }
    let (chi2, dof) = pearson_chi_square(&observed, &expected, what);
    (chi2, dof as f64)
}

/// (a) and (b): directions sampled from a fixed direction follow the forward density from it,
/// and the reverse density toward it read as a function of the other direction (which is what
/// "the density of sampling `outgoing` from `incoming`" means).
#[test]
fn sampled_directions_follow_the_forward_and_reverse_densities() {
    for kind in finite_models() {
        let b = bsdf(kind, true);
        for theta in [0.0, 45.0, 80.0, 89.0] {
            for side in [1.0, -1.0] {
                let fixed = direction(&b, theta, side);
                for what in ["forward", "reverse"] {
                    let density = |w| match what {
                        "forward" => b.pdfs(fixed, w).forward,
                        _ => b.pdfs(w, fixed).reverse,
                    };
                    let (chi2, dof) = chi_square(&b, fixed, mirrored(fixed), 12, density);
                    // Mean dof, standard deviation √(2 dof): allow 5 of them.
                    let limit = dof + 5.0 * (2.0 * dof).sqrt();
                    assert!(
                        chi2 < limit,
                        "{kind:?} θ {theta} side {side}, {what}: χ² {chi2:.1} with {dof} dof"
                    );
                }
            }
        }
    }
}

/// (b): the reverse density is the forward density of the swapped pair, and the forward one is
/// `pdf`, bit for bit; `sample_with_pdfs` draws what `sample` draws and reports the same
/// densities, in both transport modes.
#[test]
fn reverse_is_forward_swapped_and_sampling_reports_both() {
    let mut rng = Rng::new(21);
    for kind in finite_models() {
        for front_face in [true, false] {
            let b = bsdf(kind, front_face);
            for _ in 0..2000 {
                let (wo, wi) = (rng.unit(), rng.unit());
                let p = b.pdfs(wo, wi);
                assert_eq!(p.forward.to_bits(), b.pdf(wo, wi).to_bits());
                assert_eq!(p.reverse.to_bits(), b.pdf(wi, wo).to_bits());
                assert_eq!(p.reverse.to_bits(), b.pdfs(wi, wo).forward.to_bits());
                assert!(!p.is_specular);
                let (u_lobe, u) = (rng.f32(), rng.vec2());
                for mode in [TransportMode::Radiance, TransportMode::Importance] {
                    let plain = b.sample(wo, u_lobe, u, mode);
                    let with = b.sample_with_pdfs(wo, u_lobe, u, mode);
                    assert_eq!(plain, with.map(|(s, _)| s));
                    let Some((s, p)) = with else { continue };
                    assert_eq!(p.forward.to_bits(), s.pdf.to_bits());
                    assert_eq!(
                        p.reverse.to_bits(),
                        b.pdfs(wo, s.incoming).reverse.to_bits()
                    );
                    assert!(!p.is_specular);
                    let swapped = b.pdf(s.incoming, wo);
                    assert_eq!(p.reverse.to_bits(), swapped.to_bits());
                    // The sample's own density is pdf() up to rounding of the round trip.
                    let pdf = b.pdf(wo, s.incoming);
                    assert!((pdf - p.forward).abs() <= 1e-3 * pdf, "{pdf} vs {p:?}");
                }
            }
        }
    }
}

/// Delta events: every sample reports its lobe's probability from both sides, those
/// probabilities are the shares of each lobe among samples from either side (counted), and
/// sampling from the sample's direction returns to where it came from with the reverse one.
#[test]
fn delta_events_report_their_lobe_probabilities_both_ways() {
    let n = 40_000;
    for (kind, front_face) in delta_models() {
        let b = bsdf(kind, front_face);
        for theta in THETAS.into_iter().chain([40.0, 45.0, 50.0, 70.0]) {
            for side in [1.0, -1.0] {
                let wo = direction(&b, theta, side);
                let reflect = b.specular_probability(wo, false);
                let refract = b.specular_probability(wo, true);
                let (finite, reflected, refracted) = sample_shares(&b, wo, n, 5);
                assert_eq!(finite, 0.0);
                assert!((reflect + refract - 1.0).abs() < 1e-6, "{kind:?}");
                for (what, p, share) in [
                    ("reflection", reflect, reflected),
                    ("refraction", refract, refracted),
                ] {
                    assert!(
                        (share - f64::from(p)).abs() <= binomial_tolerance(f64::from(p), n, 0.0),
                        "{kind:?} {front_face} θ {theta} side {side}: {what} {p} vs {share}"
                    );
                }
                for lobe in [false, true] {
                    check_delta_lobe(&b, wo, lobe);
                }
            }
        }
    }
}

/// For the delta lobe `transmission` of `b` from `wo`: one of its samples, its reported
/// densities, and the share of samples from the far direction that come back to `wo`.
#[track_caller]
fn check_delta_lobe(b: &Bsdf, wo: Vec3, transmission: bool) {
    let forward = b.specular_probability(wo, transmission);
    // The lobe's sample, with u_lobe just inside its share of [0, 1).
    let u_lobe = if transmission { 0.999_999 } else { 0.0 };
    let sample = b.sample_with_pdfs(wo, u_lobe, Vec2::ZERO, TransportMode::Radiance);
    let Some((s, p)) = sample.filter(|(s, _)| s.is_transmission == transmission) else {
        assert!(forward == 0.0 || forward < 1e-6, "{forward}");
        return;
    };
    for mode in [TransportMode::Radiance, TransportMode::Importance] {
        let (_, q) = b
            .sample_with_pdfs(wo, u_lobe, Vec2::ZERO, mode)
            .expect("the same sample in the other mode");
        assert_eq!(q, p, "the densities do not depend on the mode");
    }
    assert!(p.is_specular && s.is_specular);
    assert_eq!(p.forward.to_bits(), s.pdf.to_bits());
    assert_eq!(p.forward.to_bits(), forward.to_bits());
    assert_eq!(
        p.reverse.to_bits(),
        b.specular_probability(s.incoming, transmission).to_bits()
    );
    // Fresnel's equations are reciprocal: R is the same from both sides of a refraction. Toward
    // grazing incidence the refracted direction nears the critical angle, where R is ill
    // conditioned in f32: 4·10⁻⁵ apart at 85°, 2·10⁻⁴ at 89.5°.
    let tolerance = 2e-5 + 1e-5 / wo.dot(normal()).abs();
    assert!(
        (p.reverse - p.forward).abs() < tolerance,
        "{p:?} wo {wo} {transmission} cos {}",
        wo.dot(normal())
    );
    assert_eq!(
        b.pdfs(wo, s.incoming),
        BsdfPdfs {
            forward: 0.0,
            reverse: 0.0,
            is_specular: false
        }
    );
    // Sampling from the far side returns along `wo` as often as the reverse probability says.
    let n = 20_000;
    let mut rng = Rng::new(8);
    let mut back = 0u32;
    for _ in 0..n {
        let t = b.sample(s.incoming, rng.f32(), rng.vec2(), TransportMode::Importance);
        if t.is_some_and(|t| t.incoming.dot(wo) > 1.0 - 1e-5) {
            back += 1;
        }
    }
    let share = f64::from(back) / f64::from(n);
    let p_rev = f64::from(p.reverse);
    assert!(
        (share - p_rev).abs() <= binomial_tolerance(p_rev, n, 0.0),
        "{share} of samples come back, reverse {p_rev}"
    );
}
