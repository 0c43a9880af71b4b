use glam::Vec3;

use super::{Scene, SceneError, intersect_inlined};
use crate::test_util::{Rng, closed_box, description, point_light, quad, tri};
use crate::{Primitive, Ray, Sphere, Triangle};

/// Brute-force closest hit in f64: (t, primitive).
fn brute_force(tris: &[Triangle], spheres: &[Sphere], ray: &Ray) -> Option<(f64, Primitive)> {
    let o = ray.origin.as_dvec3();
    let d = ray.direction.as_dvec3();
    let mut best: Option<(f64, Primitive)> = None;
    let mut consider = |t: f64, p: Primitive| {
        if t > 0.0 && t < f64::from(ray.t_max) && best.is_none_or(|(bt, _)| t < bt) {
            best = Some((t, p));
        }
    };
    for (i, tr) in tris.iter().enumerate() {
        let [a, b, c] = tr.positions.map(|v| v.as_dvec3());
        let (e1, e2) = (b - a, c - a);
        let pv = d.cross(e2);
        let det = e1.dot(pv);
        if det.abs() < 1e-300 {
            continue;
        }
        let tv = o - a;
        let u = tv.dot(pv) / det;
        let qv = tv.cross(e1);
        let v = d.dot(qv) / det;
        if u < 0.0 || v < 0.0 || u + v > 1.0 {
            continue;
        }
        consider(e2.dot(qv) / det, Primitive::Triangle(i as u32));
    }
    for (i, s) in spheres.iter().enumerate() {
        let f = o - s.center.as_dvec3();
        let b = f.dot(d);
        let c = f.length_squared() - f64::from(s.radius).powi(2);
        let disc = b * b - c;
        if disc < 0.0 {
            continue;
        }
        for t in [-b - disc.sqrt(), -b + disc.sqrt()] {
            consider(t, Primitive::Sphere(i as u32));
        }
    }
    best
}

fn soup(rng: &mut Rng, n_tris: usize, n_spheres: usize) -> (Vec<Triangle>, Vec<Sphere>) {
    let tris = (0..n_tris)
        .map(|_| {
            let c = rng.vec3(-5.0, 5.0);
            tri(
                c + rng.vec3(-1.0, 1.0),
                c + rng.vec3(-1.0, 1.0),
                c + rng.vec3(-1.0, 1.0),
                0,
            )
        })
        .collect();
    let spheres = (0..n_spheres)
        .map(|_| Sphere {
            center: rng.vec3(-5.0, 5.0),
            radius: 0.2 + rng.f32(),
            material: 0,
        })
        .collect();
    (tris, spheres)
}

fn random_rays(rng: &mut Rng, n: usize) -> Vec<Ray> {
    let mut rays = Vec::new();
    for i in 0..n {
        let origin = rng.vec3(-7.0, 7.0);
        let mut dir = rng.unit();
        match i % 4 {
            // Axis-aligned rays with -0.0 components (obvhs G1).
            0 => {
                let axis = i / 4 % 3;
                let sign = if rng.f32() < 0.5 { -1.0 } else { 1.0 };
                dir = Vec3::splat(-0.0);
                dir[axis] = sign;
            }
            // One -0.0 component.
            1 => dir[i % 3] = -0.0,
            _ => {}
        }
        let t_max = if i % 5 == 0 { 3.0 } else { f32::INFINITY };
        // Built directly, so that the -0.0 components reach the query.
        rays.push(Ray {
            origin,
            direction: dir.normalize(),
            t_max,
        });
    }
    rays
}

