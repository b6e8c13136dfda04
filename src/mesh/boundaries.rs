//! 3D discontinuities behind the path core's [`Boundaries`]: the edges of
//! opaque meshes. Seen from a point `x`, an edge projects to an arc on the
//! sphere of directions across which the integrand can jump: a silhouette
//! (one side sees a face, the other sees past it), an open edge, or a
//! crease (each side sees another face: a jump for a reflector only).
//!
//! The boundary term of the directional integral is a line integral along
//! those arcs, `∮ f (L_behind − L_ahead) v_n dl`. An edge is drawn from the
//! edge hierarchy ([`super::edges`]: by weight, length × dihedral turn / π,
//! among the edges that can be discontinuities from `x`), a point uniformly
//! in angle along its arc (the same uniform number, rescaled), and the
//! inverse density per unit arc length, `Γ / p(e)` for an arc of angle `Γ`,
//! goes into the boundary point, so the path core's corner term
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

impl Space {
    /// A point on the moving edges seen through the footprint `rect` of
    /// camera pixel `pixel` from the pinhole `x`: uniform in image-plane
    /// length, `inv_pdf` per unit arc length on the sphere (the image
    /// plane's length `L` over the pieces, times the arc's rate
    /// `|T − ω(ω·T)| / |ξ|` per unit image length along the piece's
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
    /// can be discontinuities seen from `x`), a point uniformly along it;
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
        let (s, c) = (along * arc).sin_cos();
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
            inv_pdf: arc / p,
        })
    }
    // ANCHOR_END: sample_boundary

    // ANCHOR: sides
    /// The faces at the edge on either side of the sight line `ω` from `x`:
    /// face `i` lies on the side its inward direction `d_i` (in its plane,
    /// perpendicular to the edge) points to across the line, `sign(d_i·n)`
    /// for the arc's normal `n`; on each side the ray just past the line
    /// meets the face with the least `(d_i·ω)/|d_i·n|` first, or none.
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

    /// `ω × ê / |ω × ê|`: normal to the edge's arc on the sphere at `ω`.
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
