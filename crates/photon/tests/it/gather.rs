//! `gather`: bit-identical for any thread count and equal to a serial brute-force pass.

use glam::Vec3;
use photon::{
    AcceptParams, GatherScratch, GridParams, HitPointGrid, Photon, accepts, gather, gather_with,
};
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg32;

struct Scene {
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
    radii: Vec<f64>,
    photons: Vec<Photon>,
}

/// Hitpoints and photons on the two faces of a thin wall (z = 0 facing +z, z = −0.01 facing −z)
/// and on a perpendicular wall, so the side and normal tests matter.
fn scene(seed: u64) -> Scene {
    let mut rng = Pcg32::seed_from_u64(seed);
    let surface_point = |rng: &mut Pcg32| {
        let (u, v): (f32, f32) = (rng.random_range(0.0..1.0), rng.random_range(0.0..1.0));
        match rng.random_range(0..3) {
            0 => (Vec3::new(u, v, 0.0), Vec3::Z),
            1 => (Vec3::new(u, v, -0.01), -Vec3::Z),
            _ => (Vec3::new(0.0, u, v), Vec3::X),
        }
    };
    let (positions, normals): (Vec<Vec3>, Vec<Vec3>) =
        (0..3000).map(|_| surface_point(&mut rng)).unzip();
    let radii = (0..3000).map(|_| rng.random_range(0.01..0.05)).collect();
    let photons = (0..20_000)
        .map(|_| {
            let (position, normal) = surface_point(&mut rng);
            let tangent = Vec3::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
            );
            let incoming = (normal + tangent * 0.9).normalize();
            let power = Vec3::new(
                rng.random_range(0.0..1.0),
                rng.random_range(0.0..1.0),
                rng.random_range(0.0..1.0),
            );
            Photon {
                position,
                incoming,
                power,
                normal,
                bounces: 0,
                tag: rng.random_range(0..4),
            }
        })
        .collect();
    Scene {
        positions,
        normals,
        radii,
        photons,
    }
}

type Acc = (u32, [f64; 3]);

fn contribution(s: &Scene) -> impl Fn(&Photon, u32) -> Option<[f64; 3]> + Sync + '_ {
    |photon, idx| {
        let h = idx as usize;
        accepts(
            photon,
            s.positions[h],
            s.normals[h],
            s.radii[h],
            AcceptParams::COS_60,
        )
        .then(|| photon.power.as_dvec3().to_array().map(|c| c / 3.0))
    }
}

fn add(acc: &mut Acc, value: [f64; 3]) {
    acc.0 += 1;
    (0..3).for_each(|c| acc.1[c] += value[c]);
}

#[test]
fn identical_for_1_2_and_8_threads_and_equal_to_brute_force() {
    let s = scene(1);
    let grid = HitPointGrid::build(&s.positions, &s.radii, GridParams::DEFAULT);
    let run = |threads| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| gather(&grid, &s.photons, s.positions.len(), contribution(&s), add))
    };
    let one: Vec<Acc> = run(1);
    for threads in [2, 8] {
        let many = run(threads);
        assert!(
            one.iter()
                .zip(&many)
                .all(|(a, b)| a.0 == b.0 && a.1.map(f64::to_bits) == b.1.map(f64::to_bits))
        );
    }

    // Serial brute force in photon order: the same per-hitpoint summation order, so bit-equal.
    let f = contribution(&s);
    let mut brute = vec![(0_u32, [0.0_f64; 3]); s.positions.len()];
    for photon in &s.photons {
        for (h, acc) in brute.iter_mut().enumerate() {
            if let Some(v) = f(photon, h as u32) {
                add(acc, v);
            }
        }
    }
    assert!(
        one.iter()
            .zip(&brute)
            .all(|(a, b)| a.0 == b.0 && a.1.map(f64::to_bits) == b.1.map(f64::to_bits))
    );
    let n_found: u32 = one.iter().map(|a| a.0).sum();
    assert!(
        n_found > 1000,
        "the test must exercise the gather: {n_found} contributions"
    );
}

