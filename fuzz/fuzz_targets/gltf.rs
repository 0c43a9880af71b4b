//! A `.gltf` file and its buffers: the input is the JSON, a NUL byte, then the bytes served
//! for every external buffer URI.
#![no_main]

use std::io;
use std::path::Path;

use fppm_fuzz::{fuzzed, load_and_build, split_nul};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let (json, bin) = split_nul(data);
    let (json, bin) = (json.to_vec(), bin.to_vec());
    let path = fuzzed("scene.gltf");
    let main = path.clone();
    let files = move |p: &Path| -> io::Result<Vec<u8>> {
        Ok(if p == main { json.clone() } else { bin.clone() })
    };
    load_and_build(&path, files);
});
