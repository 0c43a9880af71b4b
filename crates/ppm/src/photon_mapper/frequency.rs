//! The frequency extension of the photon mappers (Belcour and Soler 2011), whole: the state a
//! hitpoint slot keeps (`SlotFrequency`), the record a frequency photon leaves
//! (`FrequencyPhoton`) and how its photon's tag names it (`TagLayout`), the spectrum steps
//! along a photon path (emitter, travel with the partial-occlusion probe, scatter), the
//! deposits into the slots, the clear-disc probes and the hold decision of the update.
//!
//! The other phases call into this file at five places: `trace` (start, travel, scatter and
//! record a frequency photon), `photon_pass` (tags and deposits), `update` (probes and the
//! frequency radius of each slot), and the AOVs.

use glam::Vec3;
use photon::{Gathered, HitPoints};
use rayon::prelude::*;
use scene::{Bsdf, EmitterShape, Hit, Lobe as MaterialLobe, Ray, Rgb};
use spectrum::{Caps, FrequencyEstimate, Lobe, Spectrum};

use super::photon_pass::NOT_IN_GRID;
use super::trace::TracedPhotons;
use super::{PHOTON_CHUNK, PhotonMapper, SLOT_CHUNK, Setup};
use crate::rng::Sampler;
use crate::update::FrequencyRadius;

/// Share of an occlusion probe, at its far end, where blockers are ignored.
const CONTACT_FRACTION: f32 = 0.05;
/// Extra probes that locate a shadow edge found by the occlusion probe.
const OCCLUSION_BISECTIONS: u32 = 4;

/// Frequency state of one hitpoint slot: the merged estimate plus what a deposit needs to
/// turn a photon's spectrum into the field seen by the camera.
///
/// 32 bytes: the merged spectrum's (a, b, c) and its flags are packed beside the distance (a
/// `FrequencyEstimate`, 32 bytes with its padding, next to an `f32` would take 40). The
/// estimate is stored bit for bit ([`Spectrum::to_bits`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct SlotFrequency {
    /// Bits of a, b, c of the merged spectrum; zero while `merged` is [`Self::EMPTY`].
    coefficients: [u64; 3],
    /// Distance to the camera (or last specular vertex) projected on the normal, z of §8.2.
    normal_distance: f32,
    /// [`Self::EMPTY`] until a frequency photon was merged, then 1 + the Lambertian flag.
    merged: u8,
    /// The clear radius of the gather disc at this visible point as a level of
    /// [`crate::disc::clear_level`] (the radius R₀·2^−level, none at `disc::LEVELS`), or
    /// [`GEOMETRY_UNKNOWN`] until it is probed: when the slot first becomes a candidate for
    /// holding, again after every new visible point.
    clear_level: u8,
    /// |cos θo| toward the camera (or the last specular vertex), in units of 1/65535: with
    /// `normal_distance` it gives the camera distance of the camera-line radius.
    mu_o: u16,
}

/// A cosine in [0, 1] in units of 1/65535.
fn quantize_cosine(mu: f32) -> u16 {
    (mu.abs().min(1.0) * f32::from(u16::MAX)).round() as u16
}

/// [`SlotFrequency::clear_level`] before the probes ran.
const GEOMETRY_UNKNOWN: u8 = u8::MAX;

impl SlotFrequency {
    /// No frequency photon merged yet.
    const EMPTY: u8 = 0;

    /// The state of a new visible point at `normal_distance`, seen at cosine `mu_o`: nothing
    /// merged, not probed.
    pub(crate) fn new(normal_distance: f32, mu_o: f32) -> Self {
        Self::restored(
            FrequencyEstimate::EMPTY,
            normal_distance,
            GEOMETRY_UNKNOWN,
            mu_o,
        )
    }

