//! The sensitivity transport model: `s_j = ∂L/∂π_j` obeys the transport
//! equation of `L`, so for the shape-parameter slots the path stays fixed in
//! space (Eulerian) and collects `s`'s sources where it meets a moving
//! boundary:
//!
//! - at an **opaque** moving boundary hit at `y`: `−v·∇L(y⁻, η)`, the
//!   gradient by a nested walk in the frozen scene started just before `y`
//!   with velocity `v` ([`Rendering`] with `frozen`);
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
use super::deform::{Deform, Slots};
use super::nested::{Scratch, radiance};
use super::rendering::{Rendering, attached_connect, attached_scatter, leibniz};
use super::walk::{Hooks, Leg, Vertex, walk};
use super::{Boundaries, Geometry, Hit, MediumId, NO_PRIM, Vector};
use crate::rng::PathRng;

/// The transport method's hooks: one walk's deformation state.
pub struct Transport<'a, G: Geometry> {
    /// What is differentiated.
    pub slots: &'a Slots,
    /// States for connections and nested walks.
    pub scratch: &'a mut Scratch<G::V>,
    /// The walk's state.
    pub d: Deform<G::V>,
    /// Whether the reflector just reached moves (its material derivative is
    /// being collected).
    moving_reflector: bool,
}

impl<'a, G: Geometry> Transport<'a, G> {
    /// Hooks over `d` (zeroed, sensor velocities set).
    pub fn new(slots: &'a Slots, scratch: &'a mut Scratch<G::V>, d: Deform<G::V>) -> Self {
        Transport {
            slots,
            scratch,
            d,
            moving_reflector: false,
        }
    }
}

impl<G: Boundaries> Transport<'_, G> {
    /// Whether a shape-parameter slot's boundary moves on this segment.
    #[inline]
    fn euler_moving(&self) -> bool {
        self.slots
            .parameter_slots
            .iter()
            .any(|j| self.d.slots[j].tb_dot != 0.0)
    }

    // ANCHOR: surface_gradient
    /// The source `−v·∇L(y⁻, w)` where the leg hits the opaque moving
    /// boundary of shape `k` at `y`, for every shape-parameter slot: the
    /// gradient by a nested walk in the frozen scene started just before `y`.
    fn surface_gradient(
        &mut self,
        g: &G,
        rng: &mut PathRng,
        leg: &Leg<G>,
        y: G::V,
        k: u32,
        drawn: Option<(f64, G::V)>,
    ) {
        let Leg { x, w, medium, beta } = *leg;
        let Some(weight) = self.scratch.work.admit(rng) else {
            return;
        };
        let mut nested = self.scratch.take(self.d.len());
        for j in self.slots.moving(k).iter() {
            nested.slots[j].u = g.velocity(j, y);
            nested.touch(j);
        }
        let start = y - w * g.nudge(y).min(0.5 * (y - x).length());
        let nested = self.frozen_walk(g, rng, nested, start, w, medium, NO_PRIM, drawn);
        for j in self.slots.parameter_slots.iter() {
            let n = &nested.slots[j];
            let (b, scale) = (n.boundary * weight, n.boundary_scale * weight);
            self.d.slots[j].add_boundary(-beta * b, (beta * scale).abs());
        }
        self.scratch.give(nested);
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
        // The in-scattered radiance just before the point, shared by the
        // slots (the nested walk's Leibniz term over its first leg).
        let scattered = match coefficients {
            Some((ks, _)) if ks > 0.0 => match self.scratch.work.admit(rng) {
                Some(weight) => {
                    let end = v.x - w * (0.5e-9 * g.size());
                    let wi = super::Lobe::sample(&g.phase_lobe(medium, w), rng);
                    let work = &mut self.scratch.work;
                    beta * ks * radiance(g, work, rng, end, wi, medium, NO_PRIM) * weight
                }
                None => 0.0,
            },
            _ => 0.0,
        };
        let ke = coefficients.map_or(0.0, |c| c.1);
        for j in self.slots.moving(k).iter() {
            let vj = g.velocity(j, v.x);
            let along = vj.dot(n);
            // As `Deform::boundary_speed` rounds a speed along the surface.
            let tb = if crate::estimator::within_rounding(along, vj.length()) {
                0.0
            } else {
                along / wn
            };
            let t = self.slots.twin(j);
            let s = &mut self.d.slots[t];
            if scattered != 0.0 {
                s.add_boundary(scattered * tb, (scattered * tb).abs());
            }
            if ke != 0.0 {
                s.add_score(-ke * tb);
            }
            s.u = s.u - vj + w * tb;
            self.d.touch(t);
        }
    }
    // ANCHOR_END: twin_gradient

    /// The path's state with each twin's derivative added to its
    /// parameter's.
    pub fn finish(mut self) -> Deform<G::V> {
        if self.slots.twins > 0 {
            for j in self.slots.parameter_slots.iter() {
                let t = &self.d.slots[self.slots.twin(j)];
                let (b, scale) = (t.boundary, t.boundary_scale);
                self.d.slots[j].add_boundary(b, scale);
            }
        }
        self.d
    }

    /// A walk in the frozen scene from `x` along `w` that differentiates
    /// the start velocities held in `nested`; returns its state. `drawn`:
    /// how the main path drew `w`, so that a lamp it hits first carries the
    /// main path's MIS weight (the connection estimates the rest).
    #[allow(clippy::too_many_arguments)]
    fn frozen_walk(
        &mut self,
        g: &G,
        rng: &mut PathRng,
        nested: Deform<G::V>,
        x: G::V,
        w: G::V,
        medium: MediumId,
        skip: u32,
        drawn: Option<(f64, G::V)>,
    ) -> Deform<G::V> {
        let mut hooks = Rendering {
            slots: self.slots,
            scratch: self.scratch,
            d: nested,
            frozen: true,
        };
        walk(g, &mut hooks, rng, x, w, medium, skip, 1.0, drawn);
        hooks.d
    }
}

