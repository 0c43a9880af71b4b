//! Light tracing combined with photon merging (`light_tracing`): the combination converges to
//! the analytic pixel averages whatever the kernel size (which only moves the MIS weights),
//! keeps the furnace's radiance, and renders a thin lens's defocus as the path tracer does.

use ppm::{Method, RenderParams};

use crate::analytic::{FURNACE, PLANE, plane_reference};
use crate::support::{mean, params, render, scene};

/// Mean ratio to the reference and mean relative error over the pixels whose reference is at
/// least half its peak.
pub(crate) fn bright_region_errors(image: &[[f32; 3]], reference: &[f64]) -> (f64, f64, usize) {
    let peak = reference.iter().copied().fold(0.0, f64::max);
    let (mut ratio, mut rel, mut n) = (0.0, 0.0, 0);
    for (pixel, &expected) in image.iter().zip(reference) {
        if expected < 0.5 * peak {
            continue;
        }
        let got = f64::from(pixel[1]);
        ratio += got / expected;
        rel += (got - expected).abs() / expected;
        n += 1;
    }
    (ratio / n as f64, rel / n as f64, n)
}

#[test]
fn merging_and_connections_sum_to_the_analytic_pixel_averages_at_any_radius() {
    let scene = scene(PLANE);
    let reference = plane_reference(&scene);
    // A pixel's footprint is about 0.13 across at the plane's centre. Kernels far below it
    // (the connections take nearly all the weight), of about one pixel (the two share it) and
    // of a few (merging takes most of it).
    for radius in [0.005, 0.05, 0.15] {
        for method in [Method::Sppm, Method::FreqSppm] {
            let mut p = params(method, 100_000);
            p.kernel.initial_radius = Some(radius);
            p.connections.light_tracing = true;
            // Photons straight from the light are what these tests connect and merge.
            p.connections.direct_lighting = false;
            let image = render(&scene, p, 8);
            let (ratio, rel, n) = bright_region_errors(&image, &reference);
            println!("{method} radius {radius}: ratio {ratio:.4}, mean relative error {rel:.4}");
            assert!(n >= 40, "only {n} pixels in the bright region");
            assert!(
                (ratio - 1.0).abs() < 0.015,
                "{method}, radius {radius}: mean ratio to the analytic radiance {ratio}"
            );
            // Measured 0.018–0.025 (photon noise of 800 000 photons).
            assert!(
                rel < 0.05,
                "{method}, radius {radius}: mean relative error {rel} over {n} pixels"
            );
        }
    }
}

#[test]
fn connection_only_paths_and_any_connection_rule_keep_the_analytic_pixel_averages() {
    // `extra_light_paths` adds light paths that are only connected, and `connect_below` moves
    // where connections are made: both only move the MIS weights, so every combination must
    // still sum to the analytic averages, at a kernel of about a pixel (both strategies share
    // the weight) and of a few (merging takes most of it where it connects).
    let scene = scene(PLANE);
    let reference = plane_reference(&scene);
    for (extra, connect_below) in [(1.0, 2.0), (3.0, f64::INFINITY), (0.5, 0.0)] {
        for radius in [0.05, 0.15] {
            let mut p = params(Method::FreqSppm, 100_000);
            p.kernel.initial_radius = Some(radius);
            p.connections.light_tracing = true;
            // Photons straight from the light are what these tests connect and merge.
            p.connections.direct_lighting = false;
            p.connections.extra_light_paths = extra;
            p.connections.connect_below = connect_below;
            let image = render(&scene, p, 8);
            let (ratio, rel, n) = bright_region_errors(&image, &reference);
            println!(
                "extra {extra}, connect below {connect_below}, radius {radius}: ratio {ratio:.4}, \
                 mean relative error {rel:.4}"
            );
            assert!(n >= 40, "only {n} pixels in the bright region");
            assert!(
                (ratio - 1.0).abs() < 0.015,
                "extra {extra}, connect below {connect_below}, radius {radius}: mean ratio {ratio}"
            );
            // Measured 0.012–0.025; 0.051 for merging alone (`connect_below` 0) with kernels
            // below a pixel.
            let bound = if connect_below == 0.0 { 0.08 } else { 0.04 };
            assert!(
                rel < bound,
                "extra {extra}, connect below {connect_below}, radius {radius}: mean relative \
                 error {rel} over {n} pixels"
            );
        }
    }
}

#[test]
fn connection_only_paths_lower_the_noise_where_kernels_are_below_a_pixel() {
    // With kernels a tenth of a pixel the connections carry the image: three connection-only
    // paths per photon give them four times the samples, so the error of the same passes
    // falls by about half (1/√4).
    let scene = scene(PLANE);
    let reference = plane_reference(&scene);
    let mut errors = Vec::new();
    for extra in [0.0, 3.0] {
        let mut p = params(Method::Sppm, 100_000);
        p.kernel.initial_radius = Some(0.002);
        p.connections.light_tracing = true;
        // Photons straight from the light are what these tests connect and merge.
        p.connections.direct_lighting = false;
        p.connections.extra_light_paths = extra;
        let image = render(&scene, p, 8);
        errors.push(bright_region_errors(&image, &reference).1);
        println!(
            "extra {extra}: {:?}",
            bright_region_errors(&image, &reference)
        );
    }
    assert!(
        errors[1] < 0.65 * errors[0],
        "mean relative error with three connection-only paths per photon {} against {} without",
        errors[1],
        errors[0]
    );
}

