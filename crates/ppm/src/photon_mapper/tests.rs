//! Tests of the photon mappers' internals.

use std::sync::Arc;

use scene::Scene;

use super::frequency::{TagLayout, UNTAGGED};
use super::{PassStats, PhotonMapper};
use crate::integrator::Integrator;
use crate::{Method, RenderParams};

#[test]
fn tags_pack_chunk_and_record_indices_when_they_fit() {
    // 489 chunks (10⁶ photons), depth 8: 9 + 14 bits.
    assert_eq!(TagLayout::new(489, 8), TagLayout::Packed { local_bits: 14 });
    assert_eq!(TagLayout::new(1, 1), TagLayout::Packed { local_bits: 11 });
    // Depth 1024: 21 bits per chunk leave 10 for 1024 chunks, not for 1025.
    assert_eq!(
        TagLayout::new(1024, 1024),
        TagLayout::Packed { local_bits: 21 }
    );
    assert_eq!(TagLayout::new(1025, 1024), TagLayout::Global);
    // The largest packed tag is below UNTAGGED.
    let TagLayout::Packed { local_bits } = TagLayout::new(1024, 1024) else {
        unreachable!()
    };
    let last = TagLayout::new(1024, 1024).chunk_base(1023) | ((1 << local_bits) - 1);
    assert!(last < UNTAGGED);
}

/// The scene file at `path` (relative to this crate) with a film of `width` × `height`.
fn scene_at(path: &str, width: u32, height: u32) -> Arc<Scene> {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(path);
    let mut description = import::load(&path).unwrap();
    description.film = scene::Film { width, height };
    Arc::new(Scene::new(description).unwrap())
}

const CORNELL_SPHERE: &str = "../../../shared/scenes/cornell_box/CornellBox-Sphere.obj";

/// The shared CornellBox-Sphere at 24 × 24.
fn cornell_sphere_24() -> Arc<Scene> {
    scene_at(CORNELL_SPHERE, 24, 24)
}

#[test]
fn global_tags_deposit_exactly_what_packed_tags_do() {
    let scene = cornell_sphere_24();
    let mut params = RenderParams::preview();
    params.method = Method::FreqPpm;
    params.budget.photons_per_pass = 5_000;
    params.budget.photons_auto = false;
    let render = |force_global_tags| {
        let mut mapper = PhotonMapper::new(Arc::clone(&scene), params).unwrap();
        mapper.frequency.force_global_tags = force_global_tags;
        let stats: Vec<PassStats> = (0..3).map(|_| mapper.iterate()).collect();
        (mapper.image(), mapper.slots.freq().to_vec(), stats)
    };
    let (packed, global) = (render(false), render(true));
    assert!(packed.1.iter().any(|f| f.estimate().has_freq()));
    assert_eq!(packed.1, global.1, "frequency states differ");
    let bits = |image: &[[f32; 3]]| {
        image
            .iter()
            .map(|p| p.map(f32::to_bits))
            .collect::<Vec<_>>()
    };
    assert_eq!(bits(&packed.0), bits(&global.0));
    for (a, b) in packed.2.iter().zip(&global.2) {
        assert_eq!(a.photons_deposited, b.photons_deposited);
        assert_eq!(a.frequency_held.to_bits(), b.frequency_held.to_bits());
    }
}

/// The clear disc a 2 × 2 block shares for 16 passes is the same whether it was computed in
/// the epoch's first pass or later (after a restore, which does not keep it): a renderer that
/// forgets its discs in the middle of the second epoch gets the same discs back, and the same
/// image, as one that kept them.
#[test]
fn block_discs_recomputed_mid_epoch_are_those_of_the_epoch_start() {
    let scene = cornell_sphere_24();
    let mut params = RenderParams::preview();
    params.method = Method::FreqSppm;
    params.budget.photons_per_pass = 5_000;
    params.budget.photons_auto = false;
    let mut kept = PhotonMapper::new(Arc::clone(&scene), params).unwrap();
    let mut forgot = PhotonMapper::new(Arc::clone(&scene), params).unwrap();
    for _ in 0..19 {
        kept.iterate();
        forgot.iterate();
    }
    forgot.block_discs.clear();
    kept.iterate();
    forgot.iterate();
    let both: Vec<_> = kept
        .block_discs
        .iter()
        .zip(&forgot.block_discs)
        .filter_map(|(a, b)| Some((a.as_ref()?, b.as_ref()?)))
        .collect();
    assert!(both.len() > 20, "only {} blocks probed in both", both.len());
    for (a, b) in both {
        assert_eq!(a, b);
    }
    let same = kept
        .image()
        .iter()
        .zip(&forgot.image())
        .all(|(x, y)| x.map(f32::to_bits) == y.map(f32::to_bits));
    assert!(same, "the image differs");
}

