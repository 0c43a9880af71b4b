//! The environment light: radiance arriving from infinitely far away in every direction,
//! constant or given by an equirectangular (latitude-longitude) HDR image.
//!
//! Orientation is Mitsuba 3's `envmap` (`src/emitters/envmap.cpp`), so that one file lights
//! both renderers alike: in the map's own frame +y is up, and the direction
//! d = (sin φ sin θ, cos θ, −cos φ sin θ) looks at u = φ / 2π (from the image's left edge) and
//! v = θ / π (from its top row). The top row is the sky straight up, the centre column looks
//! toward +z, the left and right edges toward −z, a quarter of the width toward +x.
//! [`Environment::to_world`] turns that frame into world space (the TOML `rotate = [x, y, z]`:
//! degrees about x, then y, then z, as a shape transform; Mitsuba's `to_world`).
//!
//! Radiance is interpolated bilinearly between texels exactly as Mitsuba's `eval_spectrum` does:
//! column x sits at u = (x + ½)/W, wrapping around, and row y at v = y/(H − 1), so that the first
//! and last rows lie on the poles. (Until 2026-12-07 fppm took each texel's value over its whole
//! cell: the sky seen directly then differed from Mitsuba's by 3.6 % per pixel on average, which
//! no amount of sampling removes.)
//!
//! Next-event estimation draws directions with density ∝ luminance × sin θ over the
//! interpolation's patches (the W × (H − 1) rectangles between four texels, [`MapSampler`]): a
//! marginal over rows, then a conditional within the row, each piecewise constant and inverted
//! continuously; the density in solid angle is p(u, v) / (2π² sin θ). A patch's weight is the
//! mean of its corners' luminance, the interpolation's mean over it, so the density is positive
//! exactly where there is light and the estimates, which divide the interpolated radiance by it,
//! are unbiased. A constant sky is sampled uniformly.
//! Photons start on a disc of the scene's bounding radius r perpendicular to a direction drawn
//! the same way, outside the scene (pbrt-v4's `ImageInfiniteLight::SampleLe`), so the emitted
//! power is π r² ∫ L dω.

use std::f32::consts::PI;
use std::path::PathBuf;
use std::sync::Arc;

use glam::{Mat3, Vec2, Vec3};

use crate::fingerprint::{Fingerprint, Fingerprinter};
use crate::material::luminance;
use crate::sampling::{concentric_disk, uniform_sphere};
use crate::{Aabb, Frame, Rgb};

/// An environment light as a scene describes it.
#[derive(Clone, Debug, PartialEq)]
pub struct Environment {
    /// What the sky looks like before `scale`.
    pub radiance: EnvironmentRadiance,
    /// Factor on the radiance (≥ 0).
    pub scale: f32,
    /// Rotation from the map's frame into world space (orthonormal, determinant 1).
    pub to_world: Mat3,
}

/// The radiance of an [`Environment`].
#[derive(Clone, Debug, PartialEq)]
pub enum EnvironmentRadiance {
    /// The same radiance (W/(sr·m²) per channel) from every direction.
    Constant(Rgb),
    /// An equirectangular image.
    Map(Arc<EnvironmentMap>),
}

/// An equirectangular HDR image, decoded: linear RGB, top row first, twice as wide as high.
#[derive(Clone, PartialEq)]
pub struct EnvironmentMap {
    /// The file it was read from.
    pub path: PathBuf,
    /// Width in texels (2 × height).
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// Row-major texels, each finite and non-negative.
    pub texels: Vec<Rgb>,
}

impl std::fmt::Debug for EnvironmentMap {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("EnvironmentMap")
            .field("path", &self.path)
            .field("width", &self.width)
            .field("height", &self.height)
            .finish_non_exhaustive()
    }
}

