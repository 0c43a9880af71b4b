use super::*;

#[test]
fn radius_sq_is_rounded_up() {
    for r in [0.1_f64, 1.0 / 3.0, 1e-20, 7.0e10, 0.0] {
        assert!(f64::from(radius_sq_up(r)) >= r * r, "r = {r}");
    }
    assert_eq!(radius_sq_up(1e30), f32::INFINITY);
}

#[test]
fn colliding_cells_list_a_hitpoint_once() {
    // Two hitpoints in a table of 4 buckets: a hitpoint spanning 8 cells hits some bucket twice.
    let positions = [Vec3::ZERO, Vec3::splat(10.0)];
    let radii = [1.0, 1.0];
    let grid = HitPointGrid::build(&positions, &radii, GridParams::DEFAULT);
    assert_eq!(grid.stats().n_buckets, 4);
    for b in 0..4 {
        let bucket = &grid.entries[grid.cell_start[b] as usize..grid.cell_start[b + 1] as usize];
        let mut idx: Vec<u32> = bucket.iter().map(|e| e.idx).collect();
        let n = idx.len();
        idx.dedup();
        assert_eq!(idx.len(), n, "bucket {b} lists a hitpoint twice");
    }
}

#[test]
fn huge_radius_goes_to_overflow() {
    let positions = [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z];
    let radii = [0.01, 0.01, 0.01, 1e6];
    let grid = HitPointGrid::build(&positions, &radii, GridParams::DEFAULT);
    assert_eq!(grid.stats().n_overflow, 1);
    let mut found = Vec::new();
    grid.for_each_containing(Vec3::splat(5e5), &radii, |i| found.push(i));
    assert_eq!(found, [3]);
}
