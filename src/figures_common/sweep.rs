//! The flatland and 3D figures "against π": each sweep moves a scene to
//! evenly spaced values of one parameter `π`, runs every method there (`E`
//! from the intensity estimator, `∂E/∂π` from the derivative methods) and
//! draws them as markers with ±σ bars over the reference curves, one
//! column of two panels (`E`, `∂E/∂π`) per sweep. What a sweep moves and
//! what its reference is, is the dimension's ([`Column`]).
use super::{DERIVATIVE_METHODS, REFERENCE_COLOR, color};
use super::{FigureOptions, get, grid, run_method, z};
use crate::error::Error;
use crate::estimator::Quantity;
use crate::method::{Method, Problem};
use crate::plot::{Figure, Panel, Series};
use indicatif::ProgressBar;
use serde::Serialize;
use std::sync::Arc;

/// Values of `π` per sweep (ends included).
pub const VALUES: usize = 13;

/// The methods run at every value of `π`: intensity, then the derivative
/// methods.
pub(crate) fn methods() -> impl Iterator<Item = Method> {
    std::iter::once(Method::Intensity).chain(DERIVATIVE_METHODS)
}

/// The reference at one value of `π`: `E`, the `∂E/∂π` plotted and the
/// factor the estimators' `∂E/∂π` is multiplied by to be that one.
pub(crate) type Exact = (f64, f64, f64);

/// One sweep, one column of the figure: what the figure asks of the
/// dimension's scene moved along one of its parameters.
pub(crate) trait Column {
    /// The scene the methods run on.
    type Scene;
    /// The swept parameter: the sensitivity judged.
    fn parameter(&self) -> &'static str;
    /// First and last value of `π`.
    fn range(&self) -> (f64, f64);
    /// The scene file written beside every record and curve, where the
    /// figure's sweeps move different scenes (flatland's).
    fn file(&self) -> Option<&'static str>;
    /// The scene as the panels' titles name it.
    fn title(&self) -> String;
    /// The label of the `π` axis.
    fn axis(&self) -> String;
    /// The reference curve's `E` and `∂E/∂π` at `π`.
    fn curve_at(&self, pi: f64) -> Result<(f64, f64), Error>;
    /// The scene moved to `π`, holding the swept parameter, and its
    /// reference.
    fn at(&self, pi: f64) -> Result<(Arc<Self::Scene>, Exact), Error>;
}

/// What else differs between the flatland and the 3D figure.
pub(crate) struct Spec {
    /// Prefix of the files (`flat`, `mesh`).
    pub prefix: &'static str,
    /// Points of the reference curves per sweep.
    pub curve_points: usize,
    /// Paths per run (times the effort).
    pub paths: u64,
    /// Base of the seed salts.
    pub salt: u64,
    /// The legend's label of the reference curves.
    pub reference: &'static str,
}

/// One estimate at one value of `π`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Record {
    /// Scene file name, where the figure's sweeps move different scenes.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub scene: Option<&'static str>,
    /// The parameter.
    pub parameter: &'static str,
    /// Its value (the scene moved by it).
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
    /// Relative variance of the variance (flatland's JSON leaves it out).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub vov: Option<f64>,
    /// The reference.
    pub exact: f64,
    /// `(mean − exact) / stderr`; 0 when the estimate is exact, `None`
    /// when `stderr = 0` but the estimate is not (finite differences whose
    /// step no path's visibility changes within).
    pub z: Option<f64>,
}

/// The reference curve of one sweep.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Curve {
    /// Scene file name, where the figure's sweeps move different scenes.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub scene: Option<&'static str>,
    /// The parameter.
    pub parameter: &'static str,
    /// Values of `π`.
    pub pi: Vec<f64>,
    /// `E(π)`.
    pub e: Vec<f64>,
    /// `∂E/∂π(π)`.
    pub de: Vec<f64>,
}

/// The numbers behind the figure.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AgainstPi {
    /// Every estimate.
    pub records: Vec<Record>,
    /// The reference curves.
    pub curves: Vec<Curve>,
}

/// The reference curve of `sweep` at `n` points.
fn curve<C: Column>(sweep: &C, n: usize) -> Result<Curve, Error> {
    let pi = grid(sweep.range(), n);
    let mut e = Vec::with_capacity(pi.len());
    let mut de = Vec::with_capacity(pi.len());
    for &p in &pi {
        let (v, d) = sweep.curve_at(p)?;
        e.push(v);
        de.push(d);
    }
    Ok(Curve {
        scene: sweep.file(),
        parameter: sweep.parameter(),
        pi,
        e,
        de,
    })
}

