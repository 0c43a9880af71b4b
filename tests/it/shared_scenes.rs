//! Every shared scene that has emitters, and the suite's spectral scene, loads, builds and renders a
//! pass with every method: finite, non-negative, and not black.

use std::path::{Path, PathBuf};

use ppm::{Method, RenderParams, Renderer};
use scene::{Film, Scene};

fn shared(relative: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../shared/scenes")
        .join(relative)
}

const LIT_SCENES: &[&str] = &[
    "cornell_box/CornellBox-Original.obj",
    "cornell_box/CornellBox-Mirror.obj",
    "cornell_box/CornellBox-Sphere.obj",
    "cornell_box/CornellBox-Glossy.obj",
    "cornell_box/CornellBox-Water.obj",
    "cornell_box/CornellBox-Empty-CO.obj",
    "cornell_box/CornellBox-Empty-RG.obj",
    "cornell_box/CornellBox-Empty-Squashed.obj",
    "cornell_box/CornellBox-Empty-White.obj",
    "gltf/EmissiveStrengthTest/glTF/EmissiveStrengthTest.gltf",
    "gltf/EmissiveStrengthTest/glTF-Binary/EmissiveStrengthTest.glb",
    "gltf/LightsPunctualLamp/glTF/LightsPunctualLamp.gltf",
    "mitsuba3/scenes/cbox/cbox.xml",
    "mitsuba3/scenes/cbox/cbox-rgb.xml",
    "mitsuba3/scenes/cbox/cbox-spectral.xml",
    "pbrt-v4/killeroos/killeroo-simple.pbrt",
    "pbrt-v4/killeroos/killeroo-gold.pbrt",
    "pbrt-v4/veach-mis/veach-mis.pbrt",
];

#[test]
fn every_lit_shared_scene_renders_with_every_method() {
    for relative in LIT_SCENES {
        renders_with_every_method(&shared(relative), relative);
    }
}

/// The suite's spectral scene: smooth and rough conductors, a dispersive glass, a blackbody lamp.
#[test]
fn the_spectral_scene_renders_with_every_method() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/spectral-metals.toml");
    renders_with_every_method(&path, "spectral-metals.toml");
}

fn renders_with_every_method(path: &Path, relative: &str) {
    {
        let mut description = import::load(path).unwrap();
        description.film = Film {
            width: 12,
            height: 12,
        };
        let scene = std::sync::Arc::new(Scene::new(description).unwrap());
        for method in Method::ALL {
            let mut params = RenderParams::preview();
            params.method = method;
            params.budget.photons_per_pass = 3_000;
            let mut renderer = Renderer::new(std::sync::Arc::clone(&scene), params).unwrap();
            renderer.iterate();
            let image = renderer.image();
            assert!(
                image.iter().flatten().all(|c| c.is_finite() && *c >= 0.0),
                "{relative} with {method}: non-finite or negative pixel"
            );
            let total: f32 = image.iter().flatten().sum();
            assert!(total > 0.0, "{relative} with {method}: black image");
        }
    }
}
