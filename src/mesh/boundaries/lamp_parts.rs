//! The arc of an edge seen from a point, and the parts of it behind which
//! a lamp lies: what the boundary points of [`super`] are placed on. A
//! silhouette whose arc has a lamp behind it carries direct light across
//! its jump; those parts are taken apart from the drawn point (book:
//! chapter "Three dimensions", section "Silhouette edges").
use super::super::edge_sampler::LAMP_EDGES;
use super::super::edges::Edge;
use super::super::edges::{EdgeFacts, EdgeTree};
use super::super::space::Space;
use crate::path::NO_PRIM;
use glam::DVec3;

/// Most emitter triangles for which the edge points are also drawn where a
/// lamp lies behind them (a test per emitter triangle per draw).
pub(super) const LAMP_TRIANGLES: usize = 16;

/// An edge's arc seen from `x`: the directions `wa cos α + t sin α`,
/// `α ∈ [0, arc]`, in the plane through `x` and the edge (unit normal `n`).
#[derive(Debug, Clone, Copy)]
pub(super) struct EdgeArc {
    /// From `x` to the edge's ends.
    ra: DVec3,
    rb: DVec3,
    n: DVec3,
    wa: DVec3,
    t: DVec3,
    pub(super) arc: f64,
}

impl EdgeArc {
    /// The arc of `edge` seen from `x`; `None` seen end-on.
    #[inline]
    pub(super) fn new(edge: &Edge, x: DVec3) -> Option<EdgeArc> {
        let (ra, rb) = (edge.a - x, edge.b - x);
        let n = ra.cross(rb);
        let (sin_g, cos_g) = (n.length(), ra.dot(rb));
        let arc = sin_g.atan2(cos_g);
        if arc.is_nan() || arc <= 0.0 || sin_g == 0.0 {
            return None; // seen end-on: no arc
        }
        let n = n / sin_g;
        let wa = ra.normalize();
        Some(EdgeArc {
            ra,
            rb,
            n,
            wa,
            t: n.cross(wa),
            arc,
        })
    }
}

impl EdgeArc {
    /// The point of `edge` (whose arc this is) seen at angle `alpha`
    /// along the arc: where the ray along `wa cos α + t sin α` meets the
    /// edge's line, in the plane through `x` and the edge.
    #[inline]
    pub(super) fn point(&self, edge: &Edge, alpha: f64) -> DVec3 {
        let (s, c) = alpha.sin_cos();
        let w = self.wa * c + self.t * s;
        let d = edge.b - edge.a;
        let tau = (-(self.ra.cross(w).dot(self.n)) / d.cross(w).dot(self.n)).clamp(0.0, 1.0);
        edge.a + d * tau
    }
}

/// The parts of an arc behind which a lamp lies: intervals of `α` (one per
/// emitter triangle the arc's plane cuts; they may overlap) and their
/// total length.
#[derive(Debug, Clone, Copy)]
pub(super) struct LampParts {
    intervals: [(f64, f64); LAMP_TRIANGLES],
    count: usize,
    pub(super) total: f64,
}

impl LampParts {
    /// An angle uniform over the parts (an interval by its length, then
    /// uniform in it) for `v ∈ [0, 1)`; its density per unit angle is
    /// [`LampParts::cover`] over `total`.
    #[inline]
    pub(super) fn pick(&self, v: f64, arc: f64) -> f64 {
        let mut left = v * self.total;
        let mut pick = self.intervals[self.count - 1];
        for iv in &self.intervals[..self.count] {
            let len = iv.1 - iv.0;
            if left < len {
                pick = *iv;
                break;
            }
            left -= len;
        }
        (pick.0 + left.min(pick.1 - pick.0)).clamp(0.0, arc)
    }

