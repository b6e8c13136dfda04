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
use super::deform::{Deform, SlotSet, Slots, connect};
use super::nested::{Scratch, Work, radiance, reflected_jump, surface_radiance};
use super::walk::{Frame, Hooks, Leg, Vertex, reach};
use super::{
    Boundaries, BoundaryPoint, BoundaryView, Geometry, Hit, Lobe, NO_PRIM, Prim, Side, Surface,
    Vector,
};
use crate::rng::PathRng;

/// The rendering method's hooks: one walk's deformation state.
pub struct Rendering<'a, G: Geometry> {
    /// What is differentiated.
    pub slots: &'a Slots,
    /// States for connections and nested walks.
    pub scratch: &'a mut Scratch<G::V>,
    /// The walk's state.
    pub d: Deform<G::V>,
    /// The scene stands still: only the start's velocities are
    /// differentiated (transport's gradient walks).
    pub frozen: bool,
}

/// The slots whose material points move on shape `k` (none if `frozen`).
#[inline]
pub(super) fn movers(slots: &Slots, k: u32, frozen: bool) -> SlotSet {
    if frozen {
        SlotSet::EMPTY
    } else {
        slots.moving(k)
    }
}

/// Sets every slot's `spin` to the turn rate of `v`'s frame; returns the
/// slots whose frame turns.
#[inline]
pub(super) fn frame_spins<G: Geometry>(
    g: &G,
    slots: &Slots,
    d: &mut Deform<G::V>,
    v: &Vertex<G>,
    frozen: bool,
) -> SlotSet {
    let mut turning = SlotSet::EMPTY;
    for s in &mut d.slots {
        s.spin = <G::V as Vector>::STILL;
    }
    match v.frame {
        Frame::Sensor => {}
        Frame::Surface(k) => {
            for j in movers(slots, k, frozen).iter() {
                let spin = g.spin(j);
                if spin != <G::V as Vector>::STILL {
                    d.slots[j].spin = spin;
                    turning.insert(j);
                }
            }
        }
        Frame::Incoming => {
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
/// The Leibniz term of the free-path domain ending at `t_b` on a moving
/// boundary, for the slots in `rule`: `β κs e^{−κe t_b} L_s(t_b⁻) ṫ_b`
/// (`L_s` by a nested path, as the path's `work` admits it).
#[inline]
pub(super) fn leibniz<G: Geometry>(
    g: &G,
    d: &mut Deform<G::V>,
    rule: SlotSet,
    rng: &mut PathRng,
    leg: &Leg<G>,
    t_b: f64,
    work: &mut Work,
) {
    let Leg { x, w, medium, beta } = *leg;
    let Some((ks, ke)) = g.coefficients(medium) else {
        return;
    };
    let moving = d.live.and(rule);
    if ks <= 0.0 || !moving.iter().any(|j| d.slots[j].tb_dot != 0.0) {
        return;
    }
    // Just before the boundary, but farther than the caster's hit
    // threshold even for a nested walk that starts a hair in front of it.
    let end = x + w * (t_b - g.nudge(x + w * t_b).min(0.5 * t_b));
    let Some(weight) = work.admit(rng) else {
        return;
    };
    let wi = g.phase_lobe(medium, w).sample(rng);
    let ls = radiance(g, work, rng, end, wi, medium, NO_PRIM);
    let term = beta * ks * (-ke * t_b).exp() * ls * weight;
    for j in moving.iter() {
        let s = &mut d.slots[j];
        s.add_boundary(term * s.tb_dot, (term * s.tb_dot).abs());
    }
}
// ANCHOR_END: leibniz

/// Cosine between a sight line and the normal of the face the viewer lies
/// on below which the sight line lies in that face's plane (rounding of an
/// exact 0): its lobe weight is 0, and its boundary term too.
const EDGE_ON: f64 = 1e-12;

// ANCHOR: corner_jump
/// The boundary term of the directional integral at `v`: one discontinuity
/// drawn, the jump of the radiance across it evaluated exactly at it (one
/// nested path for each side), times its velocity relative to the frame,
/// for every slot. `spin` must hold the frame's turn rates (see
/// [`frame_spins`]), `turning` the slots whose frame turns; the nested
/// paths as the path's `work` admits them.
#[allow(clippy::too_many_arguments)]
#[inline]
pub(super) fn corner_jump<G: Boundaries>(
    g: &G,
    slots: &Slots,
    d: &mut Deform<G::V>,
    rng: &mut PathRng,
    v: &Vertex<G>,
    turning: SlotSet,
    frozen: bool,
    work: &mut Work,
) {
    // A vertex that stays put in a frame that stays put sees only the
    // discontinuities of moving shapes move.
    let mut moving_view = turning;
    for j in d.live.iter() {
        if d.slots[j].u != G::V::ZERO {
            moving_view.insert(j);
        }
    }
    let view = BoundaryView {
        all: moving_view,
        own: if frozen {
            SlotSet::EMPTY
        } else {
            slots.parameter_slots.without(moving_view)
        },
    };
    if view.all.is_empty() && view.own.is_empty() {
        return;
    }
    g.boundary_points(v, &view, rng, |rng, b| {
        corner_term(g, slots, d, rng, v, frozen, moving_view, &b, work)
    });
}

/// The term of one boundary point `b` seen from `v` ([`corner_jump`]).
#[allow(clippy::too_many_arguments)]
#[inline]
fn corner_term<G: Boundaries>(
    g: &G,
    slots: &Slots,
    d: &mut Deform<G::V>,
    rng: &mut PathRng,
    v: &Vertex<G>,
    frozen: bool,
    moving_view: SlotSet,
    b: &BoundaryPoint<G::V>,
    work: &mut Work,
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
    let involved = moving_view.union(movers(slots, b.shape, frozen));
    for j in involved.iter() {
        let s = &mut d.slots[j];
        let vq = if !frozen && j < slots.params && g.parameter_shape(j) == b.shape {
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
        Side::Surface(p) => surface_radiance(g, work, rng, g.off_boundary(b, p), p, wq, medium),
        Side::Past => radiance(g, work, rng, past, wq, medium, NO_PRIM),
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
            let (ya, yb) = (g.off_boundary(b, pa), g.off_boundary(b, pb));
            let facing = |p: Prim, y: G::V| {
                let n = g.normal(p, y);
                if wq.dot(n) > 0.0 { -n } else { n }
            };
            (facing(pa, ya).dot(facing(pb, yb)) >= SHARED_TURN.cos())
                .then_some(((ya, pa), (yb, pb)))
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
// ANCHOR_END: corner_jump

impl<G: Boundaries> Hooks<G> for Rendering<'_, G> {
    #[inline]
    fn boundary(&mut self, g: &G, x: G::V, w: G::V, hit: Option<Hit>) {
        self.d.segment(g, self.slots, self.frozen, x, w, hit);
    }
    #[inline]
    fn free_path_domain(&mut self, g: &G, rng: &mut PathRng, leg: &Leg<G>, t_b: f64) {
        let work = &mut self.scratch.work;
        leibniz(g, &mut self.d, self.slots.all(), rng, leg, t_b, work);
    }
    #[inline]
    fn visit(&mut self, _x: G::V) {
        // A frozen walk is transport's nested walk.
        let work = &mut self.scratch.work;
        if self.frozen {
            work.nested += 1;
        } else {
            work.main += 1;
        }
    }
    #[inline]
    fn collision(&mut self, _w: G::V, xi: f64, _t_b: f64, _ke: f64) {
        self.d.carry(xi);
    }
    #[inline]
    fn pass(&mut self, ke: f64) {
        self.d.pass(self.slots.all(), ke);
    }
    #[inline]
    fn arrive(&mut self, w: G::V, t: f64) {
        self.d.arrive(self.slots.all(), w, t);
    }
    #[inline]
    fn emission(&mut self, contribution: f64) {
        self.d.collect(contribution);
    }
    #[inline]
    fn connect(&mut self, g: &G, rng: &mut PathRng, v: &Vertex<G>) -> f64 {
        attached_connect(
            g,
            self.slots,
            self.scratch,
            &mut self.d,
            rng,
            v,
            self.frozen,
        )
    }
    #[inline]
    fn scatter(&mut self, g: &G, rng: &mut PathRng, v: &Vertex<G>) -> G::V {
        let work = &mut self.scratch.work;
        attached_scatter(g, self.slots, &mut self.d, rng, v, self.frozen, work)
    }
}

/// Next-event estimation with the connection's direction attached to the
/// vertex's frame (rendering's rule; transport's too).
#[inline]
pub(super) fn attached_connect<G: Boundaries>(
    g: &G,
    slots: &Slots,
    scratch: &mut Scratch<G::V>,
    d: &mut Deform<G::V>,
    rng: &mut PathRng,
    v: &Vertex<G>,
    frozen: bool,
) -> f64 {
    let turning = frame_spins(g, slots, d, v, frozen);
    connect(g, slots, scratch, d, rng, v, frozen, false, |d, w, _| {
        attach(d, slots.all(), turning, w)
    })
}

/// The direction leaving `v`, attached to its frame, after the boundary
/// term of its directional integral ([`corner_jump`]).
#[inline]
pub(super) fn attached_scatter<G: Boundaries>(
    g: &G,
    slots: &Slots,
    d: &mut Deform<G::V>,
    rng: &mut PathRng,
    v: &Vertex<G>,
    frozen: bool,
    work: &mut Work,
) -> G::V {
    if slots.is_empty() {
        return v.lobe.sample(rng);
    }
    let turning = frame_spins(g, slots, d, v, frozen);
    corner_jump(g, slots, d, rng, v, turning, frozen, work);
    let w = v.lobe.sample(rng);
    attach(d, slots.all(), turning, w);
    w
}