/// A slot that the 2 × 2 blocks' shared disc calls clear at the largest kernel is clear there by
/// its own probes too: on `scenes/peers/pool-caustic.toml`, whose ground stands 7 cm above the
/// water, the shared ladder (from 8·R_max) once took the water for the ground and called the
/// discs along the pool's edge clear.
#[test]
fn a_block_calls_a_slot_clear_only_where_its_own_probes_do() {
    let scene = scene_at("../../scenes/peers/pool-caustic.toml", 96, 96);
    let mut params = RenderParams::preview();
    params.method = Method::FreqSppm;
    params.budget.photons_per_pass = 20_000;
    params.budget.photons_auto = false;
    let mut mapper = PhotonMapper::new(Arc::clone(&scene), params).unwrap();
    for _ in 0..3 {
        mapper.iterate();
    }
    let r_top = mapper.setup.kernel_max() as f32;
    let slots = &mapper.slots;
    let mut shared_clear = 0;
    for slot in 0..slots.len() {
        if !mapper.is_valid(slot) || slots.freq()[slot].clear_level() != 0 {
            continue;
        }
        shared_clear += 1;
        let own = crate::disc::clear_level(
            &scene,
            slots.position()[slot],
            slots.geometric_normal()[slot],
            r_top,
            0.5 * r_top,
        );
        assert_eq!(own, 0, "slot {slot} at {:?}", slots.position()[slot]);
    }
    assert!(
        shared_clear > 1000,
        "only {shared_clear} slots clear at R_max"
    );
}

/// The vectorised pooling (eight pixels a time, bands of rows, f32 sums) gives what a plain
/// per-pixel loop of the same rule gives: on a film whose width is not a multiple of eight, with
/// two samples per pixel and a window that reaches over band edges.
#[test]
fn pooling_matches_a_per_pixel_reference() {
    let scene = scene_at(CORNELL_SPHERE, 45, 70);
    let mut params = RenderParams::preview();
    params.method = Method::FreqSppm;
    params.budget.photons_per_pass = 20_000;
    params.budget.photons_auto = false;
    params.film.samples_per_pixel = 2;
    params.pool.mode = crate::PoolMode::Geometry;
    params.pool.max_pixels = 5;
    let mut mapper = PhotonMapper::new(Arc::clone(&scene), params).unwrap();
    for _ in 0..3 {
        mapper.iterate();
    }
    let pooled = mapper.pooled();
    let reference = reference_pooling(&mapper);
    let mut pooled_slots = 0;
    for (slot, (got, want)) in pooled.radiance.iter().zip(&reference.0).enumerate() {
        let (s_got, s_want) = (pooled.width[slot], reference.1[slot]);
        assert!(
            (s_got - s_want).abs() <= 1e-4 * s_want,
            "slot {slot}: width {s_got} against {s_want}"
        );
        pooled_slots += usize::from(s_want > 0.0);
        for c in 0..3 {
            let scale = want[c]
                .abs()
                .max(1e-3 * want.iter().copied().fold(0.0, f64::max));
            assert!(
                (got[c] - want[c]).abs() <= 2e-4 * scale + 1e-12,
                "slot {slot} channel {c}: {} against {}",
                got[c],
                want[c]
            );
        }
    }
    assert!(
        pooled_slots * 2 > reference.1.len(),
        "{pooled_slots} pooled"
    );
}

