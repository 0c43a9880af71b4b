//! Writes a ray set to a file, or reads one back and times closest-hit queries on it, so that the
//! very same rays can be fed to another ray tracer (e.g. Embree).
//!
//! ```text
//! cargo run --release -p tests --example rayset -- write <scene.obj|gltf> <primary|diffuse> <out.rays>
//! cargo run --release -p tests --example rayset -- time  <scene.obj|gltf> <in.rays>
//! ```
//!
//! File format (little-endian): the 8 bytes `FPPMRAYS`, a `u32` version (1), a `u32` ray count,
//! then per ray six `f32`: origin x, y, z, unit direction x, y, z (t ranges over [0, ∞)).
#![allow(
    clippy::unwrap_used,
    clippy::print_stdout,
    clippy::print_stderr,
    missing_docs
)]

#[path = "../benches/common/mod.rs"]
mod common;

use std::{
    io::{Read, Write},
    path::Path,
    time::Instant,
};

use glam::Vec3;
use scene::{Ray, Scene};

const MAGIC: &[u8; 8] = b"FPPMRAYS";

fn write_rays(path: &Path, rays: &[Ray]) {
    let mut out = Vec::with_capacity(16 + rays.len() * 24);
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&1u32.to_le_bytes());
    out.extend_from_slice(&(rays.len() as u32).to_le_bytes());
    for r in rays {
        for v in [r.origin, r.direction] {
            for c in v.to_array() {
                out.extend_from_slice(&c.to_le_bytes());
            }
        }
    }
    std::fs::File::create(path)
        .unwrap()
        .write_all(&out)
        .unwrap();
}

fn read_rays(path: &Path) -> Vec<Ray> {
    let mut bytes = Vec::new();
    std::fs::File::open(path)
        .unwrap()
        .read_to_end(&mut bytes)
        .unwrap();
    assert_eq!(&bytes[..8], MAGIC, "not a ray file");
    let count = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    let f = |i: usize| f32::from_le_bytes(bytes[16 + 4 * i..20 + 4 * i].try_into().unwrap());
    (0..count)
        .map(|r| Ray {
            origin: Vec3::new(f(6 * r), f(6 * r + 1), f(6 * r + 2)),
            direction: Vec3::new(f(6 * r + 3), f(6 * r + 4), f(6 * r + 5)),
            t_max: f32::INFINITY,
        })
        .collect()
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match args
        .iter()
        .map(String::as_str)
        .collect::<Vec<_>>()
        .as_slice()
    {
        ["write", scene, kind, out] => {
            let scene = Scene::new(common::load_triangles(Path::new(scene))).unwrap();
            let primary = common::primary_rays(&scene);
            let rays = match *kind {
                "primary" => primary,
                "diffuse" => common::diffuse_bounce_rays(&scene, &primary),
                other => panic!("unknown ray kind {other} (primary or diffuse)"),
            };
            write_rays(Path::new(out), &rays);
            println!("wrote {} rays to {out}", rays.len());
        }
        ["time", scene, input] => {
            let scene = Scene::new(common::load_triangles(Path::new(scene))).unwrap();
            let rays = read_rays(Path::new(input));
            let mut best = f64::INFINITY;
            let mut hits = 0;
            for _ in 0..3 {
                let start = Instant::now();
                hits = rays.iter().filter(|r| scene.intersect(r).is_some()).count();
                best = best.min(start.elapsed().as_secs_f64());
            }
            println!(
                "{} rays, {hits} hits, {:.3} s, {:.2} Mrays/s (1 thread)",
                rays.len(),
                best,
                rays.len() as f64 / best / 1e6
            );
        }
        _ => eprintln!(
            "usage: rayset write <scene> <primary|diffuse> <out.rays> | rayset time <scene> <in.rays>"
        ),
    }
}
