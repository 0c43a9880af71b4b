//! The scene's BVH over triangles, analytic spheres and analytic cylinders.
//!
//! obvhs builds a binary BVH (`Bvh2`: PLOC, a little reinsertion, SAH leaf collapse to at most
//! eight primitives), which is collapsed into our own CPU layout (`wide.rs`): 8-wide nodes whose
//! child boxes are stored in SoA rows of eight lanes and tested together with one AVX operation
//! per step (`simd.rs`), nearest child first; each leaf's triangles are tested together too, as
//! one SoA pack of eight lanes (`prim::TriPack`), and its spheres and cylinders one by one.
//! obvhs types never leave this module.
//!
//! Why a layout of our own: obvhs' `CwBvh` is a GPU layout whose compressed nodes are decoded
//! per node on the CPU; this one is tested as it is stored. docs/notes/bvh-traversal.md
//! has the measurements behind each choice, and what did not pay.
//!
//! Exactness: the box test is conservative (exit distances are widened by 1 + 2γ₃, and every
//! primitive's box is padded by a few ulps so that no primitive touches a box face), so the BVH
//! never culls a primitive that the ray meets and the primitive tests alone decide
//! (`tests.rs` checks the traversal against a linear scan over the same tests, bit for bit).
//! Unlike the `CwBvh`, the traversal needs neither `-0.0` sanitising (crates.md G1) nor absolute
//! box padding against its culling of boxes left before t = 10⁻⁴; the scene is still scaled
//! internally by a power of two (see [`internal_scale`]), now only for the range of the arithmetic.

mod cutout;
mod prim;
mod simd;
#[cfg(test)]
mod tests;
mod wide;

use std::time::Duration;

use glam::Vec3A;
use obvhs::{BvhBuildParams, aabb::Aabb as BvhAabb, bvh2::builder::build_bvh2};

use crate::{Cylinder, Ray, Sphere, Triangle};
use prim::{CylGeom, PrimRay, Ray8, SphereGeom, TriGeom, TriPack, TriPackBuilder};
use simd::F8;
use wide::{BoxRay, Leaf, Leaves, Wide};

/// The power of two that brings the largest coordinate magnitude of the scene to [2⁹, 2¹⁰).
///
/// Scaling by a power of two is exact; it keeps the intersection arithmetic (cross products of
/// edges, squared radii) clear of underflow and overflow for scenes of any size.
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

/// Whether an id of [`Accel::ids`] is a triangle's.
fn is_triangle(id: u32) -> bool {
    id & (SPHERE_BIT | CYLINDER_BIT) == 0
}

/// The id of an empty lane in [`Accel::ids`].
const NO_PRIMITIVE: u32 = u32::MAX;

/// Number of primitive slots per leaf (lanes of a [`TriPack`]).
const LANES: usize = wide::MAX_LEAF_PRIMS as usize;

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
///
/// Leaf `i` of the BVH owns the primitive slots `4i .. 4i + 4`: the lanes of `packs[i]` for its
/// triangles, and the entries of `ids` for all of its primitives.
#[derive(Clone, Debug)]
pub(crate) struct Accel {
    /// `None` when the scene has no primitive.
    bvh: Option<Wide>,
    /// The triangles of each leaf.
    packs: Vec<TriPack>,
    /// Per slot: triangle index, `SPHERE_BIT | sphere index`, `CYLINDER_BIT | cylinder index` or
    /// [`NO_PRIMITIVE`].
    ids: Vec<u32>,
    /// Spheres in description order, in internal coordinates.
    spheres: Vec<SphereGeom>,
    /// Cylinders in description order, in internal coordinates.
    cylinders: Vec<CylGeom>,
    /// Power of two by which world coordinates are multiplied (exactly) to get internal ones.
    scale: f32,
    /// Number of primitives in the BVH.
    len: usize,
    /// Per leaf, the lanes whose triangle is a cut-out (see `cutout.rs`); empty unless set.
    cutout_lanes: Vec<u8>,
}

