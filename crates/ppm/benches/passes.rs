//! Throughput of the photon mappers on the Cornell box with spheres at 512×512:
//! `cargo bench -p ppm --bench passes`.
//!
//! Prints, for 1 and 2 threads: photon paths per second (tracing only, and whole passes),
//! gather queries per second, hitpoints per pixel, memory per hitpoint, and the extra cost of
//! frequency photons at the default fraction. Times are wall-clock medians over 15 passes,
//! measured side by side in one run: the configurations (method × thread count) take turns, one
//! pass each, so that their ratios hold even though the shared machine's speed drifts by ±20 %
//! over minutes. Absolute numbers are as noisy as the machine; "(best pass)" is the tracing rate
//! of the fastest timed pass.
//!
//! "trace paths/s" is the photon paths started in a pass (all of them, including those that
//! end at the first hit) over the wall time of the tracing phase alone (`PassTimings::trace`:
//! emission, intersections, BSDF sampling, roulette, storing photons, frequency bookkeeping);
//! "pass paths/s" divides the same count by the whole pass (camera, index, trace, gather and
//! update).
//!
//! `FPPM_BENCH_METHODS=ppm,freq` restricts the methods, `FPPM_BENCH_THREADS=1,2` the thread
//! counts (the summary lines need both 1 and 2 threads of ppm and freq); `FPPM_BENCH_PHOTONS`
//! and `FPPM_BENCH_PASSES` change the photons per pass and the timed passes (for profiling
//! under callgrind); `FPPM_BENCH_LIGHT_TRACING=0` turns off the photons' connections to the
//! camera (the work of a pass before light tracing, for comparisons with older builds). A
//! second table gives the median seconds of each phase of a pass. "pass CPU s" is the process
//! CPU time of a pass (all threads): with 1 thread it is the work itself, whatever else runs
//! on the machine.
//!
//! The summary lines are medians over pass rounds of ratios or differences within a round (the
//! passes compared ran seconds apart). Even so, the tracing phase's extra time of freq over
//! ppm varies from run to run by a good part of the bookkeeping share itself, which is why 15
//! passes are timed by default; `docs/performance.md` has the share measured without that
//! noise.
//!
//! The frequency line splits freq's extra pass time into its bookkeeping (the tracing phase's
//! extra time over ppm's: spectra and occlusion probes along the frequency photons' paths; plus
//! `PassTimings::frequency`: their deposits and the clear-disc probes) and the rest, which is the
//! flux gather over the larger kernels the frequency floor holds (the hitpoints each stored
//! photon reaches, printed for both methods), whose pairs also carry the photons' tags for the
//! deposits (4 bytes each, not counted as bookkeeping).
//!
//! Memory is `Renderer::memory` after the timed passes (allocated capacities), per hitpoint
//! slot: the state kept from pass to pass (records, the renderer's slot columns, the grid and
//! its slot map) and the per-pass buffers, sized by the hitpoints (M, Φ and frequency
//! accumulators) or by the photons (traced and sorted photons, keys, gather bins).

#![allow(clippy::print_stdout, clippy::unwrap_used, missing_docs)]

use std::path::Path;

use ppm::{Method, PassStats, RenderParams, Renderer};

fn env_or<T: std::str::FromStr>(name: &str, default: T) -> T {
    std::env::var(name)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// CPU seconds (user + system) used by this process so far, from `/proc/self/stat` (10 ms
/// ticks); 0 where unavailable. Robust to other jobs on the machine, unlike wall time.
fn process_cpu_seconds() -> f64 {
    std::fs::read_to_string("/proc/self/stat")
        .ok()
        .and_then(|stat| {
            // Fields after the parenthesised command name; utime and stime are fields 14, 15.
            let rest = &stat[stat.rfind(')')? + 2..];
            let fields: Vec<&str> = rest.split_whitespace().collect();
            let ticks =
                fields.get(11)?.parse::<f64>().ok()? + fields.get(12)?.parse::<f64>().ok()?;
            Some(ticks / 100.0)
        })
        .unwrap_or(0.0)
}

/// One configuration under test: a renderer of one method in a pool of some threads, and what
/// its timed passes gave.
struct Run {
    method: Method,
    threads: usize,
    pool: rayon::ThreadPool,
    renderer: Renderer,
    stats: Vec<PassStats>,
    cpu: Vec<f64>,
}

/// Renders `passes` timed passes of every (method, thread count), interleaved: one pass of each
/// configuration in turn, so that every configuration sees the same machine. The speed of the
/// shared machine drifts by ±20 % over minutes; measured one after the other, the ratios of the
/// summary (frequency overhead, parallel speed-up) drifted with it.
fn run(
    scene: &std::sync::Arc<scene::Scene>,
    configs: &[(Method, usize)],
    photons_per_pass: u32,
    passes: usize,
) -> Vec<Run> {
    let mut runs: Vec<Run> = configs
        .iter()
        .map(|&(method, threads)| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let mut params = RenderParams::preview();
            params.method = method;
            params.budget.photons_per_pass = photons_per_pass;
            params.budget.photons_auto = false;
            params.connections.light_tracing = env_or("FPPM_BENCH_LIGHT_TRACING", 1u8) != 0;
            let mut renderer = Renderer::new(std::sync::Arc::clone(scene), params).unwrap();
            // The first pass traces the hitpoints and builds the grid: not the steady state.
            pool.install(|| renderer.iterate());
            Run {
                method,
                threads,
                pool,
                renderer,
                stats: Vec::new(),
                cpu: Vec::new(),
            }
        })
        .collect();
    for _ in 0..passes {
        for run in &mut runs {
            let Run {
                pool,
                renderer,
                stats,
                cpu,
                ..
            } = run;
            let before = process_cpu_seconds();
            stats.push(pool.install(|| renderer.iterate()));
            cpu.push(process_cpu_seconds() - before);
        }
    }
    runs
}

