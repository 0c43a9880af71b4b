//! `HitPointGrid` against a brute-force scan: identical sets, in increasing index order per
//! bucket, on random and adversarial inputs.

use glam::Vec3;
use photon::{CellSize, GridParams, HitPointGrid, within_radius};
use proptest::prelude::*;
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg32;

const ALL_PARAMS: [GridParams; 4] = [
    GridParams::DEFAULT,
    GridParams {
        cell_size: CellSize::MaxRadius(2.0),
        rebuild_below: 0.8,
    },
    GridParams {
        cell_size: CellSize::MeanRadius(0.5),
        rebuild_below: 0.8,
    },
    GridParams {
        cell_size: CellSize::MeanRadius(8.0),
        rebuild_below: 0.8,
    },
];

/// The specification: every valid hitpoint (finite position, radius ≥ 0) whose sphere contains
/// `p` by `within_radius`.
fn brute_force(positions: &[Vec3], radii: &[f64], p: Vec3) -> Vec<u32> {
    (0..positions.len() as u32)
        .filter(|&i| {
            let (x, r) = (positions[i as usize], radii[i as usize]);
            x.is_finite() && r >= 0.0 && within_radius(p, x, r * r)
        })
        .collect()
}

fn grid_query(grid: &HitPointGrid, p: Vec3) -> Vec<u32> {
    let mut found = Vec::new();
    grid.for_each_containing(p, |i| found.push(i));
    let n = found.len();
    found.sort_unstable();
    found.dedup();
    assert_eq!(found.len(), n, "a hitpoint was reported twice at {p}");
    found
}

/// Checks every query point with every grid parameter preset.
#[track_caller]
fn check(positions: &[Vec3], radii: &[f64], queries: &[Vec3]) {
    for params in ALL_PARAMS {
        let grid = HitPointGrid::build(positions, radii, params);
        for &p in queries {
            assert_eq!(
                grid_query(&grid, p),
                brute_force(positions, radii, p),
                "{params:?} at {p}"
            );
        }
    }
}

fn random_vec(rng: &mut Pcg32, lo: f32, hi: f32) -> Vec3 {
    Vec3::new(
        rng.random_range(lo..hi),
        rng.random_range(lo..hi),
        rng.random_range(lo..hi),
    )
}

/// Random hitpoints in a box, radii over four orders of magnitude, queries near hitpoints,
/// uniformly in and around the box, and exactly on sphere boundaries.
fn random_case(seed: u64, n: usize) -> (Vec<Vec3>, Vec<f64>, Vec<Vec3>) {
    let mut rng = Pcg32::seed_from_u64(seed);
    let positions: Vec<Vec3> = (0..n).map(|_| random_vec(&mut rng, -1.0, 1.0)).collect();
    let radii: Vec<f64> = (0..n)
        .map(|_| 10f64.powf(rng.random_range(-4.0..0.0)))
        .collect();
    let mut queries = Vec::new();
    for i in 0..n {
        let dir = random_vec(&mut rng, -1.0, 1.0).normalize_or(Vec3::X);
        let r = radii[i] as f32;
        queries.push(positions[i] + dir * r * rng.random_range(0.0..1.2));
        queries.push(positions[i] + dir * r);
        queries.push(positions[i] + Vec3::X * r);
    }
    queries.extend((0..n).map(|_| random_vec(&mut rng, -1.5, 1.5)));
    (positions, radii, queries)
}

#[test]
fn random_inputs_match_brute_force() {
    for seed in 0..8 {
        let (positions, radii, queries) = random_case(seed, 400);
        check(&positions, &radii, &queries);
    }
}

