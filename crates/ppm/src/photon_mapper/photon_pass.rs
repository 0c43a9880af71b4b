//! Phase 3 of a pass: the photon pass. Photons are traced in parallel in fixed chunks, sorted
//! in Morton order and gathered into the hitpoints with `photon::gather_with`, which sums every
//! hitpoint's contributions in photon order whatever the thread count.

use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

use photon::{AcceptParams, GatherScratch, MortonScratch, Photon};
use rayon::prelude::*;
use scene::{Bsdf, Rgb};

use super::frequency::FrequencyPhoton;
use super::index::NOT_IN_GRID;
use super::trace::{LightTracing, TracedPhotons};
use super::{PHOTON_CHUNK, PassStats, PhotonMapper, seen_directly};
use crate::rng::CONNECT_ONLY_STREAM;

/// The photon pass's buffers and what it leaves for the update: M and Φ per grid entry.
///
/// The buffers are kept from one pass to the next: a pass of a million photons fills about a
/// hundred megabytes of them, which freshly allocated would cost page faults and serial copies.
/// None of it carries state between passes.
#[derive(Default)]
pub(crate) struct PhotonPass {
    /// Per chunk of [`PHOTON_CHUNK`] photon paths, what they stored.
    pub(super) traced: Vec<TracedPhotons>,
    /// Per chunk of [`PHOTON_CHUNK`] connection-only light paths (`extra_light_paths`), what
    /// they connected.
    connect_only: Vec<TracedPhotons>,
    /// Morton keys of the stored photons.
    keys: MortonScratch,
    /// The stored photons in Morton order.
    sorted: Vec<Photon>,
    gather: GatherScratch<Rgb>,
    /// The flux gather of the frequency-guided methods: each pair with its photon's tag.
    tagged_gather: GatherScratch<(Rgb, u32)>,
    /// Per grid entry: M and Φ of the pass.
    per_entry: Vec<(u32, [f64; 3])>,
    /// Per slot: its grid entry, or [`NOT_IN_GRID`].
    slot_entry: Vec<u32>,
    /// Per slot: the light-traced radiance of the pass times the photons emitted
    /// (`light_tracing` only; empty otherwise).
    light: Vec<[f64; 3]>,
    /// Per slot: the MIS weight of a merge at its visible point against the photon's
    /// connection to the camera (`light_tracing` only; empty otherwise).
    merge_weight: Vec<f32>,
}

impl PhotonPass {
    /// M and Φ of `slot` in the last pass.
    pub(crate) fn deposit_of(&self, slot: usize) -> (u32, [f64; 3]) {
        match self.slot_entry[slot] {
            NOT_IN_GRID => (0, [0.0; 3]),
            entry => self.per_entry[entry as usize],
        }
    }

    /// The light-traced radiance of `slot` in the last pass, times the photons emitted.
    pub(crate) fn light_of(&self, slot: usize) -> [f64; 3] {
        self.light.get(slot).copied().unwrap_or([0.0; 3])
    }

    /// Heap bytes of the buffers sized by the photons, and of those sized by the hitpoints.
    pub(super) fn heap_bytes(&self) -> (usize, usize) {
        use std::mem::size_of;
        let traced: usize = self
            .traced
            .iter()
            .chain(&self.connect_only)
            .map(|t| {
                t.photons.capacity() * size_of::<Photon>()
                    + t.frequency.capacity() * size_of::<FrequencyPhoton>()
                    + t.splats.capacity() * size_of::<(u32, [f32; 3])>()
                    + t.volume.capacity() * size_of::<super::volume::VolumePhoton>()
            })
            .sum::<usize>()
            + (self.traced.capacity() + self.connect_only.capacity()) * size_of::<TracedPhotons>();
        (
            traced
                + self.sorted.capacity() * size_of::<Photon>()
                + self.keys.heap_bytes()
                + self.gather.heap_bytes()
                + self.tagged_gather.heap_bytes(),
            self.per_entry.capacity() * size_of::<(u32, [f64; 3])>()
                + self.slot_entry.capacity() * size_of::<u32>()
                + self.light.capacity() * size_of::<[f64; 3]>()
                + self.merge_weight.capacity() * size_of::<f32>(),
        )
    }
}

