//! The conductor against what does not share its code: Fresnel at normal incidence in closed
//! form, the white furnace (a perfect conductor reflects 1 when smooth, and when rough what an
//! independent numerical integral of the GGX single-scattering model gives), the sampler's
//! χ² against its density, the evaluation at sampled wavelengths against the Born and Wolf
//! closed form, and the RGB η and k derived from pbrt-v4's spectra against Mitsuba 3's. The
//! forward and reverse densities are checked with every other model's in `pdf_tests.rs`.

use std::f64::consts::PI;

use glam::{DVec3, Vec3};

use super::pdf_tests::{bsdf, chi_square, direction, mirrored, normal};
use super::{Bsdf, Conductor, MaterialKind, TransportMode};
use crate::Rgb;
use crate::spectral::{self, MITSUBA_RGB_METALS, SampledWavelengths};
use crate::test_util::Rng;

fn conductor(eta: Rgb, k: Rgb, roughness: f32) -> Conductor {
    Conductor {
        eta,
        k,
        specular_reflectance: Rgb::ONE,
        roughness,
    }
}

/// η = 1, k = 10⁴: Fresnel is 1 to within 10⁻⁷ at every angle.
fn perfect(roughness: f32) -> Conductor {
    conductor(Rgb::ONE, Rgb::splat(1e4), roughness)
}

/// The mean weight of `n` samples from `wo`: the Monte Carlo estimate of the directional albedo.
fn albedo_by_sampling(b: &Bsdf, wo: Vec3, n: u32) -> f64 {
    let mut rng = Rng::new(5);
    let mut sum = 0.0;
    for _ in 0..n {
        if let Some(s) = b.sample(wo, rng.f32(), rng.vec2(), TransportMode::Radiance) {
            sum += f64::from(s.weight.x);
        }
    }
    sum / f64::from(n)
}

/// GGX D in double precision, written from Walter et al. 2007 (eq. 33).
fn ggx_d(cos_m: f64, alpha: f64) -> f64 {
    let c2 = cos_m * cos_m;
    let t2 = (1.0 - c2) / c2;
    let a2 = alpha * alpha;
    a2 / (PI * c2 * c2 * (a2 + t2) * (a2 + t2))
}

/// Smith Λ for GGX (Heitz 2014, eq. 72).
fn lambda(cos: f64, alpha: f64) -> f64 {
    let t2 = (1.0 - cos * cos) / (cos * cos);
    0.5 * (-1.0 + (1.0 + alpha * alpha * t2).sqrt())
}

/// The single-scattering GGX reflection with F = 1 and height-correlated Smith G₂, integrated
/// over the hemisphere of ωi in spherical coordinates (midpoint rule, `n` × 2`n` cells): the
/// directional albedo of a perfect rough conductor seen from polar angle `theta`.
fn ggx_albedo(theta: f64, alpha: f64, n: usize) -> f64 {
    let wo = DVec3::new(theta.sin(), 0.0, theta.cos());
    let mut sum = 0.0;
    for i in 0..n {
        let ti = (i as f64 + 0.5) / n as f64 * 0.5 * PI;
        let (si, ci) = ti.sin_cos();
        for j in 0..2 * n {
            let pj = (j as f64 + 0.5) / (2 * n) as f64 * 2.0 * PI;
            let wi = DVec3::new(si * pj.cos(), si * pj.sin(), ci);
            let wm = (wo + wi).normalize();
            let g2 = 1.0 / (1.0 + lambda(wo.z, alpha) + lambda(wi.z, alpha));
            let f = ggx_d(wm.z, alpha) * g2 / (4.0 * wo.z * wi.z);
            sum += f * ci * si;
        }
    }
    sum * (0.5 * PI / n as f64) * (2.0 * PI / (2 * n) as f64)
}

