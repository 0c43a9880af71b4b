//! Vertex connection and merging (`vcm`; Georgiev, Křivánek, Davidovič & Slusallek 2012) and
//! bidirectional path tracing (`bdpt`, the same code without merging).
//!
//! A pass traces `photons_per_pass` light subpaths (`light.rs`), keeping their non-specular
//! vertices and connecting each to the lens, builds a hash grid over the kept vertices with the
//! pass's merge radius, and traces `samples_per_pixel` camera subpaths per pixel
//! (`camera.rs`), which at every vertex add the emission found there and, at non-specular ones,
//! next-event estimation, connections to the vertices of one light subpath (camera path j with
//! light subpath j mod n_L) and merges with every light vertex within the radius. Every
//! contribution carries its balance-heuristic weight over all the strategies that could have
//! sampled its path, computed recursively (`mis.rs`).
//!
//! The merge radius of pass i (0-based) is r₀·gᵢ with Knaus and Zwicker's schedule (that of
//! `appm`, with α = `alpha`), so that merging is consistent: r₀ is `initial_radius` or
//! [`AUTO_RADIUS_SCALE`] times the photon mappers' automatic radius. Nothing but the per-pixel
//! sums carries from pass to pass: a pass depends only on its index, so the sums are exact
//! (`PassSums`, fixed point) and work units that render disjoint ranges of passes merge into the
//! image of one render, bit for bit.

mod camera;
mod light;
pub(crate) mod mis;
mod radius;
#[cfg(test)]
mod tests;

use std::sync::Arc;
use std::time::Instant;

use glam::Vec3;
use photon::{GridParams, HitPointGrid};
use rayon::prelude::*;
use scene::{Hit, Scene};

use self::camera::{CameraPass, CameraSample};
use self::light::{LightChunk, LightPass, LightVertex, LightVertices, PATH_CHUNK};
use self::mis::{Mis, Strategies};
use self::radius::{FrequencyField, MergeRadius};
use crate::checkpoint::codec::{Reader, StateError, Writer};
use crate::independent::sums::FIXED_POINT;
use crate::independent::{PassSums, schedule_squared};
use crate::integrator::Integrator;
use crate::params::{Method, ParamError, RenderParams};
use crate::photon_mapper::auto_initial_radius;
use crate::stats::{MemoryEstimate, MemoryUse, PassStats};

/// vcm's default r₀ as a share of the photon mappers' automatic radius (about two pixels'
/// footprint): about half a pixel's. Merges cost a grid query and a BSDF evaluation for every
/// light vertex in the disc, and connections already carry most diffuse transport, so a smaller
/// disc than a photon mapper's gather wins at equal time (docs/integrators.md, "The radius").
pub(crate) const AUTO_RADIUS_SCALE: f64 = 0.25;

/// Pixels per parallel work item of the camera subpaths.
const PIXEL_CHUNK: usize = 64;
/// Light vertices kept per light subpath, for the memory estimate: 0.66 to 4.7 on the
/// repository's scenes (docs/integrators.md); the estimate takes 5.
const VERTICES_PER_PATH: u64 = 5;
/// Bytes per kept light vertex: the vertex in its chunk's buffer (which may hold twice what it
/// keeps, as it grows by doubling), its position copy for the grid and the grid's entries
/// (measured 35–40 per hitpoint for the photon mappers' grid).
const BYTES_PER_VERTEX: u64 = 2 * std::mem::size_of::<LightVertex>() as u64 + 12 + 48;
/// Bytes per light subpath of a pass besides its vertices: its end offset (twice, for the
/// doubling) and up to five connections to the lens of 16 bytes.
const BYTES_PER_PATH: u64 = 8 + 80;

/// A vertex connection and merging render: per-pixel sums of the pass estimates.
pub(crate) struct Vcm {
    scene: Arc<Scene>,
    params: RenderParams,
    strategies: Strategies,
    width: u32,
    height: u32,
    /// r₀, the merge radius of the first pass.
    radius: f64,
    passes: u32,
    /// Per pixel: the exact sum over the passes rendered of each pass's estimate of the pixel's
    /// mean radiance (fixed point; `sums.passes` of them, fewer than `passes` in a work unit
    /// that started after pass 0).
    sums: PassSums,
    /// Per chunk of [`PATH_CHUNK`] light subpaths, what they produced; kept from pass to pass.
    chunks: Vec<LightChunk>,
    /// Per chunk, the pass number of its first kept vertex; then their total.
    offsets: Vec<u32>,
    /// The grid of the last pass (kept for its memory report).
    grid: Option<HitPointGrid>,
    /// With frequency-sized merges, the predicted radius over the scene, from the pilot run
    /// before the first pass this render traces (a function of the scene and the parameters).
    field: Option<FrequencyField>,
}

