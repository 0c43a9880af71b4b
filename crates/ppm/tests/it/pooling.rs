//! The image-space pooling of the photon mappers (`pool`): on a plane under a point light it
//! keeps the analytic pixel averages; at a point light's hard shadow edge the frequency-sized
//! width keeps the edge (and lowers the noise beside it) where a width blind to the light blurs
//! it; on a silhouette, whose pixels see two surfaces, it keeps their mix.

use std::f64::consts::PI;

use glam::{Vec2, Vec3};
use ppm::{Aov, Method, PoolMode, Renderer};

use crate::analytic::{PLANE, plane_reference};
use crate::light_tracing::bright_region_errors;
use crate::support::{params, scene};

#[test]
fn pooling_keeps_the_analytic_pixel_averages_of_a_plane_under_a_point_light() {
    let scene = scene(PLANE);
    let reference = plane_reference(&scene);
    let mut errors = Vec::new();
    for mode in [PoolMode::Off, PoolMode::Frequency] {
        let mut p = params(Method::FreqSppm, 100_000);
        // A pixel's footprint is about 0.13 across at the plane's centre.
        p.kernel.initial_radius = Some(0.05);
        p.connections.direct_lighting = false;
        p.pool.mode = mode;
        let mut renderer = Renderer::new(scene.clone(), p).unwrap();
        for _ in 0..8 {
            renderer.iterate();
        }
        let image = renderer.image();
        let (ratio, rel, n) = bright_region_errors(&image, &reference);
        // Over the whole lit plane, whose 1/d³ fall-off is curved at the scale of a few pixels
        // of this 20 × 20 film.
        let peak = reference.iter().copied().fold(0.0, f64::max);
        let lit: Vec<(f64, f64)> = image
            .iter()
            .zip(&reference)
            .filter(|(_, e)| **e >= 0.05 * peak)
            .map(|(p, &e)| (f64::from(p[1]), e))
            .collect();
        let plane_rel = lit.iter().map(|(g, e)| (g - e).abs() / e).sum::<f64>() / lit.len() as f64;
        println!(
            "pool {}: ratio {ratio:.4}, mean relative error {rel:.4} (bright), {plane_rel:.4} (lit)",
            mode.name()
        );
        assert!(n >= 40, "only {n} pixels in the bright region");
        assert!(
            (ratio - 1.0).abs() < 0.015,
            "pool {}: mean ratio to the analytic radiance {ratio}",
            mode.name()
        );
        let width = renderer.aov(Aov::PoolWidth).unwrap();
        let pooled = width.iter().filter(|&&w| w > 0.0).count();
        match mode {
            PoolMode::Off => assert_eq!(pooled, 0),
            // The light on a plane is smooth: nearly every pixel pools.
            _ => assert!(
                pooled * 10 >= width.len() * 9,
                "{pooled} of {} pooled",
                width.len()
            ),
        }
        // Measured 0.025 either way (photon noise of 800 000 photons).
        assert!(
            rel < 0.05,
            "pool {}: mean relative error {rel}",
            mode.name()
        );
        errors.push(plane_rel);
    }
    // Measured 0.042 unpooled and 0.046 pooled: here the blur the prediction allows costs
    // about what the pooling saves, and no more.
    assert!(
        errors[1] < 1.15 * errors[0],
        "pooling blurred the plane's fall-off: {errors:?} (off, freq)"
    );
}

/// The plane under the point light, with a small roof between them: its shadow on the plane is
/// x ∈ [0, 2], |z| ≤ 0.3, whose edge x = 0 runs across the middle of the image.
const SHADOW: &str = r#"
format = 1
[camera]
position = [0.0, 2.0, 2.0]
look_at = [0.0, 0.0, 0.0]
fov_y = 50.0
[film]
width = 48
height = 48
[materials.floor]
type = "diffuse"
albedo = [0.8, 0.8, 0.8]
[[shapes]]
type = "quad"
corner = [-100.0, 0.0, 100.0]
edge1 = [200.0, 0.0, 0.0]
edge2 = [0.0, 0.0, -200.0]
material = "floor"
[[shapes]]
type = "quad"
corner = [0.0, 0.5, -0.15]
edge1 = [1.0, 0.0, 0.0]
edge2 = [0.0, 0.0, 0.3]
material = "floor"
[[lights]]
type = "point"
position = [0.0, 1.0, 0.0]
intensity = [10.0, 10.0, 10.0]
"#;

