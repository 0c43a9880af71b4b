//! Analytic open cylinders: intersection against an independent f64 solver, normals, curvature,
//! arc and height clipping, robust spawning, and a mirror's paraxial focus.

use std::f64::consts::PI;

use glam::Vec3;

use super::{Scene, SceneError};
use crate::test_util::{Rng, description, diffuse, point_light, quad};
use crate::{Cylinder, Hit, Material, MaterialKind, Primitive, Ray, Triangle};

fn cylinder(
    center: Vec3,
    axis: Vec3,
    radius: f32,
    height: f32,
    arc_deg: f32,
    facing: Vec3,
) -> Cylinder {
    let axis = axis.normalize();
    let facing = (facing - facing.dot(axis) * axis).normalize();
    Cylinder {
        center,
        axis,
        radius,
        height,
        arc: if arc_deg >= 360.0 {
            std::f32::consts::TAU
        } else {
            arc_deg.to_radians()
        },
        facing,
        material: 0,
    }
}

/// The upright unit cylinder used by the direct tests: axis +Y, radius 1, height 2.
fn upright(arc_deg: f32, facing: Vec3) -> Cylinder {
    cylinder(Vec3::ZERO, Vec3::Y, 1.0, 2.0, arc_deg, facing)
}

fn scene_of(triangles: Vec<Triangle>, cylinders: Vec<Cylinder>) -> Scene {
    let mut d = description(
        triangles,
        vec![],
        vec![point_light(Vec3::new(0.0, 50.0, 0.0))],
    );
    d.cylinders = cylinders;
    Scene::new(d).unwrap()
}

/// What the reference solver found along a ray.
enum Reference {
    /// The closest valid hit: t and the cylinder index.
    Hit(f64, u32),
    /// No valid hit.
    Miss,
    /// A root lies too close to an edge, a tangent or the origin to decide in f32.
    Ambiguous,
}

/// Independent f64 reference: each cylinder in its own frame (facing, axis × facing, axis), the
/// textbook quadratic, the arc tested by the polar angle.
fn reference(cylinders: &[Cylinder], ray: &Ray) -> Reference {
    const EDGE: f64 = 1e-3;
    let mut best: Option<(f64, u32)> = None;
    let mut ambiguous = false;
    for (i, c) in cylinders.iter().enumerate() {
        let a = c.axis.as_dvec3();
        let u = c.facing.as_dvec3();
        let w = a.cross(u);
        let rel = ray.origin.as_dvec3() - c.center.as_dvec3();
        let d = ray.direction.as_dvec3();
        let (ox, oy, oz) = (rel.dot(u), rel.dot(w), rel.dot(a));
        let (dx, dy, dz) = (d.dot(u), d.dot(w), d.dot(a));
        let r = f64::from(c.radius);
        let qa = dx * dx + dy * dy;
        let qb = 2.0 * (ox * dx + oy * dy);
        let qc = ox * ox + oy * oy - r * r;
        let disc = qb * qb - 4.0 * qa * qc;
        if qa < 1e-12 || disc < 0.0 {
            continue;
        }
        if disc < 1e-6 * qa * r * r {
            ambiguous = true; // (nearly) tangent
        }
        for t in [
            (-qb - disc.sqrt()) / (2.0 * qa),
            (-qb + disc.sqrt()) / (2.0 * qa),
        ] {
            let z = oz + t * dz;
            let angle = (oy + t * dy).atan2(ox + t * dx);
            let half = 0.5 * f64::from(c.arc);
            let h = f64::from(c.height);
            let scale = r.max(h);
            let near_edge = t.abs() < EDGE * scale
                || (t - f64::from(ray.t_max)).abs() < EDGE * scale
                || z.abs() < EDGE * scale
                || (z - h).abs() < EDGE * scale
                || (half < PI && (angle.abs() - half).abs() < EDGE);
            let valid =
                t > 0.0 && t < f64::from(ray.t_max) && z >= 0.0 && z <= h && angle.abs() <= half;
            if near_edge {
                ambiguous = true;
            }
            if valid && best.is_none_or(|(bt, _)| t < bt) {
                best = Some((t, i as u32));
            }
        }
    }
    if ambiguous {
        return Reference::Ambiguous;
    }
    match best {
        Some((t, i)) => Reference::Hit(t, i),
        None => Reference::Miss,
    }
}

