//! Scenes whose answer is known in closed form.

use std::f64::consts::PI;

use glam::Vec2;
use ppm::{Method, RenderParams};

use crate::support::{PHOTON_METHODS, mean, params, render, rmse, scene};

/// Inside a closed diffuse sphere of albedo ρ and radius R with a point light of intensity I at
/// its centre, every wall point has radiance L = ρ·I / (π·R²·(1 − ρ)) (direct E = I/R², and the
/// uniform radiosity B = ρ(E + B)). With ρ = 0.5, R = 1 and I = π, L = 1 (pbrt's test).
pub(crate) const FURNACE: &str = r#"
format = 1
[camera]
position = [0.0, 0.0, 0.3]
look_at = [0.0, 0.0, -1.0]
fov_y = 70.0
[film]
width = 16
height = 16
[materials.wall]
type = "diffuse"
albedo = [0.5, 0.5, 0.5]
[[shapes]]
type = "sphere"
center = [0.0, 0.0, 0.0]
radius = 1.0
material = "wall"
[[lights]]
type = "point"
position = [0.0, 0.0, 0.0]
intensity = [3.14159265, 3.14159265, 3.14159265]
"#;

#[test]
fn furnace_sphere_gives_the_analytic_radiance_for_every_method() {
    let scene = scene(FURNACE);
    for method in PHOTON_METHODS {
        // With direct lighting the light straight from the point light comes from a light
        // sample at the visible points (16 per pixel and pass), the rest from photons.
        for direct_lighting in [false, true] {
            let mut p = params(method, 20_000);
            p.budget.max_depth = 64;
            p.connections.direct_lighting = direct_lighting;
            if direct_lighting {
                p.film.samples_per_pixel = 16;
            }
            let image = render(&scene, p, 8);
            let m = mean(&image);
            assert!(
                (m - 1.0).abs() < 0.02,
                "{method} (direct lighting {direct_lighting}): mean radiance {m}, expected 1"
            );
        }
    }
    let mut p = params(Method::Path, 1);
    p.film.samples_per_pixel = 16;
    p.budget.max_depth = 64;
    let m = mean(&render(&scene, p, 4));
    assert!(
        (m - 1.0).abs() < 0.02,
        "path: mean radiance {m}, expected 1"
    );
}

/// A closed cube whose inward-facing walls all emit Le = 0.5 and reflect ρ = 0.5, with a small
/// mirror ball at its centre; `camera` is the TOML camera table.
///
/// In a closed enclosure of uniform emission and albedo the radiance is uniform, and paths with
/// j bounces bring Le·ρ^j, so a bound of k bounces gives L_k = Le·Σ_{j=0..k} ρ^j = 1 − 0.5^(k+1).
/// Seen in the mirror, the walls lose one bounce to it: L_(k−1). (The ball, 0.1 across a cube
/// of side 2, changes the walls' radiance by well under 1 %.)
pub(crate) fn emissive_box(camera: &str) -> String {
    let mut toml = format!(
        "format = 1\n{camera}\n[film]\nwidth = 16\nheight = 16\n\
         [materials.wall]\ntype = \"diffuse\"\nalbedo = [0.5, 0.5, 0.5]\nemission = [0.5, 0.5, 0.5]\n\
         [materials.silver]\ntype = \"mirror\"\n\
         [[shapes]]\ntype = \"sphere\"\ncenter = [0.0, 0.0, 0.0]\nradius = 0.1\nmaterial = \"silver\"\n"
    );
    toml += &cube_walls("wall");
    toml
}

/// The six faces of the cube [−1, 1]³ as quads of `material`, facing inward (TOML shapes).
pub(crate) fn cube_walls(material: &str) -> String {
    // Corner and edges of each face, edge1 × edge2 pointing into the cube.
    let faces: [[[f64; 3]; 3]; 6] = [
        [[-1.0, -1.0, -1.0], [0.0, 0.0, 2.0], [2.0, 0.0, 0.0]],
        [[-1.0, 1.0, -1.0], [2.0, 0.0, 0.0], [0.0, 0.0, 2.0]],
        [[-1.0, -1.0, -1.0], [0.0, 2.0, 0.0], [0.0, 0.0, 2.0]],
        [[1.0, -1.0, -1.0], [0.0, 0.0, 2.0], [0.0, 2.0, 0.0]],
        [[-1.0, -1.0, -1.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]],
        [[-1.0, -1.0, 1.0], [0.0, 2.0, 0.0], [2.0, 0.0, 0.0]],
    ];
    faces
        .iter()
        .map(|[corner, edge1, edge2]| {
            format!(
                "[[shapes]]\ntype = \"quad\"\ncorner = {corner:?}\nedge1 = {edge1:?}\nedge2 = {edge2:?}\nmaterial = \"{material}\"\n"
            )
        })
        .collect()
}

