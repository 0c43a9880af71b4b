//! What textures change at a hit: the scattering colour, the emission, the shading normal and
//! whether the surface is there at all (cut-outs). Untextured materials skip all of it: the
//! scene knows whether any material has a normal map or a cut-out and tests nothing otherwise.

use glam::{Vec2, Vec3};

use super::Scene;
use crate::texture::{MaterialTextures, TextureRef};
use crate::{Bsdf, Hit, Material, Primitive, Ray, Rgb};

impl Scene {
    /// The texture coordinates at `hit`: the triangle's interpolated texture coordinates (its
    /// barycentrics if it has none), a sphere's (φ/2π, θ/π) about +z, a cylinder's (arc, height).
    #[inline]
    pub fn texture_uv(&self, hit: &Hit) -> Vec2 {
        match hit.primitive {
            Primitive::Triangle(i) => {
                triangle_uv(&self.description.triangles[i as usize], hit.uv.x, hit.uv.y)
            }
            // A sphere's (φ/2π, θ/π), from the hit point: only textured hits need it, so the
            // hit itself does not pay the atan2 and acos.
            Primitive::Sphere(i) => {
                let s = &self.description.spheres[i as usize];
                let outward = (hit.position - s.center).normalize_or(Vec3::Z);
                let phi = outward.y.atan2(outward.x).rem_euclid(std::f32::consts::TAU);
                let theta = outward.z.clamp(-1.0, 1.0).acos();
                Vec2::new(phi / std::f32::consts::TAU, theta / std::f32::consts::PI)
            }
            Primitive::Cylinder(_) => hit.uv,
        }
    }

    /// The textures of material `idx`, if it has any.
    #[inline]
    fn textures(&self, idx: u32) -> Option<&MaterialTextures> {
        self.material(idx).and_then(|m| m.textures.as_deref())
    }

    /// The BSDF of `material` at `hit` (whose material it is), with its colour texture.
    /// Inlined into the photon loop for untextured materials, where an outlined call would be
    /// a noticeable share of a photon path (docs/performance.md); the textured case out of line.
    #[inline(always)]
    pub fn material_bsdf(&self, material: &Material, hit: &Hit) -> Bsdf {
        match material.textures.as_deref().and_then(|t| t.color.as_ref()) {
            None => Bsdf::new(material, hit),
            Some(color) => self.textured_bsdf(material, hit, color),
        }
    }

    #[inline(never)]
    fn textured_bsdf(&self, material: &Material, hit: &Hit, color: &TextureRef) -> Bsdf {
        let tint = color.color(self.texture_uv(hit));
        Bsdf::tinted(material.kind, hit.shading_normal, hit.front_face, tint)
    }

    /// The colour by which a texture multiplies the material's scattering at `hit` (one when
    /// untextured): what a hitpoint stores in its weight, so that the photon gather, which
    /// evaluates the untextured material, gets the textured one.
    #[inline]
    pub fn scattering_tint(&self, hit: &Hit) -> Rgb {
        match self.textures(hit.material).and_then(|t| t.color.as_ref()) {
            None => Rgb::ONE,
            Some(color) => color.color(self.texture_uv(hit)),
        }
    }

    /// The emission of `material` at `hit`, with its emission texture.
    #[inline]
    pub(super) fn textured_emission(&self, material: &Material, hit: &Hit) -> Rgb {
        match material
            .textures
            .as_deref()
            .and_then(|t| t.emission.as_ref())
        {
            None => material.emission,
            Some(e) => material.emission * e.color(self.texture_uv(hit)),
        }
    }

    /// Applies the material's normal map, if any, to the shading normal of a triangle hit.
    ///
    /// The tangent frame is the file's where the triangle has vertex tangents (glTF
    /// `TANGENT`): T interpolated like the normals and made perpendicular to the interpolated
    /// normal N, B = w·(N × T) with w the sign of the interpolated handedness (glTF 2.0,
    /// "Meshes"). Otherwise it is the triangle's: T = ∂p/∂u made perpendicular to N, B = −∂p/∂v
    /// (texture v grows downwards while a normal map's green axis points up the image), on
    /// the side of N × T that ∂p/∂v says, so that mirrored texture coordinates keep the map's
    /// handedness. A perturbed normal that would face away from the geometric one is not used.
    pub(super) fn apply_normal_map(&self, hit: &mut Hit) {
        let Primitive::Triangle(i) = hit.primitive else {
            return;
        };
        let tri = &self.description.triangles[i as usize];
        let Some(map) = self.textures(hit.material).and_then(|t| t.normal.as_ref()) else {
            return;
        };
        if tri.uv.is_none() {
            return;
        }
        // The interpolated normal on the front side: the map is in the surface's own frame.
        let n = if hit.front_face {
            hit.shading_normal
        } else {
            -hit.shading_normal
        };
        let Some((t, b)) = vertex_tangent_frame(tri, hit.uv, n).or_else(|| triangle_frame(tri, n))
        else {
            return;
        };
        let texel = map.texture.lookup(self.texture_uv(hit)).truncate() * 2.0 - Vec3::ONE;
        let local = Vec3::new(texel.x * map.scale, texel.y * map.scale, texel.z);
        let Some(mapped) = (local.x * t + local.y * b + local.z * n).try_normalize() else {
            return;
        };
        let mapped = if hit.front_face { mapped } else { -mapped };
        if mapped.dot(hit.geometric_normal) > 0.0 {
            hit.shading_normal = mapped;
        }
    }

