//! Tests of vcm's internals: the recursive MIS weights of every strategy of sampled paths
//! against weights computed from each strategy's density, and the furnace for each strategy
//! alone.

#![allow(clippy::print_stderr)]

use std::path::Path;
use std::sync::Arc;

use glam::{Vec2, Vec3};
use scene::{Bsdf, Hit, Scene, TransportMode};

use super::Vcm;
use super::mis::{Mis, Strategies};
use super::radius::FrequencyField;
use crate::integrator::Integrator;
use crate::rng::Sampler;
use crate::{Method, RenderParams};

fn scene(toml: &str) -> Arc<Scene> {
    let description = import::load_toml_str(toml, Path::new("test.toml")).unwrap();
    Arc::new(Scene::new(description).unwrap())
}

/// A box with white, red and glossy walls, a mirror sphere and a ceiling lamp: every kind of
/// vertex that has densities both ways, and a specular one.
const BOX: &str = r#"
format = 1
[camera]
position = [0.0, 1.0, 3.0]
look_at = [0.0, 1.0, 0.0]
fov_y = 45.0
[film]
width = 16
height = 16
[materials.white]
type = "diffuse"
albedo = [0.8, 0.8, 0.8]
[materials.red]
type = "diffuse"
albedo = [0.7, 0.1, 0.1]
[materials.shiny]
type = "glossy"
reflectance = [0.9, 0.9, 0.9]
roughness = 0.3
[materials.silver]
type = "mirror"
[materials.lamp]
type = "diffuse"
albedo = [0.0, 0.0, 0.0]
emission = [5.0, 5.0, 5.0]
[[shapes]]
type = "quad"
corner = [-1.0, 0.0, 1.0]
edge1 = [2.0, 0.0, 0.0]
edge2 = [0.0, 0.0, -2.0]
material = "shiny"
[[shapes]]
type = "quad"
corner = [-1.0, 2.0, -1.0]
edge1 = [2.0, 0.0, 0.0]
edge2 = [0.0, 0.0, 2.0]
material = "white"
[[shapes]]
type = "quad"
corner = [-1.0, 0.0, -1.0]
edge1 = [2.0, 0.0, 0.0]
edge2 = [0.0, 2.0, 0.0]
material = "white"
[[shapes]]
type = "quad"
corner = [-1.0, 0.0, 1.0]
edge1 = [0.0, 0.0, -2.0]
edge2 = [0.0, 2.0, 0.0]
material = "red"
[[shapes]]
type = "quad"
corner = [1.0, 0.0, -1.0]
edge1 = [0.0, 0.0, 2.0]
edge2 = [0.0, 2.0, 0.0]
material = "white"
[[shapes]]
type = "quad"
corner = [-0.3, 1.98, -0.3]
edge1 = [0.6, 0.0, 0.0]
edge2 = [0.0, 0.0, 0.6]
material = "lamp"
[[shapes]]
type = "sphere"
center = [0.4, 0.4, -0.2]
radius = 0.35
material = "silver"
"#;

/// A surface vertex of a test path.
struct Vertex {
    hit: Hit,
    bsdf: Bsdf,
}

/// A path x₀ (on the lamp) … x_{k−1} (the first camera hit), x_k the pinhole, drawn by a camera
/// random walk whose last vertex is joined to a light sample; `None` where the walk fails or
/// ends on a specular vertex.
fn sample_path(scene: &Scene, index: u64, k: usize) -> Option<Vec<Vertex>> {
    let mut sampler = Sampler::new(3, 0, index);
    let camera = scene.camera();
    let film = sampler.next_2d() * Vec2::new(16.0, 16.0);
    let mut ray = camera.generate_ray(film, Vec2::ZERO);
    let mut walk = Vec::new();
    for step in 0..k - 1 {
        let hit = scene.intersect(&ray)?;
        let bsdf = scene.bsdf(&hit)?;
        if scene.emitted(&hit) != scene::Rgb::ZERO {
            return None;
        }
        let outgoing = -ray.direction;
        walk.push(Vertex { hit, bsdf });
        if step + 2 < k {
            let s = bsdf.sample(
                outgoing,
                sampler.next_f32(),
                sampler.next_2d(),
                TransportMode::Radiance,
            )?;
            ray = hit.spawn_ray(s.incoming);
        }
    }
    let last = walk.last()?;
    if last.bsdf.is_specular() {
        return None;
    }
    let light = scene.lights().sample_direct(
        last.hit.position,
        last.hit.geometric_normal,
        sampler.next_f32(),
        sampler.next_2d(),
    )?;
    let hit = scene.intersect(&last.hit.spawn_ray(light.incoming))?;
    if scene.emitted(&hit) == scene::Rgb::ZERO {
        return None;
    }
    let bsdf = scene.bsdf(&hit)?;
    walk.push(Vertex { hit, bsdf });
    walk.reverse();
    Some(walk)
}

