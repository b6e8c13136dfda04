//! The sensitivity transport model: `s_j = ∂L/∂π_j` obeys the transport
//! equation of `L`, so for the shape-parameter slots the path stays fixed in
//! space (Eulerian) and collects `s`'s sources where it meets a moving
//! boundary:
//!
//! - at an **opaque** moving boundary hit at `y`: `−v·∇L(y⁻, η)`, the
//!   gradient by a nested walk in the frozen scene started just before `y`
//!   with velocity `v` ([`Rendering`] in a [`SceneMotion::Frozen`] scene);
//! - at a moving **reflector**: the material derivative of the reflected
//!   radiance: the corner terms seen from the moving point, and its regular
//!   part by a nested frozen walk from the moving point in the turning frame;
//! - at a moving **medium boundary**: the interface swaps the coefficients
//!   of the points it sweeps, `ṫ_b [κs,b L_s,b − κs,a L_s,a − (κe,b − κe,a)
//!   L]`, the in-scattered radiances by one nested path on each side.
//!
//! The sensor-position slots (`∂I/∂x`, …) follow rendering's rules.
//! Book: chapter "Flatland: one deformation, three estimators", section
//! "Transport"; in 3D, chapter "Three dimensions", section "Transport in 3D".
use super::deform::{Deform, SlotSet};
use super::derivative_walk::{DerivativeWalk, SceneMotion};
use super::nested::radiance;
use super::rendering::Rendering;
use super::walk::{Drawn, Hooks, Landing, Leg, Ray, Vertex, walk};
use super::{Boundaries, Coefficients, Geometry, Hit, MediumId, NO_PRIM, Vector};
use crate::rng::PathRng;

/// The transport method's hooks: one walk's state, and what it collects at
/// a moving reflector.
pub struct Transport<'a, G: Geometry> {
    /// The walk's state (its scene moves: its shape-parameter slots stay
    /// fixed in space by the method's own rules).
    pub walk: DerivativeWalk<'a, G>,
    /// Whether the reflector just reached moves (its material derivative is
    /// being collected).
    moving_reflector: bool,
}

impl<'a, G: Geometry> Transport<'a, G> {
    /// Hooks over `walk` (zeroed, sensor velocities set, scene moving).
    pub fn new(walk: DerivativeWalk<'a, G>) -> Self {
        Transport {
            walk,
            moving_reflector: false,
        }
    }
}

