//! Primitive data in BVH order and the ray–primitive tests (in internal, scaled coordinates).

use glam::{Vec3, Vec3A};

use super::simd::F8;
use crate::{Cylinder, Sphere};

/// A ray as the primitive tests see it; the upper end of the interval is passed separately, since
/// it shrinks during a closest-hit traversal.
#[derive(Clone, Copy, Debug)]
pub(super) struct PrimRay {
    pub(super) origin: Vec3A,
    /// Unit direction.
    pub(super) direction: Vec3A,
    /// Lower end of the ray interval (0: hits at the origin count for triangles).
    pub(super) tmin: f32,
}

/// A triangle as obvhs' `RtTriangle` stores it: v0, e1 = v0 − v1, e2 = v2 − v0 (the normal
/// ng = e1 × e2 is computed where needed).
#[derive(Clone, Copy, Debug)]
pub(super) struct TriGeom {
    pub(super) v0: Vec3A,
    pub(super) e1: Vec3A,
    pub(super) e2: Vec3A,
}

impl TriGeom {
    pub(super) fn new(p: [Vec3; 3]) -> Self {
        let v0 = Vec3A::from(p[0]);
        Self {
            v0,
            e1: v0 - Vec3A::from(p[1]),
            e2: Vec3A::from(p[2]) - v0,
        }
    }

    /// Whether the triangle has a finite, non-zero normal (others never enter the BVH).
    pub(super) fn is_proper(&self) -> bool {
        let ng = self.e1.cross(self.e2);
        ng.is_finite() && ng != Vec3A::ZERO
    }
}

/// A sphere in internal (scaled) coordinates.
#[derive(Clone, Copy, Debug)]
pub(super) struct SphereGeom {
    center: Vec3A,
    radius2: f32,
}

impl SphereGeom {
    pub(super) fn new(s: &Sphere, scale: f32) -> Self {
        let radius = s.radius * scale;
        Self {
            center: Vec3A::from(s.center * scale),
            radius2: radius * radius,
        }
    }

    /// Closest root in (tmin, tmax) of |o + t·d − c|² = r² for a unit `d` (the Ray Tracing Gems
    /// ch. 7 form), or ∞.
    #[inline(always)]
    pub(super) fn intersect(&self, ray: &PrimRay, tmax: f32) -> f32 {
        let f = ray.origin - self.center;
        let b = -f.dot(ray.direction);
        let l = f + b * ray.direction;
        let disc = self.radius2 - l.length_squared();
        if disc < 0.0 {
            return f32::INFINITY;
        }
        let c = f.length_squared() - self.radius2;
        let q = b + disc.sqrt().copysign(b);
        if q == 0.0 {
            return f32::INFINITY;
        }
        let (t0, t1) = {
            let a = c / q;
            if a < q { (a, q) } else { (q, a) }
        };
        if t0 > ray.tmin && t0 < tmax {
            t0
        } else if t1 > ray.tmin && t1 < tmax {
            t1
        } else {
            f32::INFINITY
        }
    }
}

/// The ray splatted over the eight lanes of a [`TriPack`] (whose test takes `tmin` = 0, which
/// every query uses; a constant zero takes no register).
#[derive(Clone, Copy, Debug)]
pub(super) struct Ray8 {
    origin: [F8; 3],
    direction: [F8; 3],
}

impl Ray8 {
    #[inline(always)]
    pub(super) fn new(ray: &PrimRay) -> Self {
        let (o, d) = (ray.origin, ray.direction);
        Self {
            origin: [F8::splat(o.x), F8::splat(o.y), F8::splat(o.z)],
            direction: [F8::splat(d.x), F8::splat(d.y), F8::splat(d.z)],
        }
    }
}

/// The triangles of one leaf in SoA form (384 bytes), tested together: lane i holds v0, e1, e2
/// and the normal ng = e1 × e2 of a [`TriGeom`] by axis (ng computed at build time exactly as the
/// test computed it before, so the bits are the same). Lanes without a triangle have a NaN `v0`,
/// which fails every comparison of the test.
#[derive(Clone, Copy, Debug)]
pub(super) struct TriPack {
    v0: [F8; 3],
    e1: [F8; 3],
    e2: [F8; 3],
    ng: [F8; 3],
}

/// A [`TriPack`] under construction: rows of lanes as arrays.
#[derive(Clone, Copy, Debug)]
pub(super) struct TriPackBuilder {
    v0: [[f32; 8]; 3],
    e1: [[f32; 8]; 3],
    e2: [[f32; 8]; 3],
    ng: [[f32; 8]; 3],
}

