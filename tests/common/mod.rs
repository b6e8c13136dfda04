//! Shared helpers of the integration tests.
#![allow(dead_code)]
use geosens::rod::{Direction, Method, Probe, Rod, exact};
use geosens::{Quantity, RunConfig, RunResult, run};

pub mod cli;

/// The paper's thin rod (κs = 0.07, κe = 0.1, π̃ = 2).
pub fn thin() -> Rod {
    Rod::new(0.07, 0.1, 2.0).unwrap()
}

/// The paper's thick rod (κs = 2.1, κe = 3, π̃ = 2).
pub fn thick() -> Rod {
    Rod::new(2.1, 3.0, 2.0).unwrap()
}

/// Runs `method` at `(x, omega)` on one thread.
pub fn estimate(
    method: Method,
    rod: Rod,
    x: f64,
    omega: Direction,
    paths: u64,
    seed: u64,
) -> RunResult {
    let probe = Probe::new(&rod, x, omega).unwrap();
    let cfg = RunConfig::new(paths, seed).unwrap().threads(1);
    run(method.estimator((rod, probe)).unwrap().as_ref(), &cfg).unwrap()
}

/// The exact value of `q` at `(x, omega)`.
pub fn exact_value(rod: &Rod, x: f64, omega: Direction, q: &Quantity) -> f64 {
    exact::solve(rod, x, omega).get(q)
}

/// Largest standard error, as a fraction of `max(|exact|, floor)` (see
/// [`floor`]), for which a comparison with exact means something: 4 standard
/// errors are then a fifth of the value, so an estimator off by a factor,
/// missing a term or returning 0 fails. The 3D tests' rule
/// (`tests/mesh_methods.rs`).
pub const RESOLUTION: f64 = 0.05;

/// Below this, a value's error bar is measured against it instead of
/// against `|exact|`. None for `I`, an exponential across the rod whose
/// relative error is what counts (as for the 3D tests' `E`); for a
/// derivative, a quarter of its largest `|exact|` over 65 positions across
/// the rod in both directions, so that a value near 0 is resolved to
/// 1.25 % of that (the 3D tests' floors: 0.02–0.05 for derivatives up to
/// about 0.3). A derivative that is 0 along the whole rod in f64 (light
/// never reaches the moving end of a rod thousands of free paths thick) is
/// measured against `∂I/∂x`'s, in the same units.
pub fn floor(rod: &Rod, q: &Quantity) -> f64 {
    let largest = |q: &Quantity| {
        (0..=64)
            .flat_map(|i| {
                let x = rod.length * f64::from(i) / 64.0;
                [Direction::Right, Direction::Left].map(|omega| exact_value(rod, x, omega, q))
            })
            .fold(0.0, |m, v| v.abs().max(m))
    };
    match q {
        Quantity::Intensity => 0.0,
        _ => {
            let own = largest(q);
            let scale = if own > 0.0 {
                own
            } else {
                largest(&Quantity::gradient("x"))
            };
            0.25 * scale
        }
    }
}

/// Asserts every estimate of `method` is within `k` standard errors of
/// exact, with an error bar that resolves it: at most [`RESOLUTION`] of the
/// larger of `|exact|` and its [`floor`].
pub fn assert_within(
    method: Method,
    rod: Rod,
    x: f64,
    omega: Direction,
    paths: u64,
    seed: u64,
    k: f64,
) {
    let r = estimate(method, rod, x, omega, paths, seed);
    for (q, e) in &r.estimates {
        let reference = exact_value(&rod, x, omega, q);
        let z = e.z_score(reference);
        assert!(
            z <= k,
            "{} {q} at x={x} {omega:?} on {rod:?}: {} ± {} vs exact {reference} (z = {z:.2})",
            method.name(),
            e.mean,
            e.stderr
        );
        let bound = RESOLUTION * reference.abs().max(floor(&rod, q));
        assert!(
            e.stderr <= bound,
            "{} {q} at x={x} {omega:?} on {rod:?}: {} ± {} does not resolve exact {reference} \
             (error bar above {bound})",
            method.name(),
            e.mean,
            e.stderr
        );
    }
}
