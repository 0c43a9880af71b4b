//! Which emitter next-event estimation samples from a given point: a bounding volume hierarchy
//! over the emitters with a finite position, each node bounding its emitters' positions, their
//! directions of emission and their power, descended by the importance of each child at the
//! receiving point (pbrt-v4's `BVHLightSampler`; Conty Estevez and Kulla 2018, "Importance
//! Sampling of Many Lights with Adaptive Tree Splitting").
//!
//! Why: picking an emitter by its share of the scene's power sends most light samples of a point
//! beside a dim lamp toward a bright one across the room, or toward the faces of a lamp that
//! point away; the point's own lamp is then found by rare samples of large weight. The importance
//! of a node at a point is its power over the squared distance, times a bound of the cosine at
//! the emitters and at the receiver (zero where no emitter of the node can face the point).
//!
//! The infinite lights (directional, environment) keep their share of the power: with that
//! probability one of them is picked by power, otherwise the tree is descended. Sampling and the
//! probability of a given emitter ([`LightTree::pmf`]) evaluate the same importances in the same
//! order, so the densities that multiple importance sampling needs are those the sampler used,
//! bit for bit.

use std::f32::consts::PI;

use glam::{Quat, Vec3};

use super::Emitter;
use crate::sampling::Distribution1D;

/// A cone of directions: unit axis `w` and the cosine of its half-angle (−1: every direction).
#[derive(Clone, Copy, Debug)]
struct Cone {
    w: Vec3,
    cos_theta: f32,
}

impl Cone {
    const SPHERE: Cone = Cone {
        w: Vec3::Z,
        cos_theta: -1.0,
    };

    /// The narrowest cone (up to pbrt's construction) that holds both (pbrt-v4's
    /// `Union(DirectionCone, DirectionCone)`), widened by a hair so that rounding never leaves a
    /// child's direction outside.
    fn union(a: Cone, b: Cone) -> Cone {
        let theta_a = a.cos_theta.clamp(-1.0, 1.0).acos();
        let theta_b = b.cos_theta.clamp(-1.0, 1.0).acos();
        let theta_d = a.w.angle_between(b.w);
        if (theta_d + theta_b).min(PI) <= theta_a {
            return a;
        }
        if (theta_d + theta_a).min(PI) <= theta_b {
            return b;
        }
        let theta_o = (theta_a + theta_d + theta_b) / 2.0 + 1e-4;
        if theta_o >= PI {
            return Cone::SPHERE;
        }
        let axis = a.w.cross(b.w);
        if axis.length_squared() == 0.0 {
            return Cone::SPHERE;
        }
        let w = Quat::from_axis_angle(axis.normalize(), theta_o - theta_a) * a.w;
        Cone {
            w: w.normalize(),
            cos_theta: theta_o.cos(),
        }
    }
}

/// What a node knows of its emitters: where they are, which way they emit, how much.
#[derive(Clone, Copy, Debug)]
pub(super) struct LightBounds {
    lo: Vec3,
    hi: Vec3,
    /// The emitters' normals (or axes) lie within this cone.
    normals: Cone,
    /// Cosine of the largest angle beyond the normal cone at which they still emit (0 for a
    /// one-sided Lambertian surface: up to 90°).
    cos_emit: f32,
    /// The luminance of their power.
    phi: f32,
    /// Derived once ([`LightBounds::new`]): the centre of `lo..hi`, half its diagonal, and the
    /// sine of the normal cone's half-angle.
    centre: Vec3,
    radius: f32,
    sin_o: f32,
}

impl LightBounds {
    /// Bounds with their derived quantities: the centre of `lo..hi`, half its diagonal, and the
    /// sine of the normal cone's half-angle.
    fn new(lo: Vec3, hi: Vec3, normals: Cone, cos_emit: f32, phi: f32) -> Self {
        Self {
            lo,
            hi,
            normals,
            cos_emit,
            phi,
            centre: 0.5 * (lo + hi),
            radius: 0.5 * (hi - lo).length(),
            sin_o: (1.0 - normals.cos_theta * normals.cos_theta)
                .max(0.0)
                .sqrt(),
        }
    }

