//! Photon paths through participating media (`docs/media.md`): the medium a photon starts in,
//! its free flights, and its scattering by the phase function. `trace.rs` calls these only in
//! scenes with media.

use glam::Vec3;
use scene::{FreeFlight, Hit, Ray, Rgb, medium_after};

use super::Setup;
use crate::light_path::luminance;
use crate::path::MAX_CROSSINGS;
use crate::rng::Sampler;

/// What a photon's free flight along a ray in a medium ends in.
pub(super) enum Flight {
    /// It reaches the next surface (or leaves the scene) with this power.
    Through(Rgb),
    /// It scatters at `position`; `power` is its power times σs·T/pdf, the flux the phase
    /// function scatters (and the volume photon's power).
    Scatter { position: Vec3, power: Rgb },
    /// Nothing goes on (every channel's density is zero).
    End,
    /// Its power became NaN or infinite.
    NonFinite,
}

impl Setup {
    /// The medium at `point`, found by walking from the camera, whose medium the scene gives,
    /// to `point` through every surface between them: each changes the medium as a ray crossing
    /// it would (`scene::medium_after`). A photon starts in the medium of its emission point as
    /// the camera would reach it.
    pub(super) fn medium_at(&self, point: Vec3) -> Option<u32> {
        let scene = &*self.scene;
        let camera = scene.camera().position();
        let mut medium = scene.media().camera;
        let to = point - camera;
        let distance = to.length();
        if !(distance.is_finite() && distance > 0.0) {
            return medium;
        }
        let mut ray = Ray::new(camera, to, distance * (1.0 - 1e-4));
        for _ in 0..=MAX_CROSSINGS {
            let Some(hit) = scene.intersect(&ray) else {
                return medium;
            };
            medium = medium_after(scene.shape_media(&hit), &hit, ray.direction, medium);
            ray = hit.spawn_ray_to(point);
        }
        medium
    }

    /// A free flight along `ray` in medium `id` toward `hit` (none: the ray leaves the scene),
    /// for a photon of power `power`: `Medium::sample_free_flight`, with the channels in
    /// proportion to the power (spectral MIS: chromatic free-flight sampling in a homogeneous
    /// medium, spectral tracking in a grid), so that every channel stays unbiased.
    pub(super) fn fly(
        &self,
        id: u32,
        ray: &Ray,
        hit: Option<&Hit>,
        power: Rgb,
        sampler: &mut Sampler,
    ) -> Flight {
        let Some(m) = self.scene.media().list.get(id as usize) else {
            return Flight::Through(power);
        };
        let t_surface = hit.map_or(f32::INFINITY, |h| h.t);
        let total = power.element_sum();
        if total.is_nan() || total <= 0.0 {
            return Flight::End;
        }
        let flight = m.sample_free_flight(
            ray.origin,
            ray.direction,
            t_surface,
            power / total,
            &mut || sampler.next_f32(),
        );
        let (weight, position) = match flight {
            FreeFlight::Scatter { t, weight } => (weight, Some(ray.at(t))),
            FreeFlight::Pass { weight } => (weight, None),
        };
        if weight == Rgb::ZERO {
            return Flight::End;
        }
        let p = power * weight;
        if !p.is_finite() {
            return Flight::NonFinite;
        }
        match position {
            Some(position) => Flight::Scatter { position, power: p },
            None => Flight::Through(p),
        }
    }

    /// A photon that arrived along `ray` with power `arrived` and scattered at `position` in
    /// medium `id` with power `scattered` (σs·T/pdf applied): its new direction, drawn from the
    /// phase function (exact: weight one), and with `roulette` Russian roulette on the ratio of
    /// the two powers, as at a surface. `None` if the path ends.
    pub(super) fn scatter_in_medium(
        &self,
        id: u32,
        ray: &Ray,
        position: Vec3,
        (arrived, scattered): (Rgb, Rgb),
        roulette: bool,
        sampler: &mut Sampler,
    ) -> Option<(Ray, Rgb)> {
        let m = self.scene.media().list.get(id as usize)?;
        let sample = m.phase().sample(-ray.direction, sampler.next_2d());
        let u_roulette = sampler.next_f32();
        let mut power = scattered;
        if roulette {
            let survive =
                (luminance(scattered) / luminance(arrived).max(f32::MIN_POSITIVE)).min(1.0);
            if u_roulette >= survive {
                return None;
            }
            power /= survive;
        }
        (power != Rgb::ZERO).then(|| (Ray::infinite(position, sample.incoming), power))
    }
}