/// The densities of the BSDF of `v` drawing `b` from `a` and `a` from `b`, as the integrator
/// takes them: discrete probabilities at a specular vertex.
fn densities(v: &Vertex, a: Vec3, b: Vec3) -> (f32, f32) {
    if v.bsdf.is_specular() {
        let ng = v.hit.geometric_normal;
        let transmission = a.dot(ng) * b.dot(ng) < 0.0;
        (
            v.bsdf.specular_probability(a, transmission),
            v.bsdf.specular_probability(b, transmission),
        )
    } else {
        (v.bsdf.pdf(a, b), v.bsdf.pdf(b, a))
    }
}

/// Every strategy of one path, with its recursive weight and its weight from the densities of
/// all strategies one by one (Veach's balance heuristic with the sample counts n_s); a merge at
/// a vertex at p has the radius `radius(p)`.
fn weights(
    scene: &Scene,
    x: &[Vertex],
    mis: &Mis,
    counts: (f32, f32),
    radius: &dyn Fn(Vec3) -> f64,
) -> Vec<(f64, f64)> {
    let (light_paths, spp) = counts;
    // η at a path vertex: every strategy computes it from the vertex's position alone.
    let eta = |i: usize| mis.eta(radius(x[i].hit.position));
    let strategies = mis.strategies;
    let k = x.len();
    let lens = scene.camera().position();
    let pos = |i: usize| if i == k { lens } else { x[i].hit.position };
    let dir = |i: usize, j: usize| (pos(j) - pos(i)).normalize();
    let d2 = |i: usize, j: usize| pos(i).distance_squared(pos(j));
    let cos = |i: usize, j: usize| dir(i, j).dot(x[i].hit.geometric_normal).abs();
    let specular = |i: usize| x[i].bsdf.is_specular();
    let focal = scene.camera().focal_pixels();
    let cos_lens = scene.camera().forward().dot(dir(k, k - 1));
    let camera_pdf = focal * focal / (cos_lens * cos_lens * cos_lens);
    let emission = scene
        .lights()
        .pdf_emission(&x[0].hit, dir(0, 1), (pos(1), x[1].hit.geometric_normal))
        .unwrap();

    // Area densities of each vertex from the light side and from the camera side.
    let mut forward = vec![0.0f64; k];
    let mut reverse = vec![0.0f64; k];
    forward[0] = f64::from(emission.pick * emission.position);
    forward[1] = f64::from(emission.direction * cos(1, 0) / d2(0, 1));
    for i in 2..k {
        let (f, _) = densities(&x[i - 1], dir(i - 1, i - 2), dir(i - 1, i));
        forward[i] = f64::from(f * cos(i, i - 1) / d2(i - 1, i));
    }
    reverse[k - 1] = f64::from(camera_pdf * cos(k - 1, k) / d2(k - 1, k));
    for i in (0..k - 1).rev() {
        let (f, _) = densities(&x[i + 1], dir(i + 1, i + 2), dir(i + 1, i));
        reverse[i] = f64::from(f * cos(i, i + 1) / d2(i, i + 1));
    }
    let direct = f64::from(emission.direct_with_pick());
    let product = |v: &[f64]| v.iter().product::<f64>();

    // (strategy on, n·p) of the connections s = 0..=k and the merges at 1..k−1.
    let mut brute: Vec<(bool, f64)> = Vec::new();
    for s in 0..=k {
        let t = k + 1 - s;
        let (on, light, n) = match (s, t) {
            (0, _) => (strategies.emission, 1.0, 1.0),
            (1, _) => (strategies.next_event, direct, 1.0),
            (_, 1) => (
                strategies.light_tracing && !specular(k - 1),
                product(&forward[..s]),
                f64::from(light_paths / spp),
            ),
            _ => (
                strategies.connection && !specular(s - 1) && !specular(s),
                product(&forward[..s]),
                1.0,
            ),
        };
        brute.push((on, n * light * product(&reverse[s..])));
    }
    for i in 1..k {
        let on = strategies.merging && !specular(i);
        let p =
            f64::from(eta(i)) * reverse[i] * product(&forward[..=i]) * product(&reverse[i + 1..]);
        brute.push((on, p));
    }
    let total: f64 = brute.iter().filter(|b| b.0).map(|b| b.1).sum();

    // The recursive sums along both subpaths: light[i] at x_i, camera[j] at x_{k−j}.
    let mut light = vec![super::mis::Partial::default(); k];
    light[1] = mis.light_start(&emission, emission.pick_direct, d2(0, 1), cos(1, 0));
    for i in 1..k - 1 {
        let (f, r) = densities(&x[i], dir(i, i - 1), dir(i, i + 1));
        let e = eta(i);
        let p = mis.scatter(
            light[i],
            false,
            i as u32,
            f,
            r,
            specular(i),
            cos(i, i + 1),
            e,
        );
        light[i + 1] = Mis::arrive(p, Some(d2(i, i + 1)), cos(i + 1, i));
    }
    let mut camera = vec![super::mis::Partial::default(); k + 1];
    camera[1] = Mis::arrive(
        mis.camera_start(camera_pdf),
        Some(d2(k, k - 1)),
        cos(k - 1, k),
    );
    for j in 1..k {
        let v = k - j;
        let (f, r) = densities(&x[v], dir(v, v + 1), dir(v, v - 1));
        let e = eta(v);
        let p = mis.scatter(
            camera[j],
            true,
            j as u32,
            f,
            r,
            specular(v),
            cos(v, v - 1),
            e,
        );
        camera[j + 1] = Mis::arrive(p, Some(d2(v, v - 1)), cos(v - 1, v));
    }
    let mut recursive: Vec<f32> = Vec::new();
    for s in 0..=k {
        let t = k + 1 - s;
        let w = match (s, t) {
            (0, _) => mis.emission_weight(camera[k], &emission),
            (1, _) => {
                let (f, r) = densities(&x[1], dir(1, 2), dir(1, 0));
                let light_pdf = emission.direct_with_pick() * d2(0, 1) / cos(0, 1);
                mis.next_event_weight(
                    camera[k - 1],
                    (k - 1) as u32,
                    &emission,
                    light_pdf,
                    d2(0, 1).sqrt(),
                    f,
                    r,
                    cos(1, 0),
                    eta(1),
                )
            }
            (_, 1) => {
                let (r, _) = densities(&x[k - 1], dir(k - 1, k), dir(k - 1, k - 2));
                let area = camera_pdf * cos(k - 1, k) / d2(k - 1, k);
                mis.light_tracing_weight(light[k - 1], (k - 1) as u32, area, r, eta(k - 1))
            }
            _ => {
                let (cf, cr) = densities(&x[s], dir(s, s + 1), dir(s, s - 1));
                let (lf, lr) = densities(&x[s - 1], dir(s - 1, s - 2), dir(s - 1, s));
                mis.connection_weight(
                    camera[k - s],
                    (k - s) as u32,
                    light[s - 1],
                    (s - 1) as u32,
                    cf * cos(s - 1, s) / d2(s - 1, s),
                    lf * cos(s, s - 1) / d2(s - 1, s),
                    cr,
                    lr,
                    (eta(s), eta(s - 1)),
                )
            }
        };
        recursive.push(w);
    }
    for i in 1..k {
        let (f, r) = densities(&x[i], dir(i, i + 1), dir(i, i - 1));
        let (c, l) = (camera[k - i], light[i]);
        recursive.push(mis.merge_weight(c, (k - i) as u32, l, i as u32, f, r, eta(i)));
    }
    brute
        .iter()
        .zip(recursive)
        .filter(|(b, _)| b.0)
        .map(|(b, w)| (f64::from(w), b.1 / total))
        .collect()
}

