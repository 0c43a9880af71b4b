use std::f32::consts::PI;

use glam::{Vec2, Vec3};

use super::EmitterShape;
use crate::test_util::{Rng, description, point_light, quad};
use crate::{Light, Ray, Rgb, Scene, Sphere};

/// Irradiance at `x` (normal `n`) from a uniform Lambertian polygon of radiance `l`
/// (Lambert's formula: E = L/2 · |Σᵢ Θᵢ n·Γᵢ|).
fn polygon_irradiance(x: Vec3, n: Vec3, vertices: &[Vec3], l: f32) -> f32 {
    let mut sum = 0.0;
    for i in 0..vertices.len() {
        let a = (vertices[i] - x).normalize();
        let b = (vertices[(i + 1) % vertices.len()] - x).normalize();
        let theta = a.dot(b).clamp(-1.0, 1.0).acos();
        sum += theta * n.dot(a.cross(b).normalize());
    }
    0.5 * l * sum.abs()
}

/// A 1 × 0.6 quad emitter (radiance 1, facing −y) at height 1 above the origin.
fn quad_light_scene() -> (Scene, [Vec3; 4]) {
    let corner = Vec3::new(-0.3, 1.0, -0.2);
    let (e1, e2) = (Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 0.0, 0.6));
    let scene = Scene::new(description(
        quad(corner, e1, e2, 1).to_vec(),
        vec![],
        vec![],
    ))
    .unwrap();
    (scene, [corner, corner + e1, corner + e1 + e2, corner + e2])
}

#[test]
fn quad_irradiance_matches_lambert_formula() {
    let (scene, vertices) = quad_light_scene();
    let lights = scene.lights();
    let mut rng = Rng::new(1);
    for (x, n) in [
        (Vec3::ZERO, Vec3::Y),
        (
            Vec3::new(1.5, 0.2, 0.3),
            Vec3::new(-1.0, 1.0, 0.0).normalize(),
        ),
        (Vec3::new(0.0, 0.9, 0.0), Vec3::Y),
    ] {
        let expected = polygon_irradiance(x, n, &vertices, 1.0);
        let n_samples = 200_000;
        let mut sum = 0.0f64;
        for _ in 0..n_samples {
            if let Some(s) = lights.sample_direct(x, Vec3::ZERO, rng.f32(), rng.vec2()) {
                assert!(!s.is_delta);
                sum += f64::from(s.radiance.x * s.incoming.dot(n).max(0.0) / s.pdf);
            }
        }
        let got = (sum / f64::from(n_samples)) as f32;
        assert!(
            (got - expected).abs() < 0.02 * expected,
            "{x}: {got} vs {expected}"
        );
    }
    // From behind the one-sided emitter there is nothing.
    assert!(
        lights
            .sample_direct(Vec3::new(0.0, 2.0, 0.0), Vec3::ZERO, 0.5, Vec2::splat(0.5))
            .is_none()
    );
}

#[test]
fn pdf_direct_matches_sample_direct() {
    let (scene, _) = quad_light_scene();
    let mut rng = Rng::new(2);
    let x = Vec3::new(0.1, 0.0, 0.2);
    for _ in 0..500 {
        let s = scene
            .lights()
            .sample_direct(x, Vec3::ZERO, rng.f32(), rng.vec2())
            .unwrap();
        let hit = scene.intersect(&Ray::infinite(x, s.incoming)).unwrap();
        assert!((hit.t - s.distance).abs() < 1e-4);
        let pdf = scene.lights().pdf_direct(x, Vec3::ZERO, &hit);
        assert!((pdf - s.pdf).abs() < 1e-3 * s.pdf, "{pdf} vs {}", s.pdf);
        assert_eq!(scene.emitted(&hit), Rgb::ONE);
    }
}