/// What a render will hold (the film aside): the per-pixel sums and a pass's estimate (and the
/// sums again while a checkpoint is written), and the light vertices, grid and connections of a
/// pass.
pub(crate) fn estimate(pixels: u64, params: &RenderParams) -> MemoryEstimate {
    let sums = pixels.saturating_mul(48);
    let paths = u64::from(params.budget.photons_per_pass);
    let per_path = BYTES_PER_PATH + VERTICES_PER_PATH * BYTES_PER_VERTEX;
    let own = MemoryEstimate {
        hitpoints: sums.saturating_add(pixels.saturating_mul(24 + 40)),
        photons: paths.saturating_mul(per_path),
        film: 0,
        checkpoint: sums,
    };
    if !(params.kernel.freq_radius && params.method == Method::Vcm) {
        return own;
    }
    // Frequency-sized merges: the pilot (a freq-sppm render, gone before the first pass
    // allocates its buffers) and the field, at most one cell of 16 bytes (and a control byte,
    // 8/7 full) per hitpoint slot.
    let pilot = crate::photon_mapper::estimate(pixels, params, true);
    let slots = pixels.saturating_mul(u64::from(params.film.samples_per_pixel));
    MemoryEstimate {
        hitpoints: own
            .hitpoints
            .max(pilot.hitpoints)
            .saturating_add(slots.saturating_mul(20)),
        photons: own.photons.max(pilot.photons),
        film: 0,
        checkpoint: own.checkpoint,
    }
}

/// |w·n_s| / |w·n_g| at `hit`: what the flux arriving along `w` per unit of geometric area
/// brings to a BSDF evaluated against the shading normal (Veach 1997, §5.3).
pub(crate) fn shading_ratio(hit: &Hit, w: Vec3) -> f32 {
    shading_ratio_about(hit.shading_normal, hit.geometric_normal, w)
}

/// [`shading_ratio`] about a shading normal and a geometric normal.
pub(crate) fn shading_ratio_about(shading: Vec3, geometric: Vec3, w: Vec3) -> f32 {
    let (s, g) = (w.dot(shading).abs(), w.dot(geometric).abs());
    if g > 0.0 { s / g } else { 0.0 }
}

impl Vcm {
    /// A render of `scene` by `params.method` (`vcm` or `bdpt`).
    pub(crate) fn new(scene: Arc<Scene>, params: RenderParams) -> Self {
        let strategies = if params.method == Method::Bdpt {
            Strategies::BDPT
        } else {
            Strategies::VCM
        };
        Self::with_strategies(scene, params, strategies)
    }

    /// A render that combines only `strategies` (for the tests of each strategy alone).
    pub(crate) fn with_strategies(
        scene: Arc<Scene>,
        params: RenderParams,
        strategies: Strategies,
    ) -> Self {
        let film = scene.description().film;
        let radius = params
            .kernel
            .initial_radius
            .unwrap_or_else(|| AUTO_RADIUS_SCALE * auto_initial_radius(&scene));
        Self {
            params,
            strategies,
            width: film.width,
            height: film.height,
            radius,
            passes: 0,
            sums: PassSums::new(film.width as usize * film.height as usize),
            chunks: Vec::new(),
            offsets: Vec::new(),
            grid: None,
            field: None,
            scene,
        }
    }

    /// A render (`vcm` or `bdpt`) whose next pass is `first_pass`: a work unit, which renders
    /// its passes and hands back their exact sums.
    ///
    /// # Errors
    ///
    /// [`ParamError`] if the method is not `vcm` or `bdpt` or a parameter is outside its domain.
    pub(crate) fn starting_at(
        scene: Arc<Scene>,
        params: RenderParams,
        first_pass: u32,
    ) -> Result<Self, ParamError> {
        if !matches!(params.method, Method::Vcm | Method::Bdpt) {
            return Err(ParamError::NotPassIndependent {
                method: params.method,
            });
        }
        params.validate()?;
        let mut render = Self::new(scene, params);
        render.passes = first_pass;
        Ok(render)
    }

    /// The merge radius of pass `pass` (0-based).
    fn radius_of(&self, pass: u32) -> f64 {
        self.radius * schedule_squared(u64::from(pass), self.params.kernel.alpha).sqrt()
    }

    /// Whether merges are sized by the frequency prediction.
    fn frequency_sized(&self) -> bool {
        self.strategies.merging && self.params.kernel.freq_radius
    }

