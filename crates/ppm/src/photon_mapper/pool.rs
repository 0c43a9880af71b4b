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
//! channel; their radiance is demodulated by that weight (L_q·w̄_p/w̄_q), so a texture is not
//! blurred. The weights are each slot's mean over the passes' visible points (`mean_weight`),
//! not the last pass's: τ sums the passes' weight × irradiance, and the last weight (one texel
//! of the pixel, one throughput through glass) would scale the pooled value by a single sample.
//! Where the pixel's gather disc is not clear of other surfaces (a probed clear radius below
//! the largest kernel), the width is at most half that radius.
//!
//! Consistency: beyond n₀ = 10⁷ photons counted the width shrinks as (n₀/n)^decay, so the image
//! converges to the unpooled estimator's limit; with decay = 1/6 the pooled area shrinks as
//! n^(−1/3), the rate that balances a kernel's squared bias (∝ s⁴) against its variance
//! (∝ 1/(n·s²)).
//!
//! Pooling is a function of the slots' saved state (positions, normals, weights, R, N, τ,
//! frequency state), so it is exact across resume and the same for any thread count.

use std::ops::{Range, Sub};

use rayon::prelude::*;
use wide::{f32x8, u32x8};

use super::{NO_VISIBLE_POINT, PhotonMapper, Setup};
use crate::params::PoolMode;

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
/// How many of its own standard errors a slot's pooled value may lie from its own estimate
/// (the channels' sum): further, the window has pooled light the slot does not see.
const AGREEMENT_SIGMAS: f64 = 3.0;

/// Taps beyond this many standard deviations carry nothing worth the work.
const CUTOFF_SIGMAS: f32 = 3.0;
/// Pixels of a row pooled at once, one per lane of a vector.
const LANES: usize = 8;
/// Columns of a band pooled row after row before the next: a multiple of [`LANES`].
const TILE_COLUMNS: usize = 128;
/// Rows of the film one task pools: its planes hold them and the window's rows around them.
const BAND_ROWS: usize = 32;

thread_local! {
    /// Each worker thread's planes, kept from band to band and from read-out to read-out: a
    /// band's planes are megabytes at 1920 pixels a row, and their first touch cost more than
    /// the pooling itself. Nothing is carried over: `Planes::fill` writes every entry it reads,
    /// and a band's results are cleared before it is pooled.
    static PLANES: std::cell::RefCell<Planes> = std::cell::RefCell::default();
}

/// One tap of the window: its offset in pixels and the film area it stands for.
#[derive(Clone, Copy, Debug)]
struct Tap {
    dx: i32,
    dy: i32,
    area: f32,
    /// Its index in [`FOOTPRINT`] if it is one of the footprint's taps (whose surface test
    /// the footprint already made), else `usize::MAX`.
    footprint: usize,
    /// How far it is in the planes ([`View::offset`]), set for each band.
    offset: isize,
}

/// The neighbours whose mean distance is a pixel's footprint.
const FOOTPRINT: [(i32, i32); 4] = [(1, 0), (-1, 0), (0, 1), (0, -1)];

/// The taps of a window of `radius` pixels, without the centre.
fn taps(radius: u32) -> Vec<Tap> {
    let m = radius as i32;
    let mut taps = Vec::new();
    for dy in -m..=m {
        for dx in -m..=m {
            if (dx == 0 && dy == 0) || dx * dx + dy * dy > m * m {
                continue;
            }
            let footprint = FOOTPRINT
                .iter()
                .position(|&d| d == (dx, dy))
                .unwrap_or(usize::MAX);
            let dense = dx.abs().max(dy.abs()) <= DENSE_RADIUS;
            if dense {
                taps.push(Tap {
                    dx,
                    dy,
                    area: 1.0,
                    footprint,
                    offset: 0,
                });
            } else if dx % 2 == 0 && dy % 2 == 0 {
                taps.push(Tap {
                    dx,
                    dy,
                    area: 4.0,
                    footprint,
                    offset: 0,
                });
            }
        }
    }
    taps
}

/// Every slot's photon radiance after pooling, and the width it pooled with (what the tests
/// hold to a per-pixel reference).
#[cfg(test)]
pub(super) struct Pooled {
    /// Photon radiance per slot (τ/(πR²N) pooled), in slot order.
    pub(super) radiance: Vec<[f64; 3]>,
    /// The Gaussian's standard deviation per slot, in scene units (0: not pooled).
    pub(super) width: Vec<f32>,
}

impl PhotonMapper {
    /// The slot's own photon radiance τ/(πR²N) (zero where none was gathered).
    #[inline]
    pub(super) fn own_radiance(&self, slot: usize) -> [f64; 3] {
        own_radiance(
            self.slots.radius()[slot],
            self.slots.flux()[slot],
            self.photons_counted() as f64,
        )
    }

    /// Whether this render pools at all.
    pub(super) fn pools(&self) -> bool {
        self.setup.pools()
    }

    /// The photon radiance of every slot, pooled as the parameters say (or each slot's own
    /// where this render does not pool), and the widths.
    #[cfg(test)]
    pub(super) fn pooled(&self) -> Pooled {
        let n = self.slots.len();
        let per_row = self.setup.width as usize * self.setup.params.film.samples_per_pixel as usize;
        let mut out = vec![([0.0; 3], 0.0f32); n];
        self.pool_bands(&mut out, per_row, |_, out, radiance, width| {
            for ((o, l), s) in out.iter_mut().zip(radiance).zip(width) {
                *o = (*l, *s);
            }
        });
        let (radiance, width) = out.into_iter().unzip();
        Pooled { radiance, width }
    }