    /// The state holding `estimate` at `normal_distance`, with the disc probed to
    /// `clear_level` (as [`Self::clear_level`] returned it).
    pub(crate) fn restored(
        estimate: FrequencyEstimate,
        normal_distance: f32,
        clear_level: u8,
        mu_o: f32,
    ) -> Self {
        let mut freq = Self {
            coefficients: [0; 3],
            normal_distance,
            merged: Self::EMPTY,
            clear_level,
            mu_o: quantize_cosine(mu_o),
        };
        freq.set_estimate(estimate);
        freq
    }

    /// Keeps the merged estimate for a new visible point at `normal_distance`, whose disc is
    /// not probed yet.
    pub(super) fn move_to(&mut self, normal_distance: f32, mu_o: f32) {
        self.normal_distance = normal_distance;
        self.mu_o = quantize_cosine(mu_o);
        self.clear_level = GEOMETRY_UNKNOWN;
    }

    /// Distance to the camera (or last specular vertex) projected on the normal.
    pub(crate) fn normal_distance(&self) -> f32 {
        self.normal_distance
    }

    /// The probed clear level of the gather disc, or `u8::MAX` before the probe.
    pub(crate) fn clear_level(&self) -> u8 {
        self.clear_level
    }

    /// The merged estimate.
    pub(crate) fn estimate(&self) -> FrequencyEstimate {
        if self.merged == Self::EMPTY {
            return FrequencyEstimate::EMPTY;
        }
        let [a, b, c] = self.coefficients;
        let spectrum = Spectrum::from_bits([a, b, c, u64::from(self.merged - 1)])
            .expect("the bits of a valid spectrum, stored by set_estimate");
        FrequencyEstimate::from_spectrum(Some(spectrum))
    }

    /// Replaces the merged estimate.
    fn set_estimate(&mut self, estimate: FrequencyEstimate) {
        match estimate.spectrum() {
            None => {
                self.coefficients = [0; 3];
                self.merged = Self::EMPTY;
            }
            Some(spectrum) => {
                let [a, b, c, lambertian] = spectrum.to_bits();
                self.coefficients = [a, b, c];
                // `to_bits` encodes the flag as 0 or 1.
                self.merged = 1 + u8::from(lambertian != 0);
            }
        }
    }

    /// The frequency radius r_freq of the merged deposits with kernel constant `k` (`None`
    /// before the first): min(r_x, r_θ) of the poster, where each deposit's a already holds
    /// the camera-line radius ([`Self::seen_from_camera`]).
    pub(super) fn frequency_radius(&self, k: f64) -> Option<f64> {
        self.estimate().radius(f64::from(self.normal_distance), k)
    }

    /// A deposit's field as this slot reads it: for a glossy field, the camera-line radius
    /// r_cam of design §8.2 folded into a ([`Spectrum::seen_along_camera_line`]), which sees
    /// how a highlight narrows along the rays that reach the camera.
    pub(super) fn seen_from_camera(&self, field: Spectrum, caps: &Caps) -> Spectrum {
        if field.is_lambertian() {
            return field;
        }
        let mu_o = f64::from(self.mu_o.max(1)) / f64::from(u16::MAX);
        let camera_distance = f64::from(self.normal_distance) / mu_o;
        field.seen_along_camera_line(camera_distance, mu_o, caps)
    }

    /// The clear radius of the slot's gather disc, once probed (levels of `r_top`).
    pub(super) fn clear_radius(&self, r_top: f64) -> Option<f64> {
        (self.clear_level != GEOMETRY_UNKNOWN)
            .then(|| crate::disc::level_radius(self.clear_level, r_top))
    }

    /// The radius below which the slot holds its kernel: the frequency radius r_freq of its
    /// merged deposits (`None` before the first), bounded by the clear radius of its disc
    /// (levels of `r_top`, the largest kernel, [`Setup::kernel_max`]) once probed.
    pub(super) fn hold_radius(&self, k: f64, r_top: f64) -> Option<f64> {
        let r_freq = self.frequency_radius(k)?;
        Some(if self.clear_level == GEOMETRY_UNKNOWN {
            r_freq
        } else {
            r_freq.min(crate::disc::level_radius(self.clear_level, r_top))
        })
    }
}

