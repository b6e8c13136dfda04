//! The one event loop: backward path tracing with free paths
//! `ξ ~ μ e^{−μ ξ}` in homogeneous media (`μ = κs`, raised in optically thin
//! media so that their rare collisions are drawn; the rest of the
//! extinction carried as the weight `(κs/μ) e^{−(κe−μ) ξ}`), surface events, next-event estimation with multiple
//! importance sampling (power heuristic) at every scattering vertex, and
//! Russian roulette on the throughput. The intensity estimator is this loop
//! with the unit hooks `()`; each derivative method observes its events
//! through [`Hooks`] and adds its own terms. Book: chapter "Flatland",
//! sections "Backward path tracing" and "Next-event estimation".
use super::deform::{Deform, SlotSet};
use super::record;
use super::thin_media::collision_rate;
use super::{Coefficients, Geometry, Hit, Lobe, MediumId, NO_PRIM, Prim, Surface, Vector, mis};
use crate::rng::{PathRng, free_path};
use rand::RngExt;

/// Events after which Russian roulette starts.
pub const ROULETTE_DEPTH: u32 = 5;
/// Highest survival probability of the roulette after
/// [`ROULETTE_CAP_DEPTH`] events: a path in a lossless enclosure still ends.
pub const ROULETTE_CAP: f64 = 0.95;
/// Events after which the survival probability is capped at
/// [`ROULETTE_CAP`]. Before, a path survives with probability `min(1, β)`:
/// in a thick conservative medium (β stays 1) it walks until it leaves,
/// ~τ² events for optical thickness τ, instead of dying after a few hundred
/// (a fixed cap of 0.95 per event made the estimate collapse to 0 from
/// τ ≈ 50 on, with an error bar that could not see it).
pub const ROULETTE_CAP_DEPTH: u32 = 100_000;

/// The frame a scattering vertex's lobe is attached to: it decides how a
/// direction drawn there turns when the parameters change.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Frame {
    /// The sensor's, which stands still.
    Sensor,
    /// The surface of shape `k` (a reflector), turning with it.
    Surface(u32),
    /// The incoming direction's (a collision in a medium).
    Incoming,
}

/// A ray through the scene: from `x` along the unit `w`, in `medium`,
/// leaving the primitive `skip` ([`NO_PRIM`]: none), which it does not hit
/// again at its start. Where a walk, a shadow walk or a nested walk starts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ray<V> {
    /// Origin.
    pub x: V,
    /// Direction (unit).
    pub w: V,
    /// Medium the origin lies in.
    pub medium: MediumId,
    /// Primitive the origin lies on.
    pub skip: Prim,
}

/// How a walk's direction was drawn, for the multiple importance sampling
/// of a lamp the walk hits first: with density `pdf` at the scattering
/// vertex at `from`, where next-event estimation drew that lamp's points
/// with the light strategy's density. (A walk without it was given its
/// direction, and counts such a lamp whole.)
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Drawn<V> {
    /// Density with which the vertex's lobe drew the direction.
    pub pdf: f64,
    /// The vertex.
    pub from: V,
}

/// Where a leg ends on an opaque surface: the point `y` on shape `k`, and
/// how the leg's direction was drawn (`None`: it was given).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Landing<V> {
    /// The point.
    pub y: V,
    /// Its shape.
    pub k: u32,
    /// How the direction was drawn.
    pub drawn: Option<Drawn<V>>,
}

/// A straight leg of a path: from `x` along the unit `w` through `medium`,
/// with throughput `beta` at the event that sees it.
#[derive(Debug, Clone, Copy)]
pub struct Leg<G: Geometry> {
    /// Start.
    pub x: G::V,
    /// Direction.
    pub w: G::V,
    /// Medium it runs through.
    pub medium: MediumId,
    /// Throughput.
    pub beta: f64,
}