    /// Turns the material of a hit on a metallic-roughness texture into the variant its texel
    /// chooses.
    pub(super) fn apply_metallic_roughness(&self, hit: &mut Hit) {
        let Some(&Some(first)) = self.variant_first.get(hit.material as usize) else {
            return;
        };
        let Some(mr) = self
            .textures(hit.material)
            .and_then(|t| t.metallic_roughness.as_ref())
        else {
            return;
        };
        hit.material = first + mr.variant(self.texture_uv(hit));
    }

    /// Whether triangle `index` is present at barycentrics (b1, b2) for `ray` (its material's
    /// cut-out test; a blend cut-out decides by a hash of the ray, so that a ray meets the same
    /// surface every time it is traced).
    pub(super) fn covered(&self, ray: &Ray, index: u32, b1: f32, b2: f32) -> bool {
        let tri = &self.description.triangles[index as usize];
        let Some(textures) = self.textures(tri.material) else {
            return true;
        };
        textures.opaque(triangle_uv(tri, b1, b2), ray_hash(ray, index))
    }
}

/// The frame (T, B) of a triangle's vertex tangents at barycentrics `b` = (b1, b2) about the unit
/// normal `n`: T = Σ bᵢ·Tᵢ made perpendicular to `n`, B = w·(n × T) with w the sign of
/// Σ bᵢ·wᵢ. `None` without vertex tangents or where T is parallel to `n`.
fn vertex_tangent_frame(tri: &crate::Triangle, b: Vec2, n: Vec3) -> Option<(Vec3, Vec3)> {
    let [t0, t1, t2] = tri.tangents?.map(glam::Vec4::from_array);
    let t = (1.0 - b.x - b.y) * t0 + b.x * t1 + b.y * t2;
    let sign = if t.w < 0.0 { -1.0 } else { 1.0 };
    let xyz = t.truncate();
    let t = (xyz - n * n.dot(xyz)).try_normalize()?;
    Some((t, sign * n.cross(t)))
}

/// A triangle's own tangent frame (T, B) from its texture coordinates about the unit normal
/// `n`: T = ∂p/∂u made perpendicular to `n`, B = ±(n × T) on the side of −∂p/∂v. `None`
/// without texture coordinates, for a degenerate parametrisation, or where ∂p/∂u is parallel
/// to `n`.
fn triangle_frame(tri: &crate::Triangle, n: Vec3) -> Option<(Vec3, Vec3)> {
    let [uv0, uv1, uv2] = tri.uv?;
    let [p0, p1, p2] = tri.positions;
    let (duv02, duv12) = (uv0 - uv2, uv1 - uv2);
    let (dp02, dp12) = (p0 - p2, p1 - p2);
    let det = duv02.x * duv12.y - duv02.y * duv12.x;
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let dpdu = (duv12.y * dp02 - duv02.y * dp12) / det;
    let dpdv = (duv02.x * dp12 - duv12.x * dp02) / det;
    let t = (dpdu - n * n.dot(dpdu)).try_normalize()?;
    let b = n.cross(t);
    Some((t, if b.dot(-dpdv) < 0.0 { -b } else { b }))
}

/// The variants of the materials with a metallic-roughness texture: per material the index
/// of its first variant (empty if there are none) and the variants, numbered after
/// `materials`. A variant is the material with another kind: the same name (with the
/// variant's number), emission and textures.
pub(super) fn material_variants(materials: &[Material]) -> (Vec<Option<u32>>, Vec<Material>) {
    let mut first = vec![None; materials.len()];
    let mut variants = Vec::new();
    for (i, m) in materials.iter().enumerate() {
        let Some(mr) = m
            .textures
            .as_deref()
            .and_then(|t| t.metallic_roughness.as_ref())
        else {
            continue;
        };
        first[i] = Some((materials.len() + variants.len()) as u32);
        variants.extend(
            mr.variant_kinds()
                .into_iter()
                .enumerate()
                .map(|(k, kind)| Material {
                    name: format!("{} (texel variant {k})", m.name),
                    kind,
                    ..m.clone()
                }),
        );
    }
    if variants.is_empty() {
        first.clear();
    }
    (first, variants)
}

/// Whether a material's textures cut its surface out anywhere.
pub(super) fn has_cutout(textures: Option<&MaterialTextures>) -> bool {
    textures.is_some_and(|t| t.alpha.is_some())
}

/// The texture coordinates of a triangle at barycentrics (b1, b2).
#[inline]
fn triangle_uv(tri: &crate::Triangle, b1: f32, b2: f32) -> Vec2 {
    match tri.uv {
        Some([uv0, uv1, uv2]) => (1.0 - b1 - b2) * uv0 + b1 * uv1 + b2 * uv2,
        None => Vec2::new(b1, b2),
    }
}

/// A number in [0, 1) that depends on the ray and the triangle only (a 64-bit mix of their
/// bits), the random number of a stochastic cut-out.
fn ray_hash(ray: &Ray, index: u32) -> f32 {
    let mut h = u64::from(index) ^ 0x9e37_79b9_7f4a_7c15;
    for v in [ray.origin, ray.direction] {
        for c in v.to_array() {
            h = (h ^ u64::from(c.to_bits())).wrapping_mul(0xff51_afd7_ed55_8ccd);
            h ^= h >> 33;
        }
    }
    h = h.wrapping_mul(0xc4ce_b9fe_1a85_ec53);
    h ^= h >> 33;
    (h >> 40) as f32 / (1u64 << 24) as f32
}