#[test]
fn intersect_matches_brute_force() {
    let mut rng = Rng::new(7);
    let (tris, spheres) = soup(&mut rng, 400, 12);
    let scene = Scene::new(description(
        tris.clone(),
        spheres.clone(),
        vec![point_light(Vec3::ZERO)],
    ))
    .unwrap();
    assert_eq!(scene.primitive_count(), 412);
    let mut n_hits = 0;
    for ray in random_rays(&mut rng, 20_000) {
        let got = scene.intersect(&ray);
        let want = brute_force(&tris, &spheres, &ray);
        match (got, want) {
            (None, None) => {}
            (Some(h), Some((t, p))) => {
                n_hits += 1;
                let tol = 1e-4 * t.max(1.0);
                assert!(
                    (f64::from(h.t) - t).abs() < tol,
                    "{ray:?}: t {} vs {t}",
                    h.t
                );
                if h.primitive != p {
                    // Only acceptable if both are (almost) equally close.
                    let other = brute_force(
                        &tris,
                        &spheres,
                        &Ray {
                            t_max: (t + tol) as f32,
                            ..ray
                        },
                    );
                    assert!(other.is_some(), "{ray:?}: {:?} vs {p:?}", h.primitive);
                }
                assert!(h.position.distance(ray.at(h.t)) < 1e-3);
            }
            (got, want) => {
                // Grazing hits exactly on an edge may go either way.
                let grazing = want.is_some_and(|(t, _)| t < 0.0) || got.is_some_and(|h| h.t < 0.0);
                assert!(grazing, "{ray:?}: got {got:?}, want {want:?}");
            }
        }
        // occluded agrees with intersect, and the inlined traversal gives the same hit.
        assert_eq!(scene.occluded(&ray), got.is_some(), "{ray:?}");
        assert_eq!(
            intersect_inlined(&scene, &ray).map(|h| h.t.to_bits()),
            got.map(|h| h.t.to_bits()),
            "{ray:?}"
        );
    }
    assert!(n_hits > 2000, "{n_hits}");
}

#[test]
fn sphere_front_face_and_curvature() {
    let sphere = Sphere {
        center: Vec3::new(1.0, 2.0, 3.0),
        radius: 2.0,
        material: 0,
    };
    let scene = Scene::new(description(
        vec![],
        vec![sphere],
        vec![point_light(Vec3::ZERO)],
    ))
    .unwrap();
    // From outside.
    let h = scene
        .intersect(&Ray::infinite(Vec3::new(1.0, 2.0, 10.0), -Vec3::Z))
        .unwrap();
    assert!(h.front_face);
    assert!((h.t - 5.0).abs() < 1e-5);
    assert!(h.geometric_normal.abs_diff_eq(Vec3::Z, 1e-6));
    assert!((h.curvature + 0.5).abs() < 1e-6);
    assert_eq!(h.primitive, Primitive::Sphere(0));
    // From inside.
    let h = scene
        .intersect(&Ray::infinite(Vec3::new(1.0, 2.0, 3.0), Vec3::Z))
        .unwrap();
    assert!(!h.front_face);
    assert!((h.t - 2.0).abs() < 1e-5);
    assert!(h.geometric_normal.abs_diff_eq(-Vec3::Z, 1e-6));
    assert!((h.curvature - 0.5).abs() < 1e-6);
    // Spawned rays: reflected outward never re-hit; refracted inward hit the far side.
    let mut rng = Rng::new(3);
    for _ in 0..2000 {
        let origin = sphere.center + 6.0 * rng.unit();
        let target = sphere.center + 1.9 * rng.unit();
        let Some(h) = scene.intersect(&Ray::infinite(origin, target - origin)) else {
            continue;
        };
        let mut out = rng.unit();
        if out.dot(h.geometric_normal) < 0.0 {
            out = -out;
        }
        assert!(scene.intersect(&h.spawn_ray(out)).is_none());
        let inside = scene.intersect(&h.spawn_ray(-out)).unwrap();
        assert!(inside.t > 1e-3 && !inside.front_face, "{inside:?}");
    }
}

