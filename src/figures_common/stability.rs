//! The runs of the flatland and 3D stability figures: every derivative
//! method ([`DERIVATIVE_METHODS`]) on a scene built at each distance to a
//! singular configuration, the sensitivity to its parameter `p` judged.
use super::{FigureOptions, get, run_method};
use crate::error::Error;
use crate::estimator::Quantity;
use crate::flat::figures::DERIVATIVE_METHODS;
use crate::method::Problem;
use crate::stats::Estimate;
use serde::Serialize;
use std::sync::Arc;

/// One run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Record {
    /// Which case (the figure's names).
    pub case: &'static str,
    /// The distance to the singular configuration.
    pub distance: f64,
    /// Method name.
    pub method: &'static str,
    /// Estimate of `∂E/∂p`.
    pub mean: f64,
    /// Its standard error.
    pub stderr: f64,
    /// Paths.
    pub paths: u64,
    /// `σ² N`.
    pub variance: f64,
    /// Relative variance of the variance.
    pub vov: f64,
    /// The exact `∂E/∂p` where one exists.
    pub exact: Option<f64>,
    /// The estimate's distance to `exact` in standard errors where an exact
    /// value exists (the figure's `z`).
    pub z: Option<f64>,
}

/// One case: its name, its distances, and the scene (parameter `p`) at a
/// distance with its exact `∂E/∂p` if known.
pub(crate) type Case<'a, S> = (
    &'static str,
    &'a [f64],
    &'a dyn Fn(f64) -> Result<(S, Option<f64>), Error>,
);

/// Runs every derivative method with `paths` paths on `opts.threads` at
/// every distance of every case, one salt a run from `salt` on; `z` scores
/// an estimate against the exact value. `what` names the progress bar.
pub(crate) fn measure<S>(
    opts: &FigureOptions,
    what: &str,
    cases: &[Case<'_, S>],
    paths: u64,
    mut salt: u64,
    z: fn(&Estimate, f64) -> Option<f64>,
) -> Result<Vec<Record>, Error>
where
    Arc<S>: Problem,
{
    let total: usize = cases.iter().map(|c| c.1.len()).sum();
    let bar = opts.bar((total * DERIVATIVE_METHODS.len()) as u64, what);
    let mut records = Vec::new();
    for &(case, distances, build) in cases {
        for &distance in distances {
            let (scene, exact) = build(distance)?;
            let scene = Arc::new(scene);
            for method in DERIVATIVE_METHODS {
                salt += 1;
                let r = run_method(opts, method, &scene, paths, salt, opts.threads)?;
                let e = get(&r, &Quantity::sensitivity("p"))?;
                records.push(Record {
                    case,
                    distance,
                    method: method.name(),
                    mean: e.mean,
                    stderr: e.stderr,
                    paths: r.paths,
                    variance: e.stderr * e.stderr * r.paths as f64,
                    vov: e.vov,
                    exact,
                    z: exact.and_then(|x| z(&e, x)),
                });
                bar.inc(1);
            }
        }
    }
    bar.finish();
    Ok(records)
}