impl<G: Boundaries> Hooks<G> for Transport<'_, G> {
    #[inline]
    fn boundary(&mut self, g: &G, x: G::V, w: G::V, hit: Option<Hit>) {
        self.d.segment(g, self.slots, false, x, w, hit);
    }
    #[inline]
    fn free_path_domain(&mut self, g: &G, rng: &mut PathRng, leg: &Leg<G>, t_b: f64) {
        let work = &mut self.scratch.work;
        leibniz(
            g,
            &mut self.d,
            self.slots.frozen_scene(),
            rng,
            leg,
            t_b,
            work,
        );
    }
    #[inline]
    fn visit(&mut self, _x: G::V) {
        self.scratch.work.main += 1;
    }
    #[inline]
    fn collision(&mut self, _w: G::V, xi: f64, _t_b: f64, _ke: f64) {
        self.d.carry(xi);
    }
    #[inline]
    fn pass(&mut self, ke: f64) {
        self.d.pass(self.slots.frozen_scene(), ke);
    }
    #[inline]
    fn arrive(&mut self, w: G::V, t: f64) {
        self.d.arrive(self.slots.frozen_scene(), w, t);
    }
    #[inline]
    fn emission(&mut self, contribution: f64) {
        self.d.collect(contribution);
    }
    #[inline]
    fn opaque(
        &mut self,
        g: &G,
        rng: &mut PathRng,
        leg: &Leg<G>,
        y: G::V,
        k: u32,
        drawn: Option<(f64, G::V)>,
    ) {
        if self.euler_moving() {
            self.surface_gradient(g, rng, leg, y, k, drawn);
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
        let ks = |medium: MediumId| g.coefficients(medium).map_or(0.0, |c| c.0);
        let work = &mut self.scratch.work;
        let side = |work: &mut _, rng: &mut PathRng, medium: MediumId, at: G::V| {
            if ks(medium) > 0.0 {
                let wi = super::Lobe::sample(&g.phase_lobe(medium, w), rng);
                ks(medium) * radiance(g, work, rng, at, wi, medium, NO_PRIM)
            } else {
                0.0
            }
        };
        let ke = |medium: MediumId| g.coefficients(medium).map_or(0.0, |c| c.1);
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
        for j in self.slots.parameter_slots.iter() {
            let s = &mut self.d.slots[j];
            let t = beta * s.tb_dot * scattered;
            s.add_boundary(t, t.abs());
            s.add_score(-dke * s.tb_dot);
            if s.score != 0.0 {
                self.d.live.insert(j);
            }
        }
    }
    // ANCHOR_END: interface
    #[inline]
    fn reflect(&mut self, g: &G, rng: &mut PathRng, leg: &Leg<G>, v: &Vertex<G>, k: u32) {
        let moving = self.slots.moving(k);
        self.moving_reflector = !moving.is_empty();
        if !self.moving_reflector {
            return;
        }
        // The incoming radiance's gradient at the moving point first.
        if self.slots.twins > 0 {
            self.twin_gradient(g, rng, leg, v, k);
        } else {
            self.surface_gradient(g, rng, leg, v.x, k, None);
        }
        // The material derivative of the reflected radiance: the point moves
        // with the surface (the corner terms see it move).
        for j in moving.iter() {
            self.d.slots[j].u = g.velocity(j, v.x);
            self.d.touch(j);
        }
    }
    #[inline]
    fn connect(&mut self, g: &G, rng: &mut PathRng, v: &Vertex<G>) -> f64 {
        attached_connect(g, self.slots, self.scratch, &mut self.d, rng, v, false)
    }
    #[inline]
    fn scatter(&mut self, g: &G, rng: &mut PathRng, v: &Vertex<G>) -> G::V {
        let work = &mut self.scratch.work;
        attached_scatter(g, self.slots, &mut self.d, rng, v, false, work)
    }
    #[inline]
    fn reflected(&mut self, g: &G, rng: &mut PathRng, v: &Vertex<G>, w: G::V) {
        let params = self.slots.parameter_slots;
        if self.moving_reflector && self.slots.twins > 0 {
            // … and its regular part: the path goes on fixed in space, and
            // the twins carry the moving point's velocities along it in
            // the frozen scene.
            for j in params.iter() {
                let t = self.slots.twin(j);
                let (u, wd) = (self.d.slots[j].u, self.d.slots[j].wd);
                let s = &mut self.d.slots[t];
                s.u = s.u + u;
                s.wd = s.wd + wd;
                self.d.slots[j].u = G::V::ZERO;
                self.d.touch(t);
            }
            self.moving_reflector = false;
        }
        if self.moving_reflector {
            // … and its regular part: the radiance reflected at the moving
            // point in the turning frame, by a nested walk in the frozen
            // scene (as the work admits it); the path itself goes on fixed
            // in space.
            let admitted = self.scratch.work.admit(rng);
            let mut nested = self.scratch.take(self.d.len());
            for j in params.iter() {
                let s = &mut self.d.slots[j];
                nested.slots[j].u = s.u;
                nested.slots[j].wd = s.wd;
                s.u = G::V::ZERO;
                nested.touch(j);
            }
            let nested = match admitted {
                Some(weight) => {
                    let drawn = Some((super::Lobe::pdf(&v.lobe, w), v.x));
                    let nested = self.frozen_walk(g, rng, nested, v.x, w, v.medium, v.skip, drawn);
                    for j in params.iter() {
                        let n = &nested.slots[j];
                        let (b, scale) = (n.boundary * weight, n.boundary_scale * weight);
                        self.d.slots[j].add_boundary(v.beta * b, (v.beta * scale).abs());
                    }
                    nested
                }
                None => nested,
            };
            self.scratch.give(nested);
            self.moving_reflector = false;
        }
        for j in params.iter() {
            self.d.slots[j].wd = G::V::ZERO;
        }
    }
}
