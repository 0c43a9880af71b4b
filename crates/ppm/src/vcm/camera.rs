//! The camera subpaths of a pass: at every vertex the emission found there, and at every
//! non-specular one next-event estimation, connections to the stored vertices of the paired
//! light subpath and merges with every light vertex within the merge radius, each weighted by
//! its MIS weight (`mis.rs`).

use glam::{Vec2, Vec3};
use photon::HitPointGrid;
use scene::{Bsdf, Hit, Rgb, Scene, TransportMode};

use super::light::LightVertices;
use super::mis::{Mis, Partial};
use super::radius::MergeRadius;
use super::shading_ratio_about;
use crate::rng::{CAMERA_STREAM, Sampler};

/// The cosine above which the normals of a camera vertex and a light vertex must agree for a
/// merge (60°, the photon mappers' acceptance test): a light vertex on the back of a thin wall
/// or round a corner is not merged.
const MERGE_NORMAL_COS: f32 = 0.5;

/// What a camera subpath needs of its pass.
pub(crate) struct CameraPass<'a> {
    pub(crate) scene: &'a Scene,
    pub(crate) mis: Mis,
    pub(crate) radius: MergeRadius<'a>,
    pub(crate) seed: u64,
    pub(crate) pass: u32,
    pub(crate) max_depth: u32,
    pub(crate) rr_depth: u32,
    pub(crate) width: u32,
    pub(crate) samples_per_pixel: u32,
    /// The kept light vertices of the pass.
    pub(crate) vertices: LightVertices<'a>,
    /// Light subpaths in the pass.
    pub(crate) light_paths: u64,
    /// The grid over the light vertices with the pass's global radius (the largest a merge
    /// has), if merging.
    pub(crate) grid: Option<&'a HitPointGrid>,
}

/// What one camera subpath brought back.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct CameraSample {
    pub(crate) radiance: Rgb,
    /// Light vertices merged.
    pub(crate) merges: u64,
}

/// Where the camera subpath stands: its vertex, the way it arrived and its sums.
struct Vertex<'h> {
    hit: &'h Hit,
    bsdf: &'h Bsdf,
    /// Unit direction back along the subpath.
    outgoing: Vec3,
    partial: Partial,
    /// Its merge radius ([`MergeRadius::at`]) and [`Mis::eta`].
    radius: f64,
    eta: f32,
    /// Its number on the subpath: 1 for the first hit, after `index − 1` bounces.
    index: u32,
}