impl EnvironmentMap {
    /// The equirectangular map of twice `side` in height resampled, nearest texel as pbrt-v4
    /// looks it up, from a square equal-area octahedral map (pbrt-v4's `infinite` light) of
    /// `side` × `side` texels, row-major: the map's frame is pbrt's light frame with its x axis
    /// negated when `mirror_x` (for a light transform with a reflection).
    ///
    /// # Panics
    /// If `texels` holds fewer than `side × side` texels.
    #[must_use]
    pub fn from_equal_area(path: PathBuf, side: u32, texels: &[Rgb], mirror_x: bool) -> Self {
        let n = side as usize;
        let (w, h) = (4 * n, 2 * n);
        let mut out = Vec::with_capacity(w * h);
        for y in 0..h {
            for x in 0..w {
                let uv = Vec2::new((x as f32 + 0.5) / w as f32, (y as f32 + 0.5) / h as f32);
                let (mut d, _) = uv_to_direction(uv);
                if mirror_x {
                    d.x = -d.x;
                }
                let st = equal_area_sphere_to_square(d);
                let i = ((st.x * n as f32) as usize).min(n - 1);
                let j = ((st.y * n as f32) as usize).min(n - 1);
                out.push(texels[j * n + i]);
            }
        }
        Self {
            path,
            width: w as u32,
            height: h as u32,
            texels: out,
        }
    }
}

impl Fingerprint for Environment {
    /// The scale, the rotation and the radiance: a constant, or a map by its texels.
    fn fingerprint(&self, h: &mut Fingerprinter) {
        h.f32(self.scale);
        h.mat3(self.to_world);
        match &self.radiance {
            EnvironmentRadiance::Constant(c) => {
                h.u32(0);
                h.vec3(*c);
            }
            EnvironmentRadiance::Map(map) => {
                h.u32(1);
                h.u32(map.width);
                h.u32(map.height);
                map.texels.iter().for_each(|&t| h.vec3(t));
            }
        }
    }
}

impl Environment {
    /// The rotation of `rotate = [x, y, z]`: degrees about x, then y, then z (Rz·Ry·Rx).
    #[must_use]
    pub fn rotation_degrees(r: Vec3) -> Mat3 {
        Mat3::from_rotation_z(r.z.to_radians())
            * Mat3::from_rotation_y(r.y.to_radians())
            * Mat3::from_rotation_x(r.x.to_radians())
    }

    /// ∫ L dω over the sphere, per channel (W/m²), scale included.
    #[must_use]
    pub fn integrated_radiance(&self) -> Rgb {
        let sum = match &self.radiance {
            EnvironmentRadiance::Constant(c) => *c * (4.0 * PI),
            EnvironmentRadiance::Map(map) => {
                let (w, h) = (map.width as usize, map.height as usize);
                // Over u the periodic linear interpolation integrates to the row's mean; over v
                // the row means are interpolated linearly between the rows' positions
                // v_y = y/(H − 1), and ∫ sin(πv) against each hat is in closed form.
                let rows: Vec<glam::DVec3> = (0..h)
                    .map(|y| {
                        let sum: glam::DVec3 = map.texels[y * w..(y + 1) * w]
                            .iter()
                            .map(|t| t.as_dvec3())
                            .sum();
                        sum / w as f64
                    })
                    .collect();
                let pi = std::f64::consts::PI;
                // ∫ L dω = 2π² ∫ R(v) sin(πv) dv, R(v) the interpolated row mean.
                let total = if h == 1 {
                    rows[0] * (4.0 * pi)
                } else {
                    let dv = 1.0 / (h - 1) as f64;
                    let mut sum = glam::DVec3::ZERO;
                    for y in 0..h - 1 {
                        let (a, b) = (y as f64 * dv, (y + 1) as f64 * dv);
                        // ∫_a^b sin(πv) dv, and ∫_a^b (v − a)/(b − a) sin(πv) dv.
                        let whole = ((pi * a).cos() - (pi * b).cos()) / pi;
                        let rising = (-(b - a) * (pi * b).cos() / pi
                            + ((pi * b).sin() - (pi * a).sin()) / (pi * pi))
                            / dv;
                        sum += rows[y] * (whole - rising) + rows[y + 1] * rising;
                    }
                    sum * (2.0 * pi * pi)
                };
                total.as_vec3()
            }
        };
        sum * self.scale
    }

