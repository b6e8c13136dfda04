//! 3D discontinuities behind the path core's [`Boundaries`]: the edges of
//! opaque meshes. Seen from a point `x`, an edge projects to an arc on the
//! sphere of directions across which the integrand can jump: a silhouette
//! (one side sees a face, the other sees past it), an open edge, or a
//! crease (each side sees another face: a jump for a reflector only).
//!
//! The boundary term of the directional integral is a line integral along
//! those arcs, `∮ f (L_behind − L_ahead) v_n dl`, split into parts that
//! are each covered once (`Space::edge_points`):
//!
//! - the lamps' edges (when the emitting meshes have at most `LAMP_SET`
//!   (16) and the other meshes at most `LAMP_EDGES` (64)): each taken
//!   every time, `SET_POINTS` (2) points per edge,
//!   stratified (`Space::lamp_edge_points`). A vertex that moves sees the
//!   lamp's outline move, and the jump there is the lamp's whole radiance:
//!   the terms of opposite edges are large and nearly cancel (a point
//!   turning with a rotating cube sees the whole outline turn), so drawing
//!   one edge among all left their sum's variance, most of the image's
//!   for the showcase's rotation;
//! - the parts of each silhouette's arc behind which a lamp lies (when the
//!   tree holds at most `LAMP_EDGES` (64) edges): each taken every time,
//!   `SET_POINTS` points uniform on them, stratified. Where the jump
//!   carries direct light (a floor point in a penumbra), one or two edges
//!   carry most of the term, often with opposite signs;
//! - the rest: one point drawn, an edge from the hierarchy of the other
//!   edges ([`super::edges`]: by weight, length × dihedral turn / π, over
//!   distance, among those that can be discontinuities from `x`), then a
//!   point uniform in angle on its arc but the lamp parts taken above
//!   (over a larger tree: half the time uniform on the arc, half on its
//!   lamp parts, the density the mixture's).
//!
//! Which edges: all of them for a slot whose vertex or frame moves, a
//! parameter's own mesh's otherwise. When both kinds of slot, or the
//! parameters of several meshes, meet at a vertex, the edges are split
//! into strata (one per such mesh, and the rest): every stratum's points
//! taken every time are taken, and the one drawn point comes from a
//! stratum drawn in proportion to the slots it serves
//! (`Space::edge_strata`).
//!
//! Each point's `inv_pdf` is the inverse of its density per unit arc
//! length (a point taken every time: of its position alone), so the path
//! core's corner term (`corner_jump`, `path/rendering.rs`) is, unchanged, the edge
//! term, and the sum over the points is unbiased.
//! Book: chapter "Three dimensions", section "Silhouette edges".
use super::edges::{EdgeTree, is_discontinuity};
use super::lobe::SpaceLobe;
use super::space::Space;
use crate::path::walk::Vertex;
use crate::path::{Boundaries, BoundaryPoint, BoundaryView, NO_PRIM, Prim, Side, nearest_sides};
use crate::rng::PathRng;
use glam::DVec3;
use rand::RngExt;

mod lamp_parts;
mod strata;

use super::edge_sampler::LAMP_EDGES;
use lamp_parts::{EdgeArc, LAMP_TRIANGLES};
use strata::{Strata, Stratum};

impl Space {
    /// The unit vector in the plane of face `p`, perpendicular to the edge
    /// `e`, pointing from the edge into the face.
    #[inline]
    fn face_inward(&self, e: usize, p: Prim) -> DVec3 {
        let edge = &self.edge_tables().edges[e];
        let t = &self.tris[p as usize];
        let along = (edge.b - edge.a).normalize();
        // The face's vertex off the edge: the one farthest from its line.
        let off = t
            .iter()
            .map(|&c| {
                let r = c - edge.a;
                r - along * r.dot(along)
            })
            .max_by(|u, v| u.length_squared().total_cmp(&v.length_squared()))
            .unwrap_or(DVec3::ZERO);
        off.normalize_or_zero()
    }
}

