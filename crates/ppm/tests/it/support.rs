//! Scene fixtures and render helpers shared by the tests.

use std::path::Path;
use std::sync::Arc;

use ppm::{Method, RenderParams, Renderer};
use scene::Scene;

/// A scene from TOML text (paths relative to this directory).
pub(crate) fn scene(toml: &str) -> Arc<Scene> {
    let description = import::load_toml_str(toml, Path::new("test-scene.toml")).unwrap();
    Arc::new(Scene::new(description).unwrap())
}

/// A shared Cornell box (read in place from `../shared/scenes`), at a small film size.
pub(crate) fn cornell(name: &str, width: u32, height: u32) -> Arc<Scene> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/scenes/cornell_box")
        .join(name);
    let mut description = import::load(&path).unwrap();
    description.film = scene::Film { width, height };
    Arc::new(Scene::new(description).unwrap())
}

/// Parameters for a small test render.
pub(crate) fn params(method: Method, photons_per_pass: u32) -> RenderParams {
    let mut params = RenderParams::preview();
    params.method = method;
    params.budget.photons_per_pass = photons_per_pass;
    params.budget.photons_auto = false;
    params.seed = 7;
    params
}

/// Renders `passes` passes and returns the image.
pub(crate) fn render(scene: &Arc<Scene>, params: RenderParams, passes: u32) -> Vec<[f32; 3]> {
    let mut renderer = Renderer::new(Arc::clone(scene), params).unwrap();
    for _ in 0..passes {
        renderer.iterate();
    }
    renderer.image()
}

/// Mean of all channels of all pixels.
pub(crate) fn mean(image: &[[f32; 3]]) -> f64 {
    image
        .iter()
        .map(|p| p.iter().map(|&c| f64::from(c)).sum::<f64>() / 3.0)
        .sum::<f64>()
        / image.len() as f64
}

/// Root-mean-square difference of two images (all channels).
pub(crate) fn rmse(a: &[[f32; 3]], b: &[[f32; 3]]) -> f64 {
    let sum: f64 = a
        .iter()
        .zip(b)
        .flat_map(|(p, q)| p.iter().zip(q).map(|(&x, &y)| f64::from(x - y).powi(2)))
        .sum();
    (sum / (3 * a.len()) as f64).sqrt()
}

/// The methods that trace photons.
pub(crate) const PHOTON_METHODS: [Method; 5] = [
    Method::Ppm,
    Method::Sppm,
    Method::FreqPpm,
    Method::FreqSppm,
    Method::Appm,
];
