//! An 8-wide BVH for single-ray traversal on the CPU, collapsed from an obvhs `Bvh2`.
//!
//! Each node holds the boxes of its (up to) eight children in SoA form, one row of eight lanes per
//! bound (lower and upper bounds per axis, `simd::F8`), so one ray is tested against all eight
//! boxes with about twenty AVX instructions and no decoding. Children are visited nearest first
//! (closest hit) or in any order (any hit). Leaves are not nodes: a child reference encodes the
//! leaf's number directly, and the leaf's triangles sit in one SIMD pack (`prim::TriPack`) of the
//! same number.
//!
//! Eight lanes rather than four, AVX intrinsics rather than lane-by-lane code, and compressing
//! stores for the pushed children each paid on incoherent rays (docs/notes/bvh-traversal.md).

use std::mem::MaybeUninit;

use glam::Vec3A;
use obvhs::{aabb::Aabb as BvhAabb, bvh2::Bvh2};

use super::simd::{F8, compress};

/// Number of children per node.
const WIDTH: usize = 8;

/// Set in a child reference that is a leaf (else the reference is a node index).
const LEAF_BIT: u32 = 1 << 31;
/// Set in a leaf reference whose primitives are not all triangles.
const MIXED_BIT: u32 = 1 << 30;
/// Most primitives in one leaf: one SIMD lane each.
pub(super) const MAX_LEAF_PRIMS: u32 = 8;
/// Leaves are numbered below this bound in a leaf reference.
const MAX_LEAVES: u32 = 1 << 30;
/// A node's reference is its index times this, its byte offset in [`Wide::nodes`] divided by 8,
/// so that the node test reads its rows at (row address) + 8 · (reference), one addressing mode
/// of x86 (an index would take a shift and an addition before the first load of every node).
const NODE_REF_SCALE: u32 = (size_of::<Node>() / 8) as u32;
/// Nodes are numbered below this bound (their references stay below [`LEAF_BIT`]).
const MAX_NODES: usize = (LEAF_BIT / NODE_REF_SCALE) as usize;

/// The reference of node `index`.
fn node_ref(index: usize) -> u32 {
    assert!(index < MAX_NODES, "too many BVH nodes");
    index as u32 * NODE_REF_SCALE
}
/// The reference in an unused child slot; its box is empty, so it is never followed.
const EMPTY: u32 = u32::MAX;

/// Factor (1 + 8u with u = 2⁻²⁴, above 1 + 2γ₃) by which the exit distance of a box is widened so
/// that rounding in the slab test never culls a box the exact ray enters (pbrt-v4, "Robust
/// ray–bounds intersection"); applied to the inverse direction ([`Node::intersect`]).
const ROBUST_EXIT: f32 = 1.0 + 4.0 * f32::EPSILON;

/// Capacity of the on-stack traversal stack of ordinary trees (the bunny needs 50 entries, a
/// 1M-triangle scene 64).
const STACK_SMALL: usize = 64;
/// Capacity of the on-stack traversal stack of deep trees; deeper ones use a heap stack.
const STACK_LARGE: usize = 256;

/// The primitive tests of the leaves, as the traversals call them. A trait with inlined methods
/// rather than closures, which the compiler leaves as calls.
pub(super) trait Leaves {
    /// Lowers `tmax` to the closest hit in `leaf` below it, if any.
    fn closest(&mut self, leaf: Leaf, tmax: &mut f32);
    /// Whether anything in `leaf` is hit below `tmax`.
    fn any(&self, leaf: Leaf, tmax: f32) -> bool;
}

/// A leaf as the traversal hands it over: its number (in [`Wide::leaves`]) and whether it holds
/// anything but triangles.
#[derive(Clone, Copy, Debug)]
pub(super) struct Leaf {
    pub(super) index: usize,
    pub(super) mixed: bool,
}

#[inline(always)]
fn leaf_of(r: u32) -> Leaf {
    Leaf {
        index: (r & (MAX_LEAVES - 1)) as usize,
        mixed: r & MIXED_BIT != 0,
    }
}