#[test]
fn mesh_curvature_from_vertex_normals() {
    // A tessellated sphere of radius 2 with exact vertex normals, CCW seen from outside.
    let r = 2.0;
    let (n_theta, n_phi) = (24, 48);
    let point = |i: usize, j: usize| {
        let theta = std::f32::consts::PI * i as f32 / n_theta as f32;
        let phi = std::f32::consts::TAU * j as f32 / n_phi as f32;
        Vec3::new(
            theta.sin() * phi.cos(),
            theta.sin() * phi.sin(),
            theta.cos(),
        )
    };
    let mut tris = Vec::new();
    for i in 1..n_theta - 1 {
        for j in 0..n_phi {
            let (a, b, c, d) = (
                point(i, j),
                point(i + 1, j),
                point(i + 1, j + 1),
                point(i, j + 1),
            );
            for [p, q, s] in [[a, b, c], [a, c, d]] {
                tris.push(Triangle {
                    positions: [p * r, q * r, s * r],
                    normals: Some([p, q, s]),
                    material: 0,
                    uv: None,
                    tangents: None,
                });
            }
        }
    }
    let scene = Scene::new(description(tris, vec![], vec![point_light(Vec3::ZERO)])).unwrap();
    let outside = scene
        .intersect(&Ray::infinite(
            Vec3::new(0.1, 0.2, 10.0) * 0.0 + Vec3::new(5.0, 0.3, 0.2),
            -Vec3::X,
        ))
        .unwrap();
    assert!(outside.front_face);
    assert!(
        (outside.curvature + 0.5).abs() < 0.02,
        "{}",
        outside.curvature
    );
    let radial = outside.position.normalize();
    assert!(outside.shading_normal.dot(radial) > 0.9999, "{outside:?}");
    let inside = scene
        .intersect(&Ray::infinite(Vec3::new(0.0, 0.1, 0.2), Vec3::X))
        .unwrap();
    assert!(!inside.front_face);
    assert!(
        (inside.curvature - 0.5).abs() < 0.02,
        "{}",
        inside.curvature
    );
    assert!(inside.shading_normal.dot(-inside.position.normalize()) > 0.9999);
    // Flat triangles have zero curvature.
    let flat = Scene::new(description(
        quad(Vec3::ZERO, Vec3::X, Vec3::Y, 0).to_vec(),
        vec![],
        vec![point_light(Vec3::Z)],
    ))
    .unwrap();
    let h = flat
        .intersect(&Ray::infinite(Vec3::new(0.3, 0.3, 1.0), -Vec3::Z))
        .unwrap();
    assert_eq!(h.curvature, 0.0);
    assert!(h.front_face);
    let h = flat
        .intersect(&Ray::infinite(Vec3::new(0.3, 0.3, -1.0), Vec3::Z))
        .unwrap();
    assert!(!h.front_face);
    assert!(h.geometric_normal.abs_diff_eq(-Vec3::Z, 1e-6));
}

/// A Cornell-like closed box far from the origin (large coordinates stress the offsets).
fn box_scene(offset: Vec3) -> (Scene, Vec3, Vec3) {
    let lo = offset + Vec3::new(-1.0, 0.0, -1.0);
    let hi = offset + Vec3::new(1.0, 2.0, 1.0);
    let scene = Scene::new(description(
        closed_box(lo, hi, 0),
        vec![],
        vec![point_light(offset + Vec3::Y)],
    ))
    .unwrap();
    (scene, lo, hi)
}

#[test]
fn no_self_intersection_on_walls() {
    for offset in [
        Vec3::ZERO,
        Vec3::new(100.0, -50.0, 300.0),
        Vec3::splat(3000.0),
    ] {
        let (scene, lo, hi) = box_scene(offset);
        let centre = 0.5 * (lo + hi);
        let mut rng = Rng::new(11);
        for _ in 0..5000 {
            let ray = Ray::infinite(centre + rng.vec3(-0.9, 0.9), rng.unit());
            let hit = scene.intersect(&ray).unwrap();
            assert!(hit.front_face);
            for _ in 0..4 {
                let mut d = rng.unit();
                if d.dot(hit.geometric_normal) < 0.0 {
                    d = -d;
                }
                let next = scene
                    .intersect(&hit.spawn_ray(d))
                    .unwrap_or_else(|| panic!("leak at {offset}: {hit:?} {:?}", hit.spawn_ray(d)));
                // A ray leaving a planar wall cannot hit the same plane.
                assert!(
                    next.t > 1e-4 * (1.0 + offset.abs().max_element())
                        || next.geometric_normal != hit.geometric_normal,
                    "acne at {offset}: {next:?} from {hit:?}"
                );
                assert!(
                    next.geometric_normal.dot(hit.geometric_normal) < 0.999,
                    "re-hit the own wall at {offset}: t = {}",
                    next.t
                );
            }
        }
    }
}

