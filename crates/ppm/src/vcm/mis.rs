//! The multiple importance sampling weights of vertex connection and merging, computed
//! recursively along each subpath as in Georgiev's technical report "Implementing Vertex
//! Connection and Merging" (2012; SmallVCM is its reference): every subpath vertex carries the
//! report's partial sums ([`Partial`]: dVCM and dVC; its dVM is dVC/η), from which the
//! balance-heuristic weight of any connection or merge that ends there follows in constant time.
//!
//! The strategies of a path x₀ (on an emitter) … x_k (on the lens) are the connections (s, t) of
//! a light subpath of s vertices with a camera subpath of t = k + 1 − s vertices: s = 0 is a
//! camera path that hits the emitter, s = 1 next-event estimation, t = 1 light tracing, the
//! others connections between two stored vertices; and the merges at each non-specular interior
//! vertex. Each can be switched off ([`Strategies`]): its density then drops out of every
//! weight, so that the weights of the strategies left still sum to one over each path they can
//! sample. That the switches land where the report's sums hide them (which term of which sum
//! stands for which strategy) is derived in docs/integrators.md and checked by this module's
//! tests against weights computed from the strategies' densities one by one.
//!
//! Conventions: solid-angle densities (sr⁻¹) of the BSDFs and the camera, area densities (m⁻²)
//! of vertices; cosines against geometric normals, so that the weights are a function of the
//! path alone. Russian roulette is left out of the densities (as pbrt-v4's BDPT leaves it out):
//! weights that sum to one keep the estimate unbiased whatever densities they are computed from,
//! as long as every strategy computes the same ones.

use glam::Vec3;
use scene::{Bsdf, BsdfSample, EmissionPdf};

/// Which strategies a render combines.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Strategies {
    /// Emission found by a camera path after at least one bounce (s = 0).
    pub(crate) emission: bool,
    /// Next-event estimation at camera vertices (s = 1).
    pub(crate) next_event: bool,
    /// Light-subpath vertices connected to the lens (t = 1).
    pub(crate) light_tracing: bool,
    /// Camera vertices connected to stored light vertices (s ≥ 2, t ≥ 2).
    pub(crate) connection: bool,
    /// Camera vertices merged with the light vertices within the merge radius.
    pub(crate) merging: bool,
}

impl Strategies {
    /// Every strategy: vertex connection and merging.
    pub(crate) const VCM: Self = Self {
        emission: true,
        next_event: true,
        light_tracing: true,
        connection: true,
        merging: true,
    };
    /// Every connection, no merging: bidirectional path tracing.
    pub(crate) const BDPT: Self = Self {
        merging: false,
        ..Self::VCM
    };

    /// Whether light vertices must be stored (for connections or merges).
    pub(crate) fn stores_light_vertices(self) -> bool {
        self.connection || self.merging
    }
}

/// 1 if `on`, else 0: a strategy's switch as a factor of its terms.
fn on(on: bool) -> f32 {
    if on { 1.0 } else { 0.0 }
}

/// The partial MIS sums of a subpath at its last vertex (the report's dVCM and dVC, with the
/// balance heuristic). After [`Mis::arrive`] at vertex v:
/// - `vcm`: the density ratio of the connection that ends this subpath one vertex earlier and
///   lets the other subpath reach v, over the strategy being weighed, but for the reverse
///   density of v, which the caller multiplies in;
/// - `vc`: the sum of the ratios of the strategies further back (fewer vertices on this side)
///   to a connection at v, less the reverse density of the vertex before v, which the caller
///   multiplies in as a solid-angle density.
///
/// The report's dVM, the same sum for a merge at v, is dVC/η_v with η_v the merge factor at v:
/// every term of dVC is a strategy's density over a connection's, and a merge at v has η_v
/// times a connection's. Keeping dVC alone lets η differ from vertex to vertex (merge radii
/// that depend on the position): each scattering vertex j adds its own η_j to dVC.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct Partial {
    pub(crate) vcm: f32,
    pub(crate) vc: f32,
}

