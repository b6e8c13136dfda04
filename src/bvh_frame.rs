//! What flatland's [`SegmentBvh`](crate::flat::bvh::SegmentBvh) (segments
//! in the plane) and the mesh's [`TriangleBvh`](crate::mesh::bvh::TriangleBvh)
//! (triangles in space) share: an obvhs binary BVH (PLOC, `medium_build`)
//! over `f32` boxes in a *unit frame*, its traversal with exact `f64`
//! primitive tests, and the argument that the `f32` culling never loses a
//! hit. The crate-private pieces are generic over the dimension (a vector
//! trait implemented for `glam::DVec2` and `DVec3`) and over the primitive
//! (its box, its `f64` ray test, its index); each caster only says what its
//! primitive is.
//!
//! # Exact answers
//!
//! obvhs only sees boxes, in `f32`; every primitive it reaches is tested in
//! `f64` by the very test the caster's linear scan makes, so a hit's
//! distance and index are the scan's bit for bit. Ties (two primitives at
//! the same `t`) go to the lowest index in both: when a closer hit shrinks
//! the traversal's `f32` bound, the bound is padded, so a later hit at the
//! same `t` with a lower index is still reached.
//!
//! # Conservative culling
//!
//! The boxes live in a *unit frame*: the scene translated and scaled by a
//! power of two (exact) so that it fits in `[−1, 1]ⁿ` (n = 2 or 3); huge or
//! tiny coordinates (10³⁰, 10⁻³⁰) are then no concern of `f32`. Each box is
//! padded by [`PAD`] = 2⁻¹⁶ of the scene half-size, and so is each `f32`
//! distance bound: far more than the `f32` rounding of the ray (origin,
//! direction, slab arithmetic: below 10⁻⁶ inside the frame). The query
//! direction is scaled by a power of two (exact, without a division) to a
//! largest component in `[1, 2)`, so its length is in `[1, 2√n)` and ray
//! parameters are frame distances within that factor; obvhs's clamp of
//! inverse directions at 1/ε (ε = 2⁻²³) then only shortens slabs to at
//! least `PAD/ε` ≈ 128, beyond any parameter inside the frame (≤ 2√n). A
//! ray from outside the padded scene box first moves, in `f64`, to where it
//! enters the box, so the `f32` ray starts inside the frame whatever the
//! origin, and a ray that misses the box is a miss. Rays the frame cannot
//! hold (origins farther than 2³⁰ scene sizes, where the `f64` clipping
//! error would approach [`PAD`], non-finite input, directions whose size
//! over- or underflows) fall back to a linear scan of the primitives, with
//! the same answer.
//!
//! # Cost
//!
//! No heap allocation per query: the traversal stack is a fixed array on
//! the call stack, sized from the tree depth measured at construction (64 or
//! 256 entries; PLOC's trees are about 15 to 25 deep for 10⁴ to 10⁵
//! primitives, and a tree of 256 levels or more, never seen, would take a
//! heap stack per query).
use std::ops::{Add, Index, Mul, Sub};
use std::time::Duration;

use glam::{DVec2, DVec3, Vec3A};
use obvhs::BvhBuildParams;
use obvhs::aabb::Aabb;
use obvhs::bvh2::Bvh2;
use obvhs::bvh2::builder::build_bvh2;
use obvhs::bvh2::node::Bvh2Node;
use obvhs::faststack::StackStack;
use obvhs::ray::{Ray, RayHit};

/// Pad of every box and every distance bound, in units of the scene's
/// half-size (the unit frame): 2⁻¹⁶ ≈ 1.5·10⁻⁵.
pub const PAD: f64 = 1.0 / 65536.0;

/// Origins farther than this from the scene centre (in the unit frame) are
/// traced by a linear scan: beyond it, the `f64` clipping error would
/// approach [`PAD`].
const FAR: f64 = (1u64 << 30) as f64;

/// No primitive (the `skip` of a query that skips none, and no hit yet).
pub(crate) const NONE: u32 = u32::MAX;

