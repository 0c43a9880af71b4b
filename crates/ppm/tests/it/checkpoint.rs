//! Saving and restoring a render gives the image of an uninterrupted run, bit for bit.

use ppm::{Method, Renderer, StateError, StateHeader};

use crate::support::{cornell, params};

#[test]
fn resumed_render_is_bit_identical_to_an_uninterrupted_one() {
    let scene = cornell("CornellBox-Sphere.obj", 20, 20);
    let cases = Method::ALL.into_iter().map(|m| (m, false)).chain([
        (Method::Sppm, true),
        (Method::FreqPpm, true),
        (Method::Appm, true),
    ]);
    for (method, light_tracing) in cases {
        let mut p = params(method, 5_000);
        p.connections.light_tracing = light_tracing;
        let mut straight = Renderer::new(std::sync::Arc::clone(&scene), p).unwrap();
        for _ in 0..4 {
            straight.iterate();
        }

        let mut first = Renderer::new(std::sync::Arc::clone(&scene), p).unwrap();
        first.iterate();
        first.iterate();
        let bytes = first.save_state("scene: cornell sphere");
        drop(first);
        let header = StateHeader::read(&bytes).unwrap();
        assert_eq!(header.passes, 2);
        assert_eq!(header.note, "scene: cornell sphere");
        assert_eq!(header.params, p);
        let mut resumed = Renderer::restore(std::sync::Arc::clone(&scene), &bytes).unwrap();
        assert_eq!(resumed.passes(), 2);
        resumed.iterate();
        resumed.iterate();

        let a = straight.image();
        let b = resumed.image();
        let same = a
            .iter()
            .zip(&b)
            .all(|(x, y)| x.map(f32::to_bits) == y.map(f32::to_bits));
        assert!(
            same,
            "{method} (light tracing {light_tracing}): resumed image differs"
        );
        assert_eq!(straight.photons_emitted(), resumed.photons_emitted());
    }
}

#[test]
fn checkpoints_of_another_scene_version_or_corrupt_bytes_are_refused() {
    let scene = cornell("CornellBox-Sphere.obj", 8, 8);
    let other = cornell("CornellBox-Original.obj", 8, 8);
    let mut renderer =
        Renderer::new(std::sync::Arc::clone(&scene), params(Method::Ppm, 1_000)).unwrap();
    renderer.iterate();
    let bytes = renderer.save_state("");

    assert!(matches!(
        Renderer::restore(std::sync::Arc::clone(&other), &bytes),
        Err(StateError::SceneMismatch { .. })
    ));
    assert!(matches!(
        Renderer::restore(std::sync::Arc::clone(&scene), b"not a checkpoint"),
        Err(StateError::NotACheckpoint)
    ));
    let truncated = &bytes[..bytes.len() - 100];
    assert!(matches!(
        Renderer::restore(std::sync::Arc::clone(&scene), truncated),
        Err(StateError::Corrupt)
    ));
    let mut flipped = bytes.clone();
    let middle = flipped.len() / 2;
    flipped[middle] ^= 1;
    assert!(matches!(
        Renderer::restore(std::sync::Arc::clone(&scene), &flipped),
        Err(StateError::Corrupt)
    ));
    let mut newer = bytes;
    newer[8] = newer[8].wrapping_add(1);
    assert!(matches!(
        Renderer::restore(std::sync::Arc::clone(&scene), &newer),
        Err(StateError::Version { .. })
    ));
}

