//! Volume photons and their gather (`docs/media.md`): photons that scatter in a participating
//! medium are stored where they scatter, and the camera rays' stretches through media gather
//! them by the beam radiance estimate (Jarosz, Zwicker and Jensen 2008), with a radius that
//! shrinks pass by pass as Knaus and Zwicker (2011) prescribe, so that the mean of the passes'
//! estimates converges.
//!
//! One pass's estimate for a camera stretch (origin o, unit direction ω, length t_max, weight β
//! of the camera path at o) is
//!
//!   L = β / N · Σᵢ T(o, xᵢ′) · p(−ω, ωᵢ) · Φᵢ / A(xᵢ′)
//!
//! over the photons i of the same medium whose distance to the stretch is below r, where xᵢ′ is
//! the photon's projection onto the stretch, T the transmittance from o to it, p the phase
//! function, ωᵢ the photon's direction back toward where it came from, N the photons emitted in
//! the pass and Φᵢ the photon's power times σs·T/pdf of the free flight that stopped it (so that
//! the photons' density is σs times the radiance arriving there, per photon emitted) and A the
//! area of the disc of radius r across the stretch at xᵢ′ that lies inside the medium (πr² but
//! near the surfaces the stretch starts and ends on, [`inside_area`]). The 2D kernel in the plane
//! across the stretch blurs the in-scattered radiance as a surface kernel does, so the same
//! radius schedule applies: r²ₖ₊₁ = r²ₖ (k + α)/(k + 1).
//!
//! Stretches are found by a tree over the photons (sorted in Morton order, leaves of
//! [`LEAF`] photons, boxes grown by r), walked in a fixed order: the sums, hence the image, do
//! not depend on the number of threads.

use glam::{Vec2, Vec3};
use photon::MortonScratch;
use rayon::prelude::*;
use scene::{Medium, Rgb, Scene};

use crate::update::schedule_squared;

/// Photons per leaf of [`VolumeTree`].
const LEAF: usize = 8;

/// A photon stored where it scattered in a medium.
#[derive(Clone, Copy, Debug)]
pub(crate) struct VolumePhoton {
    pub(crate) position: Vec3,
    /// Unit direction back toward where the photon came from.
    pub(crate) incoming: Vec3,
    /// Its power times σs·T/pdf of the free flight that stopped it (per photon emitted).
    pub(crate) power: Rgb,
    /// The medium it scattered in.
    pub(crate) medium: u32,
    /// Its bounces before this one.
    pub(crate) bounces: u32,
}

/// A camera ray's stretch through a medium, gathered every pass it was traced for.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Segment {
    pub(crate) origin: Vec3,
    /// Unit direction.
    pub(crate) direction: Vec3,
    /// Its length (infinite if the ray leaves the scene in the medium).
    pub(crate) t_max: f32,
    pub(crate) medium: u32,
    /// The most bounces a photon may have made and still count here, so that no light path
    /// has more than `max_depth` scattering events (the medium vertex being one).
    pub(crate) budget: u32,
    /// The hitpoint slot whose pixel it adds to.
    pub(crate) slot: u32,
    /// The camera path's weight at `origin`: specular throughput and transmittance so far
    /// (not yet divided by the slots per pixel).
    pub(crate) weight: Rgb,
    /// The geometric normal of the surface the stretch starts on, zero if it starts at the
    /// camera: the medium's boundary there, for the kernel's correction ([`inside_area`]).
    pub(crate) entry_normal: Vec3,
    /// The geometric normal of the surface it ends on, zero if it leaves the scene.
    pub(crate) exit_normal: Vec3,
    /// Whether it lies on the slot's primary ray through a pinhole (no bounce before it), so
    /// that [`ScreenIndex`] finds its photons by the pixel it crosses.
    pub(crate) primary: bool,
    /// In a grid medium, its ratio-tracking walk: the range of [`Volume::tables`] (of the
    /// camera sample's own list while it is traced) that [`stretch_transmittance`] filled; empty
    /// in a homogeneous one, whose transmittance is exact.
    pub(crate) table: (u32, u32),
}

