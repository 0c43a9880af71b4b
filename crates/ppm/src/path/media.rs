//! The path tracer in scenes with participating media (`docs/media.md`): the same estimator as
//! [`super::PathTracer::scattered`] (next-event estimation and BSDF sampling combined by the
//! power heuristic, Russian roulette from `rr_depth`), with homogeneous media between surfaces.
//!
//! - The path knows the medium it travels in: the camera's to start with, then the side of each
//!   shape it crosses ([`scene::medium_after`]): by a dielectric's refraction, or straight
//!   through an interface, which does not scatter and does not count as a bounce.
//! - Free-flight sampling is chromatic (pbrt-v4's and Mitsuba's spectral MIS over RGB): a
//!   channel is picked with probability proportional to the path throughput, a distance drawn
//!   from that channel's exp(−σt·t), and the density is the average of the channels' densities
//!   under those probabilities, so every channel's estimate stays unbiased. In a grid medium
//!   it is spectral delta tracking ([`scene::Medium::sample_free_flight`]) with the same
//!   channel proportions, and shadow rays estimate the transmittance by ratio tracking
//!   ([`scene::Medium::transmittance_along`]).
//! - At a medium vertex the Henyey–Greenstein phase function scatters; its sampling is exact
//!   (weight one). Next-event estimation from surfaces and medium vertices multiplies by the
//!   transmittance of the shadow ray, computed exactly through every medium it crosses and
//!   through interfaces (any other surface occludes).
//! - MIS weights compare solid-angle densities of the direction only (light sampling against
//!   phase or BSDF sampling); the transmittance is a factor both strategies share, which keeps
//!   the combination unbiased.

use glam::Vec3;
use scene::{FreeFlight, Hit, Ray, Rgb, Scene, medium_after};

use super::{next_event_through, power_heuristic, roulette, sample_and_roulette};
use crate::params::RenderParams;
use crate::rng::Sampler;

/// At most this many interfaces are crossed between two scattering events (or along one
/// shadow ray); a path beyond it ends. It only guards against a ray caught between coincident
/// surfaces: real scenes never come near it.
pub(crate) const MAX_CROSSINGS: u32 = 256;

/// The vertex a path last scattered at, for the MIS weight of emission found after it.
#[derive(Clone, Copy)]
struct Scatter {
    /// Its position.
    position: Vec3,
    /// The geometric normal at a surface, zero in a medium (as the light sampler takes it).
    normal: Vec3,
    /// The solid-angle density of the direction it drew.
    pdf: f32,
    /// Whether that direction came from a delta lobe (or is the camera ray): emission then
    /// counts in full.
    specular: bool,
}