    /// Pools the film in bands of [`BAND_ROWS`] rows, in parallel, and hands `emit` each band's
    /// first slot, its share of `out` (`per_row` entries per row of the film), and its pooled
    /// radiance and widths in slot order from that first slot.
    ///
    /// Each task copies the visible points of its band and of the window's rows around it into
    /// planes (`Planes`) and pools eight pixels of a row at a time; the band's results live in
    /// per-thread buffers, so a read-out touches no image-sized memory but what `emit` writes:
    /// the cost is the taps' arithmetic, not page faults or scattered loads.
    pub(super) fn pool_bands<T: Send>(
        &self,
        out: &mut [T],
        per_row: usize,
        emit: impl Fn(usize, &mut [T], &[[f64; 3]], &[f32]) + Sync,
    ) {
        let film = Film {
            width: self.setup.width as usize,
            height: self.setup.height as usize,
            spp: self.setup.params.film.samples_per_pixel as usize,
        };
        if self.slots.is_empty() || per_row == 0 {
            return;
        }
        let pools = self.pools();
        let rule = WidthRule::new(self);
        let mut taps = taps(self.setup.params.pool.max_pixels);
        // The window's rows and columns, and at least the footprint's neighbours.
        let halo = (self.setup.params.pool.max_pixels as usize).max(1);
        // Every band's planes have the same stride.
        let stride = film.width + 2 * halo + LANES;
        for tap in &mut taps {
            tap.offset = tap.dy as isize * stride as isize + tap.dx as isize;
        }
        let taps = &taps;
        out.par_chunks_mut(BAND_ROWS * per_row)
            .enumerate()
            .for_each(|(band, out)| {
                PLANES.with_borrow_mut(|planes| {
                    let rows = band * BAND_ROWS..((band + 1) * BAND_ROWS).min(film.height);
                    let first_slot = rows.start * film.width * film.spp;
                    let slots = rows.len() * film.width * film.spp;
                    // Taken out of the planes while `pool_group` reads them.
                    let mut band = std::mem::take(&mut planes.band);
                    let mut scratch = std::mem::take(&mut planes.scratch);
                    band.reset(slots);
                    if pools {
                        for sample in 0..film.spp {
                            let centre = (&mut band, &rule, rows.clone(), first_slot);
                            planes.fill(self, film, sample, halo, centre);
                            // Tiles of columns, so that the window's rows of every plane stay
                            // in the cache from one row of the band to the next.
                            for tile in (0..film.width).step_by(TILE_COLUMNS) {
                                let tile = tile..(tile + TILE_COLUMNS).min(film.width);
                                for y in rows.clone() {
                                    for x0 in tile.clone().step_by(LANES) {
                                        pool_group(
                                            planes,
                                            &mut band,
                                            &mut scratch,
                                            &rule,
                                            taps,
                                            film,
                                            (x0, y),
                                            sample,
                                            first_slot,
                                        );
                                    }
                                }
                            }
                        }
                    } else {
                        for (i, l) in band.radiance.iter_mut().enumerate() {
                            *l = self.own_radiance(first_slot + i);
                        }
                    }
                    emit(first_slot, out, &band.radiance, &band.width);
                    planes.band = band;
                    planes.scratch = scratch;
                });
            });
    }
}

/// Pools the eight pixels of row `y` from `x0` on (those past the film's edge are computed and
/// thrown away): writes the pooled photon radiance and the width of each lane that pools into
/// `band` (whose radiance already holds every slot's own).
#[allow(clippy::too_many_arguments)]
fn pool_group(
    planes: &Planes,
    band: &mut Band,
    scratch: &mut Vec<Weighted>,
    rule: &WidthRule,
    taps: &[Tap],
    film: Film,
    (x0, y): (usize, usize),
    sample: usize,
    first_slot: usize,
) {
    // Cut here, where the compiler sees that every plane has the same length.
    let planes = &planes.view();
    let at = planes.index(x0, y);
    let centre = Centre::load(planes, at);
    if centre.valid.none() {
        return;
    }
    // The footprint: the mean distance to the pixels beside it on its surface.
    let (mut sum, mut count) = (f32x8::ZERO, f32x8::ZERO);
    // Each footprint tap's surface test, which the pooling's taps reuse.
    let mut footprint_on = [f32x8::ZERO; FOOTPRINT.len()];
    for ((dx, dy), footprint_on) in FOOTPRINT.into_iter().zip(&mut footprint_on) {
        let at = at.wrapping_add_signed(planes.offset(dx, dy));
        let position = planes.position.load(at);
        let offset = position - centre.position;
        let d2 = offset.dot(offset);
        let on = centre.on_surface(planes, at, offset, d2);
        *footprint_on = on;
        sum += d2.sqrt() & on;
        count += f32x8::ONE & on;
    }
    let (sum, count) = (sum.to_array(), count.to_array());
    let lanes = LANES.min(film.width - x0);
    let band_slot = |lane: usize| film.slot(x0 + lane, y, sample) - first_slot;
    let mut s = [0.0f32; LANES];
    for lane in 0..lanes {
        if count[lane] > 0.0 && sum[lane] > 0.0 {
            let footprint = f64::from(sum[lane] / count[lane]);
            s[lane] = rule.width(band.cap[band_slot(lane)], footprint);
        }
    }
    if s.iter().all(|&s| s <= 0.0) {
        return;
    }

    let width = f32x8::new(s);
    let active = width.simd_gt(f32x8::ZERO);
    let inv_width = (f32x8::ONE / width) & active;
    let inv_two_var = f32x8::splat(0.5) * inv_width * inv_width;
    let reach = f32x8::splat(CUTOFF_SIGMAS) * width;
    let cutoff2 = active.select(reach * reach, f32x8::splat(-1.0));
    let (t, b) = centre.normal.orthonormal_pair();
    // In three sweeps, each with few enough live vectors to stay in registers: the taps'
    // weights and coordinates, the moments, the values. Every sum still adds the taps in
    // their order.
    scratch.clear();
    for tap in taps {
        let at = at.wrapping_add_signed(tap.offset);
        let position = planes.position.load(at);
        let offset = position - centre.position;
        let d2 = offset.dot(offset);
        let near = d2.simd_le(cutoff2);
        if !near.any() {
            continue;
        }
        let on = near
            & match footprint_on.get(tap.footprint) {
                Some(&on) => on,
                None => centre.on_surface(planes, at, offset, d2),
            };
        if !on.any() {
            continue;
        }
        // k is 0 on the lanes off the surface, and u, v and the values are finite there (the
        // empty columns hold zeros): they add ±0 and need no mask.
        scratch.push(Weighted {
            k: (f32x8::splat(tap.area) * gaussian(-(d2 * inv_two_var))) & on,
            u: offset.dot(t) * inv_width,
            v: offset.dot(b) * inv_width,
            at,
        });
    }
    let mut fit = Fit::new(centre.flat);
    fit.add_moments(scratch);
    fit.add_values(scratch, &planes.flat);
    // Remodulated by the pixel's own weight: a texture is not blurred.
    let weight = centre.weight;
    let [fx, fy, fz] = fit.centre();
    let pooled = [weight.x * fx, weight.y * fy, weight.z * fz].map(f32x8::to_array);
    let has = [weight.x, weight.y, weight.z].map(|w| w.simd_gt(f32x8::ZERO).to_array());
    for lane in 0..lanes {
        if s[lane] <= 0.0 {
            continue;
        }
        let slot = band_slot(lane);
        let radiance = &mut band.radiance[slot];
        let mut value = *radiance;
        for c in 0..3 {
            if has[c][lane] != 0.0 {
                value[c] = f64::from(pooled[c][lane]);
            }
        }
        if !agrees(*radiance, value, band.spread[slot]) {
            continue;
        }
        *radiance = value;
        band.width[slot] = s[lane];
    }
}

