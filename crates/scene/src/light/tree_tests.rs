use glam::Vec3;

use crate::test_util::{Rng, description, point_light, tri};
use crate::{Light, Scene, Sphere};

/// Many emitters of every finite kind, facing every way, with powers over four decades, and a
/// directional light: what the tree must pick among.
fn many_lights() -> Scene {
    let mut rng = Rng::new(5);
    let mut triangles = Vec::new();
    for _ in 0..40 {
        let a = rng.vec3(-3.0, 3.0);
        let (b, c) = (a + 0.3 * rng.unit(), a + 0.3 * rng.unit());
        triangles.push(tri(a, b, c, 1));
    }
    let mut description = description(
        triangles,
        vec![Sphere {
            center: Vec3::new(0.5, 2.0, -1.0),
            radius: 0.2,
            material: 1,
        }],
        vec![
            point_light(Vec3::new(-2.0, 1.0, 0.5)),
            Light::Point {
                position: Vec3::new(2.0, -1.0, 0.5),
                intensity: Vec3::splat(1e3),
            },
            Light::Spot {
                position: Vec3::new(0.0, 3.0, 0.0),
                direction: -Vec3::Y,
                intensity: Vec3::splat(5.0),
                cone_angle: 0.5,
                falloff_start: 0.3,
            },
            Light::Directional {
                direction: Vec3::new(0.2, -1.0, 0.1),
                irradiance: Vec3::splat(0.01),
            },
        ],
    );
    // Emission over four decades.
    description.materials[1].emission = Vec3::new(10.0, 1.0, 0.001);
    Scene::new(description).unwrap()
}

/// The probability a sample reports is the one `pick_direct` gives the emitter it picked, bit
/// for bit, and the probabilities of all emitters at a point sum to at most one: where a node's
/// bounds face the point but none of its children's do, the descent stops with no emitter (as
/// pbrt's does), a sample that carries nothing because none of those emitters lights the point.
#[test]
fn picks_report_their_probability_and_sum_to_one() {
    let scene = many_lights();
    let lights = scene.lights();
    let n = lights.emitter_count();
    let mut rng = Rng::new(6);
    for _ in 0..200 {
        let p = rng.vec3(-4.0, 4.0);
        let normal = if rng.f32() < 0.5 {
            Vec3::ZERO
        } else {
            rng.unit()
        };
        let total: f64 = (0..n)
            .map(|i| f64::from(lights.pick_direct(i, p, normal)))
            .sum();
        assert!(total <= 1.0 + 1e-5 && total > 0.9, "{p}: {total}");
        for _ in 0..20 {
            let u = rng.f32();
            if let Some((i, pmf)) = lights.direct.sample(p, normal, u) {
                assert_eq!(pmf.to_bits(), lights.pick_direct(i, p, normal).to_bits());
            }
        }
    }
}

/// The picks follow their probabilities: a histogram of 200 000 picks at a few points against
/// `pick_direct`, and no pick as often as the probabilities fall short of one.
#[test]
fn picks_follow_their_probability() {
    let scene = many_lights();
    let lights = scene.lights();
    let n = lights.emitter_count();
    let mut rng = Rng::new(7);
    for p in [
        Vec3::ZERO,
        Vec3::new(2.5, 2.5, -2.5),
        Vec3::new(-1.0, 0.3, 3.0),
    ] {
        let samples = 200_000;
        // The last bin counts the samples without a pick.
        let mut counts = vec![0u32; n + 1];
        for _ in 0..samples {
            match lights.direct.sample(p, Vec3::Y, rng.f32()) {
                Some((i, _)) => counts[i] += 1,
                None => counts[n] += 1,
            }
        }
        let probability: Vec<f64> = (0..n)
            .map(|i| f64::from(lights.pick_direct(i, p, Vec3::Y)))
            .collect();
        let none = 1.0 - probability.iter().sum::<f64>();
        for (i, &count) in counts.iter().enumerate() {
            let expected = probability.get(i).copied().unwrap_or(none) * f64::from(samples);
            let sigma = expected.sqrt().max(1.0);
            assert!(
                (f64::from(count) - expected).abs() < 5.0 * sigma,
                "emitter {i} at {p}: {count} picks against {expected:.1}"
            );
        }
    }
}

