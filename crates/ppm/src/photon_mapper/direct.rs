//! Direct lighting at the visible points combined with the photons straight from the emitters
//! (`direct_lighting`).
//!
//! A light path with one segment from an emitter point y to a visible point x, seen by the
//! camera, is sampled by four strategies of a pass:
//!
//! - a light sample at x (next-event estimation, n per visible point and pass),
//! - a BSDF sample at x that hits the emitter (n as well),
//! - a merge: a photon from y landing within the slot's radius R of x (N photons a pass),
//! - a connection: that photon joined to the lens (light tracing, where x is seen directly).
//!
//! Their densities, in solid angle at x per camera sample, with E the emitter's densities
//! (`scene::EmissionPdf`: pick, position, direction; next-event estimation's pick and point),
//! d = |x − y| and θx, θy the angles at either end:
//!
//! | strategy | density |
//! |---|---|
//! | light sample | n · pick_direct · direct · d²/cos θy (no distance for an infinite light) |
//! | BSDF sample | n · pdf_bsdf(ωo, ωi) (zero for a delta light) |
//! | merge | πR² · a, a = N · pick · position · direction · cos θx / cos θy (no cos θy at infinity) |
//! | connection | (kq/ρ) · a, as `trace.rs` weighs connections against merges |
//!
//! Each strategy takes the balance heuristic's weight, its density over their sum (Georgiev et
//! al. 2012's vertex connection and merging restricted to these paths): the weights of a path
//! sum to one, so the estimate stays unbiased apart from the merge's own blur, and where the
//! kernel is small against the light's distance (an emitter far away, a large lamp) the
//! light and BSDF samples take the light, where it is large (an emitter beside the surface it
//! lights) the photons do. The light sample's density is that of a point in area measure turned
//! into solid angle; a delta light's (point, spot) turned the same way with cos θy = 1, so that
//! the merge and the light sample of a point light compare as densities of the same point.

use glam::Vec3;
use scene::{Bsdf, EmissionPdf, Hit, LightSampler, Rgb, Scene, TransportMode};

use super::trace::LightTracing;
use crate::rng::Sampler;

/// What the weights need of the render: N and n of the module's table.
#[derive(Clone, Copy, Debug)]
pub(super) struct DirectMis {
    /// Photon paths a pass that store photons (N).
    photons: f32,
    /// Light and BSDF sample pairs per visible point and pass (n).
    samples: f32,
}

/// What a slot's merges and connections cover in this pass: πR², and kq/ρ of its pixel (zero
/// where the camera sees the slot only through specular bounces, or no photon is connected).
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct SlotKernel {
    pub(super) merge_area: f64,
    pub(super) connect_area: f64,
}

/// The densities of a path from one emitter point that a photon carries to its merges and
/// connections: a and the light sample's (`Photon::densities`, the light sample's sign set for a
/// delta light, which no BSDF sample reaches).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct PhotonDensities {
    /// a: the merge's density per unit kernel area.
    photon: f64,
    /// The light sample's density.
    light: f64,
    /// Whether the emitter is a delta light.
    delta: bool,
}

impl PhotonDensities {
    /// As a photon stores them.
    pub(super) fn encode(self) -> [f32; 2] {
        let light = self.light as f32;
        [
            self.photon as f32,
            if self.delta {
                -light.abs()
            } else {
                light.abs()
            },
        ]
    }

    /// As [`PhotonDensities::encode`] stored them.
    pub(super) fn decode(stored: [f32; 2]) -> Self {
        Self {
            photon: f64::from(stored[0]),
            light: f64::from(stored[1].abs()),
            delta: stored[1].is_sign_negative(),
        }
    }
}

impl DirectMis {
    pub(super) fn new(photons_per_pass: u32, samples: u32) -> Self {
        Self {
            photons: photons_per_pass as f32,
            samples: samples.max(1) as f32,
        }
    }

