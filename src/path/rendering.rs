//! Differentiable rendering: differentiate the integral equation, its
//! domains held fixed. Free paths keep their length and directions turn
//! with their frame (the sensor's, a reflector's, the incoming direction at
//! a collision), so the path deforms only through the vertices it hits;
//! whatever moves across that fixed parametrisation is a boundary term:
//!
//! - the **Leibniz term** of a free-path domain `[0, t_b]` whose end moves:
//!   `κs e^{−κe t_b} L_s(t_b⁻) ṫ_b`, `L_s` from one nested path;
//! - the **jump** across a discontinuity of the directional integrand (a
//!   corner seen from the vertex): `f(η_q) T(x, q) [L_behind(q) − L_ahead(q)]
//!   v_n`, `v_n` the discontinuity's velocity relative to the frame, one
//!   discontinuity drawn at random and each side's radiance from one nested
//!   path evaluated exactly at it (double randomisation); between two faces
//!   of a reflector, both sides from shared draws and one path
//!   ([`reflected_jump`]);
//! - next-event estimation: the connection's direction turns with the frame
//!   like any other.
//!
//! Book: chapter "Flatland: one deformation, three estimators", sections
//! "Rendering" and "Corner jumps".
use super::deform::{Deform, SlotSet};
use super::derivative_walk::{DerivativeWalk, SceneMotion};
use super::nested::{SurfacePoint, Work, radiance, reflected_jump, surface_radiance};
use super::walk::{Frame, Hooks, Leg, Ray, Vertex, light_sample, reach, transmittance_by};
use super::{
    Boundaries, BoundaryPoint, BoundaryView, Coefficients, Geometry, Hit, Lobe, NO_PRIM, Prim,
    Side, Surface, Vector,
};
use crate::rng::PathRng;

/// The rendering method's hooks: one walk's state. In a frozen scene,
/// transport's frozen walks.
pub struct Rendering<'a, G: Geometry> {
    /// The walk's state.
    pub walk: DerivativeWalk<'a, G>,
}

impl<G: Geometry> DerivativeWalk<'_, G> {
    /// Sets every slot's `spin` to the turn rate of `v`'s frame; returns
    /// the slots whose frame turns.
    #[inline]
    pub(super) fn frame_spins(&mut self, g: &G, v: &Vertex<G>) -> SlotSet {
        let mut turning = SlotSet::EMPTY;
        for s in &mut self.d.slots {
            s.spin = <G::V as Vector>::STILL;
        }
        match v.frame {
            Frame::Sensor => {}
            Frame::Surface(k) => {
                for j in self.movers(k).iter() {
                    let spin = g.spin(j);
                    if spin != <G::V as Vector>::STILL {
                        self.d.slots[j].spin = spin;
                        turning.insert(j);
                    }
                }
            }
            Frame::Incoming => {
                let d = &mut self.d;
                for j in d.live.iter() {
                    let s = &mut d.slots[j];
                    if s.wd != G::V::ZERO {
                        s.spin = G::V::spin_of(v.w_in, s.wd);
                        turning.insert(j);
                    }
                }
            }
        }
        turning
    }
}

/// Directions attached to the frame: `η̇ = Ω × η` for the slots in `rule`.
#[inline]
pub(super) fn attach<V: Vector>(d: &mut Deform<V>, rule: SlotSet, turning: SlotSet, w: V) {
    for j in d.live.union(turning).and(rule).iter() {
        let s = &mut d.slots[j];
        s.wd = V::turn(s.spin, w);
        if s.wd != V::ZERO {
            d.live.insert(j);
        }
    }
}

/// The largest turn between a reflector's two faces at a corner or crease
/// for which the jump across it is drawn from shared draws
/// ([`reflected_jump`]).
pub const SHARED_TURN: f64 = std::f64::consts::FRAC_PI_4;

