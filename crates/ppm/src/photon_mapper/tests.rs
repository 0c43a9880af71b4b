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

/// The shared CornellBox-Sphere at 24 × 24.
fn cornell_sphere_24() -> Arc<Scene> {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/scenes/cornell_box/CornellBox-Sphere.obj");
    let mut description = import::load(&path).unwrap();
    description.film = scene::Film {
        width: 24,
        height: 24,
    };
    Arc::new(Scene::new(description).unwrap())
}

#[test]
fn global_tags_deposit_exactly_what_packed_tags_do() {
    let scene = cornell_sphere_24();
    let mut params = RenderParams::preview();
    params.method = Method::FreqPpm;
    params.budget.photons_per_pass = 5_000;
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