    /// A one-sided surface emitter (a triangle) of power `phi`, facing `normal`.
    pub(super) fn surface(lo: Vec3, hi: Vec3, normal: Vec3, phi: f32) -> Self {
        let normals = Cone {
            w: normal,
            cos_theta: 1.0,
        };
        Self::new(lo, hi, normals, 0.0, phi)
    }

    /// An emitter that sends light every way from within `lo..hi` (a sphere, a point light).
    pub(super) fn omni(lo: Vec3, hi: Vec3, phi: f32) -> Self {
        Self::new(lo, hi, Cone::SPHERE, 0.0, phi)
    }

    /// A spot light at `position` along `axis`, full within `cos_start`, dark beyond `cos_cone`.
    pub(super) fn spot(
        position: Vec3,
        axis: Vec3,
        cos_start: f32,
        cos_cone: f32,
        phi: f32,
    ) -> Self {
        let theta_start = cos_start.clamp(-1.0, 1.0).acos();
        let theta_cone = cos_cone.clamp(-1.0, 1.0).acos();
        let normals = Cone {
            w: axis,
            cos_theta: cos_start,
        };
        let cos_emit = (theta_cone - theta_start).max(0.0).cos();
        Self::new(position, position, normals, cos_emit, phi)
    }

    fn union(&self, other: &Self) -> Self {
        Self::new(
            self.lo.min(other.lo),
            self.hi.max(other.hi),
            Cone::union(self.normals, other.normals),
            self.cos_emit.min(other.cos_emit),
            self.phi + other.phi,
        )
    }

    fn centroid(&self) -> Vec3 {
        self.centre
    }

    /// The importance of the node's emitters at `p` on a surface of unit normal `n` (zero: no
    /// surface, no cosine bound there), pbrt-v4's `LightBounds::Importance`: zero only where no
    /// direction of the bounds' emission can reach `p`.
    fn importance(&self, p: Vec3, n: Vec3) -> f32 {
        let (centre, half_diagonal) = (self.centre, self.radius);
        let d2 = p
            .distance_squared(centre)
            .max(half_diagonal * half_diagonal);
        // cos(a − b) clamped to 1 where a < b, and sin(a − b) clamped to 0 there.
        let cos_sub = |sin_a: f32, cos_a: f32, sin_b: f32, cos_b: f32| {
            if cos_a > cos_b {
                1.0
            } else {
                cos_a * cos_b + sin_a * sin_b
            }
        };
        let sin_sub = |sin_a: f32, cos_a: f32, sin_b: f32, cos_b: f32| {
            if cos_a > cos_b {
                0.0
            } else {
                sin_a * cos_b - cos_a * sin_b
            }
        };
        let safe_sqrt = |x: f32| x.max(0.0).sqrt();
        let to_p = p - centre;
        let length = to_p.length();
        // From within the bounds every direction is possible.
        let wi = if length > 0.0 {
            to_p / length
        } else {
            Vec3::ZERO
        };
        let cos_w = if length > 0.0 {
            self.normals.w.dot(wi)
        } else {
            1.0
        };
        let sin_w = safe_sqrt(1.0 - cos_w * cos_w);
        // The half-angle the bounds' sphere subtends at p (all directions from inside it).
        let (cos_b, sin_b) = if length <= half_diagonal {
            (-1.0, 0.0)
        } else {
            let sin_b = half_diagonal / length;
            (safe_sqrt(1.0 - sin_b * sin_b), sin_b)
        };
        let (cos_o, sin_o) = (self.normals.cos_theta, self.sin_o);
        let cos_x = cos_sub(sin_w, cos_w, sin_o, cos_o);
        let sin_x = sin_sub(sin_w, cos_w, sin_o, cos_o);
        let cos_p = cos_sub(sin_x, cos_x, sin_b, cos_b);
        if cos_p <= self.cos_emit {
            return 0.0;
        }
        let mut importance = self.phi * cos_p / d2;
        if n != Vec3::ZERO && length > 0.0 {
            let cos_i = wi.dot(n).abs();
            let sin_i = safe_sqrt(1.0 - cos_i * cos_i);
            importance *= cos_sub(sin_i, cos_i, sin_b, cos_b);
        }
        if importance.is_finite() {
            importance.max(0.0)
        } else {
            0.0
        }
    }
}