/// A scattering vertex: where it is, what it leaves, its lobe and frame.
#[derive(Debug)]
pub struct Vertex<G: Geometry> {
    /// Position.
    pub x: G::V,
    /// Medium it lies in.
    pub medium: MediumId,
    /// Primitive it lies on ([`NO_PRIM`] in a medium or at the sensor).
    pub skip: Prim,
    /// The directional integrand.
    pub lobe: G::Lobe,
    /// How its directions turn.
    pub frame: Frame,
    /// The direction the path arrived along.
    pub w_in: G::V,
    /// Throughput, the lobe's weight included: a term `f(η) X(η)/p(η)`
    /// estimated at the vertex counts `beta · pdf(η)/p(η) · X(η)`.
    pub beta: f64,
    /// Whether this is the irradiance sensor (whose warp knots are known).
    pub at_sensor: bool,
    /// Whether directions here are drawn with the geometry's sensor density
    /// ([`Geometry::sensor_mixture`]) rather than the lobe's.
    pub mixed: bool,
}

impl<G: Geometry> Vertex<G> {
    /// The ray leaving the vertex along `w`.
    #[inline]
    pub fn ray(&self, w: G::V) -> Ray<G::V> {
        Ray {
            x: self.x,
            w,
            medium: self.medium,
            skip: self.skip,
        }
    }
}

// By hand: a derive would ask `G: Copy` of the geometry itself.
impl<G: Geometry> Clone for Vertex<G> {
    #[inline]
    fn clone(&self) -> Self {
        *self
    }
}

impl<G: Geometry> Copy for Vertex<G> {}

// ANCHOR: hooks
/// What a method does at the loop's events. Every method is a default
/// no-op, so the intensity estimator (`()`) pays nothing for them.
#[allow(unused_variables)]
pub trait Hooks<G: Geometry> {
    /// Whether scattering vertices connect to the lamps (next-event
    /// estimation with MIS); without, lamps count only when hit (plain path
    /// tracing, the reference the tests check next-event estimation with).
    const NEXT_EVENT: bool = true;
    /// Whether the irradiance sensor draws its directions with the
    /// geometry's own density where it has one
    /// ([`Geometry::sensor_mixture`]); the hooks' `scatter` then draws with
    /// it at a vertex marked `mixed`.
    const SENSOR_MIXTURE: bool = false;
    /// A segment from `x` along `w` ends at `hit` (`None`: it escapes).
    #[inline]
    fn boundary(&mut self, g: &G, x: G::V, w: G::V, hit: Option<Hit>) {}
    /// The leg runs through its medium to a boundary at `t_b`, before its
    /// free path is drawn.
    #[inline]
    fn free_path_domain(&mut self, g: &G, rng: &mut PathRng, leg: &Leg<G>, t_b: f64) {}
    /// A derivative walk's deformation and the slots its media's
    /// extinction acts on (`pass`, `arrive`): what the default hooks below
    /// carry along the path, the same in every derivative method. `None`
    /// (the intensity estimator's) makes them no-ops.
    #[inline]
    fn carried(&mut self) -> Option<(&mut Deform<G::V>, SlotSet)> {
        None
    }
    /// A collision at `xi < t_b` along `w` in a medium of extinction `ke`:
    /// by default the vertex is carried along the free path, which keeps
    /// its length.
    #[inline]
    fn collision(&mut self, w: G::V, xi: f64, t_b: f64, ke: f64) {
        if let Some((d, _)) = self.carried() {
            d.carry(xi);
        }
    }
    /// The segment reached its boundary through a medium of extinction `ke`.
    #[inline]
    fn pass(&mut self, ke: f64) {
        if let Some((d, slots)) = self.carried() {
            d.pass(slots, ke);
        }
    }
    /// The vertex moves onto the boundary at distance `t` along `w`.
    #[inline]
    fn arrive(&mut self, w: G::V, t: f64) {
        if let Some((d, slots)) = self.carried() {
            d.arrive(slots, w, t);
        }
    }
    /// A path vertex (figures draw paths with it).
    #[inline]
    fn visit(&mut self, x: G::V) {}
    /// An emission `contribution` is collected.
    #[inline]
    fn emission(&mut self, contribution: f64) {
        if let Some((d, _)) = self.carried() {
            d.collect(contribution);
        }
    }
    /// The leg ends on an opaque surface, at `at`.
    #[inline]
    fn opaque(&mut self, g: &G, rng: &mut PathRng, leg: &Leg<G>, at: Landing<G::V>) {}
    /// The leg crosses the transparent boundary at `y` into `after`.
    #[inline]
    fn interface(&mut self, g: &G, rng: &mut PathRng, leg: &Leg<G>, y: G::V, after: MediumId) {}
    /// The leg reaches the reflector of shape `k` at the vertex `v` (before
    /// the vertex's connection and direction).
    #[inline]
    fn reflect(&mut self, g: &G, rng: &mut PathRng, leg: &Leg<G>, v: &Vertex<G>, k: u32) {}
    /// Next-event estimation at `v`: the contribution of one emitter point.
    #[inline]
    fn connect(&mut self, g: &G, rng: &mut PathRng, v: &Vertex<G>) -> f64 {
        next_event(g, rng, v)
    }
    /// The direction leaving `v`.
    #[inline]
    fn scatter(&mut self, g: &G, rng: &mut PathRng, v: &Vertex<G>) -> G::V {
        v.lobe.sample(rng)
    }
    /// The reflector's direction `w` is drawn (after [`Hooks::reflect`]).
    #[inline]
    fn reflected(&mut self, g: &G, rng: &mut PathRng, v: &Vertex<G>, w: G::V) {}
}
// ANCHOR_END: hooks

