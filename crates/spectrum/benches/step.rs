//! One photon step of the frequency algebra: travel, reflect, their combination, and the
//! kernel radius. `cargo bench -p spectrum`. The allocation profiler shows that none of
//! them allocates.
#![allow(clippy::unwrap_used)]

use divan::{Bencher, black_box};
use spectrum::{Caps, FrequencyEstimate, K_POSTER, Lobe, MergePolicy, Spectrum};

#[global_allocator]
static ALLOC: divan::AllocProfiler = divan::AllocProfiler::system();

fn main() {
    divan::main();
}

fn setup() -> (Caps, Spectrum) {
    let caps = Caps::for_scene_size(10.0);
    let q = Spectrum::point_light(&caps).travel(1.3, &caps);
    (caps, q)
}

#[divan::bench]
fn travel(bencher: Bencher) {
    let (caps, q) = setup();
    bencher.bench_local(|| black_box(q).travel(black_box(0.7), black_box(&caps)));
}

#[divan::bench]
fn reflect(bencher: Bencher) {
    let (caps, q) = setup();
    let lobe = Lobe::Phong { exponent: 100.0 };
    bencher.bench_local(|| {
        black_box(q).reflect(
            black_box(0.8),
            black_box(0.6),
            black_box(0.5),
            black_box(lobe),
            black_box(&caps),
        )
    });
}

/// One full photon step: reflect at a curved glossy surface, then travel to the next hit.
#[divan::bench]
fn reflect_travel_step(bencher: Bencher) {
    let (caps, q) = setup();
    let lobe = Lobe::Phong { exponent: 100.0 };
    bencher.bench_local(|| {
        black_box(q)
            .reflect(
                black_box(0.8),
                black_box(0.6),
                black_box(0.5),
                black_box(lobe),
                black_box(&caps),
            )
            .travel(black_box(0.7), black_box(&caps))
    });
}

#[divan::bench]
fn radius(bencher: Bencher) {
    let (_, q) = setup();
    bencher.bench_local(|| black_box(q).radius(black_box(2.0), black_box(K_POSTER)));
}

/// A hitpoint deposit (min-radius merge) followed by the radius query.
#[divan::bench]
fn deposit_and_radius(bencher: Bencher) {
    let (_, q) = setup();
    let mut estimate = FrequencyEstimate::default();
    estimate.deposit(q, MergePolicy::MinRadius);
    bencher.bench_local(|| {
        let mut e = black_box(estimate);
        e.deposit(black_box(q), MergePolicy::MinRadius);
        e.radius(black_box(2.0), black_box(K_POSTER))
    });
}