/// A node: the child references and the child boxes in SoA form, one row of eight lanes per
/// bound (224 bytes in four cache lines). The references come first, in the cache line of the
/// first row, so that the node test (which reads every row) brings them in with the bounds
/// instead of leaving their line to be fetched once the mask of hit children is known.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
struct Node {
    /// Node index, leaf reference or [`EMPTY`], per child.
    children: [u32; WIDTH],
    /// `bounds[2 * axis]`: the lower bounds of the children along `axis`;
    /// `bounds[2 * axis + 1]`: their upper bounds.
    bounds: [F8; 6],
}

/// A [`Node`] under construction.
#[derive(Clone, Copy, Debug)]
struct NodeBuilder {
    bounds: [[f32; WIDTH]; 6],
    children: [u32; WIDTH],
}

impl NodeBuilder {
    /// A node whose slots all hold [`EMPTY`] with an empty box (lower bound +∞, upper −∞, which
    /// no slab test with a finite origin enters, whatever the direction: no NaN can arise).
    const EMPTY: Self = Self {
        bounds: [
            [f32::INFINITY; WIDTH],
            [f32::NEG_INFINITY; WIDTH],
            [f32::INFINITY; WIDTH],
            [f32::NEG_INFINITY; WIDTH],
            [f32::INFINITY; WIDTH],
            [f32::NEG_INFINITY; WIDTH],
        ],
        children: [EMPTY; WIDTH],
    };

    fn set_child(&mut self, slot: usize, aabb: &BvhAabb, child: u32) {
        for axis in 0..3 {
            self.bounds[2 * axis][slot] = aabb.min[axis];
            self.bounds[2 * axis + 1][slot] = aabb.max[axis];
        }
        self.children[slot] = child;
    }

    fn build(&self) -> Node {
        Node {
            children: self.children,
            bounds: self.bounds.map(F8::from_array),
        }
    }
}

impl Node {
    /// The mask of the child boxes the ray enters within [0, tmax], and per child the distance at
    /// which it enters (meaningful in the lanes of the mask: +0, positive or +∞; the other lanes
    /// hold all-ones bits, a NaN that [`nearest_lane`] ranks last).
    ///
    /// Slab distances are (bound − origin) · (1 / direction), computed as (origin − bound) ·
    /// (−1 / direction), which is the same number (IEEE subtraction and multiplication are
    /// symmetric under negation) except that an exact 0 may come out as −0 instead of +0; the
    /// clamp of the entry distance to +0 and the `≤` comparison do not see the difference. In this
    /// form the bound is the second operand of the subtraction, which AVX reads straight from
    /// memory. The exit distances use −(1 + 2γ₃) / direction, rounded ([`BoxRay::neg_inv_far`]):
    /// with the roundings of the inverse, of that product, of the difference and of the last
    /// product, the exit distance comes out at least (1 + 8u)(1 − u)⁴ > 1 times the exact one, as
    /// conservative as widening the exit distance afterwards (pbrt-v4, "Robust ray–bounds
    /// intersection") and one multiplication shorter. The minima and maxima are taken as two
    /// levels of a tree rather than a chain of three, which shortens the critical path of the
    /// traversal (a node test, then the next node's address) by a step.
    ///
    /// A zero direction component gives an infinite inverse, and NaN where the origin lies
    /// exactly on a bound; NaN then either culls the box or is ignored, and both are right
    /// because every box is padded beyond its primitives (`Accel::build`): a ray that stays in
    /// the plane of a box face meets none of them.
    #[inline(always)]
    fn intersect(&self, ray: &BoxRay, tmax: f32) -> (u32, F8) {
        let b = |row: usize| {
            // SAFETY: `BoxRay::new` makes every row offset that of one of the six rows of
            // `bounds` (a multiple of the size of `F8`, below six times it).
            unsafe {
                *self
                    .bounds
                    .as_ptr()
                    .cast::<u8>()
                    .add(ray.rows[row])
                    .cast::<F8>()
            }
        };
        let near = |row: usize, axis: usize| ray.origin[axis].sub(b(row)).mul(ray.neg_inv[axis]);
        let far = |row: usize, axis: usize| ray.origin[axis].sub(b(row)).mul(ray.neg_inv_far[axis]);
        let (tx0, tx1) = (near(0, 0), far(1, 0));
        let (ty0, ty1) = (near(2, 1), far(3, 1));
        let (tz0, tz1) = (near(4, 2), far(5, 2));
        let tnear = tx0.max(ty0).max(tz0.max(F8::splat(0.0)));
        let tfar = tx1.min(ty1).min(tz1.min(F8::splat(tmax)));
        // tnear is +0 or positive (or +∞), never NaN, so its bits order like a signed integer,
        // and tnear > tfar as floats exactly when the bits compare so, except for tfar = −0
        // (whose bits are the most negative integer): that box is culled, and rightly, since a
        // box whose computed exit distance is ±0 holds nothing the ray meets at t ≥ 0 (every
        // box extends at least the smallest normal float beyond its primitives, and the exit
        // distance is computed conservatively). A NaN tfar (from a NaN tmax) gives no hit as
        // floats but may as integers; no primitive test passes t < NaN.
        let miss = tnear.gt_bits(tfar);
        (!miss.bitmask() & 0xff, tnear.or(miss))
    }
}