#[test]
fn point_light_gives_inverse_square_cosine() {
    let lights = vec![
        Light::Point {
            position: Vec3::new(0.0, 2.0, 0.0),
            intensity: Rgb::splat(3.0),
        },
        Light::Point {
            position: Vec3::new(1.0, 1.0, 0.0),
            intensity: Rgb::splat(1.0),
        },
    ];
    let scene = Scene::new(description(vec![], vec![], lights)).unwrap();
    let (x, n) = (Vec3::ZERO, Vec3::Y);
    let expected = 3.0 / 4.0 + 1.0 / 2.0 * (1.0 / 2f32.sqrt());
    let mut rng = Rng::new(3);
    let n_samples = 100_000;
    let mut sum = 0.0f64;
    for _ in 0..n_samples {
        let s = scene
            .lights()
            .sample_direct(x, Vec3::ZERO, rng.f32(), rng.vec2())
            .unwrap();
        assert!(s.is_delta);
        sum += f64::from(s.radiance.x * s.incoming.dot(n).max(0.0) / s.pdf);
    }
    let got = (sum / f64::from(n_samples)) as f32;
    assert!(
        (got - expected).abs() < 0.01 * expected,
        "{got} vs {expected}"
    );
    // Power-proportional choice: 3:1.
    assert!((scene.lights().total_power().x - 16.0 * PI).abs() < 1e-3);
}

/// Mean photon power over many photons (estimates the total flux).
fn photon_flux(scene: &Scene, n: u32) -> (Rgb, Vec<super::EmissionSample>) {
    let mut rng = Rng::new(5);
    let mut sum = Rgb::ZERO;
    let mut samples = Vec::new();
    for _ in 0..n {
        if let Some(s) = scene
            .lights()
            .sample_emission(rng.f32(), rng.vec2(), rng.vec2())
        {
            sum += s.power;
            samples.push(s);
        }
    }
    (sum / n as f32, samples)
}

#[test]
fn area_emission_power_and_cosine_distribution() {
    let (scene, _) = quad_light_scene();
    let expected = PI * 1.0 * 0.6;
    assert!((scene.lights().total_power().x - expected).abs() < 1e-5);
    let (flux, samples) = photon_flux(&scene, 100_000);
    assert!((flux.x - expected).abs() < 1e-3 * expected, "{flux}");
    let (mut mean_cos, mut mean_cos2) = (0.0f64, 0.0f64);
    for s in &samples {
        let cos = s.direction.dot(s.normal);
        assert!(s.normal.abs_diff_eq(-Vec3::Y, 1e-6));
        let EmitterShape::Area { size, cos_theta } = s.emitter else {
            panic!("{:?}", s.emitter)
        };
        assert!((size - 0.6f32.sqrt() * 0.5f32.sqrt()).abs() < 1e-5);
        assert!((cos_theta - cos).abs() < 1e-5);
        mean_cos += f64::from(cos);
        mean_cos2 += f64::from(cos * cos);
        // The photon ray leaves the emitter without hitting it.
        let ray = s.ray();
        assert!(scene.intersect(&ray).is_none());
    }
    let n = samples.len() as f64;
    // Cosine-distributed: E[cos θ] = 2/3, E[cos² θ] = 1/2.
    assert!((mean_cos / n - 2.0 / 3.0).abs() < 5e-3, "{}", mean_cos / n);
    assert!((mean_cos2 / n - 0.5).abs() < 5e-3, "{}", mean_cos2 / n);
}

#[test]
fn sphere_emitter_power() {
    let sphere = Sphere {
        center: Vec3::new(0.0, 1.0, 0.0),
        radius: 0.5,
        material: 1,
    };
    let scene = Scene::new(description(vec![], vec![sphere], vec![])).unwrap();
    let expected = PI * 4.0 * PI * 0.25;
    let (flux, samples) = photon_flux(&scene, 50_000);
    assert!((flux.x - expected).abs() < 1e-3 * expected);
    for s in samples.iter().take(2000) {
        assert!(s.direction.dot(s.normal) >= 0.0);
        assert!(scene.intersect(&s.ray()).is_none(), "{s:?}");
    }
    // Irradiance at distance 3 from the centre, facing it: E = π L (R/d)².
    let x = Vec3::new(0.0, 4.0, 0.0);
    let mut rng = Rng::new(8);
    let mut sum = 0.0f64;
    let n = 200_000;
    for _ in 0..n {
        if let Some(s) = scene
            .lights()
            .sample_direct(x, Vec3::ZERO, rng.f32(), rng.vec2())
        {
            // Silhouette samples may graze past the sphere.
            let Some(hit) = scene.intersect(&Ray::infinite(x, s.incoming)) else {
                continue;
            };
            // Points on the far side are occluded by the sphere itself.
            if (hit.t - s.distance).abs() < 1e-3 {
                sum += f64::from(s.radiance.x * s.incoming.dot(-Vec3::Y) / s.pdf);
            }
        }
    }
    let got = (sum / f64::from(n)) as f32;
    let e = PI * (0.5f32 / 3.0).powi(2);
    assert!((got - e).abs() < 0.02 * e, "{got} vs {e}");
}