    /// A one-line description for reports: the file and its size, or the constant, with the
    /// scale and rotation.
    #[must_use]
    pub fn describe(&self) -> String {
        let mut text = match &self.radiance {
            EnvironmentRadiance::Constant(c) => {
                format!("constant radiance [{}, {}, {}]", c.x, c.y, c.z)
            }
            EnvironmentRadiance::Map(m) => format!(
                "{} ({}×{}, {:.1} MB)",
                m.path.file_name().map_or_else(
                    || m.path.display().to_string(),
                    |n| n.to_string_lossy().into()
                ),
                m.width,
                m.height,
                (m.texels.len() * std::mem::size_of::<Rgb>()) as f64 / 1e6
            ),
        };
        if self.scale != 1.0 {
            text.push_str(&format!(", scale {}", self.scale));
        }
        if self.to_world != Mat3::IDENTITY {
            // Rounded first, so that −0.0001 shows as 0.
            let show = |v: Vec3| {
                let r = (v * 1000.0).round() / 1000.0 + Vec3::ZERO;
                format!("[{}, {}, {}]", r.x, r.y, r.z)
            };
            text.push_str(&format!(
                ", rotated (up {}, centre {})",
                show(self.to_world * Vec3::Y),
                show(self.to_world * Vec3::Z)
            ));
        }
        text
    }
}

/// pbrt-v4's `EqualAreaSphereToSquare` (Clarberg 2008; `src/pbrt/util/math.cpp`) with the
/// exact arctangent in place of its polynomial: the point of [0, 1]² of a unit direction, +z at
/// the centre, −z at the corners, +x at the middle of the right edge, +y at the middle of the
/// bottom edge (rows counted from the top of the image).
fn equal_area_sphere_to_square(d: Vec3) -> Vec2 {
    let (x, y, z) = (d.x.abs(), d.y.abs(), d.z.abs());
    let r = (1.0 - z).max(0.0).sqrt();
    let (a, b) = (x.max(y), x.min(y));
    let b = if a == 0.0 { 0.0 } else { b / a };
    let mut phi = b.atan() * (2.0 / PI);
    if x < y {
        phi = 1.0 - phi;
    }
    let mut v = phi * r;
    let mut u = r - v;
    if d.z < 0.0 {
        std::mem::swap(&mut u, &mut v);
        u = 1.0 - u;
        v = 1.0 - v;
    }
    Vec2::new(0.5 * (u.copysign(d.x) + 1.0), 0.5 * (v.copysign(d.y) + 1.0))
}

/// Solid angle of row `y` of `h` rows: 2π (cos θ₀ − cos θ₁).
fn row_solid_angle(y: usize, h: usize) -> f64 {
    let t0 = std::f64::consts::PI * y as f64 / h as f64;
    let t1 = std::f64::consts::PI * (y + 1) as f64 / h as f64;
    std::f64::consts::TAU * (t0.cos() - t1.cos())
}

/// The map's direction (in its own frame) for image coordinates (u, v) ∈ [0, 1]²: θ = πv,
/// φ = 2πu, d = (sin φ sin θ, cos θ, −cos φ sin θ). Also returns sin θ.
#[inline]
fn uv_to_direction(uv: Vec2) -> (Vec3, f32) {
    let (sin_theta, cos_theta) = (PI * uv.y).sin_cos();
    let (sin_phi, cos_phi) = (2.0 * PI * uv.x).sin_cos();
    (
        Vec3::new(sin_phi * sin_theta, cos_theta, -cos_phi * sin_theta),
        sin_theta,
    )
}

/// Inverse of [`uv_to_direction`] for a unit direction: u ∈ [0, 1), v ∈ [0, 1].
#[inline]
fn direction_to_uv(d: Vec3) -> Vec2 {
    let u = d.x.atan2(-d.z) * (0.5 / PI);
    let u = u - u.floor();
    Vec2::new(
        if u < 1.0 { u } else { 0.0 },
        d.y.clamp(-1.0, 1.0).acos() / PI,
    )
}