#[test]
fn connections_lower_the_noise_where_kernels_are_below_a_pixel() {
    // With kernels a tenth of a pixel, merging alone sees few photons per pixel; the
    // connections see every photon in the pixel's footprint.
    let scene = scene(PLANE);
    let reference = plane_reference(&scene);
    let mut errors = Vec::new();
    for light_tracing in [false, true] {
        let mut p = params(Method::Sppm, 100_000);
        p.kernel.initial_radius = Some(0.002);
        p.connections.light_tracing = light_tracing;
        p.connections.direct_lighting = false;
        let image = render(&scene, p, 8);
        errors.push(bright_region_errors(&image, &reference).1);
        println!(
            "light tracing {light_tracing}: {:?}",
            bright_region_errors(&image, &reference)
        );
    }
    // Measured 0.025 against 1.1.
    assert!(
        errors[1] < 0.1 * errors[0],
        "mean relative error with connections {} against {} without",
        errors[1],
        errors[0]
    );
}

#[test]
fn furnace_keeps_its_radiance_with_light_tracing() {
    let scene = scene(FURNACE);
    for method in crate::support::PHOTON_METHODS {
        let mut p = params(method, 20_000);
        p.budget.max_depth = 64;
        p.connections.light_tracing = true;
        // Photons straight from the light are what these tests connect and merge.
        p.connections.direct_lighting = false;
        let m = mean(&render(&scene, p, 8));
        println!("furnace {method}: {m:.4}");
        assert!(
            (m - 1.0).abs() < 0.02,
            "{method}: mean radiance {m}, expected 1"
        );
    }
}

/// A floor half white, half black, seen out of focus through a thin lens.
const DEFOCUSED_EDGE: &str = r#"
format = 1
[camera]
position = [0.0, 2.0, 2.0]
look_at = [0.0, 0.0, 0.0]
fov_y = 40.0
aperture_radius = 0.15
focus_distance = 1.5
[film]
width = 24
height = 24
[materials.white]
type = "diffuse"
albedo = [0.8, 0.8, 0.8]
[materials.black]
type = "diffuse"
albedo = [0.05, 0.05, 0.05]
[[shapes]]
type = "quad"
corner = [-10.0, 0.0, 10.0]
edge1 = [10.0, 0.0, 0.0]
edge2 = [0.0, 0.0, -20.0]
material = "white"
[[shapes]]
type = "quad"
corner = [0.0, 0.0, 10.0]
edge1 = [10.0, 0.0, 0.0]
edge2 = [0.0, 0.0, -20.0]
material = "black"
[[lights]]
type = "point"
position = [0.0, 1.0, 0.0]
intensity = [10.0, 10.0, 10.0]
"#;

#[test]
fn thin_lens_connections_render_the_path_tracer_s_defocus() {
    let scene = scene(DEFOCUSED_EDGE);
    let mut p: RenderParams = params(Method::Path, 1);
    p.film.samples_per_pixel = 256;
    let reference = render(&scene, p, 1);
    let mut p = params(Method::Sppm, 200_000);
    // Kernels far below a pixel: the image is the connections'.
    p.kernel.initial_radius = Some(0.001);
    p.connections.light_tracing = true;
    // Photons straight from the light are what these tests connect and merge.
    p.connections.direct_lighting = false;
    let image = render(&scene, p, 8);
    // The columns across the blurred edge, in the middle rows: the profile must match the
    // path tracer's, whose own noise at 256 paths per pixel is about 1 %.
    let (mut worst, mut sum, mut n) = (0.0f64, 0.0, 0);
    for y in 8..16 {
        for x in 4..20 {
            let i = y * 24 + x;
            let expected = f64::from(reference[i][1]);
            let got = f64::from(image[i][1]);
            let diff = (got - expected).abs() / (expected + 0.05);
            worst = worst.max(diff);
            sum += diff;
            n += 1;
        }
    }
    let mean_diff = sum / f64::from(n);
    println!("thin lens: mean {mean_diff:.4}, worst {worst:.4}");
    // Measured 0.029 and 0.16.
    assert!(mean_diff < 0.05, "mean relative difference {mean_diff}");
    assert!(worst < 0.25, "worst pixel off by {worst}");
    // The edge is blurred: a pinhole's connections (no lens offset) would leave a sharp one.
    let profile: Vec<f64> = (4..20).map(|x| f64::from(image[12 * 24 + x][1])).collect();
    let steps = profile
        .windows(2)
        .filter(|w| (w[0] - w[1]).abs() > 0.05 * profile[0].max(profile[15]))
        .count();
    assert!(steps >= 3, "edge spans {steps} pixel steps: {profile:?}");
}