/// `max_depth` bounds the scattering events of the whole light path, the same way for every
/// method: emission seen directly or found by a path (the path tracer), photons and the
/// camera path's specular bounces (the photon mappers) all count.
#[test]
fn max_depth_bounds_the_bounces_of_the_whole_light_path() {
    let wall = scene(&emissive_box(
        "[camera]\nposition = [0.0, 0.0, 0.5]\nlook_at = [1.0, 0.0, 0.5]\nfov_y = 40.0",
    ));
    let mirror = scene(&emissive_box(
        "[camera]\nposition = [0.0, 0.0, 0.5]\nlook_at = [0.0, 0.0, 0.0]\nfov_y = 5.0",
    ));
    let bounded = |k: u32| 1.0 - 0.5f64.powi(k as i32 + 1);
    for k in 1..=3u32 {
        for (view, scene, expected) in [
            ("wall", &wall, bounded(k)),
            ("mirror", &mirror, bounded(k - 1)),
        ] {
            for method in PHOTON_METHODS {
                let mut p = params(method, 20_000);
                p.budget.max_depth = k;
                let m = mean(&render(scene, p, 8));
                assert!(
                    (m / expected - 1.0).abs() < 0.02,
                    "{method}, {view}, max_depth {k}: mean radiance {m}, expected {expected}"
                );
            }
            // Direct lighting: the walls' emission found by light and BSDF samples at the
            // visible points counts as one more scattering event, photons from the second on.
            let mut p = params(Method::FreqSppm, 20_000);
            p.budget.max_depth = k;
            p.connections.direct_lighting = true;
            p.film.samples_per_pixel = 16;
            let m = mean(&render(scene, p, 8));
            assert!(
                (m / expected - 1.0).abs() < 0.02,
                "freq-sppm with direct lighting, {view}, max_depth {k}: mean radiance {m}, \
                 expected {expected}"
            );
            let mut p = params(Method::Path, 1);
            p.film.samples_per_pixel = 16;
            p.budget.max_depth = k;
            let m = mean(&render(scene, p, 4));
            assert!(
                (m / expected - 1.0).abs() < 0.02,
                "path, {view}, max_depth {k}: mean radiance {m}, expected {expected}"
            );
        }
    }
}

/// A point light of intensity I at height h over a large diffuse floor of albedo ρ: the floor
/// radiance at distance d and incidence cosine cos θ is L = ρ/π · I·cos θ/d² (no other surface).
pub(crate) const PLANE: &str = r#"
format = 1
[camera]
position = [0.0, 2.0, 2.0]
look_at = [0.0, 0.0, 0.0]
fov_y = 50.0
[film]
width = 20
height = 20
[materials.floor]
type = "diffuse"
albedo = [0.8, 0.8, 0.8]
[[shapes]]
type = "quad"
corner = [-100.0, 0.0, 100.0]
edge1 = [200.0, 0.0, 0.0]
edge2 = [0.0, 0.0, -200.0]
material = "floor"
[[lights]]
type = "point"
position = [0.0, 1.0, 0.0]
intensity = [10.0, 10.0, 10.0]
"#;

/// The pixel averages of `radiance` (of a camera ray through the lens centre) over 8×8
/// sub-pixel rays per pixel, in film order.
pub(crate) fn pixel_averages(
    scene: &scene::Scene,
    radiance: impl Fn(&scene::Ray) -> f64,
) -> Vec<f64> {
    let (width, height) = scene.camera().resolution();
    let mut out = Vec::new();
    for y in 0..height {
        for x in 0..width {
            let mut sum = 0.0;
            for j in 0..8 {
                for i in 0..8 {
                    let film = Vec2::new(
                        x as f32 + (i as f32 + 0.5) / 8.0,
                        y as f32 + (j as f32 + 0.5) / 8.0,
                    );
                    sum += radiance(&scene.camera().generate_ray(film, Vec2::splat(0.5)));
                }
            }
            out.push(sum / 64.0);
        }
    }
    out
}

