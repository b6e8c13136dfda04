//! The path core behind the crate's [`Estimator`] interface: one call
//! samples one path from the sensor (with its nested paths and
//! connections) and writes `I`, then `∂I/∂π_j` for every parameter in
//! declaration order, then (transport) the sensor position's gradient.
//! States are reused across the paths of a chunk: the hot loop allocates
//! nothing per path.
use super::deform::Slots;
use super::derivative_walk::{DerivativeWalk, SceneMotion};
use super::expectation::Expectation;
use super::nested::{Budget, Scratch, Work};
use super::rendering::Rendering;
use super::transport::Transport;
use super::walk::{Drawn, Frame, Hooks, Ray, Vertex, walk};
use super::{Boundaries, Geometry, Lobe, NO_PRIM, PixelSample, Sensor, Vector};
use crate::estimator::{Estimator, Quantity};
use crate::rng::PathRng;
use crate::stats::{ChunkSums, StratumSums};

/// A reading of the sensor by one path (a camera's: through `pixel`): its
/// weight, and the factor (the sensor lobe's weight) every derivative
/// weight is multiplied by.
#[inline]
pub fn reading<G: Geometry, H: Hooks<G>>(
    g: &G,
    hooks: &mut H,
    rng: &mut PathRng,
    pixel: PixelSample,
) -> (f64, f64) {
    let medium = g.sensor_medium();
    // The sensor's rays start from its point, in its medium.
    let ray = |x: G::V, w: G::V| Ray {
        x,
        w,
        medium,
        skip: NO_PRIM,
    };
    match g.sensor() {
        Sensor::Camera { point } => {
            let Some(lobe) = g.pixel_lobe(pixel) else {
                return (0.0, 0.0);
            };
            // No connection: a pinhole's lobe is a direction density, and
            // the lamp's side cannot aim through the pinhole. A lamp seen
            // directly counts whole (`drawn` = None).
            let v = Vertex {
                x: point,
                medium,
                skip: NO_PRIM,
                lobe,
                w_in: G::V::ZERO,
                frame: Frame::Sensor,
                beta: 1.0,
                // Not `at_sensor`: flatland precomputes knots for the
                // irradiance sensor only. (3D's sensor view serves any
                // vertex at the sensor's point, the pinhole included.)
                at_sensor: false,
                mixed: false,
            };
            let w = hooks.scatter(g, rng, &v);
            let scale = lobe.weight();
            (scale * walk(g, hooks, rng, ray(point, w), 1.0, None), scale)
        }
        Sensor::Radiance { point, direction } => {
            (walk(g, hooks, rng, ray(point, direction), 1.0, None), 1.0)
        }
        Sensor::Irradiance { point, normal } => {
            let lobe = g.cosine_lobe(normal, 1.0);
            // The walk carries the lobe's weight outside, so Russian
            // roulette sees the same throughput as the radiance's.
            let mixed = H::SENSOR_MIXTURE && g.sensor_mixture();
            let v = Vertex {
                x: point,
                medium,
                skip: NO_PRIM,
                lobe,
                w_in: normal,
                frame: Frame::Sensor,
                beta: 1.0,
                at_sensor: true,
                mixed,
            };
            let direct = if H::NEXT_EVENT {
                hooks.connect(g, rng, &v)
            } else {
                0.0
            };
            let w = hooks.scatter(g, rng, &v);
            // Drawn with the sensor's own density `q`, the path carries
            // `p/q` (the lobe's weight `f/p` stays outside, in `scale`).
            let (q, beta) = if mixed {
                let q = g.sensor_mixture_pdf(&lobe, w);
                (q, lobe.pdf(w) / q)
            } else {
                (lobe.pdf(w), 1.0)
            };
            let drawn = H::NEXT_EVENT.then_some(Drawn {
                pdf: q,
                from: point,
            });
            let scale = lobe.weight();
            (
                scale * (direct + walk(g, hooks, rng, ray(point, w), beta, drawn)),
                scale,
            )
        }
    }
}

/// Which derivative method a [`DerivativeEstimator`] runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scheme {
    /// [`Rendering`].
    Rendering,
    /// [`Expectation`].
    Expectation,
    /// [`Transport`] (with the sensor position's gradient).
    Transport,
}