#[test]
fn normal_incidence_is_the_closed_form() {
    let eta = Rgb::new(0.2, 1.1, 2.9);
    let k = Rgb::new(3.5, 0.0, 3.1);
    let c = conductor(eta, k, 0.0);
    let a = MaterialKind::Conductor(c).albedo();
    for i in 0..3 {
        let (n, k) = (f64::from(eta[i]), f64::from(k[i]));
        let expected = ((n - 1.0).powi(2) + k * k) / ((n + 1.0).powi(2) + k * k);
        assert!((f64::from(a[i]) - expected).abs() < 1e-6, "{i}: {a}");
    }
    // The smooth conductor's sample at normal incidence carries the same reflectance, tinted.
    let tinted = Conductor {
        specular_reflectance: Rgb::new(0.5, 1.0, 0.25),
        ..c
    };
    let b = bsdf(MaterialKind::Conductor(tinted), true);
    let s = b
        .sample(
            normal(),
            0.5,
            glam::Vec2::splat(0.5),
            TransportMode::Radiance,
        )
        .unwrap();
    assert!(s.is_specular && s.pdf == 1.0);
    assert!((s.incoming - normal()).length() < 1e-5);
    assert!(
        (s.weight - a * tinted.specular_reflectance)
            .abs()
            .max_element()
            < 1e-6
    );
}

#[test]
fn white_furnace() {
    let smooth = bsdf(MaterialKind::Conductor(perfect(0.0)), true);
    for theta in [0.0, 30.0, 60.0, 85.0, 89.0] {
        for side in [1.0, -1.0] {
            let wo = direction(&smooth, theta, side);
            let s = smooth
                .sample(wo, 0.3, glam::Vec2::new(0.2, 0.7), TransportMode::Radiance)
                .unwrap();
            assert!((s.weight - Rgb::ONE).abs().max_element() < 1e-5, "{s:?}");
            assert!((s.incoming - mirrored(wo)).length() < 1e-5);
        }
    }
    for alpha in [0.05, 0.2, 0.5, 1.0] {
        let rough = bsdf(MaterialKind::Conductor(perfect(alpha)), true);
        for theta in [0.0f32, 30.0, 60.0, 80.0] {
            let wo = direction(&rough, theta, 1.0);
            let expected = ggx_albedo(f64::from(theta).to_radians(), f64::from(alpha), 400);
            let measured = albedo_by_sampling(&rough, wo, 100_000);
            assert!(
                (measured - expected).abs() < 5e-3 && measured <= 1.0 + 5e-3,
                "α {alpha} θ {theta}: sampled {measured:.4}, integral {expected:.4}"
            );
        }
    }
    // The integral itself: nearly 1 for a sharp lobe, GGX's known loss for a rough one
    // (Kulla and Conty 2017: about 0.7 at α = 0.5 and 0.3 at α = 1, normal incidence).
    assert!(ggx_albedo(0.0, 0.05, 400) > 0.99);
    let (half, one) = (ggx_albedo(0.0, 0.5, 400), ggx_albedo(0.0, 1.0, 400));
    assert!(
        (0.6..0.8).contains(&half) && (0.25..0.4).contains(&one),
        "{half} {one}"
    );
}

/// Sampled directions of the rough conductor follow [`Bsdf::pdf`], from several angles and
/// both sides.
#[test]
fn sampling_matches_the_density() {
    let gold = Conductor {
        specular_reflectance: Rgb::new(0.9, 0.8, 0.7),
        ..conductor(
            Rgb::new(0.143, 0.375, 1.442),
            Rgb::new(3.983, 2.386, 1.603),
            0.3,
        )
    };
    let b = bsdf(MaterialKind::Conductor(gold), true);
    for theta in [0.0, 45.0, 80.0] {
        for side in [1.0, -1.0] {
            let wo = direction(&b, theta, side);
            let (chi2, dof) = chi_square(&b, wo, mirrored(wo), 31, |w| b.pdf(wo, w));
            let limit = dof + 5.0 * (2.0 * dof).sqrt();
            assert!(
                chi2 < limit,
                "θ {theta} side {side}: χ² {chi2:.1}, {dof} dof"
            );
        }
    }
}

/// The conductor's Fresnel reflectance in the closed form of Born and Wolf (pbrt-v3's
/// `FrConductor`), real arithmetic only.
fn born_wolf(cos: f64, n: f64, k: f64) -> f64 {
    let cos2 = cos * cos;
    let sin2 = 1.0 - cos2;
    let t0 = n * n - k * k - sin2;
    let a2_b2 = (t0 * t0 + 4.0 * n * n * k * k).sqrt();
    let a = (0.5 * (a2_b2 + t0)).sqrt();
    let rs = (a2_b2 + cos2 - 2.0 * a * cos) / (a2_b2 + cos2 + 2.0 * a * cos);
    let t3 = cos2 * a2_b2 + sin2 * sin2;
    let t4 = 2.0 * a * cos * sin2;
    0.5 * (rs + rs * (t3 - t4) / (t3 + t4))
}

