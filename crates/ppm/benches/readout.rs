//! The cost of reading the image of a photon mapper (pooling included) at 1920×1080:
//! `cargo bench -p ppm --bench readout`.
//!
//! Renders the Cornell box with spheres for a few passes (the frequency pilot included, so the
//! pooling widths are those of a running render), then times `Renderer::image()` with 1 and 2
//! threads, taking turns, and prints the median and the fastest read-out of each with pooling on
//! (the default) and off (`pool = off`, the same state), and the first read-out apart (the
//! first touch of its buffers' pages), in wall seconds and in the CPU seconds of all the
//! process's threads (rayon's idle workers spinning included). `FPPM_BENCH_READS` sets the timed
//! read-outs per configuration, `FPPM_BENCH_SIZE=WxH` the film, `FPPM_BENCH_SCENE` the scene file,
//! `FPPM_BENCH_DUMP=PATH` writes the pooled image read with 1 and 2 threads to `PATH.1` and
//! `PATH.2` (raw little-endian f32 RGB), to compare builds.

#![allow(clippy::print_stdout, clippy::unwrap_used, missing_docs)]

use std::path::Path;
use std::time::Instant;

use ppm::{PoolMode, RenderParams, Renderer};

/// CPU seconds of every thread of this process so far (`/proc/self/task/*/schedstat`), which
/// the machine's other load disturbs less than the wall clock.
fn cpu_seconds() -> f64 {
    let Ok(tasks) = std::fs::read_dir("/proc/self/task") else {
        return f64::NAN;
    };
    let ns: u64 = tasks
        .filter_map(|task| {
            let stat = std::fs::read_to_string(task.ok()?.path().join("schedstat")).ok()?;
            stat.split_whitespace().next()?.parse::<u64>().ok()
        })
        .sum();
    ns as f64 * 1e-9
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let reads: usize = std::env::var("FPPM_BENCH_READS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(9);
    let (width, height) = std::env::var("FPPM_BENCH_SIZE")
        .ok()
        .and_then(|v| {
            let (w, h) = v.split_once('x')?;
            Some((w.parse().ok()?, h.parse().ok()?))
        })
        .unwrap_or((1920u32, 1080u32));
    let path = std::env::var_os("FPPM_BENCH_SCENE").map_or_else(
        || {
            Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("../../../shared/scenes/cornell_box/CornellBox-Sphere.obj")
        },
        std::path::PathBuf::from,
    );
    let mut description = import::load(&path).unwrap();
    description.film = scene::Film { width, height };
    let scene = std::sync::Arc::new(scene::Scene::new(description).unwrap());
    let params = RenderParams::preview();
    let passes = params.growth_pass().unwrap_or(0) + 3;
    let mut off = params;
    off.pool.mode = PoolMode::Off;
    // Pooling reads the state and never changes it: both renderers hold the same one.
    let [mut pooled, mut unpooled] = [params, off].map(|params| {
        let mut renderer = Renderer::new(std::sync::Arc::clone(&scene), params).unwrap();
        for _ in 0..passes {
            renderer.iterate();
        }
        renderer
    });
    println!(
        "{}, {width}x{height}, {passes} passes of freq-sppm, median (fastest) of {reads} read-outs",
        path.display()
    );
    let pools: Vec<(usize, rayon::ThreadPool)> = [1, 2]
        .into_iter()
        .map(|n| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(n)
                .build()
                .unwrap();
            (n, pool)
        })
        .collect();
    // The pooled image of each thread count as raw little-endian f32 RGB, to compare builds.
    if let Some(dump) = std::env::var_os("FPPM_BENCH_DUMP") {
        for (threads, pool) in &pools {
            let renderer = &mut pooled;
            let image = pool.install(move || renderer.image());
            let bytes: Vec<u8> = image
                .iter()
                .flatten()
                .flat_map(|v| v.to_le_bytes())
                .collect();
            let mut path = dump.clone();
            path.push(format!(".{threads}"));
            std::fs::write(path, bytes).unwrap();
        }
    }
    // `&mut`: a renderer is Send, not Sync.
    let mut configs: [(&str, &mut Renderer); 2] =
        [("pooled", &mut pooled), ("unpooled", &mut unpooled)];
    let mut times = vec![Vec::new(); pools.len() * configs.len()];
    let mut cpu = vec![Vec::new(); pools.len() * configs.len()];
    for _ in 0..reads {
        for (p, (_, pool)) in pools.iter().enumerate() {
            for (c, (_, renderer)) in configs.iter_mut().enumerate() {
                let renderer: &mut Renderer = renderer;
                let (start, cpu_start) = (Instant::now(), cpu_seconds());
                let image = pool.install(move || renderer.image());
                times[p * 2 + c].push(start.elapsed().as_secs_f64());
                cpu[p * 2 + c].push(cpu_seconds() - cpu_start);
                std::hint::black_box(image);
            }
        }
    }
    for (p, (threads, _)) in pools.iter().enumerate() {
        for (c, (name, _)) in configs.iter().enumerate() {
            let t = &times[p * configs.len() + c];
            let best = t.iter().copied().fold(f64::INFINITY, f64::min);
            let cpu = &cpu[p * configs.len() + c];
            println!(
                "{name:<9} {threads} thread(s): {:.3} s ({best:.3} s), first {:.3} s; CPU {:.3} s, first {:.3} s",
                median(t.clone()),
                t[0],
                median(cpu.clone()),
                cpu[0]
            );
        }
    }
}
