//! Every row of the design's "known input → output" table (§9.1), except the two PPM
//! update rows, which belong to the `ppm` crate.
//!
//! Where the table prints fewer than ten significant digits, the test checks the exact
//! closed form to 10⁻⁹ and the printed digits to their own precision.

use spectrum::{
    Caps, Covariance, K_POSTER, K_STRICT, Lobe, Spectrum, angular_radius, refracted_cosine,
    spatial_radius,
};

use crate::support::{TWO_PI_SQ, abc, q0};

const U: &Caps = &Caps::UNBOUNDED;

#[test]
fn travel() {
    let q = abc(1.0, 2.0, 0.0).travel(3.0, U);
    assert_abc!(q, (19.0, 2.0, 6.0));
    assert_close!(q.determinant(), 2.0);
}

#[test]
fn travel_composition() {
    let twice = q0().travel(1.5, U).travel(1.5, U);
    assert_abc!(twice, (22.0, 2.0, 6.5));
    let once = q0().travel(3.0, U);
    assert_abc!(twice, (once.a(), once.b(), once.c()));
}

#[test]
fn kick() {
    let q = q0().kick(0.5, U);
    assert_abc!(q, (1.0, 2.75, 1.0));
    assert_close!(q.determinant(), 1.75);
}

#[test]
fn two_f_system_swaps_space_and_angle() {
    let f: f64 = 0.5;
    let q = q0().travel(f, U).kick(-1.0 / f, U).travel(f, U);
    assert_abc!(q, (0.5, 4.0, -0.5));
    assert_abc!(q, (f * f * q0().b(), q0().a() / (f * f), -q0().c()));
}

#[test]
fn imaging_has_magnification_minus_one() {
    let (a, big_b) = (0.3, 5.0);
    let q = abc(a, big_b, 0.0)
        .travel(1.0, U)
        .kick(-2.0, U)
        .travel(1.0, U);
    assert_close!(q.a(), a, 1e-12);
    assert_close!(q.b(), 4.0 * a + big_b);
}

#[test]
fn projection_in() {
    assert_abc!(q0().project_in(0.5, U), (4.0, 2.0, 1.0));
}

#[test]
fn flat_mirror_leaves_abc_unchanged() {
    for mu in [1.0, 0.8, 0.3, 0.01] {
        assert_abc!(
            q0().reflect(mu, mu, 0.0, Lobe::Mirror, U),
            (1.0, 2.0, 0.5),
            1e-12
        );
    }
}

#[test]
fn curved_mirror_normal_incidence() {
    assert_abc!(
        q0().reflect(1.0, 1.0, 0.25, Lobe::Mirror, U),
        (1.0, 1.75, 0.0)
    );
}

#[test]
fn glossy_curved_oblique_mirror() {
    let q = q0().reflect(0.8, 0.6, 0.5, Lobe::Gaussian { variance: 0.01 }, U);
    let b = 2.0 - 1.25 + 1.5625 + TWO_PI_SQ * 0.01;
    assert_abc!(q, (0.5625, b, -0.5625));
    assert_close!(q.b(), 2.509_892_09, 5e-9);
    assert_close!(q.determinant(), 0.5625 * b - 0.5625 * 0.5625);
    assert_close!(q.determinant(), 1.095_408_05, 5e-9);
    // The same lobe as a Phong exponent: σρ² = 1/n.
    let phong = q0().reflect(0.8, 0.6, 0.5, Lobe::Phong { exponent: 100.0 }, U);
    assert_abc!(phong, (q.a(), q.b(), q.c()), 1e-15);
}

#[test]
fn refraction_normal_incidence_flat() {
    let q = q0().refract(1.0, 1.5, 1.0, 1.0, 0.0, U);
    assert_abc!(q, (1.0, 8.0 / 9.0, 1.0 / 3.0));
    assert_close!(q.determinant(), 1.75 / 2.25);
}

