//! The differentiated backward walk shared by the *rendering*,
//! *expectation* and *transport* estimators. Every vertex of the path carries, per parameter
//! `j`, a velocity `u_j = ∂x/∂π_j` and its outgoing direction an angular
//! velocity `φ̇_j`: a choice of how the sampled path deforms when `π_j`
//! changes. The path weight is differentiated along that deformation (the
//! running score `Λ_j`), and whatever the deformation does not carry along
//! becomes a boundary term:
//!
//! - **free paths** inside a medium run on `[0, t_b]`, `t_b` the distance to
//!   the next boundary, whose velocity `ṫ_b` follows from the boundary's
//!   motion. *Expectation* stretches the domain (`ξ̇ = ξ ṫ_b / t_b`, score
//!   `ṫ_b/t_b − κe ξ̇`), as on the rod; *rendering* keeps `ξ` fixed and adds
//!   the Leibniz term `κs e^{−κe t_b} L_s(t_b⁻) ṫ_b`, `L_s` from a nested
//!   path;
//! - **directions** at the sensor, at reflectors and at collisions are
//!   integrated over the circle, where the integrand jumps at the corners of
//!   opaque shapes seen from the vertex. *Rendering* turns directions with
//!   the local frame and adds, for one corner drawn at random, the jump
//!   `f (L⁻ − L⁺)` times the corner's angular velocity relative to the frame,
//!   `L⁻`, `L⁺` from two nested paths just either side (double
//!   randomisation). *Expectation* moves directions with a warp: the
//!   piecewise-linear field on the circle through the angular velocities of
//!   the visible corners (and of the frame at the horizons), continuous, so
//!   no boundary term is left; its slope enters the score.
//!
//! Book: chapter "Flatland", sections "One deformation, three estimators" and
//! "The warp field".
// Slots index several parallel per-parameter arrays at once; index loops
// read like the formulas.
#![allow(clippy::needless_range_loop)]
use super::geometry::{NO_SEGMENT, cross, perp};
use super::scene::{MAX_PARAMETERS, Phase, Scene, Sensor, Surface};
use super::trace::{
    cosine_direction, crossed, phase_direction, phase_log_slope, phase_value, radiance, survives,
};
use crate::rng::{PathRng, free_path};
use glam::DVec2;
use rand::RngExt;

/// Derivative slots a walk carries: every parameter, then the sensor's two
/// gradient axes.
pub(crate) const MAX_SLOTS: usize = MAX_PARAMETERS + 2;

/// Half-angle (radians) between the two nested paths of a corner's jump.
const JUMP_EPS: f64 = 1e-7;

/// How the path deforms with the parameters, and what is left as boundary
/// terms.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Scheme {
    /// Fixed free paths and frame-attached directions; boundary terms by
    /// double randomisation.
    Rendering,
    /// Stretched free paths and the corner warp; no boundary term.
    Expectation,
    /// The path stays fixed in space (Eulerian): sources where it meets a
    /// moving boundary, coupled to the radiance gradient there.
    Transport,
}

/// What a walk differentiates: the scene's parameters and optionally the
/// sensor position (`∂I/∂x`, `∂I/∂y`).
#[derive(Debug, Clone)]
pub(crate) struct Slots {
    /// Number of parameters.
    pub params: usize,
    /// Whether the two gradient slots follow.
    pub gradient: bool,
    /// Indices (into `scene.corners()`) of the corners of moving shapes.
    pub moving_corners: Vec<u32>,
    /// The corners visible from an irradiance sensor in front of it, by
    /// angle from +x: the warp's knots there, the same for every path.
    pub sensor_knots: Vec<Knot>,
    /// Per shape, the slots that move it (bit `j` for slot `j`).
    pub shape_slots: Vec<u32>,
}

impl Slots {
    pub(crate) fn new(scene: &Scene, gradient: bool) -> Slots {
        let params = scene.parameters().len();
        let moving = |k: u32| (0..params).any(|j| scene.parameter_shape(j) == k);
        let moving_corners = scene
            .corners()
            .iter()
            .enumerate()
            .filter(|(_, c)| moving(c.1))
            .map(|(i, _)| i as u32)
            .collect();
        let mut sensor_knots: Vec<Knot> = match scene.sensor() {
            Sensor::Irradiance { point, normal } => scene
                .corners()
                .iter()
                .filter(|&&(q, _)| (q - point).dot(normal) > 0.0)
                .filter(|&&(q, _)| scene.visible(point, q, NO_SEGMENT))
                .map(|&(q, k)| ((q - point).y.atan2((q - point).x), q, k))
                .collect(),
            Sensor::Radiance { .. } => Vec::new(),
        };
        sensor_knots.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut shape_slots = vec![0u32; scene.shapes().len()];
        for j in 0..params {
            shape_slots[scene.parameter_shape(j) as usize] |= 1 << j;
        }
        Slots {
            shape_slots,
            params,
            gradient,
            moving_corners,
            sensor_knots,
        }
    }