/// A ray prepared for the box tests: origin and negated inverse direction splatted over the
/// lanes, and per axis the rows of [`Node::bounds`] of the sides of a box where the ray enters
/// and where it leaves.
#[derive(Clone, Copy, Debug)]
pub(super) struct BoxRay {
    origin: [F8; 3],
    /// −1 / direction.
    neg_inv: [F8; 3],
    /// −1 / direction, times [`ROBUST_EXIT`] (each rounded), for the exit distances.
    neg_inv_far: [F8; 3],
    /// Byte offsets in [`Node::bounds`] of the entry row along x and of the exit row along x,
    /// then the same for y and z (byte offsets spare the traversal a multiplication per row).
    rows: [usize; 6],
}

impl BoxRay {
    /// Any finite `direction` will do: a ±0.0 component has an inverse of ±∞, which
    /// [`Node::intersect`] handles.
    #[inline(always)]
    pub(super) fn new(origin: Vec3A, direction: Vec3A) -> Self {
        let inv = Vec3A::ONE / direction;
        let neg_inv = -inv;
        let neg_inv_far = neg_inv * ROBUST_EXIT;
        let row = size_of::<F8>();
        // Bit `axis`: whether the ray runs towards −axis (one comparison of all three).
        let negative = inv.cmplt(Vec3A::ZERO).bitmask() as usize;
        let near = |axis: usize| (2 * axis + (negative >> axis & 1)) * row;
        let far = |axis: usize| near(axis) ^ row;
        Self {
            origin: [
                F8::splat(origin.x),
                F8::splat(origin.y),
                F8::splat(origin.z),
            ],
            neg_inv: [
                F8::splat(neg_inv.x),
                F8::splat(neg_inv.y),
                F8::splat(neg_inv.z),
            ],
            neg_inv_far: [
                F8::splat(neg_inv_far.x),
                F8::splat(neg_inv_far.y),
                F8::splat(neg_inv_far.z),
            ],
            rows: [near(0), far(0), near(1), far(1), near(2), far(2)],
        }
    }
}

/// The traversal stack: child references and the distances at which the ray enters their boxes,
/// in two arrays, so that the children a node test leaves behind are pushed with one compressing
/// store each ([`compress`]). The storage is borrowed (on the machine stack for trees of ordinary
/// depth, on the heap otherwise) and left uninitialised, since zeroing it per ray is a noticeable
/// share of an incoherent ray's instructions (docs/performance.md).
struct Stack<'a> {
    /// `refs[..len]` and `dist[..len]` are initialised.
    refs: &'a mut [MaybeUninit<u32>],
    dist: &'a mut [MaybeUninit<f32>],
    len: usize,
}