/// `I` and every sensitivity from one path, by one derivative method.
pub struct DerivativeEstimator<G> {
    /// The scene.
    pub geometry: G,
    /// Its parameter slots.
    pub slots: Slots,
    /// The method.
    pub scheme: Scheme,
    /// Names of the parameters, then of the gradient axes.
    pub names: Vec<Quantity>,
    /// Warnings about particular quantities (see [`Estimator::caveats`]).
    pub caveats: Vec<(Quantity, String)>,
    /// The nested walks' budget per path ([`super::nested`]).
    pub budget: Budget,
}

impl<G: Boundaries> DerivativeEstimator<G> {
    /// One path's weights, states from `scratch`.
    #[inline]
    fn path(
        &self,
        rng: &mut PathRng,
        scratch: &mut Scratch<G::V>,
        out: &mut [f64],
        pixel: PixelSample,
    ) {
        let g = &self.geometry;
        let slots = &self.slots;
        // Each path spends its own budget: paths stay independent, and a
        // run's numbers do not depend on how its paths are chunked.
        scratch.work = Work::new(self.budget);
        let mut d = scratch.take(slots.len());
        slots.start(&mut d);
        let walk = DerivativeWalk {
            slots,
            scene: SceneMotion::Moving,
            scratch,
            d,
        };
        let ((i, scale), d) = match self.scheme {
            Scheme::Rendering => {
                let mut h = Rendering { walk };
                (reading(g, &mut h, rng, pixel), h.walk.d)
            }
            Scheme::Expectation => {
                let mut h = Expectation {
                    walk,
                    pending: None,
                };
                (reading(g, &mut h, rng, pixel), h.walk.d)
            }
            Scheme::Transport => {
                let mut h = Transport::new(walk);
                (reading(g, &mut h, rng, pixel), h.finish())
            }
        };
        out[0] = i;
        for (o, s) in out[1..].iter_mut().zip(&d.slots) {
            *o = scale * s.derivative();
        }
        scratch.give(d);
    }
}

impl<G: Boundaries> DerivativeEstimator<G> {
    /// [`Estimator::sample`], and the work the path cost: the events of its
    /// main walk and of its nested walks.
    pub fn sample_with_work(&self, rng: &mut PathRng, weights: &mut [f64]) -> Work {
        let mut scratch = Scratch::default();
        self.path(rng, &mut scratch, weights, PixelSample::default());
        scratch.work
    }
}

impl<G: Boundaries> Estimator for DerivativeEstimator<G> {
    fn method(&self) -> &'static str {
        match self.scheme {
            Scheme::Rendering => "rendering",
            Scheme::Expectation => "expectation",
            Scheme::Transport => "transport",
        }
    }
    fn quantities(&self) -> Vec<Quantity> {
        std::iter::once(Quantity::Intensity)
            .chain(self.names.iter().cloned())
            .collect()
    }
    fn caveats(&self) -> Vec<(Quantity, String)> {
        self.caveats.clone()
    }
    fn sample(&self, rng: &mut PathRng, weights: &mut [f64]) {
        self.path(
            rng,
            &mut Scratch::default(),
            weights,
            PixelSample::default(),
        );
    }
    fn accumulate(&self, rng: &mut PathRng, paths: u64, sums: &mut [ChunkSums]) {
        let mut w = vec![0.0; sums.len()];
        let mut scratch = Scratch::default();
        for _ in 0..paths {
            self.path(rng, &mut scratch, &mut w, PixelSample::default());
            for (s, &x) in sums.iter_mut().zip(&w) {
                s.push(x);
            }
        }
    }
    fn image(&self) -> Option<(u32, u32)> {
        self.geometry.image()
    }
    fn sample_pixel(&self, rng: &mut PathRng, pixel: PixelSample, weights: &mut [f64]) {
        self.path(rng, &mut Scratch::default(), weights, pixel);
    }
    fn accumulate_pixel(&self, rng: &mut PathRng, pixel: u32, spp: u64, sums: &mut [StratumSums]) {
        let mut w = vec![0.0; sums.len()];
        let mut scratch = Scratch::default();
        crate::estimator::stratified(pixel, spp, sums, &mut w, |s, w| {
            self.path(rng, &mut scratch, w, s)
        });
    }
}