/// Runs every method ([`methods`]) with `spec.paths` paths on
/// `opts.threads` at [`VALUES`] values of `π` over the sweep's range. One
/// salt a run, from `salt` on.
fn measure<C: Column>(
    opts: &FigureOptions,
    spec: &Spec,
    sweep: &C,
    salt: &mut u64,
    bar: &ProgressBar,
) -> Result<Vec<Record>, Error>
where
    Arc<C::Scene>: Problem,
{
    let parameter = sweep.parameter();
    let mut runs = Vec::new();
    for pi in grid(sweep.range(), VALUES) {
        let (scene, (e, de, factor)) = sweep.at(pi)?;
        for method in methods() {
            *salt += 1;
            let r = run_method(opts, method, &scene, spec.paths, *salt, opts.threads)?;
            let (q, quantity, exact, f) = match method {
                Method::Intensity => (Quantity::Intensity, "E", e, 1.0),
                _ => (Quantity::sensitivity(parameter), "dE/dπ", de, factor),
            };
            let est = get(&r, &q)?;
            let (mean, stderr) = (est.mean * f, est.stderr * f);
            runs.push(Record {
                scene: sweep.file(),
                parameter,
                pi,
                method: method.name(),
                quantity,
                paths: r.paths,
                mean,
                stderr,
                vov: Some(est.vov),
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
const QUANTITIES: [(&str, &str); 2] = [("E", "E (irradiance)"), ("dE/dπ", "∂E/∂π")];

/// `(π, y)` split where `y` jumps (a step far larger than its neighbours'),
/// so that a jump is drawn as a gap rather than a steep line.
fn pieces(xy: &[(f64, f64)]) -> Vec<Vec<(f64, f64)>> {
    let steps: Vec<f64> = xy.windows(2).map(|w| (w[1].1 - w[0].1).abs()).collect();
    let span = xy.iter().map(|p| p.1).fold(f64::NEG_INFINITY, f64::max)
        - xy.iter().map(|p| p.1).fold(f64::INFINITY, f64::min);
    let mut out = vec![Vec::new()];
    for (i, &p) in xy.iter().enumerate() {
        if i > 0 {
            let s = steps[i - 1];
            let before = if i >= 2 { steps[i - 2] } else { 0.0 };
            let after = steps.get(i).copied().unwrap_or(0.0);
            if s > 1e-3 * span && s > 8.0 * before.max(after) {
                out.push(Vec::new());
            }
        }
        if let Some(last) = out.last_mut() {
            last.push(p);
        }
    }
    out
}

/// The markers of the panel of `quantity`: every method that estimates it,
/// side by side (`step` is the spacing of the values of `π`) so that the
/// error bars do not hide each other.
fn markers(quantity: &str, step: f64, records: &[Record]) -> Vec<Series> {
    let methods: Vec<Method> = if quantity == "E" {
        vec![Method::Intensity]
    } else {
        DERIVATIVE_METHODS.to_vec()
    };
    let mut series = Vec::new();
    for (k, &method) in methods.iter().enumerate() {
        let offset = (k as f64 - 0.5 * (methods.len() - 1) as f64) * 0.1 * step;
        let points = records
            .iter()
            .filter(|r| r.method == method.name() && r.quantity == quantity)
            .map(|r| (r.pi + offset, r.mean, r.stderr))
            .collect();
        series.push(Series::points("", color(method), points));
    }
    series
}

/// The figure's one legend, across its top (the same entries for every
/// panel, where a legend per panel would move from corner to corner): the
/// reference curve, labelled `reference`, and every method.
fn legend(reference: &str) -> Vec<Series> {
    let mut series = vec![Series::line(reference, REFERENCE_COLOR, vec![])];
    for method in methods() {
        series.push(Series::points(&super::label(method), color(method), vec![]));
    }
    series
}

/// The two panels of one sweep, `E` and `∂E/∂π`, each over its reference
/// curve (jumps drawn as gaps), without a legend of their own.
fn panels<C: Column>(sweep: &C, curve: &Curve, records: &[Record]) -> [Panel; 2] {
    let (lo, hi) = sweep.range();
    let step = (hi - lo) / (VALUES - 1) as f64;
    QUANTITIES.map(|(quantity, y_label)| {
        let ys = if quantity == "E" { &curve.e } else { &curve.de };
        let xy: Vec<(f64, f64)> = curve.pi.iter().copied().zip(ys.iter().copied()).collect();
        let mut series: Vec<Series> = pieces(&xy)
            .into_iter()
            .map(|piece| Series::line("", REFERENCE_COLOR, piece))
            .collect();
        series.extend(markers(quantity, step, records));
        Panel {
            title: format!(
                "{}: {} against {}",
                sweep.title(),
                quantity.replace("dE/dπ", "∂E/∂π"),
                curve.parameter
            ),
            x_label: sweep.axis(),
            y_label: y_label.into(),
            series,
            ..Panel::default()
        }
    })
}

/// Runs every sweep of `sweeps` (its reference curve, its runs) and draws
/// them, one column each, `E` on the top row and `∂E/∂π` below; returns the
/// numbers and the figure (to be saved as `<prefix>_against_pi`).
pub(crate) fn figure<C: Column>(
    opts: &FigureOptions,
    spec: &Spec,
    sweeps: &[C],
) -> Result<(AgainstPi, Figure), Error>
where
    Arc<C::Scene>: Problem,
{
    let runs = sweeps.len() * VALUES * methods().count();
    let bar = opts.bar(runs as u64, &format!("{}: against π", spec.prefix));
    let mut salt = spec.salt;
    let mut numbers = AgainstPi {
        records: Vec::new(),
        curves: Vec::new(),
    };
    let (mut top, mut bottom) = (Vec::new(), Vec::new());
    for sweep in sweeps {
        let c = curve(sweep, spec.curve_points)?;
        let r = measure(opts, spec, sweep, &mut salt, &bar)?;
        let [e, de] = panels(sweep, &c, &r);
        top.push(e);
        bottom.push(de);
        numbers.records.extend(r);
        numbers.curves.push(c);
    }
    bar.finish();
    top.extend(bottom);
    let mut figure = Figure::new(top, sweeps.len());
    figure.legend = legend(spec.reference);
    Ok((numbers, figure))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn jumps_break_the_curve() {
        let xy: Vec<(f64, f64)> = (0..20)
            .map(|i| {
                let x = f64::from(i) / 19.0;
                (x, x + if x > 0.5 { 1.0 } else { 0.0 })
            })
            .collect();
        let p = pieces(&xy);
        assert_eq!(p.len(), 2);
        assert_eq!(p[0].len() + p[1].len(), 20);
        // A kink is not a jump.
        let kink: Vec<(f64, f64)> = (0..20)
            .map(|i| {
                let x = f64::from(i) / 19.0 - 0.5;
                (x, x.abs())
            })
            .collect();
        assert_eq!(pieces(&kink).len(), 1);
    }
}
