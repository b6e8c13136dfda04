//! A bounding volume hierarchy over flatland segments: [`SegmentBvh`], the
//! [`RayCast`] for scenes of more than about 20 segments. Below that,
//! [`LinearScan`](super::geometry::LinearScan) is faster: `cargo bench
//! --bench raycast` found the scan ahead at 16 segments and 1.8 times
//! behind at 32; at 10⁴ segments the BVH is about 100 times faster.
//!
//! The hierarchy is obvhs's binary BVH, built by PLOC on a degenerate 3D
//! embedding: segment `i` becomes the box `[min x, min y, −1] … [max x,
//! max y, +1]` and rays lie in the plane `z = 0`. With the constant depth,
//! the builder's surface-area cost `dx dy + 2 (dx + dy)` is mostly the box
//! perimeter, the right cost in the plane (a random line meets a convex set
//! with probability proportional to its perimeter). obvhs only sees boxes,
//! in `f32`; every segment it reaches is tested in `f64` by
//! [`Segment::intersect`], the very test the linear scan makes, so a hit's
//! distance and index are bit for bit the linear scan's.
//!
//! # Conservative culling
//!
//! The boxes live in a *unit frame*, the scene translated and scaled by a
//! power of two so that it fits in `[−1, 1]²`; huge or tiny coordinates are
//! then no concern of `f32`. Each box is padded by [`PAD`] (2⁻¹⁶ of the
//! scene half-size), and each `f32` distance bound by as much: far more than
//! the `f32` rounding of the ray (origin, direction, obvhs's clamped inverse
//! direction, slab arithmetic), which stays below 10⁻⁶ inside the frame. A
//! ray from outside the padded scene box first moves, in `f64`, to where it
//! enters the box, so the `f32` ray starts inside the frame whatever the
//! origin. Rays the frame cannot hold (origins farther than 2³⁰ scene sizes,
//! non-finite input, directions whose size over- or underflows) fall back to
//! a linear scan of the segments, with the same result.
//!
//! Ties (two segments at the same `t`, as at a polygon's vertex) go to the
//! lowest index, as in the linear scan. The one case where the two could
//! differ is a ray grazing a segment's end so closely (angles below about
//! 10⁻¹⁰ rad) that the `f64` test itself is rounding noise.
//!
//! # Cost
//!
//! No heap allocation per query: the traversal stack is a fixed array on
//! the call stack, sized from the tree depth measured at construction (64 or
//! 256 entries; PLOC's trees are about 15 deep for 10⁴ segments and 20 for
//! 10⁵, and a tree of 256 levels or more would take a heap stack per query).
//! Construction takes some tens of milliseconds for 10⁴ segments.
use std::fmt;
use std::time::Duration;

use glam::{DVec2, Vec3A};
use obvhs::BvhBuildParams;
use obvhs::aabb::Aabb;
use obvhs::bvh2::Bvh2;
use obvhs::bvh2::builder::build_bvh2;
use obvhs::faststack::{FastStack, StackStack};
use obvhs::ray::{Ray, RayHit};

use super::geometry::{Hit, NO_SEGMENT, RayCast, Segment};

/// Pad of every box and every distance bound, in units of the scene's
/// half-size (the unit frame): 2⁻¹⁶ ≈ 1.5·10⁻⁵.
pub const PAD: f64 = 1.0 / 65536.0;

/// Origins farther than this from the scene centre (in the unit frame) are
/// traced by a linear scan: beyond it, the `f64` clipping error would
/// approach [`PAD`].
const FAR: f64 = (1u64 << 30) as f64;

/// A segment in BVH order, with its index in the caller's list.
#[derive(Debug, Clone, Copy)]
struct Prim {
    segment: Segment,
    id: u32,
}

/// The map from scene coordinates to the unit frame, `p ↦ p s − c s`, with
/// `s` a power of two (so `p s` is exact).
#[derive(Debug, Clone, Copy)]
struct Frame {
    /// The centre times the scale.
    offset: DVec2,
    /// The scale, a power of two.
    scale: f64,
}