#[test]
fn back_face_photons_never_count() {
    // Every accepted photon arrived on the hitpoint's side: no photon from z = −0.01 (normal −z)
    // reaches a hitpoint on z = 0 (normal +z), although the wall is thinner than every radius.
    let s = scene(2);
    let grid = HitPointGrid::build(&s.positions, &s.radii, GridParams::DEFAULT);
    let pairs = gather(
        &grid,
        &s.photons,
        s.positions.len(),
        |photon, idx| contribution(&s)(photon, idx).map(|_| photon.normal),
        |acc: &mut Vec<Vec3>, n| acc.push(n),
    );
    let mut n_checked = 0;
    for (h, normals) in pairs.iter().enumerate() {
        for n in normals {
            assert!(
                n.dot(s.normals[h]) > 0.5,
                "hitpoint {h} got a photon with normal {n}"
            );
            n_checked += 1;
        }
    }
    assert!(n_checked > 1000);
    // The scene does put back-face photons inside front-face radii.
    let n_back = s
        .photons
        .iter()
        .map(|photon| {
            let mut n = 0;
            grid.for_each_containing(photon.position, |h| {
                n += usize::from(photon.normal.dot(s.normals[h as usize]) < -0.5)
            });
            n
        })
        .sum::<usize>();
    assert!(n_back > 1000, "{n_back} back-face photons within a radius");
}

#[test]
fn accumulating_again_equals_a_second_gather() {
    // The flux gather carries the photon's tag along; folding the tags again afterwards (only the
    // odd ones, each with its hitpoint index) must give exactly what a second full gather gives,
    // for any thread count.
    let s = scene(3);
    let grid = HitPointGrid::build(&s.positions, &s.radii, GridParams::DEFAULT);
    let tagged = |photon: &Photon, idx| contribution(&s)(photon, idx).map(|v| (v, photon.tag));
    let fold_odd = |acc: &mut Vec<(u32, u32)>, h: u32, (_, tag): ([f64; 3], u32)| {
        if tag % 2 == 1 {
            acc.push((h, tag));
        }
    };
    let second: Vec<Vec<(u32, u32)>> = gather(
        &grid,
        &s.photons,
        s.positions.len(),
        tagged,
        |acc: &mut Vec<(u32, u32)>, v| {
            // `gather` does not pass the hitpoint: every entry of one accumulator has it.
            if v.1 % 2 == 1 {
                acc.push((u32::MAX, v.1));
            }
        },
    );
    for threads in [1, 2, 8] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let (flux, again) = pool.install(|| {
            let mut scratch = GatherScratch::default();
            let mut flux = Vec::new();
            let gathered = gather_with(
                &mut scratch,
                &grid,
                &s.photons,
                &mut flux,
                s.positions.len(),
                tagged,
                |acc: &mut Acc, (v, _)| add(acc, v),
            );
            let mut again = Vec::new();
            gathered.accumulate_again(&mut again, fold_odd);
            (flux, again)
        });
        let plain = gather(&grid, &s.photons, s.positions.len(), contribution(&s), add);
        assert!(
            flux.iter()
                .zip(&plain)
                .all(|(a, b)| a.0 == b.0 && a.1.map(f64::to_bits) == b.1.map(f64::to_bits))
        );
        assert_eq!(again.len(), s.positions.len());
        let mut n_folded = 0;
        for (h, (a, b)) in again.iter().zip(&second).enumerate() {
            assert!(a.iter().all(|&(idx, _)| idx as usize == h));
            let tags = |v: &Vec<(u32, u32)>| v.iter().map(|&(_, t)| t).collect::<Vec<_>>();
            assert_eq!(tags(a), tags(b), "hitpoint {h}, {threads} threads");
            n_folded += a.len();
        }
        assert!(n_folded > 500, "{n_folded} odd tags folded");
    }
}
