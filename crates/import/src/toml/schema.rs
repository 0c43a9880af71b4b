//! The file as serde reads it: one struct per table, `deny_unknown_fields`.

use serde::Deserialize;
use std::collections::BTreeMap;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct SceneFile {
    #[allow(dead_code, reason = "checked before the typed parse")]
    pub(super) format: ::toml::Value,
    pub(super) camera: Option<CameraToml>,
    pub(super) film: Option<FilmToml>,
    #[serde(default)]
    pub(super) materials: BTreeMap<String, MaterialToml>,
    #[serde(default)]
    pub(super) shapes: Vec<ShapeToml>,
    #[serde(default)]
    pub(super) lights: Vec<LightToml>,
    /// Extension: participating media by name (`docs/scene-format-extensions.md`).
    #[serde(default)]
    pub(super) media: BTreeMap<String, MediumToml>,
    pub(super) render: Option<RenderToml>,
}

/// A medium (extension): homogeneous, or with a density grid.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct MediumToml {
    pub(super) sigma_a: [f32; 3],
    pub(super) sigma_s: [f32; 3],
    pub(super) g: Option<f32>,
    pub(super) grid: Option<GridToml>,
}

/// A medium's density grid (extension): a Mitsuba `.vol` file or inline values, over an
/// axis-aligned box of the world.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct GridToml {
    pub(super) file: Option<String>,
    pub(super) size: Option<[u32; 3]>,
    pub(super) density: Option<Vec<f32>>,
    pub(super) min: Option<[f32; 3]>,
    pub(super) max: Option<[f32; 3]>,
    pub(super) edge: Option<String>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct CameraToml {
    pub(super) position: [f32; 3],
    pub(super) look_at: [f32; 3],
    pub(super) up: Option<[f32; 3]>,
    pub(super) fov_y: f32,
    pub(super) aperture_radius: Option<f32>,
    pub(super) focus_distance: Option<f32>,
    /// Extension: the medium the camera sits in.
    pub(super) medium: Option<String>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct FilmToml {
    pub(super) width: i64,
    pub(super) height: i64,
}

#[derive(Deserialize)]
#[serde(tag = "type", rename_all = "lowercase", deny_unknown_fields)]
pub(super) enum MaterialToml {
    Diffuse {
        albedo: ColorToml,
        emission: Option<ColorToml>,
        cutout: Option<String>,
    },
    Mirror {
        reflectance: Option<ColorToml>,
        emission: Option<ColorToml>,
        cutout: Option<String>,
    },
    Dielectric {
        ior: f32,
        /// Extension: GGX α of a rough dielectric (`docs/scene-format-extensions.md`).
        roughness: Option<f32>,
        emission: Option<ColorToml>,
    },
    Glossy {
        reflectance: ColorToml,
        roughness: f32,
        emission: Option<ColorToml>,
        cutout: Option<String>,
    },
    /// Extension: no scattering, a boundary of media.
    Interface {},
}

/// A colour: `[r, g, b]`, or (extension, `docs/scene-format-extensions.md`) an image texture
/// `{ texture = "file.png", scale = [r, g, b] }`.
pub(super) enum ColorToml {
    Rgb([f32; 3]),
    Texture {
        texture: String,
        scale: Option<[f32; 3]>,
    },
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TextureToml {
    texture: String,
    scale: Option<[f32; 3]>,
}

impl<'de> Deserialize<'de> for ColorToml {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Visitor;
        impl<'de> serde::de::Visitor<'de> for Visitor {
            type Value = ColorToml;
            fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str("an array of 3 numbers or a table { texture = \"file\" }")
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(
                self,
                seq: A,
            ) -> Result<ColorToml, A::Error> {
                <[f32; 3]>::deserialize(serde::de::value::SeqAccessDeserializer::new(seq))
                    .map(ColorToml::Rgb)
            }
            fn visit_map<A: serde::de::MapAccess<'de>>(
                self,
                map: A,
            ) -> Result<ColorToml, A::Error> {
                let t =
                    TextureToml::deserialize(serde::de::value::MapAccessDeserializer::new(map))?;
                Ok(ColorToml::Texture {
                    texture: t.texture,
                    scale: t.scale,
                })
            }
        }
        d.deserialize_any(Visitor)
    }
}

#[derive(Deserialize)]
#[serde(tag = "type", rename_all = "lowercase", deny_unknown_fields)]
pub(super) enum ShapeToml {
    Mesh {
        file: String,
        material: Option<String>,
        transform: Option<TransformToml>,
        /// Extension: the media inside and outside (`docs/scene-format-extensions.md`).
        interior: Option<String>,
        exterior: Option<String>,
    },
    Sphere {
        center: [f32; 3],
        radius: f32,
        material: String,
        interior: Option<String>,
        exterior: Option<String>,
    },
    Quad {
        corner: [f32; 3],
        edge1: [f32; 3],
        edge2: [f32; 3],
        material: String,
    },
    /// Extension to format 1 (`docs/scene-format-extensions.md`).
    Cylinder {
        center: [f32; 3],
        axis: Option<[f32; 3]>,
        radius: f32,
        height: f32,
        arc: Option<f32>,
        facing: Option<[f32; 3]>,
        material: String,
    },
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct TransformToml {
    pub(super) scale: Option<[f32; 3]>,
    pub(super) rotate: Option<[f32; 3]>,
    pub(super) translate: Option<[f32; 3]>,
}

#[derive(Deserialize)]
#[serde(tag = "type", rename_all = "lowercase", deny_unknown_fields)]
pub(super) enum LightToml {
    Point {
        position: [f32; 3],
        intensity: [f32; 3],
    },
    Spot {
        position: [f32; 3],
        direction: [f32; 3],
        intensity: [f32; 3],
        cone_angle: f32,
        falloff_start: Option<f32>,
    },
    Directional {
        direction: [f32; 3],
        irradiance: [f32; 3],
    },
    /// An extension (`docs/scene-format-extensions.md`): `file` or `radiance`.
    Environment {
        file: Option<String>,
        radiance: Option<[f32; 3]>,
        scale: Option<f32>,
        rotate: Option<[f32; 3]>,
    },
}

/// The `[render]` table: `passes`, and render parameters that `ppm` reads.
#[derive(Deserialize)]
pub(super) struct RenderToml {
    pub(super) passes: Option<u32>,
    #[serde(flatten)]
    pub(super) params: std::collections::BTreeMap<String, ::toml::Value>,
}