#[derive(Clone, Debug)]
enum Node {
    /// Emitters `first..first + count` of [`LightTree::leaf_emitters`], picked among by power.
    Leaf { first: u32, count: u32 },
    /// Two children: the first right after this node, the second at `second`.
    Interior { second: u32 },
}

/// Where an emitter sits in the tree.
#[derive(Clone, Copy, Debug)]
struct Trail {
    /// Bit d set: the second child at depth d.
    bits: u64,
    depth: u8,
    /// Its share of its leaf's power.
    share: f32,
}

/// The hierarchy over the emitters with a finite position.
#[derive(Clone, Debug)]
pub(super) struct LightTree {
    nodes: Vec<Node>,
    bounds: Vec<LightBounds>,
    /// The leaves' emitters with the cumulative share of their leaf's power up to and with each,
    /// and their own share.
    leaf_emitters: Vec<(u32, f32, f32)>,
    /// Per emitter of the sampler, `None` for those outside the tree.
    trails: Vec<Option<Trail>>,
}

/// Emitters that share one plane and face one way are kept in one leaf, up to this many: the
/// importances of their parts hardly differ at a point (the two triangles of a quad lamp), and
/// a descent between them would cost more than it gains.
const FLAT_LEAF: usize = 8;

impl LightTree {
    /// The tree over `lights` (emitter index, bounds), `None` if there are none; `n_emitters`
    /// is the sampler's emitter count.
    pub(super) fn new(mut lights: Vec<(u32, LightBounds)>, n_emitters: usize) -> Option<Self> {
        if lights.is_empty() {
            return None;
        }
        let mut tree = Self {
            nodes: Vec::with_capacity(2 * lights.len()),
            bounds: Vec::with_capacity(2 * lights.len()),
            leaf_emitters: Vec::with_capacity(lights.len()),
            trails: vec![None; n_emitters],
        };
        tree.build(&mut lights, 0, 0);
        Some(tree)
    }

    /// Whether `lights` go in one leaf: one emitter, or a few one-sided surfaces in one plane
    /// facing one way.
    fn is_flat(lights: &[(u32, LightBounds)]) -> bool {
        let [(_, first), rest @ ..] = lights else {
            return true;
        };
        if rest.is_empty() {
            return true;
        }
        if lights.len() > FLAT_LEAF || first.normals.cos_theta < 1.0 || first.cos_emit != 0.0 {
            return false;
        }
        let (n, offset) = (first.normals.w, first.normals.w.dot(first.lo));
        let size = (first.hi - first.lo).length();
        rest.iter().all(|(_, b)| {
            b.normals.cos_theta >= 1.0
                && b.cos_emit == 0.0
                && b.normals.w.dot(n) > 0.9998
                && (b.normals.w.dot(b.lo) - offset).abs() <= 1e-4 * size.max(1e-6)
        })
    }

