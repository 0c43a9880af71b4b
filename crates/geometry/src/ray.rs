//! Rays, surface hits and robust secondary-ray spawning.

use glam::{Vec2, Vec3};

/// Relative amount by which [`Hit::spawn_ray_to`] stops short of its target.
const SHADOW_EPSILON: f32 = 1e-4;

/// A ray `origin + t·direction` for `t` in `[0, t_max)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    /// Start point.
    pub origin: Vec3,
    /// Unit direction. Components equal to `-0.0` are accepted (queries sanitise them).
    pub direction: Vec3,
    /// Largest parameter considered; `f32::INFINITY` for an unbounded ray.
    pub t_max: f32,
}

impl Ray {
    /// A ray with a normalised `direction` whose `-0.0` components are turned into `+0.0`
    /// (kept from when obvhs' CwBvh traversal, which misses hits for `-0.0` components, gotcha
    /// G1 in crates.md, ran the queries; our own traversal in `bvh/wide.rs` handles both).
    ///
    /// A zero or non-finite `direction` yields a non-finite direction, and queries then report no hit.
    #[inline]
    pub fn new(origin: Vec3, direction: Vec3, t_max: f32) -> Self {
        Self {
            origin,
            direction: direction.normalize() + Vec3::ZERO,
            t_max,
        }
    }

    /// An unbounded ray (`t_max = ∞`); see [`Ray::new`].
    #[inline]
    pub fn infinite(origin: Vec3, direction: Vec3) -> Self {
        Self::new(origin, direction, f32::INFINITY)
    }

    /// The point at parameter `t`.
    #[inline]
    pub fn at(&self, t: f32) -> Vec3 {
        self.origin + t * self.direction
    }
}

/// Which primitive of the [`crate::SceneDescription`] a ray hit.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Primitive {
    /// Index into [`crate::SceneDescription::triangles`].
    Triangle(u32),
    /// Index into [`crate::SceneDescription::spheres`].
    Sphere(u32),
    /// Index into [`crate::SceneDescription::cylinders`].
    Cylinder(u32),
}

/// The closest intersection of a ray with the scene.
///
/// Normal convention: `geometric_normal` and `shading_normal` are unit vectors on the side the ray
/// came from (`geometric_normal · ray.direction ≤ 0`), which suits two-sided scattering.
/// `front_face` says whether that side is the primitive's front: the counter-clockwise side of a
/// triangle, the outside of a sphere or cylinder. Emission and the dielectric's inside/outside follow `front_face`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Ray parameter of the hit (the distance, since ray directions are unit).
    pub t: f32,
    /// World-space hit point (recomputed from barycentrics or reprojected onto the sphere).
    pub position: Vec3,
    /// Conservative per-axis bound on the floating-point error of `position`.
    pub position_error: Vec3,
    /// Unit geometric normal facing the side the ray came from.
    pub geometric_normal: Vec3,
    /// Unit shading normal (interpolated vertex normals if present, else the geometric normal),
    /// flipped onto the same side as `geometric_normal`.
    pub shading_normal: Vec3,
    /// Whether the ray hit the front face (counter-clockwise side of a triangle, outside of a sphere
    /// or cylinder).
    pub front_face: bool,
    /// Index into [`crate::SceneDescription::materials`].
    pub material: u32,
    /// Signed mean curvature seen from the side the ray came from, following frequency-algebra §3:
    /// positive when the centre of curvature lies on the ray's side (concave, focusing).
    /// A sphere is exactly −1/R from outside and +1/R from inside; a cylinder reports its mean
    /// curvature, −1/(2R) from outside and +1/(2R) from inside (its curvature around the axis,
    /// the one that focuses in a plane across the axis, is twice that); a mesh triangle gets the mean
    /// over its edges of −Δn·Δp/|Δp|² from its vertex normals; flat or normal-less triangles give 0.
    pub curvature: f32,
    /// The primitive that was hit.
    pub primitive: Primitive,
    /// Triangle barycentrics (b1, b2) of the hit (b0 = 1 − b1 − b2); for spheres (φ/2π, θ/π) about +z;
    /// for cylinders (position across the kept arc from 0 to 1, counter-clockwise about the axis;
    /// height / `height`).
    pub uv: Vec2,
}

impl Hit {
    /// A ray leaving the surface in `direction`, its origin pushed off the surface just far enough to
    /// the side of `direction` that it cannot hit this surface again at t ≈ 0 (pbrt-v4 `OffsetRayOrigin`).
    #[inline]
    pub fn spawn_ray(&self, direction: Vec3) -> Ray {
        Ray::infinite(self.offset_origin(direction), direction)
    }

    /// A shadow ray toward `target` that stops just short of it, so that a surface at `target` itself
    /// does not count as an occluder: short by a relative 10⁻⁴ of the distance, and at least by a
    /// bound on the rounding error of a surface point computed at `target` (32 ε·max|targetᵢ|).
    #[inline]
    pub fn spawn_ray_to(&self, target: Vec3) -> Ray {
        let origin = self.offset_origin(target - self.position);
        let d = target - origin;
        let distance = d.length();
        let short =
            (SHADOW_EPSILON * distance).max(32.0 * f32::EPSILON * target.abs().max_element());
        Ray::new(origin, d, (distance - short).max(0.0))
    }

    /// The hit point pushed along the geometric normal to the side of `direction`, by the projected
    /// error bound, then rounded away from the surface by one ulp per axis.
    #[inline]
    pub fn offset_origin(&self, direction: Vec3) -> Vec3 {
        offset_ray_origin(
            self.position,
            self.position_error,
            self.geometric_normal,
            direction,
        )
    }
}

/// pbrt-v4's `OffsetRayOrigin`: moves `p` along `n` (to the side of `w`) by `|n|·error`, then one ulp further away.
#[inline(always)]
pub(crate) fn offset_ray_origin(p: Vec3, error: Vec3, n: Vec3, w: Vec3) -> Vec3 {
    // A floor on the offset: exact coordinates have zero error, but the origin must still leave the
    // plane strictly (triangle queries accept t = 0).
    let d = n
        .abs()
        .dot(error)
        .max(f32::EPSILON * p.abs().max_element())
        .max(1e-20);
    let mut offset = d * n;
    if w.dot(n) < 0.0 {
        offset = -offset;
    }
    let po = p + offset;
    let round = |v: f32, o: f32| {
        if o > 0.0 {
            v.next_up()
        } else if o < 0.0 {
            v.next_down()
        } else {
            v
        }
    };
    Vec3::new(
        round(po.x, offset.x),
        round(po.y, offset.y),
        round(po.z, offset.z),
    )
}
