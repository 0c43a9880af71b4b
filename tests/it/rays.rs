//! Ray-query robustness of the scene runtime on real data: McGuire's Cornell box (OBJ), read
//! by the importers.

use glam::{Vec2, Vec3};
use scene::{Film, Frame, Ray, Scene};

/// McGuire's Cornell box, read in place from the shared scenes beside the checkout.
fn cornell() -> Scene {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../shared/scenes/cornell_box/CornellBox-Original.obj");
    let mut description = import::load(&path).unwrap();
    description.film = Film {
        width: 64,
        height: 64,
    };
    Scene::new(description).unwrap()
}

/// A hash-based uniform number in [0, 1).
fn uniform(index: u64, dim: u64) -> f32 {
    let mut x = index.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ dim.wrapping_mul(0xC2B2_AE3D_27D4_EB4F);
    x ^= x >> 33;
    x = x.wrapping_mul(0xFF51_AFD7_ED55_8CCD);
    x ^= x >> 33;
    (x >> 40) as f32 / (1u64 << 24) as f32
}

fn cosine_direction(normal: Vec3, u: Vec2) -> Vec3 {
    let r = u.x.sqrt();
    let phi = std::f32::consts::TAU * u.y;
    Frame::from_normal(normal).to_world(Vec3::new(
        r * phi.cos(),
        r * phi.sin(),
        (1.0 - u.x).max(0.0).sqrt(),
    ))
}

#[test]
fn random_walks_leave_only_through_the_opening() {
    let scene = cornell();
    let (mut bounces, mut escaped) = (0u64, 0u64);
    for path in 0..20_000u64 {
        let u = |d: u64| uniform(path, d);
        let film = Vec2::new(64.0 * u(0), 64.0 * u(1));
        let mut ray = scene.camera().generate_ray(film, Vec2::ZERO);
        for depth in 0..16u64 {
            let Some(hit) = scene.intersect(&ray) else {
                // Only the open front (z ≈ 0.99) lets rays out once they are inside.
                if depth > 0 {
                    let exit_t = (0.99 - ray.origin.z) / ray.direction.z;
                    assert!(ray.direction.z > 0.0 && exit_t >= 0.0, "leak from {ray:?}");
                    let exit = ray.at(exit_t);
                    assert!(
                        exit.x.abs() < 1.03 && exit.y > -0.01 && exit.y < 2.0,
                        "leak through a wall: {ray:?} exits at {exit}"
                    );
                    escaped += 1;
                }
                break;
            };
            bounces += 1;
            assert!(
                hit.t > 1e-5 || depth == 0,
                "self-intersection at t = {}",
                hit.t
            );
            let dir = cosine_direction(
                hit.geometric_normal,
                Vec2::new(u(2 + 2 * depth), u(3 + 2 * depth)),
            );
            ray = hit.spawn_ray(dir);
        }
    }
    assert!(bounces > 100_000, "{bounces}");
    assert!(escaped > 1000, "{escaped}");
}

#[test]
fn corner_shadow_rays_are_not_blocked() {
    let scene = cornell();
    // Floor points near the right wall (x = 1.00) see wall points near the floor.
    for i in 0..5000u64 {
        let eps = 10f32.powf(-1.0 - 4.0 * uniform(i, 0));
        let z = -0.9 + 1.7 * uniform(i, 1);
        let floor = scene
            .intersect(&Ray::infinite(Vec3::new(1.0 - eps, 0.5, z), -Vec3::Y))
            .unwrap();
        let wall = scene
            .intersect(&Ray::infinite(
                Vec3::new(0.95, eps * (0.5 + uniform(i, 2)), z + 0.01),
                Vec3::X,
            ))
            .unwrap();
        assert!(
            scene.visible(&floor, wall.position),
            "blocked corner (eps {eps})"
        );
        assert!(
            scene.visible(&wall, floor.position),
            "blocked corner (eps {eps})"
        );
        // Just below the floor is never visible.
        assert!(!scene.visible(&wall, Vec3::new(0.9, -1e-3, z)));
    }
}