/// The transmittance of `medium` along the camera stretch (`origin`, unit `direction`,
/// `t_max`): exact in a homogeneous medium, drawing nothing; in a grid, one ratio-tracking walk
/// (`Medium::transmittance_walk`, numbers from `u`) whose tentative collisions are appended to
/// `table` as (t, the walk's product up to and including t), so that the one walk serves the
/// stretch's end and every photon gathered along it ([`table_transmittance`]).
pub(crate) fn stretch_transmittance(
    medium: &Medium,
    origin: Vec3,
    direction: Vec3,
    t_max: f32,
    table: &mut Vec<(f32, Rgb)>,
    u: &mut impl FnMut() -> f32,
) -> Rgb {
    medium.transmittance_walk(origin, direction, t_max, u, |t, tr| table.push((t, tr)))
}

/// The transmittance from a stretch's origin to `t` along it, from its ratio-tracking walk.
fn table_transmittance(table: &[(f32, Rgb)], t: f32) -> Rgb {
    match table.partition_point(|&(tj, _)| tj <= t) {
        0 => Rgb::ONE,
        k => table[k - 1].1,
    }
}

/// The area of the disc of radius `r` across the stretch at distance `t` along it that lies
/// inside the medium, taking the surfaces the stretch starts and ends on as planes: the kernel's
/// normalization. Dividing by πr² instead would count the part of the disc beyond the medium's
/// boundary, where no photon can be, and darken every stretch by a share of about r/length
/// (4.6 % in the middle of the fog box at 64² with R₀, measured against the path tracer): the
/// boundary bias of density estimation, here corrected to first order by renormalising the
/// kernel over the region photons can occupy.
fn inside_area(segment: &Segment, t: f32, r: f32) -> f32 {
    let full = std::f32::consts::PI * r * r;
    let d = segment.direction;
    // The area of the disc beyond a plane of unit normal `n` at signed distance `h` from its
    // centre, measured along n toward the medium.
    let outside = |n: Vec3, h: f32| -> f32 {
        let cos = n.dot(d);
        let sin = (1.0 - cos * cos).max(0.0).sqrt();
        if n == Vec3::ZERO || sin < 1e-6 {
            return 0.0;
        }
        let a = (h / sin).clamp(-r, r);
        if a >= r {
            return 0.0;
        }
        r * r * (a / r).acos() - a * (r * r - a * a).max(0.0).sqrt()
    };
    let n_entry = segment.entry_normal;
    let entry = outside(n_entry, t * n_entry.dot(d).abs());
    let exit = if segment.t_max.is_finite() {
        let n_exit = segment.exit_normal;
        outside(n_exit, (segment.t_max - t) * n_exit.dot(d).abs())
    } else {
        0.0
    };
    // Never below a tenth of the disc: a stretch that grazes a boundary keeps a bounded weight.
    (full - entry - exit).max(0.1 * full)
}

#[derive(Clone, Copy, Debug)]
struct Aabb {
    min: Vec3,
    max: Vec3,
}

impl Aabb {
    const EMPTY: Self = Self {
        min: Vec3::splat(f32::INFINITY),
        max: Vec3::splat(f32::NEG_INFINITY),
    };

    fn union(self, other: Self) -> Self {
        Self {
            min: self.min.min(other.min),
            max: self.max.max(other.max),
        }
    }

    /// Whether the stretch [0, `t_max`] of the ray (origin, 1/direction) meets the box.
    #[inline]
    fn meets(&self, origin: Vec3, inverse: Vec3, t_max: f32) -> bool {
        let t0 = (self.min - origin) * inverse;
        let t1 = (self.max - origin) * inverse;
        // `min`/`max` take the other operand where one is NaN (0 · ∞ on a slab's plane).
        let near = t0.min(t1).max_element().max(0.0);
        let far = t0.max(t1).min_element().min(t_max);
        near <= far
    }
}