/// Whether a slot's pooled value lies within [`AGREEMENT_SIGMAS`] of its own estimate's standard
/// errors (relative `spread`, taken of the larger of the two: the test errs towards pooling).
/// A window that reaches over a change of the light the prediction did not see (the ceiling in
/// the shadow of a lamp hung just below it) pools a value the slot's own photons contradict.
#[inline]
fn agrees(own: [f64; 3], pooled: [f64; 3], spread: f64) -> bool {
    let (own, pooled) = (own.iter().sum::<f64>(), pooled.iter().sum::<f64>());
    (pooled - own).abs() <= AGREEMENT_SIGMAS * spread * own.max(pooled)
}

/// The photon radiance τ/(πR²N) of a slot of radius `radius` and flux `flux` after `n`
/// photons (zero where none was gathered): τ times one reciprocal, not three quotients
/// (f64 division is the slowest step of a read-out's pass over the slots).
#[inline]
fn own_radiance(radius: f64, flux: [f64; 3], n: f64) -> [f64; 3] {
    let denominator = std::f64::consts::PI * radius * radius * n;
    if denominator > 0.0 {
        let inverse = 1.0 / denominator;
        flux.map(|c| c * inverse)
    } else {
        [0.0; 3]
    }
}

/// The film's shape as the slots are laid out: pixel-major, `spp` slots per pixel.
#[derive(Clone, Copy, Debug)]
struct Film {
    width: usize,
    height: usize,
    spp: usize,
}

impl Film {
    fn slot(self, x: usize, y: usize, sample: usize) -> usize {
        (y * self.width + x) * self.spp + sample
    }
}

/// How wide a slot pools, from its footprint, its frequency radius, its gather radius and its
/// clear disc.
struct WidthRule {
    mode: PoolMode,
    /// Half the window, in pixels.
    half_window: f64,
    scale: f64,
    kernel_k: f64,
    r_top: f64,
    /// The consistency shrink (n₀/n)^decay, 1 before n₀.
    shrink: f64,
}

impl WidthRule {
    fn new(mapper: &PhotonMapper) -> Self {
        let params = &mapper.setup.params;
        let n = mapper.photons_counted() as f64;
        Self {
            mode: params.pool.mode,
            half_window: 0.5 * f64::from(params.pool.max_pixels),
            scale: params.pool.scale,
            kernel_k: params.frequency.kernel_k,
            r_top: mapper.setup.kernel_max(),
            shrink: if n > SHRINK_AFTER {
                (SHRINK_AFTER / n).powf(params.pool.decay)
            } else {
                1.0
            },
        }
    }

    /// The widest a slot may pool whatever its footprint (scene units, before the shrink): the
    /// frequency rule's width, under half the clear radius where the disc is not clear.
    fn cap(&self, mapper: &PhotonMapper, slot: usize) -> f64 {
        let slots = &mapper.slots;
        let freq = slots.freq()[slot];
        let mut s = match self.mode {
            PoolMode::Off => 0.0,
            PoolMode::Geometry => f64::INFINITY,
            PoolMode::Frequency => freq.frequency_radius(self.kernel_k).map_or(0.0, |r_freq| {
                let budget = self.scale * r_freq;
                let r = slots.radius()[slot];
                (budget * budget - r * r).max(0.0).sqrt() / 2.0
            }),
        };
        // A disc not clear at the largest kernel sits near another surface: pool no further
        // than half its clear radius.
        if freq.clear_level() != 0
            && let Some(clear) = freq.clear_radius(self.r_top)
        {
            s = s.min(0.5 * clear);
        }
        s
    }

    /// The Gaussian's standard deviation in scene units of a slot of [`Self::cap`] `cap` whose
    /// neighbours on its surface lie `footprint` away (their mean), 0 where it does not pool.
    #[inline]
    fn width(&self, cap: f64, footprint: f64) -> f32 {
        let window = self.half_window * footprint;
        let s = cap.min(window) * self.shrink;
        // A width far below a pixel pools nothing worth the taps.
        if s < 0.25 * footprint { 0.0 } else { s as f32 }
    }
}