#[test]
fn refraction_oblique_curved() {
    let mu_t = refracted_cosine(1.0, 1.5, 0.8).unwrap();
    assert_close!(mu_t, 0.84f64.sqrt(), 1e-15);
    let s = 0.8 / (1.5 * mu_t);
    let t = mu_t / 0.8;
    let h = (1.0 - s) * 0.5 / 0.8;
    // The ray matrix of the table.
    assert_close!(t, 1.145_643_924);
    assert_close!(h, 0.261_303_516, 5e-9);
    assert_close!(s, 0.581_914_374, 5e-9);
    let q = q0().refract(1.0, 1.5, 0.8, mu_t, 0.5, U);
    assert_abc!(q, (1.3125, 0.897_584_477, 0.632_694_119));
    assert_close!(q.determinant(), 1.75 / 2.25);
}

#[test]
fn phong_bandlimit() {
    let q = q0().bandlimit(Lobe::Phong { exponent: 100.0 }, U);
    assert_abc!(q, (1.0, 2.197_392_088, 0.5));
    assert_close!(q.b(), 2.0 + TWO_PI_SQ / 100.0, 1e-15);
}

#[test]
fn lambert_bandlimit() {
    let caps = Caps::for_scene_size(3.0);
    let inputs = [q0(), abc(0.01, 0.3, -0.05), abc(5.0, 19.0, 9.0)];
    for q in inputs {
        let q = q.capped(&caps);
        let l = q.bandlimit(Lobe::Lambert, &caps);
        assert_abc!(l, (q.a(), caps.b_max(), 0.0), 0.0);
        assert!(l.is_lambertian());
    }
}

#[test]
fn occlusion() {
    let q = q0().occlude(0.25, U);
    assert_abc!(q, (2.0 / 3.0, 1.916_666_666_666_666_7, 1.0 / 3.0));
    // Equals ½(Σ + diag(o, 0))⁻¹.
    let sigma = q0().covariance().unwrap();
    let windowed = Covariance::new(sigma.p() + 0.25, sigma.q(), sigma.r()).unwrap();
    let back = Spectrum::from_covariance(windowed, U).unwrap();
    assert_abc!(q, (back.a(), back.b(), back.c()), 1e-12);
}

#[test]
fn cosine() {
    let gap = std::f64::consts::FRAC_PI_2 - 0.8;
    let w_c = 1.0 / (gap * gap);
    assert_close!(w_c, 1.683_141_884, 5e-9);
    let den = 1.0 + 2.0 * w_c * 2.0;
    let q = q0().cosine(0.8, U);
    assert_abc!(q, (1.0 - 2.0 * w_c * 0.25 / den, 2.0 / den, 0.5 / den));
    assert_abc!(q, (0.891_165_394, 0.258_646_302, 0.064_661_576), 1e-8);
}

#[test]
fn covariance_form_travel() {
    let sigma = Covariance::new(4.0 / 7.0, -1.0 / 7.0, 2.0 / 7.0).unwrap();
    let from_q = q0().covariance().unwrap();
    assert_close!(from_q.p(), sigma.p(), 1e-15);
    assert_close!(from_q.q(), sigma.q(), 1e-15);
    assert_close!(from_q.r(), sigma.r(), 1e-15);
    let q_form = q0().travel(0.7, U);
    let sigma_form = Spectrum::from_covariance(sigma.travel(0.7), U).unwrap();
    assert_abc!(sigma_form, (q_form.a(), q_form.b(), q_form.c()));
}

#[test]
fn point_light_in_a_flat_mirror() {
    let (a_min, b_max) = (TWO_PI_SQ * 1e-8, TWO_PI_SQ);
    let caps = Caps::new(a_min, 1e6, a_min, b_max).unwrap();
    let light = Spectrum::point_light(&caps);
    assert_abc!(light, (a_min, b_max, 0.0), 0.0);
    assert_close!(a_min, 1.9739e-7, 1e-4);
    assert_close!(b_max, 19.739_208_8, 5e-9);
    let mirrored = light
        .travel(1.0, &caps)
        .reflect(0.6, 0.6, 0.0, Lobe::Mirror, &caps)
        .travel(2.0, &caps);
    let direct = light.travel(3.0, &caps);
    assert_abc!(mirrored, (direct.a(), direct.b(), direct.c()));
    assert_abc!(mirrored, (a_min + 9.0 * b_max, b_max, 3.0 * b_max));
    assert_abc!(mirrored, (177.652_879, 19.739_208_8, 59.217_626_4), 5e-9);
}

