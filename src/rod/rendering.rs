//! Differentiable rendering (He et al. 2024, Sec. 3.2 and Algorithm 5).
//! Differentiating the Fredholm equation (Eq. 23) in `π̃` leaves the same
//! integral operator plus a boundary term at `x' = π̃`,
//! `e^{−κe(π̃−x)} (κs/2) I(π̃, +1)` (Eq. 34). Its unknown intensity is
//! estimated by one nested path started at `π̃` (double randomization,
//! Appendix D, Eq. 40): a path that leaves through the moving end scores
//! `(κs/2) e^{−κa L} Ŵ(π̃, +1)`.
//!
//! The primary path is an intensity path too, so `I` comes for free.
//! Book: chapter "Differentiable rendering".
use super::walk::{score, walk};
use super::{Direction, PARAMETER, Probe, Rod, Side};
use crate::estimator::{Estimator, Quantity};
use crate::rng::PathRng;

/// The differentiable-rendering estimator of `I` and `∂I/∂π̃`.
#[derive(Debug, Clone, Copy)]
pub struct RenderingEstimator {
    /// The rod.
    pub rod: Rod,
    /// Where the intensity is observed.
    pub probe: Probe,
}

impl Estimator for RenderingEstimator {
    fn method(&self) -> &'static str {
        "rendering"
    }

    fn quantities(&self) -> Vec<Quantity> {
        vec![Quantity::Intensity, Quantity::sensitivity(PARAMETER)]
    }

    // ANCHOR: sample
    #[inline]
    fn sample(&self, rng: &mut PathRng, weights: &mut [f64]) {
        let rod = &self.rod;
        let Some(exit) = walk(rod, self.probe.x, self.probe.omega.reverse(), rng, &mut ()) else {
            // Absorbed: every weight carries e^{−κa L} = 0.
            weights.fill(0.0);
            return;
        };
        match exit.side {
            Side::Start => {
                weights[0] = score(rod, Side::Start, exit.length) * exit.bias;
                weights[1] = 0.0;
            }
            Side::End => {
                weights[0] = 0.0;
                // I(π̃, +1) is seen by a backward path from π̃ travelling left;
                // its absorption and the primary's share one exponential.
                weights[1] = if rod.ks > 0.0 {
                    match walk(rod, rod.length, Direction::Left, rng, &mut ()) {
                        Some(nested) => {
                            0.5 * rod.ks
                                * score(rod, nested.side, exit.length + nested.length)
                                * (exit.bias * nested.bias)
                        }
                        None => 0.0,
                    }
                } else {
                    0.0
                };
            }
        }
    }
    // ANCHOR_END: sample
}