/// Whether two visible points of one slot in successive passes lie on the same surface, by the
/// tests that decide whether a neighbour pools (same material and photon-bounce budget, both
/// normals within about 25°, each close to the other's tangent plane), the weights aside: a
/// slot whose visible point moves between surfaces (a pixel on a silhouette, or one that sees
/// the sky in some passes) sums their radiance in one estimate, which the last pass's geometry
/// does not describe, so it neither pools nor is pooled from (`PhotonMapper::mixed`).
pub(super) fn same_surface(a: Surface, b: Surface) -> bool {
    let (Some(a), Some(b)) = (a, b) else {
        return a.is_none() && b.is_none();
    };
    let offset = b.position - a.position;
    let d2 = offset.length_squared();
    let near_plane = |n: glam::Vec3| {
        let h = n.dot(offset);
        h * h <= PLANE_SLOPE * PLANE_SLOPE * d2
    };
    a.material == b.material
        && a.budget == b.budget
        && a.normal.dot(b.normal) >= NORMAL_COS
        && a.shading_normal.dot(b.shading_normal) >= NORMAL_COS
        && near_plane(a.normal)
        && near_plane(b.normal)
}

/// A slot's visible point as [`same_surface`] compares it (`None`: the slot has none).
pub(super) type Surface = Option<SurfacePoint>;

/// What [`same_surface`] compares of a visible point.
#[derive(Clone, Copy, Debug)]
pub(super) struct SurfacePoint {
    pub(super) position: glam::Vec3,
    pub(super) normal: glam::Vec3,
    pub(super) shading_normal: glam::Vec3,
    pub(super) material: u32,
    pub(super) budget: u16,
}

impl Setup {
    /// Whether this render pools at all (never `appm`, whose image is its exact pass sums).
    pub(super) fn pools(&self) -> bool {
        let params = &self.params;
        if params.method.is_pass_independent() {
            return false;
        }
        match params.pool.mode {
            PoolMode::Off => false,
            PoolMode::Frequency => params.method.uses_frequency() && params.pool.max_pixels > 0,
            PoolMode::Geometry => params.pool.max_pixels > 0,
        }
    }
}

/// One band's results in slot order from its first slot, and what its slots' own state gives.
#[derive(Default)]
struct Band {
    /// Photon radiance: each slot's own, replaced by the pooled value where it pools.
    radiance: Vec<[f64; 3]>,
    /// The pooling width (0: not pooled).
    width: Vec<f32>,
    /// [`WidthRule::cap`] of each slot with a visible point.
    cap: Vec<f64>,
    /// The relative standard error of each slot's own estimate, 1/√N.
    spread: Vec<f64>,
}

impl Band {
    /// Room for `slots` slots, with no width: the radiance of every slot and the cap of every
    /// slot with a visible point are written before they are read (`Planes::fill`, or the
    /// own radiance where nothing pools), so only the widths are cleared.
    fn reset(&mut self, slots: usize) {
        self.radiance.resize(slots, [0.0; 3]);
        self.width.clear();
        self.width.resize(slots, 0.0);
        self.cap.resize(slots, 0.0);
        self.spread.resize(slots, 0.0);
    }
}

/// e^x for the lanes where −4.5 ≤ x ≤ 0 (a tap within [`CUTOFF_SIGMAS`]), bit for bit what
/// `f32x8::exp` gives there (the same reduction and polynomial), without its handling of
/// overflow, underflow and NaN: the other lanes are masked out, and are only kept finite.
#[inline(always)]
fn gaussian(x: f32x8) -> f32x8 {
    const LN2_HI: f32 = 0.693_359_4;
    const LN2_LO: f32 = -2.121_944_4e-4;
    let x = x.fast_max(f32x8::splat(-87.0));
    let r = (x * f32x8::LOG2_E).round_ties_even();
    let x = r.mul_neg_add(f32x8::splat(LN2_HI), x);
    let x = r.mul_neg_add(f32x8::splat(LN2_LO), x);
    let [p0, p1, p2, p3, p4, p5] = [
        1.0 / 2.0,
        1.0 / 6.0,
        1.0 / 24.0,
        1.0 / 120.0,
        1.0 / 720.0,
        1.0 / 5040.0,
    ]
    .map(f32x8::splat);
    let x2 = x * x;
    let x4 = x2 * x2;
    let z = p3
        .mul_add(x, p2)
        .mul_add(x2, p5.mul_add(x, p4).mul_add(x4, p1.mul_add(x, p0)));
    let z = z.mul_add(x2, x);
    // 2^r by the exponent's bits (r ≥ −126 after the clamp).
    let biased = r + f32x8::splat(127.0 + 8_388_608.0);
    let scale = f32x8::from_bits(biased.to_bits() << 23);
    (z + f32x8::ONE) * scale
}

/// Three planes of one vector quantity.
#[derive(Default)]
struct Plane3 {
    x: Vec<f32>,
    y: Vec<f32>,
    z: Vec<f32>,
}

impl Plane3 {
    /// Room for `len` entries at least (never shrunk: the last band is shorter than the others,
    /// and growing back would write every entry again).
    fn reserve(&mut self, len: usize) {
        for plane in [&mut self.x, &mut self.y, &mut self.z] {
            if plane.len() < len {
                plane.resize(len, 0.0);
            }
        }
    }
}

/// Eight consecutive values of a plane as a vector.
#[inline]
fn load(plane: &[f32], at: usize) -> f32x8 {
    f32x8::from(&plane[at..at + LANES])
}

