//! A checkpoint whose decompressed columns are the fuzzer's: the input's first byte picks one of
//! the saved checkpoints of the `checkpoint` target's scene (one per method, after one and after
//! two passes: `fppm_fuzz::column_checkpoints`), the rest replaces its columns, and
//! `ppm::checkpoint_surgery::join` compresses them and makes the checksum right before
//! `Renderer::restore`. The `checkpoint` target mutates the compressed bytes, which rarely
//! decompress; this one reaches the column decoder. A restored renderer runs one pass.
#![no_main]

use std::sync::{Arc, LazyLock};

use fppm_fuzz::{checkpoint_scene, column_checkpoints};
use libfuzzer_sys::fuzz_target;
use scene::Scene;

static SCENE: LazyLock<Arc<Scene>> = LazyLock::new(checkpoint_scene);
static HEADS: LazyLock<Vec<Vec<u8>>> = LazyLock::new(|| {
    column_checkpoints(&SCENE)
        .into_iter()
        .map(|(_, head, _)| head)
        .collect()
});

fuzz_target!(|data: &[u8]| {
    let Some((&which, columns)) = data.split_first() else {
        return;
    };
    let head = &HEADS[usize::from(which) % HEADS.len()];
    let bytes = ppm::checkpoint_surgery::join(head, columns);
    let Ok(mut renderer) = ppm::Renderer::restore(Arc::clone(&SCENE), &bytes) else {
        return;
    };
    renderer.iterate();
    let image = renderer.image();
    assert_eq!(image.len(), 16, "a 4 × 4 image");
});