    /// Appends the subtree over `lights`, whose root is at `depth` along `trail`, and returns
    /// its bounds. Splits at the median centroid along the axis of the widest spread of
    /// centroids; the order is total (ties by emitter index), so the tree does not depend on
    /// the order it was given.
    fn build(&mut self, lights: &mut [(u32, LightBounds)], depth: u8, trail: u64) -> LightBounds {
        let at = self.nodes.len();
        if Self::is_flat(lights) {
            lights.sort_unstable_by_key(|(i, _)| *i);
            let bounds = lights[1..]
                .iter()
                .fold(lights[0].1, |acc, (_, b)| acc.union(b));
            let first = self.leaf_emitters.len() as u32;
            let mut cumulative = 0.0f64;
            let total: f64 = lights.iter().map(|(_, b)| f64::from(b.phi)).sum();
            for (k, &(emitter, b)) in lights.iter().enumerate() {
                let share = (f64::from(b.phi) / total) as f32;
                cumulative += f64::from(b.phi);
                // The last one closes the leaf at exactly one.
                let upto = if k + 1 == lights.len() {
                    1.0
                } else {
                    (cumulative / total) as f32
                };
                self.leaf_emitters.push((emitter, upto, share));
                self.trails[emitter as usize] = Some(Trail {
                    bits: trail,
                    depth,
                    share,
                });
            }
            self.nodes.push(Node::Leaf {
                first,
                count: lights.len() as u32,
            });
            self.bounds.push(bounds);
            return bounds;
        }
        self.nodes.push(Node::Interior { second: 0 });
        self.bounds.push(lights[0].1);
        let (lo, hi) = lights.iter().fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(lo, hi), (_, b)| (lo.min(b.centroid()), hi.max(b.centroid())),
        );
        let axis = (hi - lo).max_position();
        lights.sort_unstable_by(|(ia, a), (ib, b)| {
            a.centroid()[axis]
                .total_cmp(&b.centroid()[axis])
                .then(ia.cmp(ib))
        });
        let (first, second) = lights.split_at_mut(lights.len() / 2);
        // Depth stays far below 64: the halves are balanced.
        let a = self.build(first, depth + 1, trail);
        let second_at = self.nodes.len() as u32;
        let b = self.build(second, depth + 1, trail | (1 << depth));
        self.nodes[at] = Node::Interior { second: second_at };
        let union = a.union(&b);
        self.bounds[at] = union;
        union
    }

    /// Picks an emitter for the point `p` with surface normal `n` (zero: none) by `u` ∈ [0, 1):
    /// its index and probability, `None` where no emitter of the tree can light `p`. A tree of
    /// one leaf is not descended at all: its emitters are picked by power, as photons are.
    pub(super) fn sample(&self, p: Vec3, n: Vec3, mut u: f32) -> Option<(usize, f32)> {
        let mut node = 0usize;
        let mut pmf = 1.0f32;
        loop {
            match self.nodes[node] {
                Node::Leaf { first, count } => {
                    let leaf = &self.leaf_emitters[first as usize..(first + count) as usize];
                    let k = leaf
                        .iter()
                        .position(|&(_, upto, _)| u < upto)
                        .unwrap_or(leaf.len() - 1);
                    let (emitter, _, share) = leaf[k];
                    return Some((emitter as usize, pmf * share));
                }
                Node::Interior { second } => {
                    let (i0, i1) = (
                        self.bounds[node + 1].importance(p, n),
                        self.bounds[second as usize].importance(p, n),
                    );
                    let total = i0 + i1;
                    if total <= 0.0 {
                        return None;
                    }
                    let p0 = i0 / total;
                    if u < p0 {
                        node += 1;
                        pmf *= p0;
                        u = (u / p0).min(ONE_MINUS_EPSILON);
                    } else {
                        node = second as usize;
                        let p1 = i1 / total;
                        pmf *= p1;
                        u = ((u - p0) / p1).clamp(0.0, ONE_MINUS_EPSILON);
                    }
                }
            }
        }
    }

    /// The probability that [`LightTree::sample`] at `p` with normal `n` picks `emitter`.
    pub(super) fn pmf(&self, p: Vec3, n: Vec3, emitter: usize) -> f32 {
        let Some(&Some(trail)) = self.trails.get(emitter) else {
            return 0.0;
        };
        let mut node = 0usize;
        let mut pmf = 1.0f32;
        for d in 0..trail.depth {
            let Node::Interior { second } = self.nodes[node] else {
                return 0.0;
            };
            let (i0, i1) = (
                self.bounds[node + 1].importance(p, n),
                self.bounds[second as usize].importance(p, n),
            );
            let total = i0 + i1;
            if total <= 0.0 {
                return 0.0;
            }
            if trail.bits & (1 << d) == 0 {
                node += 1;
                pmf *= i0 / total;
            } else {
                node = second as usize;
                pmf *= i1 / total;
            }
        }
        pmf * trail.share
    }
}

