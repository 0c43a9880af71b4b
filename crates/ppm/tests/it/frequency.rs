//! What the frequency photons predict: smooth light keeps large kernels, shadow edges and
//! caustics get small ones.

use ppm::{Aov, Method, Renderer};

use crate::support::{params, scene};

/// A point light 1 above a floor, with a thin occluder at height 0.5 covering x < 0: the floor
/// is lit for x > 0 and in shadow for x < 0, with a hard edge along x = 0. The camera looks
/// straight down, so pixel columns map to floor x linearly (screen right = +x).
const SHADOW_EDGE: &str = r#"
format = 1
[camera]
position = [0.0, 3.0, 0.0]
look_at = [0.0, 0.0, 0.0]
up = [0.0, 0.0, -1.0]
fov_y = 60.0
[film]
width = 40
height = 40
[materials.floor]
type = "diffuse"
albedo = [0.8, 0.8, 0.8]
[materials.black]
type = "diffuse"
albedo = [0.0, 0.0, 0.0]
[[shapes]]
type = "quad"
corner = [-10.0, 0.0, 10.0]
edge1 = [20.0, 0.0, 0.0]
edge2 = [0.0, 0.0, -20.0]
material = "floor"
[[shapes]]
type = "quad"
corner = [-3.0, 0.5, 3.0]
edge1 = [3.0, 0.0, 0.0]
edge2 = [0.0, 0.0, -6.0]
material = "black"
[[lights]]
type = "point"
position = [0.0, 1.0, 0.0]
intensity = [5.0, 5.0, 5.0]
"#;

#[test]
fn shadow_edges_predict_smaller_kernels_than_smooth_light() {
    let scene = scene(SHADOW_EDGE);
    let mut p = params(Method::FreqPpm, 40_000);
    p.frequency.fraction = 1.0;
    p.kernel.initial_radius = Some(0.02);
    // The frequency analysis of the photons straight from the light, which direct lighting
    // would leave out.
    p.connections.direct_lighting = false;
    let mut renderer = Renderer::new(std::sync::Arc::clone(&scene), p).unwrap();
    for _ in 0..4 {
        renderer.iterate();
    }
    let radius = renderer.aov(Aov::FreqRadius).unwrap();
    let half_width = 3.0 * (30f64.to_radians()).tan();
    let floor_x = |pixel: usize| ((pixel % 40) as f64 + 0.5) / 40.0 * 2.0 * half_width - half_width;
    // Share of hitpoints whose predicted kernel is small (< 0.2, ten initial radii), among
    // the lit floor pixels next to the shadow edge (0 < x < one pixel) and far from it.
    let small_share = |radius: &[f32], near: bool| {
        let selected: Vec<f32> = radius
            .iter()
            .enumerate()
            .filter(|&(pixel, &r)| {
                let x = floor_x(pixel);
                r > 0.0
                    && if near {
                        x > 0.0 && x < 0.09
                    } else {
                        x > 0.4 && x < 1.0
                    }
            })
            .map(|(_, &r)| r)
            .collect();
        let small = selected.iter().filter(|&&r| r < 0.2).count();
        (small as f64 / selected.len() as f64, selected.len())
    };
    let (near, n_near) = small_share(&radius, true);
    let (far, n_far) = small_share(&radius, false);
    eprintln!("small kernels: {near:.3} of {n_near} pixels at the edge, {far:.3} of {n_far} away");
    assert!(n_near >= 20 && n_far >= 100);
    // Hitpoints within 2·R₀ of the edge can see it (about half of the edge column).
    assert!(near > 0.3, "edge: {near}");
    assert!(far < 0.02, "smooth floor: {far}");

    // Without the occlusion probe the edge is invisible to the frequency analysis.
    p.frequency.occlusion = false;
    let mut blind = Renderer::new(std::sync::Arc::clone(&scene), p).unwrap();
    for _ in 0..4 {
        blind.iterate();
    }
    let (blind_near, _) = small_share(&blind.aov(Aov::FreqRadius).unwrap(), true);
    assert!(blind_near < 0.02, "without probes: {blind_near}");
}

#[test]
fn smooth_direct_light_holds_most_kernels() {
    let scene = scene(SHADOW_EDGE);
    let mut p = params(Method::FreqPpm, 40_000);
    p.kernel.initial_radius = Some(0.02);
    // The frequency analysis of the photons straight from the light, which direct lighting
    // would leave out.
    p.connections.direct_lighting = false;
    p.frequency.fraction = 0.5;
    let mut renderer = Renderer::new(std::sync::Arc::clone(&scene), p).unwrap();
    let mut held = 0.0;
    for _ in 0..4 {
        held = renderer.iterate().frequency_held;
    }
    // Everything the camera sees is directly lit and smooth except next to the shadow edge:
    // every hitpoint that has received a frequency photon holds its radius.
    assert!(held > 0.5, "share held by the frequency floor: {held}");
    let classical = Renderer::new(std::sync::Arc::clone(&scene), params(Method::Ppm, 20_000))
        .unwrap()
        .iterate()
        .frequency_held;
    assert_eq!(classical, 0.0);
}