#[test]
fn corners_neither_leak_nor_block() {
    for offset in [Vec3::ZERO, Vec3::new(100.0, -50.0, 300.0)] {
        let (scene, lo, hi) = box_scene(offset);
        let mut rng = Rng::new(5);
        for k in 0..2000 {
            // A point on the floor near the corner with the x = hi wall, aimed at from inside.
            let eps = 10f32.powf(-1.0 - 4.0 * rng.f32());
            let z = lo.z + 0.1 + 1.8 * rng.f32();
            let floor_point = Vec3::new(hi.x - eps, lo.y, z);
            let from_floor = scene
                .intersect(&Ray::infinite(
                    floor_point + Vec3::new(-0.5, 0.5, 0.0),
                    Vec3::new(0.5, -0.5, 0.0),
                ))
                .unwrap();
            let wall_point = Vec3::new(
                hi.x,
                lo.y + eps * (0.5 + rng.f32()),
                z + 0.01 * (rng.f32() - 0.5),
            );
            let wall_hit = scene
                .intersect(&Ray::infinite(
                    wall_point - Vec3::new(0.5, 0.0, 0.0),
                    Vec3::X,
                ))
                .unwrap();
            assert!(
                scene.visible(&from_floor, wall_hit.position),
                "corner blocked ({k}, eps {eps}, offset {offset}): {from_floor:?} {wall_hit:?} {:?} {:?}",
                from_floor.spawn_ray_to(wall_hit.position),
                scene.intersect(&from_floor.spawn_ray_to(wall_hit.position))
            );
            assert!(scene.visible(&wall_hit, from_floor.position));
            // Just outside the box is never visible from inside.
            let outside = Vec3::new(hi.x + eps.max(1e-3), floor_point.y + 0.3, z);
            assert!(!scene.visible(&from_floor, outside), "leak to {outside}");
            let below = Vec3::new(hi.x - 0.3, lo.y - eps.max(1e-3), z);
            assert!(!scene.visible(&wall_hit, below), "leak to {below}");
        }
    }
}

#[test]
fn scene_errors() {
    let empty = description(vec![], vec![], vec![]);
    let err = Scene::new(empty).unwrap_err();
    assert!(matches!(err, SceneError::Empty { .. }));
    assert_eq!(
        err.to_string(),
        "scene `test.toml` has no geometry and no lights"
    );

    let dark = description(
        quad(Vec3::ZERO, Vec3::X, Vec3::Y, 0).to_vec(),
        vec![],
        vec![],
    );
    assert!(matches!(
        Scene::new(dark).unwrap_err(),
        SceneError::NoLight { .. }
    ));

    // An emitter with zero area is no light either.
    let degenerate = description(
        vec![tri(Vec3::ZERO, Vec3::X, 2.0 * Vec3::X, 1)],
        vec![],
        vec![],
    );
    assert!(matches!(
        Scene::new(degenerate).unwrap_err(),
        SceneError::NoLight { .. }
    ));

    let bad_material = description(
        vec![tri(Vec3::ZERO, Vec3::X, Vec3::Y, 9)],
        vec![],
        vec![point_light(Vec3::Z)],
    );
    let err = Scene::new(bad_material).unwrap_err();
    assert_eq!(
        err.to_string(),
        "scene `test.toml`: triangle 0 refers to material 9 but there are 2 materials"
    );

    let mut bad_camera = description(vec![], vec![], vec![point_light(Vec3::Z)]);
    bad_camera.camera.look_at = bad_camera.camera.position;
    assert!(matches!(
        Scene::new(bad_camera).unwrap_err(),
        SceneError::Camera { .. }
    ));

    let bad_sphere = description(
        vec![],
        vec![Sphere {
            center: Vec3::ZERO,
            radius: -1.0,
            material: 0,
        }],
        vec![point_light(Vec3::Z)],
    );
    assert!(matches!(
        Scene::new(bad_sphere).unwrap_err(),
        SceneError::Invalid { .. }
    ));

    // Lights only is fine (nothing to hit).
    let lights_only = Scene::new(description(vec![], vec![], vec![point_light(Vec3::Z)])).unwrap();
    assert!(
        lights_only
            .intersect(&Ray::infinite(Vec3::ZERO, Vec3::X))
            .is_none()
    );
    assert!(!lights_only.occluded(&Ray::infinite(Vec3::ZERO, Vec3::X)));
}

