//! A lone OBJ file and its MTL library: the input is the OBJ, a NUL byte, then the MTL (served
//! for whatever `mtllib` names).
#![no_main]

use std::io;
use std::path::Path;

use fppm_fuzz::{fuzzed, load_and_build, split_nul};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let (obj, mtl) = split_nul(data);
    let (obj, mtl) = (obj.to_vec(), mtl.to_vec());
    let path = fuzzed("mesh.obj");
    let main = path.clone();
    let files = move |p: &Path| -> io::Result<Vec<u8>> {
        if p == main {
            Ok(obj.clone())
        } else if p.extension().is_some_and(|e| e == "mtl") {
            Ok(mtl.clone())
        } else {
            Err(io::ErrorKind::NotFound.into())
        }
    };
    load_and_build(&path, files);
});
