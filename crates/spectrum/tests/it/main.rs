//! Integration tests of the `spectrum` crate: one binary, one module per concern.
#![allow(clippy::unwrap_used, clippy::print_stdout)]

/// Asserts that two floats agree to a relative tolerance (default 10⁻⁹), printing both
/// values and their difference on failure. A relative tolerance is measured against
/// max(|expected|, |got|); exact zeros must then match to `tol` absolutely.
macro_rules! assert_close {
    ($got:expr, $expected:expr) => {
        assert_close!($got, $expected, 1e-9)
    };
    ($got:expr, $expected:expr, $tol:expr) => {{
        let (got, expected, tol): (f64, f64, f64) = ($got, $expected, $tol);
        let scale = got.abs().max(expected.abs()).max(if got == 0.0 || expected == 0.0 { 1.0 } else { 0.0 });
        let diff = got - expected;
        assert!(
            diff.abs() <= tol * scale,
            "{} = {got:e}, expected {} = {expected:e}: difference {diff:e} (relative {:e}, tolerance {tol:e})",
            stringify!($got),
            stringify!($expected),
            diff.abs() / scale.max(f64::MIN_POSITIVE),
        );
    }};
}

/// Asserts that a spectrum has the given (a, b, c) to a relative tolerance.
macro_rules! assert_abc {
    ($q:expr, ($a:expr, $b:expr, $c:expr)) => {
        assert_abc!($q, ($a, $b, $c), 1e-9)
    };
    ($q:expr, ($a:expr, $b:expr, $c:expr), $tol:expr) => {{
        let q: spectrum::Spectrum = $q;
        assert_close!(q.a(), $a, $tol);
        assert_close!(q.b(), $b, $tol);
        assert_close!(q.c(), $c, $tol);
    }};
}

mod support;

/// The conservative 3D collapse against explicit tangential and sagittal maps.
mod collapse;

/// Degenerate and wild inputs never give NaN or a non-PSD form.
mod degenerate;
/// The hitpoint accumulator and its merge policies.
mod estimate;
/// Conventions checked against numerical Fourier transforms (§9.4).
mod fourier;
/// Known input → output rows of the design's table (§9.1).
mod known_values;
/// Algebraic laws and invariants over random PSD inputs (§9.2).
mod laws;
/// Snapshots of complete photon paths, so convention changes show in review.
mod paths;
/// End-to-end optics: virtual images, focusing, lens imaging (§9.3).
mod physics;