impl<G: Boundaries> Transport<'_, G> {
    /// Whether a shape-parameter slot's boundary moves on this segment.
    #[inline]
    fn euler_moving(&self) -> bool {
        let walk = &self.walk;
        walk.slots
            .parameter_slots
            .iter()
            .any(|j| walk.d.slots[j].tb_dot != 0.0)
    }

    // ANCHOR: surface_gradient
    /// The source `−v·∇L(y⁻, w)` where the leg hits the opaque moving
    /// boundary of shape `k` at `y` (`at`), for every shape-parameter slot:
    /// the gradient by a nested walk in the frozen scene started just
    /// before `y`.
    fn surface_gradient(&mut self, g: &G, rng: &mut PathRng, leg: &Leg<G>, at: Landing<G::V>) {
        let Landing { y, k, drawn } = at;
        let Leg { x, w, medium, beta } = *leg;
        let walk = &mut self.walk;
        let Some(weight) = walk.scratch.work.admit(rng) else {
            return;
        };
        let mut nested = walk.scratch.take(walk.d.len());
        for j in walk.slots.moving(k).iter() {
            nested.slots[j].u = g.velocity(j, y);
            nested.touch(j);
        }
        let start = Ray {
            x: y - w * g.nudge(y).min(0.5 * (y - x).length()),
            w,
            medium,
            skip: NO_PRIM,
        };
        let nested = self.frozen_walk(g, rng, nested, start, drawn);
        let walk = &mut self.walk;
        for j in walk.slots.parameter_slots.iter() {
            let n = &nested.slots[j];
            let (b, scale) = (n.boundary * weight, n.boundary_scale * weight);
            walk.d.slots[j].add_boundary(-beta * b, (beta * scale).abs());
        }
        walk.scratch.give(nested);
    }
    // ANCHOR_END: surface_gradient

    // ANCHOR: twin_gradient
    /// [`Self::surface_gradient`] at a moving reflector, carried by the
    /// twins: the nested walk would start a hair before `v.x` with the
    /// velocities `v_j(y)` and be subtracted; by linearity the twins take
    /// `−v_j` there and follow the path on. What that walk's first, tiny
    /// leg does is done here: the hit's `ṫ_b` for the start velocity, the
    /// transmittance's and the in-scattering's terms of a medium, and the
    /// arrival on the surface (`u += η ṫ_b`).
    fn twin_gradient(&mut self, g: &G, rng: &mut PathRng, leg: &Leg<G>, v: &Vertex<G>, k: u32) {
        let Leg {
            w, medium, beta, ..
        } = *leg;
        let n = g.normal(v.skip, v.x);
        let wn = w.dot(n);
        if wn == 0.0 {
            return;
        }
        let coefficients = g.coefficients(medium);
        let walk = &mut self.walk;
        // The in-scattered radiance just before the point, shared by the
        // slots (the nested walk's Leibniz term over its first leg).
        let scattered = match coefficients {
            Some(Coefficients { ks, .. }) if ks > 0.0 => match walk.scratch.work.admit(rng) {
                Some(weight) => {
                    let ray = Ray {
                        x: v.x - w * (0.5 * g.nudge(v.x)),
                        w: super::Lobe::sample(&g.phase_lobe(medium, w), rng),
                        medium,
                        skip: NO_PRIM,
                    };
                    let work = &mut walk.scratch.work;
                    beta * ks * radiance(g, work, rng, ray) * weight
                }
                None => 0.0,
            },
            _ => 0.0,
        };
        let ke = coefficients.map_or(0.0, |c| c.ke);
        for j in walk.slots.moving(k).iter() {
            let vj = g.velocity(j, v.x);
            let along = vj.dot(n);
            // As `Deform::boundary_speed` rounds a speed along the surface.
            let tb = if crate::estimator::within_rounding(along, vj.length()) {
                0.0
            } else {
                along / wn
            };
            let t = walk.slots.twin(j);
            let s = &mut walk.d.slots[t];
            if scattered != 0.0 {
                s.add_boundary(scattered * tb, (scattered * tb).abs());
            }
            if ke != 0.0 {
                s.add_score(-ke * tb);
            }
            s.u = s.u - vj + w * tb;
            walk.d.touch(t);
        }
    }
    // ANCHOR_END: twin_gradient

    /// The path's state with each twin's derivative added to its
    /// parameter's.
    pub fn finish(self) -> Deform<G::V> {
        let DerivativeWalk { slots, mut d, .. } = self.walk;
        if slots.twins > 0 {
            for j in slots.parameter_slots.iter() {
                let t = &d.slots[slots.twin(j)];
                let (b, scale) = (t.boundary, t.boundary_scale);
                d.slots[j].add_boundary(b, scale);
            }
        }
        d
    }

    /// A walk in the frozen scene along `ray` that differentiates the start
    /// velocities held in `nested`; returns its state. `drawn`: how the
    /// main path drew the ray's direction, so that a lamp it hits first
    /// carries the main path's MIS weight (the connection estimates the
    /// rest).
    fn frozen_walk(
        &mut self,
        g: &G,
        rng: &mut PathRng,
        nested: Deform<G::V>,
        ray: Ray<G::V>,
        drawn: Option<Drawn<G::V>>,
    ) -> Deform<G::V> {
        let mut hooks = Rendering {
            walk: DerivativeWalk {
                slots: self.walk.slots,
                scene: SceneMotion::Frozen,
                scratch: &mut *self.walk.scratch,
                d: nested,
            },
        };
        walk(g, &mut hooks, rng, ray, 1.0, drawn);
        hooks.walk.d
    }
}