/// The radiance arriving along the camera ray `ray` in a scene with media.
pub(super) fn trace(scene: &Scene, params: &RenderParams, ray: Ray, sampler: &mut Sampler) -> Rgb {
    let lights = scene.lights();
    let media = &scene.media().list;
    let mut medium = scene.media().camera;
    let mut ray = ray;
    let mut radiance = Rgb::ZERO;
    let mut beta = Rgb::ONE;
    let mut depth = 0;
    let mut crossings = 0;
    let mut last = Scatter {
        position: ray.origin,
        normal: Vec3::ZERO,
        pdf: 1.0,
        specular: true,
    };
    loop {
        let hit = scene.intersect(&ray);
        let t_surface = hit.map_or(f32::INFINITY, |h| h.t);
        if let Some(m) = medium.and_then(|m| media.get(m as usize)) {
            let total = beta.x + beta.y + beta.z;
            if total.is_nan() || total <= 0.0 {
                break;
            }
            let q = beta / total;
            // The distance of a medium vertex before the surface, if the flight ends in one
            // (`Medium::sample_free_flight`: chromatic free-flight sampling in a homogeneous
            // medium, spectral delta tracking in a grid); `beta` is weighted either way.
            let flight = m.sample_free_flight(ray.origin, ray.direction, t_surface, q, &mut || {
                sampler.next_f32()
            });
            let (scatter_at, weight) = match flight {
                FreeFlight::Scatter { t, weight } => (Some(t), weight),
                FreeFlight::Pass { weight } => (None, weight),
            };
            beta *= weight;
            if beta == Rgb::ZERO || !beta.is_finite() {
                break;
            }
            if let Some(t) = scatter_at {
                let position = ray.at(t);
                if depth >= params.budget.max_depth {
                    break;
                }
                let phase = m.phase();
                let outgoing = -ray.direction;
                let (u_light, u_light_2d) = (sampler.next_f32(), sampler.next_2d());
                if let Some(sample) =
                    lights.sample_direct(position, Vec3::ZERO, u_light, u_light_2d)
                    && sample.pdf > 0.0
                {
                    let p = phase.eval(outgoing, sample.incoming);
                    let shadow = shadow_ray(position, sample.incoming, sample.distance);
                    let tr = transmittance_by(scene, shadow, medium, &mut || sampler.next_f32());
                    if p > 0.0 && tr != Rgb::ZERO {
                        let weight = if sample.is_delta {
                            1.0
                        } else {
                            power_heuristic(sample.pdf, p)
                        };
                        radiance += beta * tr * sample.radiance * (p * weight / sample.pdf);
                    }
                }
                let s = phase.sample(outgoing, sampler.next_2d());
                let u_roulette = sampler.next_f32();
                if !roulette(&mut beta, depth, params, u_roulette) {
                    break;
                }
                last = Scatter {
                    position,
                    normal: Vec3::ZERO,
                    pdf: s.pdf,
                    specular: false,
                };
                ray = Ray::infinite(position, s.incoming);
                depth += 1;
                crossings = 0;
                continue;
            }
        }
        let Some(hit) = hit else {
            if lights.has_environment() {
                let weight = if last.specular {
                    1.0
                } else {
                    power_heuristic(last.pdf, lights.pdf_environment(ray.direction))
                };
                radiance += beta * lights.environment_radiance(ray.direction) * weight;
            }
            break;
        };
        if scene.is_interface(&hit) {
            crossings += 1;
            if crossings > MAX_CROSSINGS {
                break;
            }
            medium = medium_after(scene.shape_media(&hit), &hit, ray.direction, medium);
            ray = hit.spawn_ray(ray.direction);
            continue;
        }
        let emitted = scene.emitted(&hit);
        if emitted != Rgb::ZERO {
            let weight = if last.specular {
                1.0
            } else {
                power_heuristic(
                    last.pdf,
                    lights.pdf_direct(last.position, last.normal, &hit),
                )
            };
            radiance += beta * emitted * weight;
        }
        if depth >= params.budget.max_depth {
            break;
        }
        let Some(bsdf) = scene.bsdf(&hit) else {
            break;
        };
        let outgoing = -ray.direction;
        let u_light = sampler.next_f32();
        let u_light_2d = sampler.next_2d();
        if !bsdf.is_specular() {
            radiance += beta
                * surface_next_event(
                    scene, &hit, &bsdf, outgoing, medium, u_light, u_light_2d, sampler,
                );
        }
        let Some(sample) = sample_and_roulette(&bsdf, outgoing, &mut beta, depth, params, sampler)
        else {
            break;
        };
        medium = medium_after(scene.shape_media(&hit), &hit, sample.incoming, medium);
        last = Scatter {
            position: hit.position,
            normal: hit.geometric_normal,
            pdf: sample.pdf,
            specular: sample.is_specular,
        };
        ray = hit.spawn_ray(sample.incoming);
        depth += 1;
        crossings = 0;
    }
    radiance
}