impl TriPackBuilder {
    /// A pack with no triangle.
    pub(super) const EMPTY: Self = Self {
        v0: [[f32::NAN; 8]; 3],
        e1: [[0.0; 8]; 3],
        e2: [[0.0; 8]; 3],
        ng: [[0.0; 8]; 3],
    };

    /// Puts the triangle `g` into `lane`.
    pub(super) fn set(&mut self, lane: usize, g: &TriGeom) {
        // The same products and differences, in the same order, as `TriPack::intersect` used to
        // compute per ray (`ay·bz − az·by`, …): scalar IEEE arithmetic gives the lanes' bits.
        let (a, b) = (g.e1, g.e2);
        let ng = [
            a.y * b.z - a.z * b.y,
            a.z * b.x - a.x * b.z,
            a.x * b.y - a.y * b.x,
        ];
        for (axis, n) in ng.into_iter().enumerate() {
            self.v0[axis][lane] = g.v0[axis];
            self.e1[axis][lane] = g.e1[axis];
            self.e2[axis][lane] = g.e2[axis];
            self.ng[axis][lane] = n;
        }
    }

    pub(super) fn build(&self) -> TriPack {
        TriPack {
            v0: self.v0.map(F8::from_array),
            e1: self.e1.map(F8::from_array),
            e2: self.e2.map(F8::from_array),
            ng: self.ng.map(F8::from_array),
        }
    }
}

impl TriPack {
    /// Möller–Trumbore in the form of obvhs' `RtTriangle::intersect` (with the stored
    /// ng = e1 × e2), with inclusive edges, on eight triangles at once: the lanes hit with t in
    /// [0, tmax) (a comparison result), and t per lane (meaningful only in those lanes).
    ///
    /// Also returns the barycentrics u (of v1) and v (of v2) per lane. A closest-hit query reports
    /// those of the hit lane rather than recomputing them for the one triangle, which would cost
    /// instructions and could give numbers that differ by rounding from the ones the inside test
    /// accepted (glam's `cross` uses FMA where the CPU has it).
    #[inline(always)]
    pub(super) fn intersect(&self, ray: &Ray8, tmax: f32) -> (F8, F8, F8, F8) {
        let [ox, oy, oz] = ray.origin;
        let [dx, dy, dz] = ray.direction;
        let [ax, ay, az] = self.e1;
        let [bx, by, bz] = self.e2;
        let [nx, ny, nz] = self.ng;
        let (cx, cy, cz) = (self.v0[0].sub(ox), self.v0[1].sub(oy), self.v0[2].sub(oz));
        // r = d × c.
        let cross = |a1: F8, b1: F8, a2: F8, b2: F8| a1.mul(b1).sub(a2.mul(b2));
        let (rx, ry, rz) = (
            cross(dy, cz, dz, cy),
            cross(dz, cx, dx, cz),
            cross(dx, cy, dy, cx),
        );
        let dot = |x: F8, y: F8, z: F8, a: F8, b: F8, c: F8| x.mul(a).add(y.mul(b)).add(z.mul(c));
        let one = F8::splat(1.0);
        let zero = F8::splat(0.0);
        let inv_det = one.div(dot(nx, ny, nz, dx, dy, dz));
        let u = dot(rx, ry, rz, bx, by, bz).mul(inv_det);
        let v = dot(rx, ry, rz, ax, ay, az).mul(inv_det);
        let w = one.sub(u).sub(v);
        let t = dot(nx, ny, nz, cx, cy, cz).mul(inv_det);
        // t = 0 counts: spawned origins sit strictly off their own surface, but may lie
        // exactly on an adjacent wall at a corner, and must not slip through it. A non-finite
        // inv_det (det = ±0 or tiny) needs no test of its own: u and v are then ±∞ or NaN, both
        // pass 0 ≤ u, v only as +∞, and then w = 1 − ∞ − ∞ = −∞ fails.
        //
        // 0 ≤ u, v, w as 0 ≤ min(min(u, v), w), which is the same test: `min` returns its second
        // operand when either is NaN, and w = 1 − u − v is NaN whenever u or v is, so a NaN
        // among the three reaches the comparison; without NaN, the minimum of the three is ≥ 0
        // exactly when all are (a ±0 minimum passes, as ±0 would).
        let hit = zero
            .le(u.min(v).min(w))
            .and(zero.le(t))
            .and(t.lt(F8::splat(tmax)));
        (hit, t, u, v)
    }
}

/// A cylinder in internal (scaled) coordinates.
#[derive(Clone, Copy, Debug)]
pub(super) struct CylGeom {
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
    pub(super) fn new(c: &Cylinder, scale: f32) -> Self {
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
    pub(super) fn intersect(&self, ray: &PrimRay, tmax: f32) -> f32 {
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
            if !(t > ray.tmin && t < tmax) {
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