/// The hold decision of the update: the frequency radius a slot's update sees (none for the
/// classical methods), and whether the slot holds its radius R this pass.
pub(super) fn hold(
    freq: &SlotFrequency,
    radius: f64,
    uses_frequency: bool,
    k: f64,
    r_top: f64,
) -> (FrequencyRadius, bool) {
    let r_freq = if uses_frequency {
        freq.hold_radius(k, r_top)
            .map_or(FrequencyRadius::None, FrequencyRadius::Predicted)
    } else {
        FrequencyRadius::None
    };
    let held = matches!(r_freq, FrequencyRadius::Predicted(r) if radius <= r);
    (r_freq, held)
}

/// What a frequency photon brings to the hitpoints its flux counts for (its [`photon::Photon`],
/// whose `tag` names this record, is stored with the others): its spectrum on arrival, the
/// curvature at its hit, and that spectrum already reflected by the lobe of the surface it
/// landed on (`field`, for `field_lobe`). 80 bytes.
///
/// A hitpoint that accepts the photon nearly always lies on the same surface, so the reflection
/// a deposit needs (design §8.1) is computed once per photon instead of once per photon and
/// hitpoint; a hitpoint of another lobe recomputes it from `spectrum` and `curvature`, with the
/// same result either way.
#[derive(Clone, Copy)]
pub(super) struct FrequencyPhoton {
    field: Spectrum,
    field_lobe: MaterialLobe,
    curvature: f32,
    /// |cos θi| of the photon's arrival, for the tangential axis of the deposit.
    mu_i: f32,
    /// Index of its photon in the chunk's `photons`.
    photon: u32,
    spectrum: Spectrum,
}

impl FrequencyPhoton {
    fn new(
        photon: u32,
        curvature: f32,
        mu_i: f32,
        lobe: MaterialLobe,
        spectrum: Spectrum,
        caps: &Caps,
    ) -> Self {
        Self {
            field: deposit_field(spectrum, curvature, mu_i, lobe, caps),
            field_lobe: lobe,
            curvature,
            mu_i,
            photon,
            spectrum,
        }
    }

    /// The field a hitpoint of lobe `lobe` reads from this photon.
    fn field(&self, lobe: MaterialLobe, caps: &Caps) -> Spectrum {
        if lobe == self.field_lobe {
            self.field
        } else {
            deposit_field(self.spectrum, self.curvature, self.mu_i, lobe, caps)
        }
    }
}

/// The field a hitpoint's radius reads (design §8.1): the photon's spectrum reflected by the
/// hitpoint's lobe, with μo = 1 so that a stays in surface units (b does not depend on μo),
/// under the conservative 3D collapse of §8.5 (on the surface, the smaller a and b of the
/// tangential and sagittal reflections at the arrival cosine μi).
fn deposit_field(
    spectrum: Spectrum,
    curvature: f32,
    mu_i: f32,
    lobe: MaterialLobe,
    caps: &Caps,
) -> Spectrum {
    spectrum.reflect_isotropic(
        f64::from(mu_i),
        1.0,
        f64::from(curvature),
        spectrum_lobe(lobe),
        caps,
    )
}

/// A frequency photon's field on its way: the spectra of the two tangent axes (design §8.5),
/// which no single Gaussian bounds after travel. Both are carried along a segment; at a hit
/// the sharper stands for the photon ([`Spectrum::sharper`]).
pub(super) type Axes = [Spectrum; 2];

/// The field a photon carrying `axes` has where it lands.
pub(super) fn arrived(axes: Axes) -> Spectrum {
    axes[0].sharper(axes[1])
}

/// [`photon::Photon::tag`] of a photon without a frequency record.
pub(super) const UNTAGGED: u32 = u32::MAX;

