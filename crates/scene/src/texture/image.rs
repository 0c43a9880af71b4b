//! Decoded images: 8-bit or float texels, checked once when an importer hands them over, and
//! their bilinear lookup.

use std::path::{Path, PathBuf};
#[cfg(test)]
use std::sync::Arc;
use std::sync::OnceLock;

use glam::{Vec2, Vec3, Vec4};

use super::Wrap;

/// A decoded image, loaded once per file and shared by every material that uses it. The
/// importers decode files into it ([`Image::new`]); nothing here reads a file.
#[derive(Clone)]
pub struct Image {
    path: PathBuf,
    width: u32,
    height: u32,
    texels: Texels,
    /// Whether the file has an alpha channel that masks something (some texel below ½);
    /// otherwise a cut-out reads the first channel (a grey mask).
    has_alpha: bool,
    /// [`Image::mean`] of the linear and the sRGB-decoded colours, computed on first use: every
    /// emissive triangle under an emission texture weighs itself with it.
    means: [OnceLock<Vec3>; 2],
}

/// The texels of an [`Image`], row-major from the top-left.
#[derive(Clone)]
pub enum Texels {
    /// 8-bit RGBA as stored in the file (sRGB-encoded or data).
    Bytes(Vec<[u8; 4]>),
    /// Linear RGBA floats (EXR, Radiance HDR).
    Floats(Vec<[f32; 4]>),
}

/// Why texels cannot make an [`Image`].
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ImageError {
    /// The image has no texels.
    #[error("texture has zero size ({width}x{height})")]
    ZeroSize {
        /// Width in texels.
        width: u32,
        /// Height in texels.
        height: u32,
    },
    /// The texel count is not width × height.
    #[error("texture of {width}x{height} texels holds {found} texels")]
    WrongLength {
        /// Width in texels.
        width: u32,
        /// Height in texels.
        height: u32,
        /// Texels given.
        found: usize,
    },
    /// A float texel is NaN or infinite.
    #[error("texture has a {} texel at ({x}, {y})", if *.nan { "nan" } else { "infinite" })]
    NotFinite {
        /// Column of the first such texel.
        x: u32,
        /// Row of the first such texel.
        y: u32,
        /// Whether it is a NaN (else an infinity).
        nan: bool,
    },
}

impl std::fmt::Debug for Image {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Image")
            .field("path", &self.path)
            .field("width", &self.width)
            .field("height", &self.height)
            .field("bytes", &self.memory())
            .finish()
    }
}

/// Two images are the same texture when they come from the same file.
impl PartialEq for Image {
    fn eq(&self, other: &Self) -> bool {
        self.path == other.path
    }
}

/// The sRGB transfer function, decoded, for each 8-bit value.
fn srgb_table() -> &'static [f32; 256] {
    static TABLE: std::sync::OnceLock<[f32; 256]> = std::sync::OnceLock::new();
    TABLE.get_or_init(|| {
        let mut t = [0.0; 256];
        for (i, v) in t.iter_mut().enumerate() {
            let c = f64::from(i as u8) / 255.0;
            *v = if c <= 0.04045 {
                c / 12.92
            } else {
                ((c + 0.055) / 1.055).powf(2.4)
            } as f32;
        }
        t
    })
}

impl Image {
    /// The image of `width` × `height` texels read from `path` (which names it in reports and
    /// tells two textures apart). `alpha_channel` says whether the file has an alpha channel:
    /// it counts as a mask only where some texel is below ½, since files whose mask is their
    /// grey channel often carry an all-but-opaque alpha channel as well.
    ///
    /// # Errors
    /// [`ImageError`] if the image is empty, the texels are not `width × height`, or a float
    /// texel is NaN or infinite.
    pub fn new(
        path: PathBuf,
        width: u32,
        height: u32,
        texels: Texels,
        alpha_channel: bool,
    ) -> Result<Self, ImageError> {
        if width == 0 || height == 0 {
            return Err(ImageError::ZeroSize { width, height });
        }
        let found = match &texels {
            Texels::Bytes(t) => t.len(),
            Texels::Floats(t) => t.len(),
        };
        if found as u64 != u64::from(width) * u64::from(height) {
            return Err(ImageError::WrongLength {
                width,
                height,
                found,
            });
        }
        if let Texels::Floats(t) = &texels
            && let Some(i) = t.iter().position(|t| !t.iter().all(|c| c.is_finite()))
        {
            return Err(ImageError::NotFinite {
                x: i as u32 % width,
                y: i as u32 / width,
                nan: t[i].iter().any(|c| c.is_nan()),
            });
        }
        let has_alpha = alpha_channel
            && match &texels {
                Texels::Bytes(t) => t.iter().any(|p| p[3] < 128),
                Texels::Floats(t) => t.iter().any(|p| p[3] < 0.5),
            };
        Ok(Self {
            path,
            width,
            height,
            texels,
            has_alpha,
            means: Default::default(),
        })
    }

