//! The clear-disc probes of the frequency methods: how far each visible point's gather disc
//! stays on its own surface (`crate::disc`), probed per slot or shared by a 2 × 2 block of
//! pixels ([`BlockDisc`]), which bounds held kernels (and with `clear_cap` every kernel); and the
//! growth of kernels after the pilot.

use glam::Vec3;
use rayon::prelude::*;

use super::super::{PhotonMapper, SLOT_CHUNK};
use super::GEOMETRY_UNKNOWN;

/// Passes that share one clear disc per 2 × 2 block of pixels ([`BlockDisc`]).
pub(crate) const BLOCK_DISC_PASSES: u32 = 16;

/// The clear disc that the slots of a 2 × 2 block of pixels share for [`BLOCK_DISC_PASSES`]
/// passes: probed (out to eight times the largest kernel R_max) around the visible point of
/// the block's first slot that has one in the first pass of the epoch.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct BlockDisc {
    /// The first pass of the epoch.
    epoch: u32,
    centre: Vec3,
    normal: Vec3,
    /// The clear radius around `centre`; 0 if none (or no slot had a visible point).
    clear: f64,
}

impl BlockDisc {
    /// Whether the gather disc of radius `r_top` around `position` (unit geometric normal
    /// `normal`) lies inside this one: the same plane, and δ + r_top within the clear radius.
    fn covers(&self, position: Vec3, normal: Vec3, r_top: f64) -> bool {
        let offset = position - self.centre;
        let lift = 1e-3 * r_top as f32 + 1e-5 * self.centre.abs().max_element();
        self.normal.dot(normal) >= 0.9999
            && self.normal.dot(offset).abs() <= lift
            && f64::from(offset.length()) + r_top <= self.clear
    }
}

