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
    let image = path_render(HAZE, 1024, 4, 1);
    assert_close(
        channel_means(&image),
        haze_radiance(),
        0.03,
        "single scattering",
    );
}

/// The scene of [`single_scattering_matches_the_slab_integral`].
const HAZE: &str = r#"
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

/// The closed form of [`single_scattering_matches_the_slab_integral`] for [`HAZE`].
fn haze_radiance() -> [f64; 3] {
    let g: f64 = 0.3;
    let p = (1.0 - g * g) / (4.0 * PI * (1.0 + g).powi(3));
    [0.1, 0.2, 0.4].map(|s: f64| {
        let t = s + 0.05;
        s * p * (1.0 - (-4.0 * t).exp()) / (2.0 * t)
    })
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
    white_furnace(FURNACE_GRID);
}

fn white_furnace(grid: &str) {
    let toml = furnace_fog_box() + grid;
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
    let toml = HAZE.replace(
        "sigma_a = [0.05, 0.05, 0.05]\nsigma_s = [0.1, 0.2, 0.4]\ng = 0.3\n",
        "sigma_a = [0.1, 0.1, 0.1]\nsigma_s = [0.2, 0.4, 0.8]\ng = 0.3\n[media.haze.grid]\n\
         size = [1, 2, 1]\ndensity = [0.5, 0.5]\nmin = [-1.5, -1.5, -1.5]\nmax = [1.5, 1.5, 1.5]\n",
    );
    assert!(toml.contains("[media.haze.grid]"));
    let image = path_render(&toml, 1024, 4, 1);
    assert_close(
        channel_means(&image),
        haze_radiance(),
        0.03,
        "single scattering in a grid",
    );
}