/// For paths of 3 to 6 vertices and every subset of the strategies, each strategy's recursive
/// weight is its share of the summed densities, and the weights sum to one: with one merge
/// radius, and with a radius that depends on the position (as frequency-sized merges have),
/// from 0.005 to 0.05.
#[test]
fn mis_weights_of_every_strategy_sum_to_one() {
    let constant = |_: Vec3| 0.05;
    let varying =
        |p: Vec3| 0.005 + 0.045 * f64::from(0.5 + 0.5 * (9.0 * p.x + 5.0 * p.y + 7.0 * p.z).sin());
    mis_weights_sum_to_one(&constant);
    mis_weights_sum_to_one(&varying);
}

fn mis_weights_sum_to_one(radius: &dyn Fn(Vec3) -> f64) {
    let scene = scene(BOX);
    let (light_paths, spp) = (1000u64, 2u32);
    let mut paths = 0;
    let mut with_specular = 0;
    for k in 2..=5usize {
        for index in 0..400u64 {
            let Some(x) = sample_path(&scene, index * 8 + k as u64, k) else {
                continue;
            };
            paths += 1;
            with_specular += usize::from(x.iter().any(|v| v.bsdf.is_specular()));
            for mask in 1..32u32 {
                let strategies = Strategies {
                    emission: mask & 1 != 0,
                    next_event: mask & 2 != 0,
                    light_tracing: mask & 4 != 0,
                    connection: mask & 8 != 0,
                    merging: mask & 16 != 0,
                };
                let mis = Mis::new(strategies, light_paths, spp);
                let w = weights(&scene, &x, &mis, (light_paths as f32, spp as f32), radius);
                if w.is_empty() {
                    continue;
                }
                let sum: f64 = w.iter().map(|p| p.0).sum();
                assert!(
                    (sum - 1.0).abs() < 1e-3,
                    "k = {k}, path {index}, strategies {strategies:?}: weights sum to {sum}: {w:?}"
                );
                for &(recursive, brute) in &w {
                    assert!(
                        (recursive - brute).abs() < 1e-3 * brute.max(1e-2),
                        "k = {k}, path {index}, strategies {strategies:?}: {w:?}"
                    );
                }
            }
        }
    }
    // The walks reach every length, some through the mirror.
    assert!(
        paths > 400 && with_specular > 20,
        "{paths} paths, {with_specular} specular"
    );
}

