//! The light subpaths of a pass: traced from the emitters as the photon mappers trace photons
//! (`light_path.rs`: the same emission sample, Russian roulette and BSDF samples from the same
//! (seed, pass, path index) streams), with the MIS sums of every vertex; the non-specular
//! vertices are stored for connections and merges and connected to the lens (light tracing).

use glam::Vec3;
use scene::{Bsdf, Hit, Rgb, Scene};

use super::mis::{Mis, Partial};
use super::radius::MergeRadius;
use super::shading_ratio;
use crate::light_path::{Scatter, lens_point, lens_radiance, scatter};
use crate::rng::Sampler;

/// A non-specular vertex of a light subpath, kept for the pass's connections and merges.
#[derive(Clone, Copy, Debug)]
pub(crate) struct LightVertex {
    pub(crate) position: Vec3,
    /// Unit geometric normal, on the side the subpath arrived from.
    pub(crate) normal: Vec3,
    /// Unit direction back toward the previous vertex.
    pub(crate) incoming: Vec3,
    pub(crate) bsdf: Bsdf,
    /// The subpath's power arriving here, per subpath emitted.
    pub(crate) power: Rgb,
    /// [`shading_ratio`] of `incoming` here: what a connection from here multiplies in.
    pub(crate) ratio: f32,
    pub(crate) partial: Partial,
    /// The merge radius here ([`MergeRadius::at`]) and its [`Mis::eta`].
    pub(crate) radius: f32,
    pub(crate) eta: f32,
    /// Its number on the subpath: 1 for the first vertex after the emitter, whose subpath has
    /// scattered `index − 1` times before it.
    pub(crate) index: u32,
}

/// What one chunk of light subpaths produced in a pass, reused from pass to pass.
#[derive(Default)]
pub(crate) struct LightChunk {
    /// The stored vertices, subpath after subpath, each subpath's in order.
    pub(crate) vertices: Vec<LightVertex>,
    /// Per subpath of the chunk: the end of its vertices in `vertices`.
    pub(crate) ends: Vec<u32>,
    /// (pixel, radiance per subpath emitted) of the connections to the lens, in trace order.
    pub(crate) splats: Vec<(u32, [f32; 3])>,
    /// Values dropped for being NaN or infinite.
    pub(crate) non_finite: u64,
}

impl LightChunk {
    pub(crate) fn clear(&mut self) {
        self.vertices.clear();
        self.ends.clear();
        self.splats.clear();
        self.non_finite = 0;
    }
}

/// Light subpaths per chunk (a parallel work item of the light pass); fixed so that the vertex
/// order and the sums do not depend on the thread count.
pub(crate) const PATH_CHUNK: u64 = 2048;

/// The kept vertices of a pass, left in their chunks (a copy into one list would double the
/// pass's largest buffer): numbered over the pass in chunk order, as the grid numbers them.
#[derive(Clone, Copy)]
pub(crate) struct LightVertices<'a> {
    pub(crate) chunks: &'a [LightChunk],
    /// Per chunk, the pass number of its first vertex; then their total.
    pub(crate) offsets: &'a [u32],
}

impl<'a> LightVertices<'a> {
    /// Vertex `i` of the pass.
    pub(crate) fn get(&self, i: u32) -> &'a LightVertex {
        let chunk = self.offsets.partition_point(|&o| o <= i) - 1;
        &self.chunks[chunk].vertices[(i - self.offsets[chunk]) as usize]
    }

    /// The vertices of light subpath `path` of the pass (numbered from 0), in order; none for a
    /// subpath whose chunk's vertices were not kept.
    pub(crate) fn path(&self, path: u64) -> &'a [LightVertex] {
        let Some(chunk) = self.chunks.get((path / PATH_CHUNK) as usize) else {
            return &[];
        };
        let local = (path % PATH_CHUNK) as usize;
        let start = if local == 0 { 0 } else { chunk.ends[local - 1] };
        chunk
            .vertices
            .get(start as usize..chunk.ends[local] as usize)
            .unwrap_or(&[])
    }
}

/// What a light subpath needs of its pass.
pub(crate) struct LightPass<'a> {
    pub(crate) scene: &'a Scene,
    pub(crate) mis: Mis,
    pub(crate) radius: MergeRadius<'a>,
    pub(crate) seed: u64,
    pub(crate) pass: u32,
    pub(crate) max_depth: u32,
    pub(crate) rr_depth: u32,
    pub(crate) film: (u32, u32),
}

