//! Shared helpers of the integration tests.
#![allow(dead_code)]
use geosens::rod::{Direction, Method, Probe, Rod, exact};
use geosens::{Quantity, RunConfig, RunResult, run};

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

/// Asserts every estimate of `method` is within `k` standard errors of exact.
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
    }
}