/// A checkpoint knows which texture files its scene read: the same scene with another texture
/// file (even with the same texels) or with none has another fingerprint.
#[test]
fn the_fingerprint_covers_textures() {
    // A 1 × 1 RGBA PNG.
    let png: Vec<u8> = (0..)
        .step_by(2)
        .take_while(|&i| i < PNG_HEX.len())
        .map(|i| u8::from_str_radix(&PNG_HEX[i..i + 2], 16).unwrap())
        .collect();
    let dir = std::env::temp_dir().join(format!("fppm-ppm-fingerprint-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("a.png"), &png).unwrap();
    std::fs::write(dir.join("b.png"), &png).unwrap();
    let scene = |albedo: &str| {
        let text = format!(
            "format = 1\n[materials.m]\ntype = \"diffuse\"\nalbedo = {albedo}\nemission = [1, 1, 1]\n[[shapes]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"m\"\n"
        );
        import::load_toml_str(&text, &dir.join("scene.toml")).unwrap()
    };
    let a = scene("{ texture = \"a.png\" }").fingerprint();
    let b = scene("{ texture = \"b.png\" }").fingerprint();
    let plain = scene("[1, 1, 1]").fingerprint();
    assert_ne!(a, b);
    assert_ne!(a, plain);
    assert_eq!(a, scene("{ texture = \"a.png\" }").fingerprint());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Vertex tangents (a normal map's frame) change the fingerprint; a scene without them keeps
/// the one it had.
#[test]
fn the_fingerprint_covers_tangents() {
    let mut scene = cornell("CornellBox-Sphere.obj", 4, 4).description().clone();
    let plain = scene.fingerprint();
    scene.triangles[0].tangents = Some([[1.0, 0.0, 0.0, 1.0]; 3]);
    let with = scene.fingerprint();
    scene.triangles[0].tangents = Some([[1.0, 0.0, 0.0, -1.0]; 3]);
    let mirrored = scene.fingerprint();
    assert_ne!(plain, with);
    assert_ne!(with, mirrored);
    scene.triangles[0].tangents = None;
    assert_eq!(plain, scene.fingerprint());
}

const PNG_HEX: &str = "89504e470d0a1a0a0000000d49484452000000010000000108060000001f15c4890000000d4944415478da636460f85f0f0002870180eb47ba920000000049454e44ae426082";

/// A checkpoint with its columns changed by `edit` (decompressed, edited, recompressed, the
/// checksum made right), so that the parser, not the checksum, has to refuse it.
fn edited(bytes: &[u8], edit: impl FnOnce(&mut Vec<u8>, &mut Vec<u8>)) -> Vec<u8> {
    let (mut head, mut body) = ppm::checkpoint_surgery::split(bytes).expect("a checkpoint");
    edit(&mut head, &mut body);
    ppm::checkpoint_surgery::join(&head, &body)
}

/// Found by the `checkpoint` fuzz target: a checkpoint whose checksum is right but whose slot
/// radius is zero was restored, and the next pass's update rule failed its assertion (in a
/// release build it divides by R² = 0). It is refused as corrupt.
#[test]
fn checkpoint_with_a_zero_radius_is_refused() {
    let scene = cornell("CornellBox-Sphere.obj", 4, 4);
    let mut p = params(Method::Ppm, 1);
    // A radius no computation produces, to find a slot's radius in the columns: every slot
    // that no photon reached still has it.
    let radius = 0.012_345_678_9_f64;
    p.kernel.initial_radius = Some(radius);
    let mut renderer = Renderer::new(std::sync::Arc::clone(&scene), p).unwrap();
    renderer.iterate();
    let bytes = edited(&renderer.save_state(""), |_, body| {
        let pattern = radius.to_le_bytes();
        let at = body
            .windows(8)
            .position(|w| w == pattern)
            .expect("a slot keeps the initial radius");
        body[at..at + 8].copy_from_slice(&0.0f64.to_le_bytes());
    });
    match Renderer::restore(std::sync::Arc::clone(&scene), &bytes) {
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
    let mut renderer =
        Renderer::new(std::sync::Arc::clone(&scene), params(Method::Ppm, photons)).unwrap();
    renderer.iterate();
    let bytes = edited(&renderer.save_state(""), |_, body| {
        // The columns start with the photons emitted.
        assert_eq!(body[..8], u64::from(photons).to_le_bytes());
        body[..8].copy_from_slice(&(u64::MAX - 5).to_le_bytes());
    });
    match Renderer::restore(std::sync::Arc::clone(&scene), &bytes) {
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
    let mut renderer =
        Renderer::new(std::sync::Arc::clone(&scene), params(Method::Path, 1)).unwrap();
    renderer.iterate();
    let bytes = edited(&renderer.save_state(""), |head, _| {
        // The head ends with the pass count.
        let at = head.len() - 4;
        assert_eq!(head[at..], 1u32.to_le_bytes());
        head[at..].copy_from_slice(&u32::MAX.to_le_bytes());
    });
    match Renderer::restore(std::sync::Arc::clone(&scene), &bytes) {
        Err(e) => assert_eq!(e, StateError::Corrupt),
        Ok(mut restored) => {
            restored.iterate();
            panic!("a checkpoint with u32::MAX passes was restored and rendered");
        }
    }
}
