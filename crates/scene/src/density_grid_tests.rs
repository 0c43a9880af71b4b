//! Grid media against closed forms: trilinear lookups, the transmittance that ratio tracking
//! estimates (a constant grid against Beer–Lambert, a linear ramp against exp(−∫σt)), and the
//! distribution of delta-tracking free-flight distances through the ramp (χ² against the
//! analytic CDF). Tolerances come from the estimators' standard errors.

use std::sync::Arc;

use glam::{Affine3A, Vec3};

use super::*;
use crate::test_util::{Rng, pearson_chi_square};
use crate::{FreeFlight, Medium};

/// A medium of coefficients at density 1 `sigma_a`, `sigma_s` over `grid`.
fn grid_medium(sigma_a: Vec3, sigma_s: Vec3, grid: DensityGrid) -> Medium {
    Medium {
        name: "grid".into(),
        sigma_a,
        sigma_s,
        g: 0.0,
        density: Some(Arc::new(grid)),
    }
}

/// A ramp along x over the unit cube: `n` samples of density `a + b·x` at the voxel centres
/// x = (i + ½)/n, constant in y and z, clamped at the faces.
fn ramp(n: u32, a: f32, b: f32) -> DensityGrid {
    let data = (0..n * 2 * 2)
        .map(|i| a + b * ((i % n) as f32 + 0.5) / n as f32)
        .collect();
    DensityGrid::new(
        [n, 2, 2],
        data,
        GridEdge::Clamp,
        Vec3::ZERO,
        Vec3::ONE,
        Affine3A::IDENTITY,
    )
    .unwrap()
}

/// ∫₀ˣ of the ramp's density along the x axis: linear between the first and last voxel
/// centres h and 1 − h, constant (clamped) outside them.
fn ramp_integral(n: u32, a: f32, b: f32, x: f64) -> f64 {
    let (a, b, h) = (f64::from(a), f64::from(b), 0.5 / f64::from(n));
    let f = |x: f64| a + b * x.clamp(h, 1.0 - h);
    let antiderivative = |x: f64| a * x + 0.5 * b * x * x;
    let x = x.clamp(0.0, 1.0);
    let lo = x.min(h);
    let mid = (antiderivative(x.clamp(h, 1.0 - h)) - antiderivative(h)).max(0.0);
    let hi = (x - (1.0 - h)).max(0.0);
    lo * f(0.0) + mid + hi * f(1.0)
}

#[test]
fn lookups_are_trilinear_between_voxel_centres() {
    let grid = ramp(4, 1.0, 2.0);
    // Voxel centres read their samples; between them the blend is linear.
    for x in [0.125f32, 0.375, 0.5, 0.6, 0.875] {
        let d = grid.density(Vec3::new(x, 0.3, 0.7));
        assert!((d - (1.0 + 2.0 * x)).abs() < 1e-5, "x {x}: {d}");
    }
    // Clamped at the faces, zero outside the box.
    assert!((grid.density(Vec3::new(0.01, 0.5, 0.5)) - 1.25).abs() < 1e-6);
    assert_eq!(grid.density(Vec3::new(-0.01, 0.5, 0.5)), 0.0);
    // pbrt's rule: samples outside read zero, so a face reads half its nearest sample.
    let zero = DensityGrid::new(
        [1, 1, 1],
        vec![2.0],
        GridEdge::Zero,
        Vec3::ZERO,
        Vec3::ONE,
        Affine3A::IDENTITY,
    )
    .unwrap();
    assert!((zero.density(Vec3::new(0.5, 0.5, 0.5)) - 2.0).abs() < 1e-6);
    assert!((zero.density(Vec3::new(0.0, 0.5, 0.5)) - 1.0).abs() < 1e-6);
    // The placement: a box scaled by 2 and moved by (5, 0, 0).
    let placed = grid
        .placed(Affine3A::from_scale_rotation_translation(
            Vec3::splat(2.0),
            glam::Quat::IDENTITY,
            Vec3::new(5.0, 0.0, 0.0),
        ))
        .unwrap();
    assert!((placed.density(Vec3::new(6.0, 1.0, 1.0)) - 2.0).abs() < 1e-5);
    assert_eq!(
        placed.clip(Vec3::new(0.0, 1.0, 1.0), Vec3::X, 100.0),
        Some((5.0, 7.0))
    );
}

