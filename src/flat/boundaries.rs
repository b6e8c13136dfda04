//! Flatland's discontinuities behind the path core's [`Boundaries`]: the
//! corners of opaque shapes (drawn by weight for rendering's and
//! transport's jumps, with what either side of a corner sees) and the
//! expectation method's warp, piecewise linear on the circle between the
//! nearest visible corners (by the corner tree, or a scan for few corners).
//! Book: chapter "Flatland: one deformation, three estimators", sections
//! "Corner jumps" and "The warp field".
use super::geometry::{NO_SEGMENT, cross, perp};
use super::lobe::FlatLobe;
use super::space::{Knot, Plane};
use crate::path::deform::SlotSet;
use crate::path::walk::Vertex;
use crate::path::{
    Boundaries, BoundaryPoint, BoundaryView, Hit, MovingVertex, Side, Warping, nearest_sides,
};
use glam::DVec2;
use std::f64::consts::TAU;

/// A monotone stand-in for the counter-clockwise angle in `[0, 4)` of a
/// vector with cosine part `c` and sine part `s` relative to a direction.
#[inline]
fn pseudo_angle(c: f64, s: f64) -> f64 {
    let t = c / (c.abs() + s.abs());
    if s >= 0.0 { 1.0 - t } else { 3.0 + t }
}

/// The warp at a vertex for a sampled direction: the nearest visible corner
/// (or the lobe's horizon) on each side.
#[derive(Debug, Clone, Copy)]
pub struct FlatWarp {
    ccw: Option<Knot>,
    cw: Option<Knot>,
    horizons: (f64, f64),
}

impl Boundaries for Plane {
    // ANCHOR: sample_boundary
    /// A corner drawn by weight, the draws shared out equally among the
    /// slots of `view` (a mixture): a slot that sees every corner move
    /// draws among all of them, a shape parameter among its shape's (a
    /// binary search in cumulative weights either way). A few moving
    /// corners among many that move for one parameter only are then drawn
    /// as often as their parameters need, not by their share of the weight.
    #[inline]
    fn sample_boundary(
        &self,
        v: &Vertex<Self>,
        view: &BoundaryView,
        u: f64,
    ) -> Option<BoundaryPoint<DVec2>> {
        if let FlatLobe::Pixel { x0, x1, .. } = v.lobe {
            // A camera stands still: the moving corners seen through the
            // stratum, drawn uniformly.
            debug_assert!(!view.sees_all(), "a camera does not move");
            let list = self.camera_corner_list();
            let lo = list.partition_point(|c| c.0 < x0);
            let hi = list.partition_point(|c| c.0 <= x1);
            if hi <= lo {
                return None;
            }
            let n = hi - lo;
            let index = list[lo + ((u * n as f64) as usize).min(n - 1)].1;
            let (q, shape) = self.scene.corners()[index as usize];
            return Some(BoundaryPoint {
                q,
                shape,
                index,
                inv_pdf: n as f64,
            });
        }
        let total = self.all_cdf.last().copied().unwrap_or(0.0);
        // The mixture's components: every slot that sees all corners move
        // draws among all (if any weighs), every parameter among its
        // shape's (if they weigh: `weighed_shapes`); per shape, the count
        // of its parameters in `view.own`.
        let n_all = if total > 0.0 { view.all.len() } else { 0 };
        let own_in = |k: u32| view.own.and(self.shape_params[k as usize]).len();
        // Every parameter and no other slot (a vertex that stays put, the
        // commonest view): the components are the scene's, counted once.
        let (n_own, shapes, single) = if n_all == 0 && view.own == self.all_params.0 {
            self.all_params.1
        } else {
            let mut count = (0usize, 0usize, None);
            for &k in &self.weighed_shapes {
                let c = own_in(k);
                if c > 0 {
                    count = (count.0 + c, count.1 + 1, Some(k));
                }
            }
            count
        };
        let mixed = shapes > 1 || (n_all > 0 && n_own > 0);
        let n = n_all + n_own;
        if n == 0 {
            return None;
        }
        // The component, and a fresh uniform number within it.
        let (component, u) = if !mixed {
            (single, u)
        } else {
            let r = u * n as f64;
            let i = (r as usize).min(n - 1);
            let u = (r - i as f64).clamp(0.0, 1.0);
            if i < n_all {
                (None, u)
            } else {
                let mut rest = i - n_all;
                let mut pick = single;
                for &k in &self.weighed_shapes {
                    let c = own_in(k);
                    if rest < c {
                        pick = Some(k);
                        break;
                    }
                    rest -= c;
                }
                (pick, u)
            }
        };
        let (cdf, first) = match component {
            None => (&self.all_cdf[..], 0),
            Some(k) => {
                let (start, end) = self.shape_corners[k as usize];
                (&self.shape_cdf[start as usize..end as usize], start)
            }
        };
        let w_total = *cdf.last()?;
        // Below the total even when u·total rounds up to it, so that a
        // corner of weight 0 at the end is never picked.
        let s = (u * w_total).min(w_total * (1.0 - f64::EPSILON));
        let pick = cdf.partition_point(|&c| c <= s).min(cdf.len() - 1);
        let index = first + pick as u32;
        let (q, shape) = self.scene.corners()[index as usize];
        let w = self.corner_weight[index as usize];
        let inv_pdf = if !mixed {
            w_total / w
        } else {
            // Every component that holds the corner.
            let n_shape = own_in(shape);
            let p_all = if n_all > 0 { n_all as f64 / total } else { 0.0 };
            let p_shape = n_shape as f64 / self.shape_weight(shape);
            n as f64 / (w * (p_all + p_shape))
        };
        Some(BoundaryPoint {
            q,
            shape,
            index,
            inv_pdf,
        })
    }
    // ANCHOR_END: sample_boundary

