//! The sweeps of the flatland and 3D "against π" figures: a scene moved to
//! evenly spaced values of one parameter `π`, every method run there (`E`
//! from the intensity estimator, `∂E/∂π` from the derivative methods) and
//! drawn as markers with ±σ bars over the reference curves, one column of
//! two panels (`E`, `∂E/∂π`) per sweep.
use super::{DERIVATIVE_METHODS, color};
use super::{FigureOptions, get, grid, run_method, z};
use crate::error::Error;
use crate::estimator::Quantity;
use crate::method::{Method, Problem};
use crate::plot::{Panel, Series};
use serde::Serialize;
use std::sync::Arc;

/// The methods run at every value of `π`: intensity, then the derivative
/// methods.
pub(crate) fn methods() -> impl Iterator<Item = Method> {
    std::iter::once(Method::Intensity).chain(DERIVATIVE_METHODS)
}

/// The reference at one value of `π`: `E`, the `∂E/∂π` plotted and the
/// factor the estimators' `∂E/∂π` is multiplied by to be that one.
pub(crate) type Exact = (f64, f64, f64);

/// Reference curves: `π`, `E(π)`, `∂E/∂π(π)`.
pub(crate) type Curves = (Vec<f64>, Vec<f64>, Vec<f64>);

/// The reference curves over `range` at `n` points.
pub(crate) fn curve(
    range: (f64, f64),
    n: usize,
    exact: impl Fn(f64) -> Result<(f64, f64), Error>,
) -> Result<Curves, Error> {
    let pi = grid(range, n);
    let mut e = Vec::with_capacity(pi.len());
    let mut de = Vec::with_capacity(pi.len());
    for &p in &pi {
        let (v, d) = exact(p)?;
        e.push(v);
        de.push(d);
    }
    Ok((pi, e, de))
}

/// One estimate at one value of `π`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Record {
    /// The parameter.
    pub parameter: &'static str,
    /// Its value.
    pub pi: f64,
    /// Method name.
    pub method: &'static str,
    /// `"E"` or `"dE/dπ"`.
    pub quantity: &'static str,
    /// Paths sampled.
    pub paths: u64,
    /// The estimate.
    pub mean: f64,
    /// Its standard error.
    pub stderr: f64,
    /// Relative variance of the variance.
    pub vov: f64,
    /// The reference.
    pub exact: f64,
    /// `(mean − exact) / stderr` (see [`z`](crate::mesh::figures::z)).
    pub z: Option<f64>,
}

/// Runs every method ([`methods`]) with `paths` paths on `opts.threads` at
/// every value of `values`, on the scene `at` gives with its reference; the
/// sensitivity judged is `parameter`'s. One salt a run, from `salt` on.
pub(crate) fn measure<S>(
    opts: &FigureOptions,
    values: Vec<f64>,
    parameter: &'static str,
    paths: u64,
    salt: &mut u64,
    bar: &indicatif::ProgressBar,
    at: impl Fn(f64) -> Result<(Arc<S>, Exact), Error>,
) -> Result<Vec<Record>, Error>
where
    Arc<S>: Problem,
{
    let mut runs = Vec::new();
    for pi in values {
        let (scene, (e, de, factor)) = at(pi)?;
        for method in methods() {
            *salt += 1;
            let r = run_method(opts, method, &scene, paths, *salt, opts.threads)?;
            let (q, quantity, exact, f) = match method {
                Method::Intensity => (Quantity::Intensity, "E", e, 1.0),
                _ => (Quantity::sensitivity(parameter), "dE/dπ", de, factor),
            };
            let est = get(&r, &q)?;
            let (mean, stderr) = (est.mean * f, est.stderr * f);
            runs.push(Record {
                parameter,
                pi,
                method: method.name(),
                quantity,
                paths: r.paths,
                mean,
                stderr,
                vov: est.vov,
                exact,
                z: z(mean, stderr, exact),
            });
            bar.inc(1);
        }
    }
    Ok(runs)
}

/// The panels' quantities and their axis labels: `E` on the top row,
/// `∂E/∂π` below.
pub(crate) const QUANTITIES: [(&str, &str); 2] = [("E", "E (irradiance)"), ("dE/dπ", "∂E/∂π")];

/// The markers of the panel of `quantity`: every method that estimates it,
/// side by side (`step` is the spacing of the values of `π`) so that the
/// error bars do not hide each other; `points` gives a method's
/// `(π, mean, stderr)`. Labelled by [`super::label`] when `labelled`.
pub(crate) fn markers(
    quantity: &str,
    step: f64,
    labelled: bool,
    points: impl Fn(Method) -> Vec<(f64, f64, f64)>,
) -> Vec<Series> {
    let methods: Vec<Method> = if quantity == "E" {
        vec![Method::Intensity]
    } else {
        DERIVATIVE_METHODS.to_vec()
    };
    let mut series = Vec::new();
    for (k, &method) in methods.iter().enumerate() {
        let offset = (k as f64 - 0.5 * (methods.len() - 1) as f64) * 0.1 * step;
        let points = points(method)
            .into_iter()
            .map(|(pi, mean, stderr)| (pi + offset, mean, stderr))
            .collect();
        let label = if labelled {
            super::label(method)
        } else {
            String::new()
        };
        series.push(Series::points(&label, color(method), points));
    }
    series
}

/// What [`columns`] returns.
pub(crate) struct Columns<R, C> {
    /// Every sweep's records, in order.
    pub records: Vec<R>,
    /// Every sweep's reference curve.
    pub curves: Vec<C>,
    /// The `E` panels.
    pub top: Vec<Panel>,
    /// The `∂E/∂π` panels.
    pub bottom: Vec<Panel>,
}

/// Runs every sweep of `sweeps` (its reference curve, its runs, its two
/// panels) in order.
pub(crate) fn columns<W, C, R>(
    sweeps: &[W],
    curve: impl Fn(&W) -> Result<C, Error>,
    mut measure: impl FnMut(&W) -> Result<Vec<R>, Error>,
    panels: impl Fn(&W, &C, &[R]) -> [Panel; 2],
) -> Result<Columns<R, C>, Error> {
    let mut out = Columns {
        records: Vec::new(),
        curves: Vec::new(),
        top: Vec::new(),
        bottom: Vec::new(),
    };
    for sweep in sweeps {
        let c = curve(sweep)?;
        let r = measure(sweep)?;
        let [e, de] = panels(sweep, &c, &r);
        out.top.push(e);
        out.bottom.push(de);
        out.records.extend(r);
        out.curves.push(c);
    }
    Ok(out)
}