/// One ray's query of the leaves: the ray in the forms the primitive tests take, and the slot of
/// the closest hit so far.
struct Query<'a> {
    accel: &'a Accel,
    rays: (PrimRay, Ray8),
    closest: Option<usize>,
    /// The barycentrics u, v of the lanes of the leaf of `closest`.
    uv: (F8, F8),
}

impl Leaves for Query<'_> {
    #[inline(always)]
    fn closest(&mut self, leaf: Leaf, tmax: &mut f32) {
        self.accel
            .leaf_closest(&self.rays, leaf, tmax, &mut self.closest, &mut self.uv);
    }

    #[inline(always)]
    fn any(&self, leaf: Leaf, tmax: f32) -> bool {
        self.accel.leaf_any(&self.rays, leaf, tmax)
    }
}

/// obvhs build settings: `fast_build` (PLOC with a short search, 2 % reinsertion) with leaves of
/// up to [`LANES`] primitives, one [`TriPack`] each, and a leaf-collapse traversal cost of 6
/// instead of 3.
///
/// Faster builds trace slower and slower ones do not trace faster on our scenes; the
/// measurements are in docs/notes/bvh-traversal.md.
fn build_params() -> BvhBuildParams {
    BvhBuildParams {
        max_prims_per_leaf: LANES as u32,
        collapse_traversal_cost: 6.0,
        ..BvhBuildParams::fast_build()
    }
}

/// A primitive box enlarged by a few ulps (at least the smallest normal float), so that a box
/// extends strictly beyond its primitive on every side (see `wide::Node::intersect`).
fn padded(lo: Vec3A, hi: Vec3A) -> BvhAabb {
    let pad = |v: Vec3A| 4.0 * f32::EPSILON * v.abs() + Vec3A::splat(f32::MIN_POSITIVE);
    BvhAabb::new(lo - pad(lo), hi + pad(hi))
}

/// Primitives per scene must stay below this (ids keep two tag bits); `Scene::new` checks it.
pub(crate) const MAX_PRIMITIVES: usize = CYLINDER_BIT as usize;

impl Accel {
    /// Builds the BVH over every non-degenerate triangle, every sphere and every cylinder.
    pub(crate) fn build(
        triangles: &[Triangle],
        spheres: &[Sphere],
        cylinders: &[Cylinder],
    ) -> Self {
        let scale = internal_scale(triangles, spheres, cylinders);
        let n = triangles.len() + spheres.len() + cylinders.len();
        assert!(n < MAX_PRIMITIVES, "Scene::new checks the primitive count");
        let internal = |tri: &Triangle| tri.positions.map(|v| v * scale);
        let mut ids = Vec::with_capacity(n);
        let mut aabbs = Vec::with_capacity(n);
        for (i, tri) in triangles.iter().enumerate() {
            let p = internal(tri);
            if !TriGeom::new(p).is_proper() {
                continue;
            }
            let p = p.map(Vec3A::from);
            aabbs.push(padded(p[0].min(p[1]).min(p[2]), p[0].max(p[1]).max(p[2])));
            ids.push(i as u32);
        }
        for (i, s) in spheres.iter().enumerate() {
            let c = Vec3A::from(s.center * scale);
            let r = Vec3A::splat(s.radius * scale);
            aabbs.push(padded(c - r, c + r));
            ids.push(i as u32 | SPHERE_BIT);
        }
        for (i, c) in cylinders.iter().enumerate() {
            let b = c.bounds();
            aabbs.push(padded(
                Vec3A::from(b.min * scale),
                Vec3A::from(b.max * scale),
            ));
            ids.push(i as u32 | CYLINDER_BIT);
        }
        let mut accel = Self {
            bvh: None,
            packs: Vec::new(),
            ids: Vec::new(),
            spheres: spheres.iter().map(|s| SphereGeom::new(s, scale)).collect(),
            cylinders: cylinders.iter().map(|c| CylGeom::new(c, scale)).collect(),
            scale,
            len: ids.len(),
            cutout_lanes: Vec::new(),
        };
        if ids.is_empty() {
            return accel;
        }
        let mut build_time = Duration::ZERO;
        let bvh2 = build_bvh2(&aabbs, build_params(), &mut build_time);
        drop(aabbs);
        let order = &bvh2.primitive_indices;
        let bvh = Wide::from_bvh2(&bvh2, &|first, count| {
            let range = first as usize..(first + count) as usize;
            order[range].iter().any(|&i| !is_triangle(ids[i as usize]))
        });
        // Lay the primitives out leaf by leaf, in the order the leaves were made (depth first).
        accel.packs = Vec::with_capacity(bvh.leaves.len());
        accel.ids = vec![NO_PRIMITIVE; bvh.leaves.len() * LANES];
        for (leaf, &(first, count)) in bvh.leaves.iter().enumerate() {
            let mut pack = TriPackBuilder::EMPTY;
            for lane in 0..count as usize {
                let id = ids[order[first as usize + lane] as usize];
                accel.ids[leaf * LANES + lane] = id;
                if is_triangle(id) {
                    let geom = TriGeom::new(internal(&triangles[id as usize]));
                    pack.set(lane, &geom);
                }
            }
            accel.packs.push(pack.build());
        }
        accel.bvh = Some(bvh);
        accel
    }

