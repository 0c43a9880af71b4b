//! Light tracing (`light`, Mitsuba's `ptracer`): paths traced from the emitters as photons are,
//! every non-specular vertex connected to the lens, no merging. Each connection adds
//! f·Φ·|cos θₓ|·(du/dω)/d² to the pixel it lands on: an unbiased estimate of the pixel's
//! average radiance over everything the camera sees on a non-specular surface first. What the
//! camera sees only through mirrors and glass a light tracer cannot reach (its image is black
//! there, as `ptracer`'s is); emitters and the environment seen directly are added by one
//! camera ray per pixel per pass.
//!
//! The paths are the photon mappers' (`light_path.rs`: the same emission sample, roulette and
//! BSDF samples from the same (seed, pass, photon index) streams), so for one seed `light` and
//! a photon mapper walk the same light paths.

use std::sync::Arc;
use std::time::Instant;

use glam::Vec2;
use rayon::prelude::*;
use scene::{Rgb, Scene};

use crate::checkpoint::codec::{Reader, StateError, Writer};
use crate::integrator::Integrator;
use crate::light_path::{Scatter, emit, lens_point, lens_radiance, scatter};
use crate::params::RenderParams;
use crate::rng::{CAMERA_STREAM, Sampler};
use crate::stats::{MemoryEstimate, PassStats};

/// Light paths per parallel work item; fixed so that the sums do not depend on the thread
/// count.
const PATH_CHUNK: u64 = 2048;
/// Pixels per parallel work item of the camera rays that see emitters.
const PIXEL_CHUNK: usize = 256;
/// Contributions kept per path in a pass's buffers, for the memory estimate: a path connects at
/// each non-specular vertex, about one to five of them on the scenes measured for the photon
/// buffers (docs/reliability.md); each is 16 bytes.
const SPLAT_BYTES_PER_PATH: u64 = 80;

/// A light-tracing render: per-pixel sums of the connections and of the emission seen directly.
pub(crate) struct LightTracer {
    scene: Arc<Scene>,
    params: RenderParams,
    width: u32,
    height: u32,
    passes: u32,
    /// Light paths emitted over all passes.
    emitted: u64,
    /// Per pixel: the connected radiance summed over all paths (each path's contribution is
    /// per path emitted, so the image divides by `emitted`).
    light: Vec<[f64; 3]>,
    /// Per pixel: the emission seen directly, one camera sample per pass.
    seen: Vec<[f64; 3]>,
    /// Whether the camera can see any emission (an emissive material or an environment);
    /// without it no camera ray is traced.
    sees_emission: bool,
    /// Per chunk of [`PATH_CHUNK`] paths, what they connected; kept from pass to pass.
    chunks: Vec<Chunk>,
}

/// What one chunk of paths connected in a pass.
#[derive(Default)]
struct Chunk {
    /// (pixel, radiance per path emitted), in trace order.
    splats: Vec<(u32, [f32; 3])>,
    /// Paths or contributions dropped for being NaN or infinite.
    non_finite: u64,
}

/// What a render will hold (the film aside): two `[f64; 3]` sums per pixel, as much again
/// while a checkpoint is written, and the contributions of a pass.
pub(crate) fn estimate(pixels: u64, params: &RenderParams) -> MemoryEstimate {
    let sums = pixels.saturating_mul(48);
    MemoryEstimate {
        hitpoints: sums,
        photons: u64::from(params.budget.photons_per_pass).saturating_mul(SPLAT_BYTES_PER_PATH),
        film: 0,
        checkpoint: sums,
    }
}

impl LightTracer {
    pub(crate) fn new(scene: Arc<Scene>, params: RenderParams) -> Self {
        let film = scene.description().film;
        let pixels = film.width as usize * film.height as usize;
        let sees_emission = scene.lights().has_environment()
            || scene
                .materials()
                .iter()
                .any(|m| m.emission != Rgb::ZERO || m.textures.is_some());
        Self {
            scene,
            params,
            width: film.width,
            height: film.height,
            passes: 0,
            emitted: 0,
            light: vec![[0.0; 3]; pixels],
            seen: vec![[0.0; 3]; pixels],
            sees_emission,
            chunks: Vec::new(),
        }
    }

    /// Traces light path `index` of pass `pass` and connects its non-specular vertices to the
    /// lens. `TEXTURED_HITS` must be the scene's `Scene::textured_hits`.
    fn trace<const TEXTURED_HITS: bool>(&self, pass: u32, index: u64, out: &mut Chunk) {
        let scene = &*self.scene;
        let seed = self.params.seed;
        let Some((mut sampler, emission)) = emit(scene, seed, pass, index, &mut out.non_finite)
        else {
            return;
        };
        let mut power = emission.power;
        let mut ray = emission.ray();
        let film = (self.width, self.height);
        let (max_depth, rr_depth) = (self.params.budget.max_depth, self.params.budget.rr_depth);
        // `depth`: the path's bounces before this hit; a connection adds the hit's own, so
        // hits at depth max_depth − 1 are the last that can connect.
        for depth in 0..max_depth {
            let Some(hit) = scene.intersect_inlined::<TEXTURED_HITS>(&ray) else {
                break;
            };
            let Some(material) = scene.material(hit.material) else {
                break;
            };
            let incoming = -ray.direction;
            let bsdf = scene.material_bsdf(material, &hit);
            if !bsdf.is_specular()
                && let Some((connection, pixel)) = lens_point(scene, &hit, &sampler, depth, film)
                && let Some(value) = lens_radiance(scene, &hit, &bsdf, incoming, power, &connection)
            {
                if value.is_finite() {
                    out.splats.push((pixel, [value.x, value.y, value.z]));
                } else {
                    out.non_finite += 1;
                }
            }
            if depth + 1 == max_depth {
                break;
            }
            let roulette = depth + 1 >= rr_depth;
            match scatter(&hit, &bsdf, incoming, power, roulette, &mut sampler) {
                Scatter::Continue { sample, power: p } => {
                    power = p;
                    ray = hit.spawn_ray(sample.incoming);
                }
                Scatter::End => break,
                Scatter::NonFinite => {
                    out.non_finite += 1;
                    break;
                }
            }
        }
    }

