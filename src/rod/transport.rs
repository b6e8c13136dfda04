//! The sensitivity transport model (He et al. 2024, Sec. 3.3, Eqs. 41–43).
//!
//! `I`, its spatial derivative `∂xI` and the sensitivity `s = ∂I/∂π̃` obey
//! the same transport equation (Eq. 21); they differ only by their boundary
//! sources. One solver, [`solve`], walks a backward path and scores the
//! sources of every field at the end it leaves through, attenuated by
//! `e^{−κa L}`. So one path estimates all three fields. The sources are:
//!
//! | field | at `x = 0`, `ω = +1` | at `x = π̃`, `ω = −1` |
//! |---|---|---|
//! | `I` | `I0` | `0` |
//! | `∂xI` | `(−κe + κs/2) I0 + (κs/2) I(0, −1)` | `−(κs/2) I(π̃, +1)` |
//! | `s` | `0` | `−∂xI(π̃, −1) = +(κs/2) I(π̃, +1)` |
//!
//! The `∂xI` sources are the transport equation read at the boundary (Eq. 42).
//! The `s` source follows from `I(π̃, −1, π̃) = 0` for every `π̃`: its total
//! derivative `s + ∂xI` vanishes there (Appendix E; the paper's Eq. 43 prints
//! the opposite sign, which the exact solution refutes). Sources that need an
//! unknown intensity draw one nested intensity path (double randomization).
//! Book: chapter "The sensitivity transport model".
use super::walk::{attenuation, walk};
use super::{Direction, PARAMETER, Probe, Rod, Side};
use crate::estimator::{Estimator, Quantity};
use crate::rng::PathRng;

/// The fields the rod transport model carries, in weight order.
pub const FIELDS: usize = 3;

// ANCHOR: boundary_sources
/// Boundary sources `[I, s, ∂xI]` of the coupled fields at `side`, with the
/// unknown intensity there estimated by one nested path.
pub fn boundary_sources(rod: &Rod, side: Side, rng: &mut PathRng) -> [f64; FIELDS] {
    let half_ks = 0.5 * rod.ks;
    match side {
        Side::Start => {
            // I(0, −1) is seen by a backward path from 0 travelling right.
            let i_back = if half_ks > 0.0 {
                nested_intensity(rod, 0.0, Direction::Right, rng)
            } else {
                0.0
            };
            let gradient = (half_ks - rod.ke) * rod.incoming + half_ks * i_back;
            [rod.incoming, 0.0, gradient]
        }
        Side::End => {
            // I(π̃, +1) is seen by a backward path from π̃ travelling left.
            let i_fwd = if half_ks > 0.0 {
                nested_intensity(rod, rod.length, Direction::Left, rng)
            } else {
                0.0
            };
            let gradient = -half_ks * i_fwd;
            [0.0, -gradient, gradient]
        }
    }
}
// ANCHOR_END: boundary_sources

// ANCHOR: solve
/// One intensity sample, by the same solver with the intensity's sources.
#[inline]
fn nested_intensity(rod: &Rod, x: f64, dir: Direction, rng: &mut PathRng) -> f64 {
    let [i] = solve(rod, x, dir, rng, |side, _| [rod.incoming_at(side)]);
    i
}

/// Solves the transport model for the fields whose boundary sources `source`
/// gives: walks from `x` along `dir` and returns the attenuated sources at
/// the exit (0 for an absorbed path: every source is attenuated by
/// `e^{−κa L} = 0`, so its nested paths need not be drawn).
#[inline]
pub fn solve<const N: usize>(
    rod: &Rod,
    x: f64,
    dir: Direction,
    rng: &mut PathRng,
    source: impl FnOnce(Side, &mut PathRng) -> [f64; N],
) -> [f64; N] {
    let Some(exit) = walk(rod, x, dir, rng, &mut ()) else {
        return [0.0; N];
    };
    let s = source(exit.side, rng);
    if s.iter().all(|&v| v == 0.0) {
        // Nothing to attenuate: skip the exponential (a · ±0 = ±0 anyway).
        return s;
    }
    let a = attenuation(rod, exit.length) * exit.bias;
    s.map(|v| a * v)
}
// ANCHOR_END: solve

/// The transport-model estimator of `I`, `∂I/∂π̃` and `∂I/∂x`.
#[derive(Debug, Clone, Copy)]
pub struct TransportEstimator {
    /// The rod.
    pub rod: Rod,
    /// Where the fields are observed.
    pub probe: Probe,
}

impl Estimator for TransportEstimator {
    fn method(&self) -> &'static str {
        "transport"
    }

    fn quantities(&self) -> Vec<Quantity> {
        vec![
            Quantity::Intensity,
            Quantity::sensitivity(PARAMETER),
            Quantity::gradient("x"),
        ]
    }

    #[inline]
    fn sample(&self, rng: &mut PathRng, weights: &mut [f64]) {
        let rod = &self.rod;
        let fields = solve(
            rod,
            self.probe.x,
            self.probe.omega.reverse(),
            rng,
            |side, rng| boundary_sources(rod, side, rng),
        );
        weights.copy_from_slice(&fields);
    }
}