#[test]
fn spatial_radius_poster_and_strict() {
    assert_close!(spatial_radius(1.0, K_POSTER), 0.711_508_625, 1e-9);
    assert_close!(spatial_radius(1.0, K_STRICT), 0.072_090_896, 5e-9);
    assert_close!(
        K_POSTER,
        std::f64::consts::PI * (-(0.95f64.ln())).sqrt(),
        1e-15
    );
    assert_close!(
        K_STRICT,
        (-(0.95f64.ln())).sqrt() / std::f64::consts::PI,
        1e-15
    );
    assert_close!(K_POSTER / K_STRICT, std::f64::consts::PI.powi(2), 1e-15);
    assert_close!(abc(1.0, 2.0, 0.0).spatial_radius(K_POSTER), 0.711_508_625);
}

#[test]
fn angular_radius_poster() {
    assert_close!(angular_radius(0.01, 2.0, K_POSTER), 0.142_542_344, 5e-9);
    // Phong 100 seen from z = 1, with b = 2π²/100 and with the table's rounded b.
    assert_close!(
        angular_radius(TWO_PI_SQ / 100.0, 1.0, K_POSTER),
        0.327_083_229,
        5e-9
    );
    assert_close!(
        angular_radius(0.197_392, 1.0, K_POSTER),
        0.327_083_229,
        5e-6
    );
}

#[test]
fn angular_radius_is_infinite_past_the_threshold() {
    let threshold = 1.0 / (4.0 * spectrum::BETA_95);
    assert_close!(threshold, 4.873_931_437, 5e-9);
    assert_eq!(angular_radius(threshold, 2.0, K_POSTER), f64::INFINITY);
    assert_eq!(
        angular_radius(threshold * 1.01, 2.0, K_POSTER),
        f64::INFINITY
    );
    assert!(angular_radius(threshold * 0.99, 2.0, K_POSTER).is_finite());
    // A Lambertian spectrum never limits the kernel, whatever K.
    let caps = Caps::for_scene_size(1.0);
    let lambert = q0().capped(&caps).bandlimit(Lobe::Lambert, &caps);
    assert_eq!(lambert.angular_radius(1.0, K_STRICT), f64::INFINITY);
    assert_eq!(
        lambert.radius(1.0, K_STRICT),
        lambert.spatial_radius(K_STRICT)
    );
}

/// The camera-line radius row: point light at d = 1 from a flat Phong-100 plane, camera
/// at D = 3. The closed form b_ρ·(dD/(d + D))² is the limit b_max → ∞; for a finite b_max
/// the exact value is d²·B·b_ρ/(B·(1 + d/D)² + b_ρ).
#[test]
fn camera_line_bandwidth() {
    let (d, big_d) = (1.0f64, 3.0f64);
    let b_rho = TWO_PI_SQ / 100.0;
    let closed_form = b_rho * (d * big_d / (d + big_d)).powi(2);
    assert_close!(closed_form, 0.111_033_05, 5e-8);

    // A point light whose angular window is B (the caps stay wider, so that the lobe's
    // b_ρ is not capped away).
    let field = |b_max: f64| {
        Spectrum::new(0.0, b_max, 0.0, U)
            .unwrap()
            .travel(d, U)
            .reflect(1.0, 1.0, 0.0, Lobe::Phong { exponent: 100.0 }, U)
    };
    // Finite window: exact to rounding.
    let b_max = TWO_PI_SQ;
    let finite = field(b_max).camera_line_bandwidth(big_d);
    let exact = d * d * b_max * b_rho / (b_max * (1.0 + d / big_d).powi(2) + b_rho);
    assert_close!(finite, exact);
    // Wide window: the closed form. Two effects limit the agreement: the finite-window
    // bias ≈ b_ρ/(B·(1 + d/D)²) and the PSD repair c² ≤ ab·(1 − 10⁻¹²), which adds about
    // 10⁻¹²·B² to det Q = d²·B·b_ρ. Both are ≈ 10⁻⁶ at B = 1.5·10⁵.
    let wide = field(1.5e5).camera_line_bandwidth(big_d);
    assert_close!(wide, closed_form, 3e-6);
    // A Lambertian field restricted to the camera line keeps a (as D → ∞ exactly).
    let caps = Caps::for_scene_size(1.0);
    let lambert = q0().capped(&caps).bandlimit(Lobe::Lambert, &caps);
    assert_close!(lambert.camera_line_bandwidth(1e12), lambert.a(), 1e-9);
    // And the radius on the surface divides by the outgoing cosine.
    let r = field(b_max).camera_line_radius(big_d, 0.5, K_POSTER);
    assert_close!(r, K_POSTER * finite.sqrt() / 0.5);
}

