//! The wide BVH against a linear scan over the very same primitive tests: since box culling must
//! be conservative, closest hits must agree exactly (same t, bit for bit) and so must occlusion.
//! Scene-level tests (`scene/tests.rs`) compare with an independent f64 solver.

use glam::Vec3;

use super::{Accel, Leaf, RawHit, SPHERE_BIT};
use crate::test_util::{Rng, closed_box, quad, tri};
use crate::{Cylinder, Ray, Sphere, Triangle};

/// Closest t and the primitive id over all leaves, and whether any is hit, by brute force (every
/// leaf treated as mixed, so that a wrong mixed flag would show too).
fn linear_scan(accel: &Accel, ray: &Ray) -> (Option<(f32, u32)>, bool) {
    let Some((rays, _, tmax)) = accel.internal_ray(ray) else {
        return (None, false);
    };
    let (mut t, mut closest, mut any) = (tmax, None, false);
    let mut uv = (super::F8::splat(0.0), super::F8::splat(0.0));
    for index in 0..accel.packs.len() {
        let leaf = Leaf { index, mixed: true };
        any |= accel.leaf_any(&rays, leaf, tmax);
        accel.leaf_closest(&rays, leaf, &mut t, &mut closest, &mut uv);
    }
    (closest.map(|slot| (t / accel.scale, accel.ids[slot])), any)
}

fn raw_t(hit: RawHit) -> f32 {
    match hit {
        RawHit::Triangle { t, .. } | RawHit::Sphere { t, .. } | RawHit::Cylinder { t, .. } => t,
    }
}

/// Checks every ray: same closest t as the linear scan (ties between primitives may pick either),
/// same occlusion, and barycentrics of triangle hits that pass the inside test (b1, b2 and
/// 1 − b1 − b2 at least 0, exactly: they are the numbers the leaf test accepted). Returns the
/// number of hits.
fn check(accel: &Accel, rays: &[Ray]) -> usize {
    let mut hits = 0;
    for ray in rays {
        let (want, want_any) = linear_scan(accel, ray);
        let got = accel.intersect(ray);
        assert_eq!(got.map(raw_t), want.map(|w| w.0), "{ray:?}: {got:?}");
        if let Some(RawHit::Triangle { b1, b2, .. }) = got {
            assert!(
                b1 >= 0.0 && b2 >= 0.0 && 1.0 - b1 - b2 >= 0.0,
                "{ray:?}: {got:?}"
            );
        }
        assert_eq!(accel.occluded(ray), want_any, "{ray:?}");
        hits += usize::from(got.is_some());
    }
    hits
}

/// A direction with some components forced to ±0 or to ±1 (axis-parallel), by the case `i`.
fn direction(rng: &mut Rng, i: usize) -> Vec3 {
    let mut d = rng.unit();
    let sign = |rng: &mut Rng| if rng.f32() < 0.5 { -1.0 } else { 1.0 };
    match i % 6 {
        0 => {
            // Axis-parallel, the other components ±0.
            let axis = i / 6 % 3;
            d = Vec3::new(
                if rng.f32() < 0.5 { -0.0 } else { 0.0 },
                if rng.f32() < 0.5 { -0.0 } else { 0.0 },
                if rng.f32() < 0.5 { -0.0 } else { 0.0 },
            );
            d[axis] = sign(rng);
        }
        1 => d[i / 6 % 3] = -0.0,
        2 => d[i / 6 % 3] = 0.0,
        _ => {}
    }
    d.normalize()
}

/// Rays from random points, from points on the primitives' surfaces (triangle vertices, edges
/// and interiors, exactly), and from points on the planes of triangles moving within them.
fn rays(rng: &mut Rng, tris: &[Triangle], lo: Vec3, hi: Vec3, n: usize) -> Vec<Ray> {
    let mut rays = Vec::with_capacity(n);
    for i in 0..n {
        let t = &tris[rng.next_u32() as usize % tris.len()].positions;
        let origin = match i % 5 {
            0 | 1 => lo + (hi - lo) * rng.vec3(-0.2, 1.2),
            2 => t[i % 3],
            3 => 0.5 * (t[i % 3] + t[(i + 1) % 3]),
            _ => {
                let (u, v) = (rng.f32(), rng.f32());
                let (u, v) = if u + v > 1.0 {
                    (1.0 - u, 1.0 - v)
                } else {
                    (u, v)
                };
                t[0] + u * (t[1] - t[0]) + v * (t[2] - t[0])
            }
        };
        let mut direction = direction(rng, i);
        if i % 7 == 3 {
            // Within the triangle's plane, where its box is flat: slab distances are 0 · ∞.
            let n = (t[1] - t[0]).cross(t[2] - t[0]);
            let in_plane = direction - direction.dot(n) / n.length_squared() * n;
            if in_plane.length() > 1e-3 {
                direction = in_plane.normalize();
            }
        }
        let t_max = if i % 4 == 0 {
            (hi - lo).length() * rng.f32()
        } else {
            f32::INFINITY
        };
        rays.push(Ray {
            origin,
            direction,
            t_max,
        });
    }
    rays
}