/// Points on each lamp edge and on each silhouette's lamp parts (those
/// taken every time), stratified in the fraction of the edge or parts: on
/// showcase_nofog at 64 spp, 2 instead of 1 cut cube_rot's sum over the
/// pixels of the standard errors by 19 % (cube_x's by 1 %) for 15 % more
/// time per path; 4 cut it further but cost more than they saved.
const SET_POINTS: usize = 2;

/// The fractions `(i + u) / SET_POINTS`, `i < SET_POINTS`.
#[inline]
fn stratified(u: f64) -> impl Iterator<Item = f64> {
    (0..SET_POINTS).map(move |i| ((i as f64 + u) / SET_POINTS as f64).min(1.0 - f64::EPSILON))
}

impl Space {
    /// A point on the moving edges seen through the footprint `rect` of
    /// camera pixel `pixel` from the pinhole `x`: uniform in image-plane
    /// length, `inv_pdf` per unit arc length on the sphere (the image
    /// plane's length `L` over the pieces, times the arc's rate
    /// `|T − η(η·T)| / |ξ|` per unit image length along the piece's
    /// direction `T`).
    fn pixel_boundary(
        &self,
        x: DVec3,
        pixel: u32,
        rect: &[f64; 4],
        u: f64,
    ) -> Option<BoundaryPoint<DVec3>> {
        let cam = self.camera.as_ref()?;
        let (index, p, dir, total) = self.pixel_edges().sample(pixel, rect, u)?;
        let xi = cam.f + cam.r * p[0] + cam.u * p[1];
        let len = xi.length();
        let w = xi / len;
        let t = cam.r * dir[0] + cam.u * dir[1];
        let rate = (t - w * w.dot(t)).length() / len;
        let edge = &self.edge_tables().edges[index as usize];
        let (ra, d) = (edge.a - x, edge.b - edge.a);
        let n = ra.cross(edge.b - x);
        let tau = (-(ra.cross(w).dot(n)) / d.cross(w).dot(n)).clamp(0.0, 1.0);
        let q = edge.a + d * tau;
        if !q.is_finite() || rate.is_nan() || rate <= 0.0 {
            return None;
        }
        Some(BoundaryPoint {
            q,
            shape: edge.shape,
            index,
            inv_pdf: total * rate,
        })
    }

    // ANCHOR: edge_point
    /// The boundary points of the directional integral at `x` over the
    /// edges of `stratum`, each with `inv_pdf` per unit arc length on the
    /// sphere, passed to `f`:
    ///
    /// - with `draw = (u_draw, share)`, one drawn from the tree of the
    ///   edges but the lamps' ([`Space::drawn_point`]), its density times
    ///   `share` (the probability the stratum's point is drawn at all);
    /// - when the tree holds at most [`LAMP_EDGES`] edges, [`SET_POINTS`]
    ///   on the lamp parts of each silhouette that has a lamp behind part
    ///   of its arc (uniform on them, stratified by `u_set`), the drawn
    ///   point then avoiding those parts;
    /// - [`SET_POINTS`] on each lamp edge ([`Space::lamp_edge_points`],
    ///   stratified by `u_set`).
    ///
    /// Every point of every discontinuity is covered by exactly one of
    /// these, with the density reported: the sum is unbiased. Only the
    /// edges of meshes `keep` holds give points (the others are left
    /// before any work on their lamp parts).
    #[inline]
    fn edge_points(
        &self,
        x: DVec3,
        stratum: Stratum,
        draw: Option<(f64, f64)>,
        u_set: f64,
        keep: impl Fn(u32) -> bool,
        mut f: impl FnMut(BoundaryPoint<DVec3>),
    ) {
        let tables = self.edge_tables();
        let (tree, apart, overlap, lamp_total) = self.drawn_tree(x, stratum);
        let ids = tree.edges();
        if let Some((u_draw, share)) = draw
            && let Some(b) = self.drawn_point(x, tree, apart.then_some(&overlap), u_draw)
            && keep(b.shape)
        {
            let inv_pdf = b.inv_pdf / share;
            f(BoundaryPoint { inv_pdf, ..b });
        }
        if lamp_total > 0.0 {
            for (k, &o) in overlap[..ids.len()].iter().enumerate() {
                if o <= 0.0 {
                    continue;
                }
                let index = ids[k];
                let edge = &tables.edges[index as usize];
                if !keep(edge.shape) {
                    continue;
                }
                let Some(arc) = EdgeArc::new(edge, x) else {
                    continue;
                };
                let Some(lamps) = self.lamp_intervals(x, &arc) else {
                    continue;
                };
                for u in stratified(u_set) {
                    let alpha = lamps.pick(u, arc.arc);
                    let cover = lamps.cover(alpha);
                    let q = arc.point(edge, alpha);
                    if cover > 0.0 && q.is_finite() {
                        f(BoundaryPoint {
                            q,
                            shape: edge.shape,
                            index,
                            inv_pdf: lamps.total / cover / SET_POINTS as f64,
                        });
                    }
                }
            }
        }
        for u in stratified(u_set) {
            self.lamp_edge_points(x, stratum, u, &keep, |b| {
                f(BoundaryPoint {
                    inv_pdf: b.inv_pdf / SET_POINTS as f64,
                    ..b
                })
            });
        }
    }