    /// The densities of the path from the emitter point of `pdf` (with next-event estimation's
    /// pick `pick_direct` from the receiver) to a receiver at distance² `distance2` whose
    /// geometric normal makes cos θx = `cos_x` with the path; `None` where the path leaves the
    /// emitter at a grazing angle, which carries no light.
    pub(super) fn densities(
        &self,
        pdf: &EmissionPdf,
        pick_direct: f32,
        distance2: f32,
        cos_x: f32,
    ) -> Option<PhotonDensities> {
        let (per_cos_y, to_solid_angle) = if pdf.is_infinite {
            (1.0, 1.0)
        } else {
            if pdf.cos_at_light.is_nan() || pdf.cos_at_light <= 0.0 {
                return None;
            }
            let inv = 1.0 / f64::from(pdf.cos_at_light);
            (inv, f64::from(distance2) * inv)
        };
        let photon = f64::from(self.photons)
            * f64::from(pdf.emission_with_pick())
            * f64::from(cos_x.abs())
            * per_cos_y;
        let light = f64::from(self.samples)
            * f64::from(pick_direct)
            * f64::from(pdf.direct)
            * to_solid_angle;
        (photon.is_finite() && light.is_finite()).then_some(PhotonDensities {
            photon,
            light,
            delta: pdf.is_delta,
        })
    }

    /// The BSDF sample's density for a BSDF whose single-sample density is `pdf`.
    fn bsdf_density(&self, densities: &PhotonDensities, pdf: impl FnOnce() -> f32) -> f64 {
        if densities.delta {
            0.0
        } else {
            f64::from(self.samples) * f64::from(pdf())
        }
    }

    /// The weight of a merge at a slot whose kernel is `kernel`, of a photon with `densities`,
    /// where the slot's BSDF draws the photon's direction with density `pdf`.
    pub(super) fn merge_weight(
        &self,
        densities: &PhotonDensities,
        kernel: SlotKernel,
        pdf: impl FnOnce() -> f32,
    ) -> f64 {
        let merge = kernel.merge_area * densities.photon;
        let sum = merge
            + kernel.connect_area * densities.photon
            + densities.light
            + self.bsdf_density(densities, pdf);
        ratio(merge, sum)
    }

    /// The extra term a connection's weight adds to kq + N (`trace.rs`) for a photon with
    /// `densities` at a point with `rho` camera samples per unit area: ρ times the light and BSDF
    /// samples' densities over a, so that the connection's weight kq/(kq + N + this) is its
    /// density over the four strategies'.
    pub(super) fn connection_term(
        &self,
        densities: &PhotonDensities,
        rho: f64,
        pdf: impl FnOnce() -> f32,
    ) -> f64 {
        let others = densities.light + self.bsdf_density(densities, pdf);
        if others == 0.0 {
            return 0.0;
        }
        let term = rho * others / densities.photon;
        if term.is_nan() { f64::INFINITY } else { term }
    }

    /// The weight of a camera-side strategy of density `own` (n times its single-sample
    /// density) at a slot with `kernel`, against the path's `densities`.
    fn camera_weight(
        &self,
        own: f64,
        densities: &PhotonDensities,
        kernel: SlotKernel,
        other: f64,
    ) -> f64 {
        let photons = (kernel.merge_area + kernel.connect_area) * densities.photon;
        ratio(own, own + other + photons)
    }
}

/// a / b, zero where b is zero or either is not finite (a strategy that cannot sample the path
/// takes none of it).
fn ratio(a: f64, b: f64) -> f64 {
    let w = a / b;
    if w.is_finite() {
        w.clamp(0.0, 1.0)
    } else {
        0.0
    }
}

/// The photon densities of the path from the emitter point `origin` (densities `pdf`) to a
/// photon at `hit`, which arrived along −`incoming`.
pub(super) fn photon_densities(
    lights: &LightSampler,
    mis: &DirectMis,
    pdf: &EmissionPdf,
    origin: Vec3,
    hit: &Hit,
    incoming: Vec3,
) -> Option<PhotonDensities> {
    let pick_direct = lights.pick_direct(pdf.emitter as usize, hit.position, hit.geometric_normal);
    let distance2 = (hit.position - origin).length_squared();
    mis.densities(
        pdf,
        pick_direct,
        distance2,
        incoming.dot(hit.geometric_normal),
    )
}

/// The kernels of this pass's slots, for the light and BSDF samples' weights.
pub(super) struct PassKernels<'a> {
    pub(super) mis: DirectMis,
    /// The radius each slot gathers with in this pass.
    pub(super) radii: &'a [f64],
    /// Light tracing's rule, where it is on (its radii are `radii`).
    pub(super) light: Option<LightTracing<'a>>,
}

