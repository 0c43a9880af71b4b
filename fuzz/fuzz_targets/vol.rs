//! A Mitsuba `.vol` density grid, as the grid of a fixed TOML scene's medium; then free
//! flights and transmittances through it.
#![no_main]

use std::io;
use std::path::Path;

use fppm_fuzz::{VOL_SCENE, build, fuzzed};
use glam::Vec3;
use import::LoadOptions;
use libfuzzer_sys::fuzz_target;
use scene::FreeFlight;

fuzz_target!(|data: &[u8]| {
    let vol = data.to_vec();
    let path = fuzzed("scene.toml");
    let (scene_path, grid) = (path.clone(), fuzzed("smoke.vol"));
    let files = move |p: &Path| -> io::Result<Vec<u8>> {
        if p == scene_path {
            Ok(VOL_SCENE.as_bytes().to_vec())
        } else if p == grid {
            Ok(vol.clone())
        } else {
            Err(io::ErrorKind::NotFound.into())
        }
    };
    let Ok(description) = import::load_from(&path, files, &LoadOptions::allow_no_emitter()) else {
        return;
    };
    let Some(scene) = build(description) else {
        return;
    };
    let Some(medium) = scene.media().list.first() else {
        return;
    };
    // A fixed sequence of numbers in [0, 1), the edges included.
    let mut state = 0u32;
    let mut u = move || {
        state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        (state >> 8) as f32 / (1u32 << 24) as f32
    };
    for (origin, direction) in [
        (Vec3::new(-2.0, 0.1, 0.2), Vec3::X),
        (Vec3::new(0.0, 2.0, 0.0), -Vec3::Y),
        (Vec3::new(-1.0, -1.0, -1.0), Vec3::ONE.normalize()),
        (Vec3::new(1.0, 1.0, 1.0), Vec3::Z),
    ] {
        let tr = medium.transmittance_along(origin, direction, 4.0, &mut u);
        assert!(
            tr.is_finite() && tr.min_element() >= 0.0 && tr.max_element() <= 1.0,
            "{tr}"
        );
        match medium.sample_free_flight(origin, direction, 4.0, Vec3::splat(1.0 / 3.0), &mut u) {
            FreeFlight::Scatter { t, weight } => {
                assert!(
                    (0.0..=4.0).contains(&t) && weight.is_finite(),
                    "{t} {weight}"
                );
            }
            FreeFlight::Pass { weight } => assert!(weight.is_finite(), "{weight}"),
        }
    }
});
