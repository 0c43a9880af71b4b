//! Participating media in the path tracer, against closed forms derived here: Beer–Lambert
//! transmittance through an index-matched and a dielectric boundary, exact single scattering
//! under a directional light, and the white furnace of an albedo-1 medium, each for a
//! homogeneous medium and for a density grid (delta and ratio tracking). Every other method
//! refuses such a scene, and media that nothing refers to change no bit.

use std::f64::consts::PI;

use ppm::{Method, ParamError, Renderer};

use crate::support::{PHOTON_METHODS, params, render, scene};

/// Per-channel means of an image.
fn channel_means(image: &[[f32; 3]]) -> [f64; 3] {
    let mut sum = [0.0f64; 3];
    for p in image {
        for c in 0..3 {
            sum[c] += f64::from(p[c]);
        }
    }
    sum.map(|s| s / image.len() as f64)
}

/// A path-traced render of `toml` with `spp` samples per pixel in `passes` passes.
fn path_render(toml: &str, spp: u32, passes: u32, max_depth: u32) -> Vec<[f32; 3]> {
    let mut p = params(Method::Path, 1);
    p.film.samples_per_pixel = spp;
    p.budget.max_depth = max_depth;
    render(&scene(toml), p, passes)
}

#[track_caller]
fn assert_close(got: [f64; 3], expected: [f64; 3], tolerance: f64, what: &str) {
    for c in 0..3 {
        assert!(
            (got[c] / expected[c] - 1.0).abs() < tolerance,
            "{what}: channel {c} reads {got:?}, expected {expected:?}"
        );
    }
}

/// A camera on the z axis at z = 5 looking down it with a 0.5° field of view (every pixel's
/// ray is within 0.03 of the axis where it meets the unit sphere at the origin, so its chord
/// is 2 to within 0.05 %), a sphere of radius 1 of material `boundary` around medium `ink`, and
/// behind it a large emitter of radiance 2 facing the camera.
fn through_sphere(boundary: &str) -> String {
    format!(
        r#"
format = 1
[camera]
position = [0.0, 0.0, 5.0]
look_at = [0.0, 0.0, 0.0]
fov_y = 0.5
[film]
width = 4
height = 4
[media.ink]
sigma_a = [0.1, 0.5, 1.5]
sigma_s = [0.0, 0.0, 0.0]
[materials.boundary]
{boundary}
[materials.lamp]
type = "diffuse"
albedo = [0.0, 0.0, 0.0]
emission = [2.0, 2.0, 2.0]
[[shapes]]
type = "sphere"
center = [0.0, 0.0, 0.0]
radius = 1.0
material = "boundary"
interior = "ink"
[[shapes]]
type = "quad"
corner = [-50.0, -50.0, -3.0]
edge1 = [100.0, 0.0, 0.0]
edge2 = [0.0, 100.0, 0.0]
material = "lamp"
"#
    )
}

const SIGMA_A: [f64; 3] = [0.1, 0.5, 1.5];

/// Through an index-matched sphere of absorbing ink the emitter reads L·exp(−σa·d) per
/// channel, d = 2 (free-flight sampling by σt is stochastic: 65 536 paths, 0.5 % noise).
#[test]
fn transmittance_through_an_index_matched_boundary_is_beer_lambert() {
    let image = path_render(&through_sphere("type = \"interface\""), 1024, 4, 1024);
    let expected = SIGMA_A.map(|s| 2.0 * (-2.0 * s).exp());
    assert_close(channel_means(&image), expected, 0.025, "interface");
}

/// Through a glass sphere (ior 1.5) holding the same ink, near the axis: transmission
/// (1 − R)² at the two faces with R = ((1.5 − 1)/(1.5 + 1))² = 0.04 at normal incidence, the
/// ink's T = exp(−σa·2) between them, and the light reflected back and forth inside along the
/// axis, a geometric series of ratio R²T²: L·(1 − R)²·T / (1 − R²T²). (The ball focuses the
/// rays, but the emitter behind is uniform and wide.) The boundary both refracts and changes
/// the medium.
#[test]
fn transmittance_through_a_dielectric_boundary_includes_fresnel() {
    let image = path_render(
        &through_sphere("type = \"dielectric\"\nior = 1.5"),
        1024,
        4,
        1024,
    );
    let r = 0.04;
    let expected = SIGMA_A.map(|s| {
        let t = (-2.0 * s).exp();
        2.0 * (1.0 - r) * (1.0 - r) * t / (1.0 - r * r * t * t)
    });
    assert_close(channel_means(&image), expected, 0.03, "dielectric");
}