/// The visible points of one sample index over a band of rows and the window's `halo` rows
/// around it (rows off the film hold no visible point), one plane per quantity, `stride` columns
/// per row: the film's columns with `halo` columns before and `halo + LANES` after that hold no
/// visible point, so that any tap of eight neighbouring pixels loads as one vector without a
/// bounds test per lane, and every tap of a pixel of the band is in the planes.
#[derive(Default)]
struct Planes {
    halo: usize,
    stride: usize,
    /// The film row of the planes' first row (negative above the film).
    top: isize,
    /// The entries of each plane in use.
    len: usize,
    position: Plane3,
    normal: Plane3,
    shading_normal: Plane3,
    weight: Plane3,
    /// The photon radiance over the hitpoint weight, per channel (0 where the weight is):
    /// what a neighbour lends, remodulated by the pixel's own weight.
    flat: Plane3,
    material: Vec<u32>,
    /// The photon-bounce budget, [`NO_VISIBLE_POINT`] without a visible point.
    budget: Vec<u32>,
    /// The band's results.
    band: Band,
    /// The taps of one group that reach it.
    scratch: Vec<Weighted>,
}

/// One row of every plane, to write.
struct RowMut<'a> {
    position: [&'a mut [f32]; 3],
    normal: [&'a mut [f32]; 3],
    shading_normal: [&'a mut [f32]; 3],
    weight: [&'a mut [f32]; 3],
    flat: [&'a mut [f32]; 3],
    material: &'a mut [u32],
    budget: &'a mut [u32],
}

impl RowMut<'_> {
    /// Columns `cols` without a visible point (finite zeros everywhere, so that masked lanes
    /// stay 0).
    #[inline]
    fn clear(&mut self, cols: Range<usize>) {
        for plane in [
            &mut self.position,
            &mut self.normal,
            &mut self.shading_normal,
            &mut self.weight,
            &mut self.flat,
        ] {
            for p in plane.iter_mut() {
                p[cols.clone()].fill(0.0);
            }
        }
        self.material[cols.clone()].fill(0);
        self.budget[cols].fill(u32::from(NO_VISIBLE_POINT));
    }

    /// Column `col` without a visible point, as [`Self::clear`] (without a call to fill a
    /// slice per plane).
    #[inline]
    fn clear_one(&mut self, col: usize) {
        for plane in [
            &mut self.position,
            &mut self.normal,
            &mut self.shading_normal,
            &mut self.weight,
            &mut self.flat,
        ] {
            Self::set(plane, col, [0.0; 3]);
        }
        self.material[col] = 0;
        self.budget[col] = u32::from(NO_VISIBLE_POINT);
    }

    #[inline]
    fn set(plane: &mut [&mut [f32]; 3], col: usize, value: [f32; 3]) {
        for (p, v) in plane.iter_mut().zip(value) {
            p[col] = v;
        }
    }
}

impl Plane3 {
    fn row_mut(&mut self, row: Range<usize>) -> [&mut [f32]; 3] {
        [
            &mut self.x[row.clone()],
            &mut self.y[row.clone()],
            &mut self.z[row],
        ]
    }
}

impl Planes {
    /// Copies the visible points of the band's rows `band_rows` and of the `halo` rows around
    /// them for `sample`, and writes into `band` the own radiance and cap ([`WidthRule::cap`])
    /// of each slot of the band's rows (whose first slot is `first_slot`): each slot's radiance
    /// τ/(πR²N) is computed once.
    fn fill(
        &mut self,
        mapper: &PhotonMapper,
        film: Film,
        sample: usize,
        halo: usize,
        (band, rule, band_rows, first_slot): (&mut Band, &WidthRule, Range<usize>, usize),
    ) {
        self.halo = halo;
        self.stride = film.width + 2 * halo + LANES;
        self.top = band_rows.start as isize - halo as isize;
        let rows = band_rows.len() + 2 * halo;
        let len = rows * self.stride;
        for plane in [
            &mut self.position,
            &mut self.normal,
            &mut self.shading_normal,
            &mut self.weight,
            &mut self.flat,
        ] {
            plane.reserve(len);
        }
        for plane in [&mut self.material, &mut self.budget] {
            if plane.len() < len {
                plane.resize(len, 0);
            }
        }
        self.len = len;
        let slots = &mapper.slots;
        let (radius, flux) = (slots.radius(), slots.flux());
        let (positions, normals, shading_normals) = (
            slots.position(),
            slots.geometric_normal(),
            slots.shading_normal(),
        );
        let materials = slots.material_idx();
        let n = mapper.photons_counted() as f64;
        for row in 0..rows {
            let cols = row * self.stride..(row + 1) * self.stride;
            let mut out = RowMut {
                position: self.position.row_mut(cols.clone()),
                normal: self.normal.row_mut(cols.clone()),
                shading_normal: self.shading_normal.row_mut(cols.clone()),
                weight: self.weight.row_mut(cols.clone()),
                flat: self.flat.row_mut(cols.clone()),
                material: &mut self.material[cols.clone()],
                budget: &mut self.budget[cols],
            };
            let y = self.top + row as isize;
            if y < 0 || y >= film.height as isize {
                out.clear(0..self.stride);
                continue;
            }
            let y = y as usize;
            out.clear(0..halo);
            out.clear(halo + film.width..self.stride);
            let in_band = band_rows.contains(&y);
            for x in 0..film.width {
                let col = x + halo;
                let slot = film.slot(x, y, sample);
                let budget = mapper.photon_bounces[slot];
                // A slot whose visible point has moved between surfaces is left as it is.
                let visible =
                    budget != NO_VISIBLE_POINT && !mapper.mixed.get(slot).is_some_and(|&m| m);
                if !visible && !in_band {
                    out.clear_one(col);
                    continue;
                }
                let own = own_radiance(radius[slot], flux[slot], n);
                if in_band {
                    band.radiance[slot - first_slot] = own;
                }
                if !visible {
                    out.clear_one(col);
                    continue;
                }
                if in_band {
                    band.cap[slot - first_slot] = rule.cap(mapper, slot);
                    band.spread[slot - first_slot] =
                        1.0 / mapper.slots.photon_count()[slot].max(1.0).sqrt();
                }
                // The mean weight of the passes, which the radiance carries (not the last one's).
                let weight = mapper.mean_weight[slot];
                let flat = std::array::from_fn(|c| {
                    if weight[c] > 0.0 {
                        own[c] as f32 / weight[c]
                    } else {
                        0.0
                    }
                });
                RowMut::set(&mut out.position, col, positions[slot].to_array());
                RowMut::set(&mut out.normal, col, normals[slot].to_array());
                RowMut::set(
                    &mut out.shading_normal,
                    col,
                    shading_normals[slot].to_array(),
                );
                RowMut::set(&mut out.weight, col, weight.to_array());
                RowMut::set(&mut out.flat, col, flat);
                out.material[col] = materials[slot];
                out.budget[col] = u32::from(budget);
            }
        }
    }

    /// The planes as [`View`] reads them.
    #[inline(always)]
    fn view(&self) -> View<'_> {
        let len = self.len;
        View {
            halo: self.halo,
            stride: self.stride,
            top: self.top,
            position: self.position.slices(len),
            normal: self.normal.slices(len),
            shading_normal: self.shading_normal.slices(len),
            weight: self.weight.slices(len),
            flat: self.flat.slices(len),
            material: &self.material[..len],
            budget: &self.budget[..len],
        }
    }
}

/// Three planes cut to one length.
#[derive(Clone, Copy)]
struct Slices3<'a> {
    x: &'a [f32],
    y: &'a [f32],
    z: &'a [f32],
}

impl Slices3<'_> {
    #[inline(always)]
    fn load(&self, at: usize) -> V3 {
        V3 {
            x: load(self.x, at),
            y: load(self.y, at),
            z: load(self.z, at),
        }
    }
}

