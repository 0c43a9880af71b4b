//! Participating media: homogeneous and grid media as a scene describes them ([`Medium`],
//! [`crate::DensityGrid`]), free-flight sampling and transmittance through them
//! ([`Medium::sample_free_flight`], [`Medium::transmittance_along`]), which media lie
//! on either side of a shape ([`ShapeMedia`], [`Media`]), the Henyey–Greenstein phase function
//! ([`HenyeyGreenstein`]) and the per-primitive lookup a [`crate::Scene`] answers
//! ([`MediumMap`]).
//!
//! Conventions (Mitsuba's and pbrt's): a shape's *interior* is the side behind its front face
//! (the inside of a sphere, the side from which a triangle's vertices appear clockwise), its
//! *exterior* the side its front face looks at. A ray crossing a shape whose two media differ
//! enters the medium of the side it goes to; a shape that names no media, or the same on both
//! sides, leaves the ray in the medium it was in. A shape whose material is
//! [`crate::MaterialKind::Interface`] does not scatter: it only bounds media.

use std::ops::ControlFlow;
use std::sync::Arc;

use glam::{Vec2, Vec3};

use crate::density_grid::DensityGrid;
use crate::fingerprint::{Fingerprint, Fingerprinter};
use crate::{Frame, Hit, Primitive, Rgb};

/// A medium: absorption and scattering coefficients per channel (per scene unit of length) and
/// a Henyey–Greenstein phase function of asymmetry `g`; homogeneous, or scaled at each point by
/// a density grid (σa(x) = d(x)·σa, σs(x) = d(x)·σs: the albedo is the same everywhere).
#[derive(Clone, Debug, PartialEq)]
pub struct Medium {
    /// Name in the source file (for messages).
    pub name: String,
    /// Absorption coefficient σa per channel (finite, ≥ 0).
    pub sigma_a: Rgb,
    /// Scattering coefficient σs per channel (finite, ≥ 0).
    pub sigma_s: Rgb,
    /// Henyey–Greenstein asymmetry, in (−1, 1): 0 isotropic, > 0 forward scattering.
    pub g: f32,
    /// The density grid of a heterogeneous medium, `None` for a homogeneous one. With a grid,
    /// `sigma_a` and `sigma_s` are the coefficients at density 1.
    pub density: Option<Arc<DensityGrid>>,
}

/// Where [`Medium::sample_free_flight`] ends a free flight.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FreeFlight {
    /// A real scattering event at distance `t`: the path throughput is multiplied by `weight`
    /// (which includes σs at that point) and the phase function scatters there.
    Scatter {
        /// Distance along the ray.
        t: f32,
        /// Factor of the path throughput.
        weight: Rgb,
    },
    /// The flight reaches `t_max` (the next surface, or infinity): the throughput is multiplied
    /// by `weight` (the transmittance over the probability of getting there; zero if the path
    /// died, e.g. by the iteration guard).
    Pass {
        /// Factor of the path throughput.
        weight: Rgb,
    },
}

/// The most tentative collisions one delta- or ratio-tracking walk takes; beyond it the walk
/// ends with weight zero (a guard against a majorant so large that the steps stop advancing).
const MAX_TRACKING_STEPS: u32 = 1 << 20;

/// How a tracking walk ([`track`]) ended.
enum Walk<R> {
    /// A tentative collision ended it with this.
    Ended(R),
    /// It passed `t_max`.
    Through,
    /// It took more than [`MAX_TRACKING_STEPS`] steps.
    TooLong,
}

/// The tentative collisions along `origin + t·direction`, 0 ≤ t ≤ `t_max`, in a grid: drawn from
/// exponential steps of each majorant cell's σ̄ = `peak` × its largest density (memoryless, so
/// the walk restarts at each cell's entry), numbers from `u`. `at(t, density, σ̄, u)` decides
/// each; a `Break` ends the walk.
fn track<R, U: FnMut() -> f32>(
    grid: &DensityGrid,
    origin: Vec3,
    direction: Vec3,
    t_max: f32,
    peak: f32,
    u: &mut U,
    mut at: impl FnMut(f32, f32, f32, &mut U) -> ControlFlow<R>,
) -> Walk<R> {
    let mut steps = 0;
    for segment in grid.majorant_segments(origin, direction, t_max) {
        let majorant = peak * segment.max_density;
        if majorant <= 0.0 {
            continue;
        }
        let mut t = segment.t0;
        loop {
            steps += 1;
            if steps > MAX_TRACKING_STEPS {
                return Walk::TooLong;
            }
            t -= (1.0 - u()).ln() / majorant;
            if t >= segment.t1 {
                break;
            }
            let density = grid.density(origin + direction * t);
            if let ControlFlow::Break(r) = at(t, density, majorant, u) {
                return Walk::Ended(r);
            }
        }
    }
    Walk::Through
}

