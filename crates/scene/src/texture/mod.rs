//! Image textures: decoded images shared by the materials that use them, and how a material
//! uses one (colour or data, wrap modes, a texture-coordinate transform).
//!
//! Texture coordinates follow glTF and image files: (0, 0) is the top-left corner of the image,
//! u grows to the right and v downwards. Loaders whose formats put v = 0 at the bottom (OBJ,
//! pbrt, Mitsuba, our TOML) flip v when they read texture coordinates.
//!
//! Lookups are bilinear between texel centres (pbrt-v4's convention: texel (x, y) is centred
//! on ((x + ½)/w, (y + ½)/h)). 8-bit images keep their bytes (4 per texel) and decode on
//! lookup: through the sRGB curve where the texture is a colour and the file is 8-bit, linearly
//! for data (normal maps, alpha) and always for the alpha channel. EXR and Radiance HDR images
//! hold linear floats and are never sRGB-decoded.

mod image;

use std::sync::Arc;

use glam::{Vec2, Vec3, Vec4};

#[cfg(test)]
pub(crate) use self::image::test_image;
pub use self::image::{Image, ImageError, Texels};
use crate::MaterialKind;
use crate::fingerprint::{Fingerprint, Fingerprinter};

/// What happens to texture coordinates outside [0, 1] (glTF's sampler wrap modes).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Wrap {
    /// Tile the image (glTF `REPEAT`, the default of glTF, OBJ and pbrt).
    #[default]
    Repeat,
    /// Tile with every other copy mirrored (glTF `MIRRORED_REPEAT`).
    Mirror,
    /// Extend the edge texels (glTF `CLAMP_TO_EDGE`).
    Clamp,
}

impl Wrap {
    /// The texel index for the integer coordinate `i` on an axis of `n` texels.
    #[inline]
    fn index(self, i: i64, n: u32) -> u32 {
        let n = i64::from(n);
        let j = match self {
            Wrap::Repeat => i.rem_euclid(n),
            Wrap::Clamp => i.clamp(0, n - 1),
            Wrap::Mirror => {
                let k = i.rem_euclid(2 * n);
                if k < n { k } else { 2 * n - 1 - k }
            }
        };
        j as u32
    }
}

/// How a material uses an image: the image, whether it is a colour (sRGB-decoded when 8-bit),
/// the wrap modes and an affine transform of the texture coordinates (glTF
/// `KHR_texture_transform`, OBJ `-o`/`-s`).
#[derive(Clone, Debug, PartialEq)]
pub struct TextureRef {
    /// The shared image.
    pub image: Arc<Image>,
    /// Whether the texels are colours: 8-bit colour channels then go through the sRGB curve.
    pub srgb: bool,
    /// Wrap modes along u and v.
    pub wrap: [Wrap; 2],
    /// `uv' = [a b; c d]·uv + (e, f)`, stored as (a, b, c, d, e, f); the identity by default.
    pub transform: [f32; 6],
}

impl TextureRef {
    /// The identity texture-coordinate transform.
    pub const IDENTITY: [f32; 6] = [1.0, 0.0, 0.0, 1.0, 0.0, 0.0];

    /// A texture with repeat wrapping and no transform.
    pub fn new(image: Arc<Image>, srgb: bool) -> Self {
        Self {
            image,
            srgb,
            wrap: [Wrap::Repeat; 2],
            transform: Self::IDENTITY,
        }
    }

    /// Linear RGBA at texture coordinates `uv`.
    #[inline]
    pub fn lookup(&self, uv: Vec2) -> Vec4 {
        let [a, b, c, d, e, f] = self.transform;
        let uv = Vec2::new(a * uv.x + b * uv.y + e, c * uv.x + d * uv.y + f);
        self.image.bilinear(uv, self.wrap, self.srgb)
    }

    /// The colour at `uv`.
    #[inline]
    pub fn color(&self, uv: Vec2) -> Vec3 {
        self.lookup(uv).truncate()
    }

    /// The alpha at `uv`: the alpha channel if the image has one that masks something, else
    /// its first channel (a grey mask, as OBJ `map_d` files and Mitsuba's opacity maps are).
    #[inline]
    pub fn alpha(&self, uv: Vec2) -> f32 {
        let v = self.lookup(uv);
        if self.image.has_alpha() { v.w } else { v.x }
    }
}