/// A point or direction of the scene: `DVec2` or `DVec3`.
pub(crate) trait Vector:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<f64, Output = Self>
    + Add<f64, Output = Self>
    + Sub<f64, Output = Self>
    + Index<usize, Output = f64>
{
    /// The dimension.
    const DIM: usize;
    const ZERO: Self;
    const INFINITY: Self;
    const NEG_INFINITY: Self;
    fn min(self, other: Self) -> Self;
    fn max(self, other: Self) -> Self;
    fn abs(self) -> Self;
    fn max_element(self) -> f64;
    fn is_finite(self) -> bool;
    /// Whether `self` lies outside the box `[lo, hi]`.
    fn outside(self, lo: Self, hi: Self) -> bool;
    /// The `f32` point or direction of obvhs's ray (`z = 0` in the plane).
    fn to_ray(self) -> Vec3A;
    /// obvhs's box for `[min, max]` (in the plane, `z` from −1 to 1).
    fn aabb(min: Self, max: Self) -> Aabb;
}

/// The methods both glam types have under the same names.
macro_rules! vector {
    ($t:ty, $dim:expr) => {
        const DIM: usize = $dim;
        const ZERO: Self = <$t>::ZERO;
        const INFINITY: Self = <$t>::INFINITY;
        const NEG_INFINITY: Self = <$t>::NEG_INFINITY;
        #[inline(always)]
        fn min(self, other: Self) -> Self {
            <$t>::min(self, other)
        }
        #[inline(always)]
        fn max(self, other: Self) -> Self {
            <$t>::max(self, other)
        }
        #[inline(always)]
        fn abs(self) -> Self {
            <$t>::abs(self)
        }
        #[inline(always)]
        fn max_element(self) -> f64 {
            <$t>::max_element(self)
        }
        #[inline(always)]
        fn is_finite(self) -> bool {
            <$t>::is_finite(self)
        }
        #[inline(always)]
        fn outside(self, lo: Self, hi: Self) -> bool {
            self.cmplt(lo).any() || self.cmpgt(hi).any()
        }
    };
}

impl Vector for DVec2 {
    vector!(DVec2, 2);

    #[inline(always)]
    fn to_ray(self) -> Vec3A {
        Vec3A::new(self.x as f32, self.y as f32, 0.0)
    }

    #[inline]
    fn aabb(min: Self, max: Self) -> Aabb {
        Aabb::new(
            Vec3A::new(min.x as f32, min.y as f32, -1.0),
            Vec3A::new(max.x as f32, max.y as f32, 1.0),
        )
    }
}

impl Vector for DVec3 {
    vector!(DVec3, 3);

    #[inline(always)]
    fn to_ray(self) -> Vec3A {
        self.as_vec3a()
    }

    #[inline]
    fn aabb(min: Self, max: Self) -> Aabb {
        Aabb::new(min.as_vec3a(), max.as_vec3a())
    }
}

/// A primitive of a [`Tree`]: its box, its exact ray test, its index in
/// the caller's list.
pub(crate) trait Primitive: Copy {
    type Vector: Vector;
    /// A query ray prepared for [`hit`](Primitive::hit).
    type Ray;
    /// The query ray `origin + t dir`, prepared.
    fn ray(origin: Self::Vector, dir: Self::Vector) -> Self::Ray;
    /// Distance `t` to the primitive along `ray`, if hit: the `f64` test of
    /// the caster's linear scan.
    fn hit(&self, ray: &Self::Ray) -> Option<f64>;
    /// The componentwise least and greatest of the vertices (all finite).
    fn bounds(&self) -> (Self::Vector, Self::Vector);
    /// The index in the caller's list.
    fn id(&self) -> u32;
}

/// Folds `p`'s hit into `best`, the closest `(t, id)` so far with
/// `t < t_max` (ties to the lowest id); whether it took it.
#[inline(always)]
fn take<P: Primitive>(best: &mut (f64, u32), p: &P, ray: &P::Ray, t_max: f64, skip: u32) -> bool {
    if p.id() == skip {
        return false;
    }
    if let Some(t) = p.hit(ray)
        && t < t_max
        && (t < best.0 || (t == best.0 && p.id() < best.1))
    {
        *best = (t, p.id());
        return true;
    }
    false
}

/// The closest of `prims` other than `skip` hit with `t < t_max`, as
/// `(t, id)`, ties to the lowest id.
#[inline]
pub(crate) fn scan_closest<P: Primitive>(
    prims: &[P],
    ray: &P::Ray,
    t_max: f64,
    skip: u32,
) -> Option<(f64, u32)> {
    let mut best = (t_max, NONE);
    for p in prims {
        take(&mut best, p, ray, t_max, skip);
    }
    (best.1 != NONE).then_some(best)
}