fn random_unit(rng: &mut Rng) -> Vec3 {
    loop {
        let v = Vec3::new(rng.f32(), rng.f32(), rng.f32()) * 2.0 - Vec3::ONE;
        let l = v.length_squared();
        if l > 1e-4 && l <= 1.0 {
            return v / l.sqrt();
        }
    }
}

/// Random cylinders, some cut to arcs, with random axes, and some big/small and off-centre.
fn random_cylinders(rng: &mut Rng, n: usize) -> Vec<Cylinder> {
    (0..n)
        .map(|i| {
            let center = (Vec3::new(rng.f32(), rng.f32(), rng.f32()) * 2.0 - Vec3::ONE) * 4.0;
            let axis = if i % 4 == 0 {
                Vec3::Y
            } else {
                random_unit(rng)
            };
            let arc = if i % 3 == 0 {
                360.0
            } else {
                30.0 + 300.0 * rng.f32()
            };
            let mut facing = random_unit(rng);
            if facing.cross(axis).length() < 0.1 {
                facing = axis.any_orthonormal_vector();
            }
            cylinder(
                center,
                axis,
                0.2 + 1.5 * rng.f32(),
                0.2 + 3.0 * rng.f32(),
                arc,
                facing,
            )
        })
        .collect()
}

#[test]
fn intersect_matches_an_independent_solver() {
    let mut rng = Rng::new(11);
    let cylinders = random_cylinders(&mut rng, 16);
    let scene = scene_of(vec![], cylinders.clone());
    assert_eq!(scene.primitive_count(), 16);
    let (mut hits, mut misses, mut skipped) = (0, 0, 0);
    for k in 0..40_000 {
        let origin = (Vec3::new(rng.f32(), rng.f32(), rng.f32()) * 2.0 - Vec3::ONE) * 8.0;
        // Half the rays aim at a cylinder, so that most of them hit something.
        let direction = if k % 2 == 0 {
            let c = &cylinders[(rng.next_u32() % 16) as usize];
            let target =
                c.center + c.axis * c.height * rng.f32() + random_unit(&mut rng) * c.radius;
            target - origin
        } else {
            random_unit(&mut rng)
        };
        let t_max = if k % 5 == 0 { 6.0 } else { f32::INFINITY };
        let ray = Ray::new(origin, direction, t_max);
        let got = scene.intersect(&ray);
        match reference(&cylinders, &ray) {
            Reference::Ambiguous => skipped += 1,
            Reference::Miss => {
                misses += 1;
                assert!(got.is_none(), "{ray:?}: got {got:?}, reference misses");
                assert!(!scene.occluded(&ray), "{ray:?}: occluded, reference misses");
            }
            Reference::Hit(t, i) => {
                hits += 1;
                let h = got.unwrap_or_else(|| panic!("{ray:?}: missed, reference hits {i} at {t}"));
                assert_eq!(h.primitive, Primitive::Cylinder(i), "{ray:?}");
                assert!(
                    (f64::from(h.t) - t).abs() < 1e-4 * t.max(1.0),
                    "{ray:?}: t {} vs {t}",
                    h.t
                );
                assert!(h.position.distance(ray.at(h.t)) < 1e-4, "{ray:?}");
                assert!(scene.occluded(&ray), "{ray:?}: not occluded");
                let c = &cylinders[i as usize];
                let rel = h.position - c.center;
                let radial = rel - rel.dot(c.axis) * c.axis;
                assert!((radial.length() - c.radius).abs() < 1e-5 * c.radius.max(1.0));
                assert!(h.geometric_normal.dot(ray.direction) <= 0.0);
                assert!((h.geometric_normal.length() - 1.0).abs() < 1e-5);
                assert!(h.geometric_normal.cross(radial).length() < 1e-4 * c.radius);
                assert!(h.uv.cmpge(glam::Vec2::ZERO).all() && h.uv.cmple(glam::Vec2::ONE).all());
            }
        }
    }
    assert!(
        hits > 10_000 && misses > 5_000,
        "{hits} hits, {misses} misses"
    );
    assert!(skipped < 2_000, "{skipped} ambiguous rays");
}