/// How a frequency photon's [`photon::Photon::tag`] names its record.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum TagLayout {
    /// `chunk << local_bits | index in the chunk's records`, set while tracing: the records
    /// stay where the chunks stored them.
    Packed { local_bits: u32 },
    /// The index in the concatenation of the chunks' records ([`tag_frequency_photons`]), for
    /// passes with too many chunks or too deep paths to pack both indices in 31 bits (more than
    /// 2²⁰ chunks, i.e. 2·10⁹ photons per pass, at the default depth).
    Global,
}

impl TagLayout {
    pub(super) fn new(n_chunks: usize, max_depth: u32) -> Self {
        // Bits for indices below n.
        let bits = |n: u64| u64::BITS - n.saturating_sub(1).leading_zeros();
        let local_bits = bits(PHOTON_CHUNK * u64::from(max_depth));
        let chunk_bits = bits(n_chunks as u64);
        // At most 31 bits in all: no packed tag is UNTAGGED.
        if local_bits + chunk_bits <= 31 {
            Self::Packed { local_bits }
        } else {
            Self::Global
        }
    }

    /// What a chunk's tags start from: its index in the high bits, or 0 (the chunk's own
    /// record indices, which `tag_frequency_photons` makes global after tracing).
    pub(super) fn chunk_base(self, chunk: usize) -> u32 {
        match self {
            Self::Packed { local_bits } => (chunk as u32) << local_bits,
            Self::Global => 0,
        }
    }
}

/// For [`TagLayout::Global`]: gathers the frequency records of all chunks into `records`, in
/// chunk order, and tags each record's photon with the record's index there, in parallel over
/// the chunks. (With [`TagLayout::Packed`], the default, nothing to do.)
///
/// A pass would need 2³² frequency records (256 GiB of them) before an index reached
/// [`UNTAGGED`]; photons past that are left untagged (their flux counts, their spectrum not).
fn tag_frequency_photons(traced: &mut [TracedPhotons], records: &mut Vec<FrequencyPhoton>) {
    // The copy is serial: a plain memcpy, small next to the tag writes.
    records.clear();
    let mut offsets = Vec::with_capacity(traced.len());
    for chunk in traced.iter() {
        offsets.push(records.len());
        records.extend_from_slice(&chunk.frequency);
    }
    traced
        .par_iter_mut()
        .zip(offsets)
        .for_each(|(chunk, offset)| {
            for (k, record) in chunk.frequency.iter().enumerate() {
                chunk.photons[record.photon as usize].tag =
                    u32::try_from(offset + k).unwrap_or(UNTAGGED);
            }
        });
}

/// The frequency phase's buffers, kept from one pass to the next (none of it carries state
/// between passes).
#[derive(Default)]
pub(super) struct FrequencyDeposits {
    /// With [`TagLayout::Global`], the frequency records of all chunks, in chunk order:
    /// [`photon::Photon::tag`] indexes them.
    records: Vec<FrequencyPhoton>,
    /// Per grid entry: the merged frequency deposits of the pass.
    per_entry: Vec<FrequencyEstimate>,
    /// Tests: tag as [`TagLayout::Global`] whatever the pass size.
    #[cfg(test)]
    pub(super) force_global_tags: bool,
}

impl FrequencyDeposits {
    /// The tag layout of a pass of `n_chunks` chunks.
    pub(super) fn layout(&self, n_chunks: usize, max_depth: u32) -> TagLayout {
        let layout = TagLayout::new(n_chunks, max_depth);
        #[cfg(test)]
        let layout = if self.force_global_tags {
            TagLayout::Global
        } else {
            layout
        };
        layout
    }

    /// After tracing: makes the tags name the records ([`TagLayout::Global`] only).
    pub(super) fn tag(&mut self, layout: TagLayout, traced: &mut [TracedPhotons]) {
        if layout == TagLayout::Global {
            tag_frequency_photons(traced, &mut self.records);
        }
    }

