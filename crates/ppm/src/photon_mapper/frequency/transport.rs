//! A frequency photon's spectrum along its path (design §6–8): at the emitter, along a
//! segment (travel, with the partial-occlusion probe), at a scattering event, and the record it
//! leaves where it lands ([`FrequencyPhoton`]).

use glam::Vec3;
use scene::{Bsdf, EmitterShape, Hit, Lobe as MaterialLobe, Ray};
use spectrum::{Caps, Lobe, Spectrum};

use super::super::Setup;
use crate::rng::Sampler;

/// Share of an occlusion probe, at its far end, where blockers are ignored.
const CONTACT_FRACTION: f32 = 0.05;
/// Extra probes that locate a shadow edge found by the occlusion probe.
const OCCLUSION_BISECTIONS: u32 = 4;

/// [`photon::Photon::tag`] of a photon without a frequency record.
pub(crate) const UNTAGGED: u32 = u32::MAX;

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
pub(crate) struct FrequencyPhoton {
    field: Spectrum,
    field_lobe: MaterialLobe,
    curvature: f32,
    /// |cos θi| of the photon's arrival, for the tangential axis of the deposit.
    mu_i: f32,
    /// Index of its photon in the chunk's `photons`.
    pub(crate) photon: u32,
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
    pub(crate) fn field(&self, lobe: MaterialLobe, caps: &Caps) -> Spectrum {
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
pub(crate) type Axes = [Spectrum; 2];

/// The field a photon carrying `axes` has where it lands.
pub(crate) fn arrived(axes: Axes) -> Spectrum {
    axes[0].sharper(axes[1])
}

impl Setup {
    /// Whether photon path `index` is a frequency photon: evenly spaced in the global photon
    /// index, exactly the requested share (up to rounding), with no random draw.
    #[inline]
    pub(crate) fn is_frequency_photon(&self, index: u64) -> bool {
        if !self.params.method.uses_frequency() || self.params.frequency.fraction <= 0.0 {
            return false;
        }
        let f = self.params.frequency.fraction;
        ((index + 1) as f64 * f).floor() > (index as f64 * f).floor()
    }

    /// The spectrum a photon path `index` starts with from `emitter`, if it is a frequency
    /// photon.
    #[inline]
    pub(crate) fn start_spectrum(&self, index: u64, emitter: EmitterShape) -> Option<Axes> {
        self.is_frequency_photon(index).then(|| {
            let s = emitter_spectrum(emitter, &self.caps);
            [s, s]
        })
    }

    /// Stores in `records` the frequency record of a photon with `spectrum` landing at `hit`
    /// on a surface of lobe `lobe` (the photon is the chunk's photon number `photon`), and
    /// returns the photon's tag: [`UNTAGGED`] for a classical photon.
    #[inline]
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn record_frequency_photon(
        &self,
        spectrum: Option<Spectrum>,
        hit: &Hit,
        arrived_from: Vec3,
        lobe: MaterialLobe,
        tag_base: u32,
        photon: u32,
        records: &mut Vec<FrequencyPhoton>,
    ) -> u32 {
        match spectrum {
            // A chunk stores at most PHOTON_CHUNK × max_depth ≤ 2²¹ records, so the index
            // fits (see `TagLayout`).
            Some(s) => {
                let tag = tag_base | records.len() as u32;
                records.push(FrequencyPhoton::new(
                    photon,
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
    pub(crate) fn travel_spectrum(
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
        if !self.params.frequency.occlusion {
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
pub(crate) fn scatter_spectrum(
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
        let refracted = spectrum.refract_axes(eta_i, eta_t, mu_i, mu_o, curvature, caps);
        return match bsdf.lobe() {
            // A rough refraction blurs the refracted angle by the microfacets' tilt σh times
            // 1 − s, s = ηi·μi/(ηt·μt) (design §7; σh² = α²/4 for GGX).
            MaterialLobe::Ggx { alpha } if !sample.is_specular => {
                let s = eta_i * mu_i.max(1e-6) / (eta_t * mu_o.max(1e-6));
                let sigma_h2 = f64::from(alpha) * f64::from(alpha) / 4.0;
                let lobe = Lobe::Gaussian {
                    variance: (1.0 - s) * (1.0 - s) * sigma_h2,
                };
                refracted.map(|axis| axis.bandlimit(lobe, caps))
            }
            _ => refracted,
        };
    }
    let lobe = if sample.is_specular {
        Lobe::Mirror
    } else {
        spectrum_lobe(bsdf.lobe())
    };
    spectrum.reflect_axes(mu_i, mu_o, curvature, lobe, caps)
}