impl<'a> Stack<'a> {
    /// A stack for a tree of [`Wide::stack_need`] `need`.
    #[inline(always)]
    fn new(
        refs: &'a mut [MaybeUninit<u32>],
        dist: &'a mut [MaybeUninit<f32>],
        need: usize,
    ) -> Self {
        // A push writes all WIDTH lanes above the entries that can be on the stack before it.
        assert!(refs.len() >= need + WIDTH && dist.len() >= need + WIDTH);
        Self { refs, dist, len: 0 }
    }

    /// Pushes the children of `node` whose bits are set in `mask`, in lane order, with their
    /// entry distances from `t`.
    #[inline(always)]
    fn push(&mut self, mask: u32, node: &Node, t: F8) {
        let at = self.len;
        // SAFETY: `mask` comes from one node test, whose children the traversal visits before
        // anything on the stack below them, so at most `need` entries (counting these) are ever
        // on the stack (`Wide::stack_need`): `at + WIDTH <= need + WIDTH`, within the storage
        // (`Stack::new`).
        let (refs, dist) = unsafe {
            (
                &mut *self
                    .refs
                    .as_mut_ptr()
                    .add(at)
                    .cast::<[MaybeUninit<u32>; WIDTH]>(),
                &mut *self
                    .dist
                    .as_mut_ptr()
                    .add(at)
                    .cast::<[MaybeUninit<f32>; WIDTH]>(),
            )
        };
        compress(mask, &node.children, t, refs, dist);
        self.len = at + mask.count_ones() as usize;
    }

    /// The top entry: a child reference and its entry distance.
    #[inline(always)]
    fn pop(&mut self) -> Option<(u32, f32)> {
        self.len = self.len.checked_sub(1)?;
        // SAFETY: `push` initialised every entry below the old length, which is within the
        // storage.
        unsafe {
            Some((
                self.refs.get_unchecked(self.len).assume_init(),
                self.dist.get_unchecked(self.len).assume_init(),
            ))
        }
    }
}

/// Makes `$stack`, a [`Stack`] for a tree of [`Wide::stack_need`] `$need`, and evaluates `$body`
/// with it. A macro rather than a function taking a closure, which the compiler does not inline:
/// the traversal would then read the ray from memory (docs/performance.md).
macro_rules! with_stack {
    ($need:expr, |$stack:ident| $body:expr) => {{
        const SMALL: usize = STACK_SMALL + WIDTH;
        const LARGE: usize = STACK_LARGE + WIDTH;
        let need = $need;
        if need <= STACK_SMALL {
            let mut refs = [const { MaybeUninit::uninit() }; SMALL];
            let mut dist = [const { MaybeUninit::uninit() }; SMALL];
            let $stack = &mut Stack::new(&mut refs, &mut dist, need);
            $body
        } else if need <= STACK_LARGE {
            let mut refs = [const { MaybeUninit::uninit() }; LARGE];
            let mut dist = [const { MaybeUninit::uninit() }; LARGE];
            let $stack = &mut Stack::new(&mut refs, &mut dist, need);
            $body
        } else {
            let mut refs = vec![MaybeUninit::uninit(); need + WIDTH];
            let mut dist = vec![MaybeUninit::uninit(); need + WIDTH];
            let $stack = &mut Stack::new(&mut refs, &mut dist, need);
            $body
        }
    }};
}

/// The 8-wide BVH.
#[derive(Clone, Debug)]
pub(super) struct Wide {
    nodes: Vec<Node>,
    /// The root: a node index or, for a tree that is a single leaf, a leaf reference.
    root: u32,
    /// Most entries the traversal stack can hold at once.
    stack_need: usize,
    /// Per leaf, in the order of first visit in a depth-first walk: its first position in
    /// obvhs' `primitive_indices` and its number of primitives (1..=[`MAX_LEAF_PRIMS`]).
    pub(super) leaves: Vec<(u32, u32)>,
}

/// Work item of the collapse: the obvhs node to turn into wide node `index` at `depth`.
struct Pending {
    bvh2_node: usize,
    index: usize,
    depth: usize,
}

