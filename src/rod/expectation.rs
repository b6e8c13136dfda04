//! Expectation differentiation (He et al. 2024, Sec. 3.1 and Algorithm 4):
//! `I` and `s = ∂I/∂π̃` from the same backward paths.
//!
//! A path with `j` collisions lives in the domain `ξ_k ∈ [0, d̂_k]` (k < j),
//! `ξ_j ∈ [d̂_j, ∞)`, whose borders move with `π̃`. Reynolds' transport theorem
//! with a domain-deformation velocity `V` (Eqs. 31–33, Appendix C) gives
//! `s = E[W (R − κe Λ)]`, with `W = Î e^{−κa L}` the intensity weight and,
//! along the path,
//!
//! - `Y`: the velocity `∂y/∂π̃` of the current vertex under the flow,
//! - `U_k = (1+ω_k)/2 − ω_k Y`: the velocity of the border `d̂_k` (Eq. 64),
//! - `V_k = U_k ξ_k / d̂_k` (k < j), `V_j = U_j` (Eq. 33),
//! - `Λ = Σ_k V_k`: the velocity of the total length `L`,
//! - `R = Σ_{k<j} U_k / d̂_k`: the divergence of `V`.
//!
//! The running sums replace the per-event velocity tables of Algorithm 4: O(1)
//! work and no allocation per collision. The book's chapter "Expectation
//! differentiation" derives the weight step by step.
//!
//! At `x = π̃` looking left (`ω = −1`) the first domain `[0, d̂_0]` has zero
//! length and moves at unit speed: the divergence term becomes a Dirac whose
//! weight is `κs` times an intensity path scattered at `π̃`. The estimator
//! samples that continuation; near (not at) that end the variance grows as
//! `1/(π̃ − x)`, which the tail diagnostic reports.
use super::walk::{Events, intensity_weight, scatter_direction, score, walk};
use super::{Direction, PARAMETER, Probe, Rod};
use crate::estimator::{Estimator, Quantity};
use crate::rng::PathRng;

// ANCHOR: domain_velocity
/// The domain-deformation velocity, built incrementally along a path.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct DomainVelocity {
    /// `Y = ∂y/∂π̃` of the current vertex (0 at the probe, which is fixed).
    pub vertex: f64,
    /// `Λ = Σ V_k`, the velocity of the path length.
    pub length: f64,
    /// `R = Σ U_k / d̂_k`, the divergence of the velocity field.
    pub divergence: f64,
}

impl DomainVelocity {
    /// `U = ∂d̂/∂π̃ + Σ V_i ∂d̂/∂ξ_i` of the border reached along `dir`.
    #[inline]
    pub fn border_velocity(&self, dir: Direction) -> f64 {
        match dir {
            Direction::Right => 1.0 - self.vertex,
            Direction::Left => self.vertex,
        }
    }
}

impl Events for DomainVelocity {
    #[inline]
    fn collision(&mut self, dir: Direction, xi: f64, d: f64) {
        let u = self.border_velocity(dir);
        let inv_d = 1.0 / d;
        let v = u * xi * inv_d;
        self.vertex += dir.sign() * v;
        self.length += v;
        self.divergence += u * inv_d;
    }

    #[inline]
    fn escape(&mut self, dir: Direction, _d: f64) {
        self.length += self.border_velocity(dir);
    }
}
// ANCHOR_END: domain_velocity

/// The expectation-differentiation estimator of `I` and `∂I/∂π̃`.
#[derive(Debug, Clone, Copy)]
pub struct ExpectationEstimator {
    /// The rod.
    pub rod: Rod,
    /// Where the intensity is observed.
    pub probe: Probe,
}

impl Estimator for ExpectationEstimator {
    fn method(&self) -> &'static str {
        "expectation"
    }

    fn quantities(&self) -> Vec<Quantity> {
        vec![Quantity::Intensity, Quantity::sensitivity(PARAMETER)]
    }

    // ANCHOR: sample
    #[inline]
    fn sample(&self, rng: &mut PathRng, weights: &mut [f64]) {
        let rod = &self.rod;
        let dir = self.probe.omega.reverse();
        if rod.distance_to_boundary(self.probe.x, dir) == 0.0 && dir == Direction::Right {
            // Collapsed first domain at the moving end: the Dirac term.
            weights[0] = 0.0;
            let after = scatter_direction(rng);
            weights[1] = rod.ks * intensity_weight(rod, rod.length, after, rng);
            return;
        }
        let mut v = DomainVelocity::default();
        let Some(exit) = walk(rod, self.probe.x, dir, rng, &mut v) else {
            // Absorbed: W = 0, and so is W (R − κe Λ).
            weights.fill(0.0);
            return;
        };
        let w = score(rod, exit.side, exit.length) * exit.bias;
        weights[0] = w;
        weights[1] = w * (v.divergence - rod.ke * v.length);
    }
    // ANCHOR_END: sample
}
