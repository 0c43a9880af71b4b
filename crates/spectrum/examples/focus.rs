//! How a renderer uses the algebra: follow a frequency photon through a thin lens and off
//! a concave mirror, find where the light focuses (where the irradiance bandwidth a is
//! smallest) and print the kernel radii a hitpoint there would use.
//!
//! `cargo run -p spectrum --example focus`
#![allow(clippy::print_stdout)]

use spectrum::{Caps, K_POSTER, K_STRICT, Lobe, PrimalCovariance, Spectrum};

fn main() {
    // The scene is about 1 m across: a_max = 2π²·(1 m)², a_min = 2π²·(0.1 mm)², ±1 rad
    // angular window.
    let caps = Caps::for_scene_size(1.0);

    lens(&caps);
    mirror(&caps);
}

/// A spot light 0.6 m before a thin lens of focal length 0.2 m.
fn lens(caps: &Caps) {
    let (d1, f) = (0.6, 0.2);
    println!("Spot light (half-angle 0.05 rad), {d1} m before a thin lens f = {f} m");
    let at_lens = Spectrum::spot_light(0.05, caps)
        .travel(d1, caps)
        .kick(-1.0 / f, caps);
    let (focus, a) = focus(|d| at_lens.travel(d, caps), 1.0);
    println!("  a is smallest at {focus:.4} m behind the lens (a = {a:.3e} m², the cap a_min)");
    println!("  thin-lens equation: {:.4} m", 1.0 / (1.0 / f - 1.0 / d1));
    print_profile(|d| at_lens.travel(d, caps), focus);
}

/// A 5 cm collimated beam (sun-like divergence) on a concave mirror of radius 0.5 m at
/// 30° incidence, then a hitpoint on a diffuse or glossy floor at the focus.
fn mirror(caps: &Caps) {
    let (radius, incidence) = (0.5f64, 30f64.to_radians());
    let (width, divergence) = (0.05f64, 0.0093f64);
    println!();
    println!("Collimated beam ({width} m wide) on a concave mirror R = {radius} m at 30°");
    // Boxes of width w as Gaussians of variance w²/12.
    let beam = Spectrum::from_primal_covariance(
        PrimalCovariance {
            xx: width * width / 12.0,
            xt: 0.0,
            tt: divergence * divergence / 12.0,
        },
        caps,
    )
    .expect("a diagonal covariance is PSD");
    let mu = incidence.cos();
    let reflected = beam.reflect(mu, mu, 1.0 / radius, Lobe::Mirror, caps);
    let (focus, a) = focus(|d| reflected.travel(d, caps), radius);
    println!("  a is smallest at {focus:.4} m from the mirror (a = {a:.3e} m²)");
    println!(
        "  tangential focal length (R/2)·cos θ: {:.4} m (the beam's divergence moves the waist)",
        radius / 2.0 * mu
    );
    print_profile(|d| reflected.travel(d, caps), focus);

    // A floor at the focus, hit at normal incidence, camera 2 m above it.
    let at_floor = reflected.travel(focus, caps).project_in(1.0, caps);
    let camera_distance = 2.0;
    for (name, lobe) in [
        ("diffuse", Lobe::Lambert),
        ("Phong 500", Lobe::Phong { exponent: 500.0 }),
    ] {
        // The field reflected toward the camera decides the angular radius.
        let toward_camera = at_floor.reflect(1.0, 1.0, 0.0, lobe, caps);
        println!("  {name} floor at the focus, camera {camera_distance} m above:");
        for (k_name, k) in [("K_POSTER", K_POSTER), ("K_STRICT", K_STRICT)] {
            println!(
                "    {k_name}: r_x = {:.3e} m, r_θ = {:.3e} m, r_cam = {:.3e} m → r_freq = {:.3e} m",
                toward_camera.spatial_radius(k),
                toward_camera.angular_radius(camera_distance, k),
                toward_camera.camera_line_radius(camera_distance, 1.0, k),
                toward_camera.radius(camera_distance, k),
            );
        }
    }
}

/// The distance in [0, max] where a is smallest (the middle of the plateau when the
/// focus is capped at a_min), by a fine scan.
fn focus(field_at: impl Fn(f64) -> Spectrum, max: f64) -> (f64, f64) {
    let n = 200_000;
    let samples = (0..=n).map(|i| max * f64::from(i) / f64::from(n));
    let a_min = samples
        .clone()
        .map(|d| field_at(d).a())
        .fold(f64::INFINITY, f64::min);
    let at_min: Vec<f64> = samples.filter(|&d| field_at(d).a() <= a_min).collect();
    let middle = 0.5 * (at_min[0] + at_min[at_min.len() - 1]);
    (middle, a_min)
}

/// a and the poster's spatial radius around the focus.
fn print_profile(field_at: impl Fn(f64) -> Spectrum, focus: f64) {
    println!("    distance [m]   a [m²]       r_x (K_POSTER) [m]");
    for factor in [0.5, 0.9, 0.99, 1.0, 1.01, 1.1, 1.5] {
        let d = focus * factor;
        let q = field_at(d);
        println!(
            "    {d:>10.4}   {:>10.3e}   {:>10.3e}",
            q.a(),
            q.spatial_radius(K_POSTER)
        );
    }
}