fn main() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/scenes/cornell_box/CornellBox-Sphere.obj");
    let mut description = import::load(&path).unwrap();
    description.film = scene::Film {
        width: 512,
        height: 512,
    };
    let scene = std::sync::Arc::new(scene::Scene::new(description).unwrap());
    let photons_per_pass: u32 = env_or("FPPM_BENCH_PHOTONS", 1_000_000);
    let passes: usize = env_or("FPPM_BENCH_PASSES", 15);
    println!(
        "CornellBox-Sphere, 512x512, {photons_per_pass} photons per pass, median of {passes} passes"
    );
    println!(
        "{:<10} {:>7} {:>16} {:>16} {:>16} {:>16} {:>12} {:>12}",
        "method",
        "threads",
        "trace paths/s",
        "(best pass)",
        "pass paths/s",
        "gather q/s",
        "pass s",
        "pass CPU s"
    );
    let methods: Vec<Method> = [Method::Ppm, Method::FreqPpm, Method::Sppm]
        .into_iter()
        .filter(|m| {
            std::env::var("FPPM_BENCH_METHODS")
                .map_or(true, |list| list.split(',').any(|name| name == m.name()))
        })
        .collect();
    let thread_counts: Vec<usize> = std::env::var("FPPM_BENCH_THREADS")
        .map_or(vec![1, 2], |list| {
            list.split(',').map(|t| t.parse().unwrap()).collect()
        });
    let configs: Vec<(Method, usize)> = methods
        .iter()
        .flat_map(|&m| thread_counts.iter().map(move |&t| (m, t)))
        .collect();
    let runs = run(&scene, &configs, photons_per_pass, passes);
    let mut phases = Vec::new();
    let mut memory = Vec::new();
    for Run {
        method,
        threads,
        renderer,
        stats,
        cpu,
        ..
    } in &runs
    {
        let (method, threads) = (*method, *threads);
        if !memory.iter().any(|&(m, _)| m == method) {
            memory.push((method, renderer.memory().unwrap()));
        }
        let cpu = median(cpu.clone());
        let trace = median(stats.iter().map(|s| s.timings.trace).collect());
        let best_trace = stats
            .iter()
            .map(|s| s.timings.trace)
            .fold(f64::INFINITY, f64::min);
        let gather = median(stats.iter().map(|s| s.timings.gather).collect());
        let total = median(stats.iter().map(|s| s.timings.total()).collect());
        let stored = stats.iter().map(|s| s.photons_stored).sum::<u64>() as f64 / passes as f64;
        let photons = f64::from(photons_per_pass);
        println!(
            "{:<10} {:>7} {:>16.0} {:>16.0} {:>16.0} {:>16.0} {:>12.3} {:>12.2}",
            method.name(),
            threads,
            photons / trace,
            photons / best_trace,
            photons / total,
            stored / gather,
            total,
            cpu
        );
        let phase =
            |f: fn(&ppm::PassTimings) -> f64| median(stats.iter().map(|s| f(&s.timings)).collect());
        phases.push((
            method,
            threads,
            [
                phase(|t| t.camera),
                phase(|t| t.index),
                phase(|t| t.trace),
                phase(|t| t.gather),
                phase(|t| t.update),
                phase(|t| t.frequency),
                phase(|t| t.total()),
            ],
            stats.iter().map(|s| s.photons_deposited).sum::<u64>() as f64
                / stats.iter().map(|s| s.photons_stored).sum::<u64>().max(1) as f64,
        ));
    }
    println!(
        "{:<10} {:>7} {:>9} {:>9} {:>9} {:>9} {:>9} {:>9} {:>11}   (median seconds per phase)",
        "method",
        "threads",
        "camera",
        "index",
        "trace",
        "gather",
        "update",
        "(freq)",
        "hitp./phot."
    );
    for (method, threads, p, per_photon) in &phases {
        println!(
            "{:<10} {:>7} {:>9.3} {:>9.3} {:>9.3} {:>9.3} {:>9.3} {:>9.3} {:>11.2}",
            method.name(),
            threads,
            p[0],
            p[1],
            p[2],
            p[3],
            p[4],
            p[5],
            per_photon
        );
    }
    println!(
        "(freq): the frequency deposits and clear-disc probes inside gather and update; \
         hitp./phot.: hitpoints each stored photon reached"
    );
    // The timed passes of one configuration, and the hitpoints per stored photon.
    let find = |m: Method, t: usize| {
        let run = runs.iter().find(|r| r.method == m && r.threads == t)?;
        let per_photon = phases
            .iter()
            .find(|&&(method, threads, _, _)| method == m && threads == t)
            .map(|&(_, _, _, per_photon)| per_photon)?;
        Some((&run.stats, per_photon))
    };
    // Ratios are medians over pass rounds of ratios within a round (the passes compared ran
    // seconds apart, so the machine's drift mostly cancels).
    let paired = |a: &[PassStats], b: &[PassStats], f: &dyn Fn(&PassStats, &PassStats) -> f64| {
        median(a.iter().zip(b).map(|(a, b)| f(a, b)).collect())
    };
    for method in [Method::Ppm, Method::FreqPpm] {
        if let (Some((one, _)), Some((two, _))) = (find(method, 1), find(method, 2)) {
            println!(
                "{}: parallel speed-up 1 -> 2 threads: {:.2}x pass, {:.2}x trace (medians of \
                 paired passes)",
                method.name(),
                paired(one, two, &|a, b| a.timings.total() / b.timings.total()),
                paired(one, two, &|a, b| a.timings.trace / b.timings.trace)
            );
        }
    }
    for threads in [1, 2] {
        if let (Some((ppm, ppm_reach)), Some((freq, freq_reach))) =
            (find(Method::Ppm, threads), find(Method::FreqPpm, threads))
        {
            // Bookkeeping: what frequency photons add to tracing (spectra, occlusion probes),
            // plus their deposits and the clear-disc probes. The rest of the difference is the
            // flux gather over kernels the frequency floor holds larger than PPM's.
            let extra_trace = |p: &PassStats, f: &PassStats| f.timings.trace - p.timings.trace;
            let bookkeeping =
                |p: &PassStats, f: &PassStats| extra_trace(p, f).max(0.0) + f.timings.frequency;
            println!(
                "frequency photons (default fraction {}, {threads} threads): {:+.1} % pass time vs \
                 classical PPM; bookkeeping (trace {:+.3} s, deposits and probes {:.3} s) {:.1} % of \
                 the freq pass (medians of paired passes); held kernels reach {:.2} hitpoints per \
                 photon against {:.2}",
                RenderParams::preview().frequency.fraction,
                (paired(ppm, freq, &|p, f| f.timings.total() / p.timings.total()) - 1.0) * 100.0,
                paired(ppm, freq, &extra_trace),
                median(freq.iter().map(|f| f.timings.frequency).collect()),
                paired(ppm, freq, &|p, f| bookkeeping(p, f) / f.timings.total()) * 100.0,
                freq_reach,
                ppm_reach
            );
        }
    }
    let n_slots = 512 * 512 * RenderParams::preview().film.samples_per_pixel as usize;
    println!(
        "hitpoints per pixel: {} ({} slots); fixed columns: {} bytes per hitpoint",
        RenderParams::preview().film.samples_per_pixel,
        n_slots,
        ppm::bytes_per_hitpoint()
    );
    println!(
        "{:<10} {:>8} {:>8} {:>8} {:>11} {:>11} {:>11} {:>10}   (bytes per hitpoint)",
        "method", "records", "columns", "grid", "persistent", "pass/hitp.", "pass/phot.", "total"
    );
    for (method, mem) in &memory {
        let per = |bytes: usize| bytes as f64 / mem.hitpoints.max(1) as f64;
        println!(
            "{:<10} {:>8.1} {:>8.1} {:>8.1} {:>11.1} {:>11.1} {:>11.1} {:>10.1}",
            method.name(),
            per(mem.records),
            per(mem.slot_columns),
            per(mem.grid),
            per(mem.persistent()),
            per(mem.pass_hitpoint_buffers),
            per(mem.pass_photon_buffers),
            per(mem.total())
        );
    }
}
