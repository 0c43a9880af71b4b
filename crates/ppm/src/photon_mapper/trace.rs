//! Tracing one photon path: emission, Russian roulette, scattering, and the photons it stores
//! on non-specular surfaces (with the frequency steps of `frequency.rs` for frequency photons).

use glam::Vec3;
use photon::Photon;
use scene::{Bsdf, Hit, Rgb, medium_after};

use super::Setup;
use super::frequency::{FrequencyPhoton, arrived, scatter_spectrum};
use super::media::Flight;
use super::volume::VolumePhoton;
use crate::light_path::{Scatter, emit, lens_point, lens_radiance, lens_radiance_through, scatter};
use crate::path::{MAX_CROSSINGS, transmittance};
use crate::rng::Sampler;

/// Photons of one chunk, in trace order.
#[derive(Default)]
pub(super) struct TracedPhotons {
    pub(super) photons: Vec<Photon>,
    /// The frequency records of the chunk's frequency photons, in trace order.
    pub(super) frequency: Vec<FrequencyPhoton>,
    pub(super) frequency_photons: u64,
    /// Photon paths ended because their power became NaN or infinite (and light-traced
    /// contributions dropped for it).
    pub(super) non_finite: u64,
    /// Light-traced contributions (`light_tracing`), in trace order: the hitpoint slot whose
    /// image they add to, and the radiance they add there times the photons emitted, MIS
    /// weight and 1/spp included.
    pub(super) splats: Vec<(u32, [f32; 3])>,
    /// Photons connected to the camera.
    pub(super) connections: u64,
    /// Photons stored where they scattered in a medium (`volume.rs`), in trace order.
    pub(super) volume: Vec<VolumePhoton>,
}

/// What light tracing needs of the current pass: every slot's gather radius, which its MIS
/// weight against merging depends on.
#[derive(Clone, Copy)]
pub(super) struct LightTracing<'a> {
    pub(super) radii: &'a [f64],
    pub(super) samples_per_pixel: u32,
    /// `connect_below`: see [`LightTracing::connection_rate`].
    pub(super) connect_below: f64,
    /// Light paths connected per photon stored: 1 + `extra_light_paths`.
    pub(super) paths_per_photon: f64,
}

impl LightTracing<'_> {
    /// N = πR²ρ of every slot of `pixel` for a point with `rho` camera samples per unit area:
    /// how many of the slot's camera samples a merge at that radius covers.
    fn kernel_samples(&self, pixel: u32, rho: f64) -> impl Iterator<Item = f64> + '_ {
        let spp = self.samples_per_pixel;
        let slots = (pixel * spp) as usize..((pixel + 1) * spp) as usize;
        self.radii[slots]
            .iter()
            .map(move |&r| std::f64::consts::PI * r * r * rho)
    }

    /// The probability q that a photon at a point is connected to the camera, given the N of
    /// its pixel's slots: 1 where the smallest N is at most `connect_below`, else 0. The
    /// balance heuristic weighs the connection strategy by its rate: kq/(kq + N) for the
    /// connection, N/(kq + N) for the merge (k = `paths_per_photon`, the light paths connected
    /// per photon stored), so that where q = 0 merging takes all the weight.
    ///
    /// Why a threshold: per photon landing in a pixel, the combined variance goes as
    /// 1/(q + N) and the cost as t + q·c (t the photon's own cost, c a connection's), so the
    /// efficiency (q + N)/(t + q·c) grows with q exactly when N < t/c: connect always or never.
    /// A connection costs about a third of a stored photon's share of the pass (its shadow ray
    /// against the photon's tracing, gathering and the pass's overhead), hence a few; the
    /// default was chosen at equal time (docs/integrators.md).
    pub(super) fn connection_rate(&self, pixel: u32, rho: f64) -> f64 {
        let n = self
            .kernel_samples(pixel, rho)
            .fold(f64::INFINITY, f64::min);
        if n <= self.connect_below { 1.0 } else { 0.0 }
    }
}

impl TracedPhotons {
    /// Empties the chunk for the next pass, keeping the allocations.
    pub(super) fn clear(&mut self) {
        self.photons.clear();
        self.frequency.clear();
        self.frequency_photons = 0;
        self.non_finite = 0;
        self.splats.clear();
        self.connections = 0;
        self.volume.clear();
    }
}

impl AsRef<[Photon]> for TracedPhotons {
    fn as_ref(&self) -> &[Photon] {
        &self.photons
    }
}