// ANCHOR: leibniz
impl<G: Geometry> DerivativeWalk<'_, G> {
    /// The Leibniz term of the free-path domain ending at `t_b` on a moving
    /// boundary, for the slots in `rule`: `β κs e^{−κe t_b} L_s(t_b⁻) ṫ_b`
    /// (`L_s` by a nested path, as the path's work admits it).
    #[inline]
    pub(super) fn leibniz(
        &mut self,
        g: &G,
        rule: SlotSet,
        rng: &mut PathRng,
        leg: &Leg<G>,
        t_b: f64,
    ) {
        let Leg { x, w, medium, beta } = *leg;
        let Some(Coefficients { ks, ke }) = g.coefficients(medium) else {
            return;
        };
        let d = &mut self.d;
        let moving = d.live.and(rule);
        if ks <= 0.0 || !moving.iter().any(|j| d.slots[j].tb_dot != 0.0) {
            return;
        }
        // Just before the boundary, but farther than the caster's hit
        // threshold even for a nested walk that starts a hair in front of it.
        let end = x + w * (t_b - g.nudge(x + w * t_b).min(0.5 * t_b));
        let work = &mut self.scratch.work;
        let Some(weight) = work.admit(rng) else {
            return;
        };
        let wi = g.phase_lobe(medium, w).sample(rng);
        let ray = Ray {
            x: end,
            w: wi,
            medium,
            skip: NO_PRIM,
        };
        let ls = radiance(g, work, rng, ray);
        let term = beta * ks * (-ke * t_b).exp() * ls * weight;
        for j in moving.iter() {
            let s = &mut d.slots[j];
            s.add_boundary(term * s.tb_dot, (term * s.tb_dot).abs());
        }
    }
}
// ANCHOR_END: leibniz

/// Cosine between a sight line and the normal of the face the viewer lies
/// on below which the sight line lies in that face's plane (rounding of an
/// exact 0): its lobe weight is 0, and its boundary term too.
const EDGE_ON: f64 = 1e-12;