/// Whether any of `prims` other than `skip` is hit with `t < t_max`.
#[inline]
pub(crate) fn scan_any<P: Primitive>(prims: &[P], ray: &P::Ray, t_max: f64, skip: u32) -> bool {
    prims
        .iter()
        .any(|p| p.id() != skip && p.hit(ray).is_some_and(|t| t < t_max))
}

/// The map from scene coordinates to the unit frame, `p ↦ p s − c s`, with
/// `s` a power of two (so `p s` is exact).
#[derive(Debug, Clone, Copy)]
struct Frame<V> {
    /// The centre times the scale.
    offset: V,
    /// The scale, a power of two.
    scale: f64,
}

impl<V: Vector> Frame<V> {
    /// The frame in which the boxes `bounds` fill about `[−1, 1]ⁿ`.
    fn new(bounds: impl Iterator<Item = (V, V)>) -> Frame<V> {
        let (mut lo, mut hi) = (V::INFINITY, V::NEG_INFINITY);
        for (min, max) in bounds {
            lo = lo.min(min);
            hi = hi.max(max);
        }
        if !(lo.is_finite() && hi.is_finite()) {
            return Frame {
                offset: V::ZERO,
                scale: 1.0,
            };
        }
        // Halves first: `hi − lo` may overflow.
        let centre = lo * 0.5 + hi * 0.5;
        let half = (hi * 0.5 - lo * 0.5).max_element();
        // 2^−e with 2^(e−1) < half ≤ 2^e, so the scene fits in [−1, 1]ⁿ; the
        // clamp keeps the scale a normal number (a scene of half-size beyond
        // 2^1022 fits in [−4, 4]ⁿ, one below 2^−1000 in a speck: both are
        // still bounded conservatively).
        let e = if half > 0.0 {
            (half.log2().ceil() as i64).clamp(-1000, 1022)
        } else {
            0
        };
        let scale = f64::from_bits(((1023 - e) as u64) << 52);
        Frame {
            offset: centre * scale,
            scale,
        }
    }

    /// `p` in the frame. Monotone in each coordinate, so the map of a
    /// box's corners bounds the map of what is inside.
    #[inline]
    fn map(&self, p: V) -> V {
        p * self.scale - self.offset
    }
}

/// Where the `f32` ray of a query starts and how distances map onto it.
struct Clip {
    /// The `f32` ray: origin `o + s0 w`, direction `w`, where `o` is the
    /// query origin in the frame and `w = d / m` the query direction in the
    /// frame scaled by a power of two to a largest component in `[1, 2)`.
    ray: Ray,
    /// The power of two: query distance `t` is ray parameter `t m − s0`.
    m: f64,
    /// Ray parameter of the `f32` ray's origin from the query origin.
    s0: f64,
}

impl Clip {
    /// The `f32` bound for a hit at query distance `t`: boxes entered
    /// beyond it cannot hold a hit closer than `t`.
    #[inline]
    fn bound(&self, t: f64) -> f32 {
        ((t * self.m - self.s0) + PAD) as f32
    }
}

/// What a query needs: nothing (no hit possible), a linear scan (no tree,
/// or the frame cannot hold the ray), or a traversal.
enum Plan {
    Miss,
    Linear,
    Trace(Clip),
}

/// Runs `$body` with `$stack` bound to a traversal stack deep enough for a
/// tree of `$depth` levels: a fixed array when it fits, else a heap one.
macro_rules! with_stack {
    ($depth:expr, $stack:ident, $body:expr) => {
        // A push beyond a StackStack's last slot overwrites it silently: the
        // stack holds at most depth − 1 entries, and N − 1 fit.
        if $depth < 64 {
            let $stack = &mut StackStack::<u32, 64>::default();
            $body
        } else if $depth < 256 {
            let $stack = &mut StackStack::<u32, 256>::default();
            $body
        } else {
            let $stack = &mut Vec::<u32>::with_capacity($depth);
            $body
        }
    };
}

