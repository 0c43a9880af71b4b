//! A checkpoint restored for a fixed scene (`Renderer::restore`). The input is the body of the
//! checkpoint; the harness writes the header and the checksum (`fppm_fuzz::checkpoint_bytes`),
//! so that mutations reach the parser. A restored renderer runs one pass when its parameters
//! are small enough for a fuzzer (memory bounds are not this target's subject).
#![no_main]

use std::sync::{Arc, LazyLock};

use fppm_fuzz::{checkpoint_bytes, checkpoint_scene};
use libfuzzer_sys::fuzz_target;
use scene::Scene;

static SCENE: LazyLock<Arc<Scene>> = LazyLock::new(checkpoint_scene);

fuzz_target!(|data: &[u8]| {
    let bytes = checkpoint_bytes(&SCENE, data);
    let Ok(mut renderer) = ppm::Renderer::restore(Arc::clone(&SCENE), &bytes) else {
        return;
    };
    let params = renderer.params();
    if params.budget.photons_per_pass <= 256
        && params.film.samples_per_pixel <= 4
        && params.budget.max_depth <= 16
    {
        renderer.iterate();
        let _ = renderer.image();
    }
});