/// The photons of a pass in Morton order with a binary tree of boxes over their leaves.
#[derive(Default)]
pub(crate) struct VolumeTree {
    photons: Vec<VolumePhoton>,
    /// `levels[0]` the leaves' boxes (grown by the radius), each level above the unions of
    /// pairs of the one below; the last has one box, the root.
    levels: Vec<Vec<Aabb>>,
    keys: MortonScratch,
}

impl VolumeTree {
    /// Rebuilds the tree over the photons of `chunks` (in trace order) for gathers of radius
    /// `radius`.
    pub(crate) fn build<C: AsRef<[VolumePhoton]> + Sync>(&mut self, chunks: &[C], radius: f32) {
        self.levels.clear();
        photon::morton_sort(
            chunks,
            |p: &VolumePhoton| p.position,
            &mut self.keys,
            &mut self.photons,
        );
        if self.photons.is_empty() {
            return;
        }
        let grow = Vec3::splat(radius);
        let leaves: Vec<Aabb> = self
            .photons
            .par_chunks(LEAF)
            .map(|leaf| {
                let b = leaf.iter().fold(Aabb::EMPTY, |b, p| {
                    b.union(Aabb {
                        min: p.position,
                        max: p.position,
                    })
                });
                Aabb {
                    min: b.min - grow,
                    max: b.max + grow,
                }
            })
            .collect();
        self.levels.push(leaves);
        while let Some(below) = self.levels.last().filter(|l| l.len() > 1) {
            let above = below
                .chunks(2)
                .map(|pair| pair.iter().fold(Aabb::EMPTY, |b, &c| b.union(c)))
                .collect();
            self.levels.push(above);
        }
    }

    /// Calls `visit(photon, t)` for every photon within `radius` of the stretch `segment` whose
    /// projection t onto it lies on it, in a fixed order.
    pub(crate) fn gather(
        &self,
        segment: &Segment,
        radius: f32,
        mut visit: impl FnMut(&VolumePhoton, f32),
    ) {
        let Some(top) = self.levels.len().checked_sub(1) else {
            return;
        };
        let origin = segment.origin;
        let inverse = segment.direction.recip();
        let r2 = radius * radius;
        let mut stack: Vec<(usize, usize)> = Vec::with_capacity(2 * self.levels.len());
        stack.push((top, 0));
        while let Some((level, node)) = stack.pop() {
            if !self.levels[level][node].meets(origin, inverse, segment.t_max) {
                continue;
            }
            if level == 0 {
                let end = ((node + 1) * LEAF).min(self.photons.len());
                for photon in &self.photons[node * LEAF..end] {
                    test(segment, r2, photon, &mut visit);
                }
                continue;
            }
            let below = self.levels[level - 1].len();
            // The second child first on the stack, so the first is walked first.
            for child in [2 * node + 1, 2 * node] {
                if child < below {
                    stack.push((level - 1, child));
                }
            }
        }
    }

    /// Heap bytes of the tree.
    pub(crate) fn heap_bytes(&self) -> usize {
        use std::mem::size_of;
        self.photons.capacity() * size_of::<VolumePhoton>()
            + self.keys.heap_bytes()
            + self
                .levels
                .iter()
                .map(|l| l.capacity() * size_of::<Aabb>())
                .sum::<usize>()
    }
}

/// Calls `visit(photon, t)` if `photon` lies within √`r2` of the stretch `segment` and its
/// projection t onto it lies on it.
#[inline]
fn test(
    segment: &Segment,
    r2: f32,
    photon: &VolumePhoton,
    visit: &mut impl FnMut(&VolumePhoton, f32),
) {
    let v = photon.position - segment.origin;
    let t = v.dot(segment.direction);
    if (0.0..=segment.t_max).contains(&t) && v.length_squared() - t * t <= r2 {
        visit(photon, t);
    }
}