/// The pooling of `pool.rs`, one pixel at a time in f64 (its rule restated, not its code).
fn reference_pooling(m: &PhotonMapper) -> (Vec<[f64; 3]>, Vec<f32>) {
    use glam::Vec3;
    let s = &m.slots;
    let (w, h) = (m.setup.width as i32, m.setup.height as i32);
    let spp = m.setup.params.film.samples_per_pixel as usize;
    let n = s.len();
    let own: Vec<[f64; 3]> = (0..n).map(|i| m.own_radiance(i)).collect();
    // A slot whose visible point has moved between surfaces neither pools nor is pooled from.
    let valid = |i: usize| {
        m.photon_bounces[i] != super::NO_VISIBLE_POINT && !m.mixed.get(i).is_some_and(|&x| x)
    };
    let same = |p: usize, q: usize| {
        let off = s.position()[q] - s.position()[p];
        let agree = |a: Vec3, b: Vec3| (0..3).all(|c| (a[c] - b[c]).abs() <= 0.1 * a[c].max(b[c]));
        valid(q)
            && s.material_idx()[p] == s.material_idx()[q]
            && m.photon_bounces[p] == m.photon_bounces[q]
            && s.geometric_normal()[p].dot(s.geometric_normal()[q]) >= 0.9
            && s.shading_normal()[p].dot(s.shading_normal()[q]) >= 0.9
            && s.geometric_normal()[p].dot(off).abs() <= 0.1 * off.length()
            && agree(m.mean_weight[p], m.mean_weight[q])
    };
    let at = |i: usize, dx: i32, dy: i32| {
        let pixel = (i / spp) as i32;
        let (x, y) = (pixel % w + dx, pixel / w + dy);
        (x >= 0 && y >= 0 && x < w && y < h).then(|| (y * w + x) as usize * spp + i % spp)
    };
    let max = m.setup.params.pool.max_pixels as i32;
    let mut radiance = own.clone();
    let mut widths = vec![0.0f32; n];
    for p in 0..n {
        if !valid(p) {
            continue;
        }
        let near: Vec<f64> = [(1, 0), (-1, 0), (0, 1), (0, -1)]
            .into_iter()
            .filter_map(|(dx, dy)| at(p, dx, dy))
            .filter(|&q| same(p, q))
            .map(|q| f64::from(s.position()[p].distance(s.position()[q])))
            .collect();
        let footprint = near.iter().sum::<f64>() / near.len() as f64;
        if near.is_empty() || footprint <= 0.0 {
            continue;
        }
        // Geometry mode: half the window, under the clear disc's bound.
        let mut width = 0.5 * f64::from(max) * footprint;
        let freq = s.freq()[p];
        if freq.clear_level() != 0
            && let Some(clear) = freq.clear_radius(m.setup.kernel_max())
        {
            width = width.min(0.5 * clear);
        }
        if width < 0.25 * footprint {
            continue;
        }
        widths[p] = width as f32;
        let width = f64::from(width as f32);
        let normal = s.geometric_normal()[p];
        let (t, b) = normal.any_orthonormal_pair();
        // Σk·[1, u, v, uu, uv, vv] and Σk·L·[1, u, v], L demodulated by the weights.
        let mut mo = [1.0, 0.0, 0.0, 0.0, 0.0, 0.0];
        let wp = m.mean_weight[p];
        let flat = |q: usize| -> [f64; 3] {
            std::array::from_fn(|c| {
                let wq = f64::from(m.mean_weight[q][c]);
                if wq > 0.0 { own[q][c] / wq } else { 0.0 }
            })
        };
        let mut va = [flat(p), [0.0; 3], [0.0; 3]];
        // The fit is held to the range of the values it reads.
        let (mut lo, mut hi) = (flat(p), flat(p));
        for dy in -max..=max {
            for dx in -max..=max {
                let ring = dx.abs().max(dy.abs()) > 2;
                if (dx == 0 && dy == 0)
                    || dx * dx + dy * dy > max * max
                    || (ring && (dx % 2 != 0 || dy % 2 != 0))
                {
                    continue;
                }
                let Some(q) = at(p, dx, dy) else { continue };
                let off = s.position()[q] - s.position()[p];
                let d2 = f64::from(off.length_squared());
                if d2 > 9.0 * width * width || !same(p, q) {
                    continue;
                }
                let area = if ring { 4.0 } else { 1.0 };
                let k = area * (-d2 / (2.0 * width * width)).exp();
                let (u, v) = (f64::from(off.dot(t)) / width, f64::from(off.dot(b)) / width);
                for (j, x) in [1.0, u, v, u * u, u * v, v * v].into_iter().enumerate() {
                    mo[j] += k * x;
                }
                let l = flat(q);
                for c in 0..3 {
                    if k > 0.0 {
                        lo[c] = lo[c].min(l[c]);
                        hi[c] = hi[c].max(l[c]);
                    }
                    va[0][c] += k * l[c];
                    va[1][c] += k * u * l[c];
                    va[2][c] += k * v * l[c];
                }
            }
        }
        let [m0, mu, mv, muu, muv, mvv] = mo;
        let (cu, cv) = (mu / m0, mv / m0);
        let (suu, suv, svv) = (muu / m0 - cu * cu, muv / m0 - cu * cv, mvv / m0 - cv * cv);
        let det = suu * svv - suv * suv;
        for c in 0..3 {
            let mean = va[0][c] / m0;
            let value = if det.is_nan() || det <= 1e-3 {
                mean
            } else {
                let lu = va[1][c] / m0 - cu * mean;
                let lv = va[2][c] / m0 - cv * mean;
                let gu = (svv * lu - suv * lv) / det;
                let gv = (suu * lv - suv * lu) / det;
                mean - gu * cu - gv * cv
            }
            .max(lo[c])
            .min(hi[c]);
            if wp[c] > 0.0 {
                radiance[p][c] = f64::from(wp[c]) * value;
            }
        }
        // A pooled value more than three of the slot's own standard errors (1/√N of the larger
        // sum of channels) from its own estimate is refused.
        let spread = 1.0 / s.photon_count()[p].max(1.0).sqrt();
        let (mine, pooled) = (own[p].iter().sum::<f64>(), radiance[p].iter().sum::<f64>());
        if (pooled - mine).abs() > 3.0 * spread * mine.max(pooled) {
            radiance[p] = own[p];
            widths[p] = 0.0;
        }
    }
    (radiance, widths)
}