    /// An angle uniform on `[0, arc]` outside every part for `v ∈ [0,
    /// 1)`, and the angle outside them (the density is its inverse); `None`
    /// if the parts cover the arc.
    #[inline]
    pub(super) fn pick_outside(&self, v: f64, arc: f64) -> Option<(f64, f64)> {
        // The parts merged: sorted by their start (insertion sort, at most
        // LAMP_TRIANGLES), overlaps joined.
        let mut iv = self.intervals;
        let n = self.count;
        for i in 1..n {
            let mut j = i;
            while j > 0 && iv[j - 1].0 > iv[j].0 {
                iv.swap(j - 1, j);
                j -= 1;
            }
        }
        let mut merged = [(0.0, 0.0); LAMP_TRIANGLES];
        let mut m = 0;
        for &(lo, hi) in &iv[..n] {
            if m > 0 && lo <= merged[m - 1].1 {
                merged[m - 1].1 = merged[m - 1].1.max(hi);
            } else {
                merged[m] = (lo, hi);
                m += 1;
            }
        }
        let covered: f64 = merged[..m].iter().map(|(lo, hi)| hi - lo).sum();
        let outside = arc - covered;
        if outside <= 0.0 {
            return None;
        }
        // The gaps, in order: before the first part, between, after.
        let mut left = v * outside;
        let mut start = 0.0;
        for &(lo, hi) in &merged[..m] {
            let gap = (lo - start).max(0.0);
            if left < gap {
                return Some((start + left, outside));
            }
            left -= gap;
            start = hi;
        }
        Some(((start + left).min(arc), outside))
    }

    /// How many of the intervals hold `alpha`.
    #[inline]
    pub(super) fn cover(&self, alpha: f64) -> f64 {
        self.intervals[..self.count]
            .iter()
            .filter(|iv| iv.0 <= alpha && alpha <= iv.1)
            .count() as f64
    }
}

/// Whether `edge` is a silhouette seen from `x`: open, or its faces facing
/// `x` differently (a reflector's crease, a discontinuity from everywhere
/// for the edge tree, is not one unless it is so).
#[inline]
fn is_silhouette(edge: &Edge, facts: &EdgeFacts, x: DVec3) -> bool {
    if edge.faces[1] == NO_PRIM {
        return true;
    }
    let r = x - edge.a;
    let (s0, s1) = (facts.normals[0].dot(r), facts.normals[1].dot(r));
    (s0 > 0.0) != (s1 > 0.0)
}

/// The part of the segment where the plane through `x` of normal `n` (any
/// length) cuts the triangle `tri` that is seen from `x` inside the wedge
/// between two directions `ra`, `rb` of that plane (less than π apart):
/// where `r·ta ≥ 0` (`ta = n × ra`: on `rb`'s side of `ra`) and `r·tb ≥ 0`
/// (`tb = rb × n`: on `ra`'s side of `rb`), both linear along the segment.
/// Its ends relative to `x`, or `None`.
#[inline]
fn wedge_cut(tri: &[DVec3; 3], x: DVec3, n: DVec3, ta: DVec3, tb: DVec3) -> Option<[DVec3; 2]> {
    let h = tri.map(|v| (v - x).dot(n));
    let mut ends = [DVec3::ZERO; 2];
    let mut k = 0;
    for i in 0..3 {
        let (i0, i1) = (i, (i + 1) % 3);
        if (h[i0] > 0.0) != (h[i1] > 0.0) && k < 2 {
            let s = h[i0] / (h[i0] - h[i1]);
            ends[k] = tri[i0] + (tri[i1] - tri[i0]) * s - x;
            k += 1;
        }
    }
    if k < 2 {
        return None;
    }
    let (mut lo, mut hi) = (0.0f64, 1.0f64);
    for m in [ta, tb] {
        let (f0, f1) = (ends[0].dot(m), ends[1].dot(m));
        if f0 < 0.0 && f1 < 0.0 {
            return None;
        }
        if f0 < 0.0 {
            lo = lo.max(f0 / (f0 - f1));
        } else if f1 < 0.0 {
            hi = hi.min(f0 / (f0 - f1));
        }
    }
    let d = ends[1] - ends[0];
    (hi > lo).then(|| [ends[0] + d * lo, ends[0] + d * hi])
}

