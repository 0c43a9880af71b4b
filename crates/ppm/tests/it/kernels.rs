//! Kernels sized by the light: the pilot and restart of grown kernels, the slow shrink of held
//! kernels (consistency), and the clear-disc cap, against analytic answers and the laws of the
//! progressive update.

use ppm::{FrequencyFloor, FrequencyRadius, GatherStats, Method, Renderer};

use crate::analytic::{FURNACE, PLANE, pixel_averages};
use crate::support::{mean, params, render, scene};

#[test]
fn grown_kernels_keep_the_furnace_radiance() {
    // The restart after the pilot must count only the photons emitted since: counting the
    // pilot's too would darken the image by passes / (passes − pilot) (here 8/6).
    let scene = scene(FURNACE);
    for method in [Method::FreqPpm, Method::FreqSppm] {
        for cap in [false, true] {
            let mut p = params(method, 20_000);
            p.budget.max_depth = 64;
            p.frequency.grow = 4.0;
            p.frequency.pilot = 2;
            p.frequency.clear_cap = cap;
            let m = mean(&render(&scene, p, 8));
            assert!(
                (m - 1.0).abs() < 0.02,
                "{method} (cap {cap}): mean radiance {m}, expected 1"
            );
        }
    }
}

#[test]
fn grown_kernels_are_larger_than_the_start_where_the_light_is_smooth() {
    // A point light over an open floor: the light is smooth on the scale of the start radius,
    // so after the pilot most kernels grow, and the image stays on the inverse-square law.
    let scene = scene(PLANE);
    let mut p = params(Method::FreqPpm, 100_000);
    p.kernel.initial_radius = Some(0.03);
    // Kernels sized by the photons straight from the light, which direct lighting would
    // leave out.
    p.connections.direct_lighting = false;
    p.frequency.grow = 4.0;
    p.frequency.pilot = 2;
    let mut renderer = Renderer::new(std::sync::Arc::clone(&scene), p).unwrap();
    let pilot: Vec<_> = (0..2).map(|_| renderer.iterate()).collect();
    assert!(pilot.iter().all(|s| s.max_radius <= 0.03 + 1e-12));
    let after = renderer.iterate();
    assert!(
        after.max_radius > 0.06,
        "largest kernel {}",
        after.max_radius
    );
    assert!(
        after.mean_radius > 0.03,
        "mean kernel {}",
        after.mean_radius
    );
    assert!(
        after.max_radius <= 0.12 + 1e-12,
        "beyond freq_grow: {}",
        after.max_radius
    );
}

#[test]
fn a_pilot_without_frequency_photons_keeps_the_start_radius() {
    // No frequency photon, no prediction: nothing grows and the render is plain SPPM.
    let scene = scene(FURNACE);
    let mut p = params(Method::FreqSppm, 20_000);
    p.budget.max_depth = 64;
    p.frequency.fraction = 0.0;
    p.frequency.grow = 4.0;
    p.frequency.pilot = 1;
    p.kernel.initial_radius = Some(0.05);
    let mut renderer = Renderer::new(std::sync::Arc::clone(&scene), p).unwrap();
    for _ in 0..4 {
        let stats = renderer.iterate();
        assert!(stats.max_radius <= 0.05 + 1e-12, "{}", stats.max_radius);
    }
    let m = mean(&renderer.image());
    assert!((m - 1.0).abs() < 0.03, "mean radiance {m}");
}