#[test]
fn cylinders_and_triangles_share_the_bvh() {
    // A floor under a ring: rays from above hit the floor inside the ring, the ring from outside.
    let floor = quad(
        Vec3::new(-3.0, 0.0, 3.0),
        Vec3::new(6.0, 0.0, 0.0),
        Vec3::new(0.0, 0.0, -6.0),
        0,
    );
    let scene = scene_of(floor.to_vec(), vec![upright(360.0, Vec3::Z)]);
    let down = Ray::infinite(Vec3::new(0.2, 5.0, 0.1), -Vec3::Y);
    let h = scene.intersect(&down).unwrap();
    assert!(matches!(h.primitive, Primitive::Triangle(_)));
    assert!((h.t - 5.0).abs() < 1e-5);
    let side = Ray::infinite(Vec3::new(5.0, 1.0, 0.0), -Vec3::X);
    let h = scene.intersect(&side).unwrap();
    assert_eq!(h.primitive, Primitive::Cylinder(0));
    assert!((h.t - 4.0).abs() < 1e-5);
}

#[test]
fn normals_front_face_and_curvature() {
    let scene = scene_of(vec![], vec![upright(360.0, Vec3::Z)]);
    // From outside: the front, convex.
    let h = scene
        .intersect(&Ray::infinite(Vec3::new(3.0, 1.0, 0.0), -Vec3::X))
        .unwrap();
    assert!((h.t - 2.0).abs() < 1e-6);
    assert!(h.front_face);
    assert!(h.geometric_normal.distance(Vec3::X) < 1e-6);
    assert_eq!(h.shading_normal, h.geometric_normal);
    // Flat along the axis: the larger principal curvature from outside is 0.
    assert!(h.curvature.abs() < 1e-6, "{}", h.curvature);
    assert!((h.uv.y - 0.5).abs() < 1e-6);
    // From inside: the back, concave.
    let h = scene
        .intersect(&Ray::infinite(Vec3::new(0.0, 1.5, 0.0), Vec3::X))
        .unwrap();
    assert!((h.t - 1.0).abs() < 1e-6);
    assert!(!h.front_face);
    assert!(h.geometric_normal.distance(-Vec3::X) < 1e-6);
    // Concave across the axis: 1/R, the curvature that focuses.
    assert!((h.curvature - 1.0).abs() < 1e-6, "{}", h.curvature);
    assert!((h.uv.y - 0.75).abs() < 1e-6);
    // 1/R from inside and 0 from outside, for any radius.
    let scene = scene_of(
        vec![],
        vec![cylinder(Vec3::ZERO, Vec3::Y, 0.25, 1.0, 360.0, Vec3::Z)],
    );
    let h = scene
        .intersect(&Ray::infinite(Vec3::new(3.0, 0.5, 0.0), -Vec3::X))
        .unwrap();
    assert!(h.curvature.abs() < 1e-6, "{}", h.curvature);
    let h = scene
        .intersect(&Ray::infinite(Vec3::new(0.0, 0.5, 0.0), Vec3::X))
        .unwrap();
    assert!((h.curvature - 4.0).abs() < 1e-5, "{}", h.curvature);
    // A ray along the axis never meets an open cylinder.
    let scene = scene_of(vec![], vec![upright(360.0, Vec3::Z)]);
    assert!(
        scene
            .intersect(&Ray::infinite(Vec3::new(0.3, -5.0, 0.2), Vec3::Y))
            .is_none()
    );
}

