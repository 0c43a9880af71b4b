//! The emitters' densities against their samplers, for every kind: each sample reports the
//! densities that the queries give at its point and direction, and they divide its power; the
//! emitters are picked as reported. The scenes, one per kind of emitter, are here;
//! `densities_histograms.rs` checks that the samples follow the densities.

use std::sync::Arc;

use glam::{Vec2, Vec3};

use super::EmissionPdf;
use crate::light::spot_falloff;
use crate::test_util::{Rng, description, quad, tri};
use crate::texture::{MaterialTextures, TextureRef, Wrap, test_image};
use crate::{
    Environment, EnvironmentMap, EnvironmentRadiance, Light, Ray, Rgb, Scene, Sphere, Triangle,
};

/// Samples per histogram.
const N: u32 = 200_000;

/// The lamp: a 1 × 0.6 quad of material 1 facing −y at height 1, as `corner + s·e1 + t·e2`.
const CORNER: Vec3 = Vec3::new(-0.5, 1.0, -0.3);
const E1: Vec3 = Vec3::new(1.0, 0.0, 0.0);
const E2: Vec3 = Vec3::new(0.0, 0.0, 0.6);

/// A floor of the non-emitting material 0, which gives the scene its bounds.
fn floor() -> Vec<Triangle> {
    quad(
        Vec3::new(-1.0, -0.5, -1.0),
        Vec3::new(0.0, 0.0, 2.0),
        Vec3::new(2.0, 0.0, 0.0),
        0,
    )
    .to_vec()
}

fn quad_scene() -> Scene {
    Scene::new(description(
        quad(CORNER, E1, E2, 1).to_vec(),
        vec![],
        vec![],
    ))
    .unwrap()
}

/// The lamp quad with an emission texture, dim (64) on its left half and bright (255) on its
/// right, so that its two triangles are picked with different probabilities.
fn textured_quad_scene() -> Scene {
    let [mut a, mut b] = quad(CORNER, E1, E2, 2);
    a.uv = Some([Vec2::ZERO, Vec2::X, Vec2::ONE]);
    b.uv = Some([Vec2::ZERO, Vec2::ONE, Vec2::Y]);
    let mut d = description(vec![a, b], vec![], vec![]);
    let mut texture = TextureRef::new(
        test_image(2, 1, vec![[64, 64, 64, 255], [255, 255, 255, 255]]),
        false,
    );
    texture.wrap = [Wrap::Clamp; 2];
    let mut lamp = crate::test_util::diffuse(0.0, Vec3::splat(2.0));
    lamp.textures = Some(Arc::new(MaterialTextures {
        emission: Some(texture),
        ..Default::default()
    }));
    d.materials.push(lamp);
    Scene::new(d).unwrap()
}

const SPHERE_CENTER: Vec3 = Vec3::new(0.2, 1.0, -0.1);
const SPHERE_RADIUS: f32 = 0.4;

fn sphere_scene() -> Scene {
    let sphere = Sphere {
        center: SPHERE_CENTER,
        radius: SPHERE_RADIUS,
        material: 1,
    };
    Scene::new(description(vec![], vec![sphere], vec![])).unwrap()
}

fn light_scene(light: Light) -> Scene {
    Scene::new(description(floor(), vec![], vec![light])).unwrap()
}

fn point() -> Light {
    Light::Point {
        position: Vec3::new(0.1, 0.8, -0.2),
        intensity: Rgb::new(3.0, 2.0, 1.0),
    }
}

/// The spot's axis.
fn spot_axis() -> Vec3 {
    Vec3::new(0.3, -1.0, 0.2).normalize()
}

fn spot() -> Light {
    Light::Spot {
        position: Vec3::new(0.1, 0.8, -0.2),
        direction: spot_axis(),
        intensity: Rgb::splat(2.0),
        cone_angle: 35f32.to_radians(),
        falloff_start: 20f32.to_radians(),
    }
}

fn directional() -> Light {
    Light::Directional {
        direction: Vec3::new(0.3, -1.0, 0.2),
        irradiance: Rgb::splat(2.0),
    }
}