    /// Number of derivative slots.
    #[inline]
    pub(crate) fn len(&self) -> usize {
        self.params + if self.gradient { 2 } else { 0 }
    }

    /// Velocity of the material point `q` of shape `k` for slot `j`.
    #[inline]
    fn velocity(&self, scene: &Scene, j: usize, k: u32, q: DVec2) -> DVec2 {
        if j < self.params && scene.parameter_shape(j) == k {
            scene.parameters()[j].motion.velocity(q)
        } else {
            DVec2::ZERO
        }
    }

    /// Turning rate of shape `k`'s directions for slot `j`.
    #[inline]
    fn spin(&self, scene: &Scene, j: usize, k: u32) -> f64 {
        if j < self.params && scene.parameter_shape(j) == k {
            scene.parameters()[j].motion.spin()
        } else {
            0.0
        }
    }

    /// Velocity of the sensor point for slot `j`.
    #[inline]
    fn sensor_velocity(&self, j: usize) -> DVec2 {
        match j.checked_sub(self.params) {
            Some(0) => DVec2::X,
            Some(1) => DVec2::Y,
            _ => DVec2::ZERO,
        }
    }
}

/// The integrand over directions at a vertex, up to the radiance.
#[derive(Debug, Clone, Copy)]
enum Lobe {
    /// `c · (ω·n)⁺`: the sensor (`c = 1`) or a Lambertian reflector
    /// (`c = ρ/2`).
    Cosine { n: DVec2, c: f64 },
    /// `p(ω·w_in)` at a collision.
    Phase { phase: Phase, w_in: DVec2 },
}

impl Lobe {
    #[inline]
    fn value(&self, w: DVec2) -> f64 {
        match *self {
            Lobe::Cosine { n, c } => c * w.dot(n).max(0.0),
            Lobe::Phase { phase, w_in } => phase_value(phase, w.dot(w_in)),
        }
    }

    /// Integrand over density of the sampled direction.
    #[inline]
    fn weight(&self) -> f64 {
        match *self {
            Lobe::Cosine { c, .. } => 2.0 * c,
            Lobe::Phase { .. } => 1.0,
        }
    }

    #[inline]
    fn sample(&self, rng: &mut PathRng) -> DVec2 {
        match *self {
            Lobe::Cosine { n, .. } => cosine_direction(n, rng),
            Lobe::Phase { phase, w_in } => phase_direction(phase, w_in, rng),
        }
    }

    /// `∂ ln f / ∂φ` at `w`: how the integrand changes when `w` turns
    /// relative to the lobe's frame.
    #[inline]
    fn log_slope(&self, w: DVec2) -> f64 {
        match *self {
            Lobe::Cosine { n, .. } => -cross(n, w) / w.dot(n),
            Lobe::Phase { phase, w_in } => phase_log_slope(phase, w.dot(w_in), cross(w_in, w)),
        }
    }

    /// Angles from `w` to the lobe's horizon counter-clockwise and clockwise
    /// (`2π` for the full circle). Horizons are fixed in the lobe's frame, so
    /// the warp they pin is one field whatever direction was drawn.
    #[inline]
    fn horizons(&self, w: DVec2) -> (f64, f64) {
        match *self {
            Lobe::Cosine { n, .. } => {
                // φ − φ_n in (−π/2, π/2).
                let a = cross(n, w).atan2(n.dot(w));
                (
                    std::f64::consts::FRAC_PI_2 - a,
                    std::f64::consts::FRAC_PI_2 + a,
                )
            }
            // The whole circle: a knot found one way is found the other way
            // too, and none found means no corner at all.
            Lobe::Phase { .. } => (std::f64::consts::TAU, std::f64::consts::TAU),
        }
    }
}