    /// The tree the point is drawn from at `x` (all edges but the lamp
    /// set's if `all`, else the moving ones), whether the lamp parts of
    /// its silhouettes are taken apart (it holds at most [`LAMP_EDGES`]
    /// edges and the lamps at most [`LAMP_TRIANGLES`] triangles), and if
    /// so the edges' [`Space::lamp_overlaps`].
    #[inline]
    #[allow(clippy::type_complexity)]
    fn drawn_tree(&self, x: DVec3, stratum: Stratum) -> (&EdgeTree, bool, [f64; LAMP_EDGES], f64) {
        let tables = self.edge_tables();
        let (tree, cache) = match stratum {
            Stratum::All => (&tables.all_drawn, &self.sampler.sensor_lamps[1]),
            Stratum::Moving => (&tables.moving_drawn, &self.sampler.sensor_lamps[0]),
            Stratum::Shape(k) => (
                &tables.shape_drawn[k as usize],
                &self.sampler.sensor_shape_lamps[k as usize],
            ),
        };
        let apart = tree.edges().len() <= LAMP_EDGES
            && !self.emitters.is_empty()
            && self.emitters.len() <= LAMP_TRIANGLES;
        // At the sensor's point (a probe's every path starts there) the
        // lamp parts are found once per tree.
        let (overlap, total) = if !apart {
            ([0.0; LAMP_EDGES], 0.0)
        } else if x == self.scene.sensor().point() {
            *cache.get_or_init(|| self.lamp_overlaps(x, tree))
        } else {
            self.lamp_overlaps(x, tree)
        };
        (tree, apart, overlap, total)
    }

    /// A point drawn on the edges of `tree` that can be discontinuities
    /// seen from `x`: an edge from the hierarchy, then a point along its
    /// arc. With `overlap` (per edge of the tree, > 0 where its lamp parts
    /// are taken apart), uniform in angle on the arc but those parts;
    /// without, half the time uniform in angle and half on the lamp parts.
    /// `inv_pdf` per unit arc length.
    #[inline]
    fn drawn_point(
        &self,
        x: DVec3,
        tree: &EdgeTree,
        overlap: Option<&[f64; LAMP_EDGES]>,
        u: f64,
    ) -> Option<BoundaryPoint<DVec3>> {
        let tables = self.edge_tables();
        let (edges, facts, weights) = (&tables.edges, &tables.edge_facts, &tables.edge_weight);
        let (index, p_tree, along) = tree.sample(x, u, edges, facts, weights)?;
        let edge = &edges[index as usize];
        let arc = EdgeArc::new(edge, x)?;
        let (alpha, density) = match overlap {
            Some(o) => {
                let apart = tree.place(index).is_some_and(|k| o[k] > 0.0);
                match (apart, self.lamp_intervals(x, &arc)) {
                    (true, Some(l)) => {
                        let (alpha, outside) = l.pick_outside(along, arc.arc)?;
                        (alpha, p_tree / outside)
                    }
                    _ => (along * arc.arc, p_tree / arc.arc),
                }
            }
            None => match self.lamp_intervals(x, &arc) {
                Some(l) if along >= 0.5 => {
                    let alpha = l.pick(2.0 * along - 1.0, arc.arc);
                    (
                        alpha,
                        p_tree * (0.5 / arc.arc + 0.5 * l.cover(alpha) / l.total),
                    )
                }
                Some(l) => {
                    let alpha = 2.0 * along * arc.arc;
                    (
                        alpha,
                        p_tree * (0.5 / arc.arc + 0.5 * l.cover(alpha) / l.total),
                    )
                }
                None => (along * arc.arc, p_tree / arc.arc),
            },
        };
        let q = arc.point(edge, alpha);
        if !q.is_finite() || density.is_nan() || density <= 0.0 {
            return None;
        }
        Some(BoundaryPoint {
            q,
            shape: edge.shape,
            index,
            inv_pdf: 1.0 / density,
        })
    }
    // ANCHOR_END: edge_point

