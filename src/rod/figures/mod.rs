//! The rod's figures (the book's chapters "The rod", one per approach, and
//! "Comparing the approaches"): each is one function that runs its
//! experiment, deterministic from the seed, draws it with [`crate::plot`]
//! and writes PNG and SVG under the output folder. The examples
//! `examples/fig_*.rs` each call one; `geosens compare --figures DIR` calls
//! them all.
use crate::error::Error;
use crate::estimator::Quantity;
use crate::figures_common::run_method;
use crate::rod::{Direction, Method, Probe, Rod, exact};
use crate::runner::RunResult;
use std::path::PathBuf;

pub mod along;
pub mod convergence;
pub mod efficiency;
pub mod finite_difference;
pub mod stability;

pub use crate::figures_common::{FigureFn, FigureOptions};

/// The rod's runs, on the options every figure takes.
impl FigureOptions {
    /// Runs `method` at `(x, omega)` with `paths` (scaled) paths and seed
    /// `self.seed + salt`.
    pub fn run(
        &self,
        method: Method,
        rod: Rod,
        x: f64,
        omega: Direction,
        paths: u64,
        salt: u64,
    ) -> Result<RunResult, Error> {
        let probe = Probe::new(&rod, x, omega)?;
        run_method(self, method, &(rod, probe), paths, salt, self.threads)
    }
}

/// Every figure of the rod, in the book's order; returns the files written.
pub fn all(opts: &FigureOptions) -> Result<Vec<PathBuf>, Error> {
    crate::figures_common::all(
        opts,
        &[
            finite_difference::finite_difference,
            along::intensity_along_rod,
            along::sensitivity_along_rod,
            convergence::convergence,
            efficiency::efficiency,
            stability::stability,
        ],
    )
}

/// The paper's optically thin rod: κs = 0.07, κe = 0.1, length 2.
pub fn thin() -> Rod {
    Rod {
        ks: 0.07,
        ke: 0.1,
        length: 2.0,
        incoming: 1.0,
    }
}

/// The paper's optically thick rod: κs = 2.1, κe = 3, length 2.
pub fn thick() -> Rod {
    Rod {
        ks: 2.1,
        ke: 3.0,
        length: 2.0,
        incoming: 1.0,
    }
}

/// The exact value of `q` at `(x, omega)`.
pub fn exact_value(rod: &Rod, x: f64, omega: Direction, q: &Quantity) -> f64 {
    exact::solve(rod, x, omega).get(q)
}

/// `n` evenly spaced positions over `[0, length]`, ends included.
pub fn positions(rod: &Rod, n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| rod.length * i as f64 / (n - 1) as f64)
        .collect()
}