impl PassKernels<'_> {
    /// The kernel of `slot`, whose visible point at `position` (geometric normal `normal`) the
    /// camera sees directly or not.
    pub(super) fn kernel(
        &self,
        scene: &Scene,
        slot: u32,
        position: Vec3,
        normal: Vec3,
        directly: bool,
    ) -> SlotKernel {
        let r = self.radii.get(slot as usize).copied().unwrap_or(0.0);
        let merge_area = std::f64::consts::PI * r * r;
        let connect_area = match self.light {
            Some(light) if directly => {
                let rho = f64::from(scene.camera().film_density(position, normal));
                let spp = light.samples_per_pixel;
                let rate = light.connection_rate(slot / spp, rho);
                if rate == 0.0 {
                    0.0
                } else if rho > 0.0 {
                    light.paths_per_photon * rate / rho
                } else {
                    f64::INFINITY
                }
            }
            _ => 0.0,
        };
        SlotKernel {
            merge_area,
            connect_area,
        }
    }
}

/// The direct lighting at a visible point `hit` (seen along −`outgoing`): one light sample and
/// one BSDF sample, each weighted against the other and against the photons that the slot's
/// `kernel` merges and connects (this module's table).
pub(super) fn direct_lighting(
    scene: &Scene,
    hit: &Hit,
    bsdf: &Bsdf,
    outgoing: Vec3,
    sampler: &mut Sampler,
    mis: &DirectMis,
    kernel: SlotKernel,
) -> Rgb {
    let u_light = sampler.next_f32();
    let u = sampler.next_2d();
    let u_lobe = sampler.next_f32();
    let u_bsdf = sampler.next_2d();
    let lights = scene.lights();
    let mut radiance = Rgb::ZERO;
    if let Some((sample, pdf)) =
        lights.sample_direct_with_pdf(hit.position, hit.geometric_normal, u_light, u)
        && sample.pdf > 0.0
        && scene.light_visible(hit, &sample)
    {
        let f = bsdf.eval(outgoing, sample.incoming);
        let distance2 = sample.distance * sample.distance;
        let cos_x = sample.incoming.dot(hit.geometric_normal);
        if f != Rgb::ZERO
            && let Some(densities) = mis.densities(&pdf, pdf.pick_direct, distance2, cos_x)
        {
            let other = mis.bsdf_density(&densities, || bsdf.pdf(outgoing, sample.incoming));
            let weight = mis.camera_weight(densities.light, &densities, kernel, other);
            let cos = sample.incoming.dot(hit.shading_normal).abs();
            radiance += f * sample.radiance * (cos / sample.pdf * weight as f32);
        }
    }
    let Some(sample) = bsdf.sample(outgoing, u_lobe, u_bsdf, TransportMode::Radiance) else {
        return radiance;
    };
    if sample.weight == Rgb::ZERO || !sample.weight.is_finite() {
        return radiance;
    }
    let ray = hit.spawn_ray(sample.incoming);
    let next = scene.intersect(&ray);
    let (emitted, pdf, distance2) = match &next {
        Some(next) => (
            scene.emitted(next),
            lights.pdf_emission(next, -sample.incoming, (hit.position, hit.geometric_normal)),
            (next.position - hit.position).length_squared(),
        ),
        None => (
            lights.environment_radiance(ray.direction),
            lights.pdf_emission_environment(ray.direction),
            0.0,
        ),
    };
    if emitted == Rgb::ZERO {
        return radiance;
    }
    let weight = if sample.is_specular {
        // Only this strategy samples a delta lobe: a merge or a light sample evaluates it as 0.
        1.0
    } else {
        let cos_x = sample.incoming.dot(hit.geometric_normal);
        match pdf.and_then(|pdf| mis.densities(&pdf, pdf.pick_direct, distance2, cos_x)) {
            Some(densities) => {
                let own = f64::from(mis.samples) * f64::from(sample.pdf);
                mis.camera_weight(own, &densities, kernel, densities.light)
            }
            None => 0.0,
        }
    };
    radiance + sample.weight * emitted * weight as f32
}

#[cfg(test)]
mod tests {
    use super::*;