/// Random triangles, spheres and cylinders in the cube [-5, 5]³ times `scale`.
fn soup(rng: &mut Rng, scale: f32) -> (Vec<Triangle>, Vec<Sphere>, Vec<Cylinder>) {
    let tris = (0..600)
        .map(|_| {
            let c = rng.vec3(-5.0, 5.0);
            let p = [0, 1, 2].map(|_| (c + rng.vec3(-1.0, 1.0)) * scale);
            tri(p[0], p[1], p[2], 0)
        })
        .collect();
    let spheres = (0..20)
        .map(|_| Sphere {
            center: rng.vec3(-5.0, 5.0) * scale,
            radius: (0.1 + 0.5 * rng.f32()) * scale,
            material: 0,
        })
        .collect();
    let cylinders = (0..10)
        .map(|i| {
            let axis = if i % 2 == 0 { Vec3::Y } else { rng.unit() };
            let facing = axis.any_orthonormal_vector();
            Cylinder {
                center: rng.vec3(-5.0, 5.0) * scale,
                axis,
                radius: (0.2 + 0.5 * rng.f32()) * scale,
                height: (0.5 + rng.f32()) * scale,
                arc: if i % 3 == 0 {
                    3.0
                } else {
                    std::f32::consts::TAU
                },
                facing,
                material: 0,
            }
        })
        .collect();
    (tris, spheres, cylinders)
}

#[test]
fn random_soups_at_all_scales() {
    let mut rng = Rng::new(11);
    for scale in [1e-30, 1e-6, 1.0, 1e6, 1e30] {
        let (tris, spheres, cylinders) = soup(&mut rng, scale);
        let accel = Accel::build(&tris, &spheres, &cylinders);
        assert_eq!(accel.len(), 630);
        let lo = Vec3::splat(-6.0 * scale);
        let rays = rays(&mut rng, &tris, lo, -lo, 20_000);
        let hits = check(&accel, &rays);
        assert!(hits > 5_000, "scale {scale}: {hits} hits");
    }
}

/// Axis-aligned walls: many boxes flat along one axis and sharing faces, met by axis-parallel rays
/// that start on the walls, on their edges, and on their corners.
#[test]
fn axis_aligned_walls_and_grids() {
    let mut rng = Rng::new(12);
    let mut tris = closed_box(Vec3::splat(-1.0), Vec3::ONE, 0);
    for x in -4..4 {
        for z in -4..4 {
            let corner = Vec3::new(x as f32 * 0.25, -0.5, z as f32 * 0.25);
            tris.extend(quad(corner, Vec3::X * 0.25, Vec3::Z * 0.25, 0));
        }
    }
    let accel = Accel::build(&tris, &[], &[]);
    let mut all = rays(&mut rng, &tris, Vec3::splat(-1.0), Vec3::ONE, 20_000);
    // Rays along grid lines and wall planes, from lattice points.
    for i in 0..4000 {
        let lattice = |rng: &mut Rng| (rng.next_u32() % 9) as f32 * 0.25 - 1.0;
        let origin = Vec3::new(lattice(&mut rng), lattice(&mut rng), lattice(&mut rng));
        all.push(Ray {
            origin,
            direction: direction(&mut rng, 6 * (i / 6)),
            t_max: f32::INFINITY,
        });
    }
    let hits = check(&accel, &all);
    assert!(hits > 10_000, "{hits}");
}

/// One primitive, and a few: the BVH root may itself be a leaf.
#[test]
fn tiny_scenes() {
    let mut rng = Rng::new(13);
    for n in 1..6 {
        let tris: Vec<Triangle> = (0..n)
            .map(|_| {
                tri(
                    rng.vec3(-1.0, 1.0),
                    rng.vec3(-1.0, 1.0),
                    rng.vec3(-1.0, 1.0),
                    0,
                )
            })
            .collect();
        let spheres = [Sphere {
            center: Vec3::ZERO,
            radius: 0.3,
            material: 0,
        }];
        let accel = Accel::build(&tris, &spheres[..n % 2], &[]);
        let all = rays(&mut rng, &tris, Vec3::splat(-1.5), Vec3::splat(1.5), 2_000);
        check(&accel, &all);
    }
    let empty = Accel::build(&[], &[], &[]);
    assert!(
        empty
            .intersect(&Ray::infinite(Vec3::ZERO, Vec3::X))
            .is_none()
    );
}

/// A ray with a non-finite origin or direction component hits nothing (the one-SIMD-test check
/// of `Accel::internal_ray`), while ±0 components are fine.
#[test]
fn non_finite_rays_miss() {
    let tris = [tri(
        Vec3::new(-1.0, -1.0, 1.0),
        Vec3::new(1.0, -1.0, 1.0),
        Vec3::new(0.0, 1.0, 1.0),
        0,
    )];
    let accel = Accel::build(&tris, &[], &[]);
    let good = Ray::infinite(Vec3::new(-0.0, 0.0, -0.0), Vec3::Z);
    assert!(accel.intersect(&good).is_some() && accel.occluded(&good));
    for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
        for axis in 0..6 {
            let mut ray = good;
            if axis < 3 {
                ray.origin[axis] = bad;
            } else {
                ray.direction[axis - 3] = bad;
            }
            assert!(accel.intersect(&ray).is_none(), "{ray:?}");
            assert!(!accel.occluded(&ray), "{ray:?}");
        }
    }
}

