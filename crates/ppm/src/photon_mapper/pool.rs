//! The image-space reconstruction of the photon mappers' estimate: when the image is read,
//! each slot's photon radiance τ/(πR²N) is pooled with those of the same slot index in
//! neighbouring pixels whose visible points lie on the same surface, by a Gaussian whose
//! world-space width the frequency prediction of the light decides (`pool = freq`) or the
//! window alone (`pool = geometry`, the control).
//!
//! Why it pays: the variance of a pixel's estimate falls with the area its kernel covers, but a
//! larger gather disc costs R² in photon–hitpoint pairs every pass. Pooling costs O(pixels ×
//! taps) once per read-out, whatever the photon count. The blur it adds is bounded as the
//! gather disc's is: a disc of radius R blurs by R²/4 per axis, a Gaussian of standard
//! deviation s by s², and the frequency radius r_freq is the disc the light allows, so a slot
//! pools with s = √((scale·r_freq)² − R²)/2 (none once R reaches scale·r_freq: shadow edges,
//! caustic lines and contact keep their width).
//!
//! Neighbours count only on the same surface: a valid visible point of the same material and
//! photon-bounce budget, normals within about 25°, close to the pixel's tangent plane, and a
//! hitpoint weight (the texture and the specular throughput that lead to it) within 10 % per
//! channel; their radiance is demodulated by that weight (L_q·w_p/w_q), so a texture is not
//! blurred. Where the pixel's gather disc is not clear of other surfaces (a probed clear
//! radius below the largest kernel), the width is at most half that radius.
//!
//! Consistency: beyond n₀ = 10⁷ photons counted the width shrinks as (n₀/n)^decay, so the image
//! converges to the unpooled estimator's limit; with decay = 1/6 the pooled area shrinks as
//! n^(−1/3), the rate that balances a kernel's squared bias (∝ s⁴) against its variance
//! (∝ 1/(n·s²)).
//!
//! Pooling is a function of the slots' saved state (positions, normals, weights, R, N, τ,
//! frequency state), so it is exact across resume and the same for any thread count.

use glam::Vec3;
use rayon::prelude::*;

use super::{NO_VISIBLE_POINT, PhotonMapper};
use crate::params::PoolMode;
use crate::update::GatherStats;

/// Photons counted after which the pooling width starts to shrink.
const SHRINK_AFTER: f64 = 1e7;
/// Neighbours closer than this many pixels are all taps; beyond, every other pixel in each
/// direction is (each standing for 4 pixels' area): a window of 4 pixels has 28 taps, one of 8
/// 64.
const DENSE_RADIUS: i32 = 2;
/// The cosine two normals must reach to count as the same surface.
const NORMAL_COS: f32 = 0.9;
/// The largest distance from the pixel's tangent plane, as a share of the distance between
/// the two visible points.
const PLANE_SLOPE: f32 = 0.1;
/// The largest relative difference of the hitpoint weights, per channel.
const WEIGHT_TOLERANCE: f32 = 0.1;
/// Taps beyond this many standard deviations carry nothing worth the work.
const CUTOFF_SIGMAS: f64 = 3.0;

/// One tap of the window: its offset in pixels and the film area it stands for.
#[derive(Clone, Copy, Debug)]
struct Tap {
    dx: i32,
    dy: i32,
    area: f64,
}

/// The taps of a window of `radius` pixels, without the centre.
fn taps(radius: u32) -> Vec<Tap> {
    let m = radius as i32;
    let mut taps = Vec::new();
    for dy in -m..=m {
        for dx in -m..=m {
            if (dx == 0 && dy == 0) || dx * dx + dy * dy > m * m {
                continue;
            }
            let dense = dx.abs().max(dy.abs()) <= DENSE_RADIUS;
            if dense {
                taps.push(Tap { dx, dy, area: 1.0 });
            } else if dx % 2 == 0 && dy % 2 == 0 {
                taps.push(Tap { dx, dy, area: 4.0 });
            }
        }
    }
    taps
}

/// A slot's photon radiance after pooling, and the width it pooled with.
pub(super) struct Pooled {
    /// Photon radiance per slot (τ/(πR²N) pooled), in slot order.
    pub(super) radiance: Vec<[f64; 3]>,
    /// The Gaussian's standard deviation per slot, in scene units (0: not pooled).
    pub(super) width: Vec<f32>,
}

