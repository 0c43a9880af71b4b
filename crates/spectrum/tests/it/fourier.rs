//! Convention tests against direct numerical Fourier transforms (design §9.4).
//!
//! Each test samples the primal light field L(z) = exp(−π² zᵀQ⁻¹z) of a known Q, applies a
//! primal operation (shear, scale, window, angular convolution), Fourier-transforms the
//! result numerically with the crate's convention l̂(Ω) = ∫ L(z) e^{−2πiΩᵀz} dz, fits
//! (a, b, c) from ln(l̂(0)/l̂(Ω)) = ΩᵀQΩ at three frequencies, and compares the fit with
//! the Q-form operator. This checks the conventions independently of the algebra: the
//! direction of each shear, the 2π² factors and which form (Q or Σ) each update adds to.

use std::f64::consts::PI;

use spectrum::{Caps, Lobe, Spectrum};

use crate::support::q0;

const U: &Caps = &Caps::UNBOUNDED;
const N: usize = 241;

/// The primal field of a spectrum: exp(−π² zᵀQ⁻¹z).
fn primal(q: &Spectrum) -> impl Fn(f64, f64) -> f64 + use<> {
    let det = q.determinant();
    let (a, b, c) = (q.a(), q.b(), q.c());
    move |x, t| (-PI * PI * (b * x * x - 2.0 * c * x * t + a * t * t) / det).exp()
}

/// A grid of N points covering ±7 primal standard deviations of `expected` per axis.
fn grid(expected: &Spectrum) -> (Vec<f64>, Vec<f64>, f64, f64) {
    let sigma = |v: f64| (v / (2.0 * PI * PI)).sqrt();
    let axis = |half: f64| -> (Vec<f64>, f64) {
        let h = 2.0 * half / (N - 1) as f64;
        ((0..N).map(|i| -half + h * i as f64).collect(), h)
    };
    let (xs, hx) = axis(7.0 * sigma(expected.a()));
    let (ts, ht) = axis(7.0 * sigma(expected.b()));
    (xs, ts, hx, ht)
}

/// Fits (a, b, c) of sampled values `values[i][j]` = L(xs[i], ts[j]) (an even function).
fn fit(values: &[Vec<f64>], xs: &[f64], ts: &[f64], expected: &Spectrum) -> (f64, f64, f64) {
    let transform = |wx: f64, wt: f64| -> f64 {
        let mut sum = 0.0;
        for (i, x) in xs.iter().enumerate() {
            for (j, t) in ts.iter().enumerate() {
                sum += values[i][j] * (2.0 * PI * (wx * x + wt * t)).cos();
            }
        }
        sum
    };
    // Frequencies where each exponent is about 1.
    let sx = 1.0 / expected.a().sqrt();
    let st = 1.0 / expected.b().sqrt();
    let l0 = transform(0.0, 0.0);
    let e1 = (l0 / transform(sx, 0.0)).ln();
    let e2 = (l0 / transform(0.0, st)).ln();
    let e3 = (l0 / transform(sx, st)).ln();
    (
        e1 / (sx * sx),
        e2 / (st * st),
        (e3 - e1 - e2) / (2.0 * sx * st),
    )
}

/// Samples `field` on the grid of `expected`, fits it, and compares with `expected`.
#[track_caller]
fn check(field: impl Fn(f64, f64) -> f64, expected: Spectrum, tol: f64) {
    let (xs, ts, _, _) = grid(&expected);
    let values: Vec<Vec<f64>> = xs
        .iter()
        .map(|&x| ts.iter().map(|&t| field(x, t)).collect())
        .collect();
    let (a, b, c) = fit(&values, &xs, &ts, &expected);
    let scale_c = (expected.a() * expected.b()).sqrt();
    assert_close!(a, expected.a(), tol);
    assert_close!(b, expected.b(), tol);
    assert!(
        (c - expected.c()).abs() <= tol * scale_c,
        "c = {c}, expected {}",
        expected.c()
    );
}

#[test]
fn the_fit_recovers_q() {
    check(primal(&q0()), q0(), 1e-9);
}

#[test]
fn travel_shears_space_by_angle() {
    // A ray at (x, θ) reaches x + dθ: L'(x, θ) = L(x − dθ, θ).
    let d = 0.7;
    let l = primal(&q0());
    check(move |x, t| l(x - d * t, t), q0().travel(d, U), 1e-8);
}

#[test]
fn kick_shears_angle_by_space() {
    // θ' = θ + g·x: L'(x, θ) = L(x, θ − g·x).
    let g = -0.8;
    let l = primal(&q0());
    check(move |x, t| l(x, t - g * x), q0().kick(g, U), 1e-8);
}

#[test]
fn projection_stretches_space() {
    // Surface coordinate u = x/μ: L_s(u, θ) = L(μ·u, θ).
    let mu = 0.6;
    let l = primal(&q0());
    check(move |u, t| l(mu * u, t), q0().project_in(mu, U), 1e-8);
}

#[test]
fn window_is_occlusion() {
    // A Gaussian window of primal width w has spectral variance o = 1/(4π²w²).
    let w: f64 = 0.3;
    let o = 1.0 / (4.0 * PI * PI * w * w);
    let l = primal(&q0());
    check(
        move |x, t| l(x, t) * (-x * x / (2.0 * w * w)).exp(),
        q0().occlude(o, U),
        1e-8,
    );
}

#[test]
fn angular_convolution_is_the_bandlimit() {
    // L'(x, θ) = ∫ L(x, θ') ρ(θ − θ') dθ' with ρ a Gaussian of std σ: b' = b + 2π²σ².
    let sigma: f64 = 0.15;
    let expected = q0().bandlimit(
        Lobe::Gaussian {
            variance: sigma * sigma,
        },
        U,
    );
    let l = primal(&q0());
    // Integrate over θ' on a fine grid wide enough for both factors.
    let (_, ts, _, ht) = grid(&expected);
    let rho = |t: f64| (-t * t / (2.0 * sigma * sigma)).exp() / (sigma * (2.0 * PI).sqrt());
    check(
        move |x, t| ts.iter().map(|&tp| l(x, tp) * rho(t - tp) * ht).sum(),
        expected,
        1e-7,
    );
}