#[test]
fn arc_clipping() {
    // The half facing −z is kept.
    let scene = scene_of(vec![], vec![upright(180.0, -Vec3::Z)]);
    // Through the removed half (z = +1), then the inside of the kept half (z = −1).
    let h = scene
        .intersect(&Ray::infinite(Vec3::new(0.0, 1.0, 5.0), -Vec3::Z))
        .unwrap();
    assert!((h.t - 6.0).abs() < 1e-5, "{}", h.t);
    assert!(!h.front_face);
    assert!(h.geometric_normal.distance(Vec3::Z) < 1e-6);
    assert!((h.uv.x - 0.5).abs() < 1e-6, "{}", h.uv.x);
    // From the kept side: the outside of the kept half.
    let h = scene
        .intersect(&Ray::infinite(Vec3::new(0.0, 1.0, -5.0), Vec3::Z))
        .unwrap();
    assert!((h.t - 4.0).abs() < 1e-5);
    assert!(h.front_face);
    // Across, just on the removed side of the arc's edges (x = ±1 is the edge): nothing.
    assert!(
        scene
            .intersect(&Ray::infinite(Vec3::new(5.0, 1.0, 0.05), -Vec3::X))
            .is_none()
    );
    // Just on the kept side: both edges are hit, the near one first.
    let h = scene
        .intersect(&Ray::infinite(Vec3::new(5.0, 1.0, -0.05), -Vec3::X))
        .unwrap();
    assert!((h.t - (5.0 - (1.0f32 - 0.0025).sqrt())).abs() < 1e-5);
    assert!(h.front_face);
    // A quarter arc centred on +x.
    let scene = scene_of(vec![], vec![upright(90.0, Vec3::X)]);
    assert!(
        scene
            .intersect(&Ray::infinite(Vec3::new(0.0, 1.0, 0.0), Vec3::X))
            .is_some()
    );
    let diagonal = Vec3::new(1.0, 0.0, 0.8).normalize(); // 38.7° from +x: kept
    assert!(
        scene
            .intersect(&Ray::infinite(Vec3::new(0.0, 1.0, 0.0), diagonal))
            .is_some()
    );
    let diagonal = Vec3::new(1.0, 0.0, 1.2).normalize(); // 50.2°: removed
    assert!(
        scene
            .intersect(&Ray::infinite(Vec3::new(0.0, 1.0, 0.0), diagonal))
            .is_none()
    );
    // uv.x runs counter-clockwise about the axis (+y): from −45° (u = 0) toward +45° (u = 1),
    // and axis × facing = y × x = −z is +90°.
    let h = scene
        .intersect(&Ray::infinite(
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(1.0, 0.0, -0.5),
        ))
        .unwrap();
    assert!(h.uv.x > 0.5, "{}", h.uv.x);
}

#[test]
fn height_clipping() {
    let scene = scene_of(vec![], vec![upright(360.0, Vec3::Z)]);
    // Above and below the wall.
    assert!(
        scene
            .intersect(&Ray::infinite(Vec3::new(3.0, 2.01, 0.0), -Vec3::X))
            .is_none()
    );
    assert!(
        scene
            .intersect(&Ray::infinite(Vec3::new(3.0, -0.01, 0.0), -Vec3::X))
            .is_none()
    );
    // Enters low on the near side, leaves through the top opening: only the near wall.
    let d = Vec3::new(-1.0, 0.6, 0.0).normalize();
    let h = scene
        .intersect(&Ray::infinite(Vec3::new(3.0, 0.0, 0.0), d))
        .unwrap();
    assert!(h.front_face && (h.position.x - 1.0).abs() < 1e-5);
    let after = scene.intersect(&h.spawn_ray(d));
    assert!(after.is_none(), "{after:?}");
    // Over the near rim, down onto the inside of the far wall.
    let d = Vec3::new(-1.0, -0.2, 0.0).normalize();
    let h = scene
        .intersect(&Ray::infinite(Vec3::new(3.0, 2.5, 0.0), d))
        .unwrap();
    assert!(!h.front_face && (h.position.x + 1.0).abs() < 1e-5, "{h:?}");
    assert!((h.position.y - (2.5 - 0.2 * 4.0)).abs() < 1e-5);
}