    /// Traces the pass's light subpaths into `chunks` (their kept vertices and connections to
    /// the lens stay there) and numbers the kept vertices (`offsets`).
    fn light_pass(&mut self, mis: Mis, global_radius: f64, stats: &mut PassStats) {
        let n = u64::from(self.params.budget.photons_per_pass);
        let n_chunks = usize::try_from(n.div_ceil(PATH_CHUNK)).unwrap_or(usize::MAX);
        let mut chunks = std::mem::take(&mut self.chunks);
        chunks.resize_with(n_chunks, LightChunk::default);
        let pass = LightPass {
            scene: &self.scene,
            mis,
            radius: MergeRadius {
                global: global_radius,
                field: self.field.as_ref(),
            },
            seed: self.params.seed,
            pass: self.passes,
            max_depth: self.params.budget.max_depth,
            rr_depth: self.params.budget.rr_depth,
            film: (self.width, self.height),
        };
        // Light subpaths are numbered over the whole render, as photons are.
        let first = u64::from(self.passes) * n;
        chunks.par_iter_mut().enumerate().for_each(|(chunk, out)| {
            out.clear();
            let start = chunk as u64 * PATH_CHUNK;
            for index in first + start..first + (start + PATH_CHUNK).min(n) {
                pass.trace(index, out);
            }
        });
        // In chunk order, whatever the thread count.
        self.offsets.clear();
        let mut kept = 0u32;
        for chunk in &mut chunks {
            self.offsets.push(kept);
            // The grid numbers vertices in u32. A pass that keeps more (some 500 GB of
            // vertices, far beyond any memory estimate a render starts with) keeps the first
            // ones; the rest do not connect or merge.
            let fits = u32::try_from(chunk.vertices.len())
                .ok()
                .and_then(|len| kept.checked_add(len))
                .filter(|&total| total < u32::MAX);
            match fits {
                Some(total) => kept = total,
                None => chunk.vertices.clear(),
            }
            stats.non_finite += chunk.non_finite;
            stats.light_connections += chunk.splats.len() as u64;
        }
        self.offsets.push(kept);
        stats.photons_traced = n;
        stats.photons_stored = u64::from(kept);
        self.chunks = chunks;
    }
}

impl Integrator for Vcm {
    fn params(&self) -> &RenderParams {
        &self.params
    }

    fn passes(&self) -> u32 {
        self.passes
    }

    fn photons_emitted(&self) -> u64 {
        u64::from(self.passes) * u64::from(self.params.budget.photons_per_pass)
    }