/// Which `Bvh2` inner nodes become wide nodes: those of a minimal total surface area (the
/// expected number of node tests, in the SAH's terms) over all collapses in which every wide node
/// has at most [`WIDTH`] children, found by dynamic programming over the binary tree (as in Ylitie
/// et al. 2017, "Efficient incoherent ray traversal on GPUs through compressed wide BVHs", with
/// the leaves kept as obvhs made them: every leaf is one child slot somewhere, so their cost does
/// not depend on the collapse).
struct Plan {
    /// Per `Bvh2` node and `i` in 1..=WIDTH (at `i − 1`): the least total half-area of the wide
    /// nodes in its subtree (itself included if it is one) when the subtree takes at most `i`
    /// child slots of the wide node above.
    cost: Vec<[f64; WIDTH]>,
    /// Per `Bvh2` inner node and `i` (at `i − 1`): 0 where the node takes one slot itself, else
    /// the number of slots `k` given to its first child (`i − k` to the second); at `WIDTH − 1`,
    /// the split of its `WIDTH` slots when it is opened (the wide node made from it).
    split: Vec<[u8; WIDTH]>,
    open_split: Vec<u8>,
}

impl Plan {
    fn new(bvh2: &Bvh2) -> Self {
        let n = bvh2.nodes.len();
        let mut plan = Self {
            cost: vec![[0.0; WIDTH]; n],
            split: vec![[0; WIDTH]; n],
            open_split: vec![0; n],
        };
        // Children before parents: the reverse of a preorder.
        let mut preorder = Vec::with_capacity(n);
        let mut stack = vec![0usize];
        while let Some(i) = stack.pop() {
            preorder.push(i);
            let node = &bvh2.nodes[i];
            if !node.is_leaf() {
                let first = node.first_index as usize;
                stack.extend([first, first + 1]);
            }
        }
        for &i in preorder.iter().rev() {
            let node = &bvh2.nodes[i];
            if node.is_leaf() {
                continue;
            }
            let (l, r) = (node.first_index as usize, node.first_index as usize + 1);
            // opened[i − 1]: cost of the two children sharing i slots (i ≥ 2), and the split.
            let mut opened = [(f64::INFINITY, 0u8); WIDTH];
            for (slots, entry) in opened.iter_mut().enumerate().skip(1) {
                let slots = slots + 1;
                for k in 1..slots {
                    let c = plan.cost[l][k - 1] + plan.cost[r][slots - k - 1];
                    if c < entry.0 {
                        *entry = (c, k as u8);
                    }
                }
            }
            let own = f64::from(node.aabb.half_area()) + opened[WIDTH - 1].0;
            plan.open_split[i] = opened[WIDTH - 1].1;
            plan.cost[i][0] = own;
            for slots in 2..=WIDTH {
                let (c, k) = opened[slots - 1];
                (plan.cost[i][slots - 1], plan.split[i][slots - 1]) =
                    if c <= own { (c, k) } else { (own, 0) };
            }
        }
        plan
    }

    /// The `Bvh2` nodes that take the slots of the wide node made from inner node `index`, in
    /// tree order, padded with `usize::MAX`.
    fn children(&self, bvh2: &Bvh2, index: usize) -> [usize; WIDTH] {
        let mut out = [usize::MAX; WIDTH];
        let mut len = 0;
        let first = bvh2.nodes[index].first_index as usize;
        let k = self.open_split[index] as usize;
        let mut work = vec![(first + 1, WIDTH - k), (first, k)];
        while let Some((n, slots)) = work.pop() {
            let node = &bvh2.nodes[n];
            let k = if node.is_leaf() {
                0
            } else {
                self.split[n][slots - 1] as usize
            };
            if k == 0 {
                out[len] = n;
                len += 1;
            } else {
                let first = node.first_index as usize;
                work.push((first + 1, slots - k));
                work.push((first, k));
            }
        }
        out
    }
}

/// What the collapse accumulates besides the work list.
struct Collapse<'a, F> {
    nodes: Vec<Node>,
    leaves: Vec<(u32, u32)>,
    /// Whether the primitives at the given `primitive_indices` positions are not all triangles.
    mixed: &'a F,
}

