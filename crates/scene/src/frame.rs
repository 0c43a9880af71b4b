//! Orthonormal frames for moving directions between world space and a local shading space.

use glam::Vec3;

/// A right-handed orthonormal basis (`s`, `t`, `n`): local `z` is `n`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    /// First tangent (local x).
    pub s: Vec3,
    /// Second tangent (local y).
    pub t: Vec3,
    /// Normal (local z).
    pub n: Vec3,
}

impl Frame {
    /// Builds a frame around the unit normal `n` (Duff et al. 2017, "Building an Orthonormal Basis, Revisited").
    #[inline]
    pub fn from_normal(n: Vec3) -> Self {
        let sign = 1.0f32.copysign(n.z);
        let a = -1.0 / (sign + n.z);
        let b = n.x * n.y * a;
        let s = Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
        let t = Vec3::new(b, sign + n.y * n.y * a, -n.y);
        Self { s, t, n }
    }

    /// Expresses the world-space vector `v` in this frame.
    #[inline]
    pub fn to_local(&self, v: Vec3) -> Vec3 {
        Vec3::new(v.dot(self.s), v.dot(self.t), v.dot(self.n))
    }

    /// Expresses the local vector `v` in world space.
    #[inline]
    pub fn to_world(&self, v: Vec3) -> Vec3 {
        self.s * v.x + self.t * v.y + self.n * v.z
    }
}
