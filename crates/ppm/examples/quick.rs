//! Renders a scene with the library alone and writes a tone-mapped PNG:
//! `cargo run --release -p ppm --example quick -- SCENE [METHOD] [PASSES] [OUT.png]`
//! (environment: `QUICK_FILM=64` square film, `QUICK_MAX_DEPTH`, `QUICK_SPP`, `QUICK_RADIUS`,
//! `QUICK_PHOTONS`, `QUICK_SEED`).

#![allow(clippy::print_stdout, clippy::print_stderr, clippy::unwrap_used)]

use std::path::Path;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let scene_path = args
        .get(1)
        .ok_or("usage: quick SCENE [METHOD] [PASSES] [OUT.png]")?;
    let method = args.get(2).map_or("ppm", String::as_str);
    let passes: u32 = args.get(3).map_or(Ok(10), |s| s.parse())?;
    let out = args.get(4).map_or("quick.png", String::as_str);

    let mut description = import::load(Path::new(scene_path))?;
    if let Ok(size) = std::env::var("QUICK_FILM") {
        let size: u32 = size.parse()?;
        description.film = scene::Film {
            width: size,
            height: size,
        };
    }
    let scene = std::sync::Arc::new(scene::Scene::new(description)?);
    let mut params = ppm::RenderParams::preview();
    params.method = ppm::Method::from_name(method).ok_or("unknown method")?;
    if let Ok(depth) = std::env::var("QUICK_MAX_DEPTH") {
        params.budget.max_depth = depth.parse()?;
    }
    if let Ok(spp) = std::env::var("QUICK_SPP") {
        params.film.samples_per_pixel = spp.parse()?;
    }
    if let Ok(radius) = std::env::var("QUICK_RADIUS") {
        params.kernel.initial_radius = Some(radius.parse()?);
    }
    if let Ok(photons) = std::env::var("QUICK_PHOTONS") {
        params.budget.photons_per_pass = photons.parse()?;
        params.budget.photons_auto = false;
    }
    if let Ok(seed) = std::env::var("QUICK_SEED") {
        params.seed = seed.parse()?;
    }
    let mut renderer = ppm::Renderer::new(std::sync::Arc::clone(&scene), params)?;
    let start = std::time::Instant::now();
    for _ in 0..passes {
        renderer.iterate();
    }
    eprintln!("{passes} passes in {:.2?}", start.elapsed());

    let (width, height) = renderer.resolution();
    let image = renderer.image();
    let mean: f64 = image
        .iter()
        .map(|p| f64::from(p[0] + p[1] + p[2]) / 3.0)
        .sum::<f64>()
        / image.len() as f64;
    println!("mean radiance {mean:.6}");
    let mut bytes = Vec::with_capacity(image.len() * 3);
    for pixel in image {
        for c in pixel {
            let v = c.max(0.0);
            let srgb = if v <= 0.003_130_8 {
                12.92 * v
            } else {
                1.055 * v.powf(1.0 / 2.4) - 0.055
            };
            bytes.push((srgb.clamp(0.0, 1.0) * 255.0 + 0.5) as u8);
        }
    }
    image::save_buffer(out, &bytes, width, height, image::ExtendedColorType::Rgb8)?;
    Ok(())
}
