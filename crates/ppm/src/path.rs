//! The reference integrator: unidirectional path tracing with next-event estimation and
//! multiple importance sampling (power heuristic), sharing the scene, materials and lights of
//! the photon mappers. It is deliberately simple: it is the independent ground truth the photon
//! mappers are checked against, not a competitor. In scenes with participating media every
//! camera path takes `path/media.rs` instead, which adds them; other scenes never reach it.

use std::sync::Arc;

use glam::Vec2;
use rayon::prelude::*;
use scene::{Bsdf, BsdfSample, Hit, LightSample, Ray, Rgb, Scene, TransportMode};

use crate::checkpoint::codec::{Reader, StateError, Writer};
use crate::integrator::Integrator;
use crate::params::RenderParams;
use crate::rng::Sampler;
use crate::stats::{MemoryEstimate, PassStats};

mod media;
pub(crate) use self::media::{MAX_CROSSINGS, transmittance};

/// Pixels per parallel work item; fixed so the work split does not depend on the thread count.
const PIXEL_CHUNK: usize = 256;

/// Progressive path tracing: every pass adds `samples_per_pixel` paths to every pixel.
pub(crate) struct PathTracer {
    scene: Arc<Scene>,
    params: RenderParams,
    width: u32,
    /// Sum of the radiance samples per pixel.
    sum: Vec<[f64; 3]>,
    /// Passes accumulated in `sum`.
    passes: u32,
}

/// What a render will hold (the film aside): one `[f64; 3]` sum per pixel, and as much again
/// while a checkpoint is written.
pub(crate) fn estimate(pixels: u64, _params: &RenderParams) -> MemoryEstimate {
    let sums = pixels.saturating_mul(24);
    MemoryEstimate {
        hitpoints: sums,
        photons: 0,
        film: 0,
        checkpoint: sums,
    }
}

impl PathTracer {
    pub(crate) fn new(scene: Arc<Scene>, params: RenderParams) -> Self {
        let film = scene.description().film;
        Self {
            scene,
            params,
            width: film.width,
            sum: vec![[0.0; 3]; film.width as usize * film.height as usize],
            passes: 0,
        }
    }

    /// Adds one pass of `samples_per_pixel` paths per pixel; returns the number of paths and of
    /// the samples dropped for being NaN or infinite.
    fn add_pass(&mut self) -> (u64, u64) {
        let pass = self.passes;
        let spp = self.params.film.samples_per_pixel;
        let this = &*self;
        let samples: Vec<([f64; 3], u64)> = (0..this.sum.len())
            .into_par_iter()
            .with_min_len(PIXEL_CHUNK)
            .map(|pixel| {
                let mut total = [0.0f64; 3];
                let mut non_finite = 0;
                for s in 0..spp {
                    let index = pixel as u64 * u64::from(spp) + u64::from(s);
                    let l = this.trace(pixel as u32, Sampler::new(this.params.seed, pass, index));
                    // A NaN or infinite sample would stay in the pixel forever.
                    if !l.is_finite() {
                        non_finite += 1;
                        continue;
                    }
                    total[0] += f64::from(l.x);
                    total[1] += f64::from(l.y);
                    total[2] += f64::from(l.z);
                }
                (total, non_finite)
            })
            .collect();
        let mut non_finite = 0;
        for (sum, (sample, dropped)) in self.sum.iter_mut().zip(samples) {
            non_finite += dropped;
            for c in 0..3 {
                sum[c] += sample[c];
            }
        }
        self.passes += 1;
        (self.sum.len() as u64 * u64::from(spp), non_finite)
    }

    /// One camera path through `pixel`: its radiance estimate.
    fn trace(&self, pixel: u32, mut sampler: Sampler) -> Rgb {
        let (x, y) = (pixel % self.width, pixel / self.width);
        let film = Vec2::new(x as f32, y as f32) + sampler.next_2d();
        let ray = self.scene.camera().generate_ray(film, sampler.next_2d());
        if self.scene.has_media() {
            return media::trace(&self.scene, &self.params, ray, &mut sampler);
        }
        let Some(hit) = self.scene.intersect(&ray) else {
            return self.scene.lights().environment_radiance(ray.direction);
        };
        self.scene.emitted(&hit) + self.scattered(hit, -ray.direction, 0, &mut sampler)
    }

