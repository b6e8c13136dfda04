//! A bounding volume hierarchy over flatland segments: [`SegmentBvh`], the
//! [`RayCast`] for scenes of more than about 20 segments. Below that,
//! [`LinearScan`](super::geometry::LinearScan) is faster: `cargo bench
//! --bench raycast` found the scan ahead at 16 segments and 1.8 times
//! behind at 32; at 10⁴ segments the BVH is about 100 times faster.
//!
//! The hierarchy, shared with the mesh's triangles in
//! [`bvh_frame`](crate::bvh_frame), is obvhs's binary BVH, built by PLOC on
//! a degenerate 3D embedding: segment `i` becomes the box `[min x, min y, −1] … [max x,
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
//! The boxes live in the *unit frame* of [`bvh_frame`](crate::bvh_frame),
//! padded by [`PAD`]; the argument that the `f32` culling never loses a hit,
//! and the fallback to a linear scan for rays the frame cannot hold, are
//! stated there once for both casters.
//!
//! Ties (two segments at the same `t`, as at a polygon's vertex) go to the
//! lowest index, as in the linear scan. The one case where the two could
//! differ is a ray grazing a segment's end so closely (angles below about
//! 10⁻¹⁰ rad) that the `f64` test itself is rounding noise.
//!
//! # Cost
//!
//! No heap allocation per query (see [`bvh_frame`](crate::bvh_frame#cost));
//! PLOC's trees are about 15 deep for 10⁴ segments and 20 for 10⁵.
//! Construction takes some tens of milliseconds for 10⁴ segments.
use std::fmt;

use glam::DVec2;

pub use crate::bvh_frame::PAD;
use crate::bvh_frame::{Primitive, Tree};

#[cfg(test)]
use super::geometry::NO_SEGMENT;
use super::geometry::{Hit, RayCast, Segment};

/// A segment in BVH order, with its index in the caller's list.
#[derive(Debug, Clone, Copy)]
struct Prim {
    segment: Segment,
    id: u32,
}

impl Primitive for Prim {
    type Vector = DVec2;
    /// The query's origin and direction, as [`Segment::intersect`] takes them.
    type Ray = (DVec2, DVec2);

    #[inline(always)]
    fn ray(origin: DVec2, dir: DVec2) -> (DVec2, DVec2) {
        (origin, dir)
    }

    #[inline(always)]
    fn hit(&self, &(origin, dir): &(DVec2, DVec2)) -> Option<f64> {
        self.segment.intersect(origin, dir)
    }

    #[inline]
    fn bounds(&self) -> (DVec2, DVec2) {
        let s = &self.segment;
        (s.a.min(s.b), s.a.max(s.b))
    }

    #[inline(always)]
    fn id(&self) -> u32 {
        self.id
    }
}

/// A BVH ray caster over a fixed list of segments; see the [module
/// docs](self). Answers exactly as [`LinearScan`](super::geometry::LinearScan)
/// over the same list.
#[derive(Clone)]
pub struct SegmentBvh {
    /// The finite segments.
    tree: Tree<Prim>,
}

impl fmt::Debug for SegmentBvh {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("SegmentBvh")
            .field("segments", &self.tree.prims().len())
            .field("nodes", &self.tree.nodes())
            .field("depth", &self.tree.depth())
            .finish()
    }
}

impl SegmentBvh {
    /// A caster over `segments` (indices are positions in the list, as for
    /// [`LinearScan::new`](super::geometry::LinearScan::new)). Any list is
    /// accepted: an empty one is never hit, and non-finite segments, which
    /// the linear scan never reports either, are left out.
    pub fn new(segments: Vec<Segment>) -> SegmentBvh {
        let prims = segments
            .into_iter()
            .enumerate()
            .filter(|(_, s)| s.a.is_finite() && s.b.is_finite())
            .map(|(i, segment)| Prim {
                segment,
                id: i as u32,
            })
            .collect();
        SegmentBvh {
            // A tree from one segment up: the scan is faster below about 20
            // (see the module docs), but the tree answers alike.
            tree: Tree::new(prims, 0),
        }
    }
}

impl RayCast for SegmentBvh {
    fn closest_hit(&self, origin: DVec2, dir: DVec2, t_max: f64, skip: u32) -> Option<Hit> {
        self.tree
            .closest_hit(origin, dir, t_max, skip)
            .map(|(t, segment)| Hit { t, segment })
    }

    fn any_hit(&self, origin: DVec2, dir: DVec2, t_max: f64, skip: u32) -> bool {
        self.tree.any_hit(origin, dir, t_max, skip)
    }
}

#[cfg(test)]
mod tests;