impl<G: Geometry> Hooks<G> for () {}

/// Russian roulette: `false` ends the path, else the throughput is divided
/// by the survival probability.
#[inline]
pub fn survives(depth: u32, beta: &mut f64, rng: &mut PathRng) -> bool {
    if depth < ROULETTE_DEPTH {
        return true;
    }
    let cap = if depth < ROULETTE_CAP_DEPTH {
        1.0
    } else {
        ROULETTE_CAP
    };
    let q = beta.abs().min(cap);
    if q >= 1.0 {
        return true;
    }
    if q <= 0.0 || rng.random::<f64>() >= q {
        return false;
    }
    *beta /= q;
    true
}

/// The lobe of a Lambertian reflector of albedo `albedo` hit along `w`:
/// a cosine about the normal facing the arriving path.
#[inline]
pub fn reflector_lobe<G: Geometry>(g: &G, p: Prim, y: G::V, w: G::V, albedo: f64) -> G::Lobe {
    let n = g.normal(p, y);
    let n = if w.dot(n) > 0.0 { -n } else { n };
    g.cosine_lobe(n, albedo * <G::V as Vector>::LAMBERT)
}

/// The emitter point drawn for next-event estimation at `v`: the direction
/// to it, its primitive, the light strategy's density there, and the
/// connection's weight before transmittance `beta pdf(η) Le / p_light ·
/// w_MIS` (0 if the lobe or the emitter turns away).
#[inline]
pub fn light_sample<G: Geometry>(
    g: &G,
    rng: &mut PathRng,
    v: &Vertex<G>,
) -> Option<(G::V, Prim, f64)> {
    let (y, p) = g.emitter_point(rng)?;
    let d = y - v.x;
    let w = d * (1.0 / d.length());
    let (f, p_light) = (v.lobe.pdf(w), g.light_pdf(v.x, y, p));
    if f <= 0.0 || !p_light.is_finite() {
        return None;
    }
    let Surface::Emitter { radiance } = g.surface(p) else {
        return None;
    };
    // Weighed against the density the vertex draws its directions with.
    let drawn = if v.mixed {
        g.sensor_mixture_pdf(&v.lobe, w)
    } else {
        f
    };
    Some((
        w,
        p,
        v.beta * (f * radiance / p_light * mis(p_light, drawn)),
    ))
}

/// The transmittance along `ray` to the primitive `target`: `e^{−τ}`
/// through the media crossed, 0 if an opaque primitive comes first. With
/// `hooks`, every segment's boundary speed and transmittance derivative
/// (the derivative walks' connections).
#[inline]
pub fn transmittance<G: Geometry, H: Hooks<G>>(
    g: &G,
    hooks: &mut H,
    ray: Ray<G::V>,
    target: Prim,
) -> f64 {
    transmittance_by(g, hooks, ray, target, |x, w, skip| g.cast(x, w, skip))
}