/// A closed polyhedron close to the unit sphere (a 16 × 32 latitude-longitude tessellation,
/// flat triangles facing inward) whose walls all emit Le = 0.5 and reflect ρ = 0.5, seen from
/// its centre: in any closed enclosure of uniform emission and albedo paths of j bounces bring
/// Le·ρ^j. Unlike a cube it has no concave corners, where next-event estimation alone or a
/// connection alone has unbounded variance (the geometry term between two points near a
/// corner), so that every strategy alone converges at the test's budget.
fn emissive_sphere() -> Arc<Scene> {
    let toml = "format = 1\n[camera]\nposition = [0.0, 0.0, 0.0]\nlook_at = [1.0, 0.0, 0.2]\n\
                fov_y = 60.0\n[film]\nwidth = 16\nheight = 16\n\
                [materials.wall]\ntype = \"diffuse\"\nalbedo = [0.5, 0.5, 0.5]\n\
                emission = [0.5, 0.5, 0.5]\n[[shapes]]\ntype = \"quad\"\n\
                corner = [-1.0, -1.0, -1.0]\nedge1 = [2.0, 0.0, 0.0]\nedge2 = [0.0, 2.0, 0.0]\n\
                material = \"wall\"\n";
    let mut description = import::load_toml_str(toml, Path::new("sphere.toml")).unwrap();
    let template = description.triangles[0];
    let (rows, columns) = (16, 32);
    let point = |row: usize, column: usize| {
        let theta = std::f32::consts::PI * row as f32 / rows as f32;
        let phi = 2.0 * std::f32::consts::PI * column as f32 / columns as f32;
        Vec3::new(
            theta.sin() * phi.cos(),
            theta.cos(),
            theta.sin() * phi.sin(),
        )
    };
    description.triangles.clear();
    for row in 0..rows {
        for column in 0..columns {
            let (a, b) = (point(row, column), point(row, column + 1));
            let (c, d) = (point(row + 1, column), point(row + 1, column + 1));
            for [p, q, r] in [[a, b, d], [a, d, c]] {
                if (q - p).cross(r - p).length_squared() < 1e-12 {
                    continue;
                }
                // Counter-clockwise, the front face, seen from the centre.
                let inward = (q - p).cross(r - p).dot(-(p + q + r)) > 0.0;
                let mut triangle = template;
                triangle.positions = if inward { [p, q, r] } else { [p, r, q] };
                description.triangles.push(triangle);
            }
        }
    }
    Arc::new(Scene::new(description).unwrap())
}

/// How a furnace render sizes its merges.
#[derive(Clone, Copy, Debug)]
enum Radii {
    /// The pass's one radius.
    Global,
    /// The frequency prediction of the pilot (`vcm_freq_radius`).
    Frequency,
    /// A made-up field that varies from cell to cell between a fifth of r₀ and r₀: merges of
    /// many radii in one pass.
    Varying,
}