impl Medium {
    /// A homogeneous medium.
    #[must_use]
    pub fn homogeneous(name: impl Into<String>, sigma_a: Rgb, sigma_s: Rgb, g: f32) -> Self {
        Self {
            name: name.into(),
            sigma_a,
            sigma_s,
            g,
            density: None,
        }
    }

    /// Whether the coefficients are the same everywhere (no density grid): then
    /// [`Medium::sigma_t`] and [`Medium::transmittance`] are exact everywhere.
    #[inline]
    #[must_use]
    pub fn is_homogeneous(&self) -> bool {
        self.density.is_none()
    }

    /// The extinction at the world point `p`: σt for a homogeneous medium, d(p)·σt with a grid.
    #[inline]
    #[must_use]
    pub fn sigma_t_at(&self, p: Vec3) -> Rgb {
        match &self.density {
            None => self.sigma_t(),
            Some(grid) => self.sigma_t() * grid.density(p),
        }
    }

    /// One majorant of the extinction of every channel everywhere: the largest channel of σt
    /// times the grid's largest density (a hair above, so that rounding in the interpolation
    /// never makes a null coefficient negative). The tracking itself uses the tighter
    /// majorants of [`DensityGrid::majorant_segments`].
    #[must_use]
    pub fn majorant(&self) -> f32 {
        let peak = self.sigma_t().max_element();
        match &self.density {
            None => peak,
            Some(grid) => peak * grid.max_density() * (1.0 + 1e-5),
        }
    }

    /// Samples where a path travelling along `origin + t·direction` in this medium first
    /// scatters before `t_max` (the next surface, ∞ for none), with `u` giving uniform numbers
    /// in [0, 1), for a path whose throughput channels are in proportions `q` (non-negative,
    /// summing to one: the channel weights of spectral MIS).
    ///
    /// - Homogeneous: chromatic free-flight sampling (two numbers): a channel c with
    ///   probability q_c, a distance from exp(−σt,c·t), weighted by the average of the
    ///   channels' densities under q (the same estimator as the path tracer's own code).
    /// - Grid: spectral tracking (Kutz et al. 2017, "Spectral and decomposition tracking for
    ///   rendering heterogeneous volumes", history-aware): tentative collisions from a scalar
    ///   majorant σ̄ per cell of the grid's majorant grid ([`DensityGrid::majorant_segments`]:
    ///   the largest channel of σt times the cell's largest density) over the stretch inside
    ///   the grid's box; at each, a real collision with probability Σq·σt(x)/σ̄ (weight
    ///   σs(x)/Σq·σt(x), Mitsuba's and pbrt's choice: absorption is a weight, not a
    ///   termination) or a null one (weight σn(x)/Σq·σn(x), σn = σ̄ − σt), q following the
    ///   weights. Unbiased in every channel; for a grey medium it is plain delta tracking with
    ///   weights σs/σt and one.
    pub fn sample_free_flight(
        &self,
        origin: Vec3,
        direction: Vec3,
        t_max: f32,
        q: Rgb,
        u: &mut impl FnMut() -> f32,
    ) -> FreeFlight {
        let sigma_t = self.sigma_t();
        let Some(grid) = &self.density else {
            let (u_channel, u_distance) = (u(), u());
            let channel = if u_channel < q.x {
                0
            } else if u_channel < q.x + q.y {
                1
            } else {
                2
            };
            let t = if sigma_t[channel] > 0.0 {
                -(1.0 - u_distance).ln() / sigma_t[channel]
            } else {
                f32::INFINITY
            };
            if t < t_max {
                let tr = self.transmittance(t);
                let pdf = (q * sigma_t * tr).element_sum();
                let weight = if pdf > 0.0 {
                    self.sigma_s * tr / pdf
                } else {
                    Rgb::ZERO
                };
                return FreeFlight::Scatter { t, weight };
            }
            let tr = self.transmittance(t_max);
            let survive = (q * tr).element_sum();
            let weight = if survive > 0.0 {
                tr / survive
            } else {
                Rgb::ZERO
            };
            return FreeFlight::Pass { weight };
        };
        // The per-cell majorant of every channel: the largest channel of σt times the cell's
        // largest density, a hair above it.
        let peak = sigma_t.max_element() * (1.0 + 1e-5);
        let mut weight = Rgb::ONE;
        let walk = track(
            grid,
            origin,
            direction,
            t_max,
            peak,
            u,
            |t, d, majorant, u| {
                let st = sigma_t * d;
                let sn = (Rgb::splat(majorant) - st).max(Rgb::ZERO);
                // The channel weights now: q scaled by what the walk has multiplied so far.
                let qw = q * weight;
                let total = qw.element_sum();
                if total.is_nan() || total <= 0.0 {
                    return ControlFlow::Break(FreeFlight::Pass { weight: Rgb::ZERO });
                }
                let qn = qw / total;
                let real = (qn * st).element_sum();
                let null = (qn * sn).element_sum();
                let p_real = real / (real + null);
                if u() < p_real {
                    return ControlFlow::Break(FreeFlight::Scatter {
                        t,
                        weight: weight * (self.sigma_s * d) / real,
                    });
                }
                weight *= sn / null;
                ControlFlow::Continue(())
            },
        );
        match walk {
            Walk::Ended(flight) => flight,
            Walk::TooLong => FreeFlight::Pass { weight: Rgb::ZERO },
            Walk::Through => FreeFlight::Pass { weight },
        }
    }