/// The largest f32 below one.
const ONE_MINUS_EPSILON: f32 = 1.0 - f32::EPSILON / 2.0;

/// How next-event estimation picks an emitter: an infinite light by its share of the power,
/// else an emitter of the tree by its importance at the point.
#[derive(Clone, Debug)]
pub(super) struct DirectChoice {
    tree: Option<LightTree>,
    /// The infinite lights (emitter indices) and the distribution over them by power.
    infinite: Option<(Vec<usize>, Distribution1D)>,
    /// The probability of picking an infinite light.
    p_infinite: f32,
}

impl DirectChoice {
    /// The choice over `emitters` with power luminances `weights` (zero: never picked).
    pub(super) fn new(emitters: &[Emitter], weights: &[f64]) -> Self {
        let mut finite = Vec::new();
        let (mut infinite, mut infinite_weights) = (Vec::new(), Vec::new());
        for (i, (emitter, &weight)) in emitters.iter().zip(weights).enumerate() {
            if !(weight.is_finite() && weight > 0.0) {
                continue;
            }
            let phi = weight as f32;
            let bounds = match *emitter {
                Emitter::Directional { .. } | Emitter::Environment => {
                    infinite.push(i);
                    infinite_weights.push(weight);
                    continue;
                }
                Emitter::Point { position, .. } => LightBounds::omni(position, position, phi),
                Emitter::Spot {
                    position,
                    frame,
                    cos_cone,
                    cos_start,
                    ..
                } => LightBounds::spot(position, frame.n, cos_start, cos_cone, phi),
                Emitter::Triangle {
                    p0, p1, p2, normal, ..
                } => LightBounds::surface(p0.min(p1).min(p2), p0.max(p1).max(p2), normal, phi),
                Emitter::Sphere { center, radius, .. } => LightBounds::omni(
                    center - Vec3::splat(radius),
                    center + Vec3::splat(radius),
                    phi,
                ),
            };
            finite.push((i as u32, bounds));
        }
        let total: f64 = weights.iter().filter(|w| w.is_finite() && **w > 0.0).sum();
        let infinite_total: f64 = infinite_weights.iter().sum();
        let tree = LightTree::new(finite, emitters.len());
        let p_infinite = match tree {
            None => 1.0,
            Some(_) if total > 0.0 => (infinite_total / total) as f32,
            Some(_) => 0.0,
        };
        Self {
            tree,
            infinite: Distribution1D::new(&infinite_weights).map(|d| (infinite, d)),
            p_infinite,
        }
    }

    /// Picks an emitter for the point `p` with surface normal `n` (zero: none) by `u` ∈ [0, 1):
    /// its index and probability.
    #[inline]
    pub(super) fn sample(&self, p: Vec3, n: Vec3, u: f32) -> Option<(usize, f32)> {
        if u < self.p_infinite {
            let (lights, distribution) = self.infinite.as_ref()?;
            let (j, pmf) = distribution.sample((u / self.p_infinite).min(ONE_MINUS_EPSILON));
            Some((lights[j], self.p_infinite * pmf))
        } else {
            let p_tree = 1.0 - self.p_infinite;
            let u = ((u - self.p_infinite) / p_tree).clamp(0.0, ONE_MINUS_EPSILON);
            let (i, pmf) = self.tree.as_ref()?.sample(p, n, u)?;
            Some((i, p_tree * pmf))
        }
    }

    /// The probability that [`DirectChoice::sample`] at `p` with normal `n` picks `emitter`.
    #[inline]
    pub(super) fn pmf(&self, p: Vec3, n: Vec3, emitter: usize) -> f32 {
        if let Some((lights, distribution)) = &self.infinite
            && let Some(j) = lights.iter().position(|&l| l == emitter)
        {
            return self.p_infinite * distribution.pmf(j);
        }
        self.tree.as_ref().map_or(0.0, |tree| {
            (1.0 - self.p_infinite) * tree.pmf(p, n, emitter)
        })
    }
}

#[cfg(test)]
#[path = "tree_tests.rs"]
mod tests;
