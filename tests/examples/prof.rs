//! Runs one kind of ray query many times on one scene, for profilers (callgrind, perf):
//!
//! ```text
//! cargo build --release -p tests --example prof
//! valgrind --tool=callgrind target/release/examples/prof <scene> <primary|bounce> <closest|occluded> [repeats]
//! ```
//!
//! Scene loading and ray generation happen before the first query; the queries run in
//! `run_queries`, which is never inlined, so its inclusive cost is the cost of the queries.
#![allow(
    clippy::unwrap_used,
    clippy::print_stdout,
    clippy::print_stderr,
    missing_docs
)]

#[path = "../benches/common/mod.rs"]
mod common;

use std::{path::Path, time::Instant};

use scene::{Ray, Scene};

#[inline(never)]
fn run_queries(scene: &Scene, rays: &[Ray], occluded: bool) -> usize {
    if occluded {
        rays.iter().filter(|r| scene.occluded(r)).count()
    } else {
        rays.iter().filter(|r| scene.intersect(r).is_some()).count()
    }
}

/// A hash of every query's answer (primitive, t, barycentrics or occlusion), to check that a
/// change of the BVH leaves every hit unchanged.
fn checksum(scene: &Scene, rays: &[Ray], occluded: bool) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    let mut mix = |x: u64| h = (h ^ x).wrapping_mul(0x0000_0100_0000_01b3);
    for r in rays {
        if occluded {
            mix(u64::from(scene.occluded(r)));
        } else if let Some(hit) = scene.intersect(r) {
            mix(format!("{:?}", hit.primitive).len() as u64);
            mix(match hit.primitive {
                scene::Primitive::Triangle(i)
                | scene::Primitive::Sphere(i)
                | scene::Primitive::Cylinder(i) => u64::from(i),
            });
            mix(u64::from(hit.t.to_bits()));
            mix(u64::from(hit.uv.x.to_bits()) << 32 | u64::from(hit.uv.y.to_bits()));
        } else {
            mix(u64::MAX);
        }
    }
    h
}

/// CPU time consumed so far by the calling thread, in seconds (Linux); 0 elsewhere.
fn thread_cpu_seconds() -> f64 {
    common::thread_cpu_seconds().unwrap_or(0.0)
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [scene, kind, query, rest @ ..] = args.as_slice() else {
        eprintln!("usage: prof <scene> <primary|bounce> <closest|occluded> [repeats]");
        return;
    };
    let repeats: usize = rest.first().map_or(1, |r| r.parse().unwrap());
    let start = Instant::now();
    let scene = Scene::new(common::load_triangles(Path::new(scene))).unwrap();
    let build = start.elapsed().as_secs_f64();
    let primary = common::primary_rays(&scene);
    let rays = match kind.as_str() {
        "primary" => primary,
        "bounce" => common::diffuse_bounce_rays(&scene, &primary),
        other => panic!("unknown ray kind {other}"),
    };
    let occluded = match query.as_str() {
        "closest" => false,
        "occluded" => true,
        other => panic!("unknown query {other}"),
    };
    let (mut best, mut best_cpu) = (f64::INFINITY, f64::INFINITY);
    let mut hits = 0;
    for _ in 0..repeats {
        let (start, cpu) = (Instant::now(), thread_cpu_seconds());
        hits = std::hint::black_box(run_queries(&scene, &rays, occluded));
        best = best.min(start.elapsed().as_secs_f64());
        best_cpu = best_cpu.min(thread_cpu_seconds() - cpu);
    }
    println!(
        "build {build:.3} s; {} rays, {hits} hits; best {:.2} Mrays/s, {:.2} Mrays/CPU-s; checksum {:016x}",
        rays.len(),
        rays.len() as f64 / best / 1e6,
        rays.len() as f64 / best_cpu / 1e6,
        checksum(&scene, &rays, occluded)
    );
}
