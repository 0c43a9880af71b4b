//! glTF materials and their textures (the mapping of `gltf.rs`'s module documentation): the
//! metallic-roughness model mapped to the scene's models, emission, normal maps, cut-outs and
//! the images they read, once each.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::Vec3;
use scene::texture::{
    Alpha, AlphaMode, MaterialTextures, MetallicRoughness, NormalMap, TextureRef, Wrap,
};
use scene::{Material, MaterialKind};

use crate::error::{LoadError, gltf_error};
use crate::image_file::TextureCache;

/// The glTF default material: base colour 1, metallic 1, roughness 1.
pub(super) fn default_material() -> Material {
    Material {
        name: "default".to_owned(),
        kind: MaterialKind::Glossy(scene::Glossy {
            reflectance: Vec3::ONE,
            roughness: 1.0,
            diffuse: Vec3::ZERO,
        }),
        emission: Vec3::ZERO,
        textures: None,
        spectra: None,
    }
}

/// The images of a glTF file's textures, read once each.
pub(super) struct Textures<'a> {
    pub(super) path: &'a Path,
    pub(super) dir: Option<&'a Path>,
    pub(super) buffers: &'a [gltf::buffer::Data],
    pub(super) cache: TextureCache,
    pub(super) warnings: Vec<String>,
}

impl Textures<'_> {
    /// The name under which an image held inside the file (a buffer view or a `data:` URI) is
    /// cached and named in errors: `FILE#imageN`.
    fn embedded_key(&self, index: usize) -> PathBuf {
        PathBuf::from(format!("{}#image{index}", self.path.display()))
    }

    /// The texture `tex` as a colour (`srgb`) or data texture with its sampler's wrap modes and
    /// the transform of `KHR_texture_transform`. The image is a file beside the glTF file, a
    /// base64 `data:` URI or a buffer view (GLB).
    fn get(
        &mut self,
        tex: &gltf::Texture<'_>,
        srgb: bool,
        transform: Option<gltf::texture::TextureTransform<'_>>,
    ) -> Result<TextureRef, LoadError> {
        let image = tex.source();
        let image = match image.source() {
            gltf::image::Source::Uri { uri, .. } => {
                if let Some(rest) = uri.strip_prefix("data:") {
                    let bytes =
                        crate::gltf_document::image_data_uri(self.path, image.index(), rest)?;
                    self.cache
                        .load_bytes(&self.embedded_key(image.index()), &bytes)?
                } else {
                    let file = self.dir.unwrap_or(Path::new("")).join(percent_decode(uri));
                    self.cache.load(&file)?
                }
            }
            gltf::image::Source::View { view, .. } => {
                let key = self.embedded_key(image.index());
                let bytes = self
                    .buffers
                    .get(view.buffer().index())
                    .and_then(|b| b.0.get(view.offset()..view.offset() + view.length()))
                    .ok_or_else(|| {
                        gltf_error(
                            self.path,
                            format!("image {} lies outside its buffer", image.index()),
                        )
                    })?;
                self.cache.load_bytes(&key, bytes)?
            }
        };
        let wrap = |mode: gltf::texture::WrappingMode| match mode {
            gltf::texture::WrappingMode::Repeat => Wrap::Repeat,
            gltf::texture::WrappingMode::MirroredRepeat => Wrap::Mirror,
            gltf::texture::WrappingMode::ClampToEdge => Wrap::Clamp,
        };
        let sampler = tex.sampler();
        let mut texture = TextureRef::new(image, srgb);
        texture.wrap = [wrap(sampler.wrap_s()), wrap(sampler.wrap_t())];
        if let Some(t) = transform {
            // KHR_texture_transform: uv' = T·R·S·uv.
            let ([ox, oy], r, [sx, sy]) = (t.offset(), t.rotation(), t.scale());
            let (sin, cos) = r.sin_cos();
            let m = [cos * sx, sin * sy, -sin * sx, cos * sy, ox, oy];
            if m.iter().all(|v| v.is_finite()) {
                texture.transform = m;
            }
        }
        Ok(texture)
    }
}