    /// The transmittance along `origin + t·direction` from 0 to `t_max` (finite): exact for a
    /// homogeneous medium (no number drawn), an unbiased estimate for a grid by ratio tracking
    /// with a scalar majorant σ̄ per majorant cell (the product of σn(x)/σ̄ over tentative
    /// collisions drawn from σ̄ inside the grid's box), so that its mean is exp(−∫σt) in every
    /// channel.
    pub fn transmittance_along(
        &self,
        origin: Vec3,
        direction: Vec3,
        t_max: f32,
        u: &mut impl FnMut() -> f32,
    ) -> Rgb {
        self.transmittance_walk(origin, direction, t_max, u, |_, _| {})
    }

    /// [`Medium::transmittance_along`], calling `visit(t, product)` at each tentative collision
    /// of a grid's ratio-tracking walk with the walk's product up to and including it: the
    /// product at the last collision before any t ≤ `t_max` is itself an unbiased estimate of
    /// the transmittance from the origin to t (the collisions before t are a walk to t), so one
    /// walk serves every point of the ray. A homogeneous medium calls nothing.
    pub fn transmittance_walk(
        &self,
        origin: Vec3,
        direction: Vec3,
        t_max: f32,
        u: &mut impl FnMut() -> f32,
        mut visit: impl FnMut(f32, Rgb),
    ) -> Rgb {
        let Some(grid) = &self.density else {
            return self.transmittance(t_max);
        };
        let sigma_t = self.sigma_t();
        let peak = sigma_t.max_element() * (1.0 + 1e-5);
        let mut tr = Rgb::ONE;
        let walk = track(
            grid,
            origin,
            direction,
            t_max,
            peak,
            u,
            |t, d, majorant, _| {
                tr *= (Rgb::ONE - sigma_t * d / majorant).max(Rgb::ZERO);
                visit(t, tr);
                if tr == Rgb::ZERO {
                    ControlFlow::Break(())
                } else {
                    ControlFlow::Continue(())
                }
            },
        );
        if matches!(walk, Walk::TooLong) {
            return Rgb::ZERO;
        }
        tr
    }

    /// The extinction coefficient σt = σa + σs (at density 1 for a grid medium).
    #[inline]
    #[must_use]
    pub fn sigma_t(&self) -> Rgb {
        self.sigma_a + self.sigma_s
    }

    /// The transmittance exp(−σt·d) per channel over a distance `d` (zero for an infinite
    /// distance in a channel that attenuates, one in a channel that does not) of a homogeneous
    /// medium; for a grid medium, of density 1 (use [`Medium::transmittance_along`]).
    #[inline]
    #[must_use]
    pub fn transmittance(&self, d: f32) -> Rgb {
        let st = self.sigma_t();
        Rgb::new(tr(st.x, d), tr(st.y, d), tr(st.z, d))
    }

    /// Its phase function.
    #[inline]
    #[must_use]
    pub fn phase(&self) -> HenyeyGreenstein {
        HenyeyGreenstein { g: self.g }
    }
}