#[test]
fn rotated_axis() {
    // Axis +x: the circle lies in the yz plane.
    let c = cylinder(Vec3::new(-1.0, 0.0, 0.0), Vec3::X, 0.5, 2.0, 360.0, Vec3::Y);
    let scene = scene_of(vec![], vec![c]);
    let h = scene
        .intersect(&Ray::infinite(Vec3::new(0.5, 5.0, 0.0), -Vec3::Y))
        .unwrap();
    assert!((h.t - 4.5).abs() < 1e-5);
    assert!(h.front_face && h.geometric_normal.distance(Vec3::Y) < 1e-6);
    assert!((h.uv.y - 0.75).abs() < 1e-5);
    assert!(
        scene
            .intersect(&Ray::infinite(Vec3::new(1.1, 5.0, 0.0), -Vec3::Y))
            .is_none()
    );
    assert!(
        scene
            .intersect(&Ray::infinite(Vec3::new(-1.1, 5.0, 0.0), -Vec3::Y))
            .is_none()
    );
    // A tilted axis: hits lie on the surface and normals are perpendicular to the axis.
    let axis = Vec3::new(1.0, 2.0, -0.5).normalize();
    let c = cylinder(Vec3::new(0.3, -0.2, 0.1), axis, 0.7, 3.0, 360.0, Vec3::X);
    let scene = scene_of(vec![], vec![c]);
    let mut rng = Rng::new(3);
    let mut n = 0;
    for _ in 0..2000 {
        let target = c.center + axis * (3.0 * rng.f32());
        let origin = target + random_unit(&mut rng) * 5.0;
        if let Some(h) = scene.intersect(&Ray::infinite(origin, target - origin)) {
            n += 1;
            let rel = h.position - c.center;
            assert!(((rel - rel.dot(axis) * axis).length() - 0.7).abs() < 1e-5);
            assert!(h.geometric_normal.dot(axis).abs() < 1e-5);
            let o = origin - c.center;
            // From outside the tube and within its height, the wall is met from outside.
            let along = o.dot(axis);
            if (o - along * axis).length() > 0.7 && (0.0..=3.0).contains(&along) {
                assert!(h.front_face);
            }
        }
    }
    assert!(n > 1000, "{n}");
}

#[test]
fn bounds_of_a_cylinder() {
    let b = cylinder(Vec3::new(1.0, 2.0, 3.0), Vec3::Y, 0.5, 2.0, 90.0, Vec3::Z).bounds();
    assert!(b.min.distance(Vec3::new(0.5, 2.0, 2.5)) < 1e-6);
    assert!(b.max.distance(Vec3::new(1.5, 4.0, 3.5)) < 1e-6);
    let axis = Vec3::new(1.0, 1.0, 0.0).normalize();
    let c = cylinder(Vec3::ZERO, axis, 1.0, 1.0, 360.0, Vec3::Z);
    let b = c.bounds();
    let mut rng = Rng::new(5);
    for _ in 0..1000 {
        let radial = {
            let v = random_unit(&mut rng);
            (v - v.dot(axis) * axis).normalize()
        };
        let p = c.center + axis * rng.f32() + radial;
        assert!(p.cmpge(b.min - 1e-6).all() && p.cmple(b.max + 1e-6).all());
    }
}

/// A point inside cylinder `c` (away from its wall).
fn inside_point(rng: &mut Rng, c: &Cylinder) -> Vec3 {
    let radial = {
        let v = random_unit(rng);
        (v - v.dot(c.axis) * c.axis).normalize_or(c.facing)
    };
    c.center + c.axis * (c.height * (0.1 + 0.8 * rng.f32())) + radial * (c.radius * 0.8 * rng.f32())
}