    /// Ray parameter of the closest intersection in (tmin, tmax) with the sphere or cylinder of
    /// id `id`; ∞ for anything else.
    #[inline(always)]
    fn intersect_other(&self, ray: &PrimRay, tmax: f32, id: u32) -> f32 {
        if id == NO_PRIMITIVE {
            f32::INFINITY
        } else if id & SPHERE_BIT != 0 {
            self.spheres[(id & !SPHERE_BIT) as usize].intersect(ray, tmax)
        } else if id & CYLINDER_BIT != 0 {
            self.cylinders[(id & !CYLINDER_BIT) as usize].intersect(ray, tmax)
        } else {
            f32::INFINITY
        }
    }

    /// Lowers `tmax` to the closest hit in `leaf` below it, if any, and records its slot.
    #[inline(always)]
    fn leaf_closest(
        &self,
        rays: &(PrimRay, Ray8),
        leaf: Leaf,
        tmax: &mut f32,
        closest: &mut Option<usize>,
        uv: &mut (F8, F8),
    ) {
        let (hit, t, u, v) = self.packs[leaf.index].intersect(&rays.1, *tmax);
        let lanes = hit.bitmask();
        // Most leaf tests miss every lane.
        if lanes != 0 {
            // The nearest hit lane (the first on ties).
            let t = F8::select(hit, t, F8::splat(f32::INFINITY));
            let best = t.min_all();
            let lane = (t.eq(best).bitmask() & lanes).trailing_zeros() as usize;
            *tmax = best.to_array()[0];
            *closest = Some(leaf.index * LANES + lane);
            *uv = (u, v);
        }
        if leaf.mixed {
            for slot in leaf.index * LANES..(leaf.index + 1) * LANES {
                let t = self.intersect_other(&rays.0, *tmax, self.ids[slot]);
                if t < *tmax {
                    *tmax = t;
                    *closest = Some(slot);
                }
            }
        }
    }

    /// Whether anything in `leaf` is hit below `tmax`.
    #[inline(always)]
    fn leaf_any(&self, rays: &(PrimRay, Ray8), leaf: Leaf, tmax: f32) -> bool {
        if self.packs[leaf.index].intersect(&rays.1, tmax).0.bitmask() != 0 {
            return true;
        }
        leaf.mixed
            && (leaf.index * LANES..(leaf.index + 1) * LANES)
                .any(|slot| self.intersect_other(&rays.0, tmax, self.ids[slot]) < tmax)
    }

