//! The work of a path's nested walks, and the budget that bounds it.
//!
//! Rendering and transport estimate some of their terms by nested walks
//! started at the main walk's events (double randomisation): the
//! in-scattered radiance of a Leibniz term, the two sides of a corner's or
//! an edge's jump, transport's frozen walks and the in-scattered radiances
//! on either side of a moving interface. Each nested walk costs about as
//! many events as a path, and a path makes a few at every event, so the
//! work of one path grows as the square of its length. Where paths are
//! short that is a constant factor; in a closed room of reflectors of
//! albedo 1, which only the lamp ends, a path made ~3·10³ events and its
//! nested walks 4–7·10⁷ (3D: 4.5–9.4 s of CPU per path).
//!
//! [`Work`] counts, per path, the events of its main walk and of its nested
//! walks (of any depth: a frozen walk's own nested walks count too). While
//! the path's nested work is within [`Budget::free_events`] and
//! [`Budget::free_estimates`], every nested estimate is made, exactly as
//! without a budget (no path of a shipped scene comes near either). Past
//! them, a nested estimate is made with probability `r = min(1, c J / n)`
//! — `n` the nested events so far, `J` the nested estimates made, `c` =
//! [`Budget::per_estimate`] — and its result divided by `r`; skipped, it
//! adds 0. Since `n / J` is the mean cost of an estimate so far, each
//! further opportunity costs about `c` events on average: the work past the
//! budget grows with the number of opportunities (a few per event of the
//! main walk), not with the nested walks' lengths. The price is variance:
//! a term made with probability `r` has its variance multiplied by up to
//! `1/r`.
//!
//! *Unbiased.* The roulette leaves each term's expectation unchanged only
//! if `r` and the moment the free work ends are fixed by numbers the path
//! has already drawn, and the numbers drawn after are fresh. The far side
//! of a jump breaks that: it replays the numbers the near side draws from
//! the path's stream (common random numbers) and may read on past them,
//! into numbers the path has yet to draw. Its events are therefore counted
//! apart ([`Work::replayed`]) and decide nothing; and past the free work
//! the two sides draw from a stream of their own, seeded from the path's.
//! (Letting the decisions see the far side's events read transport's
//! derivative of a black cube moving in a reflecting room at 0.785 ± 0.003
//! against finite differences' 0.740 ± 0.002.) [`Scratch`], the states
//! a path's nested derivative walks reuse, carries the path's [`Work`].
//!
//! Book: chapter "When not to trust a number", section "Runs that end".
use super::deform::Deform;
use super::walk::{
    Drawn, Frame, Hooks, Ray, Vertex, behind_solid, next_event, reflector_lobe, transmittance, walk,
};
use super::{Geometry, Lobe, MediumId, Prim, Surface, Vector, mis};
use crate::rng::PathRng;
use rand::{RngExt, SeedableRng};

/// Nested events a path spends freely: the shipped scenes' paths spend at
/// most 640 (`room.toml`, transport, 2·10⁴ paths).
pub const FREE_NESTED_EVENTS: u64 = 4096;

/// Nested estimates a path makes freely: the shipped scenes' paths make at
/// most 144 (`room.toml`, transport). It bounds the free work where the
/// far sides of jumps, which are not counted in the events, are long.
pub const FREE_NESTED_ESTIMATES: u64 = 512;

/// Mean nested events per opportunity past the free work.
pub const NESTED_EVENTS_PER_ESTIMATE: f64 = 16.0;

/// How much nested work a path spends before its nested estimates are
/// rouletted, and how much per opportunity after.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Budget {
    /// Nested events spent freely (every nested estimate made).
    pub free_events: u64,
    /// Nested estimates made freely.
    pub free_estimates: u64,
    /// Past the free work, the mean nested events one opportunity may
    /// cost: a nested estimate is made with probability
    /// `min(1, per_estimate / ℓ)`, `ℓ` the mean events of the path's nested
    /// estimates so far (> 0).
    pub per_estimate: f64,
}

impl Budget {
    /// No roulette: every nested estimate made, whatever it costs.
    pub const UNLIMITED: Budget = Budget {
        free_events: u64::MAX,
        free_estimates: u64::MAX,
        per_estimate: f64::INFINITY,
    };
}

impl Default for Budget {
    fn default() -> Self {
        Budget {
            free_events: FREE_NESTED_EVENTS,
            free_estimates: FREE_NESTED_ESTIMATES,
            per_estimate: NESTED_EVENTS_PER_ESTIMATE,
        }
    }
}

/// One path's work: the events of its main walk and of its nested walks,
/// and its nested estimates made and skipped. As the hooks of a plain
/// nested walk (no derivative), it counts that walk's events.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Work {
    /// The budget the path spends.
    pub budget: Budget,
    /// Events (surface hits, collisions, escapes) of the main walk.
    pub main: u64,
    /// Events of the nested walks that draw their numbers in turn from the
    /// path's stream (or from a stream seeded from it): the roulette's
    /// decisions rest on them.
    pub nested: u64,
    /// Events of the far sides of jumps within the free work, which replay
    /// the near side's numbers and may read on into numbers the path has
    /// yet to draw: counted, but they decide nothing.
    pub replayed: u64,
    /// Nested estimates made.
    pub estimates: u64,
    /// Nested estimates the roulette skipped.
    pub skipped: u64,
}

