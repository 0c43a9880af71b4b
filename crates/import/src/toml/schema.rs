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
        /// A number, or (extension) a named glass or a dispersion law.
        ior: IorToml,
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
    /// Extension: a conductor with exact Fresnel (`docs/scene-format-extensions.md`).
    Conductor {
        /// A named metal (`Au`, `metal-Au`, or one of Mitsuba's RGB conductors).
        metal: Option<String>,
        /// η as a colour or a spectrum (with `k`, instead of `metal`).
        eta: Option<ColorToml>,
        /// k as a colour or a spectrum.
        k: Option<ColorToml>,
        /// A tint multiplying the Fresnel reflectance (1 by default).
        specular_reflectance: Option<ColorToml>,
        /// GGX α; absent or 0 is the smooth conductor.
        roughness: Option<f32>,
        emission: Option<ColorToml>,
        cutout: Option<String>,
    },
}

/// An index of refraction (extension beyond a number): a named glass (`"glass-BK7"`), or
/// `{ sellmeier = [B1, B2, B3, C1, C2, C3] }` (C in µm²), `{ cauchy = [A, B] }` or
/// `[A, B, C]` (B in µm², C in µm⁴), `{ samples = [[nm, n], …] }`.
#[derive(Deserialize)]
#[serde(untagged)]
pub(super) enum IorToml {
    Number(f32),
    Named(String),
    Law(IorLawToml),
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct IorLawToml {
    pub(super) sellmeier: Option<Vec<f64>>,
    pub(super) cauchy: Option<Vec<f64>>,
    pub(super) samples: Option<Vec<[f64; 2]>>,
}

/// The spectrum forms of a colour (extension): exactly one of `blackbody` (K), `illuminant`
/// (`"D65"`, `"A"`), `samples` ([[nm, value], …]) or `rgb`, with an optional `scale`.
#[derive(Default)]
pub(super) struct SpectrumToml {
    pub(super) blackbody: Option<f64>,
    pub(super) illuminant: Option<String>,
    pub(super) samples: Option<Vec<[f64; 2]>>,
    pub(super) rgb: Option<[f32; 3]>,
    pub(super) scale: Option<f64>,
}

/// A colour: `[r, g, b]`, or (extension, `docs/scene-format-extensions.md`) an image texture
/// `{ texture = "file.png", scale = [r, g, b] }`.
pub(super) enum ColorToml {
    Rgb([f32; 3]),
    Texture {
        texture: String,
        scale: Option<[f32; 3]>,
    },
    /// Extension: a spectrum (`docs/scene-format-extensions.md`, "Spectra").
    Spectrum(Box<SpectrumToml>),
}

/// A colour's table form: a texture or a spectrum, told apart by their keys.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ColourTableToml {
    texture: Option<String>,
    scale: Option<ScaleToml>,
    blackbody: Option<f64>,
    illuminant: Option<String>,
    samples: Option<Vec<[f64; 2]>>,
    rgb: Option<[f32; 3]>,
}

#[derive(Deserialize)]
#[serde(untagged)]
enum ScaleToml {
    Number(f64),
    Rgb([f32; 3]),
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
                use serde::de::Error;
                let t = ColourTableToml::deserialize(
                    serde::de::value::MapAccessDeserializer::new(map),
                )?;
                if let Some(texture) = t.texture {
                    if t.blackbody.is_some()
                        || t.illuminant.is_some()
                        || t.samples.is_some()
                        || t.rgb.is_some()
                    {
                        return Err(A::Error::custom(
                            "a texture cannot be given with a spectrum",
                        ));
                    }
                    let scale = match t.scale {
                        None => None,
                        Some(ScaleToml::Rgb(s)) => Some(s),
                        Some(ScaleToml::Number(_)) => {
                            return Err(A::Error::custom(
                                "a texture's scale is a colour [r, g, b]",
                            ));
                        }
                    };
                    return Ok(ColorToml::Texture { texture, scale });
                }
                let scale = match t.scale {
                    None => None,
                    Some(ScaleToml::Number(s)) => Some(s),
                    Some(ScaleToml::Rgb(_)) => {
                        return Err(A::Error::custom("a spectrum's scale is a number"));
                    }
                };
                let given = [
                    t.blackbody.is_some(),
                    t.illuminant.is_some(),
                    t.samples.is_some(),
                    t.rgb.is_some(),
                ];
                if given.iter().filter(|&&g| g).count() != 1 {
                    return Err(A::Error::custom(
                        "a colour table needs `texture` or exactly one of `blackbody`, \
                         `illuminant`, `samples`, `rgb`",
                    ));
                }
                Ok(ColorToml::Spectrum(Box::new(SpectrumToml {
                    blackbody: t.blackbody,
                    illuminant: t.illuminant,
                    samples: t.samples,
                    rgb: t.rgb,
                    scale,
                })))
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