/// The exact pixel averages of the plane scene: 8×8 sub-pixel rays per pixel through the
/// camera model, intersected with y = 0 analytically.
pub(crate) fn plane_reference(scene: &scene::Scene) -> Vec<f64> {
    let light = glam::Vec3::new(0.0, 1.0, 0.0);
    pixel_averages(scene, |ray| {
        let t = -ray.origin.y / ray.direction.y;
        if t <= 0.0 {
            return 0.0;
        }
        let to_light = light - ray.at(t);
        let d2 = f64::from(to_light.length_squared());
        0.8 / PI * 10.0 * f64::from(to_light.y) / d2.sqrt() / d2
    })
}

#[test]
fn point_light_over_a_plane_matches_the_inverse_square_law_pixel_by_pixel() {
    let scene = scene(PLANE);
    let reference = plane_reference(&scene);
    let mut cases: Vec<(Method, Vec<[f32; 3]>)> = Vec::new();
    for method in [Method::Ppm, Method::FreqPpm] {
        let mut p = params(method, 400_000);
        p.kernel.initial_radius = Some(0.03);
        cases.push((method, render(&scene, p, 16)));
    }
    let mut p = params(Method::Path, 1);
    p.film.samples_per_pixel = 64;
    cases.push((Method::Path, render(&scene, p, 1)));
    for (method, image) in cases {
        // The low-noise region: pixels whose reference radiance is at least half the peak.
        let peak = reference.iter().copied().fold(0.0, f64::max);
        let (mut sum_rel, mut n, mut worst) = (0.0, 0, 0.0f64);
        for (pixel, &expected) in image.iter().zip(&reference) {
            if expected < 0.5 * peak {
                continue;
            }
            let got = f64::from(pixel[1]);
            let rel = (got - expected).abs() / expected;
            sum_rel += rel;
            worst = worst.max(rel);
            n += 1;
        }
        let mean_rel = sum_rel / f64::from(n);
        let ratio = image
            .iter()
            .zip(&reference)
            .filter(|(_, e)| **e >= 0.5 * peak)
            .map(|(p, e)| f64::from(p[1]) / e)
            .sum::<f64>()
            / f64::from(n);
        // Photon noise per pixel is a few per cent at this budget (measured 5–6 %); the mean
        // ratio averages it out and catches any systematic error of the estimator.
        let (mean_tolerance, worst_tolerance) = match method {
            Method::Path => (0.01, 0.05),
            _ => (0.08, 0.3),
        };
        assert!(n >= 40, "{method}: only {n} pixels in the bright region");
        assert!(
            (ratio - 1.0).abs() < 0.015,
            "{method}: mean ratio to the analytic radiance {ratio}"
        );
        assert!(
            mean_rel < mean_tolerance,
            "{method}: mean relative error {mean_rel} over {n} pixels"
        );
        assert!(
            worst < worst_tolerance,
            "{method}: worst pixel off by {worst}"
        );
    }
}

/// The analytic radiance of the plane scene at film position `film`.
fn plane_radiance_at(scene: &scene::Scene, film: Vec2) -> f64 {
    let ray = scene.camera().generate_ray(film, Vec2::splat(0.5));
    let t = -ray.origin.y / ray.direction.y;
    if t <= 0.0 {
        return 0.0;
    }
    let to_light = glam::Vec3::new(0.0, 1.0, 0.0) - ray.at(t);
    let d2 = f64::from(to_light.length_squared());
    0.8 / PI * 10.0 * f64::from(to_light.y) / d2.sqrt() / d2
}

/// PPM without direct lighting (a light sample per camera pass at jittered points would
/// estimate the pixel's average, not the radiance at the fixed hitpoints).
fn fixed_hitpoints() -> RenderParams {
    let mut p = params(Method::Ppm, 1);
    p.connections.direct_lighting = false;
    p
}

