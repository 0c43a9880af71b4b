//! The environment light in every method: the white furnace (a white diffuse sphere under a
//! uniform sky of radiance 1 has radiance 1 everywhere, since a convex body sees only the sky).

use ppm::Method;

use crate::support::{PHOTON_METHODS, params, render, scene};

/// A white Lambertian sphere of radius 1 filling the middle of a 24 × 24 film, in a constant
/// environment of radiance 1.
const WHITE_FURNACE: &str = r#"
format = 1
[camera]
position = [0.0, 0.0, 4.0]
look_at = [0.0, 0.0, 0.0]
fov_y = 40.0
[film]
width = 24
height = 24
[materials.white]
type = "diffuse"
albedo = [1.0, 1.0, 1.0]
[[shapes]]
type = "sphere"
center = [0.0, 0.0, 0.0]
radius = 1.0
material = "white"
[[lights]]
type = "environment"
radiance = [1.0, 1.0, 1.0]
"#;

/// Pixels whose whole square lies on the sphere (all four corners' rays hit it), and those
/// whose square misses it.
fn masks(scene: &geometry::Scene) -> (Vec<bool>, Vec<bool>) {
    let film = scene.description().film;
    let hits = |x: f32, y: f32| {
        let ray = scene
            .camera()
            .generate_ray(glam::Vec2::new(x, y), glam::Vec2::splat(0.5));
        scene.intersect(&ray).is_some()
    };
    let (mut on, mut off) = (Vec::new(), Vec::new());
    for y in 0..film.height {
        for x in 0..film.width {
            let corners = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)]
                .map(|(dx, dy)| hits(x as f32 + dx, y as f32 + dy));
            on.push(corners.iter().all(|&h| h));
            off.push(corners.iter().all(|&h| !h));
        }
    }
    (on, off)
}

fn mean_where(image: &[[f32; 3]], mask: &[bool]) -> f64 {
    let (sum, n) =
        image
            .iter()
            .zip(mask)
            .filter(|&(_, &m)| m)
            .fold((0.0, 0usize), |(s, n), (p, _)| {
                (
                    s + p.iter().map(|&c| f64::from(c)).sum::<f64>() / 3.0,
                    n + 1,
                )
            });
    sum / n as f64
}

/// Every method within 1 % of 1 on the sphere; the sky seen past it is exactly 1.
#[test]
fn white_furnace_is_one_everywhere_for_every_method() {
    let scene = scene(WHITE_FURNACE);
    let (on, off) = masks(&scene);
    assert!(on.iter().filter(|&&m| m).count() > 100);
    let mut p = params(Method::Path, 1);
    p.samples_per_pixel = 16;
    let mut runs = vec![(Method::Path, render(&scene, p, 4))];
    for method in PHOTON_METHODS {
        runs.push((method, render(&scene, params(method, 50_000), 8)));
    }
    // With direct lighting by light sampling the sphere's radiance is all next-event
    // estimation (photons leave a convex body after their first bounce): many camera samples,
    // few photons.
    let mut p = params(Method::Sppm, 1_000);
    p.direct_lighting = true;
    p.samples_per_pixel = 16;
    runs.push((Method::Sppm, render(&scene, p, 64)));
    for (method, image) in runs {
        let sphere = mean_where(&image, &on);
        assert!(
            (sphere - 1.0).abs() < 0.01,
            "{method}: mean radiance {sphere} on the sphere, expected 1"
        );
        for (pixel, _) in off.iter().enumerate().filter(|&(_, &m)| m) {
            assert_eq!(image[pixel], [1.0; 3], "{method}: sky pixel {pixel}");
        }
    }
}

/// The shared Cornell box with the sphere (open at the front), lit by the shared `museum.exr`
/// besides its own lamp, at 24 × 24.
fn museum_cornell() -> geometry::Scene {
    let shared = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/scenes");
    let options = geometry::LoadOptions {
        environment: Some(shared.join("mitsuba3/common/textures/museum.exr")),
        ..Default::default()
    };
    let mut description =
        geometry::load_with(&shared.join("cornell_box/CornellBox-Sphere.obj"), &options).unwrap();
    description.film = geometry::Film {
        width: 24,
        height: 24,
    };
    geometry::Scene::new(description).unwrap()
}

#[test]
fn environment_lit_images_are_bit_identical_for_1_and_3_threads() {
    let scene = museum_cornell();
    assert!(scene.lights().has_environment());
    for method in Method::ALL {
        let run = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| render(&scene, params(method, 6_000), 2))
        };
        let (one, three) = (run(1), run(3));
        assert!(
            one.iter()
                .zip(&three)
                .all(|(a, b)| a.map(f32::to_bits) == b.map(f32::to_bits)),
            "{method}: image differs between 1 and 3 threads"
        );
        assert!(one.iter().flatten().all(|c| c.is_finite() && *c >= 0.0));
    }
}
