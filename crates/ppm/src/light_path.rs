//! What every integrator that follows light from the emitters shares: one scattering step of a
//! light path with Russian roulette, and the connection of a light-path vertex to the lens.
//! The photon mappers (`photon_mapper/trace.rs`) and the light tracer (`light_tracer.rs`) walk
//! their paths with these, so that both draw the same random numbers for the same path.

use glam::{Vec2, Vec3};
use scene::{Bsdf, BsdfSample, EmissionSample, Hit, LensConnection, Rgb, Scene, TransportMode};

use crate::rng::Sampler;

/// The sampler dimension where a light path's lens samples start (two per bounce), far beyond
/// what its path draws, so that connecting to the camera leaves the paths as they are.
const LENS_DIMENSION: u64 = 1 << 40;

/// The start of light path `index` of pass `pass` in a render seeded `seed`: its random
/// stream, past the emission's dimensions, and its emission sample; `None` if no emitter could
/// be drawn or the emitted power is NaN or infinite (counted in `non_finite`).
#[inline]
pub(crate) fn emit(
    scene: &Scene,
    seed: u64,
    pass: u32,
    index: u64,
    non_finite: &mut u64,
) -> Option<(Sampler, EmissionSample)> {
    let mut sampler = Sampler::new(seed, pass, index);
    let u_light = sampler.next_f32();
    let u_pos = sampler.next_2d();
    let u_dir = sampler.next_2d();
    let emission = scene.lights().sample_emission(u_light, u_pos, u_dir)?;
    if !emission.power.is_finite() {
        *non_finite += 1;
        return None;
    }
    Some((sampler, emission))
}

/// How a light path goes on after [`scatter`].
pub(crate) enum Scatter {
    /// It goes on along `sample.incoming` with `power`.
    Continue { sample: BsdfSample, power: Rgb },
    /// It ends: killed by the roulette, absorbed, or its power fell to zero.
    End,
    /// It ends because its power became NaN or infinite.
    NonFinite,
}

/// Scatters a light path of power `power` that arrived at `hit` along −`incoming`, drawing the
/// lobe choice, the BSDF sample and the roulette's number from `sampler` (always all three, so
/// that the path's later dimensions do not depend on the outcome); `roulette` says whether
/// Russian roulette may end it at this bounce.
///
/// Russian roulette (pbrt-v4 SPPM) keeps the path's power roughly constant: it kills the path
/// with probability q = 1 − lum(scattered power) / lum(power) and divides the survivor by 1 − q.
/// On a Lambertian surface the scattered power is power × albedo whatever the direction (up to
/// the shading-normal correction, which the roulette leaves out there), so the roulette runs
/// before the direction is drawn and a killed path costs no BSDF sample; elsewhere it needs the
/// sampled weight. Either way q is fixed before `u_roulette` is compared with it: unbiased.
#[inline(always)]
pub(crate) fn scatter(
    hit: &Hit,
    bsdf: &Bsdf,
    incoming: Vec3,
    power: Rgb,
    roulette: bool,
    sampler: &mut Sampler,
) -> Scatter {
    let u_lobe = sampler.next_f32();
    let u = sampler.next_2d();
    let u_roulette = sampler.next_f32();
    let kill_probability = |scattered: Rgb| {
        let ratio = luminance(scattered) / luminance(power).max(f32::MIN_POSITIVE);
        (1.0 - ratio).max(0.0)
    };
    // The survival probability, when the roulette is decided before sampling.
    let decided = match bsdf.lambertian_albedo() {
        Some(albedo) if roulette => {
            let q = kill_probability(power * albedo);
            if u_roulette < q {
                return Scatter::End;
            }
            Some(1.0 - q)
        }
        _ => None,
    };
    let Some(sample) = bsdf.sample(incoming, u_lobe, u, TransportMode::Importance) else {
        return Scatter::End;
    };
    let new_power =
        power * sample.weight * shading_normal_correction(hit, incoming, sample.incoming);
    let survive = match decided {
        Some(survive) => survive,
        None if roulette => {
            let q = kill_probability(new_power);
            if u_roulette < q {
                return Scatter::End;
            }
            1.0 - q
        }
        None => 1.0,
    };
    let power = new_power / survive;
    if !power.is_finite() {
        return Scatter::NonFinite;
    }
    if power == Rgb::ZERO {
        return Scatter::End;
    }
    Scatter::Continue { sample, power }
}