/// [`transmittance`] with its rays cast by `cast(x, w, skip)` (a connection
/// replays the hits of its shadow walk).
#[inline]
pub fn transmittance_by<G: Geometry, H: Hooks<G>>(
    g: &G,
    hooks: &mut H,
    ray: Ray<G::V>,
    target: Prim,
    mut cast: impl FnMut(G::V, G::V, Prim) -> Option<Hit>,
) -> f64 {
    let Ray {
        mut x,
        w,
        mut medium,
        mut skip,
    } = ray;
    let mut tau = 0.0;
    loop {
        let Some(h) = cast(x, w, skip) else {
            return 0.0;
        };
        hooks.boundary(g, x, w, Some(h));
        if let Some(Coefficients { ke, .. }) = g.coefficients(medium) {
            tau += ke * h.t;
            hooks.pass(ke);
        }
        if h.prim == target {
            return (-tau).exp();
        }
        let k = g.shape(h.prim);
        if g.surface(h.prim) != Surface::Transparent {
            return 0.0;
        }
        hooks.arrive(w, h.t);
        x = x + w * h.t;
        skip = h.prim;
        medium = g.crossed(medium, k);
    }
}

/// Next-event estimation at `v`: one point drawn on the emitters, its
/// radiance through the media, weighted against the lobe's own sampling by
/// the power heuristic.
#[inline]
pub fn next_event<G: Geometry>(g: &G, rng: &mut PathRng, v: &Vertex<G>) -> f64 {
    let Some((w, p, c)) = light_sample(g, rng, v) else {
        return 0.0;
    };
    c * transmittance(g, &mut (), v.ray(w), p)
}

// ANCHOR: walk
/// One path continued along `ray` with throughput `beta`, `drawn` how the
/// last scattering vertex drew the ray's direction (`None`: it was given,
/// so a lamp hit first counts whole). Returns the radiance it collects;
/// `hooks` see every event.
pub fn walk<G: Geometry, H: Hooks<G>>(
    g: &G,
    hooks: &mut H,
    rng: &mut PathRng,
    ray: Ray<G::V>,
    mut beta: f64,
    mut drawn: Option<Drawn<G::V>>,
) -> f64 {
    let _recorded = record::begin(ray.x);
    let Ray {
        mut x,
        mut w,
        mut medium,
        mut skip,
    } = ray;
    let mut depth = 0;
    let mut total = 0.0;
    loop {
        let hit = g.cast(x, w, skip);
        let t_b = hit.map_or(f64::INFINITY, |h| h.t);
        hooks.boundary(g, x, w, hit);
        if let Some(Coefficients { ks, ke }) = g.coefficients(medium) {
            if hit.is_some() {
                let leg = Leg { x, w, medium, beta };
                hooks.free_path_domain(g, rng, &leg, t_b);
            }
            // A path escaping a medium (rounding) keeps the plain rate: its
            // pass weight would have no bound.
            let mu = if hit.is_some() {
                collision_rate(ks, g.medium_chord(medium))
            } else {
                ks
            };
            let xi = free_path(mu, rng);
            if xi < t_b {
                beta *= ks / mu * (-(ke - mu) * xi).exp();
                hooks.collision(w, xi, t_b, ke);
                x = x + w * xi;
                record::vertex(x);
                hooks.visit(x);
                let v = Vertex {
                    x,
                    medium,
                    skip: NO_PRIM,
                    lobe: g.phase_lobe(medium, w),
                    w_in: w,
                    frame: Frame::Incoming,
                    beta,
                    at_sensor: false,
                    mixed: false,
                };
                if H::NEXT_EVENT {
                    total += hooks.connect(g, rng, &v);
                }
                w = hooks.scatter(g, rng, &v);
                drawn = H::NEXT_EVENT.then(|| Drawn {
                    pdf: v.lobe.pdf(w),
                    from: x,
                });
                skip = NO_PRIM;
                depth += 1;
                if !survives(depth, &mut beta, rng) {
                    return total;
                }
                continue;
            }
            beta *= (-(ke - mu) * t_b).exp();
            hooks.pass(ke);
        }
        let Some(h) = hit else {
            // Leaving the scene: the path's last leg, cut at the scene's size.
            let end = x + w * (2.0 * g.size());
            record::vertex(end);
            hooks.visit(end);
            return total;
        };
        hooks.arrive(w, h.t);
        let leg = Leg { x, w, medium, beta };
        x = x + w * h.t;
        record::vertex(x);
        hooks.visit(x);
        skip = h.prim;
        let k = g.shape(h.prim);
        match g.surface(h.prim) {
            Surface::Emitter { radiance } => {
                hooks.opaque(g, rng, &leg, Landing { y: x, k, drawn });
                let weight = drawn.map_or(1.0, |d| mis(d.pdf, g.light_pdf(d.from, x, h.prim)));
                let contribution = beta * radiance * weight;
                hooks.emission(contribution);
                return total + contribution;
            }
            Surface::Absorber => {
                hooks.opaque(g, rng, &leg, Landing { y: x, k, drawn });
                return total;
            }
            Surface::Transparent => {
                let next = g.crossed(medium, k);
                hooks.interface(g, rng, &leg, x, next);
                medium = next;
            }
            Surface::Reflector { .. } if behind_solid(g, h.prim, x, w) => {
                hooks.opaque(g, rng, &leg, Landing { y: x, k, drawn });
                return total;
            }
            Surface::Reflector { albedo } => {
                let lobe = reflector_lobe(g, h.prim, x, w, albedo);
                beta *= lobe.weight();
                let v = Vertex {
                    x,
                    medium,
                    skip,
                    lobe,
                    w_in: w,
                    frame: Frame::Surface(k),
                    beta,
                    at_sensor: false,
                    mixed: false,
                };
                hooks.reflect(g, rng, &leg, &v, k);
                if H::NEXT_EVENT {
                    total += hooks.connect(g, rng, &v);
                }
                w = hooks.scatter(g, rng, &v);
                hooks.reflected(g, rng, &v, w);
                drawn = H::NEXT_EVENT.then(|| Drawn {
                    pdf: lobe.pdf(w),
                    from: x,
                });
                depth += 1;
                if !survives(depth, &mut beta, rng) {
                    return total;
                }
            }
        }
    }
}
// ANCHOR_END: walk

