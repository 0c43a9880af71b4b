//! Triangle emitters whose emission is modulated by a texture: the radiance at a point, the
//! mean that weighs the triangle among the emitters, and the size of its finest detail.

use glam::Vec2;

use crate::{Rgb, sampling::uniform_triangle, texture::TextureRef};

/// A triangle emitter whose radiance is the material's emission times a texture.
#[derive(Clone, Debug)]
pub(super) struct TexturedTriangle {
    pub(super) emission: Rgb,
    pub(super) uv: [Vec2; 3],
    pub(super) texture: TextureRef,
}

impl TexturedTriangle {
    /// The radiance at barycentrics `b` (the weights of p1 and p2).
    #[inline]
    pub(super) fn radiance(&self, b: Vec2) -> Rgb {
        let [uv0, uv1, uv2] = self.uv;
        let uv = (1.0 - b.x - b.y) * uv0 + b.x * uv1 + b.y * uv2;
        self.emission * self.texture.color(uv)
    }

    /// The linear size of the triangle's finest emitted detail, for the frequency analysis: the
    /// side of one texel on the surface (the texture can hold nothing finer), at most √area.
    pub(super) fn feature_size(&self, area: f32) -> f32 {
        let [uv0, uv1, uv2] = self.uv;
        let (w, h) = self.texture.image.resolution();
        let [a, b, c, d, ..] = self.texture.transform;
        let uv_area = 0.5 * ((uv1 - uv0).perp_dot(uv2 - uv0) * (a * d - b * c)).abs();
        let texels = uv_area * w as f32 * h as f32;
        let size = (area / texels).sqrt();
        if size.is_finite() && size > 0.0 {
            size.min(area.sqrt())
        } else {
            area.sqrt()
        }
    }

    /// The mean radiance over the triangle, from a fixed 16 × 16 stratified set of points, and
    /// at least 10⁻³ of the texture's mean over the whole image, so that a part of the texture
    /// between the points is still sampled (with probability > 0): the choice of emitters by
    /// power stays unbiased whatever this estimate is, only its variance depends on it.
    pub(super) fn mean(&self) -> Rgb {
        const N: u32 = 16;
        let mut sum = Rgb::ZERO;
        for i in 0..N {
            for j in 0..N {
                let u = Vec2::new((i as f32 + 0.5) / N as f32, (j as f32 + 0.5) / N as f32);
                sum += self.radiance(uniform_triangle(u));
            }
        }
        let floor = self.emission * self.texture.image.mean(self.texture.srgb) * 1e-3;
        (sum / (N * N) as f32).max(floor)
    }
}