#[test]
fn points_on_cell_boundaries() {
    // Hitpoints and queries on a lattice of step 0.5 with radius 0.25 or 0.5: with the default
    // cell edge 2 × mean, many queries sit exactly on cell faces, edges and corners, and many
    // spheres touch the queries exactly.
    let mut positions = Vec::new();
    let mut radii = Vec::new();
    for i in 0..6 {
        for j in 0..6 {
            for k in 0..6 {
                positions.push(Vec3::new(i as f32, j as f32, k as f32) * 0.5);
                radii.push(if (i + j + k) % 2 == 0 { 0.25 } else { 0.5 });
            }
        }
    }
    let queries: Vec<Vec3> = (0..13 * 13 * 13)
        .map(|n| Vec3::new((n % 13) as f32, (n / 13 % 13) as f32, (n / 169) as f32) * 0.25 - 0.25)
        .collect();
    check(&positions, &radii, &queries);
}

#[test]
fn huge_radius_among_small_ones() {
    let (mut positions, mut radii, mut queries) = random_case(11, 300);
    positions.push(Vec3::new(0.3, 0.1, -0.2));
    radii.push(50.0);
    positions.push(Vec3::splat(100.0));
    radii.push(1e12);
    queries.push(Vec3::splat(60.0));
    queries.push(Vec3::splat(-1e11));
    check(&positions, &radii, &queries);
}

#[test]
fn dark_and_bright_regions() {
    // Most radii shrank to 1e-3 (bright), a tenth stayed at 0.05 and a few at 0.3 (dark): the
    // mean-radius cells put the large ones on coarser levels.
    let (positions, mut radii, queries) = random_case(21, 2000);
    for (i, r) in radii.iter_mut().enumerate() {
        *r = match i % 50 {
            0 => 0.3,
            1..=5 => 0.05,
            _ => 1e-3,
        };
    }
    let grid = HitPointGrid::build(&positions, &radii, GridParams::DEFAULT);
    assert!(grid.stats().n_levels >= 3, "{:?}", grid.stats());
    assert_eq!(grid.stats().n_overflow, 0);
    check(&positions, &radii, &queries);
}

#[test]
fn empty_grid_finds_nothing() {
    check(&[], &[], &[Vec3::ZERO, Vec3::ONE, Vec3::NAN]);
}

#[test]
fn single_hitpoint() {
    let positions = [Vec3::new(1.0, 2.0, 3.0)];
    let radii = [0.5];
    let queries = [
        Vec3::new(1.0, 2.0, 3.0),
        Vec3::new(1.5, 2.0, 3.0),
        Vec3::new(1.5001, 2.0, 3.0),
        Vec3::ZERO,
    ];
    check(&positions, &radii, &queries);
    let grid = HitPointGrid::build(&positions, &radii, GridParams::DEFAULT);
    assert_eq!(grid_query(&grid, queries[1]), [0]);
}

#[test]
fn zero_and_invalid_radii() {
    let positions = [
        Vec3::ZERO,
        Vec3::ONE,
        Vec3::new(f32::NAN, 0.0, 0.0),
        Vec3::X,
    ];
    let radii = [0.0, f64::NAN, 1.0, -1.0];
    let queries = [
        Vec3::ZERO,
        Vec3::ONE,
        Vec3::X,
        Vec3::new(0.0, 0.0, 1e-7),
        Vec3::splat(1e30),
    ];
    check(&positions, &radii, &queries);
    let positions = [Vec3::ZERO, Vec3::ONE, Vec3::X];
    let radii = [0.0, f64::INFINITY, 0.5];
    check(&positions, &radii, &queries);
}

#[test]
fn far_from_origin() {
    // Coordinates near 1e4 with radii near 1e-2: f32 resolution is ~1e-3 there.
    let mut rng = Pcg32::seed_from_u64(5);
    let base = Vec3::new(1.0e4, -2.0e4, 3.0e4);
    let positions: Vec<Vec3> = (0..300)
        .map(|_| base + random_vec(&mut rng, 0.0, 1.0))
        .collect();
    let radii: Vec<f64> = (0..300).map(|_| rng.random_range(0.005..0.05)).collect();
    let queries: Vec<Vec3> = (0..3000)
        .map(|_| base + random_vec(&mut rng, -0.1, 1.1))
        .collect();
    check(&positions, &radii, &queries);
}