/// How a material's coverage is tested: glTF `MASK` (opaque where alpha ≥ cutoff) or `BLEND`
/// (taken as a stochastic cut-out: opaque with probability alpha).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AlphaMode {
    /// Opaque where alpha ≥ the cutoff, absent elsewhere.
    Mask {
        /// glTF `alphaCutoff` (0.5 by default).
        cutoff: f32,
    },
    /// Opaque with probability alpha, decided by a hash of the ray.
    Blend,
}

/// A material's cut-out: alpha = `factor` × the texture's alpha (1 without a texture).
#[derive(Clone, Debug, PartialEq)]
pub struct Alpha {
    /// The alpha texture, if any.
    pub texture: Option<TextureRef>,
    /// Constant factor (glTF base colour factor's alpha).
    pub factor: f32,
    /// The test.
    pub mode: AlphaMode,
}

/// A tangent-space normal map (glTF `normalTexture`, OBJ `norm`).
#[derive(Clone, Debug, PartialEq)]
pub struct NormalMap {
    /// The map (read as data: n = 2·texel − 1).
    pub texture: TextureRef,
    /// glTF `scale`: multiplies the tangent-plane components.
    pub scale: f32,
}

/// Metallic factor from which a glTF material counts as a conductor.
pub const METALLIC_THRESHOLD: f32 = 0.5;

/// Roughness below which a glTF conductor is a perfect mirror.
pub const MIRROR_ROUGHNESS: f32 = 0.01;

/// glTF's metallic-roughness texture, read per texel: metallic = `metallic` × blue, roughness
/// = `roughness` × green (linear data). Each hit becomes the material glTF's mapping gives for
/// its texel's values (diffuse, mirror or glossy, as glTF materials are mapped), with the
/// roughness rounded to one of [`MetallicRoughness::LEVELS`] levels: the scene keeps one
/// material per level, so that a hitpoint stores what it hit as an index like any other.
#[derive(Clone, Debug, PartialEq)]
pub struct MetallicRoughness {
    /// The texture (data, not colour).
    pub texture: TextureRef,
    /// The base colour: the diffuse albedo or the conductor's reflectance.
    pub base: Vec3,
    /// glTF `metallicFactor`.
    pub metallic: f32,
    /// glTF `roughnessFactor`.
    pub roughness: f32,
}

impl MetallicRoughness {
    /// Roughness levels of a conductor: roughness k/`LEVELS` for k = 1..=`LEVELS` (a
    /// roughness within 1/128 of the texel's; below 0.01 a mirror).
    pub const LEVELS: u32 = 64;

    /// The material kinds a hit can take, in variant order: the diffuse base, the mirror, then
    /// the conductor at each roughness level.
    pub fn variant_kinds(&self) -> Vec<MaterialKind> {
        let mut kinds = vec![
            Self::kind(self.base, 0.0, 1.0),
            Self::kind(self.base, 1.0, 0.0),
        ];
        kinds.extend(
            (1..=Self::LEVELS).map(|k| Self::kind(self.base, 1.0, k as f32 / Self::LEVELS as f32)),
        );
        kinds
    }

    /// glTF's mapping of an opaque metallic-roughness material with base colour `base` to a
    /// scattering model: a conductor (mirror below [`MIRROR_ROUGHNESS`], else glossy with
    /// α = roughness² and no diffuse base) from metallic [`METALLIC_THRESHOLD`] on, else diffuse
    /// with the base colour. The glTF importer maps untextured materials with it too.
    #[must_use]
    pub fn kind(base: Vec3, metallic: f32, roughness: f32) -> MaterialKind {
        if metallic >= METALLIC_THRESHOLD {
            if roughness < MIRROR_ROUGHNESS {
                MaterialKind::Mirror(crate::Mirror { reflectance: base })
            } else {
                MaterialKind::Glossy(crate::Glossy {
                    reflectance: base,
                    roughness: roughness * roughness,
                    diffuse: Vec3::ZERO,
                })
            }
        } else {
            MaterialKind::Diffuse(crate::Diffuse { albedo: base })
        }
    }

    /// The variant (an index into [`MetallicRoughness::variant_kinds`]) at `uv`.
    #[inline]
    pub fn variant(&self, uv: Vec2) -> u32 {
        let texel = self.texture.lookup(uv);
        let (metallic, roughness) = (self.metallic * texel.z, self.roughness * texel.y);
        if metallic < METALLIC_THRESHOLD {
            0
        } else if roughness < MIRROR_ROUGHNESS {
            1
        } else {
            let level = (roughness.min(1.0) * Self::LEVELS as f32).round() as u32;
            1 + level.clamp(1, Self::LEVELS)
        }
    }
}