impl PhotonMapper {
    /// Every slot's own photon radiance τ/(πR²N) (zero where none was gathered).
    fn slot_radiance(&self) -> Vec<[f64; 3]> {
        let radius = self.slots.radius();
        let count = self.slots.photon_count();
        let flux = self.slots.flux();
        let n_emitted = self.photons_counted() as f64;
        (0..self.slots.len())
            .into_par_iter()
            .map(|slot| {
                GatherStats {
                    radius: radius[slot],
                    photon_count: count[slot],
                    flux: flux[slot],
                }
                .radiance(n_emitted)
                .unwrap_or([0.0; 3])
            })
            .collect()
    }

    /// Whether this render pools at all (never `appm`, whose image is its exact pass sums).
    pub(super) fn pools(&self) -> bool {
        let params = &self.setup.params;
        if params.method.is_pass_independent() {
            return false;
        }
        match params.pool.mode {
            PoolMode::Off => false,
            PoolMode::Frequency => params.method.uses_frequency() && params.pool.max_pixels > 0,
            PoolMode::Geometry => params.pool.max_pixels > 0,
        }
    }

    /// The photon radiance of every slot, pooled as the parameters say (or each slot's own
    /// where this render does not pool).
    pub(super) fn pooled(&self) -> Pooled {
        let own = self.slot_radiance();
        if !self.pools() || self.slots.is_empty() {
            let width = vec![0.0; own.len()];
            return Pooled {
                radiance: own,
                width,
            };
        }
        let guides = self.guides();
        let width = self.pool_widths(&guides);
        let taps = taps(self.setup.params.pool.max_pixels);
        let radiance = (0..own.len())
            .into_par_iter()
            .map(|slot| self.pool_slot(&guides, slot, &own, f64::from(width[slot]), &taps))
            .collect();
        Pooled { radiance, width }
    }

    /// Each slot's pooling width: the Gaussian's standard deviation in scene units, 0 where it
    /// does not pool.
    fn pool_widths(&self, guides: &[Guide]) -> Vec<f32> {
        let params = &self.setup.params;
        let pool = params.pool;
        let k = params.frequency.kernel_k;
        let r_top = self.setup.kernel_max();
        let n = self.photons_counted() as f64;
        let shrink = if n > SHRINK_AFTER {
            (SHRINK_AFTER / n).powf(pool.decay)
        } else {
            1.0
        };
        let slots = &self.slots;
        (0..slots.len())
            .into_par_iter()
            .map(|slot| {
                let Some(footprint) = self.footprint(guides, slot) else {
                    return 0.0;
                };
                let window = 0.5 * f64::from(pool.max_pixels) * footprint;
                let freq = slots.freq()[slot];
                let mut s = match pool.mode {
                    PoolMode::Off => 0.0,
                    PoolMode::Geometry => window,
                    PoolMode::Frequency => freq.frequency_radius(k).map_or(0.0, |r_freq| {
                        let budget = pool.scale * r_freq;
                        let r = slots.radius()[slot];
                        (budget * budget - r * r).max(0.0).sqrt() / 2.0
                    }),
                };
                s = s.min(window);
                // A disc not clear at the largest kernel sits near another surface: pool no
                // further than half its clear radius.
                if freq.clear_level() != 0
                    && let Some(clear) = freq.clear_radius(r_top)
                {
                    s = s.min(0.5 * clear);
                }
                let s = s * shrink;
                // A width far below a pixel pools nothing worth the taps.
                if s < 0.25 * footprint { 0.0 } else { s as f32 }
            })
            .collect()
    }