impl Space {
    /// Whether a lamp (an emitter triangle) lies behind some of the arc of
    /// `edge` seen from `x`: [`wedge_cut`] per emitter triangle, in raw
    /// vectors (no square root, no angle), the cheap test before
    /// [`Space::lamp_intervals`].
    #[inline]
    fn lamp_behind(&self, x: DVec3, edge: &Edge) -> bool {
        let (ra, rb) = (edge.a - x, edge.b - x);
        let n = ra.cross(rb);
        // First whether the plane cuts a lamp at all (most planes miss).
        let cut = |tri: &[DVec3; 3]| {
            let h = tri.map(|v| (v - x).dot(n) > 0.0);
            h[0] != h[1] || h[1] != h[2]
        };
        if !self
            .emitters
            .iter()
            .any(|&(p, _)| cut(&self.tris[p as usize]))
        {
            return false;
        }
        let (ta, tb) = (n.cross(ra), rb.cross(n));
        self.emitters
            .iter()
            .any(|&(prim, _)| wedge_cut(&self.tris[prim as usize], x, n, ta, tb).is_some())
    }

    /// The parts of an edge's arc seen from `x` behind which an emitter
    /// triangle lies: per triangle, the angles of the part of the segment
    /// where the arc's plane cuts it that lies inside the arc's wedge
    /// ([`wedge_cut`]). `None` without such parts, or with more than
    /// [`LAMP_TRIANGLES`] emitter triangles.
    pub(super) fn lamp_intervals(&self, x: DVec3, a: &EdgeArc) -> Option<LampParts> {
        if self.emitters.is_empty() || self.emitters.len() > LAMP_TRIANGLES {
            return None;
        }
        let mut out = [(0.0, 0.0); LAMP_TRIANGLES];
        let (mut count, mut total) = (0, 0.0);
        let tb = a.rb.cross(a.n);
        for &(prim, _) in &self.emitters {
            let Some(ends) = wedge_cut(&self.tris[prim as usize], x, a.n, a.t, tb) else {
                continue;
            };
            let [u, v] = ends.map(|r| r.dot(a.t).atan2(r.dot(a.wa)).clamp(0.0, a.arc));
            let (lo, hi) = (u.min(v), u.max(v));
            if hi > lo {
                out[count] = (lo, hi);
                count += 1;
                total += hi - lo;
            }
        }
        (count > 0 && total > 0.0).then_some(LampParts {
            intervals: out,
            count,
            total,
        })
    }

    /// Per edge of `tree` (in its order), > 0 where its lamp parts are
    /// taken apart ([`Space::edge_points`]): the angle of its arc seen
    /// from `x` with a lamp behind over the distance to its midpoint, 0
    /// unless it is a silhouette from `x` (a crease whose faces both face
    /// `x`, or both away, shows no lamp past it, whatever lies behind its
    /// arc), and their total; all 0 when the tree holds more than
    /// [`LAMP_EDGES`] edges or the lamps more than [`LAMP_TRIANGLES`]
    /// triangles.
    #[inline]
    pub(super) fn lamp_overlaps(&self, x: DVec3, tree: &EdgeTree) -> ([f64; LAMP_EDGES], f64) {
        let tables = self.edge_tables();
        let ids = tree.edges();
        let mut overlap = [0.0f64; LAMP_EDGES];
        let mut total = 0.0;
        if ids.len() > LAMP_EDGES
            || self.emitters.is_empty()
            || self.emitters.len() > LAMP_TRIANGLES
        {
            return (overlap, total);
        }
        for (k, &e) in ids.iter().enumerate() {
            let edge = &tables.edges[e as usize];
            if !is_silhouette(edge, &tables.edge_facts[e as usize], x) || !self.lamp_behind(x, edge)
            {
                continue;
            }
            if let Some(parts) = EdgeArc::new(edge, x).and_then(|a| self.lamp_intervals(x, &a)) {
                let r = (0.5 * (edge.a + edge.b) - x).length();
                let w = parts.total / r;
                overlap[k] = w;
                total += w;
            }
        }
        (overlap, total)
    }
}