// ANCHOR: corner_jump
impl<G: Boundaries> DerivativeWalk<'_, G> {
    /// The boundary term of the directional integral at `v`: one
    /// discontinuity drawn, the jump of the radiance across it evaluated
    /// exactly at it (one nested path for each side), times its velocity
    /// relative to the frame, for every slot. `spin` must hold the frame's
    /// turn rates (see [`Self::frame_spins`]), `turning` the slots whose
    /// frame turns; the nested paths as the path's work admits them.
    #[inline]
    pub(super) fn corner_jump(
        &mut self,
        g: &G,
        rng: &mut PathRng,
        v: &Vertex<G>,
        turning: SlotSet,
    ) {
        // A vertex that stays put in a frame that stays put sees only the
        // discontinuities of moving shapes move.
        let mut moving_view = turning;
        for j in self.d.live.iter() {
            if self.d.slots[j].u != G::V::ZERO {
                moving_view.insert(j);
            }
        }
        let view = BoundaryView {
            all: moving_view,
            own: match self.scene {
                SceneMotion::Moving => self.slots.parameter_slots.without(moving_view),
                SceneMotion::Frozen => SlotSet::EMPTY,
            },
        };
        if view.all.is_empty() && view.own.is_empty() {
            return;
        }
        g.boundary_points(v, &view, rng, |rng, b| {
            self.corner_term(g, rng, v, &view, &b)
        });
    }

    /// The term of one boundary point `b` seen from `v`
    /// ([`Self::corner_jump`]), the slots whose vertex or frame moves in
    /// `view.all`.
    #[inline]
    fn corner_term(
        &mut self,
        g: &G,
        rng: &mut PathRng,
        v: &Vertex<G>,
        view: &BoundaryView,
        b: &BoundaryPoint<G::V>,
    ) {
        let r = b.q - v.x;
        let dist = r.length();
        let wq = r * (1.0 / dist);
        let f = v.lobe.pdf(wq);
        if f <= 0.0 {
            return;
        }
        // A point in the plane of the face the vertex lies on (that face's own
        // corners and edges) is seen exactly edge-on, where the lobe is 0; by
        // rounding its cosine is ~10⁻¹⁶ instead, and the nested path that
        // leaves the next face at that corner starts on its far side: inside a
        // closed reflector of albedo 1 it then walks 10⁵ events (rendering and
        // transport took 10³ times the intensity estimator's time).
        if v.skip != NO_PRIM && g.normal(v.skip, v.x).dot(wq).abs() <= EDGE_ON {
            return;
        }
        let Some((t, medium)) = reach(g, v.x, b.q, v.medium, v.skip, |p| g.holds(b, p)) else {
            return;
        };
        let normal = g.boundary_normal(v.x, b);
        let mut any = false;
        let movers = self.movers(b.shape);
        let involved = view.all.union(movers);
        let (d, work) = (&mut self.d, &mut self.scratch.work);
        for j in involved.iter() {
            let s = &mut d.slots[j];
            let vq = if movers.contains(j) {
                g.velocity(j, b.q)
            } else {
                G::V::ZERO
            };
            // The velocity of the unit direction to q, relative to the frame.
            let rel = vq - s.u;
            let wq_dot = (rel - wq * rel.dot(wq)) * (1.0 / dist);
            s.tb_dot = (wq_dot - G::V::turn(s.spin, wq)).dot(normal);
            any |= s.tb_dot != 0.0;
        }
        if !any {
            return;
        }
        let (ahead, behind) = g.sides(v.x, b);
        // The path past the boundary starts a hair (10⁻⁹ of the scene's size)
        // beyond q along the same sight line: from q itself, a face at the
        // edge seen nearly edge-on (at an angle γ) is hit by rounding at
        // t ~ 10⁻¹⁶/γ, beyond the casters' T_MIN once γ < 10⁻⁴, and hides the
        // light the jump is made of (an absorbing tetrahedron with a face
        // 3·10⁻⁵ rad from edge-on lost 13 % of its derivative). The step takes
        // such a face's plane behind the ray's origin down to γ ~ 10⁻⁷.
        let past = b.q + wq * g.nudge(b.q);
        let side = |work: &mut Work, rng: &mut PathRng, side: Side| match side {
            Side::Surface(p) => {
                let at = SurfacePoint {
                    y: g.off_boundary(b, p),
                    prim: p,
                };
                surface_radiance(g, work, rng, at, wq, medium)
            }
            Side::Past => {
                let ray = Ray {
                    x: past,
                    w: wq,
                    medium,
                    skip: NO_PRIM,
                };
                radiance(g, work, rng, ray)
            }
        };
        let reflector = |s: Side| match s {
            Side::Surface(p) => matches!(g.surface(p), Surface::Reflector { .. }).then_some(p),
            Side::Past => None,
        };
        let shared = match (reflector(ahead), reflector(behind)) {
            // Two faces of a reflector that turn little from one another (their
            // normals, as seen from the viewer, within SHARED_TURN): their
            // radiances from shared draws, whose difference is of the order of
            // the turn. Past it, the mixture of two lobes that barely overlap
            // costs more than the shared draws save (measured: a 125° concave
            // corner had rendering's variance four times larger).
            (Some(pa), Some(pb)) => {
                let on = |p: Prim| SurfacePoint {
                    y: g.off_boundary(b, p),
                    prim: p,
                };
                let (sa, sb) = (on(pa), on(pb));
                let facing = |s: SurfacePoint<G::V>| {
                    let n = g.normal(s.prim, s.y);
                    if wq.dot(n) > 0.0 { -n } else { n }
                };
                (facing(sa).dot(facing(sb)) >= SHARED_TURN.cos()).then_some((sa, sb))
            }
            _ => None,
        };
        // A side that is a lamp or black is known; a reflector's or the
        // space past the boundary takes a nested path, as the work admits.
        let walks = |s: Side| reflector(s).is_some() || s == Side::Past;
        let weight = if walks(ahead) || walks(behind) {
            work.admit(rng)
        } else {
            Some(1.0)
        };
        let Some(weight) = weight else {
            for j in involved.iter() {
                d.slots[j].tb_dot = 0.0;
            }
            return;
        };
        // The jump by `n` pairs of nested paths, averaged (one but at a
        // camera pixel: see `Boundaries::jump_paths`).
        let n = g.jump_paths(v).max(1);
        let mut jump = 0.0;
        for _ in 0..n {
            jump += if let Some((a, b)) = shared {
                reflected_jump(g, work, rng, a, b, wq, medium)
            } else {
                // Common random numbers for the two sides.
                work.jump(rng, |work, rng, far| {
                    side(work, rng, if far { behind } else { ahead })
                })
            };
        }
        let jump = jump / n as f64;
        // d/dπ ∫ f L dη ∋ f (L_behind − L_ahead) v_n: the side ahead shrinks.
        let term = v.beta * f * t * jump * b.inv_pdf * weight;
        for j in involved.iter() {
            let s = &mut d.slots[j];
            s.add_boundary(term * s.tb_dot, (term * s.tb_dot).abs());
            s.tb_dot = 0.0;
        }
    }
}
// ANCHOR_END: corner_jump

