//! A TOML scene file; the OBJ, MTL and glTF files it names are served as stubs.
#![no_main]

use fppm_fuzz::{fuzzed, load_and_build, with_stubs};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let path = fuzzed("scene.toml");
    load_and_build(&path, with_stubs(path.clone(), data.to_vec()));
});
