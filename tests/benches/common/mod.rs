//! Shared by the BVH benchmark and the `rayset` and `prof` examples: scene loading, ray sets and
//! thread CPU time.
#![allow(
    dead_code,
    clippy::unwrap_used,
    clippy::print_stdout,
    clippy::print_stderr,
    missing_docs,
    unreachable_pub
)]

use std::path::Path;

use glam::{Vec2, Vec3};
use scene::{Film, Light, Ray, Scene, SceneDescription};

/// A scene file loaded with the crate's own loaders (emitters not required), rendered at
/// 1024×1024, with a point light above the bounding box if the file has no light at all.
pub fn load_triangles(path: &Path) -> SceneDescription {
    let options = import::LoadOptions {
        require_emitter: false,
        ..Default::default()
    };
    let mut description = import::load_with(path, &options).unwrap();
    description.film = Film {
        width: 1024,
        height: 1024,
    };
    let emissive = description
        .materials
        .iter()
        .any(|m| m.emission != Vec3::ZERO);
    if description.lights.is_empty() && !emissive {
        let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
        for t in &description.triangles {
            for p in t.positions {
                lo = lo.min(p);
                hi = hi.max(p);
            }
        }
        let radius = 0.5 * (hi - lo).length();
        description.lights.push(Light::Point {
            position: 0.5 * (lo + hi) + Vec3::Y * 2.0 * radius,
            intensity: Vec3::ONE,
        });
    }
    description
}

/// A hash-based uniform number in [0, 1) for (index, dimension).
pub fn uniform(index: u64, dim: u64) -> f32 {
    let mut x = index.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ dim.wrapping_mul(0xC2B2_AE3D_27D4_EB4F);
    x ^= x >> 33;
    x = x.wrapping_mul(0xFF51_AFD7_ED55_8CCD);
    x ^= x >> 33;
    x = x.wrapping_mul(0xC4CE_B9FE_1A85_EC53);
    x ^= x >> 33;
    (x >> 40) as f32 / (1u64 << 24) as f32
}

/// One camera ray per pixel through the pixel centre.
pub fn primary_rays(scene: &Scene) -> Vec<Ray> {
    let (w, h) = scene.camera().resolution();
    let mut rays = Vec::with_capacity((w * h) as usize);
    for y in 0..h {
        for x in 0..w {
            rays.push(
                scene
                    .camera()
                    .generate_ray(Vec2::new(x as f32 + 0.5, y as f32 + 0.5), Vec2::splat(0.5)),
            );
        }
    }
    rays
}

/// For every primary ray that hits: a cosine-distributed bounce from its hit point (the
/// realistic incoherent set of a path tracer's or photon tracer's second segment).
pub fn diffuse_bounce_rays(scene: &Scene, primary: &[Ray]) -> Vec<Ray> {
    let mut rays = Vec::new();
    for (i, ray) in primary.iter().enumerate() {
        let Some(hit) = scene.intersect(ray) else {
            continue;
        };
        let (u1, u2) = (uniform(i as u64, 0), uniform(i as u64, 1));
        let r = u1.sqrt();
        let phi = std::f32::consts::TAU * u2;
        let local = Vec3::new(r * phi.cos(), r * phi.sin(), (1.0 - u1).max(0.0).sqrt());
        let frame = scene::Frame::from_normal(hit.geometric_normal);
        rays.push(hit.spawn_ray(frame.to_world(local)));
    }
    rays
}

/// CPU time consumed so far by the calling thread, in seconds (Linux: the first field of
/// `/proc/thread-self/schedstat`, in nanoseconds); `None` elsewhere.
pub fn thread_cpu_seconds() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    Some(stat.split_whitespace().next()?.parse::<f64>().ok()? * 1e-9)
}
