//! End-to-end optics (design §9.3): the algebra must reproduce first-order imaging.

use proptest::prelude::*;
use spectrum::{Caps, Lobe, Spectrum};

use crate::support::{TWO_PI_SQ, abc};

/// Caps for the focusing tests: the usual windows (b_max = 2π², i.e. ±1 rad), but a
/// resolution (a_min, b_min = 10⁻¹⁴) far below the focal spots, so the caps cannot flatten
/// the minimum that the search looks for. (Under scene caps the focus of a collimated
/// beam is a plateau at a_min.)
fn paraxial_caps() -> Caps {
    Caps::new(1e-14, 1e4, 1e-14, TWO_PI_SQ).unwrap()
}

/// The minimiser of a unimodal function on [lo, hi] by golden-section search.
fn argmin(f: impl Fn(f64) -> f64, mut lo: f64, mut hi: f64) -> f64 {
    let ratio = (5f64.sqrt() - 1.0) / 2.0;
    for _ in 0..200 {
        let x1 = hi - ratio * (hi - lo);
        let x2 = lo + ratio * (hi - lo);
        if f(x1) < f(x2) {
            hi = x2;
        } else {
            lo = x1;
        }
    }
    0.5 * (lo + hi)
}

/// Where a collimated beam reflected by a mirror of radius R at cosine μ focuses: the
/// travel distance at which a (the irradiance width) is smallest.
fn focus_distance(radius: f64, mu: f64, caps: &Caps) -> f64 {
    // A collimated beam of width w = 0.2·R (paraxial: the reflected angles ±2w/R stay
    // inside the ±1 rad window) with b = 10⁻¹⁰: the exact focus g·a/(b + g²·a) is then
    // 1/g to better than 10⁻⁹.
    let width = 0.2 * radius;
    let beam = Spectrum::new(TWO_PI_SQ * width * width / 12.0, 1e-10, 0.0, caps).unwrap();
    let reflected = beam.reflect(mu, mu, 1.0 / radius, Lobe::Mirror, caps);
    argmin(|d| reflected.travel(d, caps).a(), 0.0, 2.0 * radius)
}

#[test]
fn concave_mirror_focuses_at_half_the_radius() {
    let caps = paraxial_caps();
    for radius in [0.5, 2.0, 7.0] {
        let focus = focus_distance(radius, 1.0, &caps);
        assert_close!(focus, radius / 2.0, 1e-6);
    }
}

#[test]
fn oblique_concave_mirror_focuses_at_the_tangential_focal_length() {
    let caps = paraxial_caps();
    for (radius, theta) in [(2.0f64, 0.3f64), (2.0, 1.0), (5.0, 0.7)] {
        let focus = focus_distance(radius, theta.cos(), &caps);
        assert_close!(focus, radius / 2.0 * theta.cos(), 1e-6);
    }
}

#[test]
fn convex_mirror_does_not_focus() {
    let caps = Caps::for_scene_size(10.0);
    let beam = Spectrum::sun(0.0093, &caps);
    let reflected = beam.reflect(1.0, 1.0, -1.0, Lobe::Mirror, &caps);
    // a only grows (up to its cap) with distance: the beam diverges.
    let mut last = reflected.a();
    for step in 1..50 {
        let a = reflected.travel(0.1 * f64::from(step), &caps).a();
        assert!(a >= last);
        last = a;
    }
}

#[test]
fn flipping_the_angle_alone_breaks_the_virtual_image() {
    // The left-handed convention (c' = −c) makes the light travel backwards after the
    // mirror, which the virtual-image test catches.
    let caps = Caps::for_scene_size(100.0);
    let light = Spectrum::point_light(&caps).travel(1.0, &caps);
    let wrong = light.flip(&caps).travel(2.0, &caps);
    let right = light
        .reflect(0.7, 0.7, 0.0, Lobe::Mirror, &caps)
        .travel(2.0, &caps);
    let direct = Spectrum::point_light(&caps).travel(3.0, &caps);
    assert_abc!(right, (direct.a(), direct.b(), direct.c()));
    assert!((wrong.a() - direct.a()).abs() > 0.1 * direct.a());
}

#[test]
fn lens_focuses_a_point_light_on_its_image() {
    // A 10 µm source emitting a narrow cone (±0.05 rad) at d1 = 3 before a thin lens of
    // f = 1: image at d2 = 1.5, magnified by d2/d1. (The waist, where a is smallest, sits
    // off the image plane by a relative ≈ a_src/(b·d1²), here 10⁻⁹.)
    let caps = paraxial_caps();
    let (d1, f) = (3.0, 1.0);
    let source = Spectrum::new(
        TWO_PI_SQ * 1e-10 / 12.0,
        Spectrum::spot_light(0.05, &caps).b(),
        0.0,
        &caps,
    )
    .unwrap();
    let at_lens = source.travel(d1, &caps).kick(-1.0 / f, &caps);
    let focus = argmin(|d| at_lens.travel(d, &caps).a(), 0.0, 10.0);
    let d2 = 1.0 / (1.0 / f - 1.0 / d1);
    assert_close!(focus, d2, 1e-6);
    // The image a cancels from intermediates ≈ d1²·b = 0.15 down to 4·10⁻¹¹ (a 4·10⁹ loss).
    assert_close!(
        at_lens.travel(d2, &caps).a(),
        (d2 / d1).powi(2) * source.a(),
        2e-6
    );
}

