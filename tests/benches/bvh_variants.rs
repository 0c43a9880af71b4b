//! Compares obvhs' own layouts and build presets (triangles only, RtTriangle) with ours
//! (`Scene::intersect` / `Scene::occluded`, i.e. `src/bvh/`) on the same ray sets, single-threaded:
//! the measurements behind the choice made in `src/bvh/mod.rs`.
//! `cargo bench -p tests --bench bvh_variants`.
#![allow(clippy::unwrap_used, clippy::print_stdout, missing_docs)]

mod common;

use std::{
    path::Path,
    time::{Duration, Instant},
};

use glam::Vec3A;
use obvhs::{
    BvhBuildParams,
    bvh2::builder::build_bvh2_from_tris,
    cwbvh::builder::build_cwbvh_from_tris,
    ray::{Ray as BRay, RayHit},
    rt_triangle::RtTriangle,
    triangle::Triangle,
};
use scene::{Ray, Scene};

fn time<F: Fn(&BRay) -> bool>(rays: &[BRay], f: F) -> f64 {
    let mut best = f64::INFINITY;
    for _ in 0..3 {
        let start = Instant::now();
        let n = rays.iter().filter(|r| f(r)).count();
        std::hint::black_box(n);
        best = best.min(start.elapsed().as_secs_f64());
    }
    rays.len() as f64 / best / 1e6
}

fn main() {
    let path = Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../shared/scenes/stanford_bunny/stanford-bunny.obj"
    ));
    let desc = common::load_triangles(path);
    let tris: Vec<Triangle> = desc
        .triangles
        .iter()
        .map(|t| Triangle {
            v0: t.positions[0].into(),
            v1: t.positions[1].into(),
            v2: t.positions[2].into(),
        })
        .collect();
    let scene = Scene::new(desc).unwrap();
    let primary = common::primary_rays(&scene);
    let bounce = common::diffuse_bounce_rays(&scene, &primary);
    let conv = |rays: &[Ray]| -> Vec<BRay> {
        rays.iter()
            .map(|r| BRay::new_inf(r.origin.into(), Vec3A::from(r.direction) + Vec3A::ZERO))
            .collect()
    };
    let ours = |rays: &[Ray], shadow: bool| {
        let mut best = f64::INFINITY;
        for _ in 0..3 {
            let start = Instant::now();
            let n = if shadow {
                rays.iter().filter(|r| scene.occluded(r)).count()
            } else {
                rays.iter().filter(|r| scene.intersect(r).is_some()).count()
            };
            std::hint::black_box(n);
            best = best.min(start.elapsed().as_secs_f64());
        }
        rays.len() as f64 / best / 1e6
    };
    for (set, rays) in [("primary", &primary), ("bounce", &bounce)] {
        println!(
            "bunny ours (Scene): {set:7} closest {:5.2} Mrays/s; occluded {:5.2}",
            ours(rays, false),
            ours(rays, true)
        );
    }
    let (primary, bounce) = (conv(&primary), conv(&bounce));
    for (name, params) in [
        ("fast", BvhBuildParams::fast_build()),
        ("medium", BvhBuildParams::medium_build()),
        ("slow", BvhBuildParams::slow_build()),
    ] {
        let mut d = Duration::ZERO;
        let start = Instant::now();
        let cw = build_cwbvh_from_tris(&tris, params, &mut d);
        let cw_build = start.elapsed().as_secs_f64();
        let cw_tris: Vec<RtTriangle> = cw
            .primitive_indices
            .iter()
            .map(|&i| RtTriangle::from(&tris[i as usize]))
            .collect();
        let start = Instant::now();
        let b2 = build_bvh2_from_tris(&tris, params, &mut d);
        let b2_build = start.elapsed().as_secs_f64();
        let b2_tris: Vec<RtTriangle> = b2
            .primitive_indices
            .iter()
            .map(|&i| RtTriangle::from(&tris[i as usize]))
            .collect();
        for (set, rays) in [("primary", &primary), ("bounce", &bounce)] {
            let cw_rate = time(rays, |r| {
                let mut h = RayHit::none();
                cw.ray_traverse(*r, &mut h, |r, id| cw_tris[id].intersect(r))
            });
            let b2_rate = time(rays, |r| {
                let mut h = RayHit::none();
                b2.ray_traverse(*r, &mut h, |r, id| b2_tris[id].intersect(r))
            });
            let cw_shadow = time(rays, |r| {
                !cw.ray_traverse_miss(*r, |r, id| cw_tris[id].intersect(r))
            });
            println!(
                "bunny {name:6} build cw {cw_build:.3} s / bvh2 {b2_build:.3} s; {set:7} closest cw {cw_rate:5.2} bvh2 {b2_rate:5.2} Mrays/s; occluded cw {cw_shadow:5.2}"
            );
        }
    }
    // Build times alone on the 1M-triangle scene.
    let path = Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../shared/scenes/gltf/MetalRoughSpheresNoTextures/glTF/MetalRoughSpheresNoTextures.gltf"
    ));
    if !path.exists() {
        return;
    }
    let big: Vec<Triangle> = common::load_triangles(path)
        .triangles
        .iter()
        .map(|t| Triangle {
            v0: t.positions[0].into(),
            v1: t.positions[1].into(),
            v2: t.positions[2].into(),
        })
        .collect();
    for (name, params) in [
        ("fastest", BvhBuildParams::fastest_build()),
        ("fast", BvhBuildParams::fast_build()),
        ("medium", BvhBuildParams::medium_build()),
    ] {
        let mut d = Duration::ZERO;
        let start = Instant::now();
        let cw = build_cwbvh_from_tris(&big, params, &mut d);
        println!(
            "{} triangles, {name:7} CwBvh build {:.3} s (core {:.3} s, {} nodes)",
            big.len(),
            start.elapsed().as_secs_f64(),
            d.as_secs_f64(),
            cw.nodes.len()
        );
    }
    drop(scene);
}
