//! Integration tests that span several crates: one binary, one module per area.

#![allow(
    clippy::unwrap_used,
    clippy::print_stdout,
    clippy::print_stderr,
    missing_docs
)]

mod architecture;
mod mitsuba_roundtrip;
mod pbrt_by_hand;
mod rays;
mod shared_scenes;

/// `passes` path-traced passes (max depth 5, `seed`) of `scene` on a `width × height` film:
/// the renders the importer tests compare.
fn path_image(
    mut scene: scene::SceneDescription,
    (width, height): (u32, u32),
    seed: u64,
    passes: u32,
) -> Vec<[f32; 3]> {
    scene.film = scene::Film { width, height };
    let scene = std::sync::Arc::new(scene::Scene::new(scene).unwrap());
    let mut params = ppm::RenderParams::preview();
    params.method = ppm::Method::Path;
    params.budget.max_depth = 5;
    params.seed = seed;
    let mut renderer = ppm::Renderer::new(std::sync::Arc::clone(&scene), params).unwrap();
    for _ in 0..passes {
        renderer.iterate();
    }
    renderer.image()
}