#[test]
fn area_light_example() {
    let caps = Caps::for_scene_size(10.0);
    let surface = Spectrum::area_light(0.5, 1.0, &caps);
    assert_close!(surface.a(), std::f64::consts::PI.powi(2) / 6.0 * 0.25);
    assert_close!(surface.a(), 0.411_234, 2e-6);
    let ray = Spectrum::area_light(0.5, 0.8, &caps);
    assert_close!(ray.a(), 0.263_189, 2e-6);
    assert_close!(ray.a(), surface.project_out(0.8, &caps).a());
    assert!(ray.is_lambertian() && ray.b() == caps.b_max());
}

#[test]
fn emitters() {
    let caps = Caps::for_scene_size(10.0);
    let spot = Spectrum::spot_light(0.3, &caps);
    assert_abc!(spot, (caps.a_min(), TWO_PI_SQ * 0.09 / 3.0, 0.0));
    let smooth = Spectrum::spot_light_falloff(50.0, &caps);
    assert_abc!(smooth, (caps.a_min(), TWO_PI_SQ / 50.0, 0.0));
    let directional = Spectrum::directional_light(&caps);
    assert_abc!(directional, (caps.a_max(), caps.b_min(), 0.0), 0.0);
    // Travel only adds c = d·b_min, far below its bound √(a_max·b_min).
    let travelled = directional.travel(123.0, &caps);
    assert_abc!(
        travelled,
        (caps.a_max(), caps.b_min(), 123.0 * caps.b_min())
    );
    let sun = Spectrum::sun(0.0093, &caps);
    assert_close!(sun.b(), 1.42e-4, 2e-3);
    assert_close!(
        sun.b(),
        std::f64::consts::PI.powi(2) * 0.0093f64.powi(2) / 6.0
    );
    assert_eq!(sun.a(), caps.a_max());
}

/// The lobe widths of design §7 (σρ² in rad², b_ρ = 2π²σρ²).
#[test]
fn lobe_widths() {
    let cases = [
        (Lobe::Mirror, 0.0),
        (Lobe::Phong { exponent: 100.0 }, 0.01),
        (Lobe::BlinnPhong { exponent: 100.0 }, 0.04),
        (Lobe::Beckmann { roughness: 0.3 }, 0.18),
        (Lobe::Ggx { roughness: 0.3 }, 0.09),
        (Lobe::Gaussian { variance: 0.02 }, 0.02),
    ];
    for (lobe, variance) in cases {
        assert_close!(lobe.angular_variance().unwrap(), variance, 1e-15);
        assert_close!(lobe.bandwidth().unwrap(), TWO_PI_SQ * variance, 1e-15);
    }
    assert_close!(
        Lobe::Phong { exponent: 100.0 }.bandwidth().unwrap(),
        0.197_392,
        1e-6
    );
    assert_eq!(Lobe::Lambert.angular_variance(), None);
    assert_eq!(
        Lobe::Gaussian { variance: -1.0 }.angular_variance(),
        Some(0.0)
    );
    assert_eq!(
        Lobe::Gaussian { variance: f64::NAN }.angular_variance(),
        Some(0.0)
    );
}