#[test]
fn held_kernels_shrink_as_a_power_of_the_photon_count() {
    // With α_hold < 1 a held slot follows the PPM recursion with α = α_hold. For a constant M
    // per pass, N = k·α·M after k passes and each pass scales R² by (k + 1)/(k + 1/α), whose
    // product is Γ-like: R² ∝ k^(1 − 1/α) = N^−(1−α)/α. So the radius goes to 0 while
    // N·R² ∝ N^(2 − 1/α) → ∞ for α > 1/2: bias and variance both vanish.
    let hold_alpha = 0.9;
    let mut stats = GatherStats::new(1.0);
    let held = FrequencyRadius::Predicted(10.0);
    let mut at = Vec::new();
    for pass in 1..=20_000u32 {
        stats.update_with_hold(50, [1.0; 3], 0.7, held, FrequencyFloor::Keep, hold_alpha);
        if pass == 2_000 || pass == 20_000 {
            at.push((stats.photon_count, stats.radius));
        }
    }
    let (n1, r1) = at[0];
    let (n2, r2) = at[1];
    let slope = (r2 * r2 / (r1 * r1)).ln() / (n2 / n1).ln();
    assert!(
        (slope + (1.0 - hold_alpha) / hold_alpha).abs() < 0.005,
        "slope {slope}"
    );
    assert!(n2 * r2 * r2 > 5.0 * n1 * r1 * r1);
    // α_hold = 1 is the poster's keep rule: the radius never moves.
    let mut kept = GatherStats::new(1.0);
    for _ in 0..100 {
        kept.update_with_hold(50, [1.0; 3], 0.7, held, FrequencyFloor::Keep, 1.0);
    }
    assert_eq!(kept.radius, 1.0);
    assert_eq!(kept.photon_count, 5_000.0);
}

#[test]
fn capping_a_radius_keeps_the_estimate_of_a_uniform_density() {
    let mut stats = GatherStats {
        radius: 0.2,
        photon_count: 400.0,
        flux: [8.0, 4.0, 2.0],
    };
    let before = stats.radiance(1e6).unwrap();
    stats.cap_radius(0.05);
    assert_eq!(stats.radius, 0.05);
    let after = stats.radiance(1e6).unwrap();
    for c in 0..3 {
        assert!((after[c] - before[c]).abs() <= 1e-12 * before[c]);
    }
    assert!((stats.photon_count - 25.0).abs() < 1e-9);
    // A cap above the radius changes nothing.
    let copy = stats;
    stats.cap_radius(1.0);
    assert_eq!(stats, copy);
}

/// The plane under its point light with a black square at half the light's height: the floor's
/// shadow is the square scaled by 2, |x|, |z| < 0.4, with edges as sharp as the light.
const SHADOWED_PLANE: &str = r#"
format = 1
[camera]
position = [0.0, 2.0, 2.0]
look_at = [0.0, 0.0, 0.0]
fov_y = 50.0
[film]
width = 40
height = 40
[materials.floor]
type = "diffuse"
albedo = [0.8, 0.8, 0.8]
[materials.black]
type = "diffuse"
albedo = [0.0, 0.0, 0.0]
[[shapes]]
type = "quad"
corner = [-100.0, 0.0, 100.0]
edge1 = [200.0, 0.0, 0.0]
edge2 = [0.0, 0.0, -200.0]
material = "floor"
[[shapes]]
type = "quad"
corner = [-0.2, 0.5, 0.2]
edge1 = [0.4, 0.0, 0.0]
edge2 = [0.0, 0.0, -0.4]
material = "black"
[[lights]]
type = "point"
position = [0.0, 1.0, 0.0]
intensity = [10.0, 10.0, 10.0]
"#;

/// The exact pixel averages of [`SHADOWED_PLANE`] (8×8 sub-pixel rays): 0 on the black square
/// and in its shadow, the inverse-square law elsewhere.
fn shadowed_plane_reference(scene: &scene::Scene) -> Vec<f64> {
    let light = glam::Vec3::new(0.0, 1.0, 0.0);
    pixel_averages(scene, |ray| {
        let top = ray.at((0.5 - ray.origin.y) / ray.direction.y);
        let t = -ray.origin.y / ray.direction.y;
        let p = ray.at(t);
        if (top.x.abs() < 0.2 && top.z.abs() < 0.2)
            || t <= 0.0
            || (p.x.abs() < 0.4 && p.z.abs() < 0.4)
        {
            return 0.0;
        }
        let to_light = light - p;
        let d2 = f64::from(to_light.length_squared());
        0.8 / std::f64::consts::PI * 10.0 * f64::from(to_light.y) / d2.sqrt() / d2
    })
}