impl Setup {
    /// Traces photon path `index` of pass `pass` and stores its non-specular hits in `out`.
    /// `TEXTURED_HITS` must be the scene's `Scene::textured_hits`. Without `STORE` the path is
    /// a connection-only light path (`extra_light_paths`, `index` with
    /// `CONNECT_ONLY_STREAM` set): it carries no spectrum and stores nothing, and its
    /// non-specular hits are only connected to the camera.
    ///
    /// The hot loop of a pass: `Scene::intersect_inlined` compiles the BVH traversal and the
    /// hit into it, so that the `Hit` is not returned through memory, and one copy per kind of
    /// scene keeps the texture work of hits out of the untextured one. Not inlined itself (one
    /// call per path), so that it stays visible in profiles; docs/performance.md says where
    /// its time goes.
    ///
    /// `MEDIA` must be the scene's `Scene::has_media`: in media the path draws free flights
    /// (`media.rs`), stores a volume photon where it scatters, and crosses interfaces without a
    /// bounce; a frequency photon loses its spectrum when it scatters in a medium or crosses an
    /// interface (the spectrum's operators for media are not implemented).
    #[inline(never)]
    pub(super) fn trace_photon<const TEXTURED_HITS: bool, const STORE: bool, const MEDIA: bool>(
        &self,
        pass: u32,
        index: u64,
        tag_base: u32,
        light: Option<LightTracing<'_>>,
        out: &mut TracedPhotons,
    ) {
        let seed = self.params.seed;
        let Some((mut sampler, emission)) =
            emit(&self.scene, seed, pass, index, &mut out.non_finite)
        else {
            return;
        };
        let mut power = emission.power;
        let mut ray = emission.ray();
        let mut spectrum = if STORE {
            self.start_spectrum(index, emission.emitter)
        } else {
            None
        };
        if spectrum.is_some() {
            out.frequency_photons += 1;
        }
        // Read once: the stores into `out` in the loop would otherwise make the compiler
        // reload them through `self.params` at every bounce.
        let max_depth = self.params.budget.max_depth;
        let rr_depth = self.params.budget.rr_depth;
        let direct_lighting = self.params.connections.direct_lighting;
        let mut medium = if MEDIA {
            self.medium_at(ray.origin)
        } else {
            None
        };
        let mut crossings = 0;
        // `depth`: the photon's bounces before this hit. A hitpoint adds one more, so hits at
        // depth max_depth − 1 are the last that can count.
        let mut depth = 0;
        while depth < max_depth {
            let hit = self.scene.intersect_inlined::<TEXTURED_HITS>(&ray);
            if MEDIA && let Some(id) = medium {
                match self.fly(id, &ray, hit.as_ref(), power, &mut sampler) {
                    Flight::Through(p) => power = p,
                    Flight::End => break,
                    Flight::NonFinite => {
                        out.non_finite += 1;
                        break;
                    }
                    Flight::Scatter { position, power: p } => {
                        spectrum = None;
                        if STORE {
                            out.volume.push(VolumePhoton {
                                position,
                                incoming: -ray.direction,
                                power: p,
                                medium: id,
                                bounces: depth,
                            });
                        }
                        if depth + 1 == max_depth {
                            break;
                        }
                        let Some(next) = self.scatter_in_medium(
                            id,
                            &ray,
                            position,
                            (power, p),
                            depth + 1 >= rr_depth,
                            &mut sampler,
                        ) else {
                            break;
                        };
                        (ray, power) = next;
                        depth += 1;
                        crossings = 0;
                        continue;
                    }
                }
            }
            let Some(hit) = hit else {
                break;
            };
            if MEDIA && self.scene.is_interface(&hit) {
                crossings += 1;
                if crossings > MAX_CROSSINGS {
                    break;
                }
                spectrum = None;
                medium = medium_after(self.scene.shape_media(&hit), &hit, ray.direction, medium);
                ray = hit.spawn_ray(ray.direction);
                continue;
            }
            let Some(material) = self.scene.material(hit.material) else {
                break;
            };
            let incoming = -ray.direction;
            if let Some(s) = spectrum.as_mut() {
                *s = self.travel_spectrum(*s, &ray, &hit, &mut sampler);
            }
            // The frequency photon's field where it lands: the sharper of its two axes.
            let here = spectrum.map(arrived);
            let bsdf = self.scene.material_bsdf(material, &hit);
            // With direct lighting by light sampling, photons straight from an emitter are
            // already accounted for at the hitpoints.
            let counted_by_light_sampling = direct_lighting && depth == 0;
            // Camera paths pass through the sharp glossy surfaces as through mirrors
            // (`glossy_continue`): the light there is theirs, so nothing is stored or connected.
            let merged_here = !bsdf.is_specular() && !self.passes_through(material);
            if merged_here && !counted_by_light_sampling && !STORE {
                if let Some(light) = light {
                    self.connect_to_camera::<MEDIA>(
                        &hit, &bsdf, incoming, power, medium, &sampler, depth, light, out,
                    );
                }
            } else if merged_here && !counted_by_light_sampling {
                let tag = self.record_frequency_photon(
                    here,
                    &hit,
                    incoming,
                    material.kind.lobe(),
                    tag_base,
                    out.photons.len() as u32,
                    &mut out.frequency,
                );
                out.photons.push(Photon {
                    position: hit.position,
                    incoming,
                    power,
                    normal: hit.geometric_normal,
                    bounces: depth,
                    tag,
                });
                if let Some(light) = light {
                    self.connect_to_camera::<MEDIA>(
                        &hit, &bsdf, incoming, power, medium, &sampler, depth, light, out,
                    );
                }
            }
            // Scatter, unless no later hit could count.
            if depth + 1 == max_depth {
                break;
            }
            let roulette = depth + 1 >= rr_depth;
            let sample = match scatter(&hit, &bsdf, incoming, power, roulette, &mut sampler) {
                Scatter::Continue { sample, power: p } => {
                    power = p;
                    sample
                }
                Scatter::End => break,
                Scatter::NonFinite => {
                    out.non_finite += 1;
                    break;
                }
            };
            if let Some(s) = here {
                spectrum = Some(scatter_spectrum(
                    s, &hit, incoming, &sample, &bsdf, material, &self.caps,
                ));
            }
            if MEDIA {
                medium = medium_after(self.scene.shape_media(&hit), &hit, sample.incoming, medium);
                crossings = 0;
            }
            ray = hit.spawn_ray(sample.incoming);
            depth += 1;
        }
    }
}