impl Plane3 {
    fn slices(&self, len: usize) -> Slices3<'_> {
        Slices3 {
            x: &self.x[..len],
            y: &self.y[..len],
            z: &self.z[..len],
        }
    }
}

/// The planes as the pooling reads them: every plane cut to the same length, so that the
/// compiler checks the bounds of a tap's seventeen loads once.
struct View<'a> {
    halo: usize,
    stride: usize,
    top: isize,
    position: Slices3<'a>,
    normal: Slices3<'a>,
    shading_normal: Slices3<'a>,
    weight: Slices3<'a>,
    flat: Slices3<'a>,
    material: &'a [u32],
    budget: &'a [u32],
}

impl View<'_> {
    /// Where pixel (x, y) of the film is.
    #[inline]
    fn index(&self, x: usize, y: usize) -> usize {
        (y as isize - self.top) as usize * self.stride + x + self.halo
    }

    /// How far from a pixel its neighbour `(dx, dy)` is in the planes.
    fn offset(&self, dx: i32, dy: i32) -> isize {
        dy as isize * self.stride as isize + dx as isize
    }
}

/// Three vectors: a 3D quantity of eight pixels.
#[derive(Clone, Copy)]
struct V3 {
    x: f32x8,
    y: f32x8,
    z: f32x8,
}

impl V3 {
    #[inline]
    fn dot(self, other: Self) -> f32x8 {
        self.x * other.x + self.y * other.y + self.z * other.z
    }

    /// Two tangents completing each unit vector to an orthonormal basis (Duff et al. 2017, as
    /// glam's `any_orthonormal_pair`).
    fn orthonormal_pair(self) -> (Self, Self) {
        let sign = self.z.simd_lt(f32x8::ZERO).select(-f32x8::ONE, f32x8::ONE);
        let a = -f32x8::ONE / (sign + self.z);
        let b = self.x * self.y * a;
        (
            V3 {
                x: f32x8::ONE + sign * self.x * self.x * a,
                y: sign * b,
                z: -sign * self.x,
            },
            V3 {
                x: b,
                y: sign + self.y * self.y * a,
                z: -self.y,
            },
        )
    }
}

impl Sub for V3 {
    type Output = Self;
    #[inline]
    fn sub(self, other: Self) -> Self {
        V3 {
            x: self.x - other.x,
            y: self.y - other.y,
            z: self.z - other.z,
        }
    }
}

/// Eight pixels' visible points as the surface tests read them.
struct Centre {
    position: V3,
    normal: V3,
    shading_normal: V3,
    weight: V3,
    flat: V3,
    material: u32x8,
    budget: u32x8,
    /// Lanes with a visible point.
    valid: f32x8,
}

impl Centre {
    #[inline]
    fn load(planes: &View, at: usize) -> Self {
        let budget = load_u32(planes.budget, at);
        let none = u32x8::splat(u32::from(NO_VISIBLE_POINT));
        Self {
            position: planes.position.load(at),
            normal: planes.normal.load(at),
            shading_normal: planes.shading_normal.load(at),
            weight: planes.weight.load(at),
            flat: planes.flat.load(at),
            material: load_u32(planes.material, at),
            budget,
            valid: !mask(budget.simd_eq(none)),
        }
    }

    /// The lanes whose neighbour at `at` (`offset` away, at squared distance `d2`) lies on the
    /// pixel's surface: a visible point of the same material and photon-bounce budget, both
    /// normals within about 25°, close to the pixel's tangent plane, and hitpoint weights within
    /// 10 % per channel.
    #[inline(always)]
    fn on_surface(&self, planes: &View, at: usize, offset: V3, d2: f32x8) -> f32x8 {
        let same = mask(load_u32(planes.material, at).simd_eq(self.material))
            & mask(load_u32(planes.budget, at).simd_eq(self.budget))
            & self.valid;
        let cos = f32x8::splat(NORMAL_COS);
        let normals = self.normal.dot(planes.normal.load(at)).simd_ge(cos)
            & self
                .shading_normal
                .dot(planes.shading_normal.load(at))
                .simd_ge(cos);
        let height = self.normal.dot(offset);
        let plane = (height * height).simd_le(f32x8::splat(PLANE_SLOPE * PLANE_SLOPE) * d2);
        same & normals & plane & weights_agree(self.weight, planes.weight.load(at))
    }
}