/// Found by the `scene_render` fuzz target: in a scene 10⁻²⁰ across, the internal scale is
/// 2¹⁰⁰, and a camera ray from a finite origin of 10³⁰ overflowed to an infinite origin in
/// internal space, whose box tests entered the empty box of an unused child slot and followed
/// its reference (an index out of bounds in `leaf_closest`). A NaN upper bound did the same.
/// Such rays miss now.
#[test]
fn rays_that_overflow_the_internal_scale_miss() {
    let mut rng = Rng::new(7);
    let tris: Vec<Triangle> = (0..64)
        .map(|i| {
            let c = Vec3::new(rng.f32(), rng.f32(), rng.f32()) * 1e-20;
            tri(c, c + Vec3::X * 1e-21, c + Vec3::Y * 1e-21, i)
        })
        .collect();
    let accel = Accel::build(&tris, &[], &[]);
    for origin in [
        Vec3::splat(1e30),
        Vec3::new(-3e38, 0.0, 0.0),
        Vec3::new(0.0, 1e35, -1e35),
    ] {
        for d in [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Z, Vec3::ONE.normalize()] {
            let ray = Ray::infinite(origin, d);
            assert!(accel.intersect(&ray).is_none(), "{ray:?}");
            assert!(!accel.occluded(&ray), "{ray:?}");
        }
    }
    let mut ray = Ray::infinite(Vec3::splat(0.5e-20), Vec3::Z);
    ray.t_max = f32::NAN;
    assert!(accel.intersect(&ray).is_none() && !accel.occluded(&ray));
}

/// Tens of thousands of primitives, so that the tree is many levels deep.
#[test]
fn large_scene() {
    let mut rng = Rng::new(14);
    let tris: Vec<Triangle> = (0..40_000)
        .map(|_| {
            let c = rng.vec3(-20.0, 20.0);
            tri(
                c + rng.vec3(-0.3, 0.3),
                c + rng.vec3(-0.3, 0.3),
                c + rng.vec3(-0.3, 0.3),
                0,
            )
        })
        .collect();
    let spheres: Vec<Sphere> = (0..100)
        .map(|_| Sphere {
            center: rng.vec3(-20.0, 20.0),
            radius: 0.5,
            material: 0,
        })
        .collect();
    let accel = Accel::build(&tris, &spheres, &[]);
    let all = rays(
        &mut rng,
        &tris,
        Vec3::splat(-20.0),
        Vec3::splat(20.0),
        5_000,
    );
    let hits = check(&accel, &all);
    assert!(hits > 1_000, "{hits}");
    let sphere_hits = all
        .iter()
        .filter_map(|r| accel.intersect(r))
        .filter(|h| matches!(h, RawHit::Sphere { .. }))
        .count();
    assert!(sphere_hits > 0 && accel.ids.iter().any(|id| id & SPHERE_BIT != 0));
}

/// A leaf larger than a pack (obvhs makes none with our settings) becomes a node of small leaves
/// under the same box, all of which a ray through the box reaches.
#[test]
fn oversized_leaves_are_split() {
    use super::wide::{BoxRay, Leaves, MAX_LEAF_PRIMS, Wide};
    use glam::Vec3A;
    use obvhs::{aabb::Aabb, bvh2::Bvh2, bvh2::node::Bvh2Node};

    struct Visited(Vec<usize>);
    impl Leaves for Visited {
        fn closest(&mut self, leaf: Leaf, _: &mut f32) {
            self.0.push(leaf.index);
        }
        fn any(&self, _: Leaf, _: f32) -> bool {
            false
        }
    }

    let aabb = Aabb::new(Vec3A::ZERO, Vec3A::ONE);
    for count in [5, 20, 70] {
        let bvh2 = Bvh2 {
            nodes: vec![Bvh2Node::new(aabb, count, 0)],
            primitive_indices: (0..count).collect(),
            ..Default::default()
        };
        let wide = Wide::from_bvh2(&bvh2, &|_, _| false);
        let mut covered = vec![false; count as usize];
        for &(first, n) in &wide.leaves {
            assert!((1..=MAX_LEAF_PRIMS).contains(&n));
            for i in first..first + n {
                assert!(!std::mem::replace(&mut covered[i as usize], true));
            }
        }
        assert!(covered.iter().all(|&c| c), "{count}");
        let ray = BoxRay::new(Vec3A::new(0.5, 0.5, -1.0), Vec3A::Z);
        let mut visited = Visited(Vec::new());
        let mut tmax = f32::INFINITY;
        wide.closest(&ray, &mut tmax, &mut visited);
        visited.0.sort_unstable();
        assert_eq!(visited.0, (0..wide.leaves.len()).collect::<Vec<_>>());
        assert!(!wide.any(&ray, f32::INFINITY, &visited));
    }
}