impl<G: Boundaries> Hooks<G> for Rendering<'_, G> {
    #[inline]
    fn boundary(&mut self, g: &G, x: G::V, w: G::V, hit: Option<Hit>) {
        self.walk.segment(g, x, w, hit);
    }
    #[inline]
    fn free_path_domain(&mut self, g: &G, rng: &mut PathRng, leg: &Leg<G>, t_b: f64) {
        let all = self.walk.slots.all();
        self.walk.leibniz(g, all, rng, leg, t_b);
    }
    #[inline]
    fn visit(&mut self, _x: G::V) {
        // A frozen walk is transport's nested walk.
        let work = &mut self.walk.scratch.work;
        match self.walk.scene {
            SceneMotion::Moving => work.main += 1,
            SceneMotion::Frozen => work.nested += 1,
        }
    }
    #[inline]
    fn carried(&mut self) -> Option<(&mut Deform<G::V>, SlotSet)> {
        Some((&mut self.walk.d, self.walk.slots.all()))
    }
    #[inline]
    fn connect(&mut self, g: &G, rng: &mut PathRng, v: &Vertex<G>) -> f64 {
        self.walk.attached_connect(g, rng, v)
    }
    #[inline]
    fn scatter(&mut self, g: &G, rng: &mut PathRng, v: &Vertex<G>) -> G::V {
        self.walk.attached_scatter(g, rng, v)
    }
}

impl<G: Boundaries> DerivativeWalk<'_, G> {
    /// Next-event estimation with the connection's direction attached to
    /// the vertex's frame (rendering's rule; transport's too).
    #[inline]
    pub(super) fn attached_connect(&mut self, g: &G, rng: &mut PathRng, v: &Vertex<G>) -> f64 {
        let turning = self.frame_spins(g, v);
        self.connect(g, rng, v, false, |walk, w, _| {
            attach(&mut walk.d, walk.slots.all(), turning, w)
        })
    }

    /// The direction leaving `v`, attached to its frame, after the boundary
    /// term of its directional integral ([`Self::corner_jump`]).
    #[inline]
    pub(super) fn attached_scatter(&mut self, g: &G, rng: &mut PathRng, v: &Vertex<G>) -> G::V {
        if self.slots.is_empty() {
            return v.lobe.sample(rng);
        }
        let turning = self.frame_spins(g, v);
        self.corner_jump(g, rng, v, turning);
        let w = v.lobe.sample(rng);
        attach(&mut self.d, self.slots.all(), turning, w);
        w
    }
}