#[inline]
fn load_u32(plane: &[u32], at: usize) -> u32x8 {
    u32x8::from(&plane[at..at + LANES])
}

/// An integer mask as a float mask.
#[inline]
fn mask(m: u32x8) -> f32x8 {
    f32x8::from_bits(m)
}

/// The lanes where two hitpoint weights agree within [`WEIGHT_TOLERANCE`] in every channel.
#[inline]
fn weights_agree(a: V3, b: V3) -> f32x8 {
    let tolerance = f32x8::splat(WEIGHT_TOLERANCE);
    // Weights are finite: the maximum needs no care for NaN.
    let agree = |a: f32x8, b: f32x8| (a - b).abs().simd_le(a.fast_max(b) * tolerance);
    agree(a.x, b.x) & agree(a.y, b.y) & agree(a.z, b.z)
}

/// A tap that reaches some of a group's pixels: its Gaussian weight per lane (0 where it does
/// not reach or lies off the pixel's surface), its position in units of the width in the
/// pixel's tangent frame, and where it is in the planes.
#[derive(Clone, Copy)]
struct Weighted {
    k: f32x8,
    u: f32x8,
    v: f32x8,
    at: usize,
}

/// The moments of eight weighted least-squares plane fits, in units of the pooling width, with
/// the pixels' own values at weight 1 at (0, 0).
struct Fit {
    /// Σk·[1, u, v, uu, uv, vv].
    moments: [f32x8; 6],
    /// Σk·L·[1, u, v] per channel.
    values: [[f32x8; 3]; 3],
    /// The smallest and the largest value per channel of the taps that count (k > 0) and of
    /// the centre: the range the fit's value is held to.
    range: [[f32x8; 3]; 2],
}

impl Fit {
    fn new(own: V3) -> Self {
        let zero = [f32x8::ZERO; 3];
        let mut moments = [f32x8::ZERO; 6];
        moments[0] = f32x8::ONE;
        let own = [own.x, own.y, own.z];
        Self {
            moments,
            values: [own, zero, zero],
            range: [own, own],
        }
    }

    /// Adds the taps' weights and positions to the moments.
    #[inline]
    fn add_moments(&mut self, taps: &[Weighted]) {
        let mut m = self.moments;
        for &Weighted { k, u, v, .. } in taps {
            let (ku, kv) = (k * u, k * v);
            m[0] += k;
            m[1] += ku;
            m[2] += kv;
            m[3] += ku * u;
            m[4] += ku * v;
            m[5] += kv * v;
        }
        self.moments = m;
    }

    /// Adds the taps' values (of `flat`) to the value sums.
    #[inline]
    fn add_values(&mut self, taps: &[Weighted], flat: &Slices3) {
        let mut values = self.values;
        let [mut lo, mut hi] = self.range;
        for &Weighted { k, u, v, at } in taps {
            let (ku, kv) = (k * u, k * v);
            let counts = k.simd_gt(f32x8::ZERO);
            let value = flat.load(at);
            for (c, value) in [value.x, value.y, value.z].into_iter().enumerate() {
                values[0][c] += k * value;
                values[1][c] += ku * value;
                values[2][c] += kv * value;
                lo[c] = counts.select(lo[c].min(value), lo[c]);
                hi[c] = counts.select(hi[c].max(value), hi[c]);
            }
        }
        self.values = values;
        self.range = [lo, hi];
    }

    /// Each lane's plane value at the centre, or the weighted mean where the neighbours do not
    /// span the plane (all on one line) well enough to fit a gradient; held to the range of the
    /// values it was fitted to. A plane extrapolated over a curved falloff (beside a lamp, at a
    /// shadow's rim) overshoots that range, as far as below zero: a linear field read where its
    /// samples surround the centre, and the mean, never leave it.
    #[inline]
    fn centre(&self) -> [f32x8; 3] {
        let [m0, mu, mv, muu, muv, mvv] = self.moments;
        let inv = f32x8::ONE / m0;
        // Covariance of the tap positions about their weighted mean.
        let (cu, cv) = (mu * inv, mv * inv);
        let (suu, suv, svv) = (
            muu * inv - cu * cu,
            muv * inv - cu * cv,
            mvv * inv - cv * cv,
        );
        let det = suu * svv - suv * suv;
        // False for a NaN determinant too.
        let spans = det.simd_gt(f32x8::splat(1e-3));
        let inv_det = f32x8::ONE / det;
        std::array::from_fn(|c| {
            let mean = self.values[0][c] * inv;
            // L(0) = mean − g·centroid, g = Σ⁻¹·cov(p, L).
            let lu = self.values[1][c] * inv - cu * mean;
            let lv = self.values[2][c] * inv - cv * mean;
            let gu = (svv * lu - suv * lv) * inv_det;
            let gv = (suu * lv - suv * lu) * inv_det;
            let [lo, hi] = [self.range[0][c], self.range[1][c]];
            spans.select(mean - gu * cu - gv * cv, mean).max(lo).min(hi)
        })
    }
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
            let area: f64 = taps.iter().map(|t| f64::from(t.area)).sum();
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

    /// Fits the centre (value `own` at u = v = 0) to taps at `(u, v)` with `values`, every
    /// lane alike, weights k = 1.
    fn fit_centre(own: f32, taps: &[((f32, f32), f32)]) -> f32 {
        let plane: Vec<f32> = taps.iter().flat_map(|&(_, value)| [value; LANES]).collect();
        let flat = Slices3 {
            x: &plane,
            y: &plane,
            z: &plane,
        };
        let weighted: Vec<Weighted> = taps
            .iter()
            .enumerate()
            .map(|(i, &((u, v), _))| Weighted {
                k: f32x8::ONE,
                u: f32x8::splat(u),
                v: f32x8::splat(v),
                at: i * LANES,
            })
            .collect();
        let own = f32x8::splat(own);
        let mut fit = Fit::new(V3 {
            x: own,
            y: own,
            z: own,
        });
        fit.add_moments(&weighted);
        fit.add_values(&weighted, &flat);
        fit.centre()[0].to_array()[0]
    }