/// A BVH over a fixed list of primitives, answering exactly as
/// [`scan_closest`] and [`scan_any`] over them; see the [module docs](self).
#[derive(Clone)]
pub(crate) struct Tree<P: Primitive> {
    /// Empty when no tree was built (a list below `linear_below`).
    bvh: Bvh2,
    /// The primitives in BVH leaf order (list order without a tree).
    prims: Vec<P>,
    frame: Frame<P::Vector>,
    /// The padded scene box in the frame; rays are clipped to it.
    lo: P::Vector,
    hi: P::Vector,
    /// Nodes on the longest root-to-leaf path (sizes the traversal stack).
    depth: usize,
}

impl<P: Primitive> Tree<P> {
    /// A tree over `prims` (all finite), or none when there are fewer than
    /// `linear_below` (or none at all): queries then scan.
    pub(crate) fn new(prims: Vec<P>, linear_below: usize) -> Tree<P> {
        let frame = Frame::new(prims.iter().map(P::bounds));
        let (mut lo, mut hi) = (P::Vector::INFINITY, P::Vector::NEG_INFINITY);
        let boxes: Vec<Aabb> = prims
            .iter()
            .map(|p| {
                let (min, max) = p.bounds();
                let (min, max) = (frame.map(min) - PAD, frame.map(max) + PAD);
                lo = lo.min(min);
                hi = hi.max(max);
                P::Vector::aabb(min, max)
            })
            .collect();
        let (bvh, prims) = if boxes.is_empty() || boxes.len() < linear_below {
            (Bvh2::default(), prims)
        } else {
            let bvh = build_bvh2(
                &boxes,
                BvhBuildParams::medium_build(),
                &mut Duration::default(),
            );
            let ordered = bvh
                .primitive_indices
                .iter()
                .map(|&k| prims[k as usize])
                .collect();
            (bvh, ordered)
        };
        let depth = tree_depth(&bvh);
        Tree {
            bvh,
            prims,
            frame,
            lo: lo - PAD,
            hi: hi + PAD,
            depth,
        }
    }

    /// The primitives (in BVH leaf order).
    pub(crate) fn prims(&self) -> &[P] {
        &self.prims
    }

    /// Nodes of the tree (0 without one).
    pub(crate) fn nodes(&self) -> usize {
        self.bvh.nodes.len()
    }

    /// Nodes on the longest root-to-leaf path.
    pub(crate) fn depth(&self) -> usize {
        self.depth
    }

    /// How to answer a query.
    #[inline]
    fn plan(&self, origin: P::Vector, dir: P::Vector, t_max: f64) -> Plan {
        if t_max.is_nan() || t_max <= 0.0 || self.prims.is_empty() {
            return Plan::Miss;
        }
        if self.bvh.nodes.is_empty() {
            return Plan::Linear;
        }
        let o = self.frame.map(origin);
        let d = dir * self.frame.scale;
        let a = d.abs().max_element();
        if !(o.is_finite() && a > 0.0 && a.is_finite()) || o.abs().max_element() > FAR {
            return Plan::Linear;
        }
        // m = 2^⌊log₂ a⌋ and w = d / m, both exact, without a division.
        let e = a.to_bits() >> 52; // a > 0: the biased exponent
        if !a.is_normal() || e >= 2045 {
            return Plan::Linear;
        }
        let m = f64::from_bits(e << 52);
        let w = d * f64::from_bits((2046 - e) << 52);
        // An origin outside the padded scene box moves to where the ray
        // enters it, at parameter s0.
        let mut s0 = 0.0_f64;
        if o.outside(self.lo, self.hi) {
            let mut s1 = f64::INFINITY;
            for i in 0..P::Vector::DIM {
                if w[i] == 0.0 {
                    if o[i] < self.lo[i] || o[i] > self.hi[i] {
                        return Plan::Miss;
                    }
                } else {
                    let inv = 1.0 / w[i];
                    let (ta, tb) = ((self.lo[i] - o[i]) * inv, (self.hi[i] - o[i]) * inv);
                    s0 = s0.max(ta.min(tb));
                    s1 = s1.min(ta.max(tb));
                }
            }
            if s0 > s1 || s0 > t_max * m + PAD {
                return Plan::Miss;
            }
        }
        let p = o + w * s0;
        let mut clip = Clip {
            ray: Ray::new(p.to_ray(), w.to_ray(), 0.0, f32::INFINITY),
            m,
            s0,
        };
        clip.ray.tmax = clip.bound(t_max);
        Plan::Trace(clip)
    }