/// Whether a ray along `w` meets primitive `p` at `y` from behind a solid
/// ([`Geometry::solid`]): a sight line through a corner (the sensor in the
/// plane of a face, say) that rounding carried inside. The radiance there
/// is irrelevant (nothing outside sees it), so the back is black; left lit,
/// a closed reflector of albedo 1 kept the path for the roulette's 10⁵
/// events (rendering took 10⁴ times the intensity estimator's time).
#[inline]
pub(super) fn behind_solid<G: Geometry>(g: &G, p: Prim, y: G::V, w: G::V) -> bool {
    g.solid(p) && w.dot(g.normal(p, y)) > 0.0
}

/// How many hits on primitives that hold a boundary point a sight line to
/// it passes ([`reach`], and flatland's `Scene::sees_corner`): a corner
/// has two segments and an edge two faces, and rounding may meet each
/// once; past that the line is taken as blocked rather than walked on.
pub const HOLDING_PASSES: u32 = 4;

/// Whether `q` is visible from `x` (in `medium`, leaving `skip`): the
/// transmittance to it and the medium there.
pub fn reach<G: Geometry>(
    g: &G,
    mut x: G::V,
    q: G::V,
    mut medium: MediumId,
    mut skip: Prim,
    holds: impl Fn(Prim) -> bool,
) -> Option<(f64, MediumId)> {
    let d = q - x;
    let mut left = d.length();
    let w = d * (1.0 / left);
    let mut tau = 0.0;
    // Hits on primitives that hold q pass (they meet the sight line only
    // at q, so a hit short of it is rounding; see `Boundaries::holds`).
    let mut passes = 0;
    loop {
        let ke = g.coefficients(medium).map_or(0.0, |c| c.ke);
        match g.cast(x, w, skip) {
            Some(h) if h.t < left * (1.0 - super::tolerance::SHORT_OF_END) => {
                let opaque = g.surface(h.prim) != Surface::Transparent;
                if opaque && !(passes < HOLDING_PASSES && holds(h.prim)) {
                    return None;
                }
                tau += ke * h.t;
                left -= h.t;
                x = x + w * h.t;
                skip = h.prim;
                if opaque {
                    passes += 1;
                } else {
                    medium = g.crossed(medium, g.shape(h.prim));
                }
            }
            _ => return Some(((-(tau + ke * left)).exp(), medium)),
        }
    }
}
