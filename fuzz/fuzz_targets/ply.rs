//! A PLY mesh (ASCII or binary), as the `plymesh` of a fixed pbrt scene.
#![no_main]

use std::io;
use std::path::Path;

use fppm_fuzz::{PLY_SCENE, fuzzed, load_and_build};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let ply = data.to_vec();
    let path = fuzzed("scene.pbrt");
    let (scene, mesh) = (path.clone(), fuzzed("mesh.ply"));
    let files = move |p: &Path| -> io::Result<Vec<u8>> {
        if p == scene {
            Ok(PLY_SCENE.as_bytes().to_vec())
        } else if p == mesh {
            Ok(ply.clone())
        } else {
            Err(io::ErrorKind::NotFound.into())
        }
    };
    load_and_build(&path, files);
});
