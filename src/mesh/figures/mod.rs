//! The 3D figures (the book's 3D chapter): each is one function that runs
//! its experiment, deterministic from the seed, draws it with
//! [`crate::plot`] and writes `mesh_<name>.{png,svg}` and the numbers behind
//! it, `mesh_<name>.json`, under the output folder. They take the rod's
//! [`FigureOptions`]; the examples `examples/fig_mesh_*.rs` each call one and
//! `geosens compare --figures DIR` calls them all after flatland's.
//!
//! The scenes are built in code ([`crate::mesh::cases`]): a black triangle
//! occluder under the unit-square lamp, whose `E` and `∂E/∂π` have closed
//! forms ([`crate::mesh::exact`]), and the configurations where the methods
//! struggle. Colours per method are flatland's ([`color`]).
use super::Scene;
use crate::error::Error;
use crate::estimator::Quantity;
use crate::method::Method;
use crate::runner::{RunConfig, RunResult, run};
use crate::stats::Estimate;
use std::path::PathBuf;
use std::sync::Arc;

pub use crate::flat::figures::{DERIVATIVE_METHODS, METHODS, REFERENCE_COLOR, color};
pub use crate::rod::figures::{FigureFn, FigureOptions};

pub mod against_pi;
pub mod convergence;
pub mod efficiency;
pub mod stability;

/// Every 3D figure, in the book's order; returns the files written.
pub fn all(opts: &FigureOptions) -> Result<Vec<PathBuf>, Error> {
    let figures: [FigureFn; 4] = [
        against_pi::against_pi,
        convergence::convergence,
        efficiency::efficiency,
        stability::stability,
    ];
    let mut written = Vec::new();
    for figure in figures {
        written.extend(figure(opts)?);
    }
    Ok(written)
}

/// Runs `method` on `scene` with `paths` (scaled by the effort) paths, seed
/// `opts.seed + salt`, on `threads` threads.
pub fn run_method(
    opts: &FigureOptions,
    method: Method,
    scene: &Arc<Scene>,
    paths: u64,
    salt: u64,
    threads: usize,
) -> Result<RunResult, Error> {
    let cfg = RunConfig::new(opts.paths(paths), opts.seed.wrapping_add(salt))?.threads(threads);
    run(method.estimator(Arc::clone(scene))?.as_ref(), &cfg)
}

/// The estimate of `q` in `r`, or an error naming the method.
pub fn get(r: &RunResult, q: &Quantity) -> Result<Estimate, Error> {
    r.get(q)
        .ok_or_else(|| Error::Output(format!("{} does not estimate {q}", r.method)))
}

/// `(mean − exact)/stderr`; 0 when the estimate is exact, `None` when
/// `stderr = 0` but the estimate is not.
pub fn z(mean: f64, stderr: f64, exact: f64) -> Option<f64> {
    let diff = mean - exact;
    if diff == 0.0 {
        Some(0.0)
    } else {
        (stderr > 0.0).then(|| diff / stderr)
    }
}

/// Legend label of `method`: what it is judged on.
pub fn label(method: Method) -> String {
    match method {
        Method::Intensity => "intensity (E)".into(),
        m => format!("{} (∂E/∂π)", m.name()),
    }
}

/// The file names (`mesh_<name>.{png,svg}`) of a figure, saved with its
/// JSON: what every figure function returns.
pub(crate) fn save<T: serde::Serialize>(
    opts: &FigureOptions,
    name: &str,
    figure: &crate::plot::Figure,
    numbers: &T,
) -> Result<Vec<PathBuf>, Error> {
    let name = format!("mesh_{name}");
    let mut written = figure.save(&opts.out, &name)?;
    written.push(opts.write_json(&name, numbers)?);
    Ok(written)
}
