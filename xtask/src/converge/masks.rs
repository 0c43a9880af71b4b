//! Regional masks of the error (low-frequency diffuse, caustic, glossy) and the radius maps.

use super::*;

/// Error restricted to each mask.
pub(super) struct Masks {
    pub(super) names: [&'static str; 3],
    pub(super) masks: [Vec<bool>; 3],
}

/// The three masks, from a camera ray through each pixel centre and the reference image:
/// - glossy: the first surface is glossy, a mirror or a dielectric;
/// - caustic (high-frequency diffuse): the first surface is diffuse and the reference's
///   luminance differs from its 5×5 box blur by more than 25 % (caustics, and also shadow and
///   contact edges);
/// - low-frequency: every other diffuse pixel (smoothly lit, directly or indirectly).
///
/// Pixels that see no surface or an emitter (or neighbour one, see
/// [`suite::transport_mask`]) belong to no mask.
pub(super) fn build_masks(scene: &scene::Scene, reference: &Image) -> Masks {
    let (w, h) = (reference.width, reference.height);
    let lum: Vec<f64> = reference
        .pixels
        .iter()
        .map(|p| 0.2126 * f64::from(p[0]) + 0.7152 * f64::from(p[1]) + 0.0722 * f64::from(p[2]))
        .collect();
    let mut low = vec![false; w * h];
    let mut caustic = vec![false; w * h];
    let mut glossy = vec![false; w * h];
    for y in 0..h {
        for x in 0..w {
            let idx = y * w + x;
            let ray = scene
                .camera()
                .generate_ray(Vec2::new(x as f32 + 0.5, y as f32 + 0.5), Vec2::splat(0.5));
            let Some(hit) = scene.intersect(&ray) else {
                continue;
            };
            let Some(material) = scene.material(hit.material) else {
                continue;
            };
            if material.emission.max_element() > 0.0 {
                continue;
            }
            match material.kind {
                scene::MaterialKind::Diffuse(_) => {
                    let (mut sum, mut n) = (0.0, 0.0);
                    for yy in y.saturating_sub(2)..(y + 3).min(h) {
                        for xx in x.saturating_sub(2)..(x + 3).min(w) {
                            sum += lum[yy * w + xx];
                            n += 1.0;
                        }
                    }
                    let blur = sum / n;
                    if (lum[idx] - blur).abs() > 0.25 * blur.max(1e-6) {
                        caustic[idx] = true;
                    } else {
                        low[idx] = true;
                    }
                }
                _ => glossy[idx] = true,
            }
        }
    }
    let transport = suite::transport_mask(scene);
    for mask in [&mut low, &mut caustic, &mut glossy] {
        for (m, t) in mask.iter_mut().zip(&transport) {
            *m &= *t;
        }
    }
    Masks {
        names: ["low", "caustic", "glossy"],
        masks: [low, caustic, glossy],
    }
}

/// The masks as one PNG: green = low-frequency, red = caustic / high-frequency, blue = glossy.
pub(super) fn write_masks(path: &Path, masks: &Masks, width: usize) -> Result<()> {
    let n = masks.masks[0].len();
    let pixels = (0..n)
        .map(|i| {
            let f = |m: usize| if masks.masks[m][i] { 1.0 } else { 0.0 };
            [f(1), 0.6 * f(0), f(2)]
        })
        .collect();
    film::write_preview(
        path,
        &Image::new(width, n / width, pixels),
        film::Tonemap::linear(1.0),
        3,
    )?;
    Ok(())
}

/// Radius map (all photon mappers), frequency radius and held-by-floor maps (frequency methods).
pub(super) fn write_maps(
    renderer: &ppm::Renderer,
    out: &Path,
    stem: &str,
    width: usize,
) -> Result<()> {
    if let Some(radius) = renderer.aov(ppm::Aov::Radius) {
        let max = percentile(&radius, 0.99);
        film::write_false_colour(
            &out.join(format!("{stem}-radius.png")),
            width,
            &radius,
            max,
            3,
        )?;
        println!("  radius map: 99th percentile {max:.5} (red)");
    }
    if let Some(held) = renderer.aov(ppm::Aov::FreqHeld) {
        film::write_false_colour(&out.join(format!("{stem}-held.png")), width, &held, 1.0, 3)?;
        let share = held.iter().map(|&v| f64::from(v)).sum::<f64>() / held.len().max(1) as f64;
        println!(
            "  held by the frequency floor: {:.1} % of hitpoints",
            100.0 * share
        );
    }
    if let Some(freq) = renderer.aov(ppm::Aov::FreqRadius) {
        let max = percentile(&freq, 0.99);
        film::write_false_colour(
            &out.join(format!("{stem}-freq-radius.png")),
            width,
            &freq,
            max,
            3,
        )?;
    }
    Ok(())
}

pub(super) fn percentile(values: &[f32], q: f64) -> f32 {
    let mut v: Vec<f32> = values
        .iter()
        .copied()
        .filter(|x| x.is_finite() && *x > 0.0)
        .collect();
    if v.is_empty() {
        return 1.0;
    }
    v.sort_by(f32::total_cmp);
    v[((v.len() as f64 * q) as usize).min(v.len() - 1)]
}