impl PhotonMapper {
    /// Probes the clear radius ([`crate::disc::clear_level`]) of every valid slot that has
    /// become a candidate for holding (R ≤ r_freq; with `all`, every slot with a frequency
    /// radius) and has not been probed at its visible point, in parallel. Deterministic: the
    /// probes use no random numbers, and which slots share a probe depends only on the pass
    /// and its visible points.
    ///
    /// With `share` (`freq_probe_share`) the slots of each 2 × 2 block of pixels share
    /// one probe for [`BLOCK_DISC_PASSES`] passes ([`BlockDisc`]): around the block's first
    /// visible point of the epoch's first pass, out to eight times the largest kernel R_max,
    /// and a slot of the block whose visible point lies in the same plane, at a distance δ
    /// with δ + R_max within that clear radius, is clear at R_max without probes of its own
    /// (its disc lies inside the probed one). The others probe their own disc as before.
    pub(crate) fn probe_clear_radii(&mut self, all: bool, share: bool) {
        let k = self.setup.params.frequency.kernel_k;
        let r_top = self.setup.kernel_max();
        let mut discs = std::mem::take(&mut self.block_discs);
        let slots = &self.slots;
        let scene = &*self.setup.scene;
        let needs_probe = |slot: usize| {
            let freq = slots.freq()[slot];
            if !self.is_valid(slot) || freq.clear_level != GEOMETRY_UNKNOWN {
                return false;
            }
            // Not probed yet, so this is the unbounded frequency radius.
            all || freq
                .hold_radius(k, r_top)
                .is_some_and(|r_freq| slots.radius()[slot] <= r_freq)
        };
        let probe = |slot: usize, r0: f64| {
            crate::disc::clear_level(
                scene,
                slots.position()[slot],
                slots.geometric_normal()[slot],
                r0 as f32,
                0.5 * r0 as f32,
            )
        };
        let probed: Vec<(usize, u8)> = if !share {
            (0..slots.len())
                .into_par_iter()
                .with_min_len(SLOT_CHUNK)
                .filter(|&slot| needs_probe(slot))
                .map(|slot| (slot, probe(slot, r_top)))
                .collect()
        } else {
            let setup = &self.setup;
            let (width, height) = (setup.width as usize, setup.height as usize);
            let spp = setup.params.film.samples_per_pixel as usize;
            let blocks_x = width.div_ceil(2);
            let block_slots = move |block: usize| {
                let (bx, by) = (2 * (block % blocks_x), 2 * (block / blocks_x));
                (by..(by + 2).min(height))
                    .flat_map(move |y| (bx..(bx + 2).min(width)).map(move |x| y * width + x))
                    .flat_map(move |pixel| pixel * spp..(pixel + 1) * spp)
            };
            let epoch = self.pass / BLOCK_DISC_PASSES * BLOCK_DISC_PASSES;
            let wide = 8.0 * r_top;
            // The block's disc in this epoch: around the first visible point of the epoch's
            // first pass, recomputed from the camera paths (not from the slots, which hold
            // this pass's points), so that it is the same whenever it is computed.
            let block_disc = |block: usize| {
                let visible =
                    block_slots(block).find_map(|slot| setup.visible_surface(slot as u32, epoch));
                let (centre, normal, clear) = match visible {
                    Some((centre, normal)) => {
                        let level = crate::disc::clear_level(
                            scene,
                            centre,
                            normal,
                            wide as f32,
                            0.5 * r_top as f32,
                        );
                        (centre, normal, crate::disc::level_radius(level, wide))
                    }
                    None => (Vec3::ZERO, Vec3::ZERO, 0.0),
                };
                BlockDisc {
                    epoch,
                    centre,
                    normal,
                    clear,
                }
            };
            discs.resize(blocks_x * height.div_ceil(2), None);
            discs
                .par_iter_mut()
                .enumerate()
                .with_min_len(SLOT_CHUNK / 4)
                .flat_map_iter(|(block, disc)| {
                    let mut out = Vec::new();
                    for slot in block_slots(block).filter(|&s| needs_probe(s)) {
                        let shared = match disc {
                            Some(d) if d.epoch == epoch => *d,
                            _ => *disc.insert(block_disc(block)),
                        };
                        let (position, normal) =
                            (slots.position()[slot], slots.geometric_normal()[slot]);
                        let level = if shared.covers(position, normal, r_top) {
                            0
                        } else {
                            probe(slot, r_top)
                        };
                        out.push((slot, level));
                    }
                    out
                })
                .collect()
        };
        self.block_discs = discs;
        let columns = self.slots.columns_mut();
        for (slot, level) in probed {
            columns.freq[slot].clear_level = level;
        }
    }

    /// The end of the pilot (at the start of pass [`RenderParams::growth_pass`], once the
    /// visible points of the pass are traced): every valid slot with a frequency radius takes
    /// the radius min(r_freq, clear radius, [`super::super::Setup::kernel_max`]) if that is larger than its
    /// own, and every slot's statistics restart (N = 0, τ = 0; the image then counts the
    /// photons emitted from this pass on). Growing a radius after flux was gathered is not a
    /// rescale (the flux outside the old disc was never counted), hence the restart.
    ///
    /// [`RenderParams::growth_pass`]: crate::RenderParams::growth_pass
    pub(crate) fn grow_kernels(&mut self) {
        // The pilot sizes kernels from each slot's own ladder.
        self.probe_clear_radii(true, false);
        let k = self.setup.params.frequency.kernel_k;
        let r_top = self.setup.kernel_max();
        let valid: Vec<bool> = (0..self.slots.len()).map(|s| self.is_valid(s)).collect();
        let columns = self.slots.columns_mut();
        columns
            .radius
            .par_iter_mut()
            .zip(columns.photon_count.par_iter_mut())
            .zip(columns.flux.par_iter_mut())
            .zip(columns.freq.par_iter())
            .zip(valid.par_iter())
            .for_each(|((((radius, count), flux), freq), &valid)| {
                if valid && let Some(target) = freq.hold_radius(k, r_top) {
                    *radius = radius.max(target.min(r_top));
                }
                *count = 0.0;
                *flux = [0.0; 3];
            });
    }
}