    /// Heap bytes of the buffers sized by the photons, and of those sized by the hitpoints.
    pub(super) fn heap_bytes(&self) -> (usize, usize) {
        use std::mem::size_of;
        (
            self.records.capacity() * size_of::<FrequencyPhoton>(),
            self.per_entry.capacity() * size_of::<FrequencyEstimate>(),
        )
    }

    /// The frequency deposits of a pass. A frequency photon counts for exactly the hitpoints
    /// its flux counts for, so they ride the flux gather: its pairs carry the photon's tag, and
    /// each grid entry merges the fields of its tagged pairs, in photon order (the merges, a
    /// min or max per coefficient, do not depend on the order anyway). Then each slot merges
    /// its entry's estimate.
    pub(super) fn deposit(
        &mut self,
        setup: &Setup<'_>,
        traced: &[TracedPhotons],
        tagged_gather: &Gathered<'_, (Rgb, u32)>,
        grid_slots: &[u32],
        slot_entry: &[u32],
        slots: &mut HitPoints<SlotFrequency>,
    ) {
        let policy = setup.params.freq_merge;
        let layout = self.layout(traced.len(), setup.params.max_depth);
        let concatenated = &self.records;
        let record = |tag: u32| match layout {
            TagLayout::Packed { local_bits } => {
                &traced[(tag >> local_bits) as usize].frequency
                    [(tag & ((1 << local_bits) - 1)) as usize]
            }
            TagLayout::Global => &concatenated[tag as usize],
        };
        let material_idx = slots.material_idx();
        let slot_freq = slots.freq();
        tagged_gather.accumulate_again(
            &mut self.per_entry,
            |acc: &mut FrequencyEstimate, entry, (_, tag)| {
                if tag == UNTAGGED {
                    return;
                }
                let slot = grid_slots[entry as usize] as usize;
                if let Some(material) = setup.scene.material(material_idx[slot]) {
                    let field = record(tag).field(material.kind.lobe(), &setup.caps);
                    acc.deposit(slot_freq[slot].seen_from_camera(field, &setup.caps), policy);
                }
            },
        );
        let per_entry = &self.per_entry;
        slots
            .columns_mut()
            .freq
            .par_iter_mut()
            .with_min_len(SLOT_CHUNK)
            .enumerate()
            .for_each(|(slot, freq)| {
                let entry = slot_entry[slot];
                if entry == NOT_IN_GRID {
                    return;
                }
                if let Some(spectrum) = per_entry[entry as usize].spectrum() {
                    let mut merged = freq.estimate();
                    merged.deposit(spectrum, policy);
                    freq.set_estimate(merged);
                }
            });
    }
}

