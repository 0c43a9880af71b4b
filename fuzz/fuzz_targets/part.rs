//! A work unit's part (`ppm::Part::from_bytes`) and what `fppm merge` does with it
//! (`crates/cli/src/units.rs`): add its sums to the merge's total, take the mean image and
//! tone-map it. The input is framed by `fppm_fuzz::part_bytes` (raw file, fields and compressed
//! sums with the checksum made right, or fields and decompressed sums), so that mutations reach
//! every layer.
#![no_main]

use fppm_fuzz::{PART_PLAN, part_bytes};
use libfuzzer_sys::fuzz_target;
use ppm::{Part, PassSums};

fuzz_target!(|data: &[u8]| {
    let (bytes, pixels) = part_bytes(data);
    let Ok(part) = Part::from_bytes(&bytes, PART_PLAN, pixels) else {
        return;
    };
    assert_eq!(
        part.sums.sums.len(),
        pixels,
        "a part holds one sum per pixel"
    );
    // What it reads is what it would write.
    let again = Part::from_bytes(&part.to_bytes(), PART_PLAN, pixels);
    assert_eq!(
        again.as_ref(),
        Ok(&part),
        "a part read back is the same part"
    );

    // The merge: the part's sums into a total, twice (as two units would), refused whole on
    // overflow; then the mean image, which is finite by construction (i128 sums over 2⁶⁴).
    let mut total = PassSums::new(pixels);
    for _ in 0..2 {
        let before = total.clone();
        if !total.add(&part.sums) {
            assert_eq!(total, before, "a refused addition adds nothing");
        }
    }
    let pixels_rgb = total.image();
    assert!(
        pixels_rgb.iter().flatten().all(|v| v.is_finite()),
        "the merged image is finite"
    );
    let image = film::Image::new(pixels, 1, pixels_rgb);
    let exposure = film::auto_exposure(&image);
    let _ = film::to_srgb8(&image, film::Tonemap::linear(exposure));
});