/// A 32 × 16 map: a gradient with a bright patch and a black band.
fn environment_map() -> EnvironmentMap {
    let (w, h) = (32u32, 16u32);
    let mut texels = Vec::new();
    for y in 0..h {
        for x in 0..w {
            texels.push(if (5..7).contains(&y) && (20..23).contains(&x) {
                Vec3::new(60.0, 50.0, 40.0)
            } else if (10..12).contains(&y) {
                Vec3::ZERO
            } else {
                Vec3::new(0.2 + x as f32 / w as f32, 0.5, 0.1 + y as f32 / h as f32)
            });
        }
    }
    EnvironmentMap {
        path: "sky.exr".into(),
        width: w,
        height: h,
        texels,
    }
}

fn environment_scene(map: bool) -> Scene {
    let mut d = description(floor(), vec![], vec![]);
    d.environment = Some(Environment {
        radiance: if map {
            EnvironmentRadiance::Map(Arc::new(environment_map()))
        } else {
            EnvironmentRadiance::Constant(Rgb::new(0.5, 1.0, 1.5))
        },
        scale: 1.5,
        to_world: Environment::rotation_degrees(Vec3::new(20.0, 35.0, -10.0)),
    });
    Scene::new(d).unwrap()
}

/// Every scene, named, each with one kind of emitter (the quad has two triangles).
fn scenes() -> Vec<(&'static str, Scene)> {
    vec![
        ("quad", quad_scene()),
        ("textured quad", textured_quad_scene()),
        ("sphere", sphere_scene()),
        ("point", light_scene(point())),
        ("spot", light_scene(spot())),
        ("directional", light_scene(directional())),
        ("environment map", environment_scene(true)),
        ("constant environment", environment_scene(false)),
    ]
}

/// Whether `a` and `b` agree to a relative `tolerance`.
fn close(a: f32, b: f32, tolerance: f32) -> bool {
    (a - b).abs() <= tolerance * a.abs().max(b.abs())
}

#[track_caller]
fn assert_pdf_close(got: &EmissionPdf, want: &EmissionPdf, tolerance: f32) {
    let ok = close(got.pick, want.pick, tolerance)
        && close(got.position, want.position, tolerance)
        && close(got.direction, want.direction, tolerance)
        && close(got.direct, want.direct, tolerance)
        && close(got.cos_at_light, want.cos_at_light, tolerance)
        && got.is_delta == want.is_delta
        && got.is_infinite == want.is_infinite;
    assert!(ok, "{got:?} vs {want:?}");
}

/// The hit of a ray from `from` through the point `target`, if it is on an emitter near there.
/// From along the surface's normal: a ray that grazes a sphere finds it imprecisely, and its
/// normal there with it.
fn hit_at(scene: &Scene, from: Vec3, target: Vec3) -> Option<crate::Hit> {
    let d = target - from;
    let hit = scene.intersect(&Ray::infinite(from, d.normalize()))?;
    ((hit.position - target).length() < 1e-3).then_some(hit)
}

