//! Round trips of the uplift, integrated by a quadrature of their own (midpoint rule at 0.1 nm)
//! rather than the fit's trapezoid at 1 nm.

use glam::DVec3;

use super::super::color::{CIE_Y_INTEGRAL, cie_xyz, xyz_to_srgb};
use super::super::spectra::{NamedIlluminant, RgbAlbedo, RgbIlluminant, RgbUnbounded};
use super::*;

/// ∫ f(λ) (x̄, ȳ, z̄)(λ) dλ over 360–830 nm, midpoint rule at 0.1 nm.
fn xyz_integral(f: impl Fn(f64) -> f64) -> DVec3 {
    let n = 4700;
    let h = 470.0 / f64::from(n);
    (0..n)
        .map(|i| {
            let l = 360.0 + (f64::from(i) + 0.5) * h;
            cie_xyz(l) * f(l)
        })
        .sum::<DVec3>()
        * h
}

/// The colour of a reflectance (or any spectrum seen as one) under D65.
fn colour_under_d65(r: impl Fn(f64) -> f64) -> DVec3 {
    let d65 = |l: f64| NamedIlluminant::D65.spectrum().eval(l);
    let white_y = xyz_integral(d65).y;
    xyz_to_srgb(xyz_integral(|l| d65(l) * r(l)) / white_y)
}

/// In-gamut colours, saturated ones included (each channel of each is checked to 1 %).
const COLOURS: [[f64; 3]; 12] = [
    [0.8, 0.1, 0.1],
    [0.1, 0.8, 0.1],
    [0.1, 0.1, 0.8],
    [0.9, 0.6, 0.05],
    [0.05, 0.5, 0.6],
    [0.6, 0.05, 0.6],
    [0.02, 0.02, 0.3],
    [0.95, 0.95, 0.2],
    [0.3, 0.2, 0.1],
    [0.5, 0.5, 0.52],
    [0.7, 0.3, 0.05],
    [0.2, 0.4, 0.9],
];

fn assert_close(got: DVec3, want: [f64; 3], what: &str) {
    for c in 0..3 {
        assert!(
            (got[c] - want[c]).abs() <= 0.01 * want[c],
            "{what} {want:?}: channel {c} is {} ({got})",
            got[c]
        );
    }
}

#[test]
fn reflectances_round_trip_under_d65() {
    for rgb in COLOURS {
        let albedo = RgbAlbedo::new(rgb).unwrap();
        assert_close(colour_under_d65(|l| albedo.eval(l)), rgb, "reflectance");
        // Bounded: a sigmoid stays in [0, 1].
        for l in (360..=830).step_by(10) {
            let v = albedo.eval(f64::from(l));
            assert!((0.0..=1.0).contains(&v));
        }
    }
}

#[test]
fn unbounded_colours_round_trip_under_d65() {
    for rgb in COLOURS {
        let big = rgb.map(|c| 7.5 * c);
        let s = RgbUnbounded::new(big).unwrap();
        assert_close(colour_under_d65(|l| s.eval(l)), big, "unbounded");
    }
}

/// An uplifted emission (× D65 of luminance 1) has the colour it was uplifted from, with no
/// illuminant: white (1, 1, 1) emits D65 itself.
#[test]
fn emissions_round_trip() {
    for rgb in COLOURS
        .into_iter()
        .chain([[1.0, 1.0, 1.0], [20.0, 10.0, 2.5]])
    {
        let e = RgbIlluminant::new(rgb).unwrap();
        let got = xyz_to_srgb(xyz_integral(|l| e.eval(l)) / CIE_Y_INTEGRAL);
        assert_close(got, rgb, "emission");
    }
}

#[test]
fn greys_are_flat() {
    for v in [0.0, 0.05, 0.5, 0.8, 1.0] {
        let albedo = RgbAlbedo::new([v; 3]).unwrap();
        assert_eq!(albedo.polynomial.c[..2], [0.0, 0.0]);
        for l in 360..=830 {
            assert!((albedo.eval(f64::from(l)) - v).abs() < 1e-12, "{v} at {l}");
        }
    }
    let s = RgbUnbounded::new([3.0; 3]).unwrap();
    for l in (360..=830).step_by(7) {
        assert!((s.eval(f64::from(l)) - 3.0).abs() < 1e-12);
    }
    // Black is zero.
    assert_eq!(RgbUnbounded::new([0.0; 3]).unwrap().eval(500.0), 0.0);
}

#[test]
fn bad_colours_are_refused() {
    assert!(RgbAlbedo::new([1.2, 0.5, 0.5]).is_err());
    assert!(RgbAlbedo::new([-0.1, 0.5, 0.5]).is_err());
    assert!(RgbUnbounded::new([f64::NAN, 0.5, 0.5]).is_err());
    assert!(RgbIlluminant::new([f64::INFINITY, 0.5, 0.5]).is_err());
    assert!(SigmoidPolynomial::fit([2.0, 0.0, 0.0]).is_err());
}

/// Primaries no smooth reflectance reaches still get a bounded spectrum of their hue.
#[test]
fn out_of_reach_colours_get_the_closest_fit() {
    let red = RgbAlbedo::new([1.0, 0.0, 0.0]).unwrap();
    let got = colour_under_d65(|l| red.eval(l));
    assert!(
        got.x > 0.8 && got.y.abs() < 0.1 && got.z.abs() < 0.1,
        "{got}"
    );
}

#[test]
fn the_cache_fits_each_colour_once() {
    let cache = UpliftCache::new();
    assert!(cache.is_empty());
    let a = cache.fit([0.8, 0.1, 0.1]).unwrap();
    let b = cache.fit([0.8, 0.1, 0.1]).unwrap();
    assert_eq!(a, b);
    assert_eq!(a, SigmoidPolynomial::fit([0.8, 0.1, 0.1]).unwrap());
    cache.fit([0.1, 0.8, 0.1]).unwrap();
    assert_eq!(cache.len(), 2);
    assert!(cache.fit([1.5, 0.0, 0.0]).is_err());
    assert_eq!(cache.len(), 2);
}