impl Frame {
    /// The frame in which `segments` fill about `[−1, 1]²`.
    fn new(segments: &[Segment]) -> Frame {
        let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
        for s in segments {
            lo = lo.min(s.a).min(s.b);
            hi = hi.max(s.a).max(s.b);
        }
        if !(lo.is_finite() && hi.is_finite()) {
            return Frame {
                offset: DVec2::ZERO,
                scale: 1.0,
            };
        }
        // Halves first: `hi − lo` may overflow.
        let centre = 0.5 * lo + 0.5 * hi;
        let half = (0.5 * hi - 0.5 * lo).max_element();
        // 2^−e with 2^(e−1) < half ≤ 2^e, so the scene fits in [−1, 1]²; the
        // clamp keeps the scale a normal number (a scene of half-size beyond
        // 2^1022 fits in [−4, 4]², one below 2^−1000 in a speck: both are
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

    #[inline]
    fn map(&self, p: DVec2) -> DVec2 {
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

/// What a query needs: nothing (no hit possible), a linear scan (the frame
/// cannot hold the ray), or a traversal.
enum Plan {
    Miss,
    Linear,
    Trace(Clip),
}

/// A BVH ray caster over a fixed list of segments; see the [module
/// docs](self). Answers exactly as [`LinearScan`](super::geometry::LinearScan)
/// over the same list.
#[derive(Clone)]
pub struct SegmentBvh {
    bvh: Bvh2,
    /// The finite segments in BVH leaf order.
    prims: Vec<Prim>,
    frame: Frame,
    /// The padded scene box in the frame, rays are clipped to it.
    lo: DVec2,
    hi: DVec2,
    /// Nodes on the longest root-to-leaf path (sizes the traversal stack).
    depth: usize,
}

impl fmt::Debug for SegmentBvh {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("SegmentBvh")
            .field("segments", &self.prims.len())
            .field("nodes", &self.bvh.nodes.len())
            .field("depth", &self.depth)
            .finish()
    }
}

impl SegmentBvh {
    /// A caster over `segments` (indices are positions in the list, as for
    /// [`LinearScan::new`](super::geometry::LinearScan::new)). Any list is
    /// accepted: an empty one is never hit, and non-finite segments, which
    /// the linear scan never reports either, are left out.
    pub fn new(segments: Vec<Segment>) -> SegmentBvh {
        let (ids, finite): (Vec<u32>, Vec<Segment>) = segments
            .into_iter()
            .enumerate()
            .filter(|(_, s)| s.a.is_finite() && s.b.is_finite())
            .map(|(i, s)| (i as u32, s))
            .unzip();
        let frame = Frame::new(&finite);
        let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
        let boxes: Vec<Aabb> = finite
            .iter()
            .map(|s| {
                let (a, b) = (frame.map(s.a), frame.map(s.b));
                let (min, max) = (a.min(b) - PAD, a.max(b) + PAD);
                lo = lo.min(min);
                hi = hi.max(max);
                Aabb::new(
                    Vec3A::new(min.x as f32, min.y as f32, -1.0),
                    Vec3A::new(max.x as f32, max.y as f32, 1.0),
                )
            })
            .collect();
        let bvh = if boxes.is_empty() {
            Bvh2::default()
        } else {
            build_bvh2(
                &boxes,
                BvhBuildParams::medium_build(),
                &mut Duration::default(),
            )
        };
        let prims = bvh
            .primitive_indices
            .iter()
            .map(|&k| Prim {
                segment: finite[k as usize],
                id: ids[k as usize],
            })
            .collect();
        let depth = tree_depth(&bvh);
        SegmentBvh {
            bvh,
            prims,
            frame,
            lo: lo - PAD,
            hi: hi + PAD,
            depth,
        }
    }

    /// How to answer a query.
    #[inline]
    fn plan(&self, origin: DVec2, dir: DVec2, t_max: f64) -> Plan {
        if t_max.is_nan() || t_max <= 0.0 || self.prims.is_empty() {
            return Plan::Miss;
        }
        let o = self.frame.map(origin);
        let d = dir * self.frame.scale;
        let a = d.abs().max_element();
        if !(o.is_finite() && a > 0.0 && a.is_finite()) || o.abs().max_element() > FAR {
            return Plan::Linear;
        }
        // m = 2^⌊log₂ a⌋ and w = d / m, both exact, without a division: the
        // direction need not be unit, only of known size (|w| in [1, 2√2)),
        // so ray parameters are frame distances to within a factor 3.
        let e = a.to_bits() >> 52; // a > 0: the biased exponent
        if !a.is_normal() || e >= 2045 {
            return Plan::Linear;
        }
        let m = f64::from_bits(e << 52);
        let w = d * f64::from_bits((2046 - e) << 52);
        // An origin outside the padded scene box moves to where the ray
        // enters it, at parameter s0.
        let mut s0 = 0.0_f64;
        if o.cmplt(self.lo).any() || o.cmpgt(self.hi).any() {
            let mut s1 = f64::INFINITY;
            for i in 0..2 {
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
        let p = o + s0 * w;
        let mut clip = Clip {
            ray: Ray::new(
                Vec3A::new(p.x as f32, p.y as f32, 0.0),
                Vec3A::new(w.x as f32, w.y as f32, 0.0),
                0.0,
                f32::INFINITY,
            ),
            m,
            s0,
        };
        clip.ray.tmax = clip.bound(t_max);
        Plan::Trace(clip)
    }

    /// The closest hit by traversal, with `stack` as the traversal stack.
    #[inline(always)]
    fn closest_with<S: FastStack<u32>>(
        &self,
        stack: &mut S,
        clip: &Clip,
        (origin, dir, t_max, skip): (DVec2, DVec2, f64, u32),
    ) -> Option<Hit> {
        let mut best = Hit {
            t: t_max,
            segment: NO_SEGMENT,
        };
        let mut leaf = |node: &obvhs::bvh2::node::Bvh2Node, ray: &mut Ray, _: &mut RayHit| {
            let first = node.first_index as usize;
            for p in &self.prims[first..first + node.prim_count as usize] {
                if p.id == skip {
                    continue;
                }
                if let Some(t) = p.segment.intersect(origin, dir)
                    && t < t_max
                    && (t < best.t || (t == best.t && p.id < best.segment))
                {
                    best = Hit { t, segment: p.id };
                    // Padded: a later equal-t, lower-index hit is still reached.
                    ray.tmax = ray.tmax.min(clip.bound(t));
                }
            }
            true
        };
        self.bvh
            .ray_traverse_dynamic(stack, clip.ray, &mut RayHit::none(), &mut leaf);
        (best.segment != NO_SEGMENT).then_some(best)
    }

    /// Whether any segment is hit, by traversal with `stack`.
    #[inline(always)]
    fn any_with<S: FastStack<u32>>(
        &self,
        stack: &mut S,
        clip: &Clip,
        (origin, dir, t_max, skip): (DVec2, DVec2, f64, u32),
    ) -> bool {
        let mut found = false;
        let mut leaf = |node: &obvhs::bvh2::node::Bvh2Node, _: &mut Ray, _: &mut RayHit| {
            let first = node.first_index as usize;
            found = self.prims[first..first + node.prim_count as usize]
                .iter()
                .any(|p| {
                    p.id != skip && p.segment.intersect(origin, dir).is_some_and(|t| t < t_max)
                });
            !found // false halts the traversal
        };
        self.bvh
            .ray_traverse_dynamic(stack, clip.ray, &mut RayHit::none(), &mut leaf);
        found
    }

    /// The closest hit by testing every segment (rays the frame cannot hold).
    fn closest_linear(&self, origin: DVec2, dir: DVec2, t_max: f64, skip: u32) -> Option<Hit> {
        let mut best: Option<Hit> = None;
        for p in &self.prims {
            if p.id == skip {
                continue;
            }
            if let Some(t) = p.segment.intersect(origin, dir)
                && t < t_max
                && best.is_none_or(|b| t < b.t || (t == b.t && p.id < b.segment))
            {
                best = Some(Hit { t, segment: p.id });
            }
        }
        best
    }
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

impl RayCast for SegmentBvh {
    fn closest_hit(&self, origin: DVec2, dir: DVec2, t_max: f64, skip: u32) -> Option<Hit> {
        match self.plan(origin, dir, t_max) {
            Plan::Miss => None,
            Plan::Linear => self.closest_linear(origin, dir, t_max, skip),
            Plan::Trace(clip) => with_stack!(
                self.depth,
                stack,
                self.closest_with(stack, &clip, (origin, dir, t_max, skip))
            ),
        }
    }

    fn any_hit(&self, origin: DVec2, dir: DVec2, t_max: f64, skip: u32) -> bool {
        match self.plan(origin, dir, t_max) {
            Plan::Miss => false,
            Plan::Linear => self.closest_linear(origin, dir, t_max, skip).is_some(),
            Plan::Trace(clip) => with_stack!(
                self.depth,
                stack,
                self.any_with(stack, &clip, (origin, dir, t_max, skip))
            ),
        }
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

#[cfg(test)]
mod tests;
