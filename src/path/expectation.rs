//! Expectation differentiation: differentiate the path-space expectation
//! along a deformation of the whole path space that carries every
//! discontinuity with it, so `I` and every `∂I/∂π_j` come from the same
//! paths with no boundary term and no nested path.
//!
//! - **Free paths** are stretched with their domain: `ξ̇ = ξ ṫ_b / t_b`,
//!   whose divergence `ṫ_b / t_b` and the transmittance's `−κe ξ̇` enter
//!   the score (the rod's velocity, He et al. 2024, Eq. 33);
//! - **directions** move with the geometry's warp (2D: piecewise linear on
//!   the circle through the angular velocities of the nearest visible
//!   corners, pinned to the frame at the lobe's horizons); its divergence
//!   and the lobe's `∂ ln f` along it enter the score;
//! - **next-event estimation**: the connection's direction moves with the
//!   same warp.
//!
//! Book: chapter "Flatland: one deformation, three estimators", sections
//! "Expectation" and "The warp field".
use super::deform::{Deform, SlotSet};
use super::derivative_walk::DerivativeWalk;
use super::walk::{Hooks, Vertex};
use super::{Boundaries, Geometry, Hit, Lobe, MovingVertex, Vector};
use crate::rng::PathRng;

/// The expectation method's hooks: one walk's state (its scene moves; its
/// scratch serves connections only).
pub struct Expectation<'a, G: Geometry> {
    /// The walk's state.
    pub walk: DerivativeWalk<'a, G>,
    /// A direction drawn in vacuum whose warp waits for its ray's hit: a
    /// path that then ends without light skips it (see `dead_end`).
    pub pending: Option<(Vertex<G>, G::V)>,
}

// ANCHOR: warp
impl<G: Boundaries> DerivativeWalk<'_, G> {
    /// Moves the direction `w` drawn at `v` with the warp: every slot's
    /// `η̇`, and the warp's divergence plus `∂ ln f` along it added to its
    /// score.
    #[inline]
    fn warp(&mut self, g: &G, v: &Vertex<G>, w: G::V, ahead: Option<Option<Hit>>) {
        let turning = self.frame_spins(g, v);
        let (slots, d) = (self.slots, &mut self.d);
        let mut involved = d.live.union(turning);
        let field = g.warp(v, w, ahead, involved);
        g.warp_shapes(&field, |k| involved = involved.union(slots.moving(k)));
        for j in involved.iter() {
            let s = &mut d.slots[j];
            let velocity = |q: G::V, k: u32| {
                if j < slots.params && g.parameter_shape(j) == k {
                    g.velocity(j, q)
                } else {
                    G::V::ZERO
                }
            };
            let vertex = MovingVertex {
                x: v.x,
                u: s.u,
                spin: s.spin,
            };
            let (wd, div) = g.warp_velocity(&field, j, vertex, w, velocity);
            s.add_score(div);
            s.add_score(v.lobe.dlog(w, wd - G::V::turn(s.spin, w)));
            s.wd = wd;
        }
        for j in involved.iter() {
            d.touch(j);
        }
    }
}
// ANCHOR_END: warp

/// Whether the path that left a vertex in vacuum and met `hit` surely ends
/// without light: it escaped or met a black absorber. Its direction's
/// velocity then multiplies nothing, and the warp (which costs more than
/// the ray) is skipped; the estimates are unchanged.
#[inline]
fn dead_end<G: Geometry>(g: &G, hit: Option<Hit>) -> bool {
    hit.is_none_or(|h| g.surface(h.prim) == super::Surface::Absorber)
}

impl<G: Boundaries> Hooks<G> for Expectation<'_, G> {
    // The warp's steep gaps at the sensor get their own share of the draws.
    const SENSOR_MIXTURE: bool = true;

    #[inline]
    fn boundary(&mut self, g: &G, x: G::V, w: G::V, hit: Option<Hit>) {
        // The warp of a direction drawn in vacuum, now that its hit is known
        // (the walk casts the ray once).
        if let Some((v, drawn)) = self.pending.take() {
            debug_assert!(drawn == w, "the pending direction is the ray's");
            if !dead_end(g, hit) {
                self.walk.warp(g, &v, w, Some(hit));
            }
        }
        self.walk.segment(g, x, w, hit);
    }
    // ANCHOR: collision
    #[inline]
    fn collision(&mut self, w: G::V, xi: f64, t_b: f64, ke: f64) {
        // The free path stretches with its domain [0, t_b].
        let d = &mut self.walk.d;
        for j in d.live.iter() {
            let s = &mut d.slots[j];
            s.add_score(s.tb_dot / t_b);
            let xi_dot = xi / t_b * s.tb_dot;
            s.add_score(-ke * xi_dot);
            s.u = s.u + w * xi_dot + s.wd * xi;
        }
    }
    // ANCHOR_END: collision
    #[inline]
    fn carried(&mut self) -> Option<(&mut Deform<G::V>, SlotSet)> {
        Some((&mut self.walk.d, self.walk.slots.all()))
    }
    #[inline]
    fn visit(&mut self, _x: G::V) {
        // Counted for the path's work (no nested walk here).
        self.walk.scratch.work.main += 1;
    }
    #[inline]
    fn connect(&mut self, g: &G, rng: &mut PathRng, v: &Vertex<G>) -> f64 {
        self.walk
            .connect(g, rng, v, true, |walk, w, ahead| walk.warp(g, v, w, ahead))
    }
    #[inline]
    fn scatter(&mut self, g: &G, rng: &mut PathRng, v: &Vertex<G>) -> G::V {
        let w = if v.mixed {
            g.sensor_mixture_sample(&v.lobe, rng)
        } else {
            v.lobe.sample(rng)
        };
        if !self.walk.slots.is_empty() {
            if g.coefficients(v.medium).is_some() {
                self.walk.warp(g, v, w, None);
            } else {
                self.pending = Some((*v, w));
            }
        }
        w
    }
}