#[test]
fn bad_grids_are_refused() {
    let make = |size: [u32; 3], data: Vec<f32>| {
        DensityGrid::new(
            size,
            data,
            GridEdge::Clamp,
            Vec3::ZERO,
            Vec3::ONE,
            Affine3A::IDENTITY,
        )
    };
    assert!(matches!(
        make([0, 1, 1], vec![]),
        Err(GridError::ZeroSize(..))
    ));
    assert!(matches!(
        make([1 << 10, 1 << 10, 1 << 10], vec![]),
        Err(GridError::TooLarge(..))
    ));
    assert!(matches!(
        make([2, 1, 1], vec![1.0]),
        Err(GridError::Count { .. })
    ));
    assert!(matches!(
        make([2, 1, 1], vec![1.0, -0.5]),
        Err(GridError::Density { index: 1, .. })
    ));
    assert!(matches!(
        make([1, 1, 1], vec![f32::INFINITY]),
        Err(GridError::Density { .. })
    ));
    let flat = DensityGrid::new(
        [1, 1, 1],
        vec![1.0],
        GridEdge::Clamp,
        Vec3::ZERO,
        Vec3::new(1.0, 0.0, 1.0),
        Affine3A::IDENTITY,
    );
    assert!(matches!(flat, Err(GridError::Bounds(..))));
    let singular = DensityGrid::new(
        [1, 1, 1],
        vec![1.0],
        GridEdge::Clamp,
        Vec3::ZERO,
        Vec3::ONE,
        Affine3A::from_scale(Vec3::new(1.0, 0.0, 1.0)),
    );
    assert_eq!(singular, Err(GridError::Transform));
    assert!(check_grid_size(1 << 9, 1 << 9, 1 << 10).is_ok());
    assert!(check_grid_size(1 << 9, 1 << 9, (1 << 10) + 1).is_err());
    assert!(check_grid_size(u64::MAX, u64::MAX, 2).is_err());
}

/// Mean and standard error of `n` draws of `f` per channel.
fn mean_and_error(n: usize, mut f: impl FnMut() -> Vec3) -> (Vec3, Vec3) {
    let (mut sum, mut sum2) = (glam::DVec3::ZERO, glam::DVec3::ZERO);
    for _ in 0..n {
        let v = f().as_dvec3();
        sum += v;
        sum2 += v * v;
    }
    let mean = sum / n as f64;
    let var = (sum2 / n as f64 - mean * mean).max(glam::DVec3::ZERO);
    (mean.as_vec3(), (var / n as f64).sqrt().as_vec3())
}

/// Asserts `mean` is `expected` within four standard errors (and a float's rounding).
#[track_caller]
fn assert_close(mean: Vec3, error: Vec3, expected: Vec3, what: &str) {
    for c in 0..3 {
        let tolerance = 4.0 * error[c] + 1e-5;
        assert!(
            (mean[c] - expected[c]).abs() <= tolerance,
            "{what}, channel {c}: {} against {} (tolerance {tolerance})",
            mean[c],
            expected[c]
        );
    }
}

