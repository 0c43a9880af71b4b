//! Shared fixtures.

use spectrum::{Caps, Spectrum};

/// The base state of the design's tables, Q0 = (a = 1, b = 2, c = 0.5), under caps wide
/// enough that no exact law is disturbed.
pub(crate) fn q0() -> Spectrum {
    abc(1.0, 2.0, 0.5)
}

/// A spectrum under [`Caps::UNBOUNDED`].
pub(crate) fn abc(a: f64, b: f64, c: f64) -> Spectrum {
    Spectrum::new(a, b, c, &Caps::UNBOUNDED).expect("fixture is PSD")
}

/// 2π².
pub(crate) const TWO_PI_SQ: f64 = 2.0 * std::f64::consts::PI * std::f64::consts::PI;

/// Asserts that a spectrum is symmetric PSD, finite and inside its caps.
#[track_caller]
pub(crate) fn assert_valid(q: &Spectrum, caps: &Caps) {
    let (a, b, c) = (q.a(), q.b(), q.c());
    assert!(
        a.is_finite() && b.is_finite() && c.is_finite(),
        "not finite: {q:?}"
    );
    assert!(
        a >= caps.a_min() && a <= caps.a_max(),
        "a outside caps: {q:?}"
    );
    assert!(
        b >= caps.b_min() && b <= caps.b_max(),
        "b outside caps: {q:?}"
    );
    assert!(c * c <= a * b, "not PSD: {q:?}");
    if q.is_lambertian() {
        assert!(
            b == caps.b_max() && c == 0.0,
            "bad Lambertian normal form: {q:?}"
        );
    }
}