#[test]
fn emitted_only_from_front_faces() {
    let scene = Scene::new(description(
        quad(Vec3::ZERO, Vec3::X, Vec3::Y, 1).to_vec(),
        vec![],
        vec![],
    ))
    .unwrap();
    let front = scene
        .intersect(&Ray::infinite(Vec3::new(0.5, 0.5, 1.0), -Vec3::Z))
        .unwrap();
    assert_eq!(scene.emitted(&front), Vec3::ONE);
    let back = scene
        .intersect(&Ray::infinite(Vec3::new(0.5, 0.5, -1.0), Vec3::Z))
        .unwrap();
    assert_eq!(scene.emitted(&back), Vec3::ZERO);
}

/// Hits within 1e-4 of the origin must be found (obvhs' CwBvh traversal, used before
/// `bvh/wide.rs`, culled boxes the ray leaves that early; kept as a regression test).
#[test]
fn hits_closer_than_obvhs_epsilon() {
    let mut tris = quad(Vec3::new(-1.0, 0.0, 1.0), Vec3::X * 2.0, -Vec3::Z * 2.0, 0).to_vec();
    tris.extend(quad(
        Vec3::new(-1.0, 0.5, 1.0),
        Vec3::X * 2.0,
        -Vec3::Z * 2.0,
        0,
    ));
    let scene = Scene::new(description(tris, vec![], vec![point_light(Vec3::Y)])).unwrap();
    for height in [1e-3f32, 1e-4, 2.4e-5, 1e-6, 1e-8] {
        for dir in [-Vec3::Y, Vec3::new(0.7, -0.44, 0.56).normalize()] {
            let ray = Ray::infinite(Vec3::new(0.155, height, 0.634), dir);
            let hit = scene
                .intersect(&ray)
                .unwrap_or_else(|| panic!("missed at {height}"));
            assert!(
                (hit.t - height / -dir.y).abs() < 1e-6,
                "{height}: {}",
                hit.t
            );
            assert!(scene.occluded(&ray));
            assert!(!scene.occluded(&Ray {
                t_max: 0.5 * hit.t,
                ..ray
            }));
        }
    }
}

#[test]
fn mesh_curvature_is_the_focusing_principal_curvature() {
    // A tessellated open cylinder of radius 0.5 about y with exact vertex normals, CCW seen
    // from outside: principal curvatures 1/R across the axis and 0 along it. From inside the
    // reported curvature must be the focusing 1/R = 2 (not the mean 1/(2R)); from outside
    // the larger of −1/R and 0, i.e. 0.
    let r = 0.5;
    let n_phi = 64;
    let ring = |j: usize| {
        let phi = std::f32::consts::TAU * j as f32 / n_phi as f32;
        Vec3::new(phi.cos(), 0.0, -phi.sin())
    };
    let mut tris = Vec::new();
    for j in 0..n_phi {
        let (n0, n1) = (ring(j), ring(j + 1));
        let (a, b) = (n0 * r, n1 * r);
        let (c, d) = (b + Vec3::Y, a + Vec3::Y);
        for ([p, q, s], normals) in [([a, b, c], [n0, n1, n1]), ([a, c, d], [n0, n1, n0])] {
            tris.push(Triangle {
                positions: [p, q, s],
                normals: Some(normals),
                material: 0,
                uv: None,
                tangents: None,
            });
        }
    }
    let scene = Scene::new(description(tris, vec![], vec![point_light(Vec3::Y * 0.5)])).unwrap();
    let outside = scene
        .intersect(&Ray::infinite(Vec3::new(3.0, 0.5, 0.01), -Vec3::X))
        .unwrap();
    assert!(outside.front_face);
    assert!(outside.curvature.abs() < 0.02, "{}", outside.curvature);
    let inside = scene
        .intersect(&Ray::infinite(Vec3::new(0.0, 0.5, 0.01), Vec3::X))
        .unwrap();
    assert!(!inside.front_face);
    assert!(
        (inside.curvature - 2.0).abs() < 0.02,
        "{}",
        inside.curvature
    );
}