/// The constants of one pass: which strategies run, and the relative sample counts.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Mis {
    pub(crate) strategies: Strategies,
    /// n_L·π if merging, else 0: η = n_L·π·r² at a vertex of merge radius r is the merges'
    /// count times their acceptance area, relative to one connection (the report's η_VCM; n_L
    /// light subpaths merge with each camera path, one connects to it).
    merge_count: f64,
    /// Light-tracing samples per camera sample of a pixel: n_L / samples per pixel.
    light_tracing_count: f32,
}

impl Mis {
    /// The constants of a pass of `light_paths` light subpaths and `samples_per_pixel` camera
    /// paths per pixel.
    pub(crate) fn new(strategies: Strategies, light_paths: u64, samples_per_pixel: u32) -> Self {
        Self {
            strategies,
            merge_count: if strategies.merging {
                light_paths as f64 * std::f64::consts::PI
            } else {
                0.0
            },
            light_tracing_count: (light_paths as f64 / f64::from(samples_per_pixel.max(1))) as f32,
        }
    }

    /// η = n_L·π·r² at a vertex whose merge radius is `radius` (0 without merging): a merge
    /// there relative to one connection.
    pub(crate) fn eta(&self, radius: f64) -> f32 {
        let eta = self.merge_count * radius * radius;
        if eta > 0.0 && eta.is_finite() {
            eta as f32
        } else {
            0.0
        }
    }

    /// The switch of the connection that a light vertex's `vcm` stands for: at the first light
    /// vertex (`index` 1) next-event estimation (the light subpath is the emitter point alone),
    /// further on a connection between stored vertices.
    fn light_vcm_switch(&self, index: u32) -> f32 {
        let s = &self.strategies;
        on(if index == 1 {
            s.next_event
        } else {
            s.connection
        })
    }

    /// The switch of the connection that a camera vertex's `vcm` stands for where the light
    /// subpath goes on from the vertex: at the first camera vertex (`index` 1) light tracing
    /// (the camera subpath is the lens alone), further on a connection between stored vertices.
    fn camera_vcm_switch(&self, index: u32) -> f32 {
        let s = &self.strategies;
        on(if index == 1 {
            s.light_tracing
        } else {
            s.connection
        })
    }

    /// A camera subpath leaving the lens along a direction of solid-angle density
    /// `camera_pdf` (per unit of film area, a pixel being one unit): light tracing's ratio to it.
    pub(crate) fn camera_start(&self, camera_pdf: f32) -> Partial {
        Partial {
            vcm: self.light_tracing_count / camera_pdf,
            vc: 0.0,
        }
    }

    /// A light subpath at its first vertex y₁, emitted with densities `emission`, y₁ at squared
    /// distance `distance2` from the emitter point (ignored for an infinite light, whose
    /// densities are of directions and disc areas), |cos| `cos_in` of the arriving direction
    /// with y₁'s geometric normal, and `pick_direct` the probability that next-event estimation
    /// at y₁ picks this emitter.
    pub(crate) fn light_start(
        &self,
        emission: &EmissionPdf,
        pick_direct: f32,
        distance2: f32,
        cos_in: f32,
    ) -> Partial {
        let emitted = emission.emission_with_pick();
        let direct = pick_direct * emission.direct;
        // Next-event estimation chooses the emitter point by `direct` instead of the emission's
        // position density; the light subpath's direction to y₁ becomes the distance and cosine
        // of y₁'s area density.
        let travel = if emission.is_infinite { 1.0 } else { distance2 };
        let vcm = direct / emitted * travel / cos_in;
        // A camera path can hit what is not a delta light: the emission's position density
        // over its whole density, with the cosine at the light (one off a surface).
        let vc = if emission.is_delta {
            0.0
        } else {
            on(self.strategies.emission) * emission.cos_at_light / emitted / cos_in
        };
        Partial { vcm, vc }
    }

    /// The subpath's sums after it travels to its next vertex: `distance2` the squared length
    /// of the segment (`None` for a first segment from an infinite light, which has no length)
    /// and `cos_in` the |cos| of the arriving direction at the new vertex's geometric normal.
    pub(crate) fn arrive(p: Partial, distance2: Option<f32>, cos_in: f32) -> Partial {
        Partial {
            vcm: p.vcm * distance2.unwrap_or(1.0) / cos_in,
            vc: p.vc / cos_in,
        }
    }