/// At sampled wavelengths the rough conductor is D·G₂·F(λ)/(4 cos θₒ cos θᵢ) with gold's η(λ),
/// k(λ); with spectra constant at the RGB values it is the RGB evaluation.
#[test]
fn evaluation_at_sampled_wavelengths() {
    let gold = spectral::Conductor::named("Au").unwrap();
    let model = conductor(Rgb::ONE, Rgb::ONE, 0.3);
    let wo = Vec3::new(0.3, 0.1, 0.9).normalize();
    let wi = Vec3::new(-0.5, 0.2, 0.7).normalize();
    let wm = (wo + wi).normalize();
    let (cos_o, cos_i) = (f64::from(wo.z), f64::from(wi.z));
    let a = 0.3;
    let g2 = 1.0 / (1.0 + lambda(cos_o, a) + lambda(cos_i, a));
    let microfacet = ggx_d(f64::from(wm.z), a) * g2 / (4.0 * cos_o * cos_i);
    for u in [0.0, 0.3, 0.77] {
        let w = SampledWavelengths::sample_uniform(u);
        let f = model.eval_spectral(&gold, wo, wi, &w);
        for lane in 0..4 {
            let (n, k) = gold.eval(f64::from(w.lambda(lane)));
            let expected = born_wolf(f64::from(wi.dot(wm)), n, k) * microfacet;
            assert!(
                (f64::from(f[lane]) - expected).abs() < 1e-4 * expected,
                "λ {}: {} vs {expected}",
                w.lambda(lane),
                f[lane]
            );
        }
        // Opposite sides scatter nothing; the smooth conductor has no density to evaluate.
        assert!(model.eval_spectral(&gold, wo, -wi, &w).is_black());
        let smooth = Conductor {
            roughness: 0.0,
            ..model
        };
        assert!(smooth.eval_spectral(&gold, wo, wi, &w).is_black());
    }
    // Flat spectra at the RGB η and k give the RGB evaluation in every channel.
    let flat = |v: f64| spectral::PiecewiseLinear::new(vec![300.0, 900.0], vec![v, v]).unwrap();
    let (n, k) = (0.27, 2.78);
    let c = spectral::Conductor::new(flat(n), flat(k)).unwrap();
    let rgb = conductor(Rgb::splat(n as f32), Rgb::splat(k as f32), 0.3);
    let f_rgb = bsdf(MaterialKind::Conductor(rgb), true);
    let frame = f_rgb.frame();
    let expected = f_rgb.eval(frame.to_world(wo), frame.to_world(wi)).x;
    let f = rgb.eval_spectral(&c, wo, wi, &SampledWavelengths::sample_uniform(0.4));
    for lane in 0..4 {
        assert!(
            (f[lane] - expected).abs() < 1e-4 * expected,
            "{f:?} vs {expected}"
        );
    }
}

/// pbrt-v4's measured η and k of gold, copper, silver and aluminium, turned into RGB as
/// `spectral::Conductor::rgb` does (Mitsuba's way for its named conductors, from its own data
/// files), land within 6 % of the RGB values Mitsuba 3 loads for the same metals; the
/// reflectances at normal incidence within 0.02.
#[test]
fn rgb_eta_and_k_match_mitsuba() {
    for name in ["Au", "Cu", "Ag", "Al"] {
        let (eta, k) = spectral::Conductor::named(name).unwrap().rgb();
        let (_, m_eta, m_k) = MITSUBA_RGB_METALS
            .iter()
            .find(|(n, _, _)| *n == name)
            .unwrap();
        let ours = conductor(
            Rgb::from_array(eta.map(|x| x as f32)),
            Rgb::from_array(k.map(|x| x as f32)),
            0.0,
        );
        let mitsuba = conductor(Rgb::from_array(*m_eta), Rgb::from_array(*m_k), 0.0);
        for c in 0..3 {
            assert!(
                (ours.k[c] - mitsuba.k[c]).abs() < 0.06 * mitsuba.k[c],
                "{name} k: {} vs {}",
                ours.k,
                mitsuba.k
            );
        }
        let (a, b) = (
            MaterialKind::Conductor(ours).albedo(),
            MaterialKind::Conductor(mitsuba).albedo(),
        );
        assert!((a - b).abs().max_element() < 0.02, "{name}: {a} vs {b}");
    }
}