impl Setup {
    /// Light tracing: the photon stored at `hit` (power `power`, arriving along −`incoming`)
    /// reflected toward the lens, added to the slots of the pixel it lands on.
    ///
    /// The radiance it adds to a pixel is f·Φ·|cos θₓ|·(du/dω)/d² (per photon emitted; the
    /// pixel is one unit of film area, `CameraModel::connect`), the same flux per unit area as
    /// a merge evaluates with f·Φ/(πR²). The photon is connected with probability q
    /// ([`LightTracing::connection_rate`]); slot s of the pixel takes the connection with the
    /// balance heuristic's weight kq/(kq + N), N = πR_s²·ρ(x), ρ the camera samples per unit
    /// area at the photon (`CameraModel::film_density`), k the light paths connected per photon
    /// stored, divided by q, by k and by spp; a merge at a directly seen hitpoint takes
    /// N/(kq + N) with ρ and q at the hitpoint (`photon_pass.rs`), so that the two weights of a
    /// path sum to one as the kernel shrinks onto it.
    ///
    /// With `MEDIA`, the light reaching the lens is weighted by the transmittance of the way
    /// there, starting in the medium on the lens's side of `hit` (`medium` is the one the
    /// photon arrived in).
    #[allow(clippy::too_many_arguments)]
    fn connect_to_camera<const MEDIA: bool>(
        &self,
        hit: &Hit,
        bsdf: &Bsdf,
        incoming: Vec3,
        power: Rgb,
        medium: Option<u32>,
        sampler: &Sampler,
        depth: u32,
        light: LightTracing<'_>,
        out: &mut TracedPhotons,
    ) {
        let Some((connection, pixel)) =
            lens_point(&self.scene, hit, sampler, depth, (self.width, self.height))
        else {
            return;
        };
        let camera = self.scene.camera();
        let rho = f64::from(camera.film_density(hit.position, hit.geometric_normal));
        let rate = light.connection_rate(pixel, rho);
        if rate == 0.0 {
            return;
        }
        let value = if MEDIA {
            lens_radiance_through(hit, bsdf, incoming, power, &connection, |lens| {
                let scene = &*self.scene;
                let start = medium_after(scene.shape_media(hit), hit, lens - hit.position, medium);
                Some(transmittance(scene, hit.spawn_ray_to(lens), start))
            })
        } else {
            lens_radiance(&self.scene, hit, bsdf, incoming, power, &connection)
        };
        let Some(value) = value else {
            return;
        };
        if !value.is_finite() {
            out.non_finite += 1;
            return;
        }
        out.connections += 1;
        let spp = light.samples_per_pixel;
        let k = light.paths_per_photon;
        for (i, n) in light.kernel_samples(pixel, rho).enumerate() {
            // Weight kq/(kq + N) over the connection's probability q (q = 1 here) and over the
            // k connecting paths per photon emitted.
            let weight = 1.0 / ((k * rate + n) * f64::from(spp));
            let v = value * weight as f32;
            out.splats.push((pixel * spp + i as u32, [v.x, v.y, v.z]));
        }
    }
}