/// The shadow ray from a point in a medium toward a light sample at `distance` (∞ for an
/// infinite light), stopping just short of a finite target as [`Hit::spawn_ray_to`] does.
fn shadow_ray(origin: Vec3, direction: Vec3, distance: f32) -> Ray {
    if distance.is_finite() {
        Ray::new(origin, direction, distance * (1.0 - 1e-4))
    } else {
        Ray::infinite(origin, direction)
    }
}

/// The transmittance along `ray` (to its `t_max`) starting in `medium`: the product of each
/// medium's over its stretch, through interfaces; zero if any other surface is in the way.
pub(crate) fn transmittance(scene: &Scene, ray: Ray, medium: Option<u32>) -> Rgb {
    // Exact through homogeneous media, which draw no number. Through a grid, ratio tracking
    // with numbers hashed from the ray: deterministic, and unbiased for each ray.
    let mut rng = RayHash::new(&ray);
    transmittance_by(scene, ray, medium, &mut || rng.next_f32())
}

/// [`transmittance`] with the numbers of ratio tracking in grid media drawn from `u` (the path
/// tracer's sampler); homogeneous media draw none.
fn transmittance_by(
    scene: &Scene,
    mut ray: Ray,
    mut medium: Option<u32>,
    u: &mut impl FnMut() -> f32,
) -> Rgb {
    let media = &scene.media().list;
    let target = ray.t_max.is_finite().then(|| ray.at(ray.t_max));
    let mut tr = Rgb::ONE;
    for _ in 0..=MAX_CROSSINGS {
        let hit = scene.intersect(&ray);
        if let Some(m) = medium.and_then(|m| media.get(m as usize)) {
            let t = hit.map_or(ray.t_max, |h| h.t);
            if m.is_homogeneous() {
                tr *= m.transmittance(t);
            } else {
                tr *= m.transmittance_along(ray.origin, ray.direction, t, u);
            }
        }
        let Some(hit) = hit else {
            return tr;
        };
        if tr == Rgb::ZERO || !scene.is_interface(&hit) {
            return Rgb::ZERO;
        }
        medium = medium_after(scene.shape_media(&hit), &hit, ray.direction, medium);
        ray = match target {
            Some(target) => hit.spawn_ray_to(target),
            None => hit.spawn_ray(ray.direction),
        };
    }
    Rgb::ZERO
}

/// Uniform numbers from a hash of a ray (SplitMix64 over its origin's and direction's bits),
/// for [`transmittance`]'s callers that have no sampler.
struct RayHash(u64);

impl RayHash {
    fn new(ray: &Ray) -> Self {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        for v in ray
            .origin
            .to_array()
            .into_iter()
            .chain(ray.direction.to_array())
        {
            state = (state ^ u64::from(v.to_bits())).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            state ^= state >> 31;
        }
        Self(state)
    }

    fn next_f32(&mut self) -> f32 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^= z >> 31;
        (z >> 40) as f32 * (1.0 / (1u64 << 24) as f32)
    }
}

/// Light sampling at a non-specular surface vertex `hit` seen along −`outgoing`, in a scene
/// with media: [`super::next_event`] with the shadow ray's transmittance for its visibility.
/// `medium` is the medium the path arrived in; the shadow ray leaves in the medium of the side
/// it leaves to.
#[allow(clippy::too_many_arguments)]
fn surface_next_event(
    scene: &Scene,
    hit: &Hit,
    bsdf: &scene::Bsdf,
    outgoing: Vec3,
    medium: Option<u32>,
    u_light: f32,
    u: glam::Vec2,
    sampler: &mut Sampler,
) -> Rgb {
    next_event_through(scene, hit, bsdf, outgoing, u_light, u, |sample| {
        let shadow = if sample.distance.is_finite() {
            hit.spawn_ray_to(hit.position + sample.incoming * sample.distance)
        } else {
            hit.spawn_ray(sample.incoming)
        };
        let start = medium_after(scene.shape_media(hit), hit, sample.incoming, medium);
        transmittance_by(scene, shadow, start, &mut || sampler.next_f32())
    })
}