    /// The radiance a path continued from `hit` (reached with `depth` bounces, looking back
    /// along `outgoing`) brings back, without the emission of `hit` itself: light sampling at
    /// every non-specular vertex and BSDF sampling, MIS-combined, up to `max_depth` bounces.
    pub(crate) fn scattered(
        &self,
        mut hit: Hit,
        mut outgoing: glam::Vec3,
        mut depth: u32,
        sampler: &mut Sampler,
    ) -> Rgb {
        let lights = self.scene.lights();
        let mut radiance = Rgb::ZERO;
        let mut beta = Rgb::ONE;
        // Each iteration scatters at `hit` (the vertex after `depth` bounces), then finds the
        // next vertex and its emission: emission found there ends a path with depth + 1 bounces,
        // light sampled at `hit` one with depth + 1, both at most max_depth.
        while depth < self.params.budget.max_depth {
            let Some(bsdf) = self.scene.bsdf(&hit) else {
                break;
            };
            let u_light = sampler.next_f32();
            let u_light_2d = sampler.next_2d();
            if !bsdf.is_specular() {
                radiance +=
                    beta * next_event(&self.scene, &hit, &bsdf, outgoing, u_light, u_light_2d);
            }
            let Some(sample) =
                sample_and_roulette(&bsdf, outgoing, &mut beta, depth, &self.params, sampler)
            else {
                break;
            };
            let ray = hit.spawn_ray(sample.incoming);
            let Some(next) = self.scene.intersect(&ray) else {
                // The path escapes: it sees the environment, shared with light sampling as an
                // emitter's emission is.
                if lights.has_environment() {
                    let weight = bsdf_emission_weight(&self.scene, &hit, &sample, None, &ray);
                    radiance += beta * lights.environment_radiance(ray.direction) * weight;
                }
                break;
            };
            let emitted = self.scene.emitted(&next);
            if emitted != Rgb::ZERO {
                // After a specular bounce emission counts in full (light sampling cannot find
                // it); otherwise it shares the path with light sampling at `hit`.
                let weight = bsdf_emission_weight(&self.scene, &hit, &sample, Some(&next), &ray);
                radiance += beta * emitted * weight;
            }
            hit = next;
            outgoing = -ray.direction;
            depth += 1;
        }
        radiance
    }
}

/// Light sampling at a non-specular vertex `hit` seen along −`outgoing`, MIS-weighted against
/// BSDF sampling by the power heuristic: the path tracer's next-event estimation, and the photon
/// mappers' direct lighting.
pub(crate) fn next_event(
    scene: &Scene,
    hit: &Hit,
    bsdf: &Bsdf,
    outgoing: glam::Vec3,
    u_light: f32,
    u: Vec2,
) -> Rgb {
    next_event_through(scene, hit, bsdf, outgoing, u_light, u, |sample| {
        if scene.light_visible(hit, sample) {
            Rgb::ONE
        } else {
            Rgb::ZERO
        }
    })
}

/// [`next_event`] with the light sample's visibility given by `transmittance` (one or zero
/// without media; what the shadow ray lets through with them).
fn next_event_through(
    scene: &Scene,
    hit: &Hit,
    bsdf: &Bsdf,
    outgoing: glam::Vec3,
    u_light: f32,
    u: Vec2,
    transmittance: impl FnOnce(&LightSample) -> Rgb,
) -> Rgb {
    let Some(sample) = scene
        .lights()
        .sample_direct(hit.position, hit.geometric_normal, u_light, u)
    else {
        return Rgb::ZERO;
    };
    if sample.pdf.is_nan() || sample.pdf <= 0.0 {
        return Rgb::ZERO;
    }
    let tr = transmittance(&sample);
    if tr == Rgb::ZERO {
        return Rgb::ZERO;
    }
    let f = bsdf.eval(outgoing, sample.incoming);
    if f == Rgb::ZERO {
        return Rgb::ZERO;
    }
    let cos = sample.incoming.dot(hit.shading_normal).abs();
    let weight = if sample.is_delta {
        1.0
    } else {
        power_heuristic(sample.pdf, bsdf.pdf(outgoing, sample.incoming))
    };
    f * tr * sample.radiance * (cos * weight / sample.pdf)
}