/// A small Lambertian lamp imaged by a concave mirror under the scene caps a renderer uses
/// (±1 rad angular window): the reflected field converges at the mirror equation's image
/// distance v = 1/(1/f − 1/u), and there it is as narrow as the lamp's image, m²·a_lamp with
/// m = v/u. The lamp's rays fill the whole window, so right after the curvature kick the
/// field's angles exceed it; clamping b (and c with it) flattened the slope and moved the
/// focus past 3 m (the ring caustic of `scenes/peers/ring-caustic.toml` was predicted smooth
/// at its cusp).
#[test]
fn concave_mirror_images_a_lambertian_lamp_under_scene_caps() {
    let caps = Caps::for_scene_size(6.0);
    for (size, u, radius) in [(0.08, 2.2, 0.5), (0.02, 1.0, 1.0), (0.1, 4.0, 2.0)] {
        let f = radius / 2.0;
        let lamp = Spectrum::area_light(size, 1.0, &caps);
        let reflected = lamp
            .travel(u, &caps)
            .reflect(1.0, 1.0, 1.0 / radius, Lobe::Mirror, &caps);
        let v = 1.0 / (1.0 / f - 1.0 / u);
        let focus = argmin(|d| reflected.travel(d, &caps).a(), 0.0, 3.0 * v);
        assert_close!(focus, v, 1e-3);
        let m = v / u;
        assert_close!(reflected.travel(v, &caps).a(), m * m * lamp.a(), 1e-2);
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(1000))]

    /// A point light seen in a flat mirror at any incidence: travel d1, mirror, travel d2
    /// equals travel d1 + d2.
    #[test]
    fn virtual_image_in_a_flat_mirror(d1 in 0.0f64..10.0, d2 in 0.0f64..10.0, mu in 0.01f64..=1.0) {
        let caps = Caps::for_scene_size(100.0);
        let light = Spectrum::point_light(&caps);
        let mirrored = light
            .travel(d1, &caps)
            .reflect(mu, mu, 0.0, Lobe::Mirror, &caps)
            .travel(d2, &caps);
        let direct = light.travel(d1 + d2, &caps);
        assert_abc!(mirrored, (direct.a(), direct.b(), direct.c()), 1e-12);
    }

    /// T(d2)·K(−1/f)·T(d1) with 1/d1 + 1/d2 = 1/f has M₁₂ = 0, so a' = (d2/d1)²·a for any
    /// input spectrum.
    #[test]
    fn thin_lens_imaging(
        a in 0.01f64..100.0, b in 0.01f64..100.0, u in -0.95f64..0.95,
        f in 0.1f64..5.0, stretch in 1.1f64..10.0,
    ) {
        let d1 = f * stretch;
        let d2 = 1.0 / (1.0 / f - 1.0 / d1);
        let q = abc(a, b, u * (a * b).sqrt());
        let u_caps = &Caps::UNBOUNDED;
        let image = q.travel(d1, u_caps).kick(-1.0 / f, u_caps).travel(d2, u_caps);
        let scale = (a + d1 * d1 * b) / a; // cancellation in the intermediate a
        assert_close!(image.a(), (d2 / d1).powi(2) * a, 1e-12 * scale.max(1.0) * (d2 / d1).powi(2).max(1.0) * 100.0);
    }

    /// The Lambertian band-limit kills angle: b = b_max, c = 0, and a (the irradiance
    /// spectrum) is kept; in a full reflection a is only projected.
    #[test]
    fn lambertian_kills_angle(
        a in 0.01f64..10.0, b in 0.01f64..10.0, u in -0.95f64..0.95,
        mu_i in 0.05f64..=1.0, mu_o in 0.05f64..=1.0, kappa in -3.0f64..3.0,
    ) {
        let caps = Caps::for_scene_size(10.0);
        let q = Spectrum::new(a, b, u * (a * b).sqrt(), &caps).unwrap();
        let diffuse = q.bandlimit(Lobe::Lambert, &caps);
        assert_abc!(diffuse, (q.a(), caps.b_max(), 0.0), 0.0);
        prop_assert!(diffuse.is_lambertian());
        let bounced = q.reflect(mu_i, mu_o, kappa, Lobe::Lambert, &caps);
        let m = mu_o / mu_i;
        assert_close!(bounced.a(), (m * m * q.a()).clamp(caps.a_min(), caps.a_max()), 1e-12);
        prop_assert_eq!(bounced.b(), caps.b_max());
        prop_assert_eq!(bounced.c(), 0.0);
    }
}

/// A convex glass surface (hit from outside, κ = −1/R) focuses a collimated beam inside
/// the glass at ηt·R/(ηt − ηi): the surface power (ηt − ηi)/R.
#[test]
fn convex_refracting_surface_focuses_inside_the_glass() {
    let caps = paraxial_caps();
    for (radius, eta_t) in [(0.5f64, 1.5f64), (2.0, 1.33), (1.0, 2.4)] {
        let width = 0.2 * radius;
        let beam = Spectrum::new(TWO_PI_SQ * width * width / 12.0, 1e-10, 0.0, &caps).unwrap();
        let inside = beam.refract(1.0, eta_t, 1.0, 1.0, -1.0 / radius, &caps);
        let focus = argmin(|d| inside.travel(d, &caps).a(), 0.0, 20.0 * radius);
        assert_close!(focus, eta_t * radius / (eta_t - 1.0), 1e-6);
    }
}