    /// The emission seen directly through `pixel` in pass `pass`: one camera ray, jittered
    /// over the pixel and the lens.
    fn seen_emission(&self, pass: u32, pixel: u32) -> Rgb {
        let mut sampler = Sampler::new(self.params.seed, pass, CAMERA_STREAM | u64::from(pixel));
        let (x, y) = (pixel % self.width, pixel / self.width);
        let film = Vec2::new(x as f32, y as f32) + sampler.next_2d();
        let ray = self.scene.camera().generate_ray(film, sampler.next_2d());
        match self.scene.intersect(&ray) {
            Some(hit) => self.scene.emitted(&hit),
            None => self.scene.lights().environment_radiance(ray.direction),
        }
    }
}

impl Integrator for LightTracer {
    fn params(&self) -> &RenderParams {
        &self.params
    }

    fn passes(&self) -> u32 {
        self.passes
    }

    fn photons_emitted(&self) -> u64 {
        self.emitted
    }

    fn iterate(&mut self) -> PassStats {
        let pass = self.passes;
        let mut stats = PassStats::empty(pass);
        let camera_clock = Instant::now();
        if self.sees_emission {
            let this = &*self;
            let seen: Vec<Rgb> = (0..this.seen.len() as u32)
                .into_par_iter()
                .with_min_len(PIXEL_CHUNK)
                .map(|pixel| this.seen_emission(pass, pixel))
                .collect();
            for (sum, l) in self.seen.iter_mut().zip(seen) {
                // A NaN or infinite emission would stay in the pixel for ever.
                if l.is_finite() {
                    sum[0] += f64::from(l.x);
                    sum[1] += f64::from(l.y);
                    sum[2] += f64::from(l.z);
                } else {
                    stats.non_finite += 1;
                }
            }
            stats.camera_paths = self.seen.len() as u64;
        }
        stats.timings.camera = camera_clock.elapsed().as_secs_f64();

        let trace_clock = Instant::now();
        let n = u64::from(self.params.budget.photons_per_pass);
        let first = self.emitted;
        let n_chunks = usize::try_from(n.div_ceil(PATH_CHUNK)).unwrap_or(usize::MAX);
        let mut chunks = std::mem::take(&mut self.chunks);
        chunks.resize_with(n_chunks, Chunk::default);
        let textured_hits = self.scene.textured_hits();
        let this = &*self;
        chunks.par_iter_mut().enumerate().for_each(|(chunk, out)| {
            out.splats.clear();
            out.non_finite = 0;
            let start = chunk as u64 * PATH_CHUNK;
            for index in first + start..first + (start + PATH_CHUNK).min(n) {
                if textured_hits {
                    this.trace::<true>(pass, index, out);
                } else {
                    this.trace::<false>(pass, index, out);
                }
            }
        });
        stats.timings.trace = trace_clock.elapsed().as_secs_f64();
        // In chunk order, whatever the thread count.
        let gather_clock = Instant::now();
        for chunk in &chunks {
            stats.light_connections += chunk.splats.len() as u64;
            stats.non_finite += chunk.non_finite;
            for &(pixel, v) in &chunk.splats {
                let sum = &mut self.light[pixel as usize];
                for c in 0..3 {
                    sum[c] += f64::from(v[c]);
                }
            }
        }
        stats.timings.gather = gather_clock.elapsed().as_secs_f64();
        self.chunks = chunks;
        self.emitted += n;
        self.passes += 1;
        stats.photons_traced = n;
        stats
    }

    /// Connected radiance over paths emitted, plus the emission seen over passes.
    fn image(&self) -> Vec<[f32; 3]> {
        let paths = self.emitted.max(1) as f64;
        let passes = f64::from(self.passes.max(1));
        self.light
            .iter()
            .zip(&self.seen)
            .map(|(l, s)| std::array::from_fn(|c| (l[c] / paths + s[c] / passes) as f32))
            .collect()
    }

    /// The paths emitted and both per-pixel sums.
    fn save(&self, w: &mut Writer) {
        w.u64(self.emitted);
        w.u64(self.light.len() as u64);
        for s in self.light.iter().chain(&self.seen) {
            s.iter().for_each(|&v| w.f64(v));
        }
    }

    fn saved_bound(&self) -> usize {
        16 + self.light.len().saturating_mul(48)
    }

    fn restore(&mut self, r: &mut Reader<'_>, passes: u32) -> Result<(), StateError> {
        let emitted = r.u64()?;
        if emitted != u64::from(passes) * u64::from(self.params.budget.photons_per_pass)
            || r.len()? != self.light.len()
        {
            return Err(StateError::Corrupt);
        }
        for s in self.light.iter_mut().chain(self.seen.iter_mut()) {
            *s = [r.f64()?, r.f64()?, r.f64()?];
        }
        self.emitted = emitted;
        self.passes = passes;
        Ok(())
    }
}