/// Each photon reports the densities that the queries give at its start and direction, and its
/// power is what the emitter sends there divided by them: L·cos θ for a surface or the sky, I
/// (times the spot's falloff) for a point or spot light, E for a directional light.
#[test]
fn emission_samples_report_the_densities_that_divide_their_power() {
    for (name, scene) in scenes() {
        let lights = scene.lights();
        let mut rng = Rng::new(1);
        let mut checked = 0;
        for _ in 0..20_000 {
            let (u_light, u_pos, u_dir) = (rng.f32(), rng.vec2(), rng.vec2());
            let plain = lights.sample_emission(u_light, u_pos, u_dir);
            let with = lights.sample_emission_with_pdf(u_light, u_pos, u_dir);
            assert_eq!(plain, with.map(|(s, _)| s), "{name}");
            let Some((s, pdf)) = with else { continue };
            let emission = pdf.emission_with_pick();
            assert!(emission > 0.0 && emission.is_finite(), "{name}: {pdf:?}");
            let sent = match s.emitter {
                super::EmitterShape::Area { .. } => {
                    // The camera's view of the same point (any ray that reaches it does).
                    let hit = hit_at(&scene, s.origin + 0.25 * s.normal, s.origin)
                        .expect("the emitter seen from its front");
                    let seen = lights
                        .pdf_emission(&hit, s.direction, (Vec3::ZERO, Vec3::ZERO))
                        .unwrap();
                    assert_pdf_close(&seen, &pdf, 1e-4);
                    assert!(!pdf.is_delta && !pdf.is_infinite);
                    scene.emitted(&hit) * pdf.cos_at_light
                }
                super::EmitterShape::Environment { .. } => {
                    let seen = lights.pdf_emission_environment(-s.direction).unwrap();
                    // A direction within rounding of a texel's edge may look up its neighbour.
                    if (seen.direction / pdf.direction - 1.0).abs() > 1e-3 {
                        continue;
                    }
                    assert_pdf_close(&seen, &pdf, 1e-3);
                    assert!(!pdf.is_delta && pdf.is_infinite && pdf.cos_at_light == 1.0);
                    lights.environment_radiance(-s.direction)
                }
                super::EmitterShape::Point => {
                    assert!(pdf.is_delta && !pdf.is_infinite && pdf.position == 1.0);
                    Rgb::new(3.0, 2.0, 1.0)
                }
                super::EmitterShape::Spot { .. } => {
                    assert!(pdf.is_delta && !pdf.is_infinite && pdf.position == 1.0);
                    let cos = s.direction.dot(spot_axis());
                    let (cone, start) = (35f32.to_radians().cos(), 20f32.to_radians().cos());
                    Rgb::splat(2.0) * spot_falloff(cos, cone, start)
                }
                super::EmitterShape::Directional => {
                    assert!(pdf.is_delta && pdf.is_infinite && pdf.direction == 1.0);
                    assert!(s.direction.abs_diff_eq(directional_direction(), 1e-6));
                    Rgb::splat(2.0)
                }
            };
            // Within 10⁻⁵ of the intensities where a spot's falloff vanishes.
            let error = (s.power * emission - sent).abs().max_element();
            assert!(
                error <= 1e-3 * sent.max_element() + 1e-5,
                "{name}: power {} × density {emission} vs {sent}",
                s.power
            );
            checked += 1;
        }
        assert!(checked > 15_000, "{name}: {checked}");
    }
}

fn directional_direction() -> Vec3 {
    Vec3::new(0.3, -1.0, 0.2).normalize()
}

/// Next-event estimation: every sample is `sample_direct`'s, its solid-angle density is the
/// direct density converted (pick · direct · d²/cos for a surface, pick · direct otherwise),
/// `pdf_direct` and `pdf_emission` agree at the point it chose, and a photon from there
/// toward the shading point has the emission density it reports.
#[test]
fn direct_samples_report_their_densities() {
    let receivers = [
        Vec3::new(0.05, 0.0, 0.1),
        Vec3::new(-1.5, 0.3, 0.8),
        Vec3::new(0.9, 2.5, 0.3),
    ];
    for (name, scene) in scenes() {
        let lights = scene.lights();
        let mut rng = Rng::new(9);
        for x in receivers {
            for _ in 0..3000 {
                let (u_light, u) = (rng.f32(), rng.vec2());
                let plain = lights.sample_direct(x, Vec3::ZERO, u_light, u);
                let with = lights.sample_direct_with_pdf(x, Vec3::ZERO, u_light, u);
                assert_eq!(plain, with.map(|(s, _)| s), "{name}");
                let Some((s, pdf)) = with else { continue };
                assert_eq!(pdf.is_delta, s.is_delta, "{name}");
                if pdf.is_infinite || pdf.is_delta {
                    assert_eq!(s.pdf.to_bits(), pdf.direct_with_pick().to_bits(), "{name}");
                } else {
                    let d2 = s.distance * s.distance;
                    let solid = pdf.direct_with_pick() * d2 / pdf.cos_at_light;
                    assert!(close(solid, s.pdf, 1e-4), "{name}: {solid} vs {}", s.pdf);
                }
                if pdf.is_delta {
                    // The light's only emitter; a spot lights x from inside its cone.
                    assert_eq!(
                        pdf,
                        lights.emitter_pdf(0, Vec3::ZERO, -s.incoming, Some((x, Vec3::ZERO)))
                    );
                    assert!(pdf.direction > 0.0 && pdf.position > 0.0, "{name}: {pdf:?}");
                    continue;
                }
                if pdf.is_infinite {
                    let seen = lights.pdf_emission_environment(s.incoming).unwrap();
                    // Within rounding of a texel's edge the lookup may find its neighbour.
                    if close(seen.direct, pdf.direct, 1e-3) {
                        assert_pdf_close(&seen, &pdf, 1e-3);
                        assert!(close(lights.pdf_environment(s.incoming), s.pdf, 1e-3));
                    }
                    continue;
                }
                let target = x + s.incoming * s.distance;
                let normal = if name == "sphere" {
                    (target - SPHERE_CENTER).normalize()
                } else {
                    -Vec3::Y
                };
                let hit = hit_at(&scene, target + 0.25 * normal, target).expect("the emitter");
                assert!(
                    close(lights.pdf_direct(x, Vec3::ZERO, &hit), s.pdf, 1e-3),
                    "{name}"
                );
                let seen = lights
                    .pdf_emission(&hit, -s.incoming, (x, Vec3::ZERO))
                    .unwrap();
                assert_pdf_close(&seen, &pdf, 1e-3);
            }
        }
    }
}

