//! The golden-image suite, `tests/scenes.toml`, and rendering one of its scenes.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Duration, Instant};

use anyhow::{Context, Result, bail};
use serde::Deserialize;

use film::Image;

/// The whole suite file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct Suite {
    /// Seeds used by `render-all --calibrate`.
    pub(crate) calibration_seeds: Vec<u64>,
    /// Every scene, in report order.
    pub(crate) scene: Vec<SuiteScene>,
}

/// One scene of the suite.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct SuiteScene {
    /// Short name: golden file name, `--bless` and `--filter` argument.
    pub(crate) name: String,
    /// Scene file, relative to the repository root.
    pub(crate) path: PathBuf,
    /// Film width in pixels (overrides the scene's).
    pub(crate) width: u32,
    /// Film height in pixels.
    pub(crate) height: u32,
    /// Photon-mapper passes at the check budget.
    pub(crate) passes: u32,
    /// Photons per pass.
    pub(crate) photons: u32,
    /// Hitpoint slots per pixel for the photon mappers.
    #[serde(default = "one")]
    pub(crate) spp: u32,
    /// Path-tracer passes (one path per pixel per pass) at the check budget.
    pub(crate) path_passes: u32,
    /// Path-tracer passes of the golden reference.
    pub(crate) reference_passes: u32,
    /// Paths per pixel per pass of the golden reference.
    pub(crate) reference_spp: u32,
    /// Maximum path depth (camera and photon paths, and the reference).
    #[serde(default = "default_depth")]
    pub(crate) max_depth: u32,
    /// Tolerances per method name.
    #[serde(default)]
    pub(crate) tolerance: BTreeMap<String, Tolerance>,
}

/// What a check accepts: relative MSE against the golden image and the deviation of the mean.
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct Tolerance {
    /// Largest accepted relative MSE.
    pub(crate) rel_mse: f64,
    /// Largest accepted |mean / reference mean − 1|.
    pub(crate) mean: f64,
}

fn one() -> u32 {
    1
}

fn default_depth() -> u32 {
    ppm::RenderParams::preview().budget.max_depth
}

/// Reads `tests/scenes.toml`.
pub(crate) fn load_suite(root: &Path) -> Result<Suite> {
    let path = root.join("tests/scenes.toml");
    let text =
        std::fs::read_to_string(&path).with_context(|| format!("reading {}", path.display()))?;
    let suite: Suite =
        toml::from_str(&text).with_context(|| format!("parsing {}", path.display()))?;
    Ok(suite)
}

/// Loads the scene file with the suite's film size.
pub(crate) fn load_scene(root: &Path, entry: &SuiteScene) -> Result<Arc<scene::Scene>> {
    load_scene_sized(root, &entry.path, entry.width, entry.height)
}

/// Loads a scene file (relative to the repository root) with the given film size.
pub(crate) fn load_scene_sized(
    root: &Path,
    path: &Path,
    width: u32,
    height: u32,
) -> Result<Arc<scene::Scene>> {
    let path = root.join(path);
    let mut description =
        import::load(&path).with_context(|| format!("loading {}", path.display()))?;
    description.film.width = width;
    description.film.height = height;
    let scene =
        scene::Scene::new(description).with_context(|| format!("building {}", path.display()))?;
    Ok(Arc::new(scene))
}

/// The parameters of `method` on `entry` at the check budget: the scene's `[render]` table,
/// then the suite's.
pub(crate) fn params(
    entry: &SuiteScene,
    scene: &scene::Scene,
    method: ppm::Method,
    seed: u64,
) -> Result<ppm::RenderParams> {
    let mut params = ppm::RenderParams::preview()
        .with_scene_defaults(&scene.description().render)
        .with_context(|| format!("[render] table of {}", entry.path.display()))?;
    params.method = method;
    params.seed = seed;
    params.budget.max_depth = entry.max_depth;
    params.budget.photons_per_pass = entry.photons;
    params.budget.photons_auto = false;
    params.film.samples_per_pixel = if method == ppm::Method::Path {
        1
    } else {
        entry.spp
    };
    Ok(params)
}