    // ANCHOR: sides
    /// The segments at the corner that lie on either side of the sight line
    /// `η` from `x`; on each side the ray just past the line meets the one
    /// whose direction `d` from the corner has the least `(d·η)/|η × d|`
    /// (it is crossed first), or none.
    fn sides(&self, x: DVec2, b: &BoundaryPoint<DVec2>) -> (Side, Side) {
        let w = (b.q - x).normalize();
        let segments = self.scene.segments();
        let at_corner = self.corner_segments[b.index as usize]
            .into_iter()
            .filter(|&s| s != NO_SEGMENT)
            .map(|s| {
                let d = far_end(&segments[s as usize], b.q) - b.q;
                (s, d, cross(w, d))
            });
        nearest_sides(w, at_corner)
    }

    // ANCHOR_END: sides
    #[inline]
    fn holds(&self, b: &BoundaryPoint<DVec2>, p: u32) -> bool {
        self.corner_segments[b.index as usize].contains(&p)
    }
    #[inline]
    fn boundary_normal(&self, x: DVec2, b: &BoundaryPoint<DVec2>) -> DVec2 {
        perp((b.q - x).normalize())
    }

    /// A point on segment `p` a hair from the corner: 10⁻⁹ of the scene's
    /// size, or further where the corner is sharp and far from the origin.
    /// The point must stay on its side of the corner's other segment,
    /// `step · sin θ` away across an acute angle θ, by more than the
    /// rounding of its coordinates: a reflecting sliver (θ ~ 10⁻⁴) 10⁵
    /// from the origin had its nested paths start across the other face,
    /// and rendering and transport read half the derivative, "reliable"
    /// (seen in random scenes).
    #[inline]
    fn off_boundary(&self, b: &BoundaryPoint<DVec2>, p: u32) -> DVec2 {
        let segments = self.scene.segments();
        let seg = segments[p as usize];
        let along = (far_end(&seg, b.q) - b.q).normalize();
        let mut sin = 1.0f64;
        for s in self.corner_segments[b.index as usize] {
            if s != p && s != NO_SEGMENT {
                let next = (far_end(&segments[s as usize], b.q) - b.q).normalize();
                if along.dot(next) > 0.0 {
                    sin = sin.min(cross(along, next).abs());
                }
            }
        }
        let rounding = 16.0 * f64::EPSILON * b.q.abs().max_element();
        let step = (crate::path::tolerance::NUDGE * self.scene.size())
            .max(rounding / sin.max(f64::MIN_POSITIVE))
            .min(0.5 * seg.length());
        b.q + along * step
    }
}

/// The warp of flatland: linear in angle between the nearest visible
/// corners (or the lobe's horizons).
impl Warping for Plane {
    type Warp = FlatWarp;

