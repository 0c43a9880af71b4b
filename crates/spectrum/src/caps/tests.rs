use super::*;

#[test]
fn harmonic_matches_the_direct_formula() {
    let (u, v, k, x) = (1.0, 2.0, 0.5, 0.5);
    let (u2, v2, k2) = harmonic(u, v, k, x);
    let den = 1.0 + x;
    assert!((u2 - u / den).abs() < 1e-15);
    assert!((k2 - k / den).abs() < 1e-15);
    assert!((v2 - (v - x * k * k / (u * den))).abs() < 1e-15);
}

#[test]
fn harmonic_infinite_weight_is_the_schur_complement() {
    assert_eq!(harmonic(2.0, 3.0, 1.0, f64::INFINITY), (0.0, 2.5, 0.0));
    assert_eq!(harmonic(0.0, 3.0, 0.0, f64::INFINITY), (0.0, 3.0, 0.0));
    assert_eq!(harmonic(2.0, 3.0, 1.0, 0.0), (2.0, 3.0, 1.0));
}

#[test]
fn det2_is_compensated() {
    // ab − c² with heavy cancellation: the exact answer is −1.
    let (a, b, c) = (1e8 + 1.0, 1e8 - 1.0, 1e8);
    assert_eq!(det2(a, b, c, c), -1.0 + 0.0);
    let (a, b) = (3.0, 1.0 / 3.0);
    assert!(det2(a, b, 1.0, 1.0).abs() < 1e-16);
}

#[test]
fn scene_caps_follow_the_suggested_scales() {
    let caps = Caps::for_scene_size(1.0);
    assert!((caps.b_max() - 19.739_208_802_178_716).abs() < 1e-12);
    assert!((caps.a_min() - 1.973_920_880_217_871_7e-7).abs() < 1e-20);
    assert_eq!(caps.a_max(), caps.b_max());
    assert!(Caps::new(1.0, 0.5, 0.0, 1.0).is_none());
    assert!(Caps::new(0.0, 1.0, 0.0, f64::INFINITY).is_none());
}

#[test]
fn clamp_handles_nan_and_infinities() {
    let caps = Caps::for_scene_size(1.0);
    let (a, b, c) = caps.clamp(f64::NAN, f64::INFINITY, f64::NEG_INFINITY);
    assert_eq!(a, caps.a_min());
    assert_eq!(b, caps.b_max());
    assert!(c < 0.0 && c * c <= a * b);
    assert_eq!(clamp_mu(f64::NAN), MU_MIN);
    assert_eq!(clamp_mu(-0.5), 0.5);
    assert_eq!(clamp_eta(f64::NAN), 1.0);
}

/// The angular window: a field inside it is untouched; a converging field (slope term far
/// above the window, small spread at fixed x) keeps its slope c/a and its spread, and lands
/// on b = b_max; a wide spread keeps the slope and half the window; and the window is the
/// harmonic update (a spatial window) with the weight that gives the new a.
#[test]
fn angular_window_keeps_the_slope() {
    let caps = Caps::new(0.0, 1e6, 0.0, 2.0).unwrap();
    assert_eq!(caps.window_angles(1.0, 1.9, 1.0), (1.0, 1.9, 1.0));
    // Slope term c²/a = 36, spread 0.1.
    let (a, b, c) = (4.0, 36.1, 12.0);
    let (a2, b2, c2) = caps.window_angles(a, b, c);
    assert!((c2 / a2 - c / a).abs() < 1e-12);
    assert!(((b2 - c2 * c2 / a2) - 0.1).abs() < 1e-9);
    assert!((b2 - 2.0).abs() < 1e-9);
    let x = a / a2 - 1.0;
    let (u, v, k) = harmonic(a, b, c, x);
    assert!((u - a2).abs() < 1e-12 && (v - b2).abs() < 1e-9 && (k - c2).abs() < 1e-12);
    // Spread 1.5 (more than half the window): slope term 1, spread clamped to the rest.
    let (a3, b3, c3) = caps.window_angles(4.0, 37.5, 12.0);
    assert!((c3 / a3 - 3.0).abs() < 1e-12);
    assert!((c3 * c3 / a3 - 1.0).abs() < 1e-9);
    let (_, b3, c3) = caps.clamp(a3, b3, c3);
    assert!((b3 - 2.0).abs() < 1e-12 && (c3 - 12.0 / 36.0).abs() < 1e-12);
    // Continuous across the edge of the window.
    let edge = caps.window_angles(4.0, 2.0 + 1e-12, 2.0);
    assert!((edge.0 - 4.0).abs() < 1e-9 && (edge.2 - 2.0).abs() < 1e-9);
}