    #[test]
    fn the_fit_stays_within_the_values_it_reads() {
        // A step seen from one side: dark at the centre and the column beside it, lit beyond.
        // The least-squares plane through these reads −0.19 at the centre.
        let mut step = Vec::new();
        for v in [-1.0f32, 0.0, 1.0] {
            for u in [1.0f32, 2.0, 3.0] {
                step.push(((u, v), if u < 1.5 { 0.0 } else { 1.0 }));
            }
        }
        let value = fit_centre(0.0, &step);
        assert!((0.0..=1.0).contains(&value), "{value}");
        // A linear field whose taps surround the centre is read exactly, as before.
        let mut ramp = Vec::new();
        for v in [-2.0f32, -1.0, 0.0, 1.0, 2.0] {
            for u in [-2.0f32, -1.0, 0.0, 1.0, 2.0] {
                if u != 0.0 || v != 0.0 {
                    ramp.push(((u, v), 0.5 + 0.1 * u - 0.05 * v));
                }
            }
        }
        let value = fit_centre(0.5, &ramp);
        assert!((value - 0.5).abs() < 1e-5, "{value}");
    }

    #[test]
    fn gaussian_is_exp_bit_for_bit_within_the_cutoff() {
        let cutoff = 0.5 * CUTOFF_SIGMAS * CUTOFF_SIGMAS;
        let steps = 1 << 20;
        for i in (0..=steps).step_by(LANES) {
            let x = f32x8::new(std::array::from_fn(|lane| {
                -cutoff * (i + lane) as f32 / steps as f32
            }));
            let (got, want) = (gaussian(x).to_array(), x.exp().to_array());
            for lane in 0..LANES {
                assert_eq!(
                    got[lane].to_bits(),
                    want[lane].to_bits(),
                    "{:?}",
                    x.to_array()
                );
            }
        }
        // Far taps stay finite (they are masked out).
        for x in [-50.0, -87.0, -200.0, -1e30] {
            assert!(gaussian(f32x8::splat(x)).to_array()[0].is_finite());
        }
    }

    #[test]
    fn weights_agree_within_the_tolerance() {
        let splat = |w: [f32; 3]| V3 {
            x: f32x8::splat(w[0]),
            y: f32x8::splat(w[1]),
            z: f32x8::splat(w[2]),
        };
        let agree = |a: [f32; 3], b: [f32; 3]| {
            let m = weights_agree(splat(a), splat(b));
            assert!(m.all() || m.none(), "lanes disagree");
            m.all()
        };
        let a = [0.5, 0.4, 0.3];
        assert!(agree(a, a));
        assert!(agree(a, a.map(|c| c * 1.05)));
        assert!(!agree(a, a.map(|c| c * 1.2)));
        assert!(!agree(a, [0.5, 0.4, 0.0]));
        assert!(agree([0.0; 3], [0.0; 3]));
    }

    #[test]
    fn tangent_pairs_are_orthonormal() {
        let normals = [
            [0.0, 0.0, 1.0],
            [0.0, 0.0, -1.0],
            [1.0, 0.0, 0.0],
            [0.0, -1.0, 0.0],
            [0.6, 0.0, -0.8],
            [0.48, 0.6, 0.64],
            [-0.36, 0.48, -0.8],
            [0.0, 0.6, 0.8],
        ];
        let lanes = |c: usize| f32x8::new(std::array::from_fn(|i| normals[i][c]));
        let n = V3 {
            x: lanes(0),
            y: lanes(1),
            z: lanes(2),
        };
        let (t, b) = n.orthonormal_pair();
        for (name, value, expected) in [
            ("t·t", t.dot(t), 1.0),
            ("b·b", b.dot(b), 1.0),
            ("t·b", t.dot(b), 0.0),
            ("t·n", t.dot(n), 0.0),
            ("b·n", b.dot(n), 0.0),
        ] {
            for v in value.to_array() {
                assert!((v - expected).abs() < 1e-5, "{name} = {v}");
            }
        }
    }

    #[test]
    fn a_visible_point_stays_on_its_surface_only_along_it() {
        use glam::Vec3;
        let at = |position: Vec3, normal: Vec3| {
            Some(SurfacePoint {
                position,
                normal,
                shading_normal: normal,
                material: 3,
                budget: 7,
            })
        };
        let here = at(Vec3::ZERO, Vec3::Y);
        // Along the plane, however far, and with a slightly turned normal: the same surface.
        assert!(same_surface(here, at(Vec3::new(5.0, 0.0, -2.0), Vec3::Y)));
        let tilted = Vec3::new(0.0, 1.0, 0.3).normalize();
        assert!(same_surface(here, at(Vec3::new(0.1, 0.0, 0.0), tilted)));
        assert!(same_surface(None, None));
        // A parallel plane behind it (a silhouette), a turned surface, another material or
        // budget, or no visible point on one side: another surface.
        assert!(!same_surface(here, at(Vec3::new(0.1, 0.5, 0.0), Vec3::Y)));
        assert!(!same_surface(here, at(Vec3::new(0.1, 0.0, 0.0), Vec3::X)));
        let other = |f: fn(&mut SurfacePoint)| {
            let mut p = here.unwrap();
            p.position.x = 0.1;
            f(&mut p);
            Some(p)
        };
        assert!(!same_surface(here, other(|p| p.material = 4)));
        assert!(!same_surface(here, other(|p| p.budget = 6)));
        assert!(!same_surface(here, None));
        assert!(!same_surface(None, here));
    }
}