/// The exact pixel averages of [`SHADOW`]'s floor (8 × 8 rays per pixel), `None` for a pixel
/// where a ray meets the roof first.
fn shadow_reference(scene: &scene::Scene) -> Vec<Option<f64>> {
    let (width, height) = scene.camera().resolution();
    let light = Vec3::new(0.0, 1.0, 0.0);
    let in_roof = |p: Vec3| (0.0..=1.0).contains(&p.x) && p.z.abs() <= 0.15;
    let mut out = Vec::new();
    for y in 0..height {
        for x in 0..width {
            let mut sum = 0.0;
            let mut seen = true;
            for j in 0..8 {
                for i in 0..8 {
                    let film = Vec2::new(
                        x as f32 + (i as f32 + 0.5) / 8.0,
                        y as f32 + (j as f32 + 0.5) / 8.0,
                    );
                    let ray = scene.camera().generate_ray(film, Vec2::splat(0.5));
                    let t_roof = (0.5 - ray.origin.y) / ray.direction.y;
                    if t_roof > 0.0 && in_roof(ray.at(t_roof)) {
                        seen = false;
                    }
                    let t = -ray.origin.y / ray.direction.y;
                    if t <= 0.0 {
                        continue;
                    }
                    let p = ray.at(t);
                    // The segment to the light crosses y = 0.5 halfway.
                    if in_roof((p + light) * 0.5) {
                        continue;
                    }
                    let to_light = light - p;
                    let d2 = f64::from(to_light.length_squared());
                    sum += 0.8 / PI * 10.0 * f64::from(to_light.y) / d2.sqrt() / d2;
                }
            }
            out.push(seen.then_some(sum / 64.0));
        }
    }
    out
}

#[test]
fn a_hard_shadow_edge_keeps_its_width_where_the_light_says_so() {
    let scene = scene(SHADOW);
    let reference = shadow_reference(&scene);
    let width = scene.camera().resolution().0 as usize;
    // The band: floor pixels within two pixels of one that the edge crosses (reference
    // strictly between 10 % and 90 % of its lit neighbour), where a blur shows.
    let partial: Vec<bool> = (0..reference.len())
        .map(|i| {
            let (x, y) = (i % width, i / width);
            let Some(value) = reference[i] else {
                return false;
            };
            let row = &reference[y * width..(y + 1) * width];
            let lit = row[x.saturating_sub(3)]
                .unwrap_or(0.0)
                .max(row[(x + 3).min(width - 1)].unwrap_or(0.0));
            lit > 0.0 && value > 0.1 * lit && value < 0.9 * lit && x > 0 && x + 1 < width
        })
        .collect();
    let band: Vec<usize> = (0..reference.len())
        .filter(|&i| {
            let (x, y) = ((i % width) as i64, (i / width) as i64);
            reference[i].is_some()
                && (-2..=2).any(|d| {
                    let xx = x + d;
                    xx >= 0 && (xx as usize) < width && partial[(y as usize) * width + xx as usize]
                })
        })
        .collect();
    assert!(
        band.len() >= 40,
        "only {} pixels in the edge band",
        band.len()
    );
    let mut bias = Vec::new();
    for mode in [PoolMode::Off, PoolMode::Frequency, PoolMode::Geometry] {
        let mut p = params(Method::FreqSppm, 100_000);
        // About a pixel's footprint at the edge.
        p.kernel.initial_radius = Some(0.05);
        p.connections.direct_lighting = false;
        p.pool.mode = mode;
        let mut renderer = Renderer::new(scene.clone(), p).unwrap();
        for _ in 0..8 {
            renderer.iterate();
        }
        let image = renderer.image();
        // Mean absolute error over the band, relative to the band's mean radiance: a blurred
        // edge is off on both sides of it.
        let (mut error, mut total) = (0.0, 0.0);
        for &i in &band {
            let expected = reference[i].unwrap_or(0.0);
            error += (f64::from(image[i][1]) - expected).abs();
            total += expected;
        }
        let error = error / total;
        println!(
            "pool {}: band error {error:.4} over {} pixels",
            mode.name(),
            band.len()
        );
        bias.push(error);
    }
    // The frequency width keeps the edge as sharp as the unpooled image, and lowers the noise
    // beside it (measured 0.071 unpooled, 0.039 pooled) ...
    assert!(
        bias[1] < 0.8 * bias[0],
        "frequency pooling blurred the edge: {bias:?} (off, freq, geometry)"
    );
    // ... where the same pooling blind to the light blurs it (0.045 against 0.038; 0.052 before
    // slots refused pooled values their own photons contradict, which spares the control's edge
    // too).
    assert!(
        bias[2] > 1.15 * bias[1],
        "the geometry-only width should blur the edge: {bias:?} (off, freq, geometry)"
    );
}