/// A field of radii from 0.02 to 0.1 on cells of 0.1 over [−1, 1]³.
fn varying_field() -> FrequencyField {
    let mut predictions = Vec::new();
    for i in -10..10 {
        for j in -10..10 {
            for k in -10..10 {
                let p = Vec3::new(i as f32, j as f32, k as f32) * 0.1 + 0.05;
                let wave = 0.5 + 0.5 * (7.0 * p.x + 5.0 * p.y + 3.0 * p.z).sin();
                predictions.push((p, 0.02 + 0.08 * f64::from(wave)));
            }
        }
    }
    FrequencyField::new(&predictions, 0.1)
}

/// The mean radiance of [`PASSES`] passes of `strategies` in the emissive sphere with
/// `max_depth`, merging with `radii`.
const PASSES: u32 = 32;
fn furnace_mean(scene: &Arc<Scene>, strategies: Strategies, max_depth: u32, radii: Radii) -> f64 {
    let mut params = RenderParams::preview();
    params.method = Method::Vcm;
    params.seed = 11;
    params.budget.photons_per_pass = 4096;
    params.budget.photons_auto = false;
    params.budget.max_depth = max_depth;
    // About a tenth of a facet: merging's bias where a kernel crosses a facet's edge stays
    // far below the tolerance (measured: 0.02 % with merging alone at 8192 paths × 32 passes).
    params.kernel.initial_radius = Some(0.1);
    params.kernel.freq_radius = matches!(radii, Radii::Frequency);
    let mut vcm = Vcm::with_strategies(Arc::clone(scene), params, strategies);
    if matches!(radii, Radii::Varying) {
        vcm.field = Some(varying_field());
    }
    for _ in 0..PASSES {
        vcm.iterate();
    }
    let image = vcm.image();
    image
        .iter()
        .map(|p| p.iter().map(|&c| f64::from(c)).sum::<f64>() / 3.0)
        .sum::<f64>()
        / image.len() as f64
}

/// Each strategy alone (weighted only against itself: weight one) and every combination of
/// the methods finds the radiance of the paths it can sample: all of them, Le·Σ ρ^j over the
/// bounces j allowed, but for connections between stored vertices, which need two bounces.
/// Emission seen directly always counts.
#[test]
fn furnace_for_each_strategy_alone_and_combined() {
    let scene = emissive_sphere();
    let none = Strategies {
        emission: false,
        next_event: false,
        light_tracing: false,
        connection: false,
        merging: false,
    };
    let cases = [
        (
            "emission",
            Strategies {
                emission: true,
                ..none
            },
            1,
            Radii::Global,
        ),
        (
            "next event",
            Strategies {
                next_event: true,
                ..none
            },
            1,
            Radii::Global,
        ),
        (
            "light tracing",
            Strategies {
                light_tracing: true,
                ..none
            },
            1,
            Radii::Global,
        ),
        (
            "connections",
            Strategies {
                connection: true,
                ..none
            },
            2,
            Radii::Global,
        ),
        (
            "merging",
            Strategies {
                merging: true,
                ..none
            },
            1,
            Radii::Global,
        ),
        ("bdpt", Strategies::BDPT, 1, Radii::Global),
        ("vcm", Strategies::VCM, 1, Radii::Global),
        (
            "vcm without connections",
            Strategies {
                emission: true,
                merging: true,
                ..none
            },
            1,
            Radii::Global,
        ),
        ("vcm, frequency radii", Strategies::VCM, 1, Radii::Frequency),
        ("vcm, varying radii", Strategies::VCM, 1, Radii::Varying),
        (
            "merging alone, varying radii",
            Strategies {
                merging: true,
                ..none
            },
            1,
            Radii::Varying,
        ),
    ];
    for max_depth in [2u32, 1024] {
        for (name, strategies, fewest_bounces, radii) in cases {
            // Le = 0.5 seen directly, Le·ρ^j = 0.5^(j+1) for fewest_bounces ≤ j ≤ max_depth.
            let expected = 0.5
                + (fewest_bounces..=max_depth.min(60))
                    .map(|j| 0.5f64.powi(j as i32 + 1))
                    .sum::<f64>();
            let m = furnace_mean(&scene, strategies, max_depth, radii);
            eprintln!("{name}, max_depth {max_depth}: {m:.5} (expected {expected:.5})");
            assert!(
                (m / expected - 1.0).abs() < 0.01,
                "{name}, max_depth {max_depth}: mean radiance {m}, expected {expected}"
            );
        }
    }
}
