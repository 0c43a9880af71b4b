//! An EXR image as `fppm diff` reads it (`film::read_exr`, here from memory).
#![no_main]

use fppm_fuzz::fuzzed;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(image) = film::read_exr_bytes(data, &fuzzed("image.exr")) {
        // What `fppm diff` does next: compare it with itself.
        let _ = film::errors(&image, &image, None);
    }
});