impl Work {
    /// A path's work before its first event.
    pub fn new(budget: Budget) -> Work {
        Work {
            budget,
            ..Work::default()
        }
    }

    /// Whether the path's nested work is still free: every nested estimate
    /// made, the far side of a jump replaying the near side's numbers from
    /// the path's stream, as without a budget.
    #[inline]
    pub fn is_free(&self) -> bool {
        let b = self.budget;
        self.nested < b.free_events && self.estimates < b.free_estimates
    }

    /// Whether a nested estimate is made now: `Some(1/r)`, the weight its
    /// result is multiplied by, or `None` (skipped: the term adds 0). Call
    /// it only where a nested walk follows. A random number is drawn only
    /// past the free work, so within it a path draws the numbers of a run
    /// without a budget.
    #[inline]
    pub fn admit(&mut self, rng: &mut PathRng) -> Option<f64> {
        debug_assert!(
            self.budget.per_estimate > 0.0,
            "a term never made is a bias"
        );
        // At least one estimate's worth, so that r > 0 even before the
        // first estimate.
        let allowed = self.budget.per_estimate * self.estimates.max(1) as f64;
        if self.is_free() || self.nested as f64 <= allowed {
            self.estimates += 1;
            return Some(1.0);
        }
        let r = allowed / self.nested as f64;
        if rng.random::<f64>() < r {
            self.estimates += 1;
            Some(1.0 / r)
        } else {
            self.skipped += 1;
            None
        }
    }

    /// The difference `L_b − L_a` of the radiances on the two sides of a
    /// jump, `side(work, rng, s)` estimating side `s` (`false`: a, `true`:
    /// b) with common random numbers. Within the free work, side b replays
    /// the numbers side a draws from the path's stream, as without a
    /// budget, its events counted in [`Work::replayed`]; past it, both
    /// draw from a stream seeded from the path's, so that no decision
    /// sees numbers the path has yet to draw.
    #[inline]
    pub fn jump(
        &mut self,
        rng: &mut PathRng,
        mut side: impl FnMut(&mut Work, &mut PathRng, bool) -> f64,
    ) -> f64 {
        if self.is_free() {
            let mut twin = rng.clone();
            let a = side(self, rng, false);
            let mut far = Work::new(self.budget);
            let b = side(&mut far, &mut twin, true);
            self.replayed += far.nested + far.replayed;
            b - a
        } else {
            let mut near = PathRng::seed_from_u64(rng.random());
            let mut twin = near.clone();
            let a = side(self, &mut near, false);
            side(self, &mut twin, true) - a
        }
    }
}

impl<G: Geometry> Hooks<G> for Work {
    #[inline]
    fn visit(&mut self, _x: G::V) {
        self.nested += 1;
    }
}

/// Deformation states reused across the paths of a chunk, for nested walks:
/// taken and given back, so the hot loop allocates nothing per path; and
/// the current path's work, which every nested walk counts into.
#[derive(Debug)]
pub struct Scratch<V: Vector> {
    free: Vec<Deform<V>>,
    /// The current path's work and budget (reset at each path's start).
    pub work: Work,
}

impl<V: Vector> Default for Scratch<V> {
    fn default() -> Self {
        Scratch {
            free: Vec::new(),
            work: Work::default(),
        }
    }
}

impl<V: Vector> Scratch<V> {
    /// A zeroed state of `n` slots.
    #[inline]
    pub fn take(&mut self, n: usize) -> Deform<V> {
        match self.free.pop() {
            Some(mut d) if d.len() == n => {
                d.clear();
                d
            }
            _ => Deform::new(n),
        }
    }

    /// A copy of `d` (the state a connection or nested path starts from).
    #[inline]
    pub fn take_copy(&mut self, d: &Deform<V>) -> Deform<V> {
        let mut t = match self.free.pop() {
            Some(t) if t.len() == d.len() => t,
            _ => Deform::new(d.len()),
        };
        t.copy_from(d);
        t
    }

    /// Returns a state for reuse.
    #[inline]
    pub fn give(&mut self, d: Deform<V>) {
        self.free.push(d);
    }
}

/// A point `y` of primitive `prim`'s surface.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfacePoint<V> {
    /// The point.
    pub y: V,
    /// The primitive.
    pub prim: Prim,
}

