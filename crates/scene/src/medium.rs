//! Participating media: homogeneous media as a scene describes them ([`Medium`]), which media lie
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

use glam::{Vec2, Vec3};

use crate::fingerprint::{Fingerprint, Fingerprinter};
use crate::{Frame, Hit, Primitive, Rgb};

/// A homogeneous medium: absorption and scattering coefficients per channel (per scene unit of
/// length) and a Henyey–Greenstein phase function of asymmetry `g`.
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
}

impl Medium {
    /// The extinction coefficient σt = σa + σs.
    #[inline]
    #[must_use]
    pub fn sigma_t(&self) -> Rgb {
        self.sigma_a + self.sigma_s
    }

    /// The transmittance exp(−σt·d) per channel over a distance `d` (zero for an infinite
    /// distance in a channel that attenuates, one in a channel that does not).
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
    /// The coefficients and `g` (not the name).
    fn fingerprint(&self, h: &mut Fingerprinter) {
        h.vec3(self.sigma_a);
        h.vec3(self.sigma_s);
        h.f32(self.g);
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
