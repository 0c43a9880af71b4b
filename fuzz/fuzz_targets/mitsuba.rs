//! A Mitsuba 3 XML scene; the PLY, OBJ and `.spd` files it names are served as stubs,
//! includes and other files are not found.
#![no_main]

use fppm_fuzz::{fuzzed, load_and_build, with_stubs};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let path = fuzzed("scene.xml");
    load_and_build(&path, with_stubs(path.clone(), data.to_vec()));
});