/// The methods that do not render media (light tracing, the bidirectional ones) refuse a scene
/// with media with one typed error; the path tracer and the photon mappers take it, but not
/// with the photon mappers' `direct_lighting`.
#[test]
fn other_methods_refuse_media() {
    let scene = scene(&through_sphere("type = \"interface\""));
    for method in [Method::Light, Method::Vcm, Method::Bdpt] {
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
                "the scene has participating media, which {method} does not render: use the \
                 default method, sppm, ppm, appm or path"
            )
        );
    }
    for method in PHOTON_METHODS {
        assert!(Renderer::new(std::sync::Arc::clone(&scene), params(method, 1)).is_ok());
        let mut p = params(method, 1);
        p.connections.direct_lighting = true;
        assert!(matches!(
            Renderer::new(std::sync::Arc::clone(&scene), p).err(),
            Some(ParamError::MediaDirectLighting)
        ));
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

/// The haze of [`single_scattering_matches_the_slab_integral`] under the same light, rendered by
/// the photon mappers: the volume photons of the first scattering, gathered along the camera
/// rays, read the same closed form (with the default's light tracing and frequency photons on).
#[test]
fn photon_mappers_match_the_single_scattering_integral() {
    let expected = haze_radiance();
    for method in [Method::Sppm, Method::FreqSppm, Method::Ppm, Method::Appm] {
        let mut params = params(method, 200_000);
        params.budget.max_depth = 1;
        params.kernel.initial_radius = Some(0.05);
        let image = render(&scene(HAZE), params, 16);
        assert_close(
            channel_means(&image),
            expected,
            0.03,
            &format!("{method}: single scattering"),
        );
    }
}

/// The albedo-one furnace of [`white_furnace_of_an_albedo_one_medium_reads_the_wall_radiance`]
/// rendered by the photon mappers: the walls seen through the fog plus the light the fog
/// scatters toward the camera (volume photons after any number of scattering events, chromatic
/// free flights) make L = 1 in every channel.
/// With the uneven grid of [`white_furnace_of_an_albedo_one_grid_reads_the_wall_radiance`] the
/// photons' free flights are spectral tracking and the camera stretches' transmittance one
/// ratio-tracking walk each, which also weighs every photon gathered along them.
///
/// The grid's photon weights (spectral tracking with uneven channels) are heavy-tailed: over
/// seven seeds at 16 × 16 pixels, 100 000 photons and 16 passes the densest channel read 0.97 to
/// 1.034 (standard deviation 0.02), hence a larger film, more passes and a 5 % tolerance there.
#[test]
fn photon_mappers_read_the_furnace_of_an_albedo_one_medium() {
    for method in [Method::Sppm, Method::FreqSppm] {
        let mut params = params(method, 50_000);
        params.kernel.initial_radius = Some(0.1);
        let image = render(&scene(&furnace_fog_box()), params, 12);
        let what = format!("{method}: furnace");
        assert_close(channel_means(&image), [1.0; 3], 0.03, &what);
    }
    let grid = furnace_fog_box().replace("width = 8\nheight = 8", "width = 16\nheight = 16")
        + FURNACE_GRID;
    assert!(grid.contains("width = 16"));
    let mut params = params(Method::Sppm, 100_000);
    params.kernel.initial_radius = Some(0.1);
    let image = render(&scene(&grid), params, 24);
    assert_close(channel_means(&image), [1.0; 3], 0.05, "grid furnace");
}

/// An uneven density grid (0 to 2.5) over the furnace box.
const FURNACE_GRID: &str = "[media.fog.grid]\nsize = [3, 2, 2]\ndensity = [0.0, 2.5, 0.4, 1.0, 0.1, 2.0, 1.5, 0.0, 0.3, 0.8, 2.2, 0.6]\nmin = [-1.0, -1.0, -1.0]\nmax = [1.0, 1.0, 1.0]\n";

/// A closed box whose black walls all emit L = 1 inward, filled with a medium of albedo one
/// and seen from inside.
fn furnace_fog_box() -> String {
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
    toml += &crate::analytic::cube_walls("wall");
    toml
}

/// The repository's fog box (`scenes/peers/fog-box.toml`: a fog bounded by an interface mesh in
/// a diffuse room) at `size`².
fn fog_box(size: u32) -> std::sync::Arc<scene::Scene> {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/peers/fog-box.toml");
    let mut description = import::load(&path).unwrap();
    description.film = scene::Film {
        width: size,
        height: size,
    };
    std::sync::Arc::new(scene::Scene::new(description).unwrap())
}

/// In a scene with media the photon mappers' images are the same bits for any thread count and
/// across a checkpoint (the volume gather's sums are saved; PPM's stretches through the fog,
/// traced once, are traced again after a restore).
#[test]
fn photon_mappers_in_media_are_deterministic_and_resume_exactly() {
    let scene = fog_box(20);
    for method in [Method::Sppm, Method::FreqSppm, Method::Ppm, Method::Appm] {
        let p = params(method, 4_000);
        let run = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| render(&scene, p, 4))
        };
        let one = run(1);
        assert!(one.iter().flatten().any(|&v| v > 0.0), "{method}: black");
        let bits = |image: &[[f32; 3]]| -> Vec<u32> {
            image.iter().flatten().map(|v| v.to_bits()).collect()
        };
        assert_eq!(
            bits(&one),
            bits(&run(2)),
            "{method}: 1 and 2 threads differ"
        );
        let mut first = Renderer::new(std::sync::Arc::clone(&scene), p).unwrap();
        first.iterate();
        first.iterate();
        let bytes = first.save_state("fog");
        let mut resumed = Renderer::restore(std::sync::Arc::clone(&scene), &bytes).unwrap();
        resumed.iterate();
        resumed.iterate();
        assert_eq!(
            bits(&one),
            bits(&resumed.image()),
            "{method}: resume differs"
        );
    }
}

/// `appm` in media cut into work units: the exact sums of disjoint ranges of passes, each
/// started at its first pass, add up to those of one render of all of them (the volume gather's
/// radius depends on the pass's index alone), and the in-scattered light is in them.
#[test]
fn appm_units_in_media_merge_into_the_single_render_bit_for_bit() {
    let scene = fog_box(12);
    let mut p = params(Method::Appm, 3_000);
    p.frequency.pilot = 1;
    let mut single = Renderer::new(std::sync::Arc::clone(&scene), p).unwrap();
    for _ in 0..5 {
        single.iterate();
    }
    let whole = single.pass_sums().unwrap().clone();
    let kernels = single.kernels().unwrap().to_vec();
    let unit = |first: u32, count: u32| {
        let mut r =
            Renderer::with_kernels(std::sync::Arc::clone(&scene), p, kernels.clone(), first)
                .unwrap();
        for _ in 0..count {
            r.iterate();
        }
        r.pass_sums().unwrap().clone()
    };
    let mut merged = ppm::PassSums::new(whole.sums.len());
    for (first, count) in [(3, 2), (0, 1), (1, 2)] {
        assert!(merged.add(&unit(first, count)));
    }
    assert_eq!(merged, whole, "merged sums differ");
    // Without the volume photons the fog would be black where no surface shows through it.
    let mut no_volume = p;
    no_volume.kernel.volume_radius = 1e-9;
    let dark = render(&scene, no_volume, 5);
    let mean = |image: &[[f32; 3]]| image.iter().flatten().map(|&v| f64::from(v)).sum::<f64>();
    assert!(mean(&single.image()) > 1.05 * mean(&dark));
}