    /// The distance in scene units between the visible point of `slot` and those of the same
    /// slot index in the pixels beside it on the same surface (their mean), or `None` where
    /// no neighbour lies on its surface.
    fn footprint(&self, guides: &[Guide], slot: usize) -> Option<f64> {
        if !guides[slot].is_valid() {
            return None;
        }
        let (width, height) = (self.setup.width as i32, self.setup.height as i32);
        let spp = self.setup.params.film.samples_per_pixel as usize;
        let pixel = (slot / spp) as i32;
        let (x, y) = (pixel % width, pixel / width);
        let position = guides[slot].position;
        let (mut sum, mut n) = (0.0f64, 0u32);
        for (dx, dy) in [(1, 0), (-1, 0), (0, 1), (0, -1)] {
            let (qx, qy) = (x + dx, y + dy);
            if qx < 0 || qy < 0 || qx >= width || qy >= height {
                continue;
            }
            let q = (qy * width + qx) as usize * spp + slot % spp;
            if same_surface(&guides[slot], &guides[q]) {
                sum += f64::from(position.distance(guides[q].position));
                n += 1;
            }
        }
        (n > 0 && sum > 0.0).then(|| sum / f64::from(n))
    }

    /// What the surface tests read of every slot, packed so that a tap touches one record.
    fn guides(&self) -> Vec<Guide> {
        let s = &self.slots;
        (0..s.len())
            .into_par_iter()
            .map(|i| Guide {
                position: s.position()[i],
                normal: s.geometric_normal()[i],
                shading_normal: s.shading_normal()[i],
                weight: s.weight()[i],
                material: s.material_idx()[i],
                budget: self.photon_bounces[i],
            })
            .collect()
    }

    /// The pooled photon radiance of `slot` with standard deviation `s` (its own where `s` is
    /// 0).
    fn pool_slot(
        &self,
        guides: &[Guide],
        slot: usize,
        own: &[[f64; 3]],
        s: f64,
        taps: &[Tap],
    ) -> [f64; 3] {
        if s <= 0.0 {
            return own[slot];
        }
        let (width, height) = (self.setup.width as i32, self.setup.height as i32);
        let spp = self.setup.params.film.samples_per_pixel as usize;
        let pixel = (slot / spp) as i32;
        let (x, y) = (pixel % width, pixel / width);
        let centre = &guides[slot];
        let (position, w_p) = (centre.position, centre.weight);
        let (t, b) = centre.normal.any_orthonormal_pair();
        let inv_two_var = 1.0 / (2.0 * s * s);
        let cutoff2 = (CUTOFF_SIGMAS * s) * (CUTOFF_SIGMAS * s);
        // A weighted least-squares plane L(u, v) = c + g·(u, v) over the tangent plane, read at
        // the centre: a linear gradient of the light costs no bias even where the neighbours
        // lie on one side only (beside a wall, an edge of the surface).
        let mut fit = LinearFit::new(own[slot]);
        for tap in taps {
            let (qx, qy) = (x + tap.dx, y + tap.dy);
            if qx < 0 || qy < 0 || qx >= width || qy >= height {
                continue;
            }
            let q = (qy * width + qx) as usize * spp + slot % spp;
            let guide = &guides[q];
            let offset = guide.position - position;
            let d2 = f64::from(offset.length_squared());
            if d2 > cutoff2 || !same_surface(centre, guide) {
                continue;
            }
            let k = tap.area * (-d2 * inv_two_var).exp();
            let w_q = guide.weight;
            let value = std::array::from_fn(|c| {
                if w_q[c] > 0.0 {
                    own[q][c] * f64::from(w_p[c] / w_q[c])
                } else {
                    0.0
                }
            });
            let (u, v) = (f64::from(offset.dot(t)) / s, f64::from(offset.dot(b)) / s);
            fit.add(k, u, v, value);
        }
        fit.centre()
    }
}

/// The moments of a weighted least-squares plane fit through the centre's neighbourhood, in
/// units of the pooling width.
struct LinearFit {
    /// Σk·[1, u, v, uu, uv, vv].
    moments: [f64; 6],
    /// Σk·L·[1, u, v] per channel.
    values: [[f64; 3]; 3],
}

impl LinearFit {
    /// The fit with the centre's own value, weight 1 at (0, 0).
    fn new(own: [f64; 3]) -> Self {
        Self {
            moments: [1.0, 0.0, 0.0, 0.0, 0.0, 0.0],
            values: [own, [0.0; 3], [0.0; 3]],
        }
    }

