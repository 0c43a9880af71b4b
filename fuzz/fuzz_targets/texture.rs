//! An image texture (PNG, JPEG, EXR, Radiance HDR) as the texture loader decodes it, through
//! the in-memory file source: a tiny TOML scene (`fuzz/stubs/texture_scene.toml`) uses the
//! fuzzed file as an albedo, a cut-out mask and an emission texture. If it loads, the scene is
//! built (the textured emitter's sampling table), rays hit both quads (shading, cut-out, emission
//! lookups), photons leave the textured emitter, and the textures are looked up bilinearly at
//! odd coordinates with every wrap mode.
#![no_main]

use fppm_fuzz::texture_files;
use glam::{Vec2, Vec3};
use import::LoadOptions;
use libfuzzer_sys::fuzz_target;
use scene::texture::{TextureRef, Wrap};
use scene::{Ray, Scene};

/// Texture coordinates at the edges, outside [0, 1], huge and not finite.
const UVS: [(f32, f32); 10] = [
    (0.0, 0.0),
    (0.5, 0.5),
    (1.0, 1.0),
    (0.999_999_9, 1e-7),
    (-0.3, 2.7),
    (-1e-8, 1.0 + 1e-7),
    (1e30, -1e30),
    (f32::MAX, f32::MIN),
    (f32::NAN, 0.5),
    (f32::INFINITY, f32::NEG_INFINITY),
];

fuzz_target!(|data: &[u8]| {
    let (path, files) = texture_files(data.to_vec());
    let Ok(description) = import::load_from(&path, files, &LoadOptions::allow_no_emitter()) else {
        return;
    };
    let textures: Vec<TextureRef> = description
        .materials
        .iter()
        .filter_map(|m| m.textures.as_deref())
        .flat_map(|t| t.references().cloned().collect::<Vec<_>>())
        .collect();
    assert!(!textures.is_empty(), "the scene's textures loaded");
    for texture in &textures {
        let (w, h) = texture.image.resolution();
        assert!(w > 0 && h > 0, "a texture has texels");
        for wrap in [Wrap::Repeat, Wrap::Mirror, Wrap::Clamp] {
            let mut t = texture.clone();
            t.wrap = [wrap; 2];
            for (u, v) in UVS {
                let value = t.lookup(Vec2::new(u, v));
                assert!(value.is_finite(), "{value} at ({u}, {v}), {wrap:?}");
                let _ = t.alpha(Vec2::new(u, v));
            }
        }
    }
    let _ = description.summary();
    let Ok(scene) = Scene::new(description) else {
        return;
    };
    // Straight down through the emitter onto the floor, and a few slanted rays.
    for (x, z) in [(0.0, 0.0), (0.3, -0.2), (-0.45, 0.45), (0.9, 0.9)] {
        let ray = Ray::infinite(
            Vec3::new(x, 3.0, z),
            Vec3::new(0.05, -1.0, 0.02).normalize(),
        );
        if let Some(hit) = scene.intersect(&ray) {
            let _ = scene.emitted(&hit);
            let _ = scene.bsdf(&hit);
            let _ = scene.scattering_tint(&hit);
        }
    }
    let lights = scene.lights();
    for i in 0..8u8 {
        let u = f32::from(i) / 8.0;
        let v = Vec2::new(u, 1.0 - u - f32::EPSILON);
        if let Some(photon) = lights.sample_emission(u, v, Vec2::new(v.y, v.x)) {
            assert!(!photon.power.is_nan(), "photon power {}", photon.power);
        }
        let _ = lights.sample_direct(Vec3::new(0.0, 0.5, 0.0), u, v);
    }
});
