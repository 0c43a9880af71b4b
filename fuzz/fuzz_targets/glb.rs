//! A binary glTF (`.glb`) file; external buffer URIs are not found.
#![no_main]

use std::io;
use std::path::Path;

use fppm_fuzz::{fuzzed, load_and_build};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let glb = data.to_vec();
    let path = fuzzed("scene.glb");
    let main = path.clone();
    let files = move |p: &Path| -> io::Result<Vec<u8>> {
        if p == main {
            Ok(glb.clone())
        } else {
            Err(io::ErrorKind::NotFound.into())
        }
    };
    load_and_build(&path, files);
});