/// No emitter that can light a point is left out: every triangle whose front faces the point
/// (some of its light reaches it) and every omnidirectional light has a positive probability,
/// with and without a receiving normal.
#[test]
fn every_emitter_that_can_light_a_point_can_be_picked() {
    let scene = many_lights();
    let lights = scene.lights();
    let mut rng = Rng::new(8);
    let mut checked = 0;
    for _ in 0..300 {
        let p = rng.vec3(-4.0, 4.0);
        let normal = if rng.f32() < 0.5 {
            Vec3::ZERO
        } else {
            rng.unit()
        };
        for (i, emitter) in lights.emitters.iter().enumerate() {
            let lit = match *emitter {
                super::Emitter::Triangle {
                    p0,
                    p1,
                    p2,
                    normal: n,
                    ..
                } => [p0, p1, p2].iter().any(|&v| (p - v).dot(n) > 1e-3),
                super::Emitter::Sphere { .. } | super::Emitter::Point { .. } => true,
                _ => continue,
            };
            if lit {
                checked += 1;
                assert!(lights.pick_direct(i, p, normal) > 0.0, "emitter {i} at {p}");
            }
        }
    }
    assert!(checked > 5000, "{checked}");
}

/// The estimate of irradiance by next-event estimation with the tree's picks converges to the
/// same value as with the power's picks (the sum over emitters of each one's exact share): a
/// point among a bright and a dim quad lamp, where the power picks the wrong one most of the
/// time and the tree the near one.
#[test]
fn irradiance_is_the_same_as_with_picks_by_power() {
    // A dim quad 0.3 above the point, a bright one (×100) 3 away: the near one dominates.
    // Both face down (front = e1 × e2 = −y).
    let mut triangles = crate::test_util::quad(
        Vec3::new(-0.1, 0.3, -0.1),
        Vec3::new(0.2, 0.0, 0.0),
        Vec3::new(0.0, 0.0, 0.2),
        1,
    )
    .to_vec();
    triangles.extend(crate::test_util::quad(
        Vec3::new(2.9, 3.0, -0.1),
        Vec3::new(0.2, 0.0, 0.0),
        Vec3::new(0.0, 0.0, 0.2),
        2,
    ));
    let mut d = description(triangles, vec![], vec![]);
    let mut bright = d.materials[1].clone();
    bright.emission = Vec3::splat(100.0);
    d.materials.push(bright);
    let scene = Scene::new(d).unwrap();
    let lights = scene.lights();
    let x = Vec3::ZERO;
    let exact = |corner: Vec3, l: f32| {
        let v = [
            corner,
            corner + Vec3::new(0.0, 0.0, 0.2),
            corner + Vec3::new(0.2, 0.0, 0.2),
            corner + Vec3::new(0.2, 0.0, 0.0),
        ];
        let mut sum = 0.0;
        for i in 0..4 {
            let a = (v[i] - x).normalize();
            let b = (v[(i + 1) % 4] - x).normalize();
            sum += a.dot(b).clamp(-1.0, 1.0).acos() * Vec3::Y.dot(a.cross(b).normalize());
        }
        0.5 * l * sum.abs()
    };
    let expected = exact(Vec3::new(-0.1, 0.3, -0.1), 1.0) + exact(Vec3::new(2.9, 3.0, -0.1), 100.0);
    let mut rng = Rng::new(9);
    let samples = 400_000;
    let (mut sum, mut sum2) = (0.0f64, 0.0f64);
    for _ in 0..samples {
        let Some(s) = lights.sample_direct(x, Vec3::Y, rng.f32(), rng.vec2()) else {
            continue;
        };
        let e = f64::from(s.radiance.x * s.incoming.dot(Vec3::Y).max(0.0) / s.pdf);
        sum += e;
        sum2 += e * e;
    }
    let mean = sum / f64::from(samples);
    let sigma = ((sum2 / f64::from(samples) - mean * mean) / f64::from(samples)).sqrt();
    assert!(
        (mean - f64::from(expected)).abs() < 4.0 * sigma + 1e-4 * f64::from(expected),
        "{mean} ± {sigma} against {expected}"
    );
    // The near lamp is picked far more often than its 1 % share of the power.
    let near = lights.pick_direct(0, x, Vec3::Y) + lights.pick_direct(1, x, Vec3::Y);
    assert!(near > 0.5, "{near}");
}
