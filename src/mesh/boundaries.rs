//! 3D discontinuities behind the path core's [`Boundaries`]: the edges of
//! opaque meshes. Seen from a point `x`, an edge projects to an arc on the
//! sphere of directions across which the integrand can jump: a silhouette
//! (one side sees a face, the other sees past it), an open edge, or a
//! crease (each side sees another face: a jump for a reflector only).
//!
//! The boundary term of the directional integral is a line integral along
//! those arcs, `∮ f (L_behind − L_ahead) v_n dl`. An edge is drawn from the
//! edge hierarchy ([`super::edges`]: by weight, length × dihedral turn / π,
//! among the edges that can be discontinuities from `x`), a point in angle
//! along its arc (the same uniform number, rescaled): half the time
//! uniformly, half the time on the parts of the arc behind which a lamp
//! lies; the inverse of the mixture's density per unit arc length goes into
//! the boundary point, so the path core's corner term
//! (`rendering::corner_jump`) is, unchanged, the edge term.
//! Book: chapter "Three dimensions", section "Silhouette edges".
use super::lobe::SpaceLobe;
use super::space::Space;
use super::warp::SpaceWarp;
use crate::path::walk::Vertex;
use crate::path::{Boundaries, BoundaryPoint, NO_PRIM, Prim, Side};
use glam::DVec3;

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

/// Most emitter triangles for which the edge points are also drawn where a
/// lamp lies behind them (a test per emitter triangle per draw).
const LAMP_TRIANGLES: usize = 16;

impl Space {
    /// The parts of an edge's arc seen from `x` (in the plane of unit normal
    /// `n`, angles `α ∈ [0, arc]` from `wa` toward `t`) behind which an
    /// emitter triangle lies: per triangle, the angles of the segment where
    /// the plane cuts it, clipped to the arc. `None` without such parts, or
    /// with more than [`LAMP_TRIANGLES`] emitter triangles.
    #[allow(clippy::type_complexity)]
    fn lamp_intervals(
        &self,
        x: DVec3,
        n: DVec3,
        wa: DVec3,
        t: DVec3,
        arc: f64,
    ) -> Option<([(f64, f64); LAMP_TRIANGLES], usize, f64)> {
        if self.emitters.is_empty() || self.emitters.len() > LAMP_TRIANGLES {
            return None;
        }
        let mut out = [(0.0, 0.0); LAMP_TRIANGLES];
        let (mut count, mut total) = (0, 0.0);
        for &(prim, _) in &self.emitters {
            let tri = self.tris[prim as usize];
            let h = tri.map(|v| (v - x).dot(n));
            // Where the plane cuts the triangle's sides.
            let mut angles = [0.0f64; 2];
            let mut k = 0;
            for i in 0..3 {
                let (a, b) = (i, (i + 1) % 3);
                if (h[a] > 0.0) != (h[b] > 0.0) && k < 2 {
                    let s = h[a] / (h[a] - h[b]);
                    let r = tri[a] + (tri[b] - tri[a]) * s - x;
                    angles[k] = r.dot(t).atan2(r.dot(wa));
                    k += 1;
                }
            }
            if k < 2 {
                continue;
            }
            let (lo, hi) = (
                angles[0].min(angles[1]).max(0.0),
                angles[0].max(angles[1]).min(arc),
            );
            if hi > lo {
                out[count] = (lo, hi);
                count += 1;
                total += hi - lo;
            }
        }
        (count > 0 && total > 0.0).then_some((out, count, total))
    }

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
}