/// Single scattering, exact: a directional light of irradiance E travelling down −z onto a
/// unit sphere of haze (σs, σa, Henyey–Greenstein g = 0.3), seen from above along −z with
/// `max_depth` 1 (one scattering event). On the axis the haze is a slab of thickness 2: at
/// depth s below its top, light arrives through s of haze and leaves toward the camera
/// through s again, turned by θ = π, so
///   L = ∫₀² σs·p(cos θ = −1)·E·exp(−2σt·s) ds = σs·p·E·(1 − exp(−4σt)) / (2σt),
/// with p(−1) = (1 − g²) / (4π (1 + g)³).
#[test]
fn single_scattering_matches_the_slab_integral() {
    let toml = r#"
format = 1
[camera]
position = [0.0, 0.0, 5.0]
look_at = [0.0, 0.0, 0.0]
fov_y = 0.5
[film]
width = 4
height = 4
[media.haze]
sigma_a = [0.05, 0.05, 0.05]
sigma_s = [0.1, 0.2, 0.4]
g = 0.3
[materials.boundary]
type = "interface"
[[shapes]]
type = "sphere"
center = [0.0, 0.0, 0.0]
radius = 1.0
material = "boundary"
interior = "haze"
[[lights]]
type = "directional"
direction = [0.0, 0.0, -1.0]
irradiance = [1.0, 1.0, 1.0]
"#;
    let image = path_render(toml, 1024, 4, 1);
    let g: f64 = 0.3;
    let p = (1.0 - g * g) / (4.0 * PI * (1.0 + g).powi(3));
    let sigma_s = [0.1, 0.2, 0.4];
    let expected = sigma_s.map(|s: f64| {
        let t = s + 0.05;
        s * p * (1.0 - (-4.0 * t).exp()) / (2.0 * t)
    });
    assert_close(channel_means(&image), expected, 0.03, "single scattering");
}

/// A closed box whose black walls all emit L = 1 inward, filled with a medium of albedo one
/// (σa = 0, a different σs per channel, strongly forward-scattering): no energy is lost, so
/// whatever the scattering every path ends on a wall and every pixel reads L in every channel.
#[test]
fn white_furnace_of_an_albedo_one_medium_reads_the_wall_radiance() {
    white_furnace("");
}

/// The white furnace with a grid of uneven densities (0 to 2.5, chromatic σs, the camera
/// inside the grid): spectral delta tracking and ratio tracking keep every channel at L.
#[test]
fn white_furnace_of_an_albedo_one_grid_reads_the_wall_radiance() {
    white_furnace(
        "[media.fog.grid]\nsize = [3, 2, 2]\ndensity = [0.0, 2.5, 0.4, 1.0, 0.1, 2.0, 1.5, 0.0, 0.3, 0.8, 2.2, 0.6]\nmin = [-1.0, -1.0, -1.0]\nmax = [1.0, 1.0, 1.0]\n",
    );
}

