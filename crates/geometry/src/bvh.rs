//! The one obvhs CwBvh over triangles and analytic spheres. obvhs types never leave this module.

use std::time::Duration;

use glam::{Vec3, Vec3A};
use obvhs::{
    BvhBuildParams,
    aabb::Aabb as BvhAabb,
    cwbvh::{CwBvh, builder::build_cwbvh},
    ray::{Ray as BvhRay, RayHit},
};

use crate::{Ray, Sphere, Triangle};

/// obvhs' CwBvh skips child boxes that the ray leaves before this distance (`EPSILON` in
/// `cwbvh/node.rs`); see [`Accel::near_ray`].
const CWBVH_CULL: f32 = 1e-4;

/// Marks sphere ids in [`Accel::ids`]; the low bits hold the sphere index.
const SPHERE_BIT: u32 = 1 << 31;

/// A primitive in BVH order, laid out for fast intersection (64 bytes).
///
/// Triangles use the layout of obvhs' `RtTriangle` (e1 = v0 − v1, e2 = v2 − v0, ng = e1 × e2).
/// Spheres are tagged by `ng == 0` (degenerate triangles never enter the BVH):
/// `v0` is the centre, `e1.x` the radius and `e1.y` its square.
#[derive(Clone, Copy, Debug)]
struct PrimGeom {
    v0: Vec3A,
    e1: Vec3A,
    e2: Vec3A,
    ng: Vec3A,
}

impl PrimGeom {
    fn triangle(p: [Vec3; 3]) -> Self {
        let v0 = Vec3A::from(p[0]);
        let e1 = v0 - Vec3A::from(p[1]);
        let e2 = Vec3A::from(p[2]) - v0;
        Self {
            v0,
            e1,
            e2,
            ng: e1.cross(e2),
        }
    }

    fn sphere(s: &Sphere) -> Self {
        Self {
            v0: Vec3A::from(s.center),
            e1: Vec3A::new(s.radius, s.radius * s.radius, 0.0),
            e2: Vec3A::ZERO,
            ng: Vec3A::ZERO,
        }
    }

    #[inline(always)]
    fn is_sphere(&self) -> bool {
        self.ng.cmpeq(Vec3A::ZERO).all()
    }

    /// Ray parameter of the closest intersection in [tmin, tmax) (triangles) or (tmin, tmax) (spheres), or ∞.
    #[inline(always)]
    fn intersect(&self, ray: &BvhRay) -> f32 {
        if self.is_sphere() {
            intersect_sphere(self.v0, self.e1.y, ray)
        } else {
            self.intersect_triangle(ray)
        }
    }

    /// Möller–Trumbore in the form of obvhs' `RtTriangle::intersect`, with inclusive edges.
    #[inline(always)]
    fn intersect_triangle(&self, ray: &BvhRay) -> f32 {
        let c = self.v0 - ray.origin;
        let r = ray.direction.cross(c);
        let inv_det = 1.0 / self.ng.dot(ray.direction);
        let u = r.dot(self.e2) * inv_det;
        let v = r.dot(self.e1) * inv_det;
        let w = 1.0 - u - v;
        if u >= 0.0 && v >= 0.0 && w >= 0.0 && inv_det.is_finite() {
            let t = self.ng.dot(c) * inv_det;
            // t = tmin counts: spawned origins sit strictly off their own surface, but may lie
            // exactly on an adjacent wall at a corner, and must not slip through it.
            if t >= ray.tmin && t < ray.tmax {
                return t;
            }
        }
        f32::INFINITY
    }

    /// Barycentrics (weight of v1, weight of v2) of the ray's hit with the triangle's plane.
    fn barycentrics(&self, origin: Vec3A, direction: Vec3A) -> (f32, f32) {
        let c = self.v0 - origin;
        let r = direction.cross(c);
        let inv_det = 1.0 / self.ng.dot(direction);
        (r.dot(self.e2) * inv_det, r.dot(self.e1) * inv_det)
    }
}