/// Over a plane lit by a point light, light sampling is exact, so the pointwise reference is
/// the analytic radiance at each slot's hitpoint: inside the range the pixel's footprint spans,
/// and (the slots being single points) not the pixel average.
#[test]
fn pointwise_reference_is_the_radiance_at_the_hitpoints() {
    let scene = scene(PLANE);
    let average = plane_reference(&scene);
    let reference = ppm::pointwise_reference(&scene, fixed_hitpoints(), 2, 1).unwrap();
    let (width, _) = scene.camera().resolution();
    let mut off_average = 0;
    for (i, (pixel, &mean)) in reference.iter().zip(&average).enumerate() {
        let (x, y) = ((i as u32 % width) as f32, (i as u32 / width) as f32);
        let samples: Vec<f64> = (0..=16)
            .flat_map(|j| {
                (0..=16).map(move |k| Vec2::new(x + j as f32 / 16.0, y + k as f32 / 16.0))
            })
            .map(|film| plane_radiance_at(&scene, film))
            .collect();
        let lo = samples.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = samples.iter().copied().fold(0.0, f64::max);
        let got = f64::from(pixel[1]);
        assert!(
            got >= lo * 0.999 - 1e-6 && got <= hi * 1.001 + 1e-6,
            "pixel {i}: {got} outside the footprint's range [{lo}, {hi}]"
        );
        if (got - mean).abs() > 1e-3 * mean {
            off_average += 1;
        }
    }
    assert!(
        off_average > reference.len() / 2,
        "only {off_average} slots differ from the pixel average"
    );
    // Disjoint path ranges are independent estimates of the same image; light sampling being
    // exact here, each equals the whole reference, and their mean is it.
    for range in [0..1, 1..2] {
        let half = ppm::pointwise_reference_paths(&scene, fixed_hitpoints(), range, 1).unwrap();
        for (h, r) in half.iter().zip(&reference) {
            assert!(
                (h[1] - r[1]).abs() <= 1e-5 * r[1].abs() + 1e-7,
                "{h:?} vs {r:?}"
            );
        }
    }
    let mut sppm = params(Method::Sppm, 1);
    assert!(ppm::pointwise_reference(&scene, sppm, 1, 1).is_err());
    sppm.method = Method::Ppm;
    sppm.connections.direct_lighting = true;
    assert!(ppm::pointwise_reference(&scene, sppm, 1, 1).is_err());
}

/// PPM's error against the pointwise reference keeps falling with the passes, where against the
/// pixel average it stops at the in-pixel variation.
#[test]
fn ppm_converges_to_the_pointwise_reference() {
    let scene = scene(PLANE);
    let average: Vec<[f32; 3]> = plane_reference(&scene)
        .into_iter()
        .map(|v| [v as f32; 3])
        .collect();
    let mut p = params(Method::Ppm, 100_000);
    p.kernel.initial_radius = Some(0.05);
    // Connections to the camera and direct lighting converge to the pixel average, not to the
    // hitpoints'.
    p.connections.light_tracing = false;
    p.connections.direct_lighting = false;
    let pointwise = ppm::pointwise_reference(&scene, p, 2, 1).unwrap();
    let mut renderer = ppm::Renderer::new(std::sync::Arc::clone(&scene), p).unwrap();
    let mut errors = Vec::new();
    for passes in [4, 16, 64] {
        while renderer.passes() < passes {
            renderer.iterate();
        }
        let image = renderer.image();
        errors.push((rmse(&image, &pointwise), rmse(&image, &average)));
    }
    eprintln!("rmse (pointwise, pixel average) at 4, 16, 64 passes: {errors:?}");
    assert!(
        errors[0].0 > errors[1].0 && errors[1].0 > errors[2].0,
        "{errors:?}"
    );
    // Measured: pointwise 0.108, 0.068, 0.042; pixel average 0.122, 0.089, 0.073 (flattening).
    assert!(
        errors[1].0 / errors[2].0 > errors[1].1 / errors[2].1,
        "{errors:?}"
    );
    assert!(errors[2].0 < 0.7 * errors[2].1, "{errors:?}");
}