/// The radiance leaving the surface at `at` toward a viewer arriving along
/// `w` (in `medium`): one path continued from that surface event. A
/// corner's jump evaluates each side with it.
pub fn surface_radiance<G: Geometry>(
    g: &G,
    work: &mut Work,
    rng: &mut PathRng,
    at: SurfacePoint<G::V>,
    w: G::V,
    medium: MediumId,
) -> f64 {
    let SurfacePoint { y, prim: p } = at;
    match g.surface(p) {
        Surface::Emitter { radiance } => radiance,
        Surface::Absorber | Surface::Transparent => 0.0,
        Surface::Reflector { .. } if behind_solid(g, p, y, w) => 0.0,
        Surface::Reflector { albedo } => {
            let lobe = reflector_lobe(g, p, y, w, albedo);
            let v = Vertex {
                x: y,
                medium,
                skip: p,
                lobe,
                w_in: w,
                frame: Frame::Surface(g.shape(p)),
                beta: lobe.weight(),
                at_sensor: false,
                mixed: false,
            };
            let direct = next_event(g, rng, &v);
            let wo = lobe.sample(rng);
            let drawn = Drawn {
                pdf: lobe.pdf(wo),
                from: y,
            };
            direct + walk(g, work, rng, v.ray(wo), v.beta, Some(drawn))
        }
    }
}

// ANCHOR: reflected_jump
/// The jump `L_b − L_a` of the radiance leaving a corner (2D) or crease
/// (3D) of a reflector toward a viewer arriving along `w` (in `medium`),
/// between its two faces: the points `a` and `b` of their surfaces, each a
/// hair from the corner.
///
/// The two reflected radiances share their draws: one emitter point, and one
/// direction from the mixture `p = (p_a + p_b)/2` of the two cosine lobes,
/// so each side's estimate is `f_s(η)/p(η) L_i(η)` plus its connection
/// (MIS against `p`), both unbiased, and their difference is
/// `(f_b − f_a)(η)/p(η) L_i(η)`: of the order of the faces' turning angle,
/// where two separate paths (the general case of a corner jump) differ by
/// `O(1)` from the first bounce on. One path gives `L_i` for both sides: a
/// ray from either point along a direction in front of both faces meets
/// neither face (the faces face the viewer on either side of the sight
/// line), so both see the same first hit; a direction in front of one face
/// only is that side's alone, traced from its point.
pub fn reflected_jump<G: Geometry>(
    g: &G,
    work: &mut Work,
    rng: &mut PathRng,
    a: SurfacePoint<G::V>,
    b: SurfacePoint<G::V>,
    w: G::V,
    medium: MediumId,
) -> f64 {
    let (SurfacePoint { y: ya, prim: pa }, SurfacePoint { y: yb, prim: pb }) = (a, b);
    let (Surface::Reflector { albedo: ra }, Surface::Reflector { albedo: rb }) =
        (g.surface(pa), g.surface(pb))
    else {
        unreachable!("reflected_jump takes two reflectors");
    };
    let la = reflector_lobe(g, pa, ya, w, ra);
    let lb = reflector_lobe(g, pb, yb, w, rb);
    let mixture = |e: G::V| 0.5 * (la.pdf(e) + lb.pdf(e));
    // The side a ray along `e` leaves from: `a` unless only `b` faces `e`.
    let from = |fa: f64| if fa > 0.0 { a } else { b };
    let mut jump = 0.0;
    // The connection: one emitter point for both sides.
    if let Some((y, p)) = g.emitter_point(rng)
        && let Surface::Emitter { radiance } = g.surface(p)
    {
        let unit = |x: G::V| {
            let d = y - x;
            d * (1.0 / d.length())
        };
        let (ea, eb) = (unit(ya), unit(yb));
        let (fa, fb) = (la.value(ea), lb.value(eb));
        let (pla, plb) = (g.light_pdf(ya, y, p), g.light_pdf(yb, y, p));
        if (fa > 0.0 || fb > 0.0) && pla.is_finite() && plb.is_finite() {
            let SurfacePoint { y: x, prim: skip } = from(fa);
            let e = if fa > 0.0 { ea } else { eb };
            let ray = Ray {
                x,
                w: e,
                medium,
                skip,
            };
            let t = transmittance(g, &mut (), ray, p);
            if t > 0.0 {
                let side = |f: f64, e: G::V, pl: f64| {
                    if f > 0.0 {
                        f * radiance / pl * mis(pl, mixture(e))
                    } else {
                        0.0
                    }
                };
                jump += t * (side(fb, eb, plb) - side(fa, ea, pla));
            }
        }
    }
    // The reflected path: one direction from the mixture.
    let e = if rng.random::<f64>() < 0.5 {
        la.sample(rng)
    } else {
        lb.sample(rng)
    };
    let p = mixture(e);
    let (fa, fb) = (la.value(e), lb.value(e));
    if p > 0.0 && fa != fb {
        let SurfacePoint { y: x, prim: skip } = from(fa);
        let ray = Ray {
            x,
            w: e,
            medium,
            skip,
        };
        let li = walk(g, work, rng, ray, 1.0, Some(Drawn { pdf: p, from: x }));
        jump += (fb - fa) / p * li;
    }
    jump
}
// ANCHOR_END: reflected_jump

/// One-sample estimate of the radiance arriving at the ray's origin from
/// its direction (the path travels along it).
#[inline]
pub fn radiance<G: Geometry>(g: &G, work: &mut Work, rng: &mut PathRng, ray: Ray<G::V>) -> f64 {
    walk(g, work, rng, ray, 1.0, None)
}