/// exp(−σ·d), with 0·∞ taken as no attenuation.
#[inline]
fn tr(sigma: f32, d: f32) -> f32 {
    if sigma == 0.0 {
        1.0
    } else {
        (-sigma * d).exp()
    }
}

impl Fingerprint for Medium {
    /// The coefficients and `g` (not the name), and the grid if there is one (so a
    /// homogeneous medium's fingerprint is what it was before grids).
    fn fingerprint(&self, h: &mut Fingerprinter) {
        h.vec3(self.sigma_a);
        h.vec3(self.sigma_s);
        h.f32(self.g);
        if let Some(grid) = &self.density {
            h.str("grid");
            grid.fingerprint(h);
        }
    }
}

/// The primitives one [`ShapeMedia`] entry covers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MediumShape {
    /// The triangles `start..end` of [`crate::SceneDescription::triangles`]: one closed mesh.
    Triangles {
        /// First triangle.
        start: u32,
        /// One past the last triangle.
        end: u32,
    },
    /// The sphere with this index in [`crate::SceneDescription::spheres`].
    Sphere(u32),
}

/// The media on either side of a shape: indices into [`Media::list`], `None` for vacuum.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ShapeMedia {
    /// The primitives.
    pub shape: MediumShape,
    /// The medium behind the front face (inside a closed shape).
    pub interior: Option<u32>,
    /// The medium in front of the front face (outside a closed shape).
    pub exterior: Option<u32>,
}

impl ShapeMedia {
    /// Whether crossing the shape changes the medium.
    #[inline]
    #[must_use]
    pub fn is_transition(&self) -> bool {
        self.interior != self.exterior
    }
}

/// The media of a scene: the list, which shapes bound them, and the medium the camera sits in.
/// The default (no media) is a scene of scene format 1, which renders as it always has.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Media {
    /// Every medium; shapes and the camera refer to them by index.
    pub list: Vec<Medium>,
    /// The shapes that bound media. A shape not listed does not change the medium.
    pub shapes: Vec<ShapeMedia>,
    /// The medium around the camera (index into `list`), `None` for vacuum.
    pub camera: Option<u32>,
}

impl Media {
    /// Whether nothing is set (no medium, no shape media, no camera medium).
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.list.is_empty() && self.shapes.is_empty() && self.camera.is_none()
    }

    /// Whether some path can be in a medium: the camera sits in one, or a shape changes the
    /// medium. Media that nothing refers to change nothing.
    #[must_use]
    pub fn are_used(&self) -> bool {
        self.camera.is_some() || self.shapes.iter().any(ShapeMedia::is_transition)
    }
}

impl Fingerprint for Media {
    fn fingerprint(&self, h: &mut Fingerprinter) {
        h.list(&self.list);
        h.list(&self.shapes);
        h.option(self.camera, |h, c| h.u32(c));
    }
}

impl Fingerprint for ShapeMedia {
    fn fingerprint(&self, h: &mut Fingerprinter) {
        match self.shape {
            MediumShape::Triangles { start, end } => {
                h.str("triangles");
                h.u32(start);
                h.u32(end);
            }
            MediumShape::Sphere(i) => {
                h.str("sphere");
                h.u32(i);
            }
        }
        for side in [self.interior, self.exterior] {
            h.option(side, |h, m| h.u32(m));
        }
    }
}

/// Which media each primitive bounds, for lookups at a hit: built by [`crate::Scene::new`] only
/// for scenes with media.
#[derive(Clone, Debug, Default)]
pub(crate) struct MediumMap {
    /// Index into `Media::shapes` per triangle (`u32::MAX`: none).
    triangles: Vec<u32>,
    /// Index into `Media::shapes` per sphere (`u32::MAX`: none).
    spheres: Vec<u32>,
}

impl MediumMap {
    /// The map of a valid description's `media` over `triangles` triangles and `spheres`
    /// spheres (the ranges are checked by validation).
    pub(crate) fn new(media: &Media, triangles: usize, spheres: usize) -> Self {
        let mut map = Self {
            triangles: vec![u32::MAX; triangles],
            spheres: vec![u32::MAX; spheres],
        };
        for (i, entry) in media.shapes.iter().enumerate() {
            if !entry.is_transition() {
                continue;
            }
            match entry.shape {
                MediumShape::Triangles { start, end } => {
                    for t in &mut map.triangles[start as usize..end as usize] {
                        *t = i as u32;
                    }
                }
                MediumShape::Sphere(s) => map.spheres[s as usize] = i as u32,
            }
        }
        map
    }