/// A knot of the warp: angle from the sampled direction, corner, shape.
type Knot = (f64, DVec2, u32);

/// A monotone stand-in for the counter-clockwise angle in `[0, 4)` of a
/// vector with cosine part `c` and sine part `s` relative to a direction.
#[inline]
fn pseudo_angle(c: f64, s: f64) -> f64 {
    let t = c / (c.abs() + s.abs());
    if s >= 0.0 { 1.0 - t } else { 3.0 + t }
}

/// Per-slot state of a walk.
struct Deriv {
    /// Vertex velocity `∂x/∂π_j`.
    u: [DVec2; MAX_SLOTS],
    /// Angular velocity of the current direction.
    phid: [f64; MAX_SLOTS],
    /// Running score `Λ_j`: derivative of the log weight along the
    /// deformation.
    score: [f64; MAX_SLOTS],
    /// Boundary terms collected so far.
    boundary: [f64; MAX_SLOTS],
    /// Slots whose `u`, `φ̇` or score may be non-zero: the others are
    /// skipped (their updates would add exact zeros).
    live: u32,
}

/// The slots set in `mask`.
#[inline]
fn bits(mut mask: u32) -> impl Iterator<Item = usize> {
    std::iter::from_fn(move || {
        (mask != 0).then(|| {
            let j = mask.trailing_zeros() as usize;
            mask &= mask - 1;
            j
        })
    })
}

/// How slot `j`'s path deforms.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Rule {
    /// Fixed free paths, frame-attached directions (rendering).
    Fixed,
    /// Stretched free paths, warped directions (expectation).
    Stretch,
    /// No deformation at all: the path is fixed in space (transport).
    Euler,
}

impl Deriv {
    fn new() -> Deriv {
        Deriv {
            u: [DVec2::ZERO; MAX_SLOTS],
            phid: [0.0; MAX_SLOTS],
            score: [0.0; MAX_SLOTS],
            boundary: [0.0; MAX_SLOTS],
            live: 0,
        }
    }
}

/// A derivative walk: its context.
pub(crate) struct Walk<'a> {
    pub scene: &'a Scene,
    pub slots: &'a Slots,
    pub scheme: Scheme,
    /// The scene stands still: a nested walk that estimates the gradient of
    /// the radiance along given start velocities (transport's coupling).
    pub frozen: bool,
}