    /// The closest primitive other than `skip` (`u32::MAX`: none) crossed
    /// by `origin + t dir` with `t < t_max`, as `(t, index)`; exactly
    /// [`scan_closest`]'s answer (ties to the lowest index).
    #[inline]
    pub(crate) fn closest_hit(
        &self,
        origin: P::Vector,
        dir: P::Vector,
        t_max: f64,
        skip: u32,
    ) -> Option<(f64, u32)> {
        self.closest_hit_along(&P::ray(origin, dir), origin, dir, t_max, skip)
    }

    /// [`Tree::closest_hit`] with the primitives' form of the ray, `ray`,
    /// made by the caller (who asks several trees the same).
    #[inline]
    pub(crate) fn closest_hit_along(
        &self,
        ray: &P::Ray,
        origin: P::Vector,
        dir: P::Vector,
        t_max: f64,
        skip: u32,
    ) -> Option<(f64, u32)> {
        let clip = match self.plan(origin, dir, t_max) {
            Plan::Miss => return None,
            Plan::Linear => return scan_closest(&self.prims, ray, t_max, skip),
            Plan::Trace(clip) => clip,
        };
        let mut best = (t_max, NONE);
        self.traverse(&clip, |prims, r| {
            for p in prims {
                if take(&mut best, p, ray, t_max, skip) {
                    // Padded: a later equal-t, lower-index hit is still reached.
                    r.tmax = r.tmax.min(clip.bound(best.0));
                }
            }
            true
        });
        (best.1 != NONE).then_some(best)
    }

    /// Whether any primitive other than `skip` (`u32::MAX`: none) is
    /// crossed by `origin + t dir` with `t < t_max`; exactly [`scan_any`]'s
    /// answer.
    #[inline]
    pub(crate) fn any_hit(&self, origin: P::Vector, dir: P::Vector, t_max: f64, skip: u32) -> bool {
        self.any_hit_along(&P::ray(origin, dir), origin, dir, t_max, skip)
    }

    /// [`Tree::any_hit`] with the primitives' form of the ray, `ray`, made
    /// by the caller.
    #[inline]
    pub(crate) fn any_hit_along(
        &self,
        ray: &P::Ray,
        origin: P::Vector,
        dir: P::Vector,
        t_max: f64,
        skip: u32,
    ) -> bool {
        let clip = match self.plan(origin, dir, t_max) {
            Plan::Miss => return false,
            Plan::Linear => return scan_any(&self.prims, ray, t_max, skip),
            Plan::Trace(clip) => clip,
        };
        let mut found = false;
        self.traverse(&clip, |prims, _| {
            found = scan_any(prims, ray, t_max, skip);
            !found // false halts the traversal
        });
        found
    }

    /// Traverses the tree along `clip`'s ray, calling `leaf` with the
    /// primitives of each leaf whose box the ray enters and the ray (whose
    /// `tmax` it may shorten), until it returns false. The one traversal
    /// of both queries: they differ only in what a leaf does.
    #[inline(always)]
    fn traverse(&self, clip: &Clip, mut leaf: impl FnMut(&[P], &mut Ray) -> bool) {
        let mut visit = |node: &Bvh2Node, r: &mut Ray, _: &mut RayHit| {
            let first = node.first_index as usize;
            leaf(&self.prims[first..first + node.prim_count as usize], r)
        };
        with_stack!(
            self.depth,
            stack,
            self.bvh
                .ray_traverse_dynamic(stack, clip.ray, &mut RayHit::none(), &mut visit)
        )
    }
}

/// Nodes on the longest root-to-leaf path of `bvh` (0 if empty), without
/// recursion.
fn tree_depth(bvh: &Bvh2) -> usize {
    if bvh.nodes.is_empty() {
        return 0;
    }
    let mut deepest = 0;
    let mut todo = vec![(0usize, 1usize)];
    while let Some((i, d)) = todo.pop() {
        let node = &bvh.nodes[i];
        if node.is_leaf() {
            deepest = deepest.max(d);
        } else {
            let c = node.first_index as usize;
            todo.push((c, d + 1));
            todo.push((c + 1, d + 1));
        }
    }
    deepest
}
