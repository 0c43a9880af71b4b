//! The light tracer (`light`): unbiased against the analytic pixel averages and the path
//! tracer wherever the camera sees a non-specular surface or an emitter first, and black where
//! it sees only mirrors and glass (as Mitsuba's `ptracer` is).

use ppm::Method;

use crate::analytic::{PLANE, plane_reference};
use crate::light_tracing::bright_region_errors;
use crate::support::{cornell, mean, params, render, rmse, scene};

#[test]
fn light_tracing_matches_the_analytic_pixel_averages_under_a_point_light() {
    let scene = scene(PLANE);
    let reference = plane_reference(&scene);
    let image = render(&scene, params(Method::Light, 100_000), 8);
    let (ratio, rel, n) = bright_region_errors(&image, &reference);
    assert!(n >= 40, "only {n} pixels in the bright region");
    assert!(
        (ratio - 1.0).abs() < 0.01,
        "mean ratio to the analytic radiance {ratio}"
    );
    // The combination's photon noise at the same 800 000 paths is 0.018–0.025
    // (light_tracing.rs); a pure light tracer connects every path there.
    assert!(rel < 0.04, "mean relative error {rel} over {n} pixels");
}

#[test]
fn light_tracing_converges_to_the_path_tracer_on_a_diffuse_box_with_a_visible_lamp() {
    let scene = cornell("CornellBox-Original.obj", 24, 24);
    let mut reference_params = params(Method::Path, 1);
    reference_params.film.samples_per_pixel = 128;
    reference_params.budget.max_depth = 16;
    let reference = render(&scene, reference_params, 4);
    // The lamp's pixels apart: their edges see the lamp in one camera sample per pass, a
    // binomial noise of several per cent at these budgets that says nothing about the paths.
    let lamp: Vec<bool> = reference.iter().map(|p| p[1] > 1.0).collect();
    let masked_mean = |image: &[[f32; 3]], on_lamp: bool| {
        let pixels: Vec<[f32; 3]> = image
            .iter()
            .zip(&lamp)
            .filter(|&(_, &l)| l == on_lamp)
            .map(|(p, _)| *p)
            .collect();
        mean(&pixels)
    };
    let mut p = params(Method::Light, 20_000);
    p.budget.max_depth = 16;
    let errors: Vec<(f64, f64, f64)> = [4, 16, 64]
        .into_iter()
        .map(|passes| {
            let image = render(&scene, p, passes);
            let lit = masked_mean(&image, false) / masked_mean(&reference, false);
            let lamp = masked_mean(&image, true) / masked_mean(&reference, true);
            (rmse(&image, &reference), lit, lamp)
        })
        .collect();
    let (last_rmse, lit, lamp_ratio) = errors[2];
    assert!(
        lamp.iter().filter(|&&l| l).count() >= 2,
        "the lamp is not in view"
    );
    assert!(
        (lit - 1.0).abs() < 0.01,
        "mean ratio to the path tracer {lit} ({errors:?})"
    );
    assert!(
        (lamp_ratio - 1.0).abs() < 0.1,
        "lamp pixels' mean ratio {lamp_ratio} ({errors:?})"
    );
    // 16x the paths: the error (light-tracing noise plus the reference's own) must fall by
    // well over half of the 4x that pure noise would give.
    assert!(
        last_rmse < 0.5 * errors[0].0,
        "error does not fall with paths: {errors:?}"
    );
}

#[test]
fn light_tracing_leaves_black_what_the_camera_sees_only_through_specular_surfaces() {
    let scene = cornell("CornellBox-Sphere.obj", 32, 32);
    let image = render(&scene, params(Method::Light, 20_000), 2);
    let film = scene.description().film;
    let (mut specular, mut lit) = (0, 0);
    for y in 0..film.height {
        for x in 0..film.width {
            // Pixels whose whole footprint sees one kind of surface: the four corners agree.
            let kinds: Vec<bool> = [(0.01, 0.01), (0.99, 0.01), (0.01, 0.99), (0.99, 0.99)]
                .into_iter()
                .map(|(dx, dy)| {
                    let film = glam::Vec2::new(x as f32 + dx, y as f32 + dy);
                    let ray = scene.camera().generate_ray(film, glam::Vec2::splat(0.5));
                    scene
                        .intersect(&ray)
                        .and_then(|hit| scene.material(hit.material))
                        .is_some_and(|m| m.kind.is_specular())
                })
                .collect();
            let value = image[(y * film.width + x) as usize];
            if kinds.iter().all(|&k| k) {
                specular += 1;
                assert_eq!(
                    value, [0.0; 3],
                    "pixel ({x}, {y}) sees only a specular sphere"
                );
            } else if kinds.iter().all(|&k| !k) && value.iter().any(|&v| v > 0.0) {
                lit += 1;
            }
        }
    }
    assert!(specular >= 20, "only {specular} pixels see a sphere alone");
    assert!(lit >= 500, "only {lit} diffuse-seen pixels received light");
}