#[test]
fn spot_light_energy() {
    let (cone, start) = (30f32.to_radians(), 20f32.to_radians());
    let light = Light::Spot {
        position: Vec3::ZERO,
        direction: Vec3::new(0.0, -1.0, 0.0),
        intensity: Rgb::splat(2.0),
        cone_angle: cone,
        falloff_start: start,
    };
    let scene = Scene::new(description(vec![], vec![], vec![light])).unwrap();
    let expected = 2.0 * 2.0 * PI * ((1.0 - start.cos()) + 0.5 * (start.cos() - cone.cos()));
    assert!((scene.lights().total_power().x - expected).abs() < 1e-4 * expected);
    // Photons carry it.
    let (flux, samples) = photon_flux(&scene, 200_000);
    assert!(
        (flux.x - expected).abs() < 5e-3 * expected,
        "{flux} vs {expected}"
    );
    for s in &samples {
        assert!(s.direction.dot(-Vec3::Y) >= cone.cos() - 1e-5);
        assert!(matches!(s.emitter, EmitterShape::Spot { .. }));
    }
    // Integrating the intensity seen from a unit sphere of points gives the same flux.
    let mut rng = Rng::new(6);
    let n = 400_000;
    let mut sum = 0.0f64;
    for _ in 0..n {
        let x = crate::sampling::uniform_sphere(rng.vec2());
        if let Some(s) = scene
            .lights()
            .sample_direct(x, Vec3::ZERO, rng.f32(), rng.vec2())
        {
            // radiance = I(ω)/d² with d = 1.
            sum += f64::from(s.radiance.x / s.pdf);
        }
    }
    let integral = (sum / f64::from(n)) as f32 * 4.0 * PI;
    assert!(
        (integral - expected).abs() < 0.01 * expected,
        "{integral} vs {expected}"
    );
    // Full inside falloff_start, zero outside the cone.
    let inside = scene
        .lights()
        .sample_direct(Vec3::new(0.1, -1.0, 0.0), Vec3::ZERO, 0.5, Vec2::ZERO)
        .unwrap();
    assert!((inside.radiance.x * inside.distance * inside.distance - 2.0).abs() < 1e-4);
    assert!(
        scene
            .lights()
            .sample_direct(Vec3::new(1.0, -1.0, 0.0), Vec3::ZERO, 0.5, Vec2::ZERO)
            .is_none()
    );
}

#[test]
fn directional_light_covers_the_scene() {
    let light = Light::Directional {
        direction: Vec3::new(0.3, -1.0, 0.2),
        irradiance: Rgb::splat(2.0),
    };
    let floor = quad(
        Vec3::new(-1.0, 0.0, -1.0),
        Vec3::new(0.0, 0.0, 2.0),
        Vec3::new(2.0, 0.0, 0.0),
        0,
    );
    let scene = Scene::new(description(floor.to_vec(), vec![], vec![light])).unwrap();
    // Photons hitting the floor carry E·A·cos θ in total.
    let (flux, samples) = photon_flux(&scene, 200_000);
    let r = scene.bounds().bounding_radius();
    assert!((flux.x - 2.0 * PI * r * r).abs() < 1e-3 * flux.x);
    let mut on_floor = 0.0f64;
    for s in &samples {
        assert_eq!(s.emitter, EmitterShape::Directional);
        if scene.intersect(&s.ray()).is_some() {
            on_floor += f64::from(s.power.x);
        }
    }
    let on_floor = (on_floor / 200_000.0) as f32;
    let cos = Vec3::new(0.3, -1.0, 0.2).normalize().dot(-Vec3::Y);
    let expected = 2.0 * 4.0 * cos;
    assert!(
        (on_floor - expected).abs() < 0.02 * expected,
        "{on_floor} vs {expected}"
    );
    let s = scene
        .lights()
        .sample_direct(Vec3::ZERO, Vec3::ZERO, 0.3, Vec2::ZERO)
        .unwrap();
    assert!(s.is_delta && s.distance.is_infinite());
    assert!(
        s.incoming
            .abs_diff_eq(-Vec3::new(0.3, -1.0, 0.2).normalize(), 1e-6)
    );
    let _ = point_light(Vec3::ZERO);
}