    fn iterate(&mut self) -> PassStats {
        let pass = self.passes;
        let mut stats = PassStats::empty(pass);
        let radius = self.radius_of(pass);
        let light_paths = u64::from(self.params.budget.photons_per_pass);
        let spp = self.params.film.samples_per_pixel;
        let mis = Mis::new(self.strategies, light_paths, spp);
        if self.frequency_sized() && self.field.is_none() {
            // Cells of the first pass's radius: the largest any merge has.
            self.field = Some(radius::pilot_field(&self.scene, self.params, self.radius));
        }

        let trace_clock = Instant::now();
        self.light_pass(mis, radius, &mut stats);
        stats.timings.trace = trace_clock.elapsed().as_secs_f64();

        let index_clock = Instant::now();
        self.grid = None;
        if self.strategies.merging {
            let vertices = || self.chunks.iter().flat_map(|c| c.vertices.iter());
            let positions: Vec<Vec3> = vertices().map(|v| v.position).collect();
            // The global radius bounds every merge's r(x); a merge checks its own.
            let radii = vec![radius; positions.len()];
            self.grid = Some(HitPointGrid::build(&positions, &radii, GridParams::DEFAULT));
            stats.mean_radius = radius;
            stats.min_radius = radius;
            stats.max_radius = radius;
            if self.field.is_some() && !positions.is_empty() {
                // The radii at the light vertices, as a sample of where merges happen.
                let at: Vec<f64> = vertices().map(|v| f64::from(v.radius)).collect();
                stats.mean_radius = at.iter().sum::<f64>() / at.len() as f64;
                stats.min_radius = at.iter().copied().fold(f64::INFINITY, f64::min);
            }
        }
        stats.timings.index = index_clock.elapsed().as_secs_f64();

        let camera_clock = Instant::now();
        let camera = CameraPass {
            scene: &self.scene,
            mis,
            radius: MergeRadius {
                global: radius,
                field: self.field.as_ref(),
            },
            seed: self.params.seed,
            pass,
            max_depth: self.params.budget.max_depth,
            rr_depth: self.params.budget.rr_depth,
            width: self.width,
            samples_per_pixel: spp,
            vertices: LightVertices {
                chunks: &self.chunks,
                offsets: &self.offsets,
            },
            light_paths,
            grid: self.grid.as_ref(),
        };
        let pixels: Vec<([f64; 3], u64, u64)> = (0..self.sums.sums.len() as u32)
            .into_par_iter()
            .with_min_len(PIXEL_CHUNK)
            .map(|pixel| {
                let mut total = [0.0f64; 3];
                let (mut merges, mut non_finite) = (0, 0);
                for s in 0..spp {
                    let CameraSample {
                        radiance,
                        merges: m,
                    } = camera.trace(pixel, s);
                    merges += m;
                    // A NaN or infinite sample would stay in the pixel for ever.
                    if !radiance.is_finite() {
                        non_finite += 1;
                        continue;
                    }
                    for c in 0..3 {
                        total[c] += f64::from(radiance[c]);
                    }
                }
                (total, merges, non_finite)
            })
            .collect();
        stats.camera_paths = self.sums.sums.len() as u64 * u64::from(spp);
        stats.timings.camera = camera_clock.elapsed().as_secs_f64();

        let gather_clock = Instant::now();
        let per_sample = 1.0 / f64::from(spp);
        let per_path = 1.0 / light_paths as f64;
        // Each pass adds its estimate of every pixel: the camera subpaths' mean plus the light
        // subpaths' connections to the lens (per subpath emitted), in chunk order.
        let mut estimate: Vec<[f64; 3]> = pixels
            .iter()
            .map(|(total, merges, non_finite)| {
                stats.photons_deposited += merges;
                stats.non_finite += non_finite;
                total.map(|v| v * per_sample)
            })
            .collect();
        for chunk in &self.chunks {
            for &(pixel, v) in &chunk.splats {
                let e = &mut estimate[pixel as usize];
                for c in 0..3 {
                    e[c] += f64::from(v[c]) * per_path;
                }
            }
        }
        // Rounded to 2⁻⁶⁴ and summed as integers: the same bits whatever passes a render (or a
        // work unit) added before. Every term is finite (non-finite samples were left out).
        for (sum, e) in self.sums.sums.iter_mut().zip(estimate) {
            for c in 0..3 {
                // `as` saturates: a pass estimate beyond 9 · 10¹⁸ is clamped, never wrapped.
                sum[c] = sum[c].saturating_add((e[c] * FIXED_POINT).round() as i128);
            }
        }
        self.sums.passes += 1;
        stats.timings.gather = gather_clock.elapsed().as_secs_f64();
        self.passes += 1;
        stats
    }

    /// The mean of the pass estimates per pixel.
    fn image(&self) -> Vec<[f32; 3]> {
        self.sums.image()
    }

    fn memory(&self) -> Option<MemoryUse> {
        use std::mem::size_of;
        let chunks: usize = self
            .chunks
            .iter()
            .map(|c| {
                c.vertices.capacity() * size_of::<LightVertex>()
                    + c.ends.capacity() * 4
                    + c.splats.capacity() * size_of::<(u32, [f32; 3])>()
            })
            .sum();
        Some(MemoryUse {
            hitpoints: self.sums.sums.len(),
            records: self.sums.sums.capacity() * size_of::<[i128; 3]>(),
            slot_columns: 0,
            // The grid is over the pass's light vertices: a photon buffer, not the slots'.
            grid: 0,
            pass_hitpoint_buffers: 0,
            pass_photon_buffers: chunks
                + self.offsets.capacity() * 4
                + self.grid.as_ref().map_or(0, |g| g.stats().bytes)
                + self.field.as_ref().map_or(0, FrequencyField::heap_bytes),
        })
    }

    /// The exact per-pixel sums and how many passes they hold.
    fn save(&self, w: &mut Writer) {
        w.u64(self.sums.passes);
        w.u64(self.sums.sums.len() as u64);
        for s in &self.sums.sums {
            for v in s {
                w.bytes(&v.to_le_bytes());
            }
        }
    }

    fn saved_bound(&self) -> usize {
        16 + self.sums.sums.len().saturating_mul(48)
    }

    fn restore(&mut self, r: &mut Reader<'_>, passes: u32) -> Result<(), StateError> {
        let summed = r.u64()?;
        if r.len()? != self.sums.sums.len() || summed > u64::from(passes) {
            return Err(StateError::Corrupt);
        }
        for s in &mut self.sums.sums {
            for v in s {
                *v = i128::from_le_bytes(r.array()?);
            }
        }
        self.sums.passes = summed;
        self.passes = passes;
        Ok(())
    }

    fn pass_sums(&self) -> Option<&PassSums> {
        Some(&self.sums)
    }

    /// None: every merge of a pass has the pass's one radius, a function of the pass index.
    fn kernels(&self) -> Option<&[f64]> {
        Some(&[])
    }
}