/// A finished render.
pub(crate) struct Rendered {
    pub(crate) image: Image,
    pub(crate) time: Duration,
}

/// Renders `passes` passes of `params` and returns the image.
pub(crate) fn render(
    scene: &Arc<scene::Scene>,
    params: ppm::RenderParams,
    passes: u32,
) -> Result<Rendered> {
    let start = Instant::now();
    let mut renderer =
        ppm::Renderer::new(Arc::clone(scene), params).context("render parameters")?;
    for _ in 0..passes {
        renderer.iterate();
    }
    let (w, h) = renderer.resolution();
    let image = Image::new(w as usize, h as usize, renderer.image());
    let time = start.elapsed();
    if image
        .pixels
        .iter()
        .any(|p| p.iter().any(|v| !v.is_finite()))
    {
        bail!("{} produced a non-finite pixel", params.method);
    }
    Ok(Rendered { image, time })
}

/// The passes of `method` at the check budget of `entry`.
pub(crate) fn passes(entry: &SuiteScene, method: ppm::Method) -> u32 {
    if method == ppm::Method::Path {
        entry.path_passes
    } else {
        entry.passes
    }
}

/// The pixels whose error is measured: every pixel except those where an emitter is seen
/// directly, at the pixel centre or at a neighbour's (a one-pixel dilation). A directly seen
/// lamp is hundreds of times brighter than the walls, so the few pixels on its outline, where
/// PPM's single fixed hitpoint per pixel lands either on or off the lamp, would otherwise
/// dominate both the mean and the relative MSE; they say nothing about light transport.
pub(crate) fn transport_mask(scene: &scene::Scene) -> Vec<bool> {
    first_hit_mask(scene, |m| m.emission.max_element() > 0.0)
}

/// The pixels whose error is measured for `method`: the [`transport_mask`], and for the light
/// tracer only those that do not see a mirror or glass first (with the same one-pixel
/// dilation), which it cannot reach by construction (as Mitsuba's `ptracer` cannot).
pub(crate) fn method_mask(scene: &scene::Scene, method: ppm::Method) -> Vec<bool> {
    let mut mask = transport_mask(scene);
    if method == ppm::Method::Light {
        let seen_direct = first_hit_mask(scene, |m| m.kind.is_specular());
        for (m, d) in mask.iter_mut().zip(seen_direct) {
            *m &= d;
        }
    }
    mask
}

/// Every pixel except those whose first hit through the pixel centre, or a neighbour's (a
/// one-pixel dilation), is a material for which `excluded` holds.
fn first_hit_mask(scene: &scene::Scene, excluded: impl Fn(&scene::Material) -> bool) -> Vec<bool> {
    let film = scene.description().film;
    let (w, h) = (film.width as usize, film.height as usize);
    let hit = first_hits(scene, excluded);
    let mut mask = vec![true; w * h];
    for y in 0..h {
        for x in 0..w {
            if hit[y * w + x] {
                for yy in y.saturating_sub(1)..(y + 2).min(h) {
                    for xx in x.saturating_sub(1)..(x + 2).min(w) {
                        mask[yy * w + xx] = false;
                    }
                }
            }
        }
    }
    mask
}

/// Per pixel of the scene's film, whether the camera ray through the pixel centre first hits a
/// material for which `class` holds.
pub(crate) fn first_hits(
    scene: &scene::Scene,
    class: impl Fn(&scene::Material) -> bool,
) -> Vec<bool> {
    let film = scene.description().film;
    let (w, h) = (film.width as usize, film.height as usize);
    let mut hits = vec![false; w * h];
    for y in 0..h {
        for x in 0..w {
            let ray = scene.camera().generate_ray(
                glam::Vec2::new(x as f32 + 0.5, y as f32 + 0.5),
                glam::Vec2::splat(0.5),
            );
            hits[y * w + x] = scene
                .intersect(&ray)
                .and_then(|hit| scene.material(hit.material))
                .is_some_and(&class);
        }
    }
    hits
}
