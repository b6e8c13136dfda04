//! The intensity estimator: backward path tracing of the sensor's reading,
//! the path core's loop with no hooks (the unit hooks `()` compile away).
//! [`Observed`] records the path's vertices for figures. Book: chapter
//! "Flatland", section "Backward path tracing".
use super::estimator::reading;
use super::walk::{Hooks, Ray};
use super::{Geometry, PixelSample};
use crate::estimator::{Estimator, Quantity};
use crate::rng::PathRng;

/// Backward path tracing of the sensor's reading: the loop with no hooks.
pub struct IntensityEstimator<G> {
    /// The scene.
    pub geometry: G,
}

impl<G: Geometry> Estimator for IntensityEstimator<G> {
    fn method(&self) -> &'static str {
        "intensity"
    }
    fn quantities(&self) -> Vec<Quantity> {
        vec![Quantity::Intensity]
    }
    #[inline]
    fn sample(&self, rng: &mut PathRng, weights: &mut [f64]) {
        weights[0] = reading(&self.geometry, &mut (), rng, PixelSample::default()).0;
    }
    fn image(&self) -> Option<(u32, u32)> {
        self.geometry.image()
    }
    #[inline]
    fn sample_pixel(&self, rng: &mut PathRng, pixel: PixelSample, weights: &mut [f64]) {
        weights[0] = reading(&self.geometry, &mut (), rng, pixel).0;
    }
}

/// Plain backward path tracing, without next-event estimation: lamps count
/// only when a path hits them. The reference the tests check next-event
/// estimation against.
pub struct PlainEstimator<G> {
    /// The scene.
    pub geometry: G,
}

/// The hooks of plain path tracing.
struct Plain;

impl<G: Geometry> Hooks<G> for Plain {
    const NEXT_EVENT: bool = false;
}

impl<G: Geometry> Estimator for PlainEstimator<G> {
    fn method(&self) -> &'static str {
        "plain"
    }
    fn quantities(&self) -> Vec<Quantity> {
        vec![Quantity::Intensity]
    }
    #[inline]
    fn sample(&self, rng: &mut PathRng, weights: &mut [f64]) {
        weights[0] = reading(&self.geometry, &mut Plain, rng, PixelSample::default()).0;
    }
}

/// Hooks that only watch: every path vertex goes to the closure.
pub struct Observed<F>(pub F);

impl<G: Geometry, F: FnMut(G::V)> Hooks<G> for Observed<F> {
    #[inline]
    fn visit(&mut self, x: G::V) {
        (self.0)(x)
    }
}

/// The radiance arriving at the ray's origin from its direction (the path
/// travels along it) by one path, calling `vertex` at every scattering,
/// reflection or crossing point and at the end of the path.
pub fn radiance_observed<G: Geometry>(
    g: &G,
    rng: &mut PathRng,
    ray: Ray<G::V>,
    vertex: impl FnMut(G::V),
) -> f64 {
    super::walk::walk(g, &mut Observed(vertex), rng, ray, 1.0, None)
}