    fn add(&mut self, k: f64, u: f64, v: f64, value: [f64; 3]) {
        let m = &mut self.moments;
        m[0] += k;
        m[1] += k * u;
        m[2] += k * v;
        m[3] += k * u * u;
        m[4] += k * u * v;
        m[5] += k * v * v;
        for (c, &value) in value.iter().enumerate() {
            self.values[0][c] += k * value;
            self.values[1][c] += k * u * value;
            self.values[2][c] += k * v * value;
        }
    }

    /// The plane's value at the centre, or the weighted mean where the neighbours do not
    /// span the plane (all on one line) well enough to fit a gradient.
    fn centre(&self) -> [f64; 3] {
        let [m0, mu, mv, muu, muv, mvv] = self.moments;
        let mean = self.values[0].map(|v| v / m0);
        // Covariance of the tap positions about their weighted mean.
        let (cu, cv) = (mu / m0, mv / m0);
        let (suu, suv, svv) = (muu / m0 - cu * cu, muv / m0 - cu * cv, mvv / m0 - cv * cv);
        let det = suu * svv - suv * suv;
        if det.is_nan() || det <= 1e-3 {
            return mean;
        }
        // L(0) = mean − g·centroid, g = Σ⁻¹·cov(p, L).
        std::array::from_fn(|c| {
            let lu = self.values[1][c] / m0 - cu * mean[c];
            let lv = self.values[2][c] / m0 - cv * mean[c];
            let gu = (svv * lu - suv * lv) / det;
            let gv = (suu * lv - suv * lu) / det;
            mean[c] - gu * cu - gv * cv
        })
    }
}

/// A slot's visible point as the surface tests read it.
#[derive(Clone, Copy, Debug)]
struct Guide {
    position: Vec3,
    normal: Vec3,
    shading_normal: Vec3,
    weight: Vec3,
    material: u32,
    /// The photon-bounce budget, [`NO_VISIBLE_POINT`] without a visible point.
    budget: u16,
}

impl Guide {
    fn is_valid(&self) -> bool {
        self.budget != NO_VISIBLE_POINT
    }
}

/// Whether the visible point `q` lies on the surface of `p`'s, as pooling requires (`p` valid).
fn same_surface(p: &Guide, q: &Guide) -> bool {
    if !q.is_valid() || p.material != q.material || p.budget != q.budget {
        return false;
    }
    if p.normal.dot(q.normal) < NORMAL_COS || p.shading_normal.dot(q.shading_normal) < NORMAL_COS {
        return false;
    }
    let offset = q.position - p.position;
    if p.normal.dot(offset).abs() > PLANE_SLOPE * offset.length() {
        return false;
    }
    weights_agree(p.weight, q.weight)
}

/// Whether two hitpoint weights agree within [`WEIGHT_TOLERANCE`] in every channel.
fn weights_agree(a: Vec3, b: Vec3) -> bool {
    let diff = (a - b).abs();
    let scale = a.max(b);
    diff.cmple(scale * WEIGHT_TOLERANCE).all()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn taps_cover_the_window_once_by_area() {
        // The taps' areas add up to the disc's pixel count beside the centre, within the
        // sparse ring's rounding.
        for radius in [1u32, 2, 4, 8, 16] {
            let taps = taps(radius);
            let area: f64 = taps.iter().map(|t| t.area).sum();
            let disc = std::f64::consts::PI * f64::from(radius * radius);
            assert!(
                (area + 1.0 - disc).abs() <= 0.15 * disc + 4.0,
                "radius {radius}: {area} against {disc}"
            );
            assert!(
                taps.iter()
                    .all(|t| t.dx * t.dx + t.dy * t.dy <= (radius * radius) as i32)
            );
        }
        assert!(taps(0).is_empty());
        assert!(taps(8).len() < 80);
    }

    #[test]
    fn weights_agree_within_the_tolerance() {
        let a = Vec3::new(0.5, 0.4, 0.3);
        assert!(weights_agree(a, a));
        assert!(weights_agree(a, a * 1.05));
        assert!(!weights_agree(a, a * 1.2));
        assert!(!weights_agree(a, Vec3::new(0.5, 0.4, 0.0)));
        assert!(weights_agree(Vec3::ZERO, Vec3::ZERO));
    }
}