    /// Calls `f` with one point on each lamp edge (of the lamp set,
    /// [`EdgeTables::lamp_set`](super::space::EdgeTables)) that can be a
    /// discontinuity seen from `x` (all of them for `Stratum::All`, else
    /// the moving lamps', for `Stratum::Shape(k)` mesh `k`'s; only of the
    /// meshes `keep` holds), every point at the same fraction `u` of its
    /// edge's arc in
    /// angle: density `1/arc` per unit arc length, each edge taken with
    /// probability 1. [`Space::edge_point`] draws among the other edges.
    #[inline]
    fn lamp_edge_points(
        &self,
        x: DVec3,
        stratum: Stratum,
        u: f64,
        keep: impl Fn(u32) -> bool,
        mut f: impl FnMut(BoundaryPoint<DVec3>),
    ) {
        let tables = self.edge_tables();
        let set = &tables.lamp_set[(stratum == Stratum::All) as usize];
        for &e in set {
            let edge = &tables.edges[e as usize];
            if matches!(stratum, Stratum::Shape(k) if edge.shape != k) || !keep(edge.shape) {
                continue;
            }
            if !is_discontinuity(edge, &tables.edge_facts[e as usize], x) {
                continue;
            }
            let Some(arc) = EdgeArc::new(edge, x) else {
                continue;
            };
            let q = arc.point(edge, u * arc.arc);
            if q.is_finite() {
                f(BoundaryPoint {
                    q,
                    shape: edge.shape,
                    index: e,
                    inv_pdf: arc.arc,
                });
            }
        }
    }
}

/// Points drawn per path at a camera pixel (stratified), and pairs of
/// nested paths per jump there ([`Boundaries::jump_paths`]). The pixels a
/// moving silhouette crosses are few, so more evaluations there cost little
/// overall; at one point and one pair, about half of the term's variance
/// was the point's and half the jump's. On showcase_nofog at 64 spp, 1
/// point with 4 pairs cut the sum over the pixels of the standard errors
/// by 19 % (cube_x) and 16 % (cube_rot) for about 10 % more time; 2 points
/// with 2 pairs each, at the same cost, by a further 18 % and 12 %.
const CAMERA_POINTS: usize = 2;
/// See [`CAMERA_POINTS`].
const CAMERA_JUMP_PATHS: u32 = 2;

impl Boundaries for Space {
    // ANCHOR: sample_boundary
    /// At a camera pixel, a point on the moving edges seen through it;
    /// elsewhere the point drawn among the edges seen from the vertex (all
    /// of them if some slot of `view` sees all move, else the moving
    /// meshes'), without the ones [`Boundaries::boundary_points`] takes
    /// every time (`Space::edge_points`); `inv_pdf` is per unit arc length
    /// on the sphere of directions. ([`Boundaries::boundary_points`]
    /// splits the edges among the slots: `Space::edge_strata`.)
    #[inline]
    fn sample_boundary(
        &self,
        v: &Vertex<Self>,
        view: &BoundaryView,
        u: f64,
    ) -> Option<BoundaryPoint<DVec3>> {
        let all = view.sees_all();
        if let SpaceLobe::Pixel { rect, pixel, .. } = v.lobe {
            // The camera stands still: only moving edges move across a
            // pixel (`all` cannot be set there).
            debug_assert!(!all, "a camera does not move");
            return self.pixel_boundary(v.x, pixel, &rect, u);
        }
        let stratum = if all { Stratum::All } else { Stratum::Moving };
        let (tree, apart, overlap, _) = self.drawn_tree(v.x, stratum);
        self.drawn_point(v.x, tree, apart.then_some(&overlap), u)
    }
    // ANCHOR_END: sample_boundary

