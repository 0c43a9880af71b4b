//! Hash-grid build time and gather throughput on a surface-like distribution.
//!
//! Setup (the obvhs `Bvh2` comparison of `crates.md`): 2²⁰ hitpoints uniform on the unit sphere
//! with radius 0.004 (±50 % jitter for some cases) and 2²⁰ photon query points on the same
//! sphere, ~4 hitpoints found per photon. Queries run (a) in random order and (b) Morton-sorted,
//! on 1 and 2 threads.
//!
//! Run: `cargo bench -p photon --bench gather`. Divan reports items/s = queries per second.
//! The table printed first is measured in thread CPU time, so it holds on a shared machine.
//! The figures it has given are in docs/performance.md.
#![allow(clippy::unwrap_used, clippy::print_stdout, missing_docs)]

use std::sync::LazyLock;

use divan::{Bencher, black_box, counter::ItemsCount};
use glam::Vec3;
use photon::{CellSize, GridParams, HitPointGrid, Photon, gather, morton_order};
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg32;
use rayon::prelude::*;

const N_HITPOINTS: usize = 1 << 20;
const N_PHOTONS: usize = 1 << 20;
const RADIUS: f64 = 0.004;

fn main() {
    cpu_time_table();
    divan::main();
}

/// CPU time of the calling thread in seconds (`/proc/thread-self/schedstat`), so the figures hold
/// on a machine shared with other jobs; 0 where unavailable.
fn thread_cpu_seconds() -> f64 {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()
        .and_then(|s| s.split_whitespace().next()?.parse::<f64>().ok())
        .map_or(0.0, |ns| ns * 1e-9)
}

/// Single-thread build and gather rates measured in thread CPU time: robust to other load.
fn cpu_time_table() {
    let data = &*DATA;
    println!("single thread, CPU time (median of 3); hitpoints in Morton order unless noted");
    println!(
        "config   | grid B/hp | entries/hp | build s | build s (random hp order) | gather M/s sorted | random"
    );
    let median = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let one = pool(1);
    for &(name, _) in &CONFIGS {
        let (grid, build, build_random) = one.install(|| {
            let mut times = Vec::new();
            let mut times_random = Vec::new();
            let mut grid = None;
            for _ in 0..3 {
                let t = thread_cpu_seconds();
                grid = Some(HitPointGrid::build(
                    &data.positions,
                    &data.radii,
                    params(name),
                ));
                times.push(thread_cpu_seconds() - t);
                let t = thread_cpu_seconds();
                black_box(HitPointGrid::build(
                    &data.positions_random,
                    &data.radii,
                    params(name),
                ));
                times_random.push(thread_cpu_seconds() - t);
            }
            (grid.unwrap(), median(times), median(times_random))
        });
        let rate = |photons: &[Vec3]| {
            let t = thread_cpu_seconds();
            let found: usize = photons.iter().map(|&p| count(&grid, p)).sum();
            black_box(found);
            photons.len() as f64 / (thread_cpu_seconds() - t) * 1e-6
        };
        let sorted = median((0..3).map(|_| rate(&data.photons_sorted)).collect());
        let random = median((0..3).map(|_| rate(&data.photons)).collect());
        let stats = grid.stats();
        println!(
            "{name:8} | {:9.1} | {:10.2} | {build:7.3} | {build_random:25.3} | {sorted:17.2} | {random:6.2}",
            stats.bytes as f64 / N_HITPOINTS as f64,
            stats.n_entries as f64 / N_HITPOINTS as f64,
        );
    }
    let found: usize = data.photons.iter().map(|&p| count(&GRIDS[0], p)).sum();
    println!(
        "{:.2} hitpoints found per photon",
        found as f64 / N_PHOTONS as f64
    );
    // Radii 0.5–1.5 × 0.004, and a dark/bright spread: 90 % shrunk to 0.002, 10 % at 0.008.
    let spread: Vec<f64> = (0..N_HITPOINTS)
        .map(|i| if i % 10 == 0 { 0.008 } else { 0.002 })
        .collect();
    for (label, radii) in [("jittered", &data.jittered_radii), ("spread", &spread)] {
        let (grid, build) = one.install(|| {
            let t = thread_cpu_seconds();
            let grid = HitPointGrid::build(&data.positions, radii, GridParams::DEFAULT);
            (grid, thread_cpu_seconds() - t)
        });
        let t = thread_cpu_seconds();
        let found: usize = data.photons_sorted.iter().map(|&p| count(&grid, p)).sum();
        let sorted = N_PHOTONS as f64 / (thread_cpu_seconds() - t) * 1e-6;
        let t = thread_cpu_seconds();
        black_box(data.photons.iter().map(|&p| count(&grid, p)).sum::<usize>());
        let random = N_PHOTONS as f64 / (thread_cpu_seconds() - t) * 1e-6;
        println!(
            "default grid, {label} radii: {:?}; build {build:.3} s, gather {sorted:.2} M/s sorted, {random:.2} M/s random, {:.2} found/photon",
            grid.stats(),
            found as f64 / N_PHOTONS as f64
        );
    }
}

struct Data {
    /// Hitpoints in Morton order, a stand-in for the spatial coherence of pixel order.
    positions: Vec<Vec3>,
    /// The same hitpoints in random order.
    positions_random: Vec<Vec3>,
    radii: Vec<f64>,
    jittered_radii: Vec<f64>,
    photons: Vec<Vec3>,
    photons_sorted: Vec<Vec3>,
}

fn on_sphere(rng: &mut Pcg32) -> Vec3 {
    let z: f32 = rng.random_range(-1.0..1.0);
    let phi: f32 = rng.random_range(0.0..std::f32::consts::TAU);
    let s = (1.0 - z * z).max(0.0).sqrt();
    Vec3::new(s * phi.cos(), s * phi.sin(), z)
}