impl<F: Fn(u32, u32) -> bool> Collapse<'_, F> {
    /// The reference to a leaf of `count` primitives from position `first`, and the number of
    /// node levels it adds. A leaf with more than [`MAX_LEAF_PRIMS`] primitives (which obvhs does
    /// not make with our build settings) becomes a node of smaller leaves that share its box.
    fn leaf(&mut self, aabb: &BvhAabb, first: u32, count: u32) -> (u32, usize) {
        if count <= MAX_LEAF_PRIMS {
            let index = self.leaves.len() as u32;
            assert!(index < MAX_LEAVES, "too many BVH leaves");
            self.leaves.push((first, count));
            let mixed = if (self.mixed)(first, count) {
                MIXED_BIT
            } else {
                0
            };
            return (LEAF_BIT | mixed | index, 0);
        }
        let per_child = count.div_ceil(WIDTH as u32);
        let at = self.nodes.len();
        self.nodes.push(NodeBuilder::EMPTY.build());
        let mut node = NodeBuilder::EMPTY;
        let mut depth = 0;
        for slot in 0..WIDTH as u32 {
            let start = slot * per_child;
            if start < count {
                let n = per_child.min(count - start);
                let (child, d) = self.leaf(aabb, first + start, n);
                node.set_child(slot as usize, aabb, child);
                depth = depth.max(d);
            }
        }
        self.nodes[at] = node.build();
        (node_ref(at), depth + 1)
    }
}

impl Wide {
    /// Collapses a `Bvh2` (no spatial splits, at least one primitive) into the wide nodes that
    /// [`Plan`] chooses: each wide node takes up to [`WIDTH`] binary nodes under the binary node
    /// it replaces. (A greedy collapse, which opens the inner child of largest surface area
    /// while there is room, leaves many nodes near the leaves with two or three children;
    /// docs/notes/bvh-traversal.md.) Nodes are laid out depth
    /// first. `mixed(first, count)` says whether a leaf's primitives are not all triangles.
    pub(super) fn from_bvh2(bvh2: &Bvh2, mixed: &impl Fn(u32, u32) -> bool) -> Self {
        let mut c = Collapse {
            nodes: Vec::with_capacity(bvh2.nodes.len() / 4 + 1),
            leaves: Vec::with_capacity(bvh2.nodes.len() / 2 + 1),
            mixed,
        };
        let root = &bvh2.nodes[0];
        if root.is_leaf() {
            let (root, depth) = c.leaf(&root.aabb, root.first_index, root.prim_count);
            return Self {
                nodes: c.nodes,
                root,
                stack_need: depth * (WIDTH - 1) + 1,
                leaves: c.leaves,
            };
        }
        let plan = Plan::new(bvh2);
        c.nodes.push(NodeBuilder::EMPTY.build());
        let mut work = vec![Pending {
            bvh2_node: 0,
            index: 0,
            depth: 1,
        }];
        let mut max_depth = 1;
        while let Some(p) = work.pop() {
            max_depth = max_depth.max(p.depth);
            let mut node = NodeBuilder::EMPTY;
            let open = plan.children(bvh2, p.bvh2_node);
            for (slot, &child) in open.iter().enumerate().filter(|&(_, &n)| n != usize::MAX) {
                let child_node = &bvh2.nodes[child];
                let reference = if child_node.is_leaf() {
                    let (reference, depth) = c.leaf(
                        &child_node.aabb,
                        child_node.first_index,
                        child_node.prim_count,
                    );
                    max_depth = max_depth.max(p.depth + depth);
                    reference
                } else {
                    let index = c.nodes.len();
                    c.nodes.push(NodeBuilder::EMPTY.build());
                    work.push(Pending {
                        bvh2_node: child,
                        index,
                        depth: p.depth + 1,
                    });
                    node_ref(index)
                };
                node.set_child(slot, &child_node.aabb, reference);
            }
            c.nodes[p.index] = node.build();
        }
        Self {
            nodes: c.nodes,
            root: 0,
            // Each level leaves at most WIDTH − 1 siblings behind.
            stack_need: max_depth * (WIDTH - 1) + 1,
            leaves: c.leaves,
        }
    }