impl Setup<'_> {
    /// Whether photon path `index` is a frequency photon: evenly spaced in the global photon
    /// index, exactly the requested share (up to rounding), with no random draw.
    #[inline]
    pub(super) fn is_frequency_photon(&self, index: u64) -> bool {
        if !self.params.method.uses_frequency() || self.params.freq_fraction <= 0.0 {
            return false;
        }
        let f = self.params.freq_fraction;
        ((index + 1) as f64 * f).floor() > (index as f64 * f).floor()
    }

    /// The spectrum a photon path `index` starts with from `emitter`, if it is a frequency
    /// photon.
    #[inline]
    pub(super) fn start_spectrum(&self, index: u64, emitter: EmitterShape) -> Option<Axes> {
        self.is_frequency_photon(index).then(|| {
            let s = emitter_spectrum(emitter, &self.caps);
            [s, s]
        })
    }

    /// The largest gather radius a slot can have: the initial radius, times `freq_grow` for a
    /// frequency method that grows kernels.
    pub(super) fn kernel_max(&self) -> f64 {
        match self.params.growth_pass() {
            Some(_) => self.kernel_scale * self.params.freq_grow,
            None => self.kernel_scale,
        }
    }

    /// Stores the frequency record of a photon with `spectrum` landing at `hit` on a surface
    /// of lobe `lobe` (the photon is the next one `out` stores), and returns the photon's tag:
    /// [`UNTAGGED`] for a classical photon.
    #[inline]
    pub(super) fn record_frequency_photon(
        &self,
        spectrum: Option<Spectrum>,
        hit: &Hit,
        arrived_from: Vec3,
        lobe: MaterialLobe,
        tag_base: u32,
        out: &mut TracedPhotons,
    ) -> u32 {
        match spectrum {
            // A chunk stores at most PHOTON_CHUNK × max_depth ≤ 2²¹ records, so the index
            // fits (see `TagLayout`).
            Some(s) => {
                let tag = tag_base | out.frequency.len() as u32;
                out.frequency.push(FrequencyPhoton::new(
                    out.photons.len() as u32,
                    hit.curvature,
                    arrived_from.dot(hit.shading_normal).abs(),
                    lobe,
                    s,
                    &self.caps,
                ));
                tag
            }
            None => UNTAGGED,
        }
    }

    /// A frequency photon's spectrum after the segment `ray` → `hit`: travel (design §4.1),
    /// plus partial occlusion (§4.7) when the occlusion probe finds a shadow edge nearby.
    ///
    /// The occlusion estimate \[UNV\] (the poster does not say how it detected partial
    /// occlusion): a probe ray from the segment's origin to a point beside the hit, offset
    /// perpendicular to the segment by w = 2·R₀ (R₀ the initial gather radius, the largest
    /// kernel a hitpoint can have, so w covers every hitpoint the photon can reach). If the
    /// probe is blocked while the photon went through, a shadow edge passes within w of the hit;
    /// [`OCCLUSION_BISECTIONS`] more probes bisect the offset to the distance δ of the edge.
    /// The visibility window at the blocker (distance t_b along the segment of length d) is
    /// modelled as a Gaussian of width w_b = δ·t_b/d, the gap between the photon and the edge
    /// there, i.e. spectral variance o = 1/(4π²·w_b²), applied as T(d − t_b)·O(o)·T(t_b).
    /// Cost: one shadow ray per segment of a frequency photon, a few more near shadow edges.
    pub(super) fn travel_spectrum(
        &self,
        axes: Axes,
        ray: &Ray,
        hit: &Hit,
        sampler: &mut Sampler,
    ) -> Axes {
        let distance = f64::from(hit.t);
        let caps = &self.caps;
        match self.occlusion(ray, hit, sampler) {
            None => axes.map(|s| s.travel(distance, caps)),
            Some((t_b, o)) => axes.map(|s| {
                s.travel(t_b, caps)
                    .occlude(o, caps)
                    .travel(distance - t_b, caps)
            }),
        }
    }

    /// The partial occlusion of the segment `ray` → `hit` (see [`Self::travel_spectrum`]): the
    /// blocker's distance along the segment and the window's spectral variance o, or `None`.
    fn occlusion(&self, ray: &Ray, hit: &Hit, sampler: &mut Sampler) -> Option<(f64, f64)> {
        let distance = f64::from(hit.t);
        if !self.params.freq_occlusion {
            return None;
        }
        let u = sampler.next_2d();
        // Offsets in the receiver's tangent plane, so that the probe's target lies on the
        // receiving surface and the surface itself cannot block it; blockers in the last
        // [`CONTACT_FRACTION`] of the probe (contact shadows, a curving receiver) are ignored.
        let frame = scene::Frame::from_normal(hit.geometric_normal);
        let phi = std::f32::consts::TAU * u.x;
        let side = frame.to_world(Vec3::new(phi.cos(), phi.sin(), 0.0));
        let probe = |offset: f32| -> Ray {
            let to_target = hit.position + side * offset - ray.origin;
            let length = to_target.length();
            Ray::new(ray.origin, to_target, length * (1.0 - CONTACT_FRACTION))
        };
        let w = (2.0 * self.kernel_max()) as f32;
        if !self.scene.occluded(&probe(w)) {
            return None;
        }
        // Bisect the offset of the shadow edge: unblocked at `lo`, blocked at `hi`. The probes
        // only ask whether they are blocked (`Scene::occluded`, any hit, no `Hit` built); the
        // blocker's distance is that of the last blocked probe, the one at the final `hi`, so a
        // single closest-hit query there gives the same t as keeping the t of every blocked
        // probe would, without building a `Hit` per blocked probe.
        let (mut lo, mut hi) = (0.0f32, w);
        for _ in 0..OCCLUSION_BISECTIONS {
            let mid = 0.5 * (lo + hi);
            if self.scene.occluded(&probe(mid)) {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        // `occluded` and `intersect` agree on whether a ray is blocked (tested in the scene crate);
        // `None` cannot happen, and would mean no occlusion.
        let t_blocker = self.scene.intersect(&probe(hi)).map(|hit| hit.t)?;
        let t_b = f64::from(t_blocker).clamp(0.0, distance);
        // The offset lies in the receiver's tangent plane; the gap that matters is across the
        // photon's ray, shorter at grazing incidence by the sine between `side` and the ray.
        let across = (side - ray.direction * side.dot(ray.direction)).length();
        let delta = f64::from(lo.max(w / 64.0) * across);
        let gap = (delta * t_b / distance).max(1e-9);
        let o = 1.0 / (4.0 * std::f64::consts::PI.powi(2) * gap * gap);
        Some((t_b, o))
    }
}

/// The lobe of a material as the frequency operators see it (design §7).
fn spectrum_lobe(lobe: MaterialLobe) -> Lobe {
    match lobe {
        MaterialLobe::Specular => Lobe::Mirror,
        MaterialLobe::Lambert => Lobe::Lambert,
        MaterialLobe::Ggx { alpha } => Lobe::Ggx {
            roughness: f64::from(alpha),
        },
    }
}

/// The spectrum of the light field leaving an emitter (design §6).
fn emitter_spectrum(shape: EmitterShape, caps: &Caps) -> Spectrum {
    match shape {
        EmitterShape::Area { size, cos_theta } => {
            Spectrum::area_light(f64::from(size), f64::from(cos_theta), caps)
        }
        EmitterShape::Point => Spectrum::point_light(caps),
        // The falloff's own variance: narrower than the hard cone's, the conservative side.
        EmitterShape::Spot {
            cone_angle,
            falloff_start,
        } => Spectrum::spot_light_smoothstep(f64::from(falloff_start), f64::from(cone_angle), caps),
        EmitterShape::Directional => Spectrum::directional_light(caps),
        // A directional light as wide as the texel it comes from.
        EmitterShape::Environment { angle } => Spectrum::sun(f64::from(angle), caps),
    }
}

/// The photon's field after scattering at `hit` into `sample.incoming` (the new travel
/// direction): the two tangent axes of design §8.5 from the field it arrived with.
pub(super) fn scatter_spectrum(
    spectrum: Spectrum,
    hit: &Hit,
    arrived_from: Vec3,
    sample: &scene::BsdfSample,
    bsdf: &Bsdf,
    material: &scene::Material,
    caps: &Caps,
) -> Axes {
    let normal = hit.shading_normal;
    let mu_i = f64::from(arrived_from.dot(normal).abs());
    let mu_o = f64::from(sample.incoming.dot(normal).abs());
    let curvature = f64::from(hit.curvature);
    if sample.is_transmission {
        let ior = material.kind.refractive_index().map_or(1.0, f64::from);
        let (eta_i, eta_t) = if hit.front_face {
            (1.0, ior)
        } else {
            (ior, 1.0)
        };
        return spectrum.refract_axes(eta_i, eta_t, mu_i, mu_o, curvature, caps);
    }
    let lobe = if sample.is_specular {
        Lobe::Mirror
    } else {
        spectrum_lobe(bsdf.lobe())
    };
    spectrum.reflect_axes(mu_i, mu_o, curvature, lobe, caps)
}

/// Whether the disc of radius `r_top` around `slot`'s visible point lies inside the clear disc
/// of radius `clear` around `leader`'s: the same plane (normals within about 0.8°, the offset
/// along the normal within the probes' own lift), and centres at most `clear − r_top` apart.
/// Passes that share one clear disc per 2 × 2 block of pixels ([`BlockDisc`]).
pub(super) const BLOCK_DISC_PASSES: u32 = 16;

/// The clear disc that the slots of a 2 × 2 block of pixels share for [`BLOCK_DISC_PASSES`]
/// passes: probed (out to eight times the largest kernel R_max) around the visible point of
/// the block's first slot that has one in the first pass of the epoch.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct BlockDisc {
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

impl PhotonMapper<'_> {
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
    pub(super) fn probe_clear_radii(&mut self, all: bool, share: bool) {
        let k = self.setup.params.kernel_k;
        let r_top = self.setup.kernel_max();
        let mut discs = std::mem::take(&mut self.block_discs);
        let slots = &self.slots;
        let scene = self.setup.scene;
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
            let spp = setup.params.samples_per_pixel as usize;
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
                        let level = crate::disc::clear_level(scene, centre, normal, wide as f32);
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
    /// the radius min(r_freq, clear radius, [`Setup::kernel_max`]) if that is larger than its
    /// own, and every slot's statistics restart (N = 0, τ = 0; the image then counts the
    /// photons emitted from this pass on). Growing a radius after flux was gathered is not a
    /// rescale (the flux outside the old disc was never counted), hence the restart.
    ///
    /// [`RenderParams::growth_pass`]: crate::RenderParams::growth_pass
    pub(super) fn grow_kernels(&mut self) {
        // The pilot sizes kernels from each slot's own ladder.
        self.probe_clear_radii(true, false);
        let k = self.setup.params.kernel_k;
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

#[cfg(test)]
mod radius_tests {
    use super::*;

    #[test]
    fn glossy_deposits_carry_the_camera_line_radius() {
        // A point light 1 m from a sharp glossy surface, seen from 3 m (design §8.2's example
        // of what the slices miss): the slices a and b are both wide, yet the highlight is
        // narrow along the camera's rays. The slot must predict the camera-line radius, far
        // below the poster's min(r_x, r_θ) of the same field.
        let caps = Caps::for_scene_size(10.0);
        let field = Spectrum::point_light(&caps).travel(1.0, &caps).reflect(
            1.0,
            1.0,
            0.0,
            Lobe::Ggx { roughness: 0.1 },
            &caps,
        );
        let (z, mu_o, k) = (3.0f32, 1.0f32, spectrum::K_STRICT);
        let slot = SlotFrequency::new(z, mu_o);
        let mut estimate = FrequencyEstimate::EMPTY;
        estimate.deposit(
            slot.seen_from_camera(field, &caps),
            spectrum::MergePolicy::MinRadius,
        );
        let slot = SlotFrequency::restored(estimate, z, GEOMETRY_UNKNOWN, mu_o);
        let poster = field.radius(f64::from(z), k);
        let r_cam = field.camera_line_radius(f64::from(z), 1.0, k);
        let got = slot.frequency_radius(k).unwrap();
        assert!(r_cam < 0.5 * poster, "{r_cam} vs {poster}");
        // (A point light's field is perfectly correlated, a_cam = 0: the caps' finest detail
        // a_min bounds it.)
        let expected = r_cam.max(spectrum::spatial_radius(caps.a_min(), k));
        assert!(
            (got - expected).abs() <= 1e-9 * expected,
            "{got} vs {expected}"
        );
        // A Lambertian field is read as it is.
        let lambert = field.bandlimit(Lobe::Lambert, &caps);
        assert!(lambert.is_lambertian());
        assert_eq!(slot.seen_from_camera(lambert, &caps), lambert);
    }
}
