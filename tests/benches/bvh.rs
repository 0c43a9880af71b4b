//! BVH build time and closest-hit throughput (rays/s) on 1 and 2 threads.
//!
//! Throughput is given per second of wall time and per CPU-second (the CPU time of the pool's
//! threads, from `/proc`): on a shared machine the latter stays close to the idle per-core rate when the
//! former does not. On an idle machine the two agree for one thread.
//!
//! `cargo bench -p tests --bench bvh` (scenes from `../shared/scenes` beside the checkout, or the paths given as arguments).
#![allow(clippy::unwrap_used, clippy::print_stdout, missing_docs)]

mod common;

use std::{path::PathBuf, time::Instant};

use rayon::prelude::*;
use scene::{Ray, Scene};

/// CPU time consumed so far by the threads of `pool`, in seconds.
fn pool_cpu_seconds(pool: &rayon::ThreadPool) -> Option<f64> {
    pool.broadcast(|_| common::thread_cpu_seconds())
        .into_iter()
        .sum()
}

/// Best-of-3 throughput in Mrays/s of wall time and in Mrays per CPU-second (the per-core rate,
/// which other work on a shared machine disturbs far less), and the number of hits.
fn throughput(scene: &Scene, rays: &[Ray], threads: usize, shadow: bool) -> (f64, f64, usize) {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    let (mut best, mut best_cpu) = (f64::INFINITY, f64::INFINITY);
    let mut hits = 0;
    for _ in 0..3 {
        let cpu = pool_cpu_seconds(&pool);
        let start = Instant::now();
        hits = pool.install(|| {
            rays.par_chunks(4096)
                .map(|chunk| {
                    if shadow {
                        chunk.iter().filter(|r| scene.occluded(r)).count()
                    } else {
                        chunk
                            .iter()
                            .filter(|r| scene.intersect(r).is_some())
                            .count()
                    }
                })
                .sum()
        });
        best = best.min(start.elapsed().as_secs_f64());
        if let (Some(before), Some(after)) = (cpu, pool_cpu_seconds(&pool)) {
            best_cpu = best_cpu.min(after - before);
        }
    }
    let n = rays.len() as f64 / 1e6;
    (n / best, n / best_cpu, hits)
}

fn main() {
    let args: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with('-'))
        .collect();
    let paths: Vec<PathBuf> = if args.is_empty() {
        vec![
            concat!(env!("CARGO_MANIFEST_DIR"), "/../../shared/scenes/stanford_bunny/stanford-bunny.obj").into(),
            concat!(env!("CARGO_MANIFEST_DIR"), "/../../shared/scenes/gltf/MetalRoughSpheresNoTextures/glTF/MetalRoughSpheresNoTextures.gltf").into(),
        ]
    } else {
        args.into_iter().map(PathBuf::from).collect()
    };
    for path in paths {
        if !path.exists() {
            println!("skipping missing {}", path.display());
            continue;
        }
        let description = common::load_triangles(&path);
        let n_tris = description.triangles.len();
        let mut build = f64::INFINITY;
        let mut scene = None;
        for _ in 0..3 {
            let d = description.clone();
            let start = Instant::now();
            let s = Scene::new(d).unwrap();
            build = build.min(start.elapsed().as_secs_f64());
            scene = Some(s);
        }
        let scene = scene.unwrap();
        println!(
            "{}: {n_tris} triangles, Scene::new (BVH build + lights) {:.3} s",
            path.file_name().unwrap().to_string_lossy(),
            build
        );
        let primary = common::primary_rays(&scene);
        let bounce = common::diffuse_bounce_rays(&scene, &primary);
        for (name, rays, shadow) in [
            ("primary closest-hit", &primary, false),
            ("diffuse-bounce closest-hit", &bounce, false),
            ("diffuse-bounce occluded", &bounce, true),
        ] {
            for threads in [1, 2] {
                let (mrays, per_cpu, hits) = throughput(&scene, rays, threads, shadow);
                println!(
                    "  {name:28} {threads} thread(s): {mrays:6.2} Mrays/s, {per_cpu:6.2} Mrays/CPU-s ({} rays, {:.1} % hit)",
                    rays.len(),
                    100.0 * hits as f64 / rays.len() as f64
                );
            }
        }
    }
}