/// Closest root in (tmin, tmax) of |o + t·d − c|² = r² for a unit `d` (the Ray Tracing Gems ch. 7 form).
#[inline(always)]
fn intersect_sphere(center: Vec3A, radius2: f32, ray: &BvhRay) -> f32 {
    let f = ray.origin - center;
    let b = -f.dot(ray.direction);
    let l = f + b * ray.direction;
    let disc = radius2 - l.length_squared();
    if disc < 0.0 {
        return f32::INFINITY;
    }
    let c = f.length_squared() - radius2;
    let q = b + disc.sqrt().copysign(b);
    if q == 0.0 {
        return f32::INFINITY;
    }
    let (t0, t1) = {
        let a = c / q;
        if a < q { (a, q) } else { (q, a) }
    };
    if t0 > ray.tmin && t0 < ray.tmax {
        t0
    } else if t1 > ray.tmin && t1 < ray.tmax {
        t1
    } else {
        f32::INFINITY
    }
}

/// What a closest-hit query found, in terms of the scene description.
#[derive(Clone, Copy, Debug)]
pub(crate) enum RawHit {
    /// A triangle with the barycentric weights of v1 and v2.
    Triangle {
        index: u32,
        t: f32,
        b1: f32,
        b2: f32,
    },
    /// A sphere.
    Sphere { index: u32, t: f32 },
}

/// The acceleration structure.
#[derive(Clone, Debug)]
pub(crate) struct Accel {
    /// `None` when the scene has no primitive.
    bvh: Option<CwBvh>,
    /// Primitives in BVH order.
    prims: Vec<PrimGeom>,
    /// BVH order → triangle index, or `SPHERE_BIT | sphere index`.
    ids: Vec<u32>,
}

impl Accel {
    /// Builds the BVH over every non-degenerate triangle and every sphere.
    pub(crate) fn build(triangles: &[Triangle], spheres: &[Sphere]) -> Self {
        let mut prims = Vec::with_capacity(triangles.len() + spheres.len());
        let mut ids = Vec::with_capacity(triangles.len() + spheres.len());
        let mut aabbs = Vec::with_capacity(triangles.len() + spheres.len());
        for (i, tri) in triangles.iter().enumerate() {
            let g = PrimGeom::triangle(tri.positions);
            if g.is_sphere() || !g.ng.is_finite() {
                continue;
            }
            let p = tri.positions.map(Vec3A::from);
            aabbs.push(BvhAabb::new(
                p[0].min(p[1]).min(p[2]),
                p[0].max(p[1]).max(p[2]),
            ));
            prims.push(g);
            ids.push(i as u32);
        }
        for (i, s) in spheres.iter().enumerate() {
            let c = Vec3A::from(s.center);
            let r = Vec3A::splat(s.radius);
            aabbs.push(BvhAabb::new(c - r, c + r));
            prims.push(PrimGeom::sphere(s));
            ids.push(i as u32 | SPHERE_BIT);
        }
        if prims.is_empty() {
            return Self {
                bvh: None,
                prims,
                ids,
            };
        }
        let bvh = build_cwbvh(
            &aabbs,
            BvhBuildParams::medium_build(),
            &mut Duration::ZERO.clone(),
        );
        // Reorder the primitives into BVH order (crates.md G2) so that leaf ids index them directly.
        let prims = bvh
            .primitive_indices
            .iter()
            .map(|&i| prims[i as usize])
            .collect();
        let ids = bvh
            .primitive_indices
            .iter()
            .map(|&i| ids[i as usize])
            .collect();
        Self {
            bvh: Some(bvh),
            prims,
            ids,
        }
    }

    /// The ray for obvhs (`-0.0` direction components become +0.0, crates.md G1).
    #[inline(always)]
    fn bvh_ray(ray: &Ray) -> BvhRay {
        let direction = Vec3A::from(ray.direction) + Vec3A::ZERO;
        BvhRay::new(Vec3A::from(ray.origin), direction, 0.0, ray.t_max)
    }

