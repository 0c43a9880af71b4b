use super::*;

#[test]
fn radius_sq_is_rounded_down_exactly() {
    for r in [0.1_f64, 1.0 / 3.0, 1e-20, 7.0e10, 0.0, 1e30, f64::INFINITY] {
        let r2 = radius_sq_down(r);
        assert!(f64::from(r2) <= r * r, "r = {r}");
        if r2 < f32::MAX {
            assert!(f64::from(r2.next_up()) > r * r, "r = {r}");
        }
    }
    assert_eq!(radius_sq_down(1e30), f32::MAX);
    assert!(radius_sq_down(-1.0).is_nan());
    assert!(radius_sq_down(f64::NAN).is_nan());
}

#[test]
fn radix_sort_is_stable_by_bucket() {
    let mut keys: Vec<u64> = [(5_u64, 0_u64), (3, 1), (5, 2), (0, 3), (4095, 4), (3, 5)]
        .iter()
        .map(|&(b, i)| b << 32 | i)
        .collect();
    radix_sort_by_bucket(&mut keys, 12);
    let pairs: Vec<(u64, u64)> = keys.iter().map(|&k| (k >> 32, k & 0xFFFF_FFFF)).collect();
    assert_eq!(pairs, [(0, 3), (3, 1), (3, 5), (5, 0), (5, 2), (4095, 4)]);
}

#[test]
fn colliding_cells_list_a_hitpoint_once() {
    // Two hitpoints in a table of 4 buckets: a hitpoint spanning 8 cells hits some bucket twice.
    let positions = [Vec3::ZERO, Vec3::splat(10.0)];
    let radii = [1.0, 1.0];
    let grid = HitPointGrid::build(&positions, &radii, GridParams::DEFAULT);
    assert_eq!(grid.stats().n_buckets, 4);
    for b in 0..4 {
        let mut idx =
            grid.entry_idx[grid.cell_start[b] as usize..grid.cell_start[b + 1] as usize].to_vec();
        let n = idx.len();
        idx.dedup();
        assert_eq!(idx.len(), n, "bucket {b} lists a hitpoint twice");
    }
}

#[test]
fn large_radii_go_to_coarser_levels_and_infinite_ones_to_overflow() {
    let positions = [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z, Vec3::ONE];
    let radii = [0.01, 0.01, 0.01, 1e6, f64::INFINITY];
    let grid = HitPointGrid::build(&positions, &radii, GridParams::DEFAULT);
    let stats = grid.stats();
    assert_eq!((stats.n_levels, stats.n_overflow), (2, 1));
    let mut found = Vec::new();
    grid.for_each_containing(Vec3::splat(5e5), |i| found.push(i));
    assert_eq!(found, [3, 4]);
}

#[test]
fn floor_i32_matches_floor_and_saturates() {
    for v in [
        0.0_f32,
        -0.0,
        0.5,
        -0.5,
        1.0,
        -1.0,
        2.999_999_8,
        -3.000_000_2,
        1e9,
        -1e9,
        16_777_217.0,
    ] {
        assert_eq!(floor_i32(v), v.floor() as i32, "{v}");
    }
    assert_eq!(floor_i32(1e20), i32::MAX);
    assert_eq!(floor_i32(-1e20), i32::MIN);
    assert_eq!(floor_i32(f32::NEG_INFINITY), i32::MIN);
    assert_eq!(floor_i32(f32::NAN), 0);
}

#[test]
fn simd_containment_matches_within_radius() {
    // A small xorshift, to keep the unit tests free of dev-dependencies.
    let mut state = 0x9E37_79B9_7F4A_7C15_u64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 40) as f32 / (1 << 24) as f32 * 2.0 - 1.0
    };
    for _ in 0..100_000 {
        let p = Vec3::new(next(), next(), next()) * 10.0;
        let x = p + Vec3::new(next(), next(), next()) * 0.1;
        // Radii right at the distance, so the comparisons sit on the rounding boundary.
        let r = f64::from(distance_sq(p, x)).sqrt() * (1.0 + f64::from(next()) * 1e-7);
        let r2 = radius_sq_down(r);
        assert_eq!(
            contains(p.extend(0.0), x.extend(r2)),
            crate::within_radius(p, x, r * r),
            "{p} {x} {r}"
        );
    }
}
