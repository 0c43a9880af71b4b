//! Queries that skip cut-out triangles: a triangle whose material has an alpha test is a hit
//! only where the test passes. Only scenes with such triangles take these paths; the others keep
//! the plain queries of `mod.rs`, untouched.

use super::wide::{Leaf, Leaves};
use super::{Accel, LANES, RawHit, simd::F8};
use crate::Ray;

/// The alpha test: whether triangle `index` is present at barycentrics (b1, b2).
pub(crate) type Coverage<'a> = &'a dyn Fn(u32, f32, f32) -> bool;

struct CutoutQuery<'a> {
    accel: &'a Accel,
    rays: (super::prim::PrimRay, super::prim::Ray8),
    closest: Option<usize>,
    /// Barycentrics of the closest hit.
    uv: (f32, f32),
    covered: Coverage<'a>,
}

impl CutoutQuery<'_> {
    /// The hit lanes of `leaf`'s triangles below `tmax` that pass the alpha test, with their
    /// parameters and barycentrics.
    #[inline(always)]
    fn triangle_lanes(&self, leaf: Leaf, tmax: f32) -> (u32, [f32; 8], [f32; 8], [f32; 8]) {
        let (hit, t, u, v): (F8, F8, F8, F8) =
            self.accel.packs[leaf.index].intersect(&self.rays.1, tmax);
        let mut lanes = hit.bitmask();
        let (t, u, v) = (t.to_array(), u.to_array(), v.to_array());
        let mut cut = lanes & u32::from(self.accel.cutout_lanes[leaf.index]);
        while cut != 0 {
            let lane = cut.trailing_zeros() as usize;
            cut &= cut - 1;
            if !(self.covered)(self.accel.ids[leaf.index * LANES + lane], u[lane], v[lane]) {
                lanes &= !(1 << lane);
            }
        }
        (lanes, t, u, v)
    }
}

impl Leaves for CutoutQuery<'_> {
    #[inline(always)]
    fn closest(&mut self, leaf: Leaf, tmax: &mut f32) {
        let (mut lanes, t, u, v) = self.triangle_lanes(leaf, *tmax);
        while lanes != 0 {
            let lane = lanes.trailing_zeros() as usize;
            lanes &= lanes - 1;
            if t[lane] < *tmax {
                *tmax = t[lane];
                self.closest = Some(leaf.index * LANES + lane);
                self.uv = (u[lane], v[lane]);
            }
        }
        if leaf.mixed {
            for slot in leaf.index * LANES..(leaf.index + 1) * LANES {
                let t = self
                    .accel
                    .intersect_other(&self.rays.0, *tmax, self.accel.ids[slot]);
                if t < *tmax {
                    *tmax = t;
                    self.closest = Some(slot);
                }
            }
        }
    }

    #[inline(always)]
    fn any(&self, leaf: Leaf, tmax: f32) -> bool {
        if self.triangle_lanes(leaf, tmax).0 != 0 {
            return true;
        }
        leaf.mixed
            && (leaf.index * LANES..(leaf.index + 1) * LANES).any(|slot| {
                self.accel
                    .intersect_other(&self.rays.0, tmax, self.accel.ids[slot])
                    < tmax
            })
    }
}

impl Accel {
    /// Marks the triangles for which `is_cutout` holds as cut-outs (tested by the `*_cutout`
    /// queries).
    pub(crate) fn set_cutouts(&mut self, is_cutout: impl Fn(u32) -> bool) {
        self.cutout_lanes = (0..self.packs.len())
            .map(|leaf| {
                let mut mask = 0u8;
                for lane in 0..LANES {
                    let id = self.ids[leaf * LANES + lane];
                    if super::is_triangle(id) && id != super::NO_PRIMITIVE && is_cutout(id) {
                        mask |= 1 << lane;
                    }
                }
                mask
            })
            .collect();
    }

    /// [`Accel::intersect`] where cut-out triangles count only where `covered` says so.
    pub(crate) fn intersect_cutout(&self, ray: &Ray, covered: Coverage<'_>) -> Option<RawHit> {
        let bvh = self.bvh.as_ref()?;
        let (rays, box_ray, mut tmax) = self.internal_ray(ray)?;
        let mut query = CutoutQuery {
            accel: self,
            rays,
            closest: None,
            uv: (0.0, 0.0),
            covered,
        };
        bvh.closest(&box_ray, &mut tmax, &mut query);
        let slot = query.closest?;
        Some(self.raw_hit(slot, tmax, || query.uv))
    }

    /// [`Accel::occluded`] where cut-out triangles count only where `covered` says so.
    pub(crate) fn occluded_cutout(&self, ray: &Ray, covered: Coverage<'_>) -> bool {
        let Some(bvh) = self.bvh.as_ref() else {
            return false;
        };
        let Some((rays, box_ray, tmax)) = self.internal_ray(ray) else {
            return false;
        };
        let query = CutoutQuery {
            accel: self,
            rays,
            closest: None,
            uv: (0.0, 0.0),
            covered,
        };
        bvh.any(&box_ray, tmax, &query)
    }
}