#[test]
fn refreshed_radii_match_brute_force() {
    let (positions, radii, queries) = random_case(3, 300);
    let mut grid = HitPointGrid::build(&positions, &radii, GridParams::DEFAULT);
    let mut shrunk: Vec<f64> = radii.iter().map(|r| r * 0.7).collect();
    shrunk[5] = -1.0;
    shrunk[6] = f64::NAN;
    shrunk[7] = 0.0;
    assert!(!grid.needs_rebuild(&radii));
    assert!(grid.needs_rebuild(&shrunk));
    assert!(grid.needs_rebuild(&shrunk[1..]));
    assert!(grid.refresh_radii(&shrunk));
    for &p in queries.iter().chain(&positions) {
        assert_eq!(
            grid_query(&grid, p),
            brute_force(&positions, &shrunk, p),
            "at {p}"
        );
    }
    // Growing back is refused.
    assert!(!grid.refresh_radii(&radii));
    assert!(!grid.refresh_radii(&radii[1..]));
}

#[test]
fn build_is_independent_of_thread_count() {
    let (positions, radii, queries) = random_case(8, 3000);
    let build = |threads| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| HitPointGrid::build(&positions, &radii, GridParams::DEFAULT))
    };
    let grids = [build(1), build(2), build(5)];
    for &p in &queries {
        let orders: Vec<Vec<u32>> = grids
            .iter()
            .map(|g| {
                let mut order = Vec::new();
                g.for_each_containing(p, |i| order.push(i));
                order
            })
            .collect();
        assert!(orders.iter().all(|o| *o == orders[0]), "{orders:?}");
    }
}

#[test]
fn build_is_deterministic_and_ordered() {
    let (positions, radii, queries) = random_case(7, 2000);
    // Max-radius cells: no overflow list, so every query is one bucket in index order.
    let params = ALL_PARAMS[1];
    let a = HitPointGrid::build(&positions, &radii, params);
    let b = HitPointGrid::build(&positions, &radii, params);
    assert_eq!(a.stats(), b.stats());
    assert_eq!(a.stats().n_overflow, 0);
    for &p in &queries {
        let mut order_a = Vec::new();
        let mut order_b = Vec::new();
        a.for_each_containing(p, |i| order_a.push(i));
        b.for_each_containing(p, |i| order_b.push(i));
        assert_eq!(order_a, order_b);
        // Bucket entries come in increasing index (no overflow in this case).
        assert!(order_a.windows(2).all(|w| w[0] < w[1]), "{order_a:?}");
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn grid_equals_brute_force(
        hits in prop::collection::vec(
            ((-10.0_f32..10.0, -10.0_f32..10.0, -10.0_f32..10.0), -5.0_f64..1.0), 0..120),
        queries in prop::collection::vec((-12.0_f32..12.0, -12.0_f32..12.0, -12.0_f32..12.0), 1..60),
        snap in 0.0_f32..1.0,
    ) {
        let positions: Vec<Vec3> = hits.iter().map(|&((x, y, z), _)| Vec3::new(x, y, z)).collect();
        let radii: Vec<f64> = hits.iter().map(|&(_, e)| 10f64.powf(e)).collect();
        // Snap some queries to a coarse lattice so they land on cell boundaries.
        let queries: Vec<Vec3> = queries.iter().map(|&(x, y, z)| {
            let q = Vec3::new(x, y, z);
            if snap < 0.5 { (q * 4.0).round() / 4.0 } else { q }
        }).chain(positions.iter().zip(&radii).map(|(&x, &r)| x + Vec3::Y * r as f32)).collect();
        for params in ALL_PARAMS {
            let grid = HitPointGrid::build(&positions, &radii, params);
            for &p in &queries {
                prop_assert_eq!(grid_query(&grid, p), brute_force(&positions, &radii, p));
            }
        }
    }
}