// ANCHOR: connect
impl<G: Boundaries> DerivativeWalk<'_, G> {
    /// Next-event estimation at `v`: one emitter point drawn as the
    /// intensity estimator draws it; its direction `η` deforms as
    /// `direction` sets it in a copy of the walk (the method's rule: the
    /// frame's turn, the warp), the connection's segments follow, and
    /// `contribution × score` is added to every slot. The connection's
    /// segments are followed by rendering's hooks (it has no free path, so
    /// only their boundary speed, transmittance and vertex carrying act).
    /// The MIS weight is a fixed partition of unity in the method's own
    /// coordinates over directions, so it is not differentiated (book:
    /// "Next-event estimation in the derivative walks"). With `precheck`, a
    /// blocked connection is found by a plain shadow walk before
    /// `direction` runs (worth it when `direction` costs more than the
    /// extra ray: the expectation method's warp); its hits are kept, handed
    /// to `direction` (the first: `Some(hit)`) and replayed to the hooks,
    /// so no ray is cast twice and the result is the same.
    pub fn connect(
        &mut self,
        g: &G,
        rng: &mut PathRng,
        v: &Vertex<G>,
        precheck: bool,
        direction: impl FnOnce(&mut DerivativeWalk<'_, G>, G::V, Option<Option<Hit>>),
    ) -> f64 {
        let Some((w, p, c)) = light_sample(g, rng, v) else {
            return 0.0;
        };
        // A blocked connection adds nothing, whatever its direction's
        // velocity: a direction rule that costs more than a shadow ray (the
        // expectation method's warp) is worth skipping there.
        let mut record = Recorded::default();
        if precheck {
            let cast = |x, w, skip| record.cast(g, x, w, skip);
            if transmittance_by(g, &mut (), v.ray(w), p, cast) == 0.0 {
                return 0.0;
            }
        }
        let d = self.scratch.take_copy(&self.d);
        let mut follow = Rendering {
            walk: DerivativeWalk {
                slots: self.slots,
                scene: self.scene,
                scratch: &mut *self.scratch,
                d,
            },
        };
        direction(&mut follow.walk, w, precheck.then(|| record.first()));
        let mut replay = 0;
        let cast = |x, w, skip| record.replay(&mut replay, g, x, w, skip);
        let contribution = c * transmittance_by(g, &mut follow, v.ray(w), p, cast);
        let tmp = follow.walk.d;
        if contribution != 0.0 {
            for j in tmp.live.iter() {
                let t = &tmp.slots[j];
                let scale = (contribution * t.score_scale).abs();
                self.d.slots[j].add_boundary(contribution * t.score, scale);
            }
        }
        self.scratch.give(tmp);
        contribution
    }
}

/// The hits of a connection's shadow walk, kept for its replay (a few: a
/// connection crosses few media boundaries; past them the replay casts).
#[derive(Default)]
struct Recorded {
    hits: [Option<Hit>; 8],
    n: usize,
}

impl Recorded {
    /// Casts and keeps the hit.
    #[inline]
    fn cast<G: Geometry>(&mut self, g: &G, x: G::V, w: G::V, skip: Prim) -> Option<Hit> {
        let h = g.cast(x, w, skip);
        if self.n < self.hits.len() {
            self.hits[self.n] = h;
            self.n += 1;
        }
        h
    }

    /// The `i`-th hit again (the replay's casts come in the same order with
    /// the same rays), cast where none was kept.
    #[inline]
    fn replay<G: Geometry>(
        &self,
        i: &mut usize,
        g: &G,
        x: G::V,
        w: G::V,
        skip: Prim,
    ) -> Option<Hit> {
        let k = *i;
        *i += 1;
        if k < self.n {
            self.hits[k]
        } else {
            g.cast(x, w, skip)
        }
    }

    /// The first hit.
    fn first(&self) -> Option<Hit> {
        self.hits[0]
    }
}
// ANCHOR_END: connect