/// The photons of a pass by the pixels whose primary rays pass within the radius of them, for
/// the stretches that lie on primary rays through a pinhole: a long stretch through a thin
/// medium meets few photons, and a tree walked along it tests fifty times more than it finds,
/// where a pixel's list holds little more than what its rays find. A photon that
/// appears wider than [`SCREEN_RADIUS_CAP`] pixels (near the camera, or behind it) goes to a
/// small tree of its own, which those stretches also walk.
#[derive(Default)]
struct ScreenIndex {
    width: usize,
    /// Per pixel, where its entries start in `entries` (one more than the pixels).
    offsets: Vec<u32>,
    /// Indices into the main tree's photons, pixel by pixel, each pixel's in the tree's order.
    entries: Vec<u32>,
    near: VolumeTree,
    /// Per photon: its film position and the distance from it within which pixel centres list
    /// it, or `None` for the near tree.
    discs: Vec<Option<(Vec2, f32)>>,
}

/// The widest a photon's disc may appear on the film, in pixels, to be listed by pixel.
const SCREEN_RADIUS_CAP: f32 = 12.0;

impl ScreenIndex {
    /// Lists `photons` (the main tree's, in its order) by the pixels of `camera`'s film whose
    /// primary rays may pass within `radius` of them.
    fn build(&mut self, camera: &scene::CameraModel, photons: &[VolumePhoton], radius: f32) {
        let (width, height) = camera.resolution();
        let (w, h) = (width as usize, height as usize);
        self.width = w;
        let focal = camera.focal_pixels();
        // The ray of pixel g passes at least z·|Δfilm|·cos θ/F from a photon at depth z whose
        // film position is Δfilm away (θ the ray's angle to the view axis, at most the film
        // corner's): a photon within `radius` of it is at most radius·F/(z·cos θ) pixels away,
        // plus the slot's jitter within its pixel.
        let half = Vec2::new(width as f32, height as f32) / (2.0 * focal);
        let cos_max = 1.0 / (1.0 + half.length_squared()).sqrt();
        let reach = radius * focal / cos_max;
        self.discs.clear();
        self.discs.par_extend(photons.par_iter().map(|p| {
            let (film, z) = camera.film_point(p.position)?;
            let rho = reach / z;
            // Pixel centres within rho + √½ of the film position (a slot's ray crosses its
            // pixel anywhere).
            (rho <= SCREEN_RADIUS_CAP).then_some((film, rho + std::f32::consts::FRAC_1_SQRT_2))
        }));
        let last = Vec2::new(width as f32 - 1.0, height as f32 - 1.0);
        // Calls `list(pixel)` for every pixel whose centre lies in the disc.
        let pixels = |(film, span): (Vec2, f32), list: &mut dyn FnMut(usize)| {
            let lo = (film - span).floor().max(Vec2::ZERO);
            let hi = (film + span).floor().min(last);
            if lo.x > hi.x || lo.y > hi.y {
                return;
            }
            for y in lo.y as usize..=hi.y as usize {
                let dy = y as f32 + 0.5 - film.y;
                for x in lo.x as usize..=hi.x as usize {
                    let dx = x as f32 + 0.5 - film.x;
                    if dx * dx + dy * dy <= span * span {
                        list(y * w + x);
                    }
                }
            }
        };
        self.offsets.clear();
        self.offsets.resize(w * h + 1, 0);
        for disc in self.discs.iter().flatten() {
            pixels(*disc, &mut |pixel| self.offsets[pixel + 1] += 1);
        }
        for i in 1..self.offsets.len() {
            self.offsets[i] += self.offsets[i - 1];
        }
        self.entries.clear();
        self.entries.resize(self.offsets[w * h] as usize, 0);
        let mut next: Vec<u32> = self.offsets[..w * h].to_vec();
        for (i, disc) in self.discs.iter().enumerate() {
            if let Some(disc) = disc {
                pixels(*disc, &mut |pixel| {
                    self.entries[next[pixel] as usize] = i as u32;
                    next[pixel] += 1;
                });
            }
        }
        let near: Vec<VolumePhoton> = photons
            .iter()
            .zip(&self.discs)
            .filter(|(_, disc)| disc.is_none())
            .map(|(p, _)| *p)
            .collect();
        self.near.build(&[near], radius);
    }