/// Hits on the inside of `c` (the scene holds only `c`) from rays cast from interior points.
fn inside_hits(scene: &Scene, c: &Cylinder, rng: &mut Rng, n: usize) -> Vec<Hit> {
    let mut hits = Vec::new();
    while hits.len() < n {
        let ray = Ray::infinite(inside_point(rng, c), random_unit(rng));
        if let Some(h) = scene.intersect(&ray) {
            assert!(!h.front_face);
            hits.push(h);
        }
    }
    hits
}

fn spawn_test_cylinders() -> Vec<Cylinder> {
    vec![
        upright(360.0, Vec3::Z),
        cylinder(
            Vec3::new(100.0, 50.0, -30.0),
            Vec3::new(0.3, 1.0, 0.2),
            0.5,
            0.35,
            360.0,
            Vec3::Z,
        ),
        cylinder(
            Vec3::new(-2e3, 1e3, 5e2),
            Vec3::new(-1.0, 0.1, 0.4),
            3.0,
            20.0,
            360.0,
            Vec3::Y,
        ),
        cylinder(
            Vec3::new(0.01, 0.0, 0.02),
            Vec3::new(0.0, 0.0, 1.0),
            1e-3,
            2e-3,
            360.0,
            Vec3::X,
        ),
    ]
}

#[test]
fn spawned_rays_do_not_reenter_their_surface() {
    let mut rng = Rng::new(99);
    for c in spawn_test_cylinders() {
        let scene = scene_of(vec![], vec![c]);
        for h in inside_hits(&scene, &c, &mut rng, 5000) {
            let inward = h.geometric_normal;
            for _ in 0..4 {
                let d = random_unit(&mut rng);
                let ray = h.spawn_ray(d);
                let next = scene.intersect(&ray);
                let cos = d.dot(inward);
                if cos < 0.0 {
                    // Out through the wall: a convex surface is never met again from outside.
                    assert!(next.is_none(), "{c:?} {h:?} {d}: re-hit {next:?}");
                } else if cos > 1e-3 {
                    // Into the interior: the only hit is across the cylinder, a chord 2R cos/|d⊥|² long.
                    let dp = d - d.dot(c.axis) * c.axis;
                    let chord = 2.0 * c.radius * cos / dp.length_squared();
                    if let Some(n) = next {
                        assert!(
                            n.t > 0.5 * chord,
                            "{c:?} {h:?} {d}: t {} for chord {chord}",
                            n.t
                        );
                        assert!(!n.front_face);
                    }
                }
            }
        }
    }
}

#[test]
fn shadow_rays_across_the_inside_are_not_blocked() {
    let mut rng = Rng::new(123);
    for c in spawn_test_cylinders() {
        let scene = scene_of(vec![], vec![c]);
        let hits = inside_hits(&scene, &c, &mut rng, 1000);
        for pair in hits.windows(2) {
            let (a, b) = (&pair[0], &pair[1]);
            // Not grazing: a chord nearly along the wall runs inside it by less than the rounding
            // of the target point, where the target's own surface may then count (for any shape).
            let d = (b.position - a.position).normalize();
            if d.dot(a.geometric_normal) < 0.05 {
                continue;
            }
            // The chord between two points of a convex surface runs inside it.
            assert!(scene.visible(a, b.position), "{c:?}: {a:?} -> {b:?}");
            assert!(scene.visible(b, a.position), "{c:?}: {b:?} -> {a:?}");
        }
    }
}