#[test]
fn the_frequency_cap_sharpens_a_shadow_edge_towards_the_analytic_image() {
    // Kernels of a few pixels blur the shadow's edge; the frequency photons' occlusion probes
    // predict radii far below that there, and the cap (`freq_cap`) brings the kernels down to
    // them, where the connections to the camera take over. Scored against the analytic pixel
    // averages over the pixels within two of the edge, and over the lit floor for the mean.
    let scene = scene(SHADOWED_PLANE);
    let reference = shadowed_plane_reference(&scene);
    let (width, height) = scene.camera().resolution();
    let (w, h) = (width as usize, height as usize);
    let peak = reference.iter().copied().fold(0.0, f64::max);
    // A pixel near the edge: its 5×5 neighbourhood holds both lit and shadowed pixels.
    let near_edge: Vec<bool> = (0..w * h)
        .map(|i| {
            let (x, y) = ((i % w) as i64, (i / w) as i64);
            let mut lit = false;
            let mut dark = false;
            for dy in -2..=2 {
                for dx in -2..=2 {
                    let (u, v) = (x + dx, y + dy);
                    if u < 0 || v < 0 || u >= w as i64 || v >= h as i64 {
                        continue;
                    }
                    let r = reference[v as usize * w + u as usize];
                    lit |= r > 0.3 * peak;
                    dark |= r == 0.0;
                }
            }
            lit && dark
        })
        .collect();
    let edge_error = |image: &[[f32; 3]]| {
        let (mut sum, mut n) = (0.0, 0);
        for (i, pixel) in image.iter().enumerate() {
            if near_edge[i] {
                let d = f64::from(pixel[1]) - reference[i];
                sum += d * d / (reference[i] * reference[i] + 0.01 * peak * peak);
                n += 1;
            }
        }
        (sum / f64::from(n), n)
    };
    let mut errors = Vec::new();
    for cap in [None, Some(1.0 / 16.0)] {
        let mut p = params(Method::FreqSppm, 100_000);
        p.kernel.initial_radius = Some(0.3);
        p.connections.direct_lighting = false;
        p.frequency.cap_floor = cap;
        p.frequency.cap_scale = 4.0;
        let image = render(&scene, p, 16);
        let (error, n) = edge_error(&image);
        assert!(n >= 60, "only {n} pixels near the edge");
        // The lit floor away from the edge, where blur cannot move the mean.
        let lit: Vec<usize> = (0..w * h)
            .filter(|&i| reference[i] >= 0.5 * peak && !near_edge[i])
            .collect();
        let ratio = lit
            .iter()
            .map(|&i| f64::from(image[i][1]) / reference[i])
            .sum::<f64>()
            / lit.len() as f64;
        println!("cap {cap:?}: relMSE near the edge {error:.5}, lit mean ratio {ratio:.4}");
        assert!(
            (ratio - 1.0).abs() < 0.03,
            "cap {cap:?}: mean ratio to the analytic radiance {ratio} on the lit floor"
        );
        errors.push(error);
    }
    assert!(
        errors[1] < 0.5 * errors[0],
        "the cap left the shadow edge's error at {} against {} without it",
        errors[1],
        errors[0]
    );
}

#[test]
fn the_frequency_cap_keeps_the_furnace_radiance() {
    let scene = scene(FURNACE);
    let mut p = params(Method::FreqSppm, 20_000);
    p.budget.max_depth = 64;
    p.frequency.cap_floor = Some(1.0 / 64.0);
    let m = mean(&render(&scene, p, 8));
    assert!((m - 1.0).abs() < 0.02, "mean radiance {m}, expected 1");
}