    fn warp(
        &self,
        v: &Vertex<Self>,
        w: DVec2,
        ahead: Option<Option<Hit>>,
        _frame: SlotSet,
    ) -> FlatWarp {
        let horizons = v.lobe.horizons(w);
        let (ccw, cw) = if v.at_sensor {
            self.sensor_knots(w, horizons)
        } else {
            self.nearest_knots(v.x, v.skip, w, ahead, horizons)
        };
        FlatWarp { ccw, cw, horizons }
    }

    #[inline]
    fn warp_shapes(&self, warp: &FlatWarp, mut f: impl FnMut(u32)) {
        for k in [warp.ccw, warp.cw].into_iter().flatten() {
            f(k.2);
        }
    }

    // ANCHOR: warp_velocity
    #[inline]
    fn warp_velocity(
        &self,
        warp: &FlatWarp,
        _slot: usize,
        vertex: MovingVertex<DVec2>,
        w: DVec2,
        velocity: impl Fn(DVec2, u32) -> DVec2,
    ) -> (DVec2, f64) {
        let MovingVertex { x, u, spin } = vertex;
        // Knot values: a corner's angular velocity, or the frame's at a
        // horizon (which keeps the integrand's domain in place).
        let rate = |q: DVec2, k: u32| {
            let r = q - x;
            cross(r, velocity(q, k) - u) / r.length_squared()
        };
        let (db, vb) = match warp.ccw {
            Some((delta, q, k)) => (delta, rate(q, k)),
            None => (warp.horizons.0, spin),
        };
        let (da, va) = match warp.cw {
            Some((delta, q, k)) => (delta, rate(q, k)),
            None => (warp.horizons.1, spin),
        };
        let slope = (vb - va) / (da + db);
        (perp(w) * (va + slope * da), slope)
    }
    // ANCHOR_END: warp_velocity
}

impl Plane {
    /// The visible corners nearest to `w` counter-clockwise and clockwise,
    /// closer than the lobe's horizons `(h_ccw, h_cw)` radians: `(angle,
    /// corner, shape)` each. One pass orders the corners by a pseudo-angle
    /// (monotone in the angle, no trigonometry); only the winners get a
    /// shadow ray, and a hidden winner makes its side scan again past it.
    fn nearest_knots(
        &self,
        x: DVec2,
        skip: u32,
        w: DVec2,
        ahead: Option<Option<Hit>>,
        (h_ccw, h_cw): (f64, f64),
    ) -> (Option<Knot>, Option<Knot>) {
        let limit = |h: f64| {
            if h >= TAU {
                4.0
            } else {
                let (s, c) = h.sin_cos();
                pseudo_angle(c, s)
            }
        };
        let (lim_ccw, lim_cw) = (limit(h_ccw), limit(h_cw));
        if let Some(knots) = self.knots_in_triangles(x, skip, w, ahead, lim_ccw, lim_cw) {
            return knots;
        }
        self.scan_knots(x, skip, w, lim_ccw, lim_cw)
    }

    /// [`Self::nearest_knots`] by a scan of every corner (pseudo-angle
    /// limits).
    fn scan_knots(
        &self,
        x: DVec2,
        skip: u32,
        w: DVec2,
        lim_ccw: f64,
        lim_cw: f64,
    ) -> (Option<Knot>, Option<Knot>) {
        let scene = &*self.scene;
        let corners = scene.corners();
        let (mut bound_ccw, mut bound_cw) = (0.0, 0.0);
        let (mut done_ccw, mut done_cw) = (false, false);
        let (mut ccw, mut cw) = (None, None);
        while !(done_ccw && done_cw) {
            let (mut best_ccw, mut best_cw) = (lim_ccw, lim_cw);
            let (mut i_ccw, mut i_cw) = (usize::MAX, usize::MAX);
            for (i, &(q, _)) in corners.iter().enumerate() {
                let r = q - x;
                let p = pseudo_angle(w.dot(r), cross(w, r));
                if !done_ccw && p > bound_ccw && p < best_ccw {
                    best_ccw = p;
                    i_ccw = i;
                }
                let pc = 4.0 - p;
                if !done_cw && pc > bound_cw && pc < best_cw {
                    best_cw = pc;
                    i_cw = i;
                }
            }
            // A side is settled when its nearest candidate is visible or it
            // has none; a hidden one moves that side's bound past it.
            let settle = |done: &mut bool, i: usize, best: f64, bound: &mut f64| {
                if *done {
                    return None;
                }
                if i == usize::MAX {
                    *done = true;
                    None
                } else if scene.sees_corner(x, i, skip) {
                    *done = true;
                    Some(i)
                } else {
                    *bound = best;
                    None
                }
            };
            ccw = ccw.or(settle(&mut done_ccw, i_ccw, best_ccw, &mut bound_ccw));
            cw = cw.or(settle(&mut done_cw, i_cw, best_cw, &mut bound_cw));
        }
        let knot = |i: Option<usize>, ccw: bool| i.map(|i| knot(x, w, corners[i], ccw));
        (knot(ccw, true), knot(cw, false))
    }