/// The value of a `w` × `h` row-major image at `uv` interpolated bilinearly as Mitsuba 3's
/// `envmap` does (`eval_spectrum`): column x at u = (x + ½)/w, periodic in u; row y at
/// v = y/(h − 1), clamped.
#[inline]
fn bilinear<T>(texels: &[T], w: usize, h: usize, uv: Vec2) -> T
where
    T: Copy + std::ops::Mul<f32, Output = T> + std::ops::Add<Output = T>,
{
    let u = uv.x - 0.5 / w as f32;
    let x = (u - u.floor()) * w as f32;
    let x0 = (x as usize).min(w - 1);
    let fx = (x - x0 as f32).clamp(0.0, 1.0);
    let x1 = if x0 + 1 == w { 0 } else { x0 + 1 };
    let y = uv.y.clamp(0.0, 1.0) * h.saturating_sub(1) as f32;
    let y0 = (y as usize).min(h.saturating_sub(2));
    let fy = (y - y0 as f32).clamp(0.0, 1.0);
    let y1 = (y0 + 1).min(h - 1);
    let row = |y: usize| texels[y * w + x0] * (1.0 - fx) + texels[y * w + x1] * fx;
    row(y0) * (1.0 - fy) + row(y1) * fy
}

/// Continuous inversion of a piecewise-constant density on [0, 1) with `n` pieces, given its
/// cumulative distribution (`n + 1` values from 0 to exactly 1): the piece and the position in
/// [0, 1).
#[inline]
fn sample_piecewise(cdf: &[f32], u: f32) -> (usize, f32) {
    let n = cdf.len() - 1;
    let i = cdf.partition_point(|&c| c <= u).clamp(1, n) - 1;
    let width = cdf[i + 1] - cdf[i];
    let du = if width > 0.0 {
        ((u - cdf[i]) / width).clamp(0.0, 1.0)
    } else {
        0.5
    };
    let x = ((i as f32 + du) / n as f32).min(1.0 - f32::EPSILON);
    (i, x)
}

/// Cumulative distribution (`n + 1` entries, last exactly 1) of non-negative weights with a
/// positive sum.
fn cdf_of(weights: &[f64], sum: f64) -> Vec<f32> {
    let mut cdf = Vec::with_capacity(weights.len() + 1);
    let mut acc = 0.0;
    cdf.push(0.0);
    for &w in weights {
        acc += w;
        cdf.push((acc / sum) as f32);
    }
    // The last positive piece ends at exactly 1, and every piece after it too.
    if let Some(last) = weights.iter().rposition(|&w| w > 0.0) {
        for c in &mut cdf[last + 1..] {
            *c = 1.0;
        }
    }
    cdf
}

/// The sampling tables of an image map, over the patches of its bilinear interpolation: patch
/// (x, y) spans u ∈ [(x + ½)/W, (x + 1½)/W) (wrapping) and v ∈ [y/(H − 1), (y + 1)/(H − 1)),
/// between the texels at its four corners (one row of patches for a map one texel high).
#[derive(Clone, Debug)]
struct MapSampler {
    width: usize,
    height: usize,
    /// Rows of patches: H − 1, at least 1.
    rows: usize,
    /// Scaled radiance per texel.
    texels: Vec<Rgb>,
    /// Per patch: the mean of its corners' luminance (the interpolation's mean over it) × sin θ
    /// at its centre, divided by its mean over the patches: the density p on the unit square
    /// of patch coordinates.
    density: Vec<f32>,
    /// Cumulative distribution over rows of patches (`rows + 1` entries).
    marginal: Vec<f32>,
    /// Cumulative distribution within each row (`width + 1` entries per row).
    conditional: Vec<f32>,
    /// √(solid angle) of a patch per row: the angular width of the light it sends.
    texel_angle: Vec<f32>,
}