impl LightPass<'_> {
    /// Traces light subpath `index` into `out`: its stored vertices, its end, its connections
    /// to the lens.
    pub(crate) fn trace(&self, index: u64, out: &mut LightChunk) {
        self.walk(index, out);
        out.ends.push(out.vertices.len() as u32);
    }

    fn walk(&self, index: u64, out: &mut LightChunk) {
        let scene = self.scene;
        let lights = scene.lights();
        let strategies = self.mis.strategies;
        // The dimensions of `light_path::emit`, so that the subpath is the photon mappers'.
        let mut sampler = Sampler::new(self.seed, self.pass, index);
        let u_light = sampler.next_f32();
        let u_pos = sampler.next_2d();
        let u_dir = sampler.next_2d();
        let Some((emission, emission_pdf)) = lights.sample_emission_with_pdf(u_light, u_pos, u_dir)
        else {
            return;
        };
        if !emission.power.is_finite() {
            out.non_finite += 1;
            return;
        }
        let emitted = emission_pdf.emission_with_pick();
        if emitted.is_nan() || emitted <= 0.0 {
            return;
        }
        let mut power = emission.power;
        let mut ray = emission.ray();
        let mut previous = emission.origin;
        let mut partial = Partial::default();
        for vertex in 1..=self.max_depth {
            let Some(hit) = scene.intersect(&ray) else {
                break;
            };
            let Some(bsdf) = scene.bsdf(&hit) else {
                break;
            };
            let incoming = -ray.direction;
            let cos_in = incoming.dot(hit.geometric_normal).abs();
            if cos_in.is_nan() || cos_in <= 0.0 {
                break;
            }
            let distance2 = previous.distance_squared(hit.position);
            partial = if vertex == 1 {
                let pick_direct = lights.pick_direct(
                    emission_pdf.emitter as usize,
                    hit.position,
                    hit.geometric_normal,
                );
                self.mis
                    .light_start(&emission_pdf, pick_direct, distance2, cos_in)
            } else {
                Mis::arrive(partial, Some(distance2), cos_in)
            };
            let radius = self.radius.at(hit.position);
            let eta = self.mis.eta(radius);
            if !bsdf.is_specular() {
                if strategies.stores_light_vertices() {
                    out.vertices.push(LightVertex {
                        position: hit.position,
                        normal: hit.geometric_normal,
                        incoming,
                        bsdf,
                        power,
                        ratio: shading_ratio(&hit, incoming),
                        partial,
                        radius: radius as f32,
                        eta,
                        index: vertex,
                    });
                }
                if strategies.light_tracing {
                    let state = (power, partial, eta);
                    self.to_lens(&hit, &bsdf, incoming, state, vertex, &sampler, out);
                }
            }
            // A vertex further on would need one more scattering event than the path may have.
            if vertex == self.max_depth {
                break;
            }
            let roulette = vertex >= self.rr_depth;
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
            partial = self.mis.scatter_sample(
                partial,
                false,
                vertex,
                &bsdf,
                incoming,
                &sample,
                hit.geometric_normal,
                eta,
            );
            previous = hit.position;
            ray = hit.spawn_ray(sample.incoming);
        }
    }

    /// Light tracing: connects the light vertex number `vertex` at `hit` (its power, MIS sums
    /// and [`Mis::eta`] in `state`) to the lens and splats its MIS-weighted radiance onto the
    /// pixel it lands on.
    #[expect(clippy::too_many_arguments, reason = "one light vertex")]
    fn to_lens(
        &self,
        hit: &Hit,
        bsdf: &Bsdf,
        incoming: Vec3,
        state: (Rgb, Partial, f32),
        vertex: u32,
        sampler: &Sampler,
        out: &mut LightChunk,
    ) {
        let (power, partial, eta) = state;
        let scene = self.scene;
        let Some((connection, pixel)) = lens_point(scene, hit, sampler, vertex - 1, self.film)
        else {
            return;
        };
        let Some(value) = lens_radiance(scene, hit, bsdf, incoming, power, &connection) else {
            return;
        };
        let toward = (connection.lens - hit.position).normalize();
        // The camera's density of this point per unit of film area, in area measure.
        let camera_area = connection.density * toward.dot(hit.geometric_normal).abs();
        let reverse = bsdf.pdf(toward, incoming);
        let weight = self
            .mis
            .light_tracing_weight(partial, vertex, camera_area, reverse, eta);
        if weight <= 0.0 {
            return;
        }
        let value = value * (weight * shading_ratio(hit, incoming));
        if value.is_finite() {
            out.splats.push((pixel, [value.x, value.y, value.z]));
        } else {
            out.non_finite += 1;
        }
    }
}
