//! Saving and restoring a render gives the image of an uninterrupted run, bit for bit.

use ppm::{Method, Renderer, StateError, StateHeader};

use crate::support::{cornell, params};

#[test]
fn resumed_render_is_bit_identical_to_an_uninterrupted_one() {
    let scene = cornell("CornellBox-Sphere.obj", 20, 20);
    for method in Method::ALL {
        let p = params(method, 5_000);
        let mut straight = Renderer::new(&scene, p).unwrap();
        for _ in 0..4 {
            straight.iterate();
        }

        let mut first = Renderer::new(&scene, p).unwrap();
        first.iterate();
        first.iterate();
        let bytes = first.save_state("scene: cornell sphere");
        drop(first);
        let header = StateHeader::read(&bytes).unwrap();
        assert_eq!(header.passes, 2);
        assert_eq!(header.note, "scene: cornell sphere");
        assert_eq!(header.params, p);
        let mut resumed = Renderer::restore(&scene, &bytes).unwrap();
        assert_eq!(resumed.passes(), 2);
        resumed.iterate();
        resumed.iterate();

        let a = straight.image();
        let b = resumed.image();
        let same = a
            .iter()
            .zip(&b)
            .all(|(x, y)| x.map(f32::to_bits) == y.map(f32::to_bits));
        assert!(same, "{method}: resumed image differs");
        assert_eq!(straight.photons_emitted(), resumed.photons_emitted());
    }
}

#[test]
fn checkpoints_of_another_scene_version_or_corrupt_bytes_are_refused() {
    let scene = cornell("CornellBox-Sphere.obj", 8, 8);
    let other = cornell("CornellBox-Original.obj", 8, 8);
    let mut renderer = Renderer::new(&scene, params(Method::Ppm, 1_000)).unwrap();
    renderer.iterate();
    let bytes = renderer.save_state("");

    assert!(matches!(
        Renderer::restore(&other, &bytes),
        Err(StateError::SceneMismatch { .. })
    ));
    assert!(matches!(
        Renderer::restore(&scene, b"not a checkpoint"),
        Err(StateError::NotACheckpoint)
    ));
    let truncated = &bytes[..bytes.len() - 100];
    assert!(matches!(
        Renderer::restore(&scene, truncated),
        Err(StateError::Corrupt)
    ));
    let mut flipped = bytes.clone();
    let middle = flipped.len() / 2;
    flipped[middle] ^= 1;
    assert!(matches!(
        Renderer::restore(&scene, &flipped),
        Err(StateError::Corrupt)
    ));
    let mut newer = bytes;
    newer[8] = newer[8].wrapping_add(1);
    assert!(matches!(
        Renderer::restore(&scene, &newer),
        Err(StateError::Version { .. })
    ));
}

/// FNV-1a (64-bit), the checksum that ends a checkpoint, written from its definition.
fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |hash, &b| {
        (hash ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

/// Found by the `checkpoint` fuzz target: a checkpoint whose checksum is right but whose slot
/// radius is zero was restored, and the next pass's update rule failed its assertion (in a
/// release build it divides by R² = 0). It is refused as corrupt.
#[test]
fn checkpoint_with_a_zero_radius_is_refused() {
    let scene = cornell("CornellBox-Sphere.obj", 4, 4);
    let mut p = params(Method::Ppm, 1);
    // A radius no computation produces, to find the slots' radii in the bytes: the parameters
    // store it first, then every slot that no photon reached still has it.
    let radius = 0.012_345_678_9_f64;
    p.initial_radius = Some(radius);
    let mut renderer = Renderer::new(&scene, p).unwrap();
    renderer.iterate();
    let mut bytes = renderer.save_state("");
    let pattern = radius.to_le_bytes();
    let at: Vec<usize> = bytes
        .windows(8)
        .enumerate()
        .filter(|(_, w)| *w == pattern)
        .map(|(i, _)| i)
        .collect();
    assert!(
        at.len() >= 2,
        "the initial radius is stored and kept by a slot"
    );
    bytes[at[1]..at[1] + 8].copy_from_slice(&0.0f64.to_le_bytes());
    let end = bytes.len() - 8;
    let checksum = fnv1a(&bytes[..end]);
    bytes[end..].copy_from_slice(&checksum.to_le_bytes());
    match Renderer::restore(&scene, &bytes) {
        Err(e) => assert_eq!(e, StateError::Corrupt),
        Ok(mut restored) => {
            restored.iterate();
            panic!("a zero radius was restored and rendered");
        }
    }
}

/// Found by the `checkpoint` fuzz target: a checkpoint whose photon count was near `u64::MAX`
/// was restored, and the next pass's photon indices overflowed (`photon_pass.rs`). The count
/// must be the passes times the photons per pass.
#[test]
fn checkpoint_with_an_impossible_photon_count_is_refused() {
    let scene = cornell("CornellBox-Sphere.obj", 4, 4);
    let photons = 777;
    let mut renderer = Renderer::new(&scene, params(Method::Ppm, photons)).unwrap();
    renderer.iterate();
    let mut bytes = renderer.save_state("");
    // The pass count (1) is followed by the photons emitted.
    let mut pattern = 1u32.to_le_bytes().to_vec();
    pattern.extend_from_slice(&u64::from(photons).to_le_bytes());
    let at = bytes
        .windows(pattern.len())
        .position(|w| w == pattern)
        .expect("passes and photons emitted are stored side by side")
        + 4;
    bytes[at..at + 8].copy_from_slice(&(u64::MAX - 5).to_le_bytes());
    let end = bytes.len() - 8;
    let checksum = fnv1a(&bytes[..end]);
    bytes[end..].copy_from_slice(&checksum.to_le_bytes());
    match Renderer::restore(&scene, &bytes) {
        Err(e) => assert_eq!(e, StateError::Corrupt),
        Ok(mut restored) => {
            restored.iterate();
            panic!("an impossible photon count was restored and rendered");
        }
    }
}

/// Found by the `checkpoint` fuzz target: a path-tracer checkpoint claiming `u32::MAX` passes
/// was restored, and the next pass overflowed the pass counter (`path.rs`).
#[test]
fn checkpoint_with_no_pass_left_is_refused() {
    let scene = cornell("CornellBox-Sphere.obj", 4, 4);
    let mut renderer = Renderer::new(&scene, params(Method::Path, 1)).unwrap();
    renderer.iterate();
    let mut bytes = renderer.save_state("");
    // The pass count (1) is followed by the number of pixels (16).
    let mut pattern = 1u32.to_le_bytes().to_vec();
    pattern.extend_from_slice(&16u64.to_le_bytes());
    let at = bytes
        .windows(pattern.len())
        .position(|w| w == pattern)
        .expect("passes and pixel count are stored side by side");
    bytes[at..at + 4].copy_from_slice(&u32::MAX.to_le_bytes());
    let end = bytes.len() - 8;
    let checksum = fnv1a(&bytes[..end]);
    bytes[end..].copy_from_slice(&checksum.to_le_bytes());
    match Renderer::restore(&scene, &bytes) {
        Err(e) => assert_eq!(e, StateError::Corrupt),
        Ok(mut restored) => {
            restored.iterate();
            panic!("a checkpoint with u32::MAX passes was restored and rendered");
        }
    }
}
