//! The scene's BVH over triangles, analytic spheres and analytic cylinders.
//!
//! obvhs builds a binary BVH (`Bvh2`: PLOC, a little reinsertion, SAH leaf collapse to at most
//! eight primitives), which is collapsed into our own CPU layout (`wide.rs`): 8-wide nodes whose
//! child boxes are stored in SoA rows of eight lanes and tested together with one AVX operation
//! per step (`simd.rs`), nearest child first; each leaf's triangles are tested together too, as
//! one SoA pack of eight lanes (`prim::TriPack`), and its spheres and cylinders one by one.
//! obvhs types never leave this module.
//!
//! This replaced traversal of obvhs' `CwBvh`, whose compressed 8-wide nodes (a GPU layout) are
//! decoded per node on the CPU (bunny diffuse-bounce closest hits ×1.7, occluded ×1.9, primary
//! ×1.5; `Scene::new` of the 1M-triangle MetalRoughSpheres ×1.7 faster).
//!
//! Where the time of an incoherent ray goes (callgrind, bunny diffuse-bounce closest hits, which
//! mostly leave the surface and miss: 7.8 node visits and 4 leaf tests per ray): building the
//! `Hit` afterwards costs about 1 % of the instructions, ray setup about 5 %, the node tests and
//! the stack about two thirds and the leaf tests a quarter. Replaying each ray four times (hot
//! caches, trained branches) was only ~15 % faster, and shuffling the rays ~30 % slower, so the
//! pixel-ordered benchmark is mostly bound by instructions and branches, not by memory. A
//! stronger obvhs build does not help much: even `reinsertion_batch_ratio` 1 (a build ~20× as
//! slow) cut the instructions by only 5 %. What did help: one AVX test of the eight child boxes
//! instead of two SSE tests of four (and no zeroing of the traversal stack per ray), 957 instead
//! of 1200 instructions per ray; then leaves of up to eight triangles in one 8-lane pack, with
//! the collapse cost raised from 3 to 6 so that obvhs fills them, 943 instructions per ray
//! (occluded 1037 → 763, primary closest hits 829 → 655). Measured with `benches/bvh.rs`, old
//! and new binaries alternating, rays per CPU-second of one thread on a shared, loaded 2-core
//! machine (±15 % run to run): bunny diffuse-bounce closest hits ×1.1–1.3 (3.0–3.3 → 3.3–4.2
//! M/s), occluded ×1.15 (3.9 → 4.5 M/s), primary ×1.2 (6.0 → 7.2 M/s); MetalRoughSpheres
//! diffuse-bounce closest hits ×1.3 (1.17 → 1.5 M/s), `Scene::new` unchanged (0.93–0.98 s);
//! with `examples/prof.rs`, which runs one query kind alone, bunny diffuse-bounce closest hits
//! ×1.25 and occluded ×1.4.
//!
//! The round after that (callgrind instructions per ray, bunny; bounce closest / bounce occluded /
//! primary closest, before: 943 / 763 / 655): the leaf pack stores ng = e1 × e2 (384 instead of
//! 288 bytes per leaf), drops the finiteness test of 1/det (redundant, see `TriPack::intersect`)
//! and skips the nearest-lane search when no lane is hit, 852 / – / –; the hit children of a
//! node are pushed with one compressing AVX store into a two-array stack whose length stays in a
//! register, 796 / 658 / –; the node test takes per-ray byte offsets of its entry and exit rows
//! and subtracts the bounds from the origin (so the loads fold into the subtraction),
//! 729 / 577 / 541; one SIMD finiteness test of the ray instead of six scalar ones and no
//! bounds check of node indices, 680 / 540 / 504; the ray's octant from one SIMD comparison,
//! 656 / 528 / 485. Checksums of every answer (`examples/prof.rs`) are unchanged. Time fell
//! less than the instructions (old and new `examples/prof.rs` alternating, rays per CPU-second,
//! loaded 2-core machine): bunny diffuse-bounce closest hits ×1.08–1.29 (median ×1.15; 3.3–3.9
//! → 4.2–4.4 M/s), occluded ×1.06–1.18, primary ×0.94–1.21; `benches/bvh.rs` agreed within its
//! noise, and `Scene::new` of MetalRoughSpheres stayed at 0.6–0.8 s. callgrind's branch
//! simulator counts 5.4 mispredicted branches per bounce ray, mostly on "one child hit or more"
//! (1.7), "leaf or node" (1.4) and "any child hit" (1.1); pushing every hit child with the
//! nearest on top and popping it, without those two branches, saved 1.9 of them but cost 48 %
//! more instructions as compiled, and was ×0.7 as fast.
//!
//! The round after that (same figures, before: 656 / 528 / 485) started from the clock: at about
//! 2.9 GHz, 4.3 M bounce rays/s is ~680 cycles per ray for 656 instructions, so the traversal waits
//! mostly on the chain from a node's loads to its mask of hit children, its nearest child and that
//! child's reference, the next node's address (~40 cycles per node, ~55 with two hits or more), and
//! on mispredicted branches. Shortening that chain, with the same bits: the nearest hit child from
//! an unsigned-integer minimum of the entry distances' bits (one cycle per step instead of four;
//! lanes not hit are all-ones bits rather than a blend of ∞), the slab minima and maxima as trees
//! of two levels rather than chains of three, and the exit widening folded into the inverse
//! direction (one multiplication less), 636 / 532 / 479, ×1.1–1.2 (4.6 → 5.2 M/s); the child
//! references moved into the first cache line of the node, fetched with the bounds instead of after
//! the mask, and the hit mask from a comparison of its own rather than the complement of another's,
//! 634 / 532 / 478, ×1.08 (medians 4.86 → 5.27 M/s); the hit mask from an integer comparison of the
//! distances' bits (exact here, see `wide::Node::intersect`; one cycle instead of four), and node
//! references scaled so that a node's row is one addressing mode away (no shift and addition before
//! its loads), 637 / 524 / 479, ×1.04 (5.37 → 5.56 M/s); 0 ≤ u, v, w in the leaf test as one
//! comparison of min(min(u, v), w), 633 / 519 / 477; the collapse into wide nodes by dynamic
//! programming (least total surface area of the wide nodes, `wide::Plan`) instead of greedily
//! opening the largest child, which leaves fewer nearly empty nodes near the leaves (the greedy
//! collapse gave the bunny 3886 nodes for 11805 leaves, four children per node on average; the plan
//! gives 2406, 5.9 children per node; MetalRoughSpheres: 37098 nodes for 183165 leaves), 621 / 513
//! / 477, its time within the noise (medians of 6 and 10 runs 5.03 → 4.74 and 5.53 → 5.53 M/s, best
//! 5.62 → 5.72 and 5.84 → 5.75). Checksums of every answer (bunny and MetalRoughSpheres, primary
//! and bounce, closest and occluded) are unchanged.
//!
//! All of it (old and new `examples/prof.rs` alternating, rays per CPU-second, best of 10 queries
//! per run, loaded 2-core machine): bunny diffuse-bounce closest hits ×1.18–1.27 (medians of 8 and
//! 10 runs: 4.33 → 5.12 and 3.79 → 4.80 M/s; best runs 4.71 → 5.88), occluded ×1.08 (5.33 → 5.76,
//! best 5.85 → 6.49), primary closest hits ×1.16 (7.58 → 8.83, best 8.06 → 9.44). `benches/bvh.rs`
//! (two alternations, 1 thread, per CPU-second) agreed: bunny bounce closest hits 3.50, 3.92 →
//! 4.77, 5.52 M/s, occluded 4.48, 4.61 → 5.33, 5.68, primary 7.53, 8.05 → 9.25, 9.64;
//! MetalRoughSpheres bounce closest hits 1.24, 1.28 → 1.67, 1.92. The plan costs `Scene::new` of
//! MetalRoughSpheres ~0.06 s (thread CPU time of the collapse and the packing 0.13–0.16 → 0.19–0.23
//! s, of all of `Accel::build` 0.74–0.90 → 0.83–0.98 s; wall-clock `Scene::new` said 2–5 s for both
//! on the loaded machine); walking the binary nodes in memory order instead of a preorder saved
//! nothing measurable.
//!
//! What did not pay: the six row addresses precomputed per ray (so that a node's loads need no
//! address arithmetic at all), 15 more instructions per ray (registers spilled) and no faster (5.76
//! vs 5.74 M/s); unchecked indexing of the child references and leaf packs, as fast (5.27 vs 5.27
//! M/s); taking the multi-hit path for a single hit too (no branch on the number of hits), 621 →
//! 681 instructions and ×0.91 (5.59 → 5.11 M/s); leaves of up to four primitives from obvhs merged
//! into packs of up to eight by the plan (leaf cost 0.8–3 times a node's), 621 → 618 instructions,
//! not worth the code.
//!
//! December 2026, photon tracing (callgrind, `passes` bench of `ppm`, CornellBox-Sphere, where
//! every ray hits): the barycentrics of a triangle hit are the leaf test's own u and v of the hit
//! lane (the leaf keeps its u, v rows when it lowers the bound) instead of a scalar recomputation
//! for the one triangle, which cost ~50 instructions per hit and could differ by rounding from the
//! numbers the inside test accepted (glam's `cross` uses FMA where the CPU has it; the reported
//! barycentrics now always pass 0 ≤ b1, b2, 1 − b1 − b2). Photon paths 4108 → 3978 instructions;
//! bunny primary closest hits 1023 → 980 per ray, diffuse-bounce closest hits (91 % misses) 606 →
//! 612. Hits move by rounding, so images are no longer bit for bit those of before; the other
//! changes of that round were exact.
//!
//! Exactness: the box test is conservative (exit distances are widened by 1 + 2γ₃, and every
//! primitive's box is padded by a few ulps so that no primitive touches a box face), so the BVH
//! never culls a primitive that the ray meets and the primitive tests alone decide
//! (`tests.rs` checks the traversal against a linear scan over the same tests, bit for bit).
//! Unlike the `CwBvh`, the traversal needs neither `-0.0` sanitising (crates.md G1) nor absolute
//! box padding against its culling of boxes left before t = 10⁻⁴; the scene is still scaled
//! internally by a power of two (see [`internal_scale`]), now only for the range of the arithmetic.

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
/// Measured with `benches/bvh.rs` (1 thread, CPU time), with the 4-lane leaves of before: on
/// the 1M-triangle MetalRoughSpheres, `fast` builds in about 0.7 s with 1.4 M diffuse-bounce
/// rays/s; `very_fast_build` saves ~0.1 s but traces 10 % slower, `fastest_build` (no
/// reinsertion) saved nothing overall and traces 20–30 % slower, and `medium_build` costs ~0.1 s
/// more for no measurable speed-up; leaves of at most 2 or 1 primitives were 10 % and 45 %
/// slower on the bunny. With 8-lane packs (callgrind, bunny diffuse-bounce closest hits): a
/// collapse cost of 6 gives 1.4 % fewer instructions than 3 (any value from 6 to 30 gives the same
/// tree), 1 gives 8 % more; PLOC search distance, search depth and reinsertion ratio as in
/// `medium_build` save 0 %, as in `slow_build` (without pre-splitting) 1 %, `very_slow_build`'s
/// reinsertion 5 % at ~20× the build time.
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
        // o·0 + d·0 is ±0 in every lane exactly when every component is finite (∞·0 and NaN give
        // NaN); one SIMD test instead of six scalar ones.
        let probe = Vec3A::from(ray.origin) * 0.0 + Vec3A::from(ray.direction) * 0.0;
        if probe.cmpne(Vec3A::ZERO).any() {
            return None;
        }
        let prim_ray = PrimRay {
            origin: Vec3A::from(ray.origin * self.scale),
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
    /// on the caller: inlined into the benchmark's rayon closure (beside `occluded`), it seemed
    /// slower than through a call from `examples/prof.rs` (within the noise of the shared
    /// machine); a call costs a few instructions of the ~900 of an incoherent ray. The photon
    /// loop, whose rays are short (2.2 nodes and 1.3 leaves in the Cornell box), takes the
    /// inlined form instead ([`Accel::intersect_inlined`]).
    #[inline(never)]
    pub(crate) fn intersect(&self, ray: &Ray) -> Option<RawHit> {
        self.intersect_inlined(ray)
    }

    /// [`Accel::intersect`] compiled into its caller: for the photon loop, where the call and
    /// the caller's vector registers saved around it cost about 40 instructions per ray.
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
        let t = tmax / self.scale;
        let id = self.ids[slot];
        Some(if id & SPHERE_BIT != 0 {
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
            let (b1, b2) = (
                query.uv.0.to_array()[slot % LANES],
                query.uv.1.to_array()[slot % LANES],
            );
            RawHit::Triangle {
                index: id,
                t,
                b1,
                b2,
            }
        })
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