impl Boundaries for Space {
    // ANCHOR: sample_boundary
    /// An edge drawn from the edge hierarchy (by weight among those that
    /// can be discontinuities seen from `x`), a point along its arc (uniform
    /// in angle, or on the parts with a lamp behind: a mixture of the two);
    /// `inv_pdf` is per unit arc length on the sphere seen from `x`.
    #[inline]
    fn sample_boundary(&self, v: &Vertex<Self>, all: bool, u: f64) -> Option<BoundaryPoint<DVec3>> {
        if let SpaceLobe::Pixel { rect, pixel, .. } = v.lobe {
            // The camera stands still: only moving edges move across a
            // pixel (`all` cannot be set there).
            debug_assert!(!all, "a camera does not move");
            return self.pixel_boundary(v.x, pixel, &rect, u);
        }
        let x = v.x;
        let tree = if all {
            &self.edge_tables().all_edges
        } else {
            &self.edge_tables().moving_edges
        };
        let (index, p, along) = tree.sample(
            x,
            u,
            &self.edge_tables().edges,
            &self.edge_tables().edge_facts,
            &self.edge_tables().edge_weight,
        )?;
        let edge = &self.edge_tables().edges[index as usize];
        // The point: uniform in angle along the edge's arc seen from x, so
        // a long edge is sampled where it subtends the most (uniform in
        // length, its far parts would be drawn as often as its near ones
        // for a vanishing share of the arc).
        let (ra, rb) = (edge.a - x, edge.b - x);
        let n = ra.cross(rb);
        let (sin_g, cos_g) = (n.length(), ra.dot(rb));
        let arc = sin_g.atan2(cos_g);
        if arc.is_nan() || arc <= 0.0 || sin_g == 0.0 {
            return None; // seen end-on: no arc
        }
        let n = n / sin_g;
        let wa = ra.normalize();
        let t = n.cross(wa);
        // Half the draws uniform in angle, half on the parts of the arc
        // behind which a lamp lies (where the jump carries direct light):
        // the density is the mixture's, whichever strategy drew the point.
        let lamps = self.lamp_intervals(x, n, wa, t, arc);
        let (alpha, density) = match lamps {
            None => (along * arc, 1.0 / arc),
            Some((ref intervals, count, total)) => {
                let alpha = if along < 0.5 {
                    2.0 * along * arc
                } else {
                    let mut left = (2.0 * along - 1.0) * total;
                    let mut pick = intervals[count - 1];
                    for iv in &intervals[..count] {
                        let len = iv.1 - iv.0;
                        if left < len {
                            pick = *iv;
                            break;
                        }
                        left -= len;
                    }
                    (pick.0 + left.min(pick.1 - pick.0)).clamp(0.0, arc)
                };
                let inside = intervals[..count]
                    .iter()
                    .filter(|iv| iv.0 <= alpha && alpha <= iv.1)
                    .count() as f64;
                (alpha, 0.5 / arc + 0.5 * inside / total)
            }
        };
        let (s, c) = alpha.sin_cos();
        let w = wa * c + t * s;
        // Where the ray along w meets the edge's line, in the plane (x, a, b).
        let d = edge.b - edge.a;
        let tau = (-(ra.cross(w).dot(n)) / d.cross(w).dot(n)).clamp(0.0, 1.0);
        let q = edge.a + d * tau;
        if !q.is_finite() {
            return None;
        }
        Some(BoundaryPoint {
            q,
            shape: edge.shape,
            index,
            inv_pdf: 1.0 / (p * density),
        })
    }
    // ANCHOR_END: sample_boundary

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
        let (mut ahead, mut behind) = ((f64::INFINITY, Side::Past), (f64::INFINITY, Side::Past));
        for p in self.edge_tables().edges[e].faces {
            if p == NO_PRIM {
                continue;
            }
            let d = self.face_inward(e, p);
            let c = d.dot(n);
            if c == 0.0 {
                continue; // seen edge-on: a grazing ray sees none of it
            }
            let order = d.dot(w) / c.abs();
            let side = if c > 0.0 { &mut ahead } else { &mut behind };
            if order < side.0 {
                *side = (order, Side::Surface(p));
            }
        }
        (ahead.1, behind.1)
    }
    // ANCHOR_END: sides

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
        b.q + d * (1e-9 * self.scene.size())
    }

    /// The fibre warp of [`super::warp`].
    type Warp = SpaceWarp;

    fn warp(&self, v: &Vertex<Self>, w: DVec3) -> SpaceWarp {
        self.fibre_warp(v, w)
    }

    fn warp_shapes(&self, warp: &SpaceWarp, f: impl FnMut(u32)) {
        self.fibre_shapes(warp, f)
    }

    fn warp_velocity(
        &self,
        warp: &SpaceWarp,
        slot: usize,
        x: DVec3,
        w: DVec3,
        u: DVec3,
        spin: DVec3,
        velocity: impl Fn(DVec3, u32) -> DVec3,
    ) -> (DVec3, f64) {
        self.fibre_velocity(warp, slot, x, w, u, spin, velocity)
    }
}