#[test]
fn a_constant_grid_transmits_as_the_homogeneous_medium() {
    let (sigma_a, sigma_s) = (Vec3::new(0.2, 0.5, 1.0), Vec3::new(0.6, 0.5, 1.5));
    let density = 1.5;
    let grid = DensityGrid::new(
        [3, 2, 5],
        vec![density; 30],
        GridEdge::Clamp,
        Vec3::splat(-1.0),
        Vec3::ONE,
        Affine3A::IDENTITY,
    )
    .unwrap();
    let medium = grid_medium(sigma_a, sigma_s, grid);
    let homogeneous = Medium::homogeneous("h", sigma_a * density, sigma_s * density, 0.0);
    let mut rng = Rng::new(7);
    let (origin, direction) = (
        Vec3::new(-1.0, -0.2, 0.1),
        Vec3::new(1.0, 0.3, -0.1).normalize(),
    );
    for d in [0.3, 1.0, 1.8] {
        let (mean, error) = mean_and_error(20_000, || {
            medium.transmittance_along(origin, direction, d, &mut || rng.f32())
        });
        assert_close(mean, error, homogeneous.transmittance(d), "ratio tracking");
    }
    // Free flight: the chance of reaching d, weighted, is the transmittance too.
    let q = Vec3::new(0.2, 0.3, 0.5);
    let d = 1.2;
    let (mean, error) = mean_and_error(40_000, || {
        match medium.sample_free_flight(origin, direction, d, q, &mut || rng.f32()) {
            FreeFlight::Pass { weight } => weight,
            FreeFlight::Scatter { .. } => Vec3::ZERO,
        }
    });
    assert_close(mean, error, homogeneous.transmittance(d), "delta tracking");
}

#[test]
fn ratio_tracking_through_a_ramp_is_exp_of_the_optical_depth() {
    let (n, a, b) = (8, 0.5, 3.0);
    let sigma_t = Vec3::new(0.5, 1.0, 2.0);
    let medium = grid_medium(sigma_t * 0.25, sigma_t * 0.75, ramp(n, a, b));
    let mut rng = Rng::new(11);
    for x in [0.05, 0.4, 0.7, 1.0] {
        let depth = ramp_integral(n, a, b, f64::from(x)) as f32;
        let expected = (-sigma_t * depth).exp();
        // Along x from the face x = 0, off the y and z centres.
        let origin = Vec3::new(0.0, 0.3, 0.8);
        let (mean, error) = mean_and_error(20_000, || {
            medium.transmittance_along(origin, Vec3::X, x, &mut || rng.f32())
        });
        assert_close(mean, error, expected, "ramp");
    }
    // A ray that starts outside the box and leaves it: only the stretch inside counts.
    let depth = ramp_integral(n, a, b, 1.0) as f32;
    let (mean, error) = mean_and_error(20_000, || {
        medium.transmittance_along(Vec3::new(-3.0, 0.5, 0.5), Vec3::X, 10.0, &mut || rng.f32())
    });
    assert_close(mean, error, (-sigma_t * depth).exp(), "ramp, through");
}

#[test]
fn delta_tracking_distances_follow_the_ramps_distribution() {
    let (n, a, b) = (8, 0.2, 2.5);
    let sigma_t = 1.5f32;
    // Albedo one and grey: every real collision scatters, with weight one.
    let medium = grid_medium(Vec3::ZERO, Vec3::splat(sigma_t), ramp(n, a, b));
    let cdf = |x: f64| 1.0 - (-f64::from(sigma_t) * ramp_integral(n, a, b, x)).exp();
    let bins = 20;
    let samples = 200_000;
    let mut observed = vec![0.0; bins + 1];
    let mut rng = Rng::new(3);
    let origin = Vec3::new(0.0, 0.5, 0.5);
    let q = Vec3::splat(1.0 / 3.0);
    for _ in 0..samples {
        match medium.sample_free_flight(origin, Vec3::X, 1.0, q, &mut || rng.f32()) {
            FreeFlight::Scatter { t, weight } => {
                assert!((weight - Vec3::ONE).abs().max_element() < 1e-5, "{weight}");
                observed[((t * bins as f32) as usize).min(bins - 1)] += 1.0;
            }
            FreeFlight::Pass { weight } => {
                assert!((weight - Vec3::ONE).abs().max_element() < 1e-4, "{weight}");
                observed[bins] += 1.0;
            }
        }
    }
    let mut expected: Vec<f64> = (0..bins)
        .map(|i| {
            let (lo, hi) = (i as f64 / bins as f64, (i + 1) as f64 / bins as f64);
            samples as f64 * (cdf(hi) - cdf(lo))
        })
        .collect();
    expected.push(samples as f64 * (1.0 - cdf(1.0)));
    let (chi2, dof) = pearson_chi_square(&observed, &expected, "free-flight distances");
    let dof = dof as f64;
    let limit = dof + 5.0 * (2.0 * dof).sqrt();
    assert!(chi2 < limit, "χ² {chi2:.1} with {dof} dof");
}

