//! A checkpoint restored for a fixed scene (`Renderer::restore`). The input is the body of the
//! checkpoint; the harness writes the header and the checksum (`fppm_fuzz::checkpoint_bytes`),
//! so that mutations reach the parser. A restored renderer runs one pass when its parameters
//! are small enough for a fuzzer (memory bounds are not this target's subject).
#![no_main]

use std::sync::LazyLock;

use fppm_fuzz::{checkpoint_bytes, checkpoint_scene};
use scene::Scene;
use libfuzzer_sys::fuzz_target;

static SCENE: LazyLock<Scene> = LazyLock::new(checkpoint_scene);

fuzz_target!(|data: &[u8]| {
    let bytes = checkpoint_bytes(&SCENE, data);
    let Ok(mut renderer) = ppm::Renderer::restore(&SCENE, &bytes) else {
        return;
    };
    let params = renderer.params();
    if params.photons_per_pass <= 256 && params.samples_per_pixel <= 4 && params.max_depth <= 16 {
        renderer.iterate();
        let _ = renderer.image();
    }
});