    /// [`Self::nearest_knots`] through the corner tree: the nearest visible
    /// corner on each side is the hit segment's end there or the
    /// smallest-angle corner inside the triangle (vertex, hit point, end);
    /// the module `corners` proves it. `None` (use the scan) without a tree
    /// or when the direction hits nothing opaque.
    fn knots_in_triangles(
        &self,
        x: DVec2,
        skip: u32,
        w: DVec2,
        ahead: Option<Option<Hit>>,
        lim_ccw: f64,
        lim_cw: f64,
    ) -> Option<(Option<Knot>, Option<Knot>)> {
        let scene = &*self.scene;
        let tree = scene.corner_tree()?;
        // The first opaque segment along w: the caller's hit when it is one
        // (the opaque caster's answer is the same segment at the same t).
        let first = match ahead {
            Some(None) => None,
            Some(Some(h)) if scene.shape_of(h.prim).surface.is_opaque() => {
                Some((h.t, scene.segments()[h.prim as usize], scene.owner(h.prim)))
            }
            _ => scene.opaque_hit(x, w, skip),
        };
        let Some((t, seg, k_hit)) = first else {
            return Some(self.knots_escaping(tree, x, w, lim_ccw, lim_cw));
        };
        let p = x + t * w;
        let (sa, sb) = (cross(w, seg.a - x), cross(w, seg.b - x));
        let (e_ccw, e_cw) = if sa > 0.0 && sb < 0.0 {
            (seg.a, seg.b)
        } else if sb > 0.0 && sa < 0.0 {
            (seg.b, seg.a)
        } else {
            return None; // the ray grazes an end: let the scan decide
        };
        let corners = scene.corners();
        let angle = |q: DVec2, ccw: bool| {
            let r = q - x;
            let pa = pseudo_angle(w.dot(r), cross(w, r));
            if ccw { pa } else { 4.0 - pa }
        };
        // Per side (ccw, cw): its triangle's far end, its limit, and the
        // best corner so far (the segment's end, if within the limit).
        let mut sides = [(e_ccw, lim_ccw, true), (e_cw, lim_cw, false)].map(|(e, lim, ccw)| {
            let pe = angle(e, ccw);
            (e, lim, ccw, (pe < lim).then_some((pe, e, k_hit)))
        });
        // One search over both triangles: together they make (x, e_ccw, e_cw).
        tree.near_triangle(x, e_ccw, e_cw, |i| {
            let (q, k) = corners[i as usize];
            for (e, lim, ccw, best) in &mut sides {
                let pq = angle(q, *ccw);
                if pq < *lim && best.is_none_or(|b| pq < b.0) && super::corners::inside(x, p, *e, q)
                {
                    *best = Some((pq, q, k));
                }
            }
        });
        let [ccw, cw] =
            sides.map(|(_, _, ccw, best)| best.map(|(_, q, k)| knot(x, w, (q, k), ccw)));
        Some((ccw, cw))
    }