/// The pooling divides each slot's photon radiance by the mean of its visible points' weights
/// over the passes (which its τ carries) rather than by the last pass's: that running mean is
/// the plain mean of the weights the passes placed, recorded here pass by pass, on a textured
/// floor whose texel under a pixel changes with each pass's jitter.
#[test]
fn mean_weight_is_the_mean_of_the_passes_weights() {
    let scene = scene_at("../../scenes/peers/textured-room.toml", 32, 32);
    let mut params = RenderParams::preview();
    params.method = Method::FreqSppm;
    params.budget.photons_per_pass = 5_000;
    params.budget.photons_auto = false;
    let mut mapper = PhotonMapper::new(scene, params).unwrap();
    let passes = 6;
    let mut seen: Vec<Vec<glam::Vec3>> = Vec::new();
    for _ in 0..passes {
        mapper.iterate();
        seen.push(mapper.slots.weight().to_vec());
    }
    let n = mapper.slots.len();
    let mut varied = 0;
    for slot in 0..n {
        let weights: Vec<glam::Vec3> = seen.iter().map(|w| w[slot]).collect();
        let mean: [f64; 3] = std::array::from_fn(|c| {
            weights.iter().map(|w| f64::from(w[c])).sum::<f64>() / f64::from(passes)
        });
        for (c, &mean) in mean.iter().enumerate() {
            let kept = f64::from(mapper.mean_weight[slot][c]);
            assert!(
                (kept - mean).abs() <= 1e-5 * mean.max(1e-3),
                "slot {slot}: {kept} against {mean}"
            );
        }
        let (lo, hi) = weights.iter().fold((f32::INFINITY, 0.0f32), |(lo, hi), w| {
            (lo.min(w.x), hi.max(w.x))
        });
        varied += usize::from(lo > 0.0 && hi > 1.05 * lo);
    }
    // The check means something: the weights of many slots change from pass to pass.
    assert!(
        varied > n / 20,
        "{varied} of {n} slots have varying weights"
    );
}