/// The emitters are picked as `pick` says, alike by both samplers, and the picks sum to one.
#[test]
fn emitters_are_picked_with_the_reported_probability() {
    let lamp = tri(CORNER, CORNER + E1, CORNER + E1 + E2, 1);
    let sphere = Sphere {
        center: SPHERE_CENTER + Vec3::new(2.0, 0.0, 0.0),
        radius: SPHERE_RADIUS,
        material: 1,
    };
    let mut d = description(
        [floor(), vec![lamp]].concat(),
        vec![sphere],
        vec![point(), spot(), directional()],
    );
    d.environment = Some(Environment {
        radiance: EnvironmentRadiance::Constant(Rgb::splat(0.05)),
        scale: 1.0,
        to_world: glam::Mat3::IDENTITY,
    });
    let scene = Scene::new(d).unwrap();
    let lights = scene.lights();
    // One key per emitter: its kind, and for an area emitter its size.
    let key = |shape: super::EmitterShape| match shape {
        super::EmitterShape::Area { size, .. } => format!("area {size}"),
        super::EmitterShape::Spot { .. } => "spot".to_owned(),
        other => format!("{other:?}").chars().take(5).collect(),
    };
    let mut counts = std::collections::BTreeMap::<String, (u32, f32)>::new();
    let mut rng = Rng::new(11);
    for _ in 0..N {
        let (u_light, u_pos, u_dir) = (rng.f32(), rng.vec2(), rng.vec2());
        let Some((s, pdf)) = lights.sample_emission_with_pdf(u_light, u_pos, u_dir) else {
            continue;
        };
        let entry = counts.entry(key(s.emitter)).or_insert((0, pdf.pick));
        assert_eq!(entry.1, pdf.pick);
        entry.0 += 1;
    }
    assert_eq!(counts.len(), 6, "{counts:?}");
    let total: f32 = counts.values().map(|(_, p)| p).sum();
    assert!((total - 1.0).abs() < 1e-5, "{total}");
    for (name, (count, pick)) in counts {
        let share = f64::from(count) / f64::from(N);
        let p = f64::from(pick);
        let tolerance = 5.0 * (p * (1.0 - p) / f64::from(N)).sqrt() + 1e-3;
        assert!((share - p).abs() < tolerance, "{name}: {share} vs {p}");
    }
    // Nothing without an environment; nothing on a surface that does not emit.
    let plain = quad_scene();
    assert!(plain.lights().pdf_emission_environment(Vec3::Y).is_none());
    let floor_hit = scene
        .intersect(&Ray::infinite(Vec3::new(0.0, 0.5, 0.0), -Vec3::Y))
        .unwrap();
    assert!(
        lights
            .pdf_emission(&floor_hit, Vec3::Y, (Vec3::ZERO, Vec3::ZERO))
            .is_none()
    );
}

#[path = "densities_histograms.rs"]
mod histograms;