impl CameraPass<'_> {
    /// Camera subpath `sample` of `pixel`: its radiance estimate of the pixel.
    pub(crate) fn trace(&self, pixel: u32, sample: u32) -> CameraSample {
        let scene = self.scene;
        let lights = scene.lights();
        let camera = scene.camera();
        let path = u64::from(pixel) * u64::from(self.samples_per_pixel) + u64::from(sample);
        let mut sampler = Sampler::new(self.seed, self.pass, CAMERA_STREAM | path);
        let (x, y) = (pixel % self.width, pixel / self.width);
        let film = Vec2::new(x as f32, y as f32) + sampler.next_2d();
        let mut ray = camera.generate_ray(film, sampler.next_2d());
        // The solid-angle density of the ray per unit of film area: F²/cos³θ, θ off the view axis.
        let cos = camera.forward().dot(ray.direction);
        let focal = camera.focal_pixels();
        let mut partial = self.mis.camera_start(focal * focal / (cos * cos * cos));
        let light_path = path % self.light_paths.max(1);
        let mut out = CameraSample::default();
        let mut beta = Rgb::ONE;
        let mut previous: Option<Hit> = None;
        for index in 1.. {
            let Some(hit) = scene.intersect(&ray) else {
                let sky = lights.environment_radiance(ray.direction);
                if sky != Rgb::ZERO {
                    let weight = match &previous {
                        None => 1.0,
                        Some(_) => lights
                            .pdf_emission_environment(ray.direction)
                            .map_or(0.0, |e| self.mis.emission_weight(partial, &e)),
                    };
                    out.radiance += beta * sky * weight;
                }
                break;
            };
            let outgoing = -ray.direction;
            let cos_in = outgoing.dot(hit.geometric_normal).abs();
            if cos_in.is_nan() || cos_in <= 0.0 {
                break;
            }
            let distance2 = previous
                .as_ref()
                .map_or(hit.t * hit.t, |p| p.position.distance_squared(hit.position));
            partial = Mis::arrive(partial, Some(distance2), cos_in);
            let emitted = scene.emitted(&hit);
            if emitted != Rgb::ZERO {
                // Seen directly, emission has no other strategy (light subpaths do not connect
                // their emitter point to the lens).
                let weight = match &previous {
                    None => 1.0,
                    Some(p) => lights
                        .pdf_emission(&hit, outgoing, (p.position, p.geometric_normal))
                        .map_or(0.0, |e| self.mis.emission_weight(partial, &e)),
                };
                out.radiance += beta * emitted * weight;
            }
            // Every strategy at this vertex adds a scattering event to the `index − 1` before.
            if index > self.max_depth {
                break;
            }
            let Some(bsdf) = scene.bsdf(&hit) else {
                break;
            };
            // Always drawn, so that later dimensions do not depend on what this vertex does.
            let u_light = sampler.next_f32();
            let u_light_2d = sampler.next_2d();
            let u_lobe = sampler.next_f32();
            let u = sampler.next_2d();
            let u_roulette = sampler.next_f32();
            let (radius, eta) = if bsdf.is_specular() {
                (0.0, 0.0)
            } else {
                let r = self.radius.at(hit.position);
                (r, self.mis.eta(r))
            };
            if !bsdf.is_specular() {
                let vertex = Vertex {
                    hit: &hit,
                    bsdf: &bsdf,
                    outgoing,
                    partial,
                    radius,
                    eta,
                    index,
                };
                let mut here = Rgb::ZERO;
                if self.mis.strategies.next_event {
                    here += self.next_event(&vertex, u_light, u_light_2d);
                }
                if self.mis.strategies.connection {
                    here += self.connect(&vertex, light_path);
                }
                if let Some(grid) = self.grid {
                    let (merged, count) = self.merge(&vertex, grid);
                    here += merged;
                    out.merges += count;
                }
                out.radiance += beta * here;
            }
            let Some(sample) = bsdf.sample(outgoing, u_lobe, u, TransportMode::Radiance) else {
                break;
            };
            beta *= sample.weight;
            if index >= self.rr_depth {
                let survive = beta.max_element().min(1.0);
                if survive <= 0.0 || u_roulette >= survive {
                    break;
                }
                beta /= survive;
            }
            if beta == Rgb::ZERO || !beta.is_finite() {
                break;
            }
            partial = self.mis.scatter_sample(
                partial,
                true,
                index,
                &bsdf,
                outgoing,
                &sample,
                hit.geometric_normal,
                eta,
            );
            ray = hit.spawn_ray(sample.incoming);
            previous = Some(hit);
        }
        out
    }

    /// Next-event estimation at `v`: one light sample, MIS-weighted against every other
    /// strategy of its path.
    fn next_event(&self, v: &Vertex<'_>, u_light: f32, u: Vec2) -> Rgb {
        let scene = self.scene;
        let hit = v.hit;
        let Some((sample, emission)) =
            scene
                .lights()
                .sample_direct_with_pdf(hit.position, hit.geometric_normal, u_light, u)
        else {
            return Rgb::ZERO;
        };
        if sample.pdf.is_nan() || sample.pdf <= 0.0 {
            return Rgb::ZERO;
        }
        let f = v.bsdf.eval(v.outgoing, sample.incoming);
        if f == Rgb::ZERO {
            return Rgb::ZERO;
        }
        let pdfs = v.bsdf.pdfs(v.outgoing, sample.incoming);
        let cos_g = sample.incoming.dot(hit.geometric_normal).abs();
        let weight = self.mis.next_event_weight(
            v.partial,
            v.index,
            &emission,
            sample.pdf,
            sample.distance,
            pdfs.forward,
            pdfs.reverse,
            cos_g,
            v.eta,
        );
        if weight <= 0.0 || !scene.light_visible(hit, &sample) {
            return Rgb::ZERO;
        }
        let cos_s = sample.incoming.dot(v.bsdf.frame().n).abs();
        f * sample.radiance * (cos_s * weight / sample.pdf)
    }

    /// The connections of `v` with the stored vertices of light subpath `light_path`.
    fn connect(&self, v: &Vertex<'_>, light_path: u64) -> Rgb {
        let mut total = Rgb::ZERO;
        let hit = v.hit;
        for y in self.vertices.path(light_path) {
            // The whole path scatters at the light vertices 1..=index and the camera vertices
            // 1..=v.index; the light subpath's vertices come in order.
            if y.index + v.index > self.max_depth {
                break;
            }
            let d = y.position - hit.position;
            let distance2 = d.length_squared();
            if distance2.is_nan() || distance2 <= 0.0 {
                continue;
            }
            let dir = d / distance2.sqrt();
            let f_camera = v.bsdf.eval(v.outgoing, dir);
            if f_camera == Rgb::ZERO {
                continue;
            }
            let f_light = y.bsdf.eval(-dir, y.incoming);
            if f_light == Rgb::ZERO {
                continue;
            }
            let camera_pdfs = v.bsdf.pdfs(v.outgoing, dir);
            let light_pdfs = y.bsdf.pdfs(y.incoming, -dir);
            let cos_camera = dir.dot(hit.geometric_normal).abs();
            let cos_light = dir.dot(y.normal).abs();
            let weight = self.mis.connection_weight(
                v.partial,
                v.index,
                y.partial,
                y.index,
                camera_pdfs.forward * cos_light / distance2,
                light_pdfs.forward * cos_camera / distance2,
                camera_pdfs.reverse,
                light_pdfs.reverse,
                (v.eta, y.eta),
            );
            if weight <= 0.0 || !self.scene.visible(hit, y.position) {
                continue;
            }
            let cos_shading = dir.dot(v.bsdf.frame().n).abs();
            let geometry = cos_shading * cos_light * y.ratio / distance2;
            total += f_camera * f_light * y.power * (geometry * weight);
        }
        total
    }

    /// The merges of `v` with the light vertices within its merge radius r(x), in the grid's
    /// order, divided by the kernel's area and the light subpaths' count; and how many there
    /// were. The kernel is centred on the camera vertex: with radii that vary over the scene,
    /// a kernel centred on each light vertex would not integrate to one where the radius
    /// changes, and the estimate would be biased there.
    fn merge(&self, v: &Vertex<'_>, grid: &HitPointGrid) -> (Rgb, u64) {
        let hit = v.hit;
        let normal = hit.geometric_normal;
        let shading = v.bsdf.frame().n;
        let mut total = Rgb::ZERO;
        let mut count = 0;
        // The grid holds every vertex within the global radius; a smaller r(x) checks its own.
        let r2 = (v.radius < self.radius.global).then_some((v.radius * v.radius) as f32);
        // A surface that transmits through a lobe of finite density (a rough dielectric) sees
        // light from both sides: a light vertex that arrived on its other side is merged too if
        // it lies on the same surface (within a quarter of the radius of the tangent plane, as the
        // photon mappers' gather does), or the weight the MIS gives this merge would be lost.
        let transmits = v.bsdf.kind().transmits();
        let plane = 0.25 * v.radius as f32;
        grid.for_each_containing(hit.position, |i| {
            let y = self.vertices.get(i);
            if r2.is_some_and(|r2| y.position.distance_squared(hit.position) >= r2) {
                return;
            }
            let same_side = y.incoming.dot(normal) > 0.0 && y.normal.dot(normal) > MERGE_NORMAL_COS;
            let crossed = || {
                transmits
                    && y.incoming.dot(normal) < 0.0
                    && y.normal.dot(-normal) > MERGE_NORMAL_COS
                    && (y.position - hit.position).dot(normal).abs() <= plane
            };
            // The merged path scatters at the light vertices 1..index − 1, at the merged vertex
            // and at the camera vertices 1..v.index − 1.
            if y.index + v.index > self.max_depth + 1 || !(same_side || crossed()) {
                return;
            }
            let f = v.bsdf.eval(v.outgoing, y.incoming);
            if f == Rgb::ZERO {
                return;
            }
            let pdfs = v.bsdf.pdfs(v.outgoing, y.incoming);
            let weight = self.mis.merge_weight(
                v.partial,
                v.index,
                y.partial,
                y.index,
                pdfs.forward,
                pdfs.reverse,
                v.eta,
            );
            let ratio = shading_ratio_about(shading, normal, y.incoming);
            total += f * y.power * (weight * ratio);
            count += 1;
        });
        // 1/(π r² n_L): the kernel's area and the light subpaths' count.
        let kernel = 1.0 / (std::f64::consts::PI * v.radius * v.radius * self.light_paths as f64);
        (total * kernel as f32, count)
    }
}