fn white_furnace(grid: &str) {
    let mut toml = String::from(
        r#"
format = 1
[camera]
position = [0.0, 0.0, 0.5]
look_at = [1.0, 0.2, 0.5]
fov_y = 70.0
medium = "fog"
[film]
width = 8
height = 8
[media.fog]
sigma_a = [0.0, 0.0, 0.0]
sigma_s = [0.5, 1.0, 2.0]
g = 0.6
[materials.wall]
type = "diffuse"
albedo = [0.0, 0.0, 0.0]
emission = [1.0, 1.0, 1.0]
"#,
    );
    toml += grid;
    // Corner and edges of each face, edge1 × edge2 pointing into the cube.
    let faces: [[[f64; 3]; 3]; 6] = [
        [[-1.0, -1.0, -1.0], [0.0, 0.0, 2.0], [2.0, 0.0, 0.0]],
        [[-1.0, 1.0, -1.0], [2.0, 0.0, 0.0], [0.0, 0.0, 2.0]],
        [[-1.0, -1.0, -1.0], [0.0, 2.0, 0.0], [0.0, 0.0, 2.0]],
        [[1.0, -1.0, -1.0], [0.0, 0.0, 2.0], [0.0, 2.0, 0.0]],
        [[-1.0, -1.0, -1.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]],
        [[-1.0, -1.0, 1.0], [0.0, 2.0, 0.0], [2.0, 0.0, 0.0]],
    ];
    for [corner, edge1, edge2] in faces {
        toml += &format!(
            "[[shapes]]\ntype = \"quad\"\ncorner = {corner:?}\nedge1 = {edge1:?}\nedge2 = {edge2:?}\nmaterial = \"wall\"\n"
        );
    }
    let image = path_render(&toml, 64, 4, 1024);
    assert_close(channel_means(&image), [1.0; 3], 0.015, "furnace mean");
    for (i, px) in image.iter().enumerate() {
        for (c, &v) in px.iter().enumerate() {
            assert!(
                (f64::from(v) - 1.0).abs() < 0.15,
                "furnace pixel {i} channel {c} reads {v}"
            );
        }
    }
}

/// Beer–Lambert through a grid of constant density 2 holding half the ink's coefficients: the
/// same image as the homogeneous ink (delta tracking, then the emitter).
#[test]
fn transmittance_through_a_constant_grid_is_beer_lambert() {
    let toml = through_sphere("type = \"interface\"").replace(
        "[media.ink]\nsigma_a = [0.1, 0.5, 1.5]",
        "[media.ink.grid]\nsize = [2, 2, 2]\ndensity = [2.0, 2.0, 2.0, 2.0, 2.0, 2.0, 2.0, 2.0]\nmin = [-1.0, -1.0, -1.0]\nmax = [1.0, 1.0, 1.0]\n[media.ink]\nsigma_a = [0.05, 0.25, 0.75]",
    );
    assert!(toml.contains("[media.ink.grid]"));
    // Delta tracking under one majorant (that of the densest channel) makes the others'
    // estimates binary: in the blue channel a path passes with probability T = e⁻³, so the
    // relative standard error is √((1 − T)/T / n), 0.85 % over n = 262 144 paths.
    let image = path_render(&toml, 1024, 16, 1024);
    let expected = SIGMA_A.map(|s| 2.0 * (-2.0 * s).exp());
    assert_close(channel_means(&image), expected, 0.03, "constant grid");
}

/// Single scattering of the haze of [`single_scattering_matches_the_slab_integral`] as a grid
/// of constant density 0.5 with doubled coefficients, clamped over a box larger than the
/// sphere: the same slab integral (delta tracking for the vertex, ratio tracking for the
/// shadow ray toward the sun).
#[test]
fn single_scattering_in_a_grid_matches_the_slab_integral() {
    let toml = r#"
format = 1
[camera]
position = [0.0, 0.0, 5.0]
look_at = [0.0, 0.0, 0.0]
fov_y = 0.5
[film]
width = 4
height = 4
[media.haze]
sigma_a = [0.1, 0.1, 0.1]
sigma_s = [0.2, 0.4, 0.8]
g = 0.3
[media.haze.grid]
size = [1, 2, 1]
density = [0.5, 0.5]
min = [-1.5, -1.5, -1.5]
max = [1.5, 1.5, 1.5]
[materials.boundary]
type = "interface"
[[shapes]]
type = "sphere"
center = [0.0, 0.0, 0.0]
radius = 1.0
material = "boundary"
interior = "haze"
[[lights]]
type = "directional"
direction = [0.0, 0.0, -1.0]
irradiance = [1.0, 1.0, 1.0]
"#;
    let image = path_render(toml, 1024, 4, 1);
    let g: f64 = 0.3;
    let p = (1.0 - g * g) / (4.0 * PI * (1.0 + g).powi(3));
    let sigma_s = [0.1, 0.2, 0.4];
    let expected = sigma_s.map(|s: f64| {
        let t = s + 0.05;
        s * p * (1.0 - (-4.0 * t).exp()) / (2.0 * t)
    });
    assert_close(
        channel_means(&image),
        expected,
        0.03,
        "single scattering in a grid",
    );
}