    fn area_light(cos_y: f32) -> EmissionPdf {
        EmissionPdf {
            emitter: 0,
            pick: 0.5,
            pick_direct: 0.25,
            position: 2.0,
            direction: cos_y / std::f32::consts::PI,
            direct: 2.0,
            cos_at_light: cos_y,
            is_delta: false,
            is_infinite: false,
        }
    }

    /// The four weights of one path sum to one, whatever the kernel and the densities.
    #[test]
    fn the_four_weights_of_a_path_sum_to_one() {
        let mis = DirectMis::new(100_000, 4);
        for (cos_y, d2, cos_x, r, connect, bsdf_pdf) in [
            (0.9, 0.3, 0.7, 0.01, 0.0, 0.2),
            (0.2, 4.0, 0.1, 0.05, 3e-4, 1.3),
            (1.0, 0.01, 1.0, 0.002, 1e-5, 0.3),
            (0.5, 100.0, 0.5, 0.2, 0.0, 0.0),
        ] {
            let pdf = area_light(cos_y);
            let d = mis.densities(&pdf, pdf.pick_direct, d2, cos_x).unwrap();
            let kernel = SlotKernel {
                merge_area: std::f64::consts::PI * r * r,
                connect_area: connect,
            };
            let light = d.light;
            let bsdf = mis.bsdf_density(&d, || bsdf_pdf);
            let w_light = mis.camera_weight(light, &d, kernel, bsdf);
            let w_bsdf = mis.camera_weight(bsdf, &d, kernel, light);
            let w_merge = mis.merge_weight(&d, kernel, || bsdf_pdf);
            // The connection's weight as trace.rs forms it: kq/(kq + N + term) with N = πR²ρ.
            let rho = 1e4;
            let kq = connect * rho;
            let w_connect = if connect > 0.0 {
                kq / (kq + kernel.merge_area * rho + mis.connection_term(&d, rho, || bsdf_pdf))
            } else {
                0.0
            };
            let sum = w_light + w_bsdf + w_merge + w_connect;
            assert!(
                (sum - 1.0).abs() < 1e-9,
                "{sum} for {cos_y} {d2} {cos_x} {r}"
            );
        }
    }

    /// A delta light: no BSDF sample, and the light sample and the merge share the path.
    #[test]
    fn a_point_light_is_shared_by_its_light_sample_and_the_merge() {
        let mis = DirectMis::new(1000, 1);
        let pdf = EmissionPdf {
            emitter: 0,
            pick: 1.0,
            pick_direct: 1.0,
            position: 1.0,
            direction: 1.0 / (4.0 * std::f32::consts::PI),
            direct: 1.0,
            cos_at_light: 1.0,
            is_delta: true,
            is_infinite: false,
        };
        let d = mis.densities(&pdf, 1.0, 4.0, 1.0).unwrap();
        let stored = PhotonDensities::decode(d.encode());
        assert!(stored.delta);
        assert!((stored.light - d.light).abs() <= 1e-6 * d.light);
        let kernel = SlotKernel {
            merge_area: 0.01,
            connect_area: 0.0,
        };
        // A BSDF density offered for a delta light is ignored.
        let w_merge = mis.merge_weight(&stored, kernel, || 5.0);
        let w_light = mis.camera_weight(stored.light, &stored, kernel, 0.0);
        assert!((w_merge + w_light - 1.0).abs() < 1e-6);
        // N · p_dir · cos/d² · πR² photons expected in the disc against n light samples of
        // mass one: 1000 / (4π) / 4 · 0.01 ≈ 0.199 against 1 after the d² of both.
        let expected = 1000.0 / (4.0 * std::f64::consts::PI) * 0.01 / 4.0;
        assert!(
            (w_merge - expected / (expected + 1.0)).abs() < 1e-4,
            "{w_merge}"
        );
    }

    /// A non-delta path stored with a light-sample density of zero keeps its sign.
    #[test]
    fn encoding_keeps_the_delta_flag_of_a_zero_density() {
        let d = PhotonDensities {
            photon: 3.0,
            light: 0.0,
            delta: true,
        };
        assert!(PhotonDensities::decode(d.encode()).delta);
        let d = PhotonDensities { delta: false, ..d };
        assert!(!PhotonDensities::decode(d.encode()).delta);
    }
}
