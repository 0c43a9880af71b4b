//! Adversarial scenes: NaN and infinity never reach an accumulator. Whatever a scene makes
//! (emission at the edge of f32, roughness that underflows, surfaces seen edge-on, slivers of
//! triangles), the image stays finite and every dropped value is counted in the pass statistics.

use ppm::{Method, Renderer};

use crate::support::{params, scene};

/// A closed box of diffuse quads around a glossy sphere, with the given ceiling emission, the
/// sphere's roughness and extra shapes.
fn box_scene(emission: f32, roughness: f32, extra: &str) -> String {
    format!(
        r#"
format = 1
[camera]
position = [0.0, 1.0, 3.0]
look_at = [0.0, 1.0, 0.0]
fov_y = 40.0
[film]
width = 24
height = 20
[materials.white]
type = "diffuse"
albedo = [0.8, 0.8, 0.8]
[materials.shiny]
type = "glossy"
reflectance = [0.9, 0.9, 0.9]
roughness = {roughness:e}
[materials.lamp]
type = "diffuse"
albedo = [0.0, 0.0, 0.0]
emission = [{emission:e}, {emission:e}, {emission:e}]
[[shapes]]
type = "quad"
corner = [-1.0, 0.0, 1.0]
edge1 = [2.0, 0.0, 0.0]
edge2 = [0.0, 0.0, -2.0]
material = "white"
[[shapes]]
type = "quad"
corner = [-1.0, 0.0, -1.0]
edge1 = [2.0, 0.0, 0.0]
edge2 = [0.0, 2.0, 0.0]
material = "white"
[[shapes]]
type = "quad"
corner = [-1.0, 1.99, -1.0]
edge1 = [2.0, 0.0, 0.0]
edge2 = [0.0, 0.0, 2.0]
material = "lamp"
[[shapes]]
type = "sphere"
center = [0.0, 0.5, 0.0]
radius = 0.4
material = "shiny"
{extra}
"#
    )
}

const METHODS: [Method; 5] = [
    Method::Ppm,
    Method::Sppm,
    Method::FreqPpm,
    Method::FreqSppm,
    Method::Path,
];

/// Renders a few passes with every method (and with direct lighting at the hitpoints for
/// SPPM); checks that the image is finite and returns the dropped values per method.
fn dropped(toml: &str) -> Vec<(Method, u64)> {
    let scene = scene(toml);
    let mut counts = Vec::new();
    for method in METHODS {
        for direct_lighting in [false, true] {
            if direct_lighting && method != Method::Sppm {
                continue;
            }
            let mut p = params(method, 5_000);
            p.connections.direct_lighting = direct_lighting;
            let mut renderer = Renderer::new(std::sync::Arc::clone(&scene), p).unwrap();
            let mut count = 0;
            for _ in 0..3 {
                count += renderer.iterate().non_finite;
            }
            let image = renderer.image();
            assert!(
                image.iter().flatten().all(|v| v.is_finite()),
                "{method} (direct lighting {direct_lighting}): non-finite pixel"
            );
            counts.push((method, count));
        }
    }
    counts
}

#[test]
fn a_healthy_scene_drops_nothing() {
    for (method, count) in dropped(&box_scene(10.0, 0.3, "")) {
        assert_eq!(count, 0, "{method}");
    }
}

/// Huge emission on a nearly smooth glossy sphere: the BSDF weight of its sharp lobe times the
/// photon's power overflows f32. Those photons are dropped and counted by every method that
/// traces them (the photon mappers and the light tracer).
#[test]
fn overflowing_photon_power_is_dropped_and_counted() {
    for (method, count) in dropped(&box_scene(1.0e37, 1.0e-12, "")) {
        if method.traces_light_paths() {
            assert!(count > 0, "{method}: nothing counted");
        }
    }
}

/// Emission whose power is beyond f32 is refused with the scene, by name, not rendered black.
#[test]
fn emission_beyond_f32_is_refused() {
    let description = import::load_toml_str(
        &box_scene(3.0e38, 0.3, ""),
        std::path::Path::new("hot.toml"),
    )
    .unwrap();
    let Err(error) = scene::Scene::new(description) else {
        panic!("accepted");
    };
    let message = error.to_string();
    assert!(message.contains("hot.toml"), "{message}");
    assert!(
        message.contains("beyond the range of 32-bit floats"),
        "{message}"
    );
}

/// Roughness at the edge of underflow, a mirror-flat quad seen edge-on by the camera, and
/// sliver quads whose area underflows: whatever they produce, the image stays finite (checked
/// in `dropped`).
#[test]
fn degenerate_surfaces_keep_the_image_finite() {
    let extra = r#"
[[shapes]]
type = "quad"
corner = [-1.0, 1.0, 1.0]
edge1 = [2.0, 0.0, 0.0]
edge2 = [0.0, 0.0, -2.0]
material = "shiny"
[[shapes]]
type = "quad"
corner = [0.3, 0.2, 0.3]
edge1 = [0.5, 0.0, 0.0]
edge2 = [0.5, 1.0e-30, 0.0]
material = "white"
"#;
    for roughness in [1.0e-30, 1.0e-12, 1.0] {
        for emission in [10.0, 1.0e37] {
            dropped(&box_scene(emission, roughness, extra));
        }
    }
}