/// Where the light-path vertex at `hit` (`depth` bounces after the emitter) meets the lens and
/// the film, and the pixel it lands on, on a `width`-pixel-wide film; `None` if it is behind
/// the camera or off the film. The lens point is drawn from the path's own stream at a fixed
/// far dimension, so the path itself is unchanged.
#[inline]
pub(crate) fn lens_point(
    scene: &Scene,
    hit: &Hit,
    sampler: &Sampler,
    depth: u32,
    (width, height): (u32, u32),
) -> Option<(LensConnection, u32)> {
    let camera = scene.camera();
    let u_lens = if camera.aperture_radius() > 0.0 {
        let mut lens = sampler.clone();
        lens.skip_to(LENS_DIMENSION + 2 * u64::from(depth));
        lens.next_2d()
    } else {
        Vec2::ZERO
    };
    let connection = camera.connect(hit.position, u_lens)?;
    // The film position is on the film (`connect`); its far edges belong to the last pixel.
    let x = (connection.film.x as u32).min(width - 1);
    let y = (connection.film.y as u32).min(height - 1);
    Some((connection, y * width + x))
}

/// The light a light-path vertex at `hit` (power `power`, arrived along −`incoming`) sends
/// through `connection` to its pixel: f·Φ·|cos θₓ|·(du/dω)/d², per photon emitted, the pixel
/// being one unit of film area. `None` where nothing arrives (no BSDF value toward the lens,
/// the lens hidden, a degenerate distance); the value may be NaN or infinite, which the caller
/// counts and drops.
#[inline]
pub(crate) fn lens_radiance(
    scene: &Scene,
    hit: &Hit,
    bsdf: &Bsdf,
    incoming: Vec3,
    power: Rgb,
    connection: &LensConnection,
) -> Option<Rgb> {
    lens_radiance_through(hit, bsdf, incoming, power, connection, |lens| {
        scene.visible(hit, lens).then_some(Rgb::ONE)
    })
}

/// [`lens_radiance`] with the visibility of the lens point given by `transmittance`: the
/// fraction of light that reaches it (`None` or zero where none does), for scenes with media.
#[inline]
pub(crate) fn lens_radiance_through(
    hit: &Hit,
    bsdf: &Bsdf,
    incoming: Vec3,
    power: Rgb,
    connection: &LensConnection,
    transmittance: impl FnOnce(Vec3) -> Option<Rgb>,
) -> Option<Rgb> {
    let to_lens = connection.lens - hit.position;
    let distance = to_lens.length();
    if distance.is_nan() || distance <= 0.0 {
        return None;
    }
    let toward = to_lens / distance;
    let f = bsdf.eval(toward, incoming);
    if f == Rgb::ZERO {
        return None;
    }
    let tr = transmittance(connection.lens).filter(|&tr| tr != Rgb::ZERO)?;
    let cos = toward.dot(hit.geometric_normal).abs();
    Some(f * power * tr * (cos * connection.density))
}

/// Veach's correction for shading normals on light paths (thesis §5.3; pbrt's
/// `CorrectShadingNormal`): the BSDF is not symmetric once the shading normal differs from the
/// geometric one, and flux carried by photons must be multiplied by
/// |ωo·n_s|·|ωi·n_g| / (|ωo·n_g|·|ωi·n_s|) at every bounce (ωo toward where the photon came
/// from, ωi the new direction). Without it photons through smooth-shaded meshes (the water
/// surface of the Cornell box) carry a few per cent too much or too little light.
fn shading_normal_correction(hit: &Hit, from: Vec3, to: Vec3) -> f32 {
    let (ns, ng) = (hit.shading_normal, hit.geometric_normal);
    let numerator = from.dot(ns).abs() * to.dot(ng).abs();
    let denominator = from.dot(ng).abs() * to.dot(ns).abs();
    if denominator > 0.0 {
        numerator / denominator
    } else {
        0.0
    }
}

pub(crate) fn luminance(c: Rgb) -> f32 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}
