//! BVH build time and closest-hit throughput (rays/s) on 1 and 2 threads.
//!
//! `cargo bench -p geometry` (scenes from `../shared/scenes` beside the checkout, or the paths given as arguments).
#![allow(clippy::unwrap_used, clippy::print_stdout, missing_docs)]

mod common;

use std::{path::PathBuf, time::Instant};

use geometry::{Ray, Scene};
use rayon::prelude::*;

fn throughput(scene: &Scene, rays: &[Ray], threads: usize, shadow: bool) -> (f64, usize) {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    let mut best = f64::INFINITY;
    let mut hits = 0;
    for _ in 0..3 {
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
    }
    (rays.len() as f64 / best / 1e6, hits)
}

fn main() {
    let args: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with('-'))
        .collect();
    let paths: Vec<PathBuf> = if args.is_empty() {
        vec![
            concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/scenes/stanford_bunny/stanford-bunny.obj").into(),
            concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/scenes/gltf/MetalRoughSpheresNoTextures/glTF/MetalRoughSpheresNoTextures.gltf").into(),
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
                let (mrays, hits) = throughput(&scene, rays, threads, shadow);
                println!(
                    "  {name:28} {threads} thread(s): {mrays:6.2} Mrays/s ({} rays, {:.1} % hit)",
                    rays.len(),
                    100.0 * hits as f64 / rays.len() as f64
                );
            }
        }
    }
}