/// A URI's `%XX` escapes decoded (glTF URIs are percent-encoded: `a%20b.png`).
fn percent_decode(uri: &str) -> String {
    let bytes = uri.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        let hex = |b: u8| (b as char).to_digit(16);
        if bytes[i] == b'%'
            && let (Some(&h), Some(&l)) = (bytes.get(i + 1), bytes.get(i + 2))
            && let (Some(h), Some(l)) = (hex(h), hex(l))
        {
            out.push((h * 16 + l) as u8);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// The material and the texture-coordinate set its textures read (the base colour's, else
/// the first texture's).
///
/// Textures: the base colour texture multiplies the base colour (and its alpha the alpha);
/// the emissive texture the emission; the normal texture perturbs the shading normal; the
/// metallic-roughness texture decides the kind and the roughness per texel (metallic × blue,
/// roughness × green, see [`MetallicRoughness`]), its mean the material's own kind (what
/// reports show). `MASK` cuts the surface out below `alphaCutoff`, `BLEND` keeps it with
/// probability alpha.
pub(super) fn material(
    m: &gltf::Material<'_>,
    index: usize,
    textures: &mut Textures<'_>,
) -> Result<(Material, u32), LoadError> {
    let pbr = m.pbr_metallic_roughness();
    let [r, g, b, alpha_factor] = pbr.base_color_factor();
    let base = Vec3::new(r, g, b);
    let (metallic_factor, roughness_factor) = (pbr.metallic_factor(), pbr.roughness_factor());
    let (mut metallic, mut roughness) = (metallic_factor, roughness_factor);
    let mut uv_sets = Vec::new();
    let mut maps = MaterialTextures::default();
    let transmission = m.transmission().map_or(0.0, |t| t.transmission_factor());
    if let Some(info) = pbr.metallic_roughness_texture() {
        uv_sets.push(info.tex_coord());
        let texture = textures.get(&info.texture(), false, info.texture_transform())?;
        // The material's own kind (what reports show) follows the texture's mean; hits take
        // their texel's (transmission wins over both).
        let mean = texture.image.mean(false);
        metallic *= mean.z;
        roughness *= mean.y;
        if transmission <= 0.0 {
            maps.metallic_roughness = Some(MetallicRoughness {
                texture,
                base,
                metallic: metallic_factor,
                roughness: roughness_factor,
            });
        }
    }
    let kind = if transmission > 0.0 {
        MaterialKind::Dielectric(scene::Dielectric {
            ior: m.ior().unwrap_or(1.5),
        })
    } else {
        MetallicRoughness::kind(base, metallic, roughness)
    };
    let emission = Vec3::from(m.emissive_factor()) * m.emissive_strength().unwrap_or(1.0);
    let base_info = pbr.base_color_texture();
    if let Some(info) = &base_info {
        uv_sets.insert(0, info.tex_coord());
        maps.color = Some(textures.get(&info.texture(), true, info.texture_transform())?);
    }
    if let Some(info) = m.emissive_texture()
        && emission != Vec3::ZERO
    {
        uv_sets.push(info.tex_coord());
        maps.emission = Some(textures.get(&info.texture(), true, info.texture_transform())?);
    }
    if let Some(normal) = m.normal_texture() {
        uv_sets.push(normal.tex_coord());
        maps.normal = Some(NormalMap {
            texture: textures.get(&normal.texture(), false, None)?,
            scale: normal.scale(),
        });
    }
    let alpha_texture = maps.color.clone().filter(|t| t.image.has_alpha());
    let mode = match m.alpha_mode() {
        gltf::material::AlphaMode::Opaque => None,
        gltf::material::AlphaMode::Mask => Some(AlphaMode::Mask {
            cutoff: m.alpha_cutoff().unwrap_or(0.5),
        }),
        gltf::material::AlphaMode::Blend => {
            (alpha_texture.is_some() || alpha_factor < 1.0).then_some(AlphaMode::Blend)
        }
    };
    maps.alpha = mode.map(|mode| Alpha {
        texture: alpha_texture,
        factor: alpha_factor,
        mode,
    });
    let uv_set = uv_sets.first().copied().unwrap_or(0);
    if uv_sets.iter().any(|&s| s != uv_set) {
        textures.warnings.push(format!(
            "material {index} reads several texture-coordinate sets; all its textures use set {uv_set}"
        ));
    }
    let material = Material {
        name: m
            .name()
            .map_or_else(|| format!("material {index}"), str::to_owned),
        kind,
        emission,
        textures: (!maps.is_empty()).then(|| Arc::new(maps)),
        spectra: None,
    };
    Ok((material, uv_set))
}