impl MapSampler {
    /// `None` when no texel has positive luminance.
    fn new(map: &EnvironmentMap, scale: f32) -> Option<Self> {
        let (w, h) = (map.width as usize, map.height as usize);
        let rows = h.saturating_sub(1).max(1);
        let lum: Vec<f64> = map
            .texels
            .iter()
            .map(|&t| f64::from(luminance(t).max(0.0)))
            .collect();
        let mut weights = vec![0.0f64; w * rows];
        let mut row_sums = vec![0.0f64; rows];
        for y in 0..rows {
            let sin_theta = (std::f64::consts::PI * (y as f64 + 0.5) / rows as f64).sin();
            let (y0, y1) = (y, (y + 1).min(h - 1));
            for x in 0..w {
                let x1 = (x + 1) % w;
                // A bilinear patch's mean is the mean of its corners; it is positive exactly
                // where the interpolated radiance is (up to the patch's edges).
                let corners =
                    lum[y0 * w + x] + lum[y0 * w + x1] + lum[y1 * w + x] + lum[y1 * w + x1];
                let l = 0.25 * corners * sin_theta;
                weights[y * w + x] = l;
                row_sums[y] += l;
            }
        }
        let total: f64 = row_sums.iter().sum();
        if !(total > 0.0 && total.is_finite()) {
            return None;
        }
        let mean = total / (w * rows) as f64;
        let mut conditional = Vec::with_capacity(rows * (w + 1));
        for y in 0..rows {
            let row = &weights[y * w..(y + 1) * w];
            if row_sums[y] > 0.0 {
                conditional.extend(cdf_of(row, row_sums[y]));
            } else {
                conditional.extend((0..=w).map(|x| x as f32 / w as f32));
            }
        }
        Some(Self {
            width: w,
            height: h,
            rows,
            texels: map.texels.iter().map(|&t| t * scale).collect(),
            density: weights.iter().map(|&l| (l / mean) as f32).collect(),
            marginal: cdf_of(&row_sums, total),
            conditional,
            texel_angle: (0..rows)
                .map(|y| (row_solid_angle(y, rows) / w as f64).sqrt() as f32)
                .collect(),
        })
    }

    /// Half a column: patch coordinates are image coordinates shifted by it.
    #[inline]
    fn half_texel(&self) -> f32 {
        0.5 / self.width as f32
    }

    /// The patch holding image coordinates `uv`.
    #[inline]
    fn patch_of(&self, uv: Vec2) -> usize {
        let u = uv.x - self.half_texel();
        let x = (((u - u.floor()) * self.width as f32) as usize).min(self.width - 1);
        let y = ((uv.y * self.rows as f32) as usize).min(self.rows - 1);
        y * self.width + x
    }

    /// The radiance at image coordinates `uv`, interpolated as Mitsuba does.
    #[inline]
    fn radiance(&self, uv: Vec2) -> Rgb {
        bilinear(&self.texels, self.width, self.height, uv)
    }

    /// A direction in the map's frame, its radiance, its patch and its solid-angle density.
    fn sample(&self, u: Vec2) -> Option<(Vec3, Rgb, usize, f32)> {
        let (y, v) = sample_piecewise(&self.marginal, u.x);
        let row = &self.conditional[y * (self.width + 1)..(y + 1) * (self.width + 1)];
        let (x, u) = sample_piecewise(row, u.y);
        let u = u + self.half_texel();
        let uv = Vec2::new(if u < 1.0 { u } else { u - 1.0 }, v);
        let (d, sin_theta) = uv_to_direction(uv);
        let patch = y * self.width + x;
        let pdf = self.density[patch] / (2.0 * PI * PI * sin_theta);
        (sin_theta > 0.0 && pdf > 0.0 && pdf.is_finite())
            .then(|| (d, self.radiance(uv), patch, pdf))
    }

    /// Solid-angle density of [`MapSampler::sample`] at the map-frame direction `d`.
    fn pdf(&self, d: Vec3) -> f32 {
        let sin_theta = (d.x * d.x + d.z * d.z).sqrt();
        if sin_theta <= 0.0 {
            return 0.0;
        }
        self.density[self.patch_of(direction_to_uv(d))] / (2.0 * PI * PI * sin_theta)
    }
}

#[derive(Clone, Debug)]
enum Radiance {
    Constant(Rgb),
    Map(MapSampler),
}