static DATA: LazyLock<Data> = LazyLock::new(|| {
    let mut rng = Pcg32::seed_from_u64(1);
    let positions_random: Vec<Vec3> = (0..N_HITPOINTS).map(|_| on_sphere(&mut rng)).collect();
    let positions = morton_order(&positions_random)
        .iter()
        .map(|&i| positions_random[i as usize])
        .collect();
    let radii = vec![RADIUS; N_HITPOINTS];
    let jittered_radii = (0..N_HITPOINTS)
        .map(|_| RADIUS * rng.random_range(0.5..1.5))
        .collect();
    let photons: Vec<Vec3> = (0..N_PHOTONS).map(|_| on_sphere(&mut rng)).collect();
    let photons_sorted = morton_order(&photons)
        .iter()
        .map(|&i| photons[i as usize])
        .collect();
    Data {
        positions,
        positions_random,
        radii,
        jittered_radii,
        photons,
        photons_sorted,
    }
});

const CONFIGS: [(&str, CellSize); 5] = [
    ("mean x4", CellSize::MeanRadius(4.0)),
    ("mean x3", CellSize::MeanRadius(3.0)),
    ("mean x2", CellSize::MeanRadius(2.0)),
    ("mean x6", CellSize::MeanRadius(6.0)),
    ("max x2", CellSize::MaxRadius(2.0)),
];

fn params(name: &str) -> GridParams {
    let cell_size = CONFIGS.iter().find(|c| c.0 == name).unwrap().1;
    GridParams {
        cell_size,
        rebuild_below: 0.8,
    }
}

static GRIDS: LazyLock<Vec<HitPointGrid>> = LazyLock::new(|| {
    CONFIGS
        .iter()
        .map(|&(name, _)| HitPointGrid::build(&DATA.positions, &DATA.radii, params(name)))
        .collect()
});

fn grid(name: &str) -> &'static HitPointGrid {
    &GRIDS[CONFIGS.iter().position(|c| c.0 == name).unwrap()]
}

fn count(grid: &HitPointGrid, p: Vec3) -> usize {
    let mut n = 0;
    grid.for_each_containing(p, |_| n += 1);
    n
}

fn pool(threads: usize) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
}

#[divan::bench(args = ["mean x4", "mean x2", "max x2"], sample_count = 5)]
fn build(bencher: Bencher, name: &str) {
    let data = &*DATA;
    bencher
        .counter(ItemsCount::new(N_HITPOINTS))
        .bench(|| HitPointGrid::build(&data.positions, &data.radii, params(name)));
}

#[divan::bench(args = ["mean x4", "max x2"], sample_count = 5)]
fn build_jittered(bencher: Bencher, name: &str) {
    let data = &*DATA;
    bencher
        .counter(ItemsCount::new(N_HITPOINTS))
        .bench(|| HitPointGrid::build(&data.positions, &data.jittered_radii, params(name)));
}

fn queries(bencher: Bencher, name: &str, sorted: bool, threads: usize) {
    let data = &*DATA;
    let grid = grid(name);
    let photons = if sorted {
        &data.photons_sorted
    } else {
        &data.photons
    };
    let pool = pool(threads);
    bencher.counter(ItemsCount::new(N_PHOTONS)).bench(|| {
        pool.install(|| {
            photons
                .par_chunks(4096)
                .map(|chunk| chunk.iter().map(|&p| count(grid, p)).sum::<usize>())
                .sum::<usize>()
        })
    });
    black_box(());
}

#[divan::bench(args = ["mean x4", "max x2"], sample_count = 5)]
fn gather_sorted_1_thread(bencher: Bencher, name: &str) {
    queries(bencher, name, true, 1);
}

#[divan::bench(args = ["mean x4", "max x2"], sample_count = 5)]
fn gather_random_1_thread(bencher: Bencher, name: &str) {
    queries(bencher, name, false, 1);
}

#[divan::bench(args = ["mean x4", "max x2"], sample_count = 5)]
fn gather_sorted_2_threads(bencher: Bencher, name: &str) {
    queries(bencher, name, true, 2);
}

#[divan::bench(args = ["mean x4", "max x2"], sample_count = 5)]
fn gather_random_2_threads(bencher: Bencher, name: &str) {
    queries(bencher, name, false, 2);
}

#[divan::bench(sample_count = 5)]
fn morton_sort_photons(bencher: Bencher) {
    let data = &*DATA;
    bencher
        .counter(ItemsCount::new(N_PHOTONS))
        .bench(|| morton_order(&data.photons));
}

/// The full deterministic pass: `photon::gather` with an (n, Φ) accumulator, sorted photons.
#[divan::bench(args = [1, 2], sample_count = 5)]
fn gather_pass_sorted(bencher: Bencher, threads: usize) {
    let data = &*DATA;
    let grid = grid("mean x4");
    let photons: Vec<Photon> = data
        .photons_sorted
        .iter()
        .map(|&position| Photon {
            position,
            incoming: position,
            power: Vec3::ONE,
            normal: position,
            bounces: 0,
            tag: 0,
        })
        .collect();
    let pool = pool(threads);
    bencher.counter(ItemsCount::new(N_PHOTONS)).bench(|| {
        pool.install(|| {
            gather(
                grid,
                &photons,
                N_HITPOINTS,
                |photon, _| Some(photon.power),
                |acc: &mut (u32, [f64; 3]), power| {
                    acc.0 += 1;
                    acc.1[0] += f64::from(power.x);
                    acc.1[1] += f64::from(power.y);
                    acc.1[2] += f64::from(power.z);
                },
            )
        })
    });
}
