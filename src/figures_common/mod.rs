//! What the flatland and 3D figures ([`crate::flat::figures`],
//! [`crate::mesh::figures`]) share: running a method on a scene, the
//! figure list runner, saving a figure with its numbers, the legend labels,
//! and the experiments whose logic is the same on both kinds of scene (the
//! `σ²·t` grouped bars, the sweeps against `π`, the convergence panel, the
//! runs near singular configurations), parameterised by what differs.
use crate::error::Error;
use crate::estimator::Quantity;
use crate::flat::figures::{FigureFn, FigureOptions};
use crate::method::{Method, Problem};
use crate::runner::{RunConfig, RunResult, run};
use crate::stats::Estimate;
use std::path::PathBuf;
use std::sync::Arc;

pub(crate) mod convergence;
pub(crate) mod efficiency;
pub(crate) mod stability;
pub(crate) mod sweep;

/// Runs every figure of `figures` in order; returns the files written.
pub(crate) fn all(opts: &FigureOptions, figures: &[FigureFn]) -> Result<Vec<PathBuf>, Error> {
    let mut written = Vec::new();
    for figure in figures {
        written.extend(figure(opts)?);
    }
    Ok(written)
}

/// Runs `method` on `scene` with `paths` (scaled by the effort) paths, seed
/// `opts.seed + salt`, on `threads` threads.
pub(crate) fn run_method<S>(
    opts: &FigureOptions,
    method: Method,
    scene: &Arc<S>,
    paths: u64,
    salt: u64,
    threads: usize,
) -> Result<RunResult, Error>
where
    Arc<S>: Problem,
{
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

/// Saves `figure` as `<prefix>_<name>.{png,svg}` with its numbers,
/// `<prefix>_<name>.json`; returns the files written.
pub(crate) fn save<T: serde::Serialize>(
    opts: &FigureOptions,
    prefix: &str,
    name: &str,
    figure: &crate::plot::Figure,
    numbers: &T,
) -> Result<Vec<PathBuf>, Error> {
    let name = format!("{prefix}_{name}");
    let mut written = figure.save(&opts.out, &name)?;
    written.push(opts.write_json(&name, numbers)?);
    Ok(written)
}

/// `n` evenly spaced values over `range`, ends included.
pub(crate) fn grid((lo, hi): (f64, f64), n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| lo + (hi - lo) * i as f64 / (n - 1) as f64)
        .collect()
}
