//! An environment map loaded from bytes and sampled. The input's first byte chooses how:
//!
//! - 0 (mod 4): the rest is an OpenEXR file, served as `sky.exr` to a tiny TOML scene
//!   (`fuzz/stubs/envmap_scene.toml`) through the in-memory file source;
//! - 1: the same as a Radiance `sky.hdr`;
//! - 2: the rest is raw texels: a height byte (1 to 16 rows, twice as many columns), a scale
//!   (f32), a rotation (three f32, degrees), then f32 texel channels (little-endian, repeated to
//!   fill the map), whatever their bits: zero, NaN, negative, subnormal, huge. They replace the
//!   scene's environment before `Scene::new`, which must refuse what it cannot sample;
//! - 3: the rest is a square equal-area map (OpenEXR) of a pbrt `infinite` light
//!   (`fuzz/stubs/envmap_scene.pbrt`), which the importer resamples to an equirectangular map.
//!
//! If the scene builds, the environment is sampled for next-event estimation (`sample_direct`),
//! evaluated (`environment_radiance`), its density asked (`pdf_environment`), and photons leave
//! it (`sample_emission`), at sample values on the edges of [0, 1).
#![no_main]

use std::sync::{Arc, LazyLock};

use fppm_fuzz::{envmap_files, envmap_pbrt_files, fuzzed};
use glam::{Vec2, Vec3};
use import::LoadOptions;
use libfuzzer_sys::fuzz_target;
use scene::{Environment, EnvironmentMap, EnvironmentRadiance, Scene, SceneDescription};

/// The scene with a constant sky, whose environment mode 2 replaces.
static BASE: LazyLock<SceneDescription> = LazyLock::new(|| {
    let text =
        fppm_fuzz::ENVMAP_SCENE.replace("file   = \"sky.exr\"", "radiance = [1.0, 1.0, 1.0]");
    import::load_toml_str(&text, &fuzzed("envmap_scene.toml")).expect("the base scene loads")
});

/// Sample values: the ends of [0, 1) and a few inside.
const US: [f32; 7] = [
    0.0,
    1e-7,
    0.25,
    0.5,
    0.7,
    0.999_999,
    1.0 - f32::EPSILON / 2.0,
];

fn f32_at(bytes: &[u8], i: usize) -> f32 {
    if bytes.is_empty() {
        return 0.0;
    }
    let b: [u8; 4] = std::array::from_fn(|k| bytes[(i * 4 + k) % bytes.len()]);
    f32::from_le_bytes(b)
}

fn raw_environment(data: &[u8]) -> Option<Environment> {
    let (&rows, rest) = data.split_first()?;
    let h = 1 + usize::from(rows) % 16;
    let w = 2 * h;
    let header = rest.get(..16)?;
    let texels = &rest[16..];
    let scale = f32_at(header, 0);
    let rotation = Vec3::new(f32_at(header, 1), f32_at(header, 2), f32_at(header, 3));
    let texels = (0..w * h)
        .map(|i| {
            Vec3::new(
                f32_at(texels, 3 * i),
                f32_at(texels, 3 * i + 1),
                f32_at(texels, 3 * i + 2),
            )
        })
        .collect();
    Some(Environment {
        radiance: EnvironmentRadiance::Map(Arc::new(EnvironmentMap {
            path: fuzzed("raw.exr"),
            width: w as u32,
            height: h as u32,
            texels,
        })),
        scale,
        to_world: Environment::rotation_degrees(rotation),
    })
}

fuzz_target!(|data: &[u8]| {
    let Some((&mode, rest)) = data.split_first() else {
        return;
    };
    let description = match mode % 4 {
        3 => {
            let (path, files) = envmap_pbrt_files(rest.to_vec());
            match import::load_from(&path, files, &LoadOptions::allow_no_emitter()) {
                Ok(d) => d,
                Err(_) => return,
            }
        }
        m @ (0 | 1) => {
            let (path, files) = envmap_files(rest.to_vec(), m == 1);
            match import::load_from(&path, files, &LoadOptions::allow_no_emitter()) {
                Ok(d) => d,
                Err(_) => return,
            }
        }
        _ => {
            let Some(environment) = raw_environment(rest) else {
                return;
            };
            let mut d = BASE.clone();
            d.environment = Some(environment);
            d
        }
    };
    let _ = description.summary();
    let Ok(scene) = Scene::new(description) else {
        return;
    };
    let lights = scene.lights();
    let point = Vec3::new(0.0, 0.5, 0.0);
    for (i, &a) in US.iter().enumerate() {
        for &b in &US {
            let u = Vec2::new(a, b);
            let u_light = US[(i + 3) % US.len()];
            if let Some(s) = lights.sample_direct(point, u_light, u) {
                assert!(s.pdf >= 0.0, "pdf {} of a direct sample", s.pdf);
                assert!(s.incoming.is_finite(), "direction {}", s.incoming);
                assert!(!s.radiance.is_nan(), "radiance {}", s.radiance);
                let pdf = lights.pdf_environment(s.incoming);
                assert!(pdf >= 0.0 && !pdf.is_nan(), "pdf_environment {pdf}");
            }
            let d = Vec3::new(a - 0.5, b - 0.5, 0.3 - a * b);
            if let Some(d) = d.try_normalize() {
                let l = lights.environment_radiance(d);
                assert!(l.is_finite(), "radiance {l} toward {d}");
                let pdf = lights.pdf_environment(d);
                assert!(
                    pdf >= 0.0 && !pdf.is_nan(),
                    "pdf_environment {pdf} toward {d}"
                );
            }
            if let Some(photon) = lights.sample_emission(u_light, u, Vec2::new(u.y, u.x)) {
                assert!(photon.direction.is_finite(), "photon direction");
                assert!(!photon.power.is_nan(), "photon power {}", photon.power);
            }
        }
    }
    // The poles and the seam of the map.
    for d in [Vec3::Y, -Vec3::Y, -Vec3::Z, Vec3::new(1e-30, 1.0, 0.0)] {
        let _ = lights.environment_radiance(d);
        let pdf = lights.pdf_environment(d);
        assert!(
            pdf >= 0.0 && !pdf.is_nan(),
            "pdf_environment {pdf} toward {d}"
        );
    }
});