    /// The subpath's sums after it scatters at its vertex number `index` (1-based from its
    /// start; `camera` says which subpath) into a direction of density `forward`, whose reverse
    /// density is `reverse` (probabilities for a `specular` event), `cos_out` the |cos| of the
    /// new direction at the vertex's geometric normal, `eta` the vertex's [`Mis::eta`].
    /// [`Mis::arrive`] completes them.
    #[expect(
        clippy::too_many_arguments,
        reason = "the densities of one scattering event"
    )]
    pub(crate) fn scatter(
        &self,
        p: Partial,
        camera: bool,
        index: u32,
        forward: f32,
        reverse: f32,
        specular: bool,
        cos_out: f32,
        eta: f32,
    ) -> Partial {
        let g = cos_out / forward;
        if specular {
            // No connection or merge can end at a specular vertex.
            return Partial {
                vcm: 0.0,
                vc: p.vc * g * reverse,
            };
        }
        let switch = if camera {
            self.camera_vcm_switch(index)
        } else {
            self.light_vcm_switch(index)
        };
        let vcm = p.vcm * switch;
        Partial {
            vc: g * (p.vc * reverse + vcm + eta),
            vcm: 1.0 / forward,
        }
    }

    /// [`Mis::scatter`] for `sample`, drawn by `bsdf` from `outgoing` at a vertex of geometric
    /// normal `normal`: the reverse density is the BSDF's from the sampled direction back to
    /// `outgoing` (the lobe's probability for a specular sample).
    #[expect(
        clippy::too_many_arguments,
        reason = "the sample and where it was drawn"
    )]
    pub(crate) fn scatter_sample(
        &self,
        p: Partial,
        camera: bool,
        index: u32,
        bsdf: &Bsdf,
        outgoing: Vec3,
        sample: &BsdfSample,
        normal: Vec3,
        eta: f32,
    ) -> Partial {
        let reverse = if sample.is_specular {
            bsdf.specular_probability(sample.incoming, sample.is_transmission)
        } else {
            bsdf.pdf(sample.incoming, outgoing)
        };
        let cos_out = sample.incoming.dot(normal).abs();
        self.scatter(
            p,
            camera,
            index,
            sample.pdf,
            reverse,
            sample.is_specular,
            cos_out,
            eta,
        )
    }

    /// Weight of emission that a camera subpath at `camera` (after [`Mis::arrive`] on the
    /// emitter, or before it for the environment) finds after at least one bounce, where the
    /// emitter produces the point and direction with densities `emission` (its `pick_direct`
    /// from the previous camera vertex). Zero without the emission strategy.
    pub(crate) fn emission_weight(&self, camera: Partial, emission: &EmissionPdf) -> f32 {
        if !self.strategies.emission {
            return 0.0;
        }
        let w_camera = on(self.strategies.next_event) * emission.direct_with_pick() * camera.vcm
            + emission.emission_with_pick() * camera.vc;
        balance(w_camera)
    }

    /// Weight of next-event estimation at camera vertex number `index` (sums `camera`): the
    /// light sample has solid-angle density `light_pdf` (the pick included) and densities
    /// `emission` as a photon toward the vertex, at `distance` (infinite for an infinite
    /// light); the BSDF draws its direction with density `forward` and reverses it with
    /// `reverse`; `cos_at_vertex` is the |cos| of the direction at the vertex's geometric normal;
    /// `eta` is the vertex's [`Mis::eta`].
    #[expect(
        clippy::too_many_arguments,
        reason = "the densities of one light sample"
    )]
    pub(crate) fn next_event_weight(
        &self,
        camera: Partial,
        index: u32,
        emission: &EmissionPdf,
        light_pdf: f32,
        distance: f32,
        forward: f32,
        reverse: f32,
        cos_at_vertex: f32,
        eta: f32,
    ) -> f32 {
        if !self.strategies.next_event {
            return 0.0;
        }
        // A BSDF sample hitting the emitter (never a delta light).
        let w_light = if emission.is_delta {
            0.0
        } else {
            on(self.strategies.emission) * forward / light_pdf
        };
        // The light subpath that emits toward the vertex, in area densities of the vertex and
        // of the emitter point.
        let travel = if emission.is_infinite {
            1.0
        } else {
            distance * distance
        };
        let ratio =
            emission.emission_with_pick() * cos_at_vertex / (emission.direct_with_pick() * travel);
        let w_camera =
            ratio * (eta + self.camera_vcm_switch(index) * camera.vcm + camera.vc * reverse);
        balance(w_light + w_camera)
    }

    /// Weight of the connection of camera vertex number `camera_index` (sums `camera`) with
    /// light vertex number `light_index` (sums `light`). `camera_to_light` is the camera BSDF's
    /// area density of the light vertex, `light_to_camera` the light BSDF's of the camera
    /// vertex; `camera_reverse` and `light_reverse` are the solid-angle densities of each
    /// vertex's BSDF drawing its subpath's previous direction from the connecting one;
    /// `etas` the two vertices' [`Mis::eta`] (camera, light).
    #[expect(clippy::too_many_arguments, reason = "the densities of one connection")]
    pub(crate) fn connection_weight(
        &self,
        camera: Partial,
        camera_index: u32,
        light: Partial,
        light_index: u32,
        camera_to_light: f32,
        light_to_camera: f32,
        camera_reverse: f32,
        light_reverse: f32,
        etas: (f32, f32),
    ) -> f32 {
        if !self.strategies.connection {
            return 0.0;
        }
        let w_light = camera_to_light
            * (etas.1 + self.light_vcm_switch(light_index) * light.vcm + light.vc * light_reverse);
        let w_camera = light_to_camera
            * (etas.0
                + self.camera_vcm_switch(camera_index) * camera.vcm
                + camera.vc * camera_reverse);
        balance(w_light + w_camera)
    }

    /// Weight of the connection of light vertex number `index` (sums `light`) to the lens:
    /// `camera_area` is the camera's area density of the vertex per camera sample and unit of
    /// film area, `reverse` the light BSDF's solid-angle density of the subpath's previous
    /// direction from the direction to the lens, `eta` the vertex's [`Mis::eta`].
    pub(crate) fn light_tracing_weight(
        &self,
        light: Partial,
        index: u32,
        camera_area: f32,
        reverse: f32,
        eta: f32,
    ) -> f32 {
        if !self.strategies.light_tracing {
            return 0.0;
        }
        let w_light = camera_area / self.light_tracing_count
            * (eta + self.light_vcm_switch(index) * light.vcm + light.vc * reverse);
        balance(w_light)
    }

    /// Weight of the merge of camera vertex number `camera_index` (sums `camera`) with light
    /// vertex number `light_index` (sums `light`): the camera BSDF draws the light vertex's
    /// arriving direction with density `forward` and its own previous direction from there with
    /// `reverse`; `eta` is the [`Mis::eta`] of the merge's radius. Every rival is relative to a
    /// connection in the sums, and this merge is η times a connection.
    #[expect(clippy::too_many_arguments, reason = "the densities of one merge")]
    pub(crate) fn merge_weight(
        &self,
        camera: Partial,
        camera_index: u32,
        light: Partial,
        light_index: u32,
        forward: f32,
        reverse: f32,
        eta: f32,
    ) -> f32 {
        if !self.strategies.merging || eta <= 0.0 {
            return 0.0;
        }
        let w_light = self.light_vcm_switch(light_index) * light.vcm + light.vc * forward;
        let w_camera = self.camera_vcm_switch(camera_index) * camera.vcm + camera.vc * reverse;
        balance((w_light + w_camera) / eta)
    }
}

/// The balance heuristic's weight 1/(1 + w) of a strategy whose rivals sum to `w` times its
/// density; zero where the sum is not finite (a rival infinitely more likely).
fn balance(w: f32) -> f32 {
    let weight = 1.0 / (1.0 + w);
    if weight.is_finite() { weight } else { 0.0 }
}
