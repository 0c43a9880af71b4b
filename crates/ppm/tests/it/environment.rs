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
fn masks(scene: &scene::Scene) -> (Vec<bool>, Vec<bool>) {
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
    p.film.samples_per_pixel = 16;
    let mut runs = vec![(Method::Path, render(&scene, p, 4))];
    for method in PHOTON_METHODS {
        runs.push((method, render(&scene, params(method, 50_000), 8)));
    }
    // With direct lighting by light sampling the sphere's radiance is all next-event
    // estimation (photons leave a convex body after their first bounce): many camera samples,
    // few photons.
    let mut p = params(Method::Sppm, 1_000);
    p.connections.direct_lighting = true;
    p.film.samples_per_pixel = 16;
    runs.push((Method::Sppm, render(&scene, p, 64)));
    // The bidirectional methods: light subpaths from the sky's disc, camera subpaths that
    // escape to it, next-event estimation of it, all weighted against each other.
    for method in [Method::Bdpt, Method::Vcm] {
        let mut p = params(method, 2_000);
        p.film.samples_per_pixel = 4;
        runs.push((method, render(&scene, p, 8)));
    }
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
fn museum_cornell() -> std::sync::Arc<scene::Scene> {
    let shared = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/scenes");
    let options = import::LoadOptions {
        environment: Some(shared.join("mitsuba3/common/textures/museum.exr")),
        ..Default::default()
    };
    let mut description =
        import::load_with(&shared.join("cornell_box/CornellBox-Sphere.obj"), &options).unwrap();
    description.film = scene::Film {
        width: 24,
        height: 24,
    };
    std::sync::Arc::new(scene::Scene::new(description).unwrap())
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

/// A 64 × 32 map: a bright 3 × 2-texel sun at θ ≈ 58°, a colour gradient elsewhere, built in
/// code (texels row-major, top row first).
fn sun_map() -> scene::EnvironmentMap {
    let (w, h) = (64u32, 32u32);
    let texels = (0..h)
        .flat_map(|y| {
            (0..w).map(move |x| {
                if (10..12).contains(&y) && (40..43).contains(&x) {
                    glam::Vec3::new(300.0, 250.0, 200.0)
                } else {
                    glam::Vec3::new(0.2 + x as f32 / 64.0, 0.5, 0.1 + y as f32 / 32.0)
                }
            })
        })
        .collect();
    scene::EnvironmentMap {
        path: "sun.exr".into(),
        width: w,
        height: h,
        texels,
    }
}

/// The irradiance on an upward surface under `map` (unrotated, +y up), per channel, for the
/// radiance Mitsuba 3's `envmap` reads from it (`eval_spectrum`, written out here): texel (x, y)
/// at u = (x + ½)/W, v = y/(H − 1), bilinear between them and periodic in u. Over u the
/// interpolation integrates to the row's mean; over v the row means are interpolated linearly,
/// and E = ∫ L cos θ dω = π² ∫₀^½ R(v) sin 2πv dv (θ = πv) by the midpoint rule.
fn upward_irradiance(map: &scene::EnvironmentMap) -> [f64; 3] {
    let (w, h) = (map.width as usize, map.height as usize);
    let rows: Vec<[f64; 3]> = (0..h)
        .map(|y| {
            let mut m = [0.0f64; 3];
            for t in &map.texels[y * w..(y + 1) * w] {
                for c in 0..3 {
                    m[c] += f64::from(t[c]) / w as f64;
                }
            }
            m
        })
        .collect();
    let n = 200_000;
    let dv = 0.5 / n as f64;
    let mut e = [0.0f64; 3];
    for i in 0..n {
        let v = (i as f64 + 0.5) * dv;
        let t = v * (h - 1) as f64;
        let y0 = (t as usize).min(h - 2);
        let f = t - y0 as f64;
        let s = (2.0 * std::f64::consts::PI * v).sin() * dv;
        for c in 0..3 {
            e[c] += (rows[y0][c] * (1.0 - f) + rows[y0 + 1][c] * f) * s;
        }
    }
    e.map(|e| e * std::f64::consts::PI * std::f64::consts::PI)
}

/// A grey floor seen from straight above under a map with a sun: its radiance is
/// albedo/π × the irradiance of the interpolated map, for the path tracer (light sampling and
/// BSDF sampling of the sky, MIS-weighted), for every photon mapper (photons from the
/// sky's disc) and for their direct lighting (the same two samples at visible points).
#[test]
fn floor_under_a_sun_map_matches_the_irradiance_of_mitsubas_interpolation() {
    let map = sun_map();
    let e = upward_irradiance(&map);
    let albedo = 0.5;
    let want: Vec<f64> = e
        .iter()
        .map(|e| albedo * e / std::f64::consts::PI)
        .collect();
    let toml = r#"
format = 1
[camera]
position = [0.0, 3.0, 0.0]
look_at = [0.0, 0.0, 0.0]
up = [0.0, 0.0, -1.0]
fov_y = 10.0
[film]
width = 8
height = 8
[materials.grey]
type = "diffuse"
albedo = [0.5, 0.5, 0.5]
[[shapes]]
type = "quad"
corner = [-1.0, 0.0, 1.0]
edge1 = [2.0, 0.0, 0.0]
edge2 = [0.0, 0.0, -2.0]
material = "grey"
[[lights]]
type = "environment"
radiance = [1.0, 1.0, 1.0]
"#;
    let mut description = import::load_toml_str(toml, std::path::Path::new("floor.toml")).unwrap();
    description.environment = Some(scene::Environment {
        radiance: scene::EnvironmentRadiance::Map(std::sync::Arc::new(map)),
        scale: 1.0,
        to_world: glam::Mat3::IDENTITY,
    });
    let scene = std::sync::Arc::new(scene::Scene::new(description).unwrap());
    let channel_means = |image: &[[f32; 3]]| {
        let mut m = [0.0f64; 3];
        for p in image {
            for c in 0..3 {
                m[c] += f64::from(p[c]) / image.len() as f64;
            }
        }
        m
    };
    let mut p = params(Method::Path, 1);
    p.film.samples_per_pixel = 64;
    let mut runs = vec![(Method::Path, render(&scene, p, 4))];
    for method in PHOTON_METHODS {
        // The sky's light as photons from its disc.
        let mut p = params(method, 100_000);
        p.connections.direct_lighting = false;
        runs.push((method, render(&scene, p, 8)));
    }
    // And by direct lighting: light and BSDF samples of the sky at the visible points (as
    // many per pixel as the path tracer's paths).
    let mut p = params(Method::FreqSppm, 20_000);
    p.film.samples_per_pixel = 32;
    p.connections.direct_lighting = true;
    runs.push((Method::FreqSppm, render(&scene, p, 8)));
    for (method, image) in runs {
        let got = channel_means(&image);
        for c in 0..3 {
            assert!(
                (got[c] / want[c] - 1.0).abs() < 0.01,
                "{method}: channel {c} {} against {}",
                got[c],
                want[c]
            );
        }
    }
}