    /// The ray in internal (scaled) space for the primitive and box tests, and its upper bound;
    /// `None` for a non-finite ray. Unlike obvhs' CwBvh (crates.md G1), the traversal needs no
    /// sanitising of `-0.0` direction components.
    #[inline(always)]
    fn internal_ray(&self, ray: &Ray) -> Option<((PrimRay, Ray8), BoxRay, f32)> {
        // The box tests need a finite origin in internal space (an unused child slot's empty box
        // is entered by an infinite one) and a tmax that is not NaN (NaN exit distances pass the
        // integer comparison of `Node::intersect`): the scaled origin is tested, since a huge
        // finite origin can overflow when scaled. o·0 + d·0 is ±0 in every lane exactly when
        // every component is finite (∞·0 and NaN give NaN); one SIMD test instead of six scalar
        // ones.
        let origin = Vec3A::from(ray.origin) * self.scale;
        let probe = origin * 0.0 + Vec3A::from(ray.direction) * 0.0;
        if probe.cmpne(Vec3A::ZERO).any() || ray.t_max.is_nan() {
            return None;
        }
        let prim_ray = PrimRay {
            origin,
            direction: Vec3A::from(ray.direction),
            tmin: 0.0,
        };
        let box_ray = BoxRay::new(prim_ray.origin, prim_ray.direction);
        Some((
            (prim_ray, Ray8::new(&prim_ray)),
            box_ray,
            ray.t_max * self.scale,
        ))
    }

    /// The closest hit with 0 ≤ t < `ray.t_max` (t > 0 for spheres).
    ///
    /// Never inlined, so that the traversal is compiled once, alone, and its speed does not depend
    /// on the caller; a call costs little next to an incoherent ray. The photon loop, whose rays
    /// are short, takes the inlined form instead ([`Accel::intersect_inlined`]).
    #[inline(never)]
    pub(crate) fn intersect(&self, ray: &Ray) -> Option<RawHit> {
        self.intersect_inlined(ray)
    }

    /// [`Accel::intersect`] compiled into its caller: for the photon loop, where the call and
    /// the caller's vector registers saved around it are a noticeable share of a short ray.
    #[inline(always)]
    pub(crate) fn intersect_inlined(&self, ray: &Ray) -> Option<RawHit> {
        let bvh = self.bvh.as_ref()?;
        let (rays, box_ray, mut tmax) = self.internal_ray(ray)?;
        let mut query = Query {
            accel: self,
            rays,
            closest: None,
            uv: (F8::splat(0.0), F8::splat(0.0)),
        };
        bvh.closest(&box_ray, &mut tmax, &mut query);
        let slot = query.closest?;
        Some(self.raw_hit(slot, tmax, || {
            (
                query.uv.0.to_array()[slot % LANES],
                query.uv.1.to_array()[slot % LANES],
            )
        }))
    }

    /// The hit of the primitive in `slot` at internal distance `tmax`; `uv` gives a triangle's
    /// barycentrics (read only for triangles).
    #[inline(always)]
    fn raw_hit(&self, slot: usize, tmax: f32, uv: impl FnOnce() -> (f32, f32)) -> RawHit {
        let t = tmax / self.scale;
        let id = self.ids[slot];
        if id & SPHERE_BIT != 0 {
            RawHit::Sphere {
                index: id & !SPHERE_BIT,
                t,
            }
        } else if id & CYLINDER_BIT != 0 {
            RawHit::Cylinder {
                index: id & !CYLINDER_BIT,
                t,
            }
        } else {
            let (b1, b2) = uv();
            RawHit::Triangle {
                index: id,
                t,
                b1,
                b2,
            }
        }
    }

    /// Whether anything is hit with 0 ≤ t < `ray.t_max` (t > 0 for spheres). Never inlined, as
    /// [`Accel::intersect`].
    #[inline(never)]
    pub(crate) fn occluded(&self, ray: &Ray) -> bool {
        let Some(bvh) = self.bvh.as_ref() else {
            return false;
        };
        let Some((rays, box_ray, tmax)) = self.internal_ray(ray) else {
            return false;
        };
        let query = Query {
            accel: self,
            rays,
            closest: None,
            uv: (F8::splat(0.0), F8::splat(0.0)),
        };
        bvh.any(&box_ray, tmax, &query)
    }

    /// Number of primitives in the BVH.
    pub(crate) fn len(&self) -> usize {
        self.len
    }
}
