//! The one obvhs CwBvh over triangles, analytic spheres and analytic cylinders. obvhs types never
//! leave this module.

use std::time::Duration;

use glam::{Vec3, Vec3A};
use obvhs::{
    BvhBuildParams,
    aabb::Aabb as BvhAabb,
    cwbvh::{CwBvh, builder::build_cwbvh},
    ray::{Ray as BvhRay, RayHit},
};

use crate::{Cylinder, Ray, Sphere, Triangle};

/// Padding of every primitive's box, in internal units.
///
/// obvhs' CwBvh skips child boxes that the ray leaves before t = 1e-4 (`EPSILON`, absolute, in
/// `cwbvh/node.rs`), so a hit closer than that would be missed when its (flat) box ends there:
/// a ray spawned next to a corner would slip through the adjacent wall. Boxes padded by more than
/// 1e-4 are left at least 1e-4 after any hit inside them, so nothing is culled that can be hit at
/// t ≥ 0. The scene is scaled (exactly, by a power of two) to coordinates of about 2¹⁰ internally,
/// which makes the padding negligible (≈ 10⁻⁷ of the scene) at any scene scale.
const CWBVH_PAD: f32 = 2e-4;

/// The power of two that brings the largest coordinate magnitude of the scene to [2⁹, 2¹⁰).
fn internal_scale(triangles: &[Triangle], spheres: &[Sphere], cylinders: &[Cylinder]) -> f32 {
    let mut max = 0.0f32;
    for t in triangles {
        for p in t.positions {
            max = max.max(p.abs().max_element());
        }
    }
    for s in spheres {
        max = max.max(s.center.abs().max_element() + s.radius);
    }
    for c in cylinders {
        let b = c.bounds();
        max = max.max(b.min.abs().max(b.max.abs()).max_element());
    }
    if !(max.is_finite() && max > 0.0) {
        return 1.0;
    }
    let k = (10 - max.log2().ceil() as i32).clamp(-100, 100);
    2f32.powi(k)
}

/// Marks sphere ids in [`Accel::ids`]; the low bits hold the sphere index.
const SPHERE_BIT: u32 = 1 << 31;

/// Marks cylinder ids in [`Accel::ids`]; the low bits hold the cylinder index. Triangle indices
/// therefore stay below 2³⁰.
const CYLINDER_BIT: u32 = 1 << 30;