/// A direction toward the environment drawn by [`EnvironmentLight::sample`].
#[derive(Clone, Copy, Debug)]
pub(crate) struct EnvironmentSample {
    /// Unit world direction toward the sky.
    pub(crate) direction: Vec3,
    /// Radiance arriving from there.
    pub(crate) radiance: Rgb,
    /// Solid-angle density.
    pub(crate) pdf: f32,
    /// Angular width (radians) of the light arriving from there: √(solid angle) of the texel.
    pub(crate) angle: f32,
}

/// An [`Environment`] ready for sampling, with the disc that photons start on.
#[derive(Clone, Debug)]
pub(crate) struct EnvironmentLight {
    to_world: Mat3,
    to_local: Mat3,
    radiance: Radiance,
    /// Centre and radius of the scene's bounding sphere.
    center: Vec3,
    radius: f32,
    /// π r² ∫ L dω.
    power: Rgb,
}

impl EnvironmentLight {
    /// `None` when the environment emits nothing.
    pub(crate) fn new(env: &Environment, bounds: Aabb) -> Option<Self> {
        let to_world = env.to_world;
        let radiance = match &env.radiance {
            EnvironmentRadiance::Constant(c) => Radiance::Constant(*c * env.scale),
            EnvironmentRadiance::Map(map) => Radiance::Map(MapSampler::new(map, env.scale)?),
        };
        let radius = bounds.bounding_radius().max(1e-3);
        let power = env.integrated_radiance() * (PI * radius * radius);
        Some(Self {
            to_world,
            to_local: to_world.transpose(),
            radiance,
            center: bounds.center(),
            radius,
            power,
        })
    }

    pub(crate) fn power(&self) -> Rgb {
        self.power
    }

    /// Area density of a photon's start on its disc, uniform over π r².
    #[inline]
    pub(crate) fn disc_pdf(&self) -> f32 {
        1.0 / (PI * self.radius * self.radius)
    }

    /// Radiance arriving from the world direction `direction` (unit).
    #[inline]
    pub(crate) fn eval(&self, direction: Vec3) -> Rgb {
        match &self.radiance {
            Radiance::Constant(c) => *c,
            Radiance::Map(m) => m.radiance(direction_to_uv(self.to_local * direction)),
        }
    }

    /// Solid-angle density with which [`EnvironmentLight::sample`] draws `direction`.
    #[inline]
    pub(crate) fn pdf(&self, direction: Vec3) -> f32 {
        match &self.radiance {
            Radiance::Constant(_) => 1.0 / (4.0 * PI),
            Radiance::Map(m) => m.pdf(self.to_local * direction),
        }
    }

    /// A direction toward the sky: uniform for a constant sky, ∝ luminance × sin θ for a map.
    pub(crate) fn sample(&self, u: Vec2) -> Option<EnvironmentSample> {
        match &self.radiance {
            Radiance::Constant(c) => Some(EnvironmentSample {
                direction: uniform_sphere(u),
                radiance: *c,
                pdf: 1.0 / (4.0 * PI),
                angle: PI,
            }),
            Radiance::Map(m) => {
                let (d, radiance, texel, pdf) = m.sample(u)?;
                Some(EnvironmentSample {
                    direction: (self.to_world * d).normalize(),
                    radiance,
                    pdf,
                    angle: m.texel_angle[texel / m.width],
                })
            }
        }
    }

    /// A photon from the sky: a direction from [`EnvironmentLight::sample`] with `u_dir`, and a
    /// start on the disc of the bounding sphere's radius facing it, outside the scene, with
    /// `u_pos`. Returns (origin, travel direction, flux, angular width).
    pub(crate) fn sample_emission(
        &self,
        u_pos: Vec2,
        u_dir: Vec2,
    ) -> Option<(Vec3, Vec3, Rgb, f32)> {
        let s = self.sample(u_dir)?;
        let frame = Frame::from_normal(s.direction);
        let disc = self.radius * concentric_disk(u_pos);
        let origin = self.center + self.radius * s.direction + disc.x * frame.s + disc.y * frame.t;
        let flux = s.radiance * (PI * self.radius * self.radius / s.pdf);
        Some((origin, -s.direction, flux, s.angle))
    }
}

#[cfg(test)]
#[path = "environment_tests.rs"]
mod tests;