    /// The node of reference `r` (without [`LEAF_BIT`]).
    #[inline(always)]
    fn node(&self, r: u32) -> &Node {
        // SAFETY: `from_bvh2` makes every child reference without `LEAF_BIT` (and a root without
        // it) the reference of a node it pushed, `node_ref`: a byte offset of 8 · r.
        unsafe {
            &*self
                .nodes
                .as_ptr()
                .cast::<u8>()
                .add(r as usize * 8)
                .cast::<Node>()
        }
    }

    /// Closest-hit traversal. `leaf` tests a leaf's primitives against the ray with the current
    /// upper bound and lowers it on a hit; nodes are visited nearest first, and those
    /// entered beyond the bound are skipped.
    #[inline(always)]
    pub(super) fn closest(&self, ray: &BoxRay, tmax: &mut f32, leaves: &mut impl Leaves) {
        with_stack!(self.stack_need, |stack| self
            .closest_with(stack, ray, tmax, leaves));
    }

    #[inline(always)]
    fn closest_with(
        &self,
        stack: &mut Stack,
        ray: &BoxRay,
        tmax: &mut f32,
        leaves: &mut impl Leaves,
    ) {
        {
            let mut current = self.root;
            loop {
                if current & LEAF_BIT != 0 {
                    leaves.closest(leaf_of(current), tmax);
                } else {
                    let node = self.node(current);
                    let (mask, tnear) = node.intersect(ray, *tmax);
                    if mask != 0 {
                        if mask & (mask - 1) == 0 {
                            current = node.children[mask.trailing_zeros() as usize & (WIDTH - 1)];
                            continue;
                        }
                        // Two or more: continue with the nearest, push the others (in lane order:
                        // sorting them costs more than it saves).
                        let nearest = nearest_lane(tnear);
                        stack.push(mask & !(1 << nearest), node, tnear);
                        current = node.children[nearest & (WIDTH - 1)];
                        continue;
                    }
                }
                // Next subtree that the ray still enters before the closest hit so far.
                loop {
                    let Some((c, t)) = stack.pop() else {
                        return;
                    };
                    if t <= *tmax {
                        current = c;
                        break;
                    }
                }
            }
        }
    }

    /// Any-hit traversal: stops as soon as `leaf` reports a hit within [0, tmax].
    #[inline(always)]
    pub(super) fn any(&self, ray: &BoxRay, tmax: f32, leaves: &impl Leaves) -> bool {
        with_stack!(self.stack_need, |stack| self
            .any_with(stack, ray, tmax, leaves))
    }

    #[inline(always)]
    fn any_with(&self, stack: &mut Stack, ray: &BoxRay, tmax: f32, leaves: &impl Leaves) -> bool {
        {
            let mut current = self.root;
            loop {
                if current & LEAF_BIT != 0 {
                    if leaves.any(leaf_of(current), tmax) {
                        return true;
                    }
                } else {
                    let node = self.node(current);
                    let (mask, tnear) = node.intersect(ray, tmax);
                    if mask != 0 {
                        current = node.children[mask.trailing_zeros() as usize & (WIDTH - 1)];
                        let rest = mask & (mask - 1);
                        if rest != 0 {
                            stack.push(rest, node, tnear);
                        }
                        continue;
                    }
                }
                match stack.pop() {
                    Some((c, _)) => current = c,
                    None => return false,
                }
            }
        }
    }
}

/// The lane of smallest entry distance among the children in the mask (the first such lane on
/// ties) in the output of [`Node::intersect`], whose entry distances are +0, positive or +∞ and
/// whose other lanes are all-ones bits: the order of the bits as unsigned integers is that of the
/// distances, with the other lanes last.
#[inline(always)]
fn nearest_lane(entries: F8) -> usize {
    entries
        .eq_bits(entries.min_all_unsigned())
        .bitmask()
        .trailing_zeros() as usize
}