    /// [`VolumeTree::gather`] for a primary stretch of the slot of pixel `pixel`.
    fn gather(
        &self,
        photons: &[VolumePhoton],
        segment: &Segment,
        pixel: usize,
        radius: f32,
        mut visit: impl FnMut(&VolumePhoton, f32),
    ) {
        let r2 = radius * radius;
        if let Some(range) = self.offsets.get(pixel..pixel + 2) {
            for &i in &self.entries[range[0] as usize..range[1] as usize] {
                test(segment, r2, &photons[i as usize], &mut visit);
            }
        }
        self.near.gather(segment, radius, visit);
    }

    fn heap_bytes(&self) -> usize {
        use std::mem::size_of;
        (self.offsets.capacity() + self.entries.capacity()) * size_of::<u32>()
            + self.discs.capacity() * size_of::<Option<(Vec2, f32)>>()
            + self.near.heap_bytes()
    }
}

/// The volume gather's radius in pass `pass` (0-based) from `initial`: r²ₖ₊₁ = r²ₖ (k + α)/(k + 1)
/// (Knaus and Zwicker 2011, for a kernel over two dimensions), k counted from 1.
pub(crate) fn radius_after(initial: f64, alpha: f64, pass: u32) -> f64 {
    initial * schedule_squared(u64::from(pass), alpha).sqrt()
}

/// What the volume gather keeps between passes: the sum of the passes' estimates per slot,
/// the number of passes summed, the camera stretches of the last camera pass and the tree.
#[derive(Default)]
pub(crate) struct Volume {
    /// Per slot: the sum over passes of its pass estimates (weighted by 1/spp); empty in a
    /// scene without media.
    pub(crate) sum: Vec<[f64; 3]>,
    /// The passes whose estimates `sum` holds.
    pub(crate) gathers: u32,
    /// Per slot: the last pass's estimate (weighted by 1/spp), for the pass-independent
    /// estimator, which sums pass images of its own; empty in a scene without media.
    pub(crate) last: Vec<[f64; 3]>,
    /// The stretches of the camera paths of the last camera pass that placed visible points,
    /// in slot order.
    pub(crate) segments: Vec<Segment>,
    /// The ratio-tracking walks of the stretches through grid media ([`Segment::table`]).
    pub(crate) tables: Vec<(f32, Rgb)>,
    /// Whether `segments` were traced by this renderer (a restored one has none yet).
    pub(crate) segments_traced: bool,
    tree: VolumeTree,
    screen: ScreenIndex,
}

impl Volume {
    /// Appends one camera sample's stretches and their ratio-tracking walks (whose ranges index
    /// `tables`).
    pub(crate) fn add_segments(&mut self, segments: &[Segment], tables: &[(f32, Rgb)]) {
        let offset = self.tables.len() as u32;
        self.tables.extend_from_slice(tables);
        self.segments.extend(segments.iter().map(|s| Segment {
            table: (s.table.0 + offset, s.table.1 + offset),
            ..*s
        }));
    }

    /// Heap bytes of the per-pass buffers (stretches and tree) and of the per-slot sums.
    pub(crate) fn heap_bytes(&self) -> (usize, usize) {
        use std::mem::size_of;
        (
            self.segments.capacity() * size_of::<Segment>()
                + self.tables.capacity() * size_of::<(f32, Rgb)>()
                + self.tree.heap_bytes()
                + self.screen.heap_bytes(),
            (self.sum.capacity() + self.last.capacity()) * size_of::<[f64; 3]>(),
        )
    }