    /// The nearest visible corners on either side of a direction that hits
    /// nothing opaque: the same triangle argument with the edges of a box
    /// around the scene (and `x`) in the place of the hit segment. The ray
    /// leaves the box at `p` on an edge no segment crosses; if no corner
    /// lies inside the triangle (`x`, `p`, the edge's end `e`), no segment
    /// enters it (it could cross only `x e`, and at most once), so the sight
    /// line to `e` is clear and the search goes on in (`x`, `e`, next box
    /// corner), around the box up to the lobe's horizon.
    fn knots_escaping(
        &self,
        tree: &super::corners::CornerTree,
        x: DVec2,
        w: DVec2,
        lim_ccw: f64,
        lim_cw: f64,
    ) -> (Option<Knot>, Option<Knot>) {
        let (lo, hi) = tree.bounds();
        let margin = 0.01 * (hi - lo).max_element().max(f64::MIN_POSITIVE);
        let (lo, hi) = (lo.min(x) - margin, hi.max(x) + margin);
        // Box corners counter-clockwise; the exit edge i runs box[i] → box[i+1].
        let boxc = [lo, DVec2::new(hi.x, lo.y), hi, DVec2::new(lo.x, hi.y)];
        let mut exit = (f64::INFINITY, 0usize);
        for i in 0..4 {
            let (a, b) = (boxc[i], boxc[(i + 1) % 4]);
            let e = b - a;
            let denom = cross(w, e);
            if denom == 0.0 {
                continue;
            }
            let t = cross(a - x, e) / denom;
            let s = cross(a - x, w) / denom;
            if t > 0.0 && (0.0..=1.0).contains(&s) && t < exit.0 {
                exit = (t, i);
            }
        }
        let p = x + exit.0 * w;
        let corners = self.scene.corners();
        let side = |lim: f64, ccw: bool| -> Option<Knot> {
            let angle = |q: DVec2| {
                let r = q - x;
                let pa = pseudo_angle(w.dot(r), cross(w, r));
                if ccw { pa } else { 4.0 - pa }
            };
            let mut from = p;
            // Around the box and back to p: five triangles cover the circle.
            for step in 0..5 {
                let i = exit.1;
                let e = match (step, ccw) {
                    (4, _) => p,
                    (_, true) => boxc[(i + 1 + step) % 4],
                    (_, false) => boxc[(i + 4 - step) % 4],
                };
                let mut best: Option<(f64, DVec2, u32)> = None;
                tree.near_triangle(x, from, e, |c| {
                    let (q, k) = corners[c as usize];
                    let pq = angle(q);
                    if pq < lim
                        && best.is_none_or(|b| pq < b.0)
                        && super::corners::inside(x, from, e, q)
                    {
                        best = Some((pq, q, k));
                    }
                });
                if let Some((_, q, k)) = best {
                    return Some(knot(x, w, (q, k), ccw));
                }
                if angle(e) >= lim {
                    return None;
                }
                from = e;
            }
            None
        };
        (side(lim_ccw, true), side(lim_cw, false))
    }

    /// The neighbours of `w` among the sensor's knots (precomputed: the
    /// sensor does not move).
    fn sensor_knots(&self, w: DVec2, (h_ccw, h_cw): (f64, f64)) -> (Option<Knot>, Option<Knot>) {
        let knots = self.sensor_knot_list();
        if knots.is_empty() {
            return (None, None);
        }
        let phi = w.y.atan2(w.x);
        let i = knots.partition_point(|k| k.0 <= phi);
        let (b, b_angle) = if i < knots.len() {
            (knots[i], knots[i].0 - phi)
        } else {
            (knots[0], knots[0].0 + TAU - phi)
        };
        let (a, a_angle) = if i > 0 {
            (knots[i - 1], phi - knots[i - 1].0)
        } else {
            (knots[knots.len() - 1], phi - knots[knots.len() - 1].0 + TAU)
        };
        (
            (b_angle < h_ccw).then_some((b_angle, b.1, b.2)),
            (a_angle < h_cw && a_angle > 0.0).then_some((a_angle, a.1, a.2)),
        )
    }
}

/// The end of `seg` that is not its corner `q`.
#[inline]
fn far_end(seg: &super::geometry::Segment, q: DVec2) -> DVec2 {
    if (seg.a - q).length_squared() < (seg.b - q).length_squared() {
        seg.b
    } else {
        seg.a
    }
}

/// The knot at corner `(q, k)` seen from `x`: its angle from `w`
/// counter-clockwise (`ccw`) or clockwise, in `(0, 2π]`.
#[inline]
fn knot(x: DVec2, w: DVec2, (q, k): (DVec2, u32), ccw: bool) -> Knot {
    let r = q - x;
    let sign = if ccw { 1.0 } else { -1.0 };
    let mut a = sign * cross(w, r).atan2(w.dot(r));
    if a <= 0.0 {
        a += TAU;
    }
    (a, q, k)
}

#[cfg(test)]
mod tests;
