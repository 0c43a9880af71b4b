//! Rays, surface hits and robust secondary-ray spawning.

use glam::{Vec2, Vec3, Vec3A};

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
    /// The most focusing curvature seen from the side the ray came from: the largest signed
    /// principal curvature, following frequency-algebra §3 (positive when the centre of
    /// curvature lies on the ray's side: concave, focusing). Under the isotropic collapse of
    /// §8.5 it is the conservative choice (the smallest predicted kernels).
    /// A sphere is exactly −1/R from outside and +1/R from inside; a cylinder 0 from outside
    /// (flat along its axis) and +1/R from inside (focusing across its axis, at R/2); a mesh
    /// triangle the largest over its edges of the normal curvature −Δn·Δp/|Δp|² from its vertex
    /// normals (signed for the side); flat or normal-less triangles give 0.
    pub curvature: f32,
    /// The primitive that was hit.
    pub primitive: Primitive,
    /// Triangle barycentrics (b1, b2) of the hit (b0 = 1 − b1 − b2); for cylinders (position
    /// across the kept arc from 0 to 1, counter-clockwise about the axis; height / `height`);
    /// zero for spheres, whose (φ/2π, θ/π) `Scene::texture_uv` computes when a texture asks.
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
    round_toward(p + offset, offset)
}

/// Per component: `v.next_up()` where `o > 0`, `v.next_down()` where `o < 0`, else `v`; bit for
/// bit, but without branches, which matters because the sign of `o` (an offset along a normal,
/// toward a random direction) is unpredictable, and a zero `o` is common (axis-aligned walls).
/// `f32::next_up`/`next_down` behind branches mispredict often (docs/performance.md).
///
/// It uses next_down(v) = −next_up(−v): flipping the sign bit of `v` by that of `o` turns both
/// directions into a `next_up` of `x`. That is the next bit pattern away from zero for x ≥ +0,
/// toward zero for x < 0, and the smallest subnormal for ±0; +∞ and NaN stay as they are.
#[inline(always)]
fn round_toward(v: Vec3, o: Vec3) -> Vec3 {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{
            __m128, _mm_add_epi32, _mm_and_si128, _mm_andnot_si128, _mm_castps_si128,
            _mm_castsi128_ps, _mm_cmpeq_epi32, _mm_cmpgt_epi32, _mm_cmpgt_ps, _mm_cmplt_ps,
            _mm_or_ps, _mm_or_si128, _mm_set1_epi32, _mm_setzero_ps, _mm_setzero_si128,
            _mm_srai_epi32, _mm_xor_si128,
        };
        // SAFETY: SSE2 is part of the x86_64 baseline.
        unsafe {
            let (vf, of) = (__m128::from(Vec3A::from(v)), __m128::from(Vec3A::from(o)));
            let (vb, ob) = (_mm_castps_si128(vf), _mm_castps_si128(of));
            let sign = _mm_set1_epi32(i32::MIN);
            let infinity = _mm_set1_epi32(0x7f80_0000);
            let flip = _mm_and_si128(ob, sign);
            let x = _mm_xor_si128(vb, flip);
            let magnitude = _mm_andnot_si128(sign, x);
            // −0 becomes +0, whose successor is the smallest subnormal.
            let zero = _mm_cmpeq_epi32(magnitude, _mm_setzero_si128());
            let x = _mm_andnot_si128(zero, x);
            // +1 for x ≥ +0, −1 for x < 0.
            let step = _mm_or_si128(_mm_srai_epi32(x, 31), _mm_set1_epi32(1));
            let up = _mm_xor_si128(_mm_add_epi32(x, step), flip);
            let moves = _mm_castps_si128(_mm_or_ps(
                _mm_cmpgt_ps(of, _mm_setzero_ps()),
                _mm_cmplt_ps(of, _mm_setzero_ps()),
            ));
            let stays = _mm_or_si128(
                _mm_cmpeq_epi32(x, infinity),
                _mm_cmpgt_epi32(magnitude, infinity),
            );
            let take = _mm_andnot_si128(stays, moves);
            let r = _mm_or_si128(_mm_and_si128(take, up), _mm_andnot_si128(take, vb));
            Vec3::from(Vec3A::from(_mm_castsi128_ps(r)))
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        let round = |v: f32, o: f32| {
            if o > 0.0 {
                v.next_up()
            } else if o < 0.0 {
                v.next_down()
            } else {
                v
            }
        };
        Vec3::new(round(v.x, o.x), round(v.y, o.y), round(v.z, o.z))
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::round_toward;

    /// The branchy definition `round_toward` must match bit for bit.
    fn reference(v: f32, o: f32) -> f32 {
        if o > 0.0 {
            v.next_up()
        } else if o < 0.0 {
            v.next_down()
        } else {
            v
        }
    }

    #[test]
    fn round_toward_is_next_up_or_down() {
        let specials = [
            0.0,
            -0.0,
            f32::MIN_POSITIVE,
            -f32::MIN_POSITIVE,
            f32::from_bits(1),
            -f32::from_bits(1),
            1.0,
            -1.0,
            f32::MAX,
            f32::MIN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
            -f32::NAN,
            f32::EPSILON,
            3.5e-3,
            -7.25e12,
        ];
        let mut values = specials.to_vec();
        // A deterministic spread of bit patterns (an LCG over all 2³² values).
        let mut bits = 0x1234_5678u32;
        for _ in 0..200_000 {
            bits = bits.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            values.push(f32::from_bits(bits));
        }
        let offsets = specials;
        for &v in &values {
            for &o in &offsets {
                let got = round_toward(Vec3::new(v, -v, 1.0), Vec3::new(o, o, -o));
                let want = Vec3::new(reference(v, o), reference(-v, o), reference(1.0, -o));
                assert_eq!(
                    got.to_array().map(f32::to_bits),
                    want.to_array().map(f32::to_bits),
                    "v = {v:e} ({:#x}), o = {o:e}",
                    v.to_bits()
                );
            }
        }
    }
}
