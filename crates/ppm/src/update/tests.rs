use super::*;

const BEFORE: GatherStats = GatherStats {
    radius: 1.0,
    photon_count: 10.0,
    flux: [3.0; 3],
};

#[track_caller]
fn check(
    before: GatherStats,
    m: u32,
    phi: f64,
    freq: FrequencyRadius,
    floor: FrequencyFloor,
    expected: GatherStats,
) {
    let mut stats = before;
    stats.update(m, [phi; 3], 0.7, freq, floor);
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-9 * b.abs().max(1.0);
    assert!(
        close(stats.radius, expected.radius)
            && close(stats.photon_count, expected.photon_count)
            && (0..3).all(|c| close(stats.flux[c], expected.flux[c])),
        "got {stats:?}, expected {expected:?}"
    );
}

const SHRUNK: GatherStats = GatherStats {
    radius: 0.948683298,
    photon_count: 13.5,
    flux: [3.6; 3],
};
const KEPT: GatherStats = GatherStats {
    radius: 1.0,
    photon_count: 15.0,
    flux: [4.0; 3],
};

#[test]
fn ppm_shrink_design_doc_row() {
    // §9.1: R=1, N=10, M=5, α=0.7, τ=3, Φ=1 → N′=13.5, R′=0.948683298, τ′=3.6.
    for floor in [FrequencyFloor::Keep, FrequencyFloor::Clamp] {
        check(BEFORE, 5, 1.0, FrequencyRadius::None, floor, SHRUNK);
        // A frequency radius below R still shrinks.
        check(
            BEFORE,
            5,
            1.0,
            FrequencyRadius::Predicted(0.5),
            floor,
            SHRUNK,
        );
    }
}

#[test]
fn ppm_keep_design_doc_row() {
    // §9.1: same, with R ≤ r_freq → N′=15, R′=1, τ′=4.
    for floor in [FrequencyFloor::Keep, FrequencyFloor::Clamp] {
        check(BEFORE, 5, 1.0, FrequencyRadius::Predicted(1.0), floor, KEPT);
        check(BEFORE, 5, 1.0, FrequencyRadius::Predicted(2.0), floor, KEPT);
    }
}

#[test]
fn no_photons_changes_nothing() {
    check(
        BEFORE,
        0,
        0.0,
        FrequencyRadius::None,
        FrequencyFloor::Keep,
        BEFORE,
    );
}

#[test]
fn clamp_stops_at_frequency_radius() {
    // The PPM shrink would reach 0.948683298 < r_freq = 0.97: the clamp holds R′ = 0.97 and
    // sets N′ = (N + M)·R′²/R² = 15·0.9409.
    let clamped = GatherStats {
        radius: 0.97,
        photon_count: 15.0 * 0.9409,
        flux: [4.0 * 0.9409; 3],
    };
    check(
        BEFORE,
        5,
        1.0,
        FrequencyRadius::Predicted(0.97),
        FrequencyFloor::Clamp,
        clamped,
    );
    // The poster's rule steps below r_freq once, then keeps.
    check(
        BEFORE,
        5,
        1.0,
        FrequencyRadius::Predicted(0.97),
        FrequencyFloor::Keep,
        SHRUNK,
    );
}

#[test]
fn alpha_one_never_shrinks() {
    let mut stats = GatherStats::new(0.25);
    for pass in 0..1000 {
        stats.update(
            1 + pass % 7,
            [1.0; 3],
            1.0,
            FrequencyRadius::None,
            FrequencyFloor::Keep,
        );
        assert_eq!(stats.radius, 0.25);
    }
}

/// Least-squares slope of (x, y) pairs.
fn slope(points: &[(f64, f64)]) -> f64 {
    let n = points.len() as f64;
    let (mx, my) = points
        .iter()
        .fold((0.0, 0.0), |(a, b), &(x, y)| (a + x / n, b + y / n));
    let sxy: f64 = points.iter().map(|&(x, y)| (x - mx) * (y - my)).sum();
    let sxx: f64 = points.iter().map(|&(x, _)| (x - mx) * (x - mx)).sum();
    sxy / sxx
}

#[test]
fn shrink_law_under_uniform_density() {
    // Uniform photon density ρ per unit area and pass: M = round(ρ·πR²). Asymptotically
    // R² ∝ i^(α−1) in the pass index i (Knaus & Zwicker 2011), equivalently
    // R² ∝ N^(−(1−α)/α) in the accumulated count, since N′ − N = αM and d ln R² ≈ −(1−α)M/N.
    let alpha = 0.7;
    let density = 1.0e6;
    let mut stats = GatherStats::new(0.1);
    let (mut by_pass, mut by_count) = (Vec::new(), Vec::new());
    for pass in 1..=20_000_u32 {
        let m = (density * std::f64::consts::PI * stats.radius * stats.radius).round() as u32;
        stats.update(
            m,
            [0.0; 3],
            alpha,
            FrequencyRadius::None,
            FrequencyFloor::Keep,
        );
        if pass >= 2000 && pass % 100 == 0 {
            let log_r2 = (stats.radius * stats.radius).ln();
            by_pass.push((f64::from(pass).ln(), log_r2));
            by_count.push((stats.photon_count.ln(), log_r2));
        }
    }
    let (s_pass, s_count) = (slope(&by_pass), slope(&by_count));
    assert!(
        (s_pass - (alpha - 1.0)).abs() < 0.01,
        "R² ∝ i^{s_pass}, expected i^{}",
        alpha - 1.0
    );
    let expected = -(1.0 - alpha) / alpha;
    assert!(
        (s_count - expected).abs() < 0.01,
        "R² ∝ N^{s_count}, expected N^{expected}"
    );
}

#[test]
fn estimate_of_uniform_density_stays_unbiased_across_shrinks() {
    // Photons exactly uniform in area: each pass brings flux Φ = E·πR² into the disc, whatever
    // the photon count M. Then L = τ/(πR²·n_passes) = E after every pass, although R shrinks.
    let irradiance = 2.5;
    let mut stats = GatherStats::new(0.3);
    for pass in 1..=500_u32 {
        let phi = irradiance * std::f64::consts::PI * stats.radius * stats.radius;
        stats.update(
            3 + pass % 5,
            [phi, 2.0 * phi, 0.5 * phi],
            0.7,
            FrequencyRadius::None,
            FrequencyFloor::Keep,
        );
        let [r, g, b] = stats.radiance(f64::from(pass)).expect("positive radius");
        for (got, want) in [
            (r, irradiance),
            (g, 2.0 * irradiance),
            (b, 0.5 * irradiance),
        ] {
            assert!(
                (got - want).abs() <= 1e-12 * want,
                "pass {pass}: {got} vs {want}"
            );
        }
    }
    assert!(
        stats.radius < 0.1,
        "the radius did shrink: {}",
        stats.radius
    );
}

#[test]
fn radiance_of_degenerate_states() {
    assert_eq!(GatherStats::new(0.0).radiance(10.0), None);
    assert_eq!(GatherStats::new(1.0).radiance(0.0), None);
    let stats = GatherStats {
        radius: 1.0,
        photon_count: 1.0,
        flux: [std::f64::consts::PI; 3],
    };
    assert_eq!(stats.radiance(1.0), Some([1.0; 3]));
}