/// A primitive in BVH order, laid out for fast intersection (64 bytes).
///
/// Triangles use the layout of obvhs' `RtTriangle` (e1 = v0 − v1, e2 = v2 − v0, ng = e1 × e2).
/// Spheres are tagged by `ng == 0` (degenerate triangles never enter the BVH):
/// `v0` is the centre, `e1.x` the radius and `e1.y` its square. Cylinders are tagged by a NaN
/// `ng.x` (triangles with a non-finite normal never enter the BVH either); their data lives in
/// [`Accel::cylinders`], found through [`Accel::ids`].
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

    /// The tag of a cylinder (see the type's documentation).
    fn cylinder() -> Self {
        Self {
            v0: Vec3A::ZERO,
            e1: Vec3A::ZERO,
            e2: Vec3A::ZERO,
            ng: Vec3A::new(f32::NAN, 0.0, 0.0),
        }
    }

    #[inline(always)]
    fn is_sphere(&self) -> bool {
        self.ng.cmpeq(Vec3A::ZERO).all()
    }

    #[inline(always)]
    fn is_cylinder(&self) -> bool {
        self.ng.x.is_nan()
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

/// A cylinder in internal (scaled) coordinates.
#[derive(Clone, Copy, Debug)]
struct CylGeom {
    /// Centre of the bottom circle.
    center: Vec3A,
    /// Unit axis.
    axis: Vec3A,
    /// Unit vector perpendicular to the axis on which the kept arc is centred.
    facing: Vec3A,
    radius: f32,
    height: f32,
    /// cos(arc / 2); below −1 for a whole circle.
    cos_half_arc: f32,
}

impl CylGeom {
    fn new(c: &Cylinder, scale: f32) -> Self {
        Self {
            center: Vec3A::from(c.center * scale),
            axis: Vec3A::from(c.axis),
            facing: Vec3A::from(c.facing),
            radius: c.radius * scale,
            height: c.height * scale,
            cos_half_arc: if c.arc >= std::f32::consts::TAU {
                -2.0
            } else {
                (0.5 * c.arc).cos()
            },
        }
    }

    /// Closest root in (tmin, tmax) of the open cylinder that lies within its height and arc, or ∞.
    ///
    /// With f = o − c split into f⊥ + fₐ·a (and likewise d), the roots of |f⊥ + t·d⊥|² = r² are
    /// t = (b ± √disc)/A with A = |d⊥|², b = −f⊥·d⊥ and disc = A·(r² − |l|²), l = f⊥ + (b/A)·d⊥
    /// the point of closest approach to the axis (the stable form of the sphere's test); both roots
    /// are tried, nearer first, against the height and arc ranges.
    #[inline(always)]
    fn intersect(&self, ray: &BvhRay) -> f32 {
        let a = self.axis;
        let f = ray.origin - self.center;
        let d = ray.direction;
        let fa = f.dot(a);
        let da = d.dot(a);
        let fp = f - fa * a;
        let dp = d - da * a;
        let aa = dp.length_squared();
        if aa.is_nan() || aa <= 0.0 {
            // Parallel to the axis: an open cylinder is never crossed.
            return f32::INFINITY;
        }
        let r2 = self.radius * self.radius;
        let b = -fp.dot(dp);
        let l = fp + (b / aa) * dp;
        let disc = aa * (r2 - l.length_squared());
        if disc.is_nan() || disc < 0.0 {
            return f32::INFINITY;
        }
        let c = fp.length_squared() - r2;
        let q = b + disc.sqrt().copysign(b);
        if q == 0.0 {
            return f32::INFINITY;
        }
        let (t0, t1) = {
            let x = c / q;
            let y = q / aa;
            if x < y { (x, y) } else { (y, x) }
        };
        for t in [t0, t1] {
            if !(t > ray.tmin && t < ray.tmax) {
                continue;
            }
            let s = fa + t * da;
            if !(s >= 0.0 && s <= self.height) {
                continue;
            }
            if self.cos_half_arc >= -1.0 {
                let radial = fp + t * dp;
                if radial.dot(self.facing) < self.cos_half_arc * radial.length() {
                    continue;
                }
            }
            return t;
        }
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
    /// A cylinder.
    Cylinder { index: u32, t: f32 },
}

/// The acceleration structure.
#[derive(Clone, Debug)]
pub(crate) struct Accel {
    /// `None` when the scene has no primitive.
    bvh: Option<CwBvh>,
    /// Primitives in BVH order.
    prims: Vec<PrimGeom>,
    /// BVH order → triangle index, `SPHERE_BIT | sphere index` or `CYLINDER_BIT | cylinder index`.
    ids: Vec<u32>,
    /// Cylinders in description order, in internal coordinates.
    cylinders: Vec<CylGeom>,
    /// Power of two by which world coordinates are multiplied (exactly) to get internal ones.
    scale: f32,
}

impl Accel {
    /// Builds the BVH over every non-degenerate triangle, every sphere and every cylinder.
    pub(crate) fn build(
        triangles: &[Triangle],
        spheres: &[Sphere],
        cylinders: &[Cylinder],
    ) -> Self {
        let scale = internal_scale(triangles, spheres, cylinders);
        let n = triangles.len() + spheres.len() + cylinders.len();
        let mut prims = Vec::with_capacity(n);
        let mut ids = Vec::with_capacity(n);
        let mut aabbs = Vec::with_capacity(n);
        let padded = |lo: Vec3A, hi: Vec3A| {
            let pad = CWBVH_PAD + 4.0 * f32::EPSILON * lo.abs().max(hi.abs()).max_element();
            BvhAabb::new(lo - Vec3A::splat(pad), hi + Vec3A::splat(pad))
        };
        for (i, tri) in triangles.iter().enumerate() {
            let p = tri.positions.map(|v| v * scale);
            let g = PrimGeom::triangle(p);
            if g.is_sphere() || !g.ng.is_finite() {
                continue;
            }
            let p = p.map(Vec3A::from);
            aabbs.push(padded(p[0].min(p[1]).min(p[2]), p[0].max(p[1]).max(p[2])));
            prims.push(g);
            ids.push(i as u32);
        }
        for (i, s) in spheres.iter().enumerate() {
            let s = Sphere {
                center: s.center * scale,
                radius: s.radius * scale,
                material: s.material,
            };
            let c = Vec3A::from(s.center);
            let r = Vec3A::splat(s.radius);
            aabbs.push(padded(c - r, c + r));
            prims.push(PrimGeom::sphere(&s));
            ids.push(i as u32 | SPHERE_BIT);
        }
        let cylinder_geoms: Vec<CylGeom> =
            cylinders.iter().map(|c| CylGeom::new(c, scale)).collect();
        for (i, c) in cylinders.iter().enumerate() {
            let b = c.bounds();
            aabbs.push(padded(
                Vec3A::from(b.min * scale),
                Vec3A::from(b.max * scale),
            ));
            prims.push(PrimGeom::cylinder());
            ids.push(i as u32 | CYLINDER_BIT);
        }
        if prims.is_empty() {
            return Self {
                bvh: None,
                prims,
                ids,
                cylinders: cylinder_geoms,
                scale,
            };
        }
        let mut build_time = Duration::ZERO;
        let bvh = build_cwbvh(&aabbs, BvhBuildParams::medium_build(), &mut build_time);
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
            cylinders: cylinder_geoms,
            scale,
        }
    }

    /// Ray parameter of the closest intersection with the primitive in BVH slot `slot`, in
    /// [tmin, tmax) (triangles) or (tmin, tmax) (spheres, cylinders), or ∞.
    #[inline(always)]
    fn intersect_prim(&self, ray: &BvhRay, slot: usize) -> f32 {
        let p = &self.prims[slot];
        if p.is_sphere() {
            intersect_sphere(p.v0, p.e1.y, ray)
        } else if p.is_cylinder() {
            let index = (self.ids[slot] & !CYLINDER_BIT) as usize;
            self.cylinders[index].intersect(ray)
        } else {
            p.intersect_triangle(ray)
        }
    }

    /// The ray for obvhs, in the internal (scaled) space. `-0.0` direction components become +0.0
    /// (crates.md G1).
    #[inline(always)]
    fn bvh_ray(&self, ray: &Ray) -> BvhRay {
        let direction = Vec3A::from(ray.direction) + Vec3A::ZERO;
        BvhRay::new(
            Vec3A::from(ray.origin * self.scale),
            direction,
            0.0,
            ray.t_max * self.scale,
        )
    }

    /// The closest hit with 0 ≤ t < `ray.t_max` (t > 0 for spheres).
    #[inline]
    pub(crate) fn intersect(&self, ray: &Ray) -> Option<RawHit> {
        let bvh = self.bvh.as_ref()?;
        if !(ray.direction.is_finite() && ray.origin.is_finite()) {
            return None;
        }
        let bray = self.bvh_ray(ray);
        let mut hit = RayHit::none();
        if !bvh.ray_traverse(bray, &mut hit, |r, id| self.intersect_prim(r, id)) {
            return None;
        }
        let t = hit.t / self.scale;
        let slot = hit.primitive_id as usize;
        let id = self.ids[slot];
        if id & SPHERE_BIT != 0 {
            Some(RawHit::Sphere {
                index: id & !SPHERE_BIT,
                t,
            })
        } else if id & CYLINDER_BIT != 0 {
            Some(RawHit::Cylinder {
                index: id & !CYLINDER_BIT,
                t,
            })
        } else {
            let (b1, b2) = self.prims[slot].barycentrics(bray.origin, bray.direction);
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
        !bvh.ray_traverse_miss(self.bvh_ray(ray), |r, id| self.intersect_prim(r, id))
    }

    /// Number of primitives in the BVH.
    pub(crate) fn len(&self) -> usize {
        self.prims.len()
    }
}