    /// Gathers the photons of pass `pass` (`photons`, `emitted` of them emitted) into every
    /// stretch, with the radius of that pass, keeps each slot's estimate as `last` and adds it
    /// to its sum; returns the contributions dropped for being NaN or infinite. The radius
    /// depends on the pass's index alone, so that the pass-independent estimator's passes can be
    /// rendered apart.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn gather_pass(
        &mut self,
        scene: &Scene,
        photons: &[&[VolumePhoton]],
        (initial_radius, alpha): (f64, f64),
        pass: u32,
        emitted: u64,
        samples_per_pixel: u32,
        n_slots: usize,
    ) -> u64 {
        let radius = radius_after(initial_radius, alpha, pass) as f32;
        self.tree.build(photons, radius);
        let primary = self.segments.iter().any(|s| s.primary);
        if primary {
            self.screen
                .build(scene.camera(), &self.tree.photons, radius);
        }
        self.sum.resize(n_slots, [0.0; 3]);
        self.last.clear();
        self.last.resize(n_slots, [0.0; 3]);
        self.gathers += 1;
        let media = &scene.media().list;
        let (tree, screen, tables) = (&self.tree, &self.screen, &self.tables);
        let normalization = 1.0 / (emitted as f32 * samples_per_pixel as f32);
        let estimates: Vec<Rgb> = self
            .segments
            .par_iter()
            .with_min_len(64)
            .map(|segment| {
                let Some(medium) = media.get(segment.medium as usize) else {
                    return Rgb::ZERO;
                };
                let phase = medium.phase();
                let outgoing = -segment.direction;
                let mut sum = Rgb::ZERO;
                let table = tables
                    .get(segment.table.0 as usize..segment.table.1 as usize)
                    .unwrap_or_default();
                let homogeneous = medium.is_homogeneous();
                let visit = |photon: &VolumePhoton, t: f32| {
                    if photon.medium == segment.medium && photon.bounces <= segment.budget {
                        let tr = if homogeneous {
                            medium.transmittance(t)
                        } else {
                            table_transmittance(table, t)
                        };
                        sum += tr
                            * photon.power
                            * (phase.eval(outgoing, photon.incoming)
                                / inside_area(segment, t, radius));
                    }
                };
                if segment.primary {
                    let pixel = (segment.slot / samples_per_pixel) as usize;
                    screen.gather(&tree.photons, segment, pixel, radius, visit);
                } else {
                    tree.gather(segment, radius, visit);
                }
                sum * segment.weight * normalization
            })
            .collect();
        let mut non_finite = 0;
        for (segment, estimate) in self.segments.iter().zip(estimates) {
            if !estimate.is_finite() {
                non_finite += 1;
                continue;
            }
            let last = &mut self.last[segment.slot as usize];
            for c in 0..3 {
                last[c] += f64::from(estimate[c]);
            }
        }
        for (sum, last) in self.sum.iter_mut().zip(&self.last) {
            for c in 0..3 {
                sum[c] += last[c];
            }
        }
        non_finite
    }

    /// Slot `slot`'s in-scattered radiance: the mean of the passes' estimates.
    pub(crate) fn radiance(&self, slot: usize) -> [f64; 3] {
        match self.sum.get(slot) {
            Some(sum) if self.gathers > 0 => sum.map(|v| v / f64::from(self.gathers)),
            _ => [0.0; 3],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn photon(position: Vec3) -> VolumePhoton {
        VolumePhoton {
            position,
            incoming: Vec3::Z,
            power: Rgb::ONE,
            medium: 0,
            bounces: 0,
        }
    }

    /// The tree finds exactly the photons a brute-force scan finds, each once.
    #[test]
    fn tree_gather_matches_brute_force() {
        let mut state = 12345u64;
        let mut next = || {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            ((state >> 40) as f32) / (1u64 << 24) as f32
        };
        let photons: Vec<VolumePhoton> = (0..5000)
            .map(|_| photon(Vec3::new(next(), next(), next()) * 2.0 - 1.0))
            .collect();
        let radius = 0.07;
        let mut tree = VolumeTree::default();
        tree.build(&[photons.as_slice()], radius);
        for _ in 0..200 {
            let origin = Vec3::new(next(), next(), next()) * 4.0 - 2.0;
            let direction = (Vec3::new(next(), next(), next()) - 0.5).normalize();
            let t_max = if next() < 0.2 {
                f32::INFINITY
            } else {
                3.0 * next()
            };
            let segment = Segment {
                origin,
                direction,
                t_max,
                medium: 0,
                budget: 0,
                slot: 0,
                weight: Rgb::ONE,
                entry_normal: Vec3::ZERO,
                exit_normal: Vec3::ZERO,
                primary: false,
                table: (0, 0),
            };
            let mut found = Vec::new();
            tree.gather(&segment, radius, |p, _| found.push(p.position.to_array()));
            let mut expected: Vec<[f32; 3]> = photons
                .iter()
                .filter(|p| {
                    let v = p.position - origin;
                    let t = v.dot(direction);
                    (0.0..=t_max).contains(&t) && v.length_squared() - t * t <= radius * radius
                })
                .map(|p| p.position.to_array())
                .collect();
            let key = |a: &[f32; 3]| a.map(f32::to_bits);
            found.sort_by_key(key);
            expected.sort_by_key(key);
            assert_eq!(found, expected);
        }
    }

    /// The pixel lists (with their near tree) find, for a stretch on a pixel's primary ray,
    /// exactly the photons a brute-force scan finds, each once: photons all around the camera,
    /// some behind it and some off the film.
    #[test]
    fn screen_index_matches_brute_force() {
        let mut state = 999u64;
        let mut next = || {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            ((state >> 40) as f32) / (1u64 << 24) as f32
        };
        let camera = scene::CameraModel::new(
            &scene::Camera {
                position: Vec3::new(0.1, 0.2, 3.0),
                look_at: Vec3::new(0.0, 0.0, 0.0),
                up: Vec3::Y,
                fov_y: 50f32.to_radians(),
                aperture_radius: 0.0,
                focus_distance: 1.0,
            },
            &scene::Film {
                width: 40,
                height: 30,
            },
        )
        .unwrap();
        let photons: Vec<VolumePhoton> = (0..20_000)
            .map(|_| photon(Vec3::new(next(), next(), next() * 1.2) * 4.0 - 2.0))
            .collect();
        let radius = 0.05;
        let mut tree = VolumeTree::default();
        tree.build(&[photons.as_slice()], radius);
        let mut screen = ScreenIndex::default();
        screen.build(&camera, &tree.photons, radius);
        assert!(!screen.near.photons.is_empty() && !screen.entries.is_empty());
        for pixel in 0..40 * 30 {
            let (x, y) = (pixel % 40, pixel / 40);
            let film = Vec2::new(x as f32 + next(), y as f32 + next());
            let ray = camera.generate_ray(film, Vec2::ZERO);
            let segment = Segment {
                origin: ray.origin + ray.direction.normalize() * 0.3 * next(),
                direction: ray.direction.normalize(),
                t_max: 1.0 + 4.0 * next(),
                medium: 0,
                budget: 0,
                slot: pixel as u32,
                weight: Rgb::ONE,
                entry_normal: Vec3::ZERO,
                exit_normal: Vec3::ZERO,
                primary: true,
                table: (0, 0),
            };
            let mut found = Vec::new();
            screen.gather(&tree.photons, &segment, pixel, radius, |p, _| {
                found.push(p.position.to_array());
            });
            let mut expected = Vec::new();
            for p in &photons {
                test(&segment, radius * radius, p, &mut |p, _| {
                    expected.push(p.position.to_array());
                });
            }
            let key = |a: &[f32; 3]| a.map(f32::to_bits);
            found.sort_by_key(key);
            expected.sort_by_key(key);
            assert_eq!(found, expected, "pixel {pixel}");
        }
    }

    #[test]
    fn radius_follows_the_schedule() {
        assert_eq!(radius_after(2.0, 0.7, 0), 2.0);
        let r1 = radius_after(2.0, 0.7, 1);
        assert!((r1 * r1 - 4.0 * 1.7 / 2.0).abs() < 1e-12);
        let r2 = radius_after(2.0, 0.7, 2);
        assert!((r2 * r2 - 4.0 * 1.7 / 2.0 * 2.7 / 3.0).abs() < 1e-12);
    }
}