impl PhotonMapper {
    /// Traces this pass's photons (in parallel, fixed chunks), then gathers them into the
    /// hitpoints in Morton order, and the frequency photons' deposits with them; reports the
    /// photon counts and the tracing and frequency times in `stats`.
    pub(super) fn photon_pass(&mut self, stats: &mut PassStats) {
        let setup = &self.setup;
        let n = u64::from(setup.params.budget.photons_per_pass);
        let first_index = self.n_emitted;
        let pass = self.pass;
        let clock = Instant::now();
        let buffers = &mut self.photons;
        let n_chunks = usize::try_from(n.div_ceil(PHOTON_CHUNK)).unwrap_or(usize::MAX);
        buffers.traced.resize_with(n_chunks, TracedPhotons::default);
        let layout = self
            .frequency
            .layout(n_chunks, setup.params.budget.max_depth);
        let textured_hits = setup.scene.textured_hits();
        let has_media = setup.scene.has_media();
        let connect_only = setup.params.connect_only_paths();
        let light = setup
            .params
            .connections
            .light_tracing
            .then(|| LightTracing {
                radii: self.slots.radius(),
                samples_per_pixel: setup.params.film.samples_per_pixel,
                connect_below: setup.params.connections.connect_below,
                paths_per_photon: 1.0 + connect_only as f64 / n as f64,
            });
        let n_connect_chunks = usize::try_from(connect_only.div_ceil(PHOTON_CHUNK)).unwrap_or(0);
        buffers
            .connect_only
            .resize_with(n_connect_chunks, TracedPhotons::default);
        // The photons' chunks, then the connection-only paths' chunks, in one parallel loop.
        buffers
            .traced
            .par_iter_mut()
            .chain(buffers.connect_only.par_iter_mut())
            .enumerate()
            .for_each(|(chunk, out)| {
                out.clear();
                if chunk < n_chunks {
                    let start = chunk as u64 * PHOTON_CHUNK;
                    let end = (start + PHOTON_CHUNK).min(n);
                    let tag_base = layout.chunk_base(chunk);
                    for idx in start..end {
                        let index = first_index + idx;
                        match (textured_hits, has_media) {
                            (true, true) => setup.trace_photon::<true, true, true>(
                                pass, index, tag_base, light, out,
                            ),
                            (true, false) => setup.trace_photon::<true, true, false>(
                                pass, index, tag_base, light, out,
                            ),
                            (false, true) => setup.trace_photon::<false, true, true>(
                                pass, index, tag_base, light, out,
                            ),
                            (false, false) => setup.trace_photon::<false, true, false>(
                                pass, index, tag_base, light, out,
                            ),
                        }
                    }
                } else {
                    let start = (chunk - n_chunks) as u64 * PHOTON_CHUNK;
                    let end = (start + PHOTON_CHUNK).min(connect_only);
                    for idx in start..end {
                        let index = CONNECT_ONLY_STREAM | idx;
                        match (textured_hits, has_media) {
                            (true, true) => {
                                setup.trace_photon::<true, false, true>(pass, index, 0, light, out);
                            }
                            (true, false) => {
                                setup
                                    .trace_photon::<true, false, false>(pass, index, 0, light, out);
                            }
                            (false, true) => {
                                setup
                                    .trace_photon::<false, false, true>(pass, index, 0, light, out);
                            }
                            (false, false) => setup
                                .trace_photon::<false, false, false>(pass, index, 0, light, out),
                        }
                    }
                }
            });
        self.n_emitted += n;
        if let Some(light) = light {
            // In chunk order, whatever the thread count.
            let n_slots = self.slots.len();
            buffers.light.clear();
            buffers.light.resize(n_slots, [0.0; 3]);
            for chunk in buffers.traced.iter().chain(&buffers.connect_only) {
                stats.light_connections += chunk.connections;
                for &(slot, v) in &chunk.splats {
                    let sum = &mut buffers.light[slot as usize];
                    for c in 0..3 {
                        sum[c] += f64::from(v[c]);
                    }
                }
            }
            // The balance heuristic against the photon's connection to the camera
            // (`trace.rs`): N/(kq + N), N = πR²ρ, ρ the camera samples per unit area at the
            // visible point; 1 where the camera sees it only through specular bounces (a
            // connection cannot reach it).
            let camera = setup.scene.camera();
            let max_depth = setup.params.budget.max_depth;
            let (positions, normals) = (self.slots.position(), self.slots.geometric_normal());
            let (budgets, radii) = (&self.photon_bounces, self.slots.radius());
            let spp = setup.params.film.samples_per_pixel as usize;
            buffers.merge_weight.clear();
            buffers
                .merge_weight
                .par_extend((0..n_slots).into_par_iter().map(|slot| {
                    let budget = budgets[slot];
                    if !seen_directly(budget, max_depth) {
                        return 1.0;
                    }
                    let rho = f64::from(camera.film_density(positions[slot], normals[slot]));
                    let n = std::f64::consts::PI * radii[slot] * radii[slot] * rho;
                    let q = light.connection_rate((slot / spp) as u32, rho);
                    (n / (light.paths_per_photon * q + n)) as f32
                }));
        }
        let frequency_photons = buffers.traced.iter().map(|c| c.frequency_photons).sum();
        stats.non_finite += (buffers.traced.iter().chain(&buffers.connect_only))
            .map(|c| c.non_finite)
            .sum::<u64>();
        let trace_seconds = clock.elapsed().as_secs_f64();
        let uses_frequency = setup.params.method.uses_frequency();
        let frequency_clock = Instant::now();
        if uses_frequency {
            self.frequency.tag(layout, &mut buffers.traced);
        }
        let frequency_seconds = frequency_clock.elapsed().as_secs_f64();
        let n_slots = self.slots.len();
        stats.photons_traced = n;
        stats.frequency_photons = frequency_photons;
        stats.timings.trace = trace_seconds;
        stats.timings.frequency += frequency_seconds;
        // Slot → grid entry (`NOT_IN_GRID` for slots the grid does not index).
        let grid_slots = self.index.grid_slots();
        buffers.per_entry.clear();
        buffers.slot_entry.clear();
        buffers.slot_entry.resize(n_slots, NOT_IN_GRID);
        for (entry, &slot) in grid_slots.iter().enumerate() {
            buffers.slot_entry[slot as usize] = entry as u32;
        }
        let Some(grid) = self.index.grid() else {
            return;
        };
        // Morton order (of the photons' positions, ties in trace order).
        photon::morton_sort(
            &buffers.traced,
            |p: &Photon| p.position,
            &mut buffers.keys,
            &mut buffers.sorted,
        );

        let slots = &self.slots;
        let photon_bounces = &self.photon_bounces;
        let merge_weight = &buffers.merge_weight;
        // Fluxes dropped for being NaN or infinite (a BSDF value at a grazing angle, say):
        // rare, so an atomic counter costs nothing on the common path.
        let non_finite_fluxes = AtomicU64::new(0);
        let flux = |photon: &Photon, entry: u32| {
            let slot = grid_slots[entry as usize] as usize;
            // Whether the photon, which the grid reported for `slot` (so it lies within the
            // slot's radius: the grid's test is exactly that of `photon::accepts`), counts for
            // it: the light path they make has at most `max_depth` bounces, and the photon is
            // on the hitpoint's side, with agreeing normals (see `photon::faces`), or on the
            // other side of a surface that transmits through a lobe of finite density (a rough
            // dielectric), whose hitpoints see light from both sides. A photon from the other
            // side must lie on the hitpoint's surface, within a quarter of the radius of its
            // tangent plane: the far face of a thin slab, whose photons have not crossed it
            // yet, is rejected once the radius is below four times the slab's thickness
            // (a curved surface keeps its own photons while R is below half its radius of
            // curvature).
            let normal = slots.geometric_normal()[slot];
            let crossed = || {
                let off_plane = (photon.position - slots.position()[slot]).dot(normal).abs();
                f64::from(off_plane) <= 0.25 * slots.radius()[slot]
                    && photon::faces(photon, -normal, AcceptParams::COS_60)
                    && setup
                        .scene
                        .material(slots.material_idx()[slot])
                        .is_some_and(|m| m.kind.transmits())
            };
            let accepts = photon.bounces <= u32::from(photon_bounces[slot])
                && (photon::faces(photon, normal, AcceptParams::COS_60) || crossed());
            accepts.then(|| {
                let material = setup.scene.material(slots.material_idx()[slot])?;
                // The shading normal faces the outside of a refracting material (the camera
                // pass turns it so), as `eval_about` takes it.
                let (normal, outgoing) = (slots.shading_normal()[slot], slots.outgoing()[slot]);
                let f = Bsdf::eval_about(material.kind, normal, outgoing, photon.incoming);
                let mut flux = f * photon.power * slots.weight()[slot];
                if let Some(&weight) = merge_weight.get(slot) {
                    flux *= weight;
                }
                if flux.is_finite() {
                    Some(flux)
                } else {
                    non_finite_fluxes.fetch_add(1, Ordering::Relaxed);
                    None
                }
            })?
        };
        let add = |acc: &mut (u32, [f64; 3]), flux: Rgb| {
            acc.0 += 1;
            acc.1[0] += f64::from(flux.x);
            acc.1[1] += f64::from(flux.y);
            acc.1[2] += f64::from(flux.z);
        };
        let tagged = if uses_frequency {
            // The flux pairs carry the photon's tag, for the frequency deposits below.
            Some(photon::gather_with(
                &mut buffers.tagged_gather,
                grid,
                &buffers.sorted,
                &mut buffers.per_entry,
                grid_slots.len(),
                |photon, entry| flux(photon, entry).map(|f| (f, photon.tag)),
                |acc, (f, _)| add(acc, f),
            ))
        } else {
            photon::gather_with(
                &mut buffers.gather,
                grid,
                &buffers.sorted,
                &mut buffers.per_entry,
                grid_slots.len(),
                flux,
                add,
            );
            None
        };
        stats.photons_stored = buffers.sorted.len() as u64;
        stats.non_finite += non_finite_fluxes.load(Ordering::Relaxed);
        for &(m, _) in &buffers.per_entry {
            stats.photons_deposited += u64::from(m);
            stats.hitpoints_hit += u64::from(m > 0);
        }
        let Some(tagged) = tagged else {
            return;
        };
        let frequency_clock = Instant::now();
        self.frequency.deposit(
            setup,
            &buffers.traced,
            &tagged,
            grid_slots,
            &buffers.slot_entry,
            &mut self.slots,
        );
        stats.timings.frequency += frequency_clock.elapsed().as_secs_f64();
    }
}