    /// The ray for the near query, its origin moved back by `shift` > [`CWBVH_CULL`] along the
    /// direction, covering t ∈ [0, min(`CWBVH_CULL`, t_max)) as t′ ∈ [shift, …); and the shift as rounded.
    ///
    /// obvhs' CwBvh culls every child box whose exit distance is below `EPSILON = 1e-4` (absolute,
    /// in `cwbvh/node.rs`), so the main query misses hits closer than that when their (flat) leaf box
    /// ends within 1e-4: a ray spawned next to a corner would slip through the adjacent wall.
    /// From the moved origin those hits lie beyond the culled range. Node and primitive tests see the
    /// same (rounded) ray, so they agree; the rounding costs an error of about an ulp of the coordinates
    /// divided by the sine of the hit angle in the returned t, which only the near query pays.
    #[inline(always)]
    fn near_ray(ray: &BvhRay, t_max: f32) -> (BvhRay, f32) {
        let shift = 2.0 * CWBVH_CULL + 16.0 * f32::EPSILON * ray.origin.abs().max_element();
        let moved = ray.origin - shift * ray.direction;
        // The shift actually applied, after rounding of the moved origin.
        let shift = (ray.origin - moved).dot(ray.direction);
        let t_max = t_max.min(1.01 * CWBVH_CULL);
        (
            BvhRay::new(moved, ray.direction, shift, t_max + shift),
            shift,
        )
    }

    /// The closest hit with 0 ≤ t < `ray.t_max` (t > 0 for spheres).
    #[inline]
    pub(crate) fn intersect(&self, ray: &Ray) -> Option<RawHit> {
        let bvh = self.bvh.as_ref()?;
        if !(ray.direction.is_finite() && ray.origin.is_finite()) {
            return None;
        }
        let bray = Self::bvh_ray(ray);
        let prims = &self.prims;
        let mut hit = RayHit::none();
        let mut t = f32::INFINITY;
        let mut hit_ray = bray;
        if bvh.ray_traverse(bray, &mut hit, |r, id| prims[id].intersect(r)) {
            t = hit.t;
        }
        if t >= CWBVH_CULL {
            // Look for hits the main query culled.
            let (near, shift) = Self::near_ray(&bray, ray.t_max);
            let mut near_hit = RayHit::none();
            if bvh.ray_traverse(near, &mut near_hit, |r, id| prims[id].intersect(r)) {
                hit = near_hit;
                t = (near_hit.t - shift).max(0.0);
                hit_ray = near;
            }
        }
        if !t.is_finite() {
            return None;
        }
        let slot = hit.primitive_id as usize;
        let id = self.ids[slot];
        if id & SPHERE_BIT != 0 {
            Some(RawHit::Sphere {
                index: id & !SPHERE_BIT,
                t,
            })
        } else {
            let (b1, b2) = prims[slot].barycentrics(hit_ray.origin, hit_ray.direction);
            Some(RawHit::Triangle {
                index: id,
                t,
                b1,
                b2,
            })
        }
    }

    /// Whether anything is hit with 0 ≤ t < `ray.t_max` (t > 0 for spheres).
    #[inline]
    pub(crate) fn occluded(&self, ray: &Ray) -> bool {
        let Some(bvh) = self.bvh.as_ref() else {
            return false;
        };
        if !(ray.direction.is_finite() && ray.origin.is_finite()) {
            return false;
        }
        let bray = Self::bvh_ray(ray);
        let prims = &self.prims;
        if !bvh.ray_traverse_miss(bray, |r, id| prims[id].intersect(r)) {
            return true;
        }
        let (near, _) = Self::near_ray(&bray, ray.t_max);
        !bvh.ray_traverse_miss(near, |r, id| prims[id].intersect(r))
    }

    /// Number of primitives in the BVH.
    pub(crate) fn len(&self) -> usize {
        self.prims.len()
    }
}
