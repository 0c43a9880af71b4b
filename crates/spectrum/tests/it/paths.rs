//! Snapshots of the operator chain of complete photon paths: each step's (a, b, c) to 9
//! significant digits, then the kernel radii at the end. Any change of convention (signs,
//! frames, constants) shows up in review as a snapshot diff.

use std::fmt::Write;

use spectrum::{Caps, K_POSTER, K_STRICT, Lobe, Spectrum, refracted_cosine};

type Step<'a> = (&'a str, Box<dyn Fn(Spectrum) -> Spectrum + 'a>);

/// Runs the steps from `start`, one line per state.
fn trace(start: (&str, Spectrum), steps: Vec<Step<'_>>) -> (String, Spectrum) {
    let mut out = String::new();
    let mut line = |name: &str, q: &Spectrum| {
        let flag = if q.is_lambertian() {
            "  lambertian"
        } else {
            ""
        };
        writeln!(
            out,
            "{name:<40} a = {:>16.8e}  b = {:>16.8e}  c = {:>16.8e}{flag}",
            q.a(),
            q.b(),
            q.c()
        )
        .unwrap();
    };
    let mut q = start.1;
    line(start.0, &q);
    for (name, step) in steps {
        q = step(q);
        line(name, &q);
    }
    (out, q)
}

/// The radii of the final state, for a camera at distance z along the normal.
fn radii(out: &mut String, q: &Spectrum, z: f64, mu_cam: f64) {
    for (name, k) in [("K_POSTER", K_POSTER), ("K_STRICT", K_STRICT)] {
        writeln!(
            out,
            "{name}: r_x = {:.8e}  r_theta(z = {z}) = {:.8e}  r_cam(D = {z}, mu_o = {mu_cam}) = {:.8e}",
            q.spatial_radius(k),
            q.angular_radius(z, k),
            q.camera_line_radius(z, mu_cam, k),
        )
        .unwrap();
    }
}

/// Point light → 1 m → concave mirror (R = 2 m, 30° incidence) → 0.5 m → diffuse floor
/// hit at 37° (μ = 0.8), seen from straight above.
#[test]
fn point_light_curved_mirror_diffuse() {
    let caps = Caps::for_scene_size(10.0);
    let mu_mirror = 30f64.to_radians().cos();
    let (mut out, last) = trace(
        ("point light", Spectrum::point_light(&caps)),
        vec![
            ("travel 1 m", Box::new(|q: Spectrum| q.travel(1.0, &caps))),
            (
                "concave mirror R = 2 m at 30 deg",
                Box::new(move |q: Spectrum| {
                    q.reflect(mu_mirror, mu_mirror, 0.5, Lobe::Mirror, &caps)
                }),
            ),
            ("travel 0.5 m", Box::new(|q: Spectrum| q.travel(0.5, &caps))),
            (
                "project onto floor, mu_i = 0.8",
                Box::new(|q: Spectrum| q.project_in(0.8, &caps)),
            ),
            (
                "Lambert band-limit",
                Box::new(|q: Spectrum| q.bandlimit(Lobe::Lambert, &caps)),
            ),
            (
                "project out toward camera, mu_o = 1",
                Box::new(|q: Spectrum| q.project_out(1.0, &caps)),
            ),
        ],
    );
    radii(&mut out, &last, 3.0, 1.0);
    insta::assert_snapshot!(out);
}

/// Area light (10 cm, emitting at μe = 0.9) → 2 m → convex glass sphere (R = 0.5 m, hit
/// from outside at 20°, η 1 → 1.5) → 0.3 m → diffuse floor at normal incidence.
#[test]
fn area_light_glass_refraction_diffuse() {
    let caps = Caps::for_scene_size(10.0);
    let mu_i = 20f64.to_radians().cos();
    let mu_t = refracted_cosine(1.0, 1.5, mu_i).unwrap();
    let (mut out, last) = trace(
        (
            "area light 0.1 m at mu_e = 0.9",
            Spectrum::area_light(0.1, 0.9, &caps),
        ),
        vec![
            ("travel 2 m", Box::new(|q: Spectrum| q.travel(2.0, &caps))),
            (
                "refract 1 -> 1.5, convex R = 0.5 m, 20 deg",
                Box::new(move |q: Spectrum| q.refract(1.0, 1.5, mu_i, mu_t, -2.0, &caps)),
            ),
            ("travel 0.3 m", Box::new(|q: Spectrum| q.travel(0.3, &caps))),
            (
                "project onto floor, mu_i = 1",
                Box::new(|q: Spectrum| q.project_in(1.0, &caps)),
            ),
            (
                "Lambert band-limit",
                Box::new(|q: Spectrum| q.bandlimit(Lobe::Lambert, &caps)),
            ),
        ],
    );
    radii(&mut out, &last, 2.0, 1.0);
    insta::assert_snapshot!(out);
}

/// Spot light (±0.1 rad cone) → 2 m → thin lens f = 0.5 m → 0.4 m → partial occluder →
/// 0.3 m → glossy Phong-200 plane at 45°, reflected toward a camera 3 m away.
#[test]
fn spot_lens_occluder_glossy() {
    let caps = Caps::for_scene_size(10.0);
    let mu = 45f64.to_radians().cos();
    let window = 0.01; // primal width of the occluder gap [m]
    let o = 1.0 / (4.0 * std::f64::consts::PI.powi(2) * window * window);
    let (mut out, last) = trace(
        (
            "spot light, half-angle 0.1 rad",
            Spectrum::spot_light(0.1, &caps),
        ),
        vec![
            ("travel 2 m", Box::new(|q: Spectrum| q.travel(2.0, &caps))),
            (
                "thin lens f = 0.5 m",
                Box::new(|q: Spectrum| q.kick(-2.0, &caps)),
            ),
            ("travel 0.4 m", Box::new(|q: Spectrum| q.travel(0.4, &caps))),
            (
                "occluder gap 1 cm",
                Box::new(move |q: Spectrum| q.occlude(o, &caps)),
            ),
            ("travel 0.3 m", Box::new(|q: Spectrum| q.travel(0.3, &caps))),
            (
                "Phong 200 plane at 45 deg",
                Box::new(move |q: Spectrum| {
                    q.reflect(mu, mu, 0.0, Lobe::Phong { exponent: 200.0 }, &caps)
                }),
            ),
        ],
    );
    radii(&mut out, &last, 3.0, mu);
    insta::assert_snapshot!(out);
}