    /// Whether the file's alpha channel masks something (some texel below ½); otherwise a
    /// cut-out reads the first channel (a grey mask).
    pub fn has_alpha(&self) -> bool {
        self.has_alpha
    }

    /// The file the image was read from.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Width and height in texels.
    pub fn resolution(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// Bytes the decoded texels take in memory.
    pub fn memory(&self) -> usize {
        match &self.texels {
            Texels::Bytes(t) => t.len() * 4,
            Texels::Floats(t) => t.len() * 16,
        }
    }

    /// Whether the texels are linear floats (EXR, HDR) rather than 8-bit values.
    pub fn is_float(&self) -> bool {
        matches!(self.texels, Texels::Floats(_))
    }

    /// Texel (x, y) (in range) as linear RGBA: colour channels of an 8-bit image through the
    /// sRGB curve if `srgb`, else divided by 255.
    #[inline]
    fn texel(&self, x: u32, y: u32, srgb: bool) -> Vec4 {
        let i = (y as usize) * (self.width as usize) + x as usize;
        match &self.texels {
            Texels::Bytes(t) => {
                let [r, g, b, a] = t[i];
                let alpha = f32::from(a) / 255.0;
                if srgb {
                    let lut = srgb_table();
                    Vec4::new(lut[r as usize], lut[g as usize], lut[b as usize], alpha)
                } else {
                    Vec4::new(f32::from(r), f32::from(g), f32::from(b), f32::from(a)) / 255.0
                }
            }
            Texels::Floats(t) => Vec4::from(t[i]),
        }
    }

    /// Bilinear lookup at texture coordinates `uv` with the wrap modes of `wrap`.
    pub(super) fn bilinear(&self, uv: Vec2, wrap: [Wrap; 2], srgb: bool) -> Vec4 {
        let x = uv.x * self.width as f32 - 0.5;
        let y = uv.y * self.height as f32 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        if !(fx.is_finite() && fy.is_finite()) {
            return self.texel(0, 0, srgb);
        }
        // `as` saturates a coordinate beyond the range of i64 (a texture coordinate of 10³⁰ from
        // a mesh file), and so must the next texel's index.
        let (x0, y0) = (x0 as i64, y0 as i64);
        let xs = [
            wrap[0].index(x0, self.width),
            wrap[0].index(x0.saturating_add(1), self.width),
        ];
        let ys = [
            wrap[1].index(y0, self.height),
            wrap[1].index(y0.saturating_add(1), self.height),
        ];
        let t = |i: usize, j: usize| self.texel(xs[i], ys[j], srgb);
        (t(0, 0) * (1.0 - fx) + t(1, 0) * fx) * (1.0 - fy)
            + (t(0, 1) * (1.0 - fx) + t(1, 1) * fx) * fy
    }

    /// The mean of the image's colour channels (linear, sRGB-decoded if `srgb`).
    pub fn mean(&self, srgb: bool) -> Vec3 {
        *self.means[usize::from(srgb)].get_or_init(|| self.mean_of_texels(srgb))
    }

    fn mean_of_texels(&self, srgb: bool) -> Vec3 {
        let mut sum = glam::DVec3::ZERO;
        for y in 0..self.height {
            for x in 0..self.width {
                sum += self.texel(x, y, srgb).truncate().as_dvec3();
            }
        }
        (sum / (f64::from(self.width) * f64::from(self.height))).as_vec3()
    }
}

/// An 8-bit image held in memory, for tests (alpha counts as in a file).
#[cfg(test)]
pub(crate) fn test_image(width: u32, height: u32, texels: Vec<[u8; 4]>) -> Arc<Image> {
    let has_alpha = texels.iter().any(|t| t[3] < 128);
    Arc::new(Image {
        path: PathBuf::from(format!("test-{width}x{height}.png")),
        width,
        height,
        texels: Texels::Bytes(texels),
        has_alpha,
        means: Default::default(),
    })
}