/// A camera path's next direction at a vertex after `depth` bounces: a BSDF sample (lobe, then
/// direction) and Russian roulette, drawn in that order from `sampler`; `beta` takes the
/// sample's weight and the roulette's. `None` where the path ends.
pub(crate) fn sample_and_roulette(
    bsdf: &Bsdf,
    outgoing: glam::Vec3,
    beta: &mut Rgb,
    depth: u32,
    params: &RenderParams,
    sampler: &mut Sampler,
) -> Option<BsdfSample> {
    let u_lobe = sampler.next_f32();
    let u = sampler.next_2d();
    let u_roulette = sampler.next_f32();
    let sample = bsdf.sample(outgoing, u_lobe, u, TransportMode::Radiance)?;
    *beta *= sample.weight;
    roulette(beta, depth, params, u_roulette).then_some(sample)
}

/// Russian roulette after a scattering event at `depth`: from `rr_depth` on, the path survives
/// with the throughput's largest channel (at most one) and is divided by it; whether it goes on
/// (a zero or non-finite throughput ends it too).
fn roulette(beta: &mut Rgb, depth: u32, params: &RenderParams, u: f32) -> bool {
    if depth + 1 >= params.budget.rr_depth {
        let survive = beta.max_element().min(1.0);
        if survive <= 0.0 || u >= survive {
            return false;
        }
        *beta /= survive;
    }
    *beta != Rgb::ZERO && beta.is_finite()
}

/// The MIS weight of emission that BSDF sample `sample` at `hit` found along `ray`: at the
/// emitter it hit (`next`) or, escaping, in the environment. After a specular lobe it counts in
/// full (light sampling cannot find it); otherwise it shares the light with [`next_event`].
pub(crate) fn bsdf_emission_weight(
    scene: &Scene,
    hit: &Hit,
    sample: &BsdfSample,
    next: Option<&Hit>,
    ray: &Ray,
) -> f32 {
    if sample.is_specular {
        return 1.0;
    }
    let lights = scene.lights();
    let light_pdf = match next {
        Some(next) => lights.pdf_direct(hit.position, hit.geometric_normal, next),
        None => lights.pdf_environment(ray.direction),
    };
    power_heuristic(sample.pdf, light_pdf)
}

/// Veach's power heuristic (β = 2) for the strategy with density `f` against one with `g`.
fn power_heuristic(f: f32, g: f32) -> f32 {
    let (f2, g2) = (f * f, g * g);
    if f2 + g2 > 0.0 { f2 / (f2 + g2) } else { 0.0 }
}

impl Integrator for PathTracer {
    fn params(&self) -> &RenderParams {
        &self.params
    }

    fn passes(&self) -> u32 {
        self.passes
    }

    fn iterate(&mut self) -> PassStats {
        let pass = self.passes;
        let clock = std::time::Instant::now();
        let (paths, non_finite) = self.add_pass();
        let mut stats = PassStats::empty(pass);
        stats.camera_paths = paths;
        stats.non_finite = non_finite;
        stats.timings.camera = clock.elapsed().as_secs_f64();
        stats
    }

    /// The mean radiance per pixel.
    fn image(&self) -> Vec<[f32; 3]> {
        let n = f64::from(self.passes.max(1)) * f64::from(self.params.film.samples_per_pixel);
        self.sum.iter().map(|s| s.map(|v| (v / n) as f32)).collect()
    }

    /// The per-pixel sums.
    fn save(&self, w: &mut Writer) {
        w.u64(self.sum.len() as u64);
        for s in &self.sum {
            s.iter().for_each(|&v| w.f64(v));
        }
    }

    fn saved_bound(&self) -> usize {
        8 + self.sum.len().saturating_mul(24)
    }

    fn restore(&mut self, r: &mut Reader<'_>, passes: u32) -> Result<(), StateError> {
        if r.len()? != self.sum.len() {
            return Err(StateError::Corrupt);
        }
        for s in &mut self.sum {
            *s = [r.f64()?, r.f64()?, r.f64()?];
        }
        self.passes = passes;
        Ok(())
    }
}