#[test]
fn spectral_tracking_is_unbiased_per_channel_in_a_chromatic_ramp() {
    let (n, a, b) = (8, 0.2, 2.5);
    let sigma_t = Vec3::new(0.3, 1.0, 3.0);
    let medium = grid_medium(sigma_t * 0.5, sigma_t * 0.5, ramp(n, a, b));
    let depth = ramp_integral(n, a, b, 0.8) as f32;
    let mut rng = Rng::new(5);
    let q = Vec3::new(0.5, 0.3, 0.2);
    let (mean, error) = mean_and_error(60_000, || {
        match medium
            .sample_free_flight(Vec3::new(0.0, 0.5, 0.5), Vec3::X, 0.8, q, &mut || rng.f32())
        {
            FreeFlight::Pass { weight } => weight,
            FreeFlight::Scatter { .. } => Vec3::ZERO,
        }
    });
    assert_close(
        mean,
        error,
        (-sigma_t * depth).exp(),
        "chromatic pass weight",
    );
}

#[test]
fn majorant_segments_cover_the_ray_and_bound_its_densities() {
    let mut rng = Rng::new(17);
    // Larger than the majorant grid on two axes, smaller on one; random densities; rotated,
    // scaled and moved; both edge rules.
    let size = [37, 5, 20];
    let data: Vec<f32> = (0..37 * 5 * 20)
        .map(|_| {
            let v = rng.f32();
            v * v * v * 4.0
        })
        .collect();
    let to_world = Affine3A::from_scale_rotation_translation(
        Vec3::new(1.5, 0.5, 2.0),
        glam::Quat::from_rotation_y(0.7) * glam::Quat::from_rotation_x(-0.3),
        Vec3::new(0.2, -1.0, 0.4),
    );
    for edge in [GridEdge::Clamp, GridEdge::Zero] {
        let grid = DensityGrid::new(
            size,
            data.clone(),
            edge,
            Vec3::splat(-1.0),
            Vec3::ONE,
            to_world,
        )
        .unwrap();
        let mut crossing = 0;
        for _ in 0..300 {
            let origin = rng.vec3(-3.0, 3.0);
            // Half the rays aim at a point of the box, half go anywhere.
            let direction = if rng.f32() < 0.5 {
                (to_world.transform_point3(rng.vec3(-1.0, 1.0)) - origin).normalize()
            } else {
                rng.unit()
            };
            let t_max = if rng.f32() < 0.3 { 2.0 } else { f32::INFINITY };
            let segments = grid.majorant_segments(origin, direction, t_max);
            let Some((t0, t1)) = grid.clip(origin, direction, t_max) else {
                assert!(segments.is_empty());
                continue;
            };
            crossing += 1;
            assert_eq!(segments.first().map(|s| s.t0), Some(t0));
            assert_eq!(segments.last().map(|s| s.t1), Some(t1));
            for pair in segments.windows(2) {
                assert_eq!(pair[0].t1, pair[1].t0);
            }
            for s in &segments {
                assert!(s.t0 <= s.t1);
                for k in 0..=16 {
                    let t = s.t0 + (s.t1 - s.t0) * k as f32 / 16.0;
                    let d = grid.density(origin + direction * t);
                    assert!(
                        d <= s.max_density * (1.0 + 1e-5) + 1e-6,
                        "{edge:?}: density {d} above its cell's {}",
                        s.max_density
                    );
                }
            }
        }
        assert!(crossing > 100, "{crossing} rays crossed the box");
    }
}