/// Every method but the path tracer refuses a scene with media with one typed error.
#[test]
fn other_methods_refuse_media() {
    let scene = scene(&through_sphere("type = \"interface\""));
    let mut methods = PHOTON_METHODS.to_vec();
    methods.extend([Method::Light, Method::Vcm, Method::Bdpt, Method::Appm]);
    for method in methods {
        let err = Renderer::new(std::sync::Arc::clone(&scene), params(method, 1000))
            .err()
            .unwrap_or_else(|| panic!("{method} rendered a scene with media"));
        assert!(
            matches!(err, ParamError::MediaUnsupported { method: m } if m == method),
            "{method}: {err}"
        );
        assert_eq!(
            err.to_string(),
            format!(
                "the scene has participating media, which only the path tracer renders: use \
                 --method path, not {method}"
            )
        );
    }
    assert!(Renderer::new(scene, params(Method::Path, 1)).is_ok());
}

/// Media that no shape and no camera refers to change nothing: the same bits as without them,
/// for the path tracer and a photon mapper.
#[test]
fn unused_media_render_bit_identically() {
    let plain = crate::analytic::FURNACE;
    let with_media = format!(
        "{plain}\n[media.unused]\nsigma_a = [1.0, 1.0, 1.0]\nsigma_s = [0.5, 0.5, 0.5]\ng = 0.2\n"
    );
    for method in [Method::Path, Method::Sppm] {
        let mut p = params(method, 2000);
        p.film.samples_per_pixel = 2;
        let a = render(&scene(plain), p, 2);
        let b = render(&scene(&with_media), p, 2);
        assert!(
            a.iter()
                .flatten()
                .zip(b.iter().flatten())
                .all(|(x, y)| x.to_bits() == y.to_bits()),
            "{method}: unused media changed the image"
        );
        assert!(
            a.iter().flatten().any(|&v| v > 0.0),
            "{method}: black image"
        );
    }
}

/// A medium that neither absorbs nor scatters, around the camera, sends every path through the
/// media code with nothing to do: the analytic scenes of `analytic.rs` then read what they read
/// without it, the closed diffuse sphere around a point light (L = 1) and the emissive box
/// bounded to k bounces (1 − 0.5^(k+1)), so surfaces, light sampling, MIS and the bounce count
/// agree with the plain path tracer.
#[test]
fn a_clear_medium_changes_nothing() {
    let clear = "[media.clear]\nsigma_a = [0.0, 0.0, 0.0]\nsigma_s = [0.0, 0.0, 0.0]\n";
    let furnace =
        crate::analytic::FURNACE.replace("fov_y = 70.0\n", "fov_y = 70.0\nmedium = \"clear\"\n");
    assert!(scene(&format!("{furnace}{clear}")).has_media());
    let m = channel_means(&path_render(&format!("{furnace}{clear}"), 16, 4, 64));
    assert_close(m, [1.0; 3], 0.02, "furnace sphere in a clear medium");
    let camera = "[camera]\nposition = [0.0, 0.0, 0.5]\nlook_at = [1.0, 0.0, 0.5]\nfov_y = 40.0\n\
                  medium = \"clear\"";
    let walls = format!("{}{clear}", crate::analytic::emissive_box(camera));
    for k in 1..=3u32 {
        let expected = 1.0 - 0.5f64.powi(k as i32 + 1);
        let m = channel_means(&path_render(&walls, 16, 4, k));
        assert_close(
            m,
            [expected; 3],
            0.02,
            &format!("emissive box, max_depth {k}"),
        );
    }
}