impl<G: Boundaries> Hooks<G> for Transport<'_, G> {
    #[inline]
    fn boundary(&mut self, g: &G, x: G::V, w: G::V, hit: Option<Hit>) {
        self.walk.segment(g, x, w, hit);
    }
    #[inline]
    fn free_path_domain(&mut self, g: &G, rng: &mut PathRng, leg: &Leg<G>, t_b: f64) {
        let rule = self.walk.slots.frozen_scene();
        self.walk.leibniz(g, rule, rng, leg, t_b);
    }
    #[inline]
    fn visit(&mut self, _x: G::V) {
        self.walk.scratch.work.main += 1;
    }
    #[inline]
    fn carried(&mut self) -> Option<(&mut Deform<G::V>, SlotSet)> {
        Some((&mut self.walk.d, self.walk.slots.frozen_scene()))
    }
    #[inline]
    fn opaque(&mut self, g: &G, rng: &mut PathRng, leg: &Leg<G>, at: Landing<G::V>) {
        if self.euler_moving() {
            self.surface_gradient(g, rng, leg, at);
        }
    }
    // ANCHOR: interface
    #[inline]
    fn interface(&mut self, g: &G, rng: &mut PathRng, leg: &Leg<G>, y: G::V, after: MediumId) {
        if !self.euler_moving() {
            return;
        }
        let (w, before, beta) = (leg.w, leg.medium, leg.beta);
        let eps = g.nudge(y);
        let ks = |medium: MediumId| g.coefficients(medium).map_or(0.0, |c| c.ks);
        let walk = &mut self.walk;
        let work = &mut walk.scratch.work;
        let side = |work: &mut _, rng: &mut PathRng, medium: MediumId, at: G::V| {
            if ks(medium) > 0.0 {
                let ray = Ray {
                    x: at,
                    w: super::Lobe::sample(&g.phase_lobe(medium, w), rng),
                    medium,
                    skip: NO_PRIM,
                };
                ks(medium) * radiance(g, work, rng, ray)
            } else {
                0.0
            }
        };
        let ke = |medium: MediumId| g.coefficients(medium).map_or(0.0, |c| c.ke);
        // The in-scattered radiances by nested paths, as the work admits.
        let scattered = if ks(before) > 0.0 || ks(after) > 0.0 {
            match work.admit(rng) {
                Some(weight) => {
                    let l_before = side(work, rng, before, y - w * eps);
                    (l_before - side(work, rng, after, y + w * eps)) * weight
                }
                None => 0.0,
            }
        } else {
            0.0
        };
        let dke = ke(before) - ke(after);
        let d = &mut walk.d;
        for j in walk.slots.parameter_slots.iter() {
            let s = &mut d.slots[j];
            let t = beta * s.tb_dot * scattered;
            s.add_boundary(t, t.abs());
            s.add_score(-dke * s.tb_dot);
            if s.score != 0.0 {
                d.live.insert(j);
            }
        }
    }
    // ANCHOR_END: interface
    #[inline]
    fn reflect(&mut self, g: &G, rng: &mut PathRng, leg: &Leg<G>, v: &Vertex<G>, k: u32) {
        let moving = self.walk.slots.moving(k);
        self.moving_reflector = !moving.is_empty();
        if !self.moving_reflector {
            return;
        }
        // The incoming radiance's gradient at the moving point first.
        if self.walk.slots.twins > 0 {
            self.twin_gradient(g, rng, leg, v, k);
        } else {
            self.surface_gradient(
                g,
                rng,
                leg,
                Landing {
                    y: v.x,
                    k,
                    drawn: None,
                },
            );
        }
        // The material derivative of the reflected radiance: the point moves
        // with the surface (the corner terms see it move).
        let d = &mut self.walk.d;
        for j in moving.iter() {
            d.slots[j].u = g.velocity(j, v.x);
            d.touch(j);
        }
    }
    #[inline]
    fn connect(&mut self, g: &G, rng: &mut PathRng, v: &Vertex<G>) -> f64 {
        self.walk.attached_connect(g, rng, v)
    }
    #[inline]
    fn scatter(&mut self, g: &G, rng: &mut PathRng, v: &Vertex<G>) -> G::V {
        self.walk.attached_scatter(g, rng, v)
    }
    #[inline]
    fn reflected(&mut self, g: &G, rng: &mut PathRng, v: &Vertex<G>, w: G::V) {
        let slots = self.walk.slots;
        let params = slots.parameter_slots;
        if self.moving_reflector && slots.twins > 0 {
            // … and its regular part: the path goes on fixed in space, and
            // the twins carry the moving point's velocities along it in
            // the frozen scene.
            let d = &mut self.walk.d;
            for j in params.iter() {
                let t = slots.twin(j);
                let (u, wd) = (d.slots[j].u, d.slots[j].wd);
                let s = &mut d.slots[t];
                s.u = s.u + u;
                s.wd = s.wd + wd;
                d.slots[j].u = G::V::ZERO;
                d.touch(t);
            }
            self.moving_reflector = false;
        }
        if self.moving_reflector {
            // … and its regular part: the radiance reflected at the moving
            // point in the turning frame, by a nested walk in the frozen
            // scene (as the work admits it); the path itself goes on fixed
            // in space.
            let admitted = self.walk.scratch.work.admit(rng);
            let mut nested = self.walk.scratch.take(self.walk.d.len());
            for j in params.iter() {
                let s = &mut self.walk.d.slots[j];
                nested.slots[j].u = s.u;
                nested.slots[j].wd = s.wd;
                s.u = G::V::ZERO;
                nested.touch(j);
            }
            let nested = match admitted {
                Some(weight) => {
                    let drawn = Drawn {
                        pdf: super::Lobe::pdf(&v.lobe, w),
                        from: v.x,
                    };
                    let nested = self.frozen_walk(g, rng, nested, v.ray(w), Some(drawn));
                    for j in params.iter() {
                        let n = &nested.slots[j];
                        let (b, scale) = (n.boundary * weight, n.boundary_scale * weight);
                        self.walk.d.slots[j].add_boundary(v.beta * b, (v.beta * scale).abs());
                    }
                    nested
                }
                None => nested,
            };
            self.walk.scratch.give(nested);
            self.moving_reflector = false;
        }
        for j in params.iter() {
            self.walk.d.slots[j].wd = G::V::ZERO;
        }
    }
}
