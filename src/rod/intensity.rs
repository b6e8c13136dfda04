//! Backward path tracing of the intensity (Algorithm 3, Eq. 28): a path from
//! the probe travelling along `−ω` collects `Î e^{−κa L}` where it leaves.
//! Book: chapter "Backward path tracing of the intensity".
use super::walk::intensity_weight;
use super::{Probe, Rod};
use crate::estimator::{Estimator, Quantity};
use crate::rng::PathRng;

/// The intensity estimator.
#[derive(Debug, Clone, Copy)]
pub struct IntensityEstimator {
    /// The rod.
    pub rod: Rod,
    /// Where the intensity is observed.
    pub probe: Probe,
}

impl Estimator for IntensityEstimator {
    fn method(&self) -> &'static str {
        "intensity"
    }

    fn quantities(&self) -> Vec<Quantity> {
        vec![Quantity::Intensity]
    }

    #[inline]
    fn sample(&self, rng: &mut PathRng, weights: &mut [f64]) {
        weights[0] = intensity_weight(&self.rod, self.probe.x, self.probe.omega.reverse(), rng);
    }
}