    /// At a camera pixel, `CAMERA_POINTS` points drawn, stratified
    /// (`Space::pixel_boundary`); elsewhere all of `Space::edge_points`.
    #[inline]
    fn boundary_points(
        &self,
        v: &Vertex<Self>,
        view: &BoundaryView,
        rng: &mut PathRng,
        mut f: impl FnMut(&mut PathRng, BoundaryPoint<DVec3>),
    ) {
        let all = view.sees_all();
        if let SpaceLobe::Pixel { rect, pixel, .. } = v.lobe {
            debug_assert!(!all, "a camera does not move");
            let u: f64 = rng.random();
            for i in 0..CAMERA_POINTS {
                let ui = ((i as f64 + u) / CAMERA_POINTS as f64).min(1.0 - f64::EPSILON);
                if let Some(b) = self.pixel_boundary(v.x, pixel, &rect, ui) {
                    f(
                        rng,
                        BoundaryPoint {
                            inv_pdf: b.inv_pdf / CAMERA_POINTS as f64,
                            ..b
                        },
                    );
                }
            }
            return;
        }
        let (u_draw, u_set): (f64, f64) = (rng.random(), rng.random());
        match self.edge_strata(view) {
            Strata::None => {}
            Strata::One(stratum) => self.edge_points(
                v.x,
                stratum,
                Some((u_draw, 1.0)),
                u_set,
                |_| true,
                |b| f(rng, b),
            ),
            Strata::Mixed { n_all } => {
                let u_pick: f64 = rng.random();
                self.split_points(v.x, view, n_all, [u_draw, u_set, u_pick], |b| f(rng, b));
            }
        }
    }

    /// `CAMERA_JUMP_PATHS` at a camera pixel, else 1.
    #[inline]
    fn jump_paths(&self, v: &Vertex<Self>) -> u32 {
        if matches!(v.lobe, SpaceLobe::Pixel { .. }) {
            CAMERA_JUMP_PATHS
        } else {
            1
        }
    }

    // ANCHOR: sides
    /// The faces at the edge on either side of the sight line `η` from `x`:
    /// face `i` lies on the side its inward direction `d_i` (in its plane,
    /// perpendicular to the edge) points to across the line, `sign(d_i·n)`
    /// for the arc's normal `n`; on each side the ray just past the line
    /// meets the face with the least `(d_i·η)/|d_i·n|` first, or none.
    fn sides(&self, x: DVec3, b: &BoundaryPoint<DVec3>) -> (Side, Side) {
        let w = (b.q - x).normalize();
        let n = self.boundary_normal(x, b);
        let e = b.index as usize;
        let at_edge = self.edge_tables().edges[e]
            .faces
            .into_iter()
            .filter(|&p| p != NO_PRIM)
            .map(|p| {
                let d = self.face_inward(e, p);
                (p, d, d.dot(n))
            });
        nearest_sides(w, at_edge)
    }
    // ANCHOR_END: sides
    #[inline]
    fn holds(&self, b: &BoundaryPoint<DVec3>, p: Prim) -> bool {
        self.edge_tables().edges[b.index as usize]
            .faces
            .contains(&p)
    }

    /// `η × ê / |η × ê|`: normal to the edge's arc on the sphere at `η`.
    #[inline]
    fn boundary_normal(&self, x: DVec3, b: &BoundaryPoint<DVec3>) -> DVec3 {
        let edge = &self.edge_tables().edges[b.index as usize];
        let w = (b.q - x).normalize();
        w.cross(edge.b - edge.a).normalize_or_zero()
    }

    #[inline]
    fn off_boundary(&self, b: &BoundaryPoint<DVec3>, p: Prim) -> DVec3 {
        let d = self.face_inward(b.index as usize, p);
        b.q + d * crate::path::Geometry::nudge(self, b.q)
    }
}

#[cfg(test)]
mod tests;