#[test]
fn mirror_focuses_a_collimated_beam_at_half_the_radius() {
    // Rays travelling +x inside an upright mirror ring of radius R meet the wall near x = R and,
    // reflected, cross the plane z = 0 at the paraxial focus x = R − R/2.
    let radius = 1.5;
    let c = cylinder(Vec3::ZERO, Vec3::Y, radius, 1.0, 180.0, Vec3::X);
    let scene = scene_of(vec![], vec![c]);
    for offset in [-0.03f32, -0.02, -0.01, 0.005, 0.01, 0.02, 0.03] {
        let ray = Ray::infinite(Vec3::new(-0.5, 0.5, offset), Vec3::X);
        let h = scene.intersect(&ray).unwrap();
        assert!(!h.front_face);
        // The reported curvature focuses where the traced rays do: f = 1/(2κ) = R/2.
        assert!(
            (0.5 / h.curvature - radius / 2.0).abs() < 1e-5,
            "{}",
            h.curvature
        );
        let n = h.shading_normal;
        let reflected = ray.direction - 2.0 * ray.direction.dot(n) * n;
        let s = -h.position.z / reflected.z;
        let crossing = h.position + s * reflected;
        assert!((crossing.y - 0.5).abs() < 1e-5);
        // Spherical aberration moves the crossing by about R·(z/R)²/4 toward the wall.
        let expected = radius - radius / 2.0;
        let tolerance = 0.3 * offset * offset / radius + 1e-5;
        assert!(
            (crossing.x - expected).abs() < tolerance,
            "offset {offset}: crossing at x = {}, expected {expected}",
            crossing.x
        );
    }
}

fn with_cylinder(material: Material, c: Cylinder) -> Result<Scene, SceneError> {
    let mut d = description(vec![], vec![], vec![point_light(Vec3::Y)]);
    d.materials = vec![material];
    d.cylinders = vec![c];
    Scene::new(d)
}

#[test]
fn scene_rejects_bad_cylinders() {
    let good = upright(360.0, Vec3::Z);
    assert!(with_cylinder(diffuse(0.5, Vec3::ZERO), good).is_ok());
    let lamp = diffuse(0.5, Vec3::ONE);
    let err = with_cylinder(lamp, good).unwrap_err();
    assert!(matches!(err, SceneError::Invalid { .. }), "{err:?}");
    assert!(err.to_string().contains("cannot"), "{err}");
    let mirror = Material {
        name: "m".into(),
        kind: MaterialKind::Mirror(crate::Mirror {
            reflectance: Vec3::ONE,
        }),
        emission: Vec3::ZERO,
        textures: None,
        spectra: None,
    };
    for bad in [
        Cylinder {
            radius: 0.0,
            ..good
        },
        Cylinder {
            height: -1.0,
            ..good
        },
        Cylinder { arc: 0.0, ..good },
        Cylinder { arc: 7.0, ..good },
        Cylinder {
            axis: Vec3::new(0.0, 2.0, 0.0),
            ..good
        },
        Cylinder {
            facing: Vec3::Y,
            ..good
        },
        Cylinder {
            center: Vec3::new(f32::NAN, 0.0, 0.0),
            ..good
        },
        Cylinder {
            radius: f32::INFINITY,
            ..good
        },
    ] {
        let err = with_cylinder(mirror.clone(), bad).unwrap_err();
        assert!(
            matches!(err, SceneError::Invalid { .. }),
            "{bad:?}: {err:?}"
        );
    }
    let err = with_cylinder(
        mirror,
        Cylinder {
            material: 3,
            ..good
        },
    )
    .unwrap_err();
    assert!(
        matches!(err, SceneError::MaterialIndex { index: 3, .. }),
        "{err:?}"
    );
}

#[test]
fn cylinder_only_scene_has_bounds_and_light_sampling() {
    let c = upright(180.0, -Vec3::Z);
    let scene = scene_of(vec![], vec![c]);
    let b = scene.bounds();
    assert!(b.min.distance(Vec3::new(-1.0, 0.0, -1.0)) < 1e-6);
    assert!(b.max.distance(Vec3::new(1.0, 2.0, 1.0)) < 1e-6);
    let h = scene
        .intersect(&Ray::infinite(Vec3::new(0.0, 1.0, -5.0), Vec3::Z))
        .unwrap();
    assert_eq!(scene.lights().pdf_direct(Vec3::ZERO, Vec3::ZERO, &h), 0.0);
    assert_eq!(scene.emitted(&h), Vec3::ZERO);
}