/// The exact pixel averages of [`SHADOW`] lit by its point light alone (8 × 8 rays per pixel),
/// the roof's top included, and whether each pixel sees both the roof and the floor.
fn direct_reference_with_roof(scene: &scene::Scene) -> Vec<(f64, bool)> {
    let (width, height) = scene.camera().resolution();
    let light = Vec3::new(0.0, 1.0, 0.0);
    let in_roof = |p: Vec3| (0.0..=1.0).contains(&p.x) && p.z.abs() <= 0.15;
    let radiance = |p: Vec3, normal_y: f32| {
        let to_light = light - p;
        let d2 = f64::from(to_light.length_squared());
        0.8 / PI * 10.0 * f64::from(to_light.y * normal_y) / d2.sqrt() / d2
    };
    let mut out = Vec::new();
    for y in 0..height {
        for x in 0..width {
            let (mut sum, mut roof, mut floor) = (0.0, false, false);
            for j in 0..8 {
                for i in 0..8 {
                    let film = Vec2::new(
                        x as f32 + (i as f32 + 0.5) / 8.0,
                        y as f32 + (j as f32 + 0.5) / 8.0,
                    );
                    let ray = scene.camera().generate_ray(film, Vec2::splat(0.5));
                    let t_roof = (0.5 - ray.origin.y) / ray.direction.y;
                    if t_roof > 0.0 && in_roof(ray.at(t_roof)) {
                        roof = true;
                        sum += radiance(ray.at(t_roof), 1.0);
                        continue;
                    }
                    let t = -ray.origin.y / ray.direction.y;
                    if t <= 0.0 {
                        continue;
                    }
                    floor = true;
                    let p = ray.at(t);
                    if !in_roof((p + light) * 0.5) {
                        sum += radiance(p, 1.0);
                    }
                }
            }
            out.push((sum / 64.0, roof && floor));
        }
    }
    out
}

#[test]
fn a_silhouette_keeps_the_light_of_both_surfaces_it_sees() {
    // A pixel on the roof's outline sees the bright roof in some passes and the floor behind it
    // in others: its estimate sums both, and pooling it with the neighbours of whichever
    // surface the last pass saw would replace that mix by one surface's light.
    let scene = scene(SHADOW);
    let reference = direct_reference_with_roof(&scene);
    let outline: Vec<usize> = (0..reference.len()).filter(|&i| reference[i].1).collect();
    assert!(
        outline.len() >= 30,
        "only {} pixels on the outline",
        outline.len()
    );
    let mut errors = Vec::new();
    for mode in [PoolMode::Off, PoolMode::Frequency, PoolMode::Geometry] {
        let mut p = params(Method::FreqSppm, 100_000);
        p.kernel.initial_radius = Some(0.05);
        p.connections.direct_lighting = false;
        // The point light's direct light alone, which the reference integrates.
        p.budget.max_depth = 1;
        p.pool.mode = mode;
        let mut renderer = Renderer::new(scene.clone(), p).unwrap();
        for _ in 0..16 {
            renderer.iterate();
        }
        let image = renderer.image();
        let (mut error, mut total) = (0.0, 0.0);
        for &i in &outline {
            error += (f64::from(image[i][1]) - reference[i].0).abs();
            total += reference[i].0;
        }
        let error = error / total;
        println!(
            "pool {}: outline error {error:.4} over {} pixels",
            mode.name(),
            outline.len()
        );
        errors.push(error);
    }
    // The outline's pixels are left as they are, however wide the pooling (measured 0.044
    // unpooled, 0.045 and 0.046 pooled): pooled with one surface's neighbours, as they were
    // before `PhotonMapper::mixed`, they read 0.076 (frequency) and 0.165 (geometry).
    for (mode, &error) in ["frequency", "geometry"].iter().zip(&errors[1..]) {
        assert!(
            error < 1.1 * errors[0] + 0.005,
            "{mode} pooling moved the outline's light: {errors:?} (off, freq, geometry)"
        );
    }
}