impl Walk<'_> {
    #[inline]
    fn rule(&self, j: usize) -> Rule {
        match self.scheme {
            Scheme::Rendering => Rule::Fixed,
            Scheme::Expectation => Rule::Stretch,
            Scheme::Transport if j < self.slots.params && !self.frozen => Rule::Euler,
            Scheme::Transport => Rule::Fixed,
        }
    }

    /// Velocity of the material point `q` of shape `k` for slot `j`.
    #[inline]
    fn velocity(&self, j: usize, k: u32, q: DVec2) -> DVec2 {
        if self.frozen {
            DVec2::ZERO
        } else {
            self.slots.velocity(self.scene, j, k, q)
        }
    }

    /// The slots that move shape `k` (none in the frozen scene).
    #[inline]
    fn moves(&self, k: u32) -> u32 {
        if self.frozen {
            0
        } else {
            self.slots.shape_slots[k as usize]
        }
    }

    /// Turning rate of shape `k` for slot `j`.
    #[inline]
    fn spin(&self, j: usize, k: u32) -> f64 {
        if self.frozen {
            0.0
        } else {
            self.slots.spin(self.scene, j, k)
        }
    }

    /// One path from the sensor: writes `I` into `out[0]` and the derivative
    /// of slot `j` into `out[1 + j]`.
    pub(crate) fn sample(&self, rng: &mut PathRng, out: &mut [f64]) {
        let scene = self.scene;
        let n = self.slots.len();
        let mut d = Deriv::new();
        for j in 0..n {
            d.u[j] = self.slots.sensor_velocity(j);
            if d.u[j] != DVec2::ZERO {
                d.live |= 1 << j;
            }
        }
        let x = scene.sensor().point();
        let medium = scene.sensor_medium();
        let (w, beta) = match scene.sensor() {
            Sensor::Radiance { direction, .. } => (direction, 1.0),
            Sensor::Irradiance { normal, .. } => {
                let lobe = Lobe::Cosine { n: normal, c: 1.0 };
                let fixed = [0.0; MAX_SLOTS];
                let w = self.directions(
                    rng, &mut d, n, x, medium, NO_SEGMENT, &lobe, &fixed, 1.0, true,
                );
                (w, lobe.weight())
            }
        };
        out[0] = self.trace(rng, &mut d, n, x, w, medium, NO_SEGMENT, beta);
        out[1..=n].copy_from_slice(&d.boundary[..n]);
    }

    /// Continues a path from `x` along `w` with throughput `beta`: returns
    /// the radiance contribution and adds the derivatives of its first `n`
    /// slots to `d.boundary`.
    #[allow(clippy::too_many_arguments)]
    fn trace(
        &self,
        rng: &mut PathRng,
        d: &mut Deriv,
        n: usize,
        mut x: DVec2,
        mut w: DVec2,
        mut medium: Option<u32>,
        mut skip: u32,
        mut beta: f64,
    ) -> f64 {
        let scene = self.scene;
        let mut intensity = 0.0;
        let mut tb_dot: [f64; MAX_SLOTS];
        let mut depth = 0u32;
        for j in 0..n {
            if d.u[j] != DVec2::ZERO || d.phid[j] != 0.0 || d.score[j] != 0.0 {
                d.live |= 1 << j;
            }
        }
        loop {
            let hit = scene.cast(x, w, skip);
            let wp = perp(w);
            let t_b = hit.map_or(f64::INFINITY, |h| h.t);
            if let Some(h) = hit {
                // The hit point stays on the moving boundary: (ẏ − v)·n = 0
                // with ẏ = u + ṫ_b w + t_b φ̇ w⊥.
                let y = x + h.t * w;
                let k = scene.owner(h.segment);
                let nb = scene.normal(h.segment);
                let wn = w.dot(nb);
                tb_dot = [0.0; MAX_SLOTS];
                for j in bits(d.live | self.moves(k)) {
                    let v = self.velocity(j, k, y);
                    tb_dot[j] = (v - d.u[j] - h.t * d.phid[j] * wp).dot(nb) / wn;
                    if tb_dot[j] != 0.0 {
                        d.live |= 1 << j;
                    }
                }
            } else {
                tb_dot = [0.0; MAX_SLOTS];
            }
            if let Some(m) = scene.medium(medium) {
                let leibniz = (0..n).any(|j| self.rule(j) == Rule::Fixed && tb_dot[j] != 0.0);
                if leibniz && m.ks > 0.0 && hit.is_some() {
                    // Leibniz term at the end of the free-path domain: the
                    // in-scattered radiance just before the boundary.
                    // Just before the boundary, but farther than the
                    // caster's T_MIN even for a nested walk that starts a
                    // hair in front of a surface.
                    let end = x + (t_b - (1e-9 * scene.size()).min(0.5 * t_b)) * w;
                    let wi = phase_direction(m.phase, w, rng);
                    let ls = radiance(scene, rng, end, wi, medium, NO_SEGMENT);
                    let term = beta * m.ks * (-m.ke * t_b).exp() * ls;
                    for j in bits(d.live) {
                        if self.rule(j) == Rule::Fixed {
                            d.boundary[j] += term * tb_dot[j];
                        }
                    }
                }
                let xi = free_path(m.ks, rng);
                let ka = m.ke - m.ks;
                if xi < t_b {
                    beta *= (-ka * xi).exp();
                    for j in bits(d.live) {
                        let xi_dot = match self.rule(j) {
                            Rule::Stretch => {
                                d.score[j] += tb_dot[j] / t_b;
                                xi / t_b * tb_dot[j]
                            }
                            Rule::Fixed | Rule::Euler => 0.0,
                        };
                        d.score[j] -= m.ke * xi_dot;
                        d.u[j] += xi_dot * w + xi * d.phid[j] * wp;
                    }
                    x += xi * w;
                    skip = NO_SEGMENT;
                    let lobe = Lobe::Phase {
                        phase: m.phase,
                        w_in: w,
                    };
                    let spin = d.phid;
                    w = self.directions(rng, d, n, x, medium, skip, &lobe, &spin, beta, false);
                    depth += 1;
                    if !survives(depth, &mut beta, rng) {
                        break;
                    }
                    continue;
                }
                beta *= (-ka * t_b).exp();
                for j in bits(d.live) {
                    if self.rule(j) != Rule::Euler {
                        d.score[j] -= m.ke * tb_dot[j];
                    }
                }
            }
            let Some(h) = hit else { break };
            let before = x;
            for j in bits(d.live) {
                if self.rule(j) != Rule::Euler {
                    d.u[j] += tb_dot[j] * w + h.t * d.phid[j] * wp;
                }
            }
            x += h.t * w;
            skip = h.segment;
            let k = scene.owner(h.segment);
            let euler = (0..n).any(|j| self.rule(j) == Rule::Euler && tb_dot[j] != 0.0);
            match scene.shapes()[k as usize].surface {
                Surface::Emitter { radiance } => {
                    if euler {
                        self.surface_gradient(rng, d, n, before, x, w, medium, beta, k);
                    }
                    let contribution = beta * radiance;
                    intensity += contribution;
                    for j in bits(d.live) {
                        d.boundary[j] += contribution * d.score[j];
                    }
                    break;
                }
                Surface::Absorber => {
                    if euler {
                        self.surface_gradient(rng, d, n, before, x, w, medium, beta, k);
                    }
                    break;
                }
                Surface::Transparent => {
                    let next = crossed(scene, medium, k);
                    if euler {
                        self.interface_source(rng, d, n, x, w, medium, next, beta, &tb_dot);
                    }
                    medium = next;
                }
                Surface::Reflector { albedo } => {
                    let nb = scene.normal(h.segment);
                    let nb = if w.dot(nb) > 0.0 { -nb } else { nb };
                    let lobe = Lobe::Cosine {
                        n: nb,
                        c: 0.5 * albedo,
                    };
                    let mut spin = [0.0; MAX_SLOTS];
                    for (j, s) in spin.iter_mut().enumerate().take(n) {
                        *s = self.spin(j, k);
                    }
                    let moving = (0..n).any(|j| {
                        self.rule(j) == Rule::Euler
                            && (spin[j] != 0.0 || self.velocity(j, k, x) != DVec2::ZERO)
                    });
                    if moving {
                        self.surface_gradient(rng, d, n, before, x, w, medium, beta, k);
                        // The material derivative of the reflected
                        // radiance: corners seen from the moving point.
                        for j in 0..n {
                            if self.rule(j) == Rule::Euler {
                                d.u[j] = self.velocity(j, k, x);
                            }
                        }
                    }
                    w = self.directions(rng, d, n, x, medium, skip, &lobe, &spin, beta, false);
                    if moving {
                        // … and its regular part: the radiance reflected at
                        // the moving point in the turning frame, by a
                        // nested walk in the frozen scene.
                        let mut g = Deriv::new();
                        for j in 0..n {
                            if self.rule(j) == Rule::Euler {
                                g.u[j] = d.u[j];
                                g.phid[j] = spin[j];
                                d.u[j] = DVec2::ZERO;
                            }
                        }
                        self.frozen().trace(rng, &mut g, n, x, w, medium, skip, 1.0);
                        for j in 0..n {
                            if self.rule(j) == Rule::Euler {
                                d.boundary[j] += beta * lobe.weight() * g.boundary[j];
                            }
                        }
                    }
                    for j in 0..n {
                        if self.rule(j) == Rule::Euler {
                            d.phid[j] = 0.0;
                        }
                    }
                    beta *= lobe.weight();
                    depth += 1;
                    if !survives(depth, &mut beta, rng) {
                        break;
                    }
                }
            }
        }
        intensity
    }

    /// The expectation method's warp at the irradiance sensor: the angular
    /// velocity `V_j(φ)` of direction `w` for every slot (figures, tests).
    pub(crate) fn sensor_warp(&self, w: DVec2, out: &mut [f64]) {
        let n = self.slots.len();
        let mut d = Deriv::new();
        let (x, lobe) = match self.scene.sensor() {
            Sensor::Irradiance { point, normal } => (point, Lobe::Cosine { n: normal, c: 1.0 }),
            Sensor::Radiance { point, direction } => (
                point,
                Lobe::Phase {
                    phase: Phase::Isotropic,
                    w_in: direction,
                },
            ),
        };
        for j in 0..n {
            d.u[j] = self.slots.sensor_velocity(j);
            if d.u[j] != DVec2::ZERO {
                d.live |= 1 << j;
            }
        }
        let at_sensor = matches!(self.scene.sensor(), Sensor::Irradiance { .. });
        self.warp(
            &mut d,
            n,
            x,
            NO_SEGMENT,
            &lobe,
            &[0.0; MAX_SLOTS],
            w,
            at_sensor,
        );
        out[..n].copy_from_slice(&d.phid[..n]);
    }

    /// The same walk in the frozen scene, rendering rules for every slot.
    fn frozen(&self) -> Walk<'_> {
        Walk {
            scene: self.scene,
            slots: self.slots,
            scheme: Scheme::Rendering,
            frozen: true,
        }
    }

    /// Transport's coupling at an opaque moving boundary hit at `y` from
    /// `x` along `w`: the source `−v·∇L(y⁻, w)` for every Eulerian slot,
    /// the gradient by a nested walk in the frozen scene started just before
    /// `y` with velocity `v`.
    #[allow(clippy::too_many_arguments)]
    fn surface_gradient(
        &self,
        rng: &mut PathRng,
        d: &mut Deriv,
        n: usize,
        x: DVec2,
        y: DVec2,
        w: DVec2,
        medium: Option<u32>,
        beta: f64,
        k: u32,
    ) {
        let mut g = Deriv::new();
        for j in 0..n {
            if self.rule(j) == Rule::Euler {
                g.u[j] = self.velocity(j, k, y);
            }
        }
        let start = y - (1e-9 * self.scene.size()).min(0.5 * (y - x).length()) * w;
        self.frozen()
            .trace(rng, &mut g, n, start, w, medium, NO_SEGMENT, 1.0);
        for j in 0..n {
            if self.rule(j) == Rule::Euler {
                d.boundary[j] -= beta * g.boundary[j];
            }
        }
    }

    /// Transport's source where the path crosses a moving medium boundary
    /// at `y` from medium `before` into `after`: the interface advancing by
    /// `ṫ_b` along the ray swaps the coefficients of the points it sweeps,
    /// `s ∋ ṫ_b [κs,b L_s,b − κs,a L_s,a − (κe,b − κe,a) L(y, w)]`; the
    /// last term multiplies what the path goes on to collect (a score), the
    /// in-scattered radiances come from one nested path on each side.
    #[allow(clippy::too_many_arguments)]
    fn interface_source(
        &self,
        rng: &mut PathRng,
        d: &mut Deriv,
        n: usize,
        y: DVec2,
        w: DVec2,
        before: Option<u32>,
        after: Option<u32>,
        beta: f64,
        tb_dot: &[f64; MAX_SLOTS],
    ) {
        let scene = self.scene;
        let eps = 1e-9 * scene.size();
        let side = |rng: &mut PathRng, medium: Option<u32>, at: DVec2| match scene.medium(medium) {
            Some(m) if m.ks > 0.0 => {
                let wi = phase_direction(m.phase, w, rng);
                m.ks * radiance(scene, rng, at, wi, medium, NO_SEGMENT)
            }
            _ => 0.0,
        };
        let ke = |medium: Option<u32>| scene.medium(medium).map_or(0.0, |m| m.ke);
        let scattered = side(rng, before, y - eps * w) - side(rng, after, y + eps * w);
        let dke = ke(before) - ke(after);
        for j in 0..n {
            if self.rule(j) == Rule::Euler {
                d.boundary[j] += beta * tb_dot[j] * scattered;
                d.score[j] -= dke * tb_dot[j];
            }
        }
    }

    /// Samples the outgoing direction at vertex `x` from `lobe`, whose frame
    /// turns at `spin[j]`; sets the direction's angular velocity, and adds
    /// the boundary term (*rendering*) or the warp's score (*expectation*).
    #[allow(clippy::too_many_arguments)]
    fn directions(
        &self,
        rng: &mut PathRng,
        d: &mut Deriv,
        n: usize,
        x: DVec2,
        medium: Option<u32>,
        skip: u32,
        lobe: &Lobe,
        spin: &[f64; MAX_SLOTS],
        beta: f64,
        at_sensor: bool,
    ) -> DVec2 {
        if n == 0 {
            // Nothing to differentiate: plain tracing.
            return lobe.sample(rng);
        }
        match self.scheme {
            Scheme::Rendering | Scheme::Transport => {
                self.corner_jump(rng, d, n, x, medium, skip, lobe, spin, beta);
                let w = lobe.sample(rng);
                d.phid[..n].copy_from_slice(&spin[..n]);
                for j in 0..n {
                    if spin[j] != 0.0 {
                        d.live |= 1 << j;
                    }
                }
                w
            }
            Scheme::Expectation => {
                let w = lobe.sample(rng);
                self.warp(d, n, x, skip, lobe, spin, w, at_sensor);
                w
            }
        }
    }

    /// Angular velocity, for slot `j`, of the direction from `x` (moving at
    /// `u`) to the corner `q` of shape `k`.
    #[inline]
    fn corner_rate(&self, j: usize, x: DVec2, u: DVec2, q: DVec2, k: u32) -> f64 {
        let r = q - x;
        cross(r, self.velocity(j, k, q) - u) / r.length_squared()
    }

    /// The boundary term of the directional integral: one corner drawn
    /// uniformly, its jump by two nested paths.
    #[allow(clippy::too_many_arguments)]
    fn corner_jump(
        &self,
        rng: &mut PathRng,
        d: &mut Deriv,
        n: usize,
        x: DVec2,
        medium: Option<u32>,
        skip: u32,
        lobe: &Lobe,
        spin: &[f64; MAX_SLOTS],
        beta: f64,
    ) {
        let scene = self.scene;
        let corners = scene.corners();
        // A vertex that stays put in a frame that stays put sees only the
        // corners of moving shapes move.
        let mut turning = 0u32;
        for j in 0..n {
            if d.u[j] != DVec2::ZERO || spin[j] != 0.0 {
                turning |= 1 << j;
            }
        }
        let moving = turning != 0;
        let count = if moving {
            corners.len()
        } else {
            self.slots.moving_corners.len()
        };
        if count == 0 {
            return;
        }
        let pick = rng.random_range(0..count);
        let (q, k) = if moving {
            corners[pick]
        } else {
            corners[self.slots.moving_corners[pick] as usize]
        };
        let wq = (q - x).normalize();
        let f = lobe.value(wq);
        if f <= 0.0 || !scene.visible(x, q, skip) {
            return;
        }
        let mut rates = [0.0; MAX_SLOTS];
        let mut any = false;
        let slots = turning | self.moves(k);
        for j in bits(slots) {
            rates[j] = self.corner_rate(j, x, d.u[j], q, k) - spin[j];
            any |= rates[j] != 0.0;
        }
        if !any {
            return;
        }
        let minus = radiance(
            scene,
            rng,
            x,
            DVec2::from_angle(-JUMP_EPS).rotate(wq),
            medium,
            skip,
        );
        let plus = radiance(
            scene,
            rng,
            x,
            DVec2::from_angle(JUMP_EPS).rotate(wq),
            medium,
            skip,
        );
        // d/dπ ∫ f L dφ ∋ (f L)(φ_q⁻) φ̇_q − (f L)(φ_q⁺) φ̇_q.
        let term = beta * f * (minus - plus) * count as f64;
        for j in bits(slots) {
            d.boundary[j] += term * rates[j];
        }
    }

    /// The warp at `x` for the sampled direction `w`: the nearest visible
    /// corner (or horizon) on each side are the knots; the field is linear
    /// in angle between them.
    #[allow(clippy::too_many_arguments)]
    fn warp(
        &self,
        d: &mut Deriv,
        n: usize,
        x: DVec2,
        skip: u32,
        lobe: &Lobe,
        spin: &[f64; MAX_SLOTS],
        w: DVec2,
        at_sensor: bool,
    ) {
        let (h_ccw, h_cw) = lobe.horizons(w);
        let (ccw, cw) = if at_sensor {
            self.sensor_knots(w, (h_ccw, h_cw))
        } else {
            self.nearest_knots(x, skip, w, (h_ccw, h_cw))
        };
        let slope_log = lobe.log_slope(w);
        // Slots with a non-zero knot value: live ones, those moving a knot's
        // shape, those whose frame turns. The others keep V = 0.
        let mut slots = d.live;
        for kn in [ccw, cw].into_iter().flatten() {
            slots |= self.moves(kn.2);
        }
        for j in 0..n {
            if spin[j] != 0.0 {
                slots |= 1 << j;
            }
        }
        d.live |= slots;
        for j in bits(slots) {
            // Knot values: a corner's angular velocity, or the frame's at a
            // horizon (which keeps the integrand's domain in place).
            let (db, vb) = match ccw {
                Some((delta, q, k)) => (delta, self.corner_rate(j, x, d.u[j], q, k)),
                None => (h_ccw, spin[j]),
            };
            let (da, va) = match cw {
                Some((delta, q, k)) => (delta, self.corner_rate(j, x, d.u[j], q, k)),
                None => (h_cw, spin[j]),
            };
            let span = da + db;
            let slope = (vb - va) / span;
            let v = va + slope * da;
            d.score[j] += slope + slope_log * (v - spin[j]);
            d.phid[j] = v;
        }
    }

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
        (h_ccw, h_cw): (f64, f64),
    ) -> (Option<Knot>, Option<Knot>) {
        let scene = self.scene;
        let corners = scene.corners();
        let limit = |h: f64| {
            if h >= std::f64::consts::TAU {
                4.0
            } else {
                let (s, c) = h.sin_cos();
                pseudo_angle(c, s)
            }
        };
        let (lim_ccw, lim_cw) = (limit(h_ccw), limit(h_cw));
        if let Some(knots) = self.knots_in_triangles(x, skip, w, lim_ccw, lim_cw) {
            return knots;
        }
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
                } else if scene.visible(x, corners[i].0, skip) {
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
        let knot = |i: Option<usize>, sign: f64| {
            i.map(|i| {
                let (q, k) = corners[i];
                let r = q - x;
                let mut a = sign * cross(w, r).atan2(w.dot(r));
                if a <= 0.0 {
                    a += std::f64::consts::TAU;
                }
                (a, q, k)
            })
        };
        (knot(ccw, 1.0), knot(cw, -1.0))
    }

    /// [`Self::nearest_knots`] through the corner grid: the nearest visible
    /// corner on each side is the hit segment's end there or the
    /// smallest-angle corner inside the triangle (vertex, hit point, end);
    /// the module `corners` proves it. `None` (use the scan) without a grid
    /// or when the direction hits nothing opaque.
    fn knots_in_triangles(
        &self,
        x: DVec2,
        skip: u32,
        w: DVec2,
        lim_ccw: f64,
        lim_cw: f64,
    ) -> Option<(Option<Knot>, Option<Knot>)> {
        let scene = self.scene;
        let grid = scene.corner_grid()?;
        let (t, seg, k_hit) = scene.opaque_hit(x, w, skip)?;
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
        let side = |e: DVec2, lim: f64, ccw: bool| -> Option<Knot> {
            let angle = |q: DVec2| {
                let r = q - x;
                let pa = pseudo_angle(w.dot(r), cross(w, r));
                if ccw { pa } else { 4.0 - pa }
            };
            let mut best: Option<(f64, DVec2, u32)> = None;
            let pe = angle(e);
            if pe < lim {
                best = Some((pe, e, k_hit));
            }
            grid.near_triangle(x, p, e, |i| {
                let (q, k) = corners[i as usize];
                let pq = angle(q);
                if pq < lim && best.is_none_or(|b| pq < b.0) && super::corners::inside(x, p, e, q) {
                    best = Some((pq, q, k));
                }
            });
            best.map(|(_, q, k)| {
                let r = q - x;
                let sign = if ccw { 1.0 } else { -1.0 };
                let mut a = sign * cross(w, r).atan2(w.dot(r));
                if a <= 0.0 {
                    a += std::f64::consts::TAU;
                }
                (a, q, k)
            })
        };
        Some((side(e_ccw, lim_ccw, true), side(e_cw, lim_cw, false)))
    }

    /// The neighbours of `w` among the sensor's knots (precomputed: the
    /// sensor does not move).
    fn sensor_knots(&self, w: DVec2, (h_ccw, h_cw): (f64, f64)) -> (Option<Knot>, Option<Knot>) {
        let knots = &self.slots.sensor_knots;
        if knots.is_empty() {
            return (None, None);
        }
        let phi = w.y.atan2(w.x);
        let i = knots.partition_point(|k| k.0 <= phi);
        let tau = std::f64::consts::TAU;
        let (b, b_angle) = if i < knots.len() {
            (knots[i], knots[i].0 - phi)
        } else {
            (knots[0], knots[0].0 + tau - phi)
        };
        let (a, a_angle) = if i > 0 {
            (knots[i - 1], phi - knots[i - 1].0)
        } else {
            (knots[knots.len() - 1], phi - knots[knots.len() - 1].0 + tau)
        };
        (
            (b_angle < h_ccw).then_some((b_angle, b.1, b.2)),
            (a_angle < h_cw && a_angle > 0.0).then_some((a_angle, a.1, a.2)),
        )
    }
}