    /// The index into `Media::shapes` of the entry that changes the medium at `primitive`.
    #[inline]
    pub(crate) fn entry(&self, primitive: Primitive) -> Option<usize> {
        let i = match primitive {
            Primitive::Triangle(i) => self.triangles.get(i as usize),
            Primitive::Sphere(i) => self.spheres.get(i as usize),
            Primitive::Cylinder(_) => None,
        };
        i.filter(|&&i| i != u32::MAX).map(|&i| i as usize)
    }
}

/// The medium a ray leaving `hit` in `direction` travels in, if the hit's shape changes the
/// medium (`entry`), else `current`.
#[inline]
#[must_use]
pub fn medium_after(
    entry: Option<&ShapeMedia>,
    hit: &Hit,
    direction: Vec3,
    current: Option<u32>,
) -> Option<u32> {
    let Some(entry) = entry else {
        return current;
    };
    // The normal of the front face: the side of the exterior.
    let front = if hit.front_face {
        hit.geometric_normal
    } else {
        -hit.geometric_normal
    };
    if direction.dot(front) > 0.0 {
        entry.exterior
    } else {
        entry.interior
    }
}

/// The Henyey–Greenstein phase function of asymmetry `g` ∈ (−1, 1).
///
/// Directions follow the BSDFs' convention: `outgoing` and `incoming` both point away from the
/// scattering point, `outgoing` back along the path being traced, `incoming` toward where light
/// comes from. Light travelling along −`incoming` and scattered into `outgoing` turns by the
/// angle θ with cos θ = −`outgoing`·`incoming`; g > 0 favours small θ (forward scattering).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HenyeyGreenstein {
    /// The asymmetry, the mean cosine of the scattering angle.
    pub g: f32,
}

/// A direction drawn by [`HenyeyGreenstein::sample`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PhaseSample {
    /// Unit direction toward where the light comes from.
    pub incoming: Vec3,
    /// The phase function's value, equal to its density (the sampling is exact).
    pub pdf: f32,
}

impl HenyeyGreenstein {
    /// The phase function for the cosine of the scattering angle θ (per steradian, integrating
    /// to one over the sphere).
    #[inline]
    #[must_use]
    pub fn of_cos(&self, cos_theta: f32) -> f32 {
        let g = self.g;
        let denom = (1.0 + g * g - 2.0 * g * cos_theta).max(1e-12);
        (1.0 - g * g) / (4.0 * std::f32::consts::PI * denom * denom.sqrt())
    }

    /// p(outgoing, incoming), which is also the density of [`HenyeyGreenstein::sample`].
    #[inline]
    #[must_use]
    pub fn eval(&self, outgoing: Vec3, incoming: Vec3) -> f32 {
        self.of_cos(-outgoing.dot(incoming))
    }

    /// The solid-angle density of drawing `incoming` from `outgoing`: [`HenyeyGreenstein::eval`].
    #[inline]
    #[must_use]
    pub fn pdf(&self, outgoing: Vec3, incoming: Vec3) -> f32 {
        self.eval(outgoing, incoming)
    }

    /// Draws `incoming` for `outgoing` with `u` ∈ [0, 1)² by inverting the distribution of
    /// cos θ (pbrt-v4's `SampleHenyeyGreenstein`); the path throughput's factor is one.
    #[must_use]
    pub fn sample(&self, outgoing: Vec3, u: Vec2) -> PhaseSample {
        let g = self.g;
        // The cosine μ of the scattering angle (between the direction light travels before,
        // −incoming, and after, outgoing), by the inverse of its distribution function.
        let mu = if g.abs() < 1e-3 {
            2.0 * u.x - 1.0
        } else {
            let s = (1.0 - g * g) / (1.0 - g + 2.0 * g * u.x);
            (1.0 + g * g - s * s) / (2.0 * g)
        }
        .clamp(-1.0, 1.0);
        let sin_theta = (1.0 - mu * mu).max(0.0).sqrt();
        let phi = std::f32::consts::TAU * u.y;
        // outgoing · incoming = −μ.
        let frame = Frame::from_normal(outgoing);
        let local = Vec3::new(sin_theta * phi.cos(), sin_theta * phi.sin(), -mu);
        PhaseSample {
            incoming: frame.to_world(local).normalize(),
            pdf: self.of_cos(mu),
        }
    }
}

#[cfg(test)]
#[path = "medium_tests.rs"]
mod tests;