/// The textures of one material. Every colour texture multiplies what the material would do
/// without it (see `docs/scene-format-extensions.md`, "Textures").
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MaterialTextures {
    /// Multiplies the material's scattering (diffuse albedo, mirror reflectance, the whole
    /// glossy BSDF); dielectrics ignore it.
    pub color: Option<TextureRef>,
    /// Multiplies the emitted radiance.
    pub emission: Option<TextureRef>,
    /// Perturbs the shading normal.
    pub normal: Option<NormalMap>,
    /// Cuts the surface out where it is transparent.
    pub alpha: Option<Alpha>,
    /// Chooses the scattering model per texel (glTF `metallicRoughnessTexture`).
    pub metallic_roughness: Option<MetallicRoughness>,
}

impl MaterialTextures {
    /// Whether nothing is textured.
    pub fn is_empty(&self) -> bool {
        self.color.is_none()
            && self.emission.is_none()
            && self.normal.is_none()
            && self.alpha.is_none()
            && self.metallic_roughness.is_none()
    }

    /// What the textures modulate, for reports: `color`, `emission`, `normal`, `alpha` (an
    /// alpha without a texture is a constant cut-out and counts too).
    pub fn uses(&self) -> Vec<&'static str> {
        [
            (self.color.is_some(), "color"),
            (self.emission.is_some(), "emission"),
            (self.normal.is_some(), "normal"),
            (self.alpha.is_some(), "alpha"),
            (self.metallic_roughness.is_some(), "metallic-roughness"),
        ]
        .into_iter()
        .filter_map(|(used, name)| used.then_some(name))
        .collect()
    }

    /// Every texture reference, for reports.
    pub fn references(&self) -> impl Iterator<Item = &TextureRef> {
        self.color
            .iter()
            .chain(&self.emission)
            .chain(self.normal.iter().map(|n| &n.texture))
            .chain(self.alpha.iter().filter_map(|a| a.texture.as_ref()))
            .chain(self.metallic_roughness.iter().map(|m| &m.texture))
    }

    /// Whether the surface is present at `uv` for a ray whose hash (uniform in [0, 1)) is `u`.
    #[inline]
    pub(crate) fn opaque(&self, uv: Vec2, u: f32) -> bool {
        let Some(alpha) = &self.alpha else {
            return true;
        };
        let a = alpha.factor * alpha.texture.as_ref().map_or(1.0, |t| t.alpha(uv));
        match alpha.mode {
            AlphaMode::Mask { cutoff } => a >= cutoff,
            AlphaMode::Blend => u < a,
        }
    }
}

impl Fingerprint for TextureRef {
    /// The image by file and size (not its texels), and how it is read.
    fn fingerprint(&self, h: &mut Fingerprinter) {
        h.str(&self.image.path().to_string_lossy());
        let (width, height) = self.image.resolution();
        h.u32(width);
        h.u32(height);
        h.u32(u32::from(self.srgb));
        self.wrap.iter().for_each(|&m| h.u32(m as u32));
        self.transform.iter().for_each(|&c| h.f32(c));
    }
}

impl Fingerprint for MaterialTextures {
    /// Each use's texture (or its absence), with the use's own parameters.
    fn fingerprint(&self, h: &mut Fingerprinter) {
        let mut texture = |r: Option<&TextureRef>| h.option(r, |h, r| h.add(r));
        texture(self.color.as_ref());
        texture(self.emission.as_ref());
        texture(self.normal.as_ref().map(|n| &n.texture));
        texture(self.alpha.as_ref().and_then(|a| a.texture.as_ref()));
        texture(self.metallic_roughness.as_ref().map(|m| &m.texture));
        if let Some(n) = &self.normal {
            h.f32(n.scale);
        }
        if let Some(a) = &self.alpha {
            h.f32(a.factor);
            match a.mode {
                AlphaMode::Mask { cutoff } => {
                    h.str("mask");
                    h.f32(cutoff);
                }
                AlphaMode::Blend => h.str("blend"),
            }
        }
        if let Some(mr) = &self.metallic_roughness {
            h.vec3(mr.base);
            h.f32(mr.metallic);
            h.f32(mr.roughness);
        }
    }
}

#[cfg(test)]
mod tests;
