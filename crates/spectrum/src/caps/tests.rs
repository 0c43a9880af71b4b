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
