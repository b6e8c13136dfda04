//! The convergence figures of flatland and 3D: every method ([`METHODS`])
//! run at 10³ to 10⁶ paths on one scene, σ and |mean − exact| against the
//! number of paths, log–log; and the pieces of such a panel the rod's
//! figures draw too (a method's σ and errors, the `∝ 1/√N` slope, the
//! panel with its legend's key).
use super::{FigureOptions, get, run_method};
use super::{METHODS, REFERENCE_COLOR, color};
use crate::error::Error;
use crate::estimator::Quantity;
use crate::method::{Method, Problem};
use crate::plot::{Legend, Mark, Panel, Series, quiet_corner, spread};
use serde::Serialize;
use std::sync::Arc;

/// Path counts in half decades from `10^lo` to `10^hi`, ends included
/// (before the effort scaling).
pub fn path_counts(lo: u32, hi: u32) -> Vec<u64> {
    (2 * lo..=2 * hi)
        .map(|k| 10f64.powf(f64::from(k) / 2.0).round() as u64)
        .collect()
}

/// One estimate of one run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Record {
    /// Method name.
    pub method: &'static str,
    /// The parameter of the panel; `None` where the figure has one and
    /// names it once, beside the records (flatland's).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub parameter: Option<&'static str>,
    /// `"E"` (intensity) or `"dE/dπ"`.
    pub quantity: &'static str,
    /// Paths sampled, `N`.
    pub paths: u64,
    /// The estimate.
    pub mean: f64,
    /// Its standard error σ.
    pub stderr: f64,
    /// The closed form.
    pub exact: f64,
    /// `mean − exact`.
    pub error: f64,
    /// Relative variance of the variance.
    pub vov: f64,
    /// Sampling wall time of the run, seconds.
    pub seconds: f64,
}

/// Runs every method on `scene` at 10³ to 10⁶ paths in half decades (times
/// the effort) on `opts.threads`, one salt a run from `salt` on; of every
/// run, the intensity estimator is judged on `E` (`e`), the others on the
/// sensitivity of every `(parameter, exact)` of `parameters`. `what` names
/// the progress bar.
pub(crate) fn measure<S>(
    opts: &FigureOptions,
    what: &str,
    scene: &Arc<S>,
    e: f64,
    parameters: &[(&'static str, f64)],
    mut salt: u64,
) -> Result<Vec<Record>, Error>
where
    Arc<S>: Problem,
{
    let counts = path_counts(3, 6);
    let bar = opts.bar((METHODS.len() * counts.len()) as u64, what);
    let mut runs = Vec::new();
    for method in METHODS {
        for &n in &counts {
            salt += 1;
            let r = run_method(opts, method, scene, n, salt, opts.threads)?;
            for &(parameter, de) in parameters {
                let (q, quantity, exact) = match method {
                    Method::Intensity => (Quantity::Intensity, "E", e),
                    _ => (Quantity::sensitivity(parameter), "dE/dπ", de),
                };
                let est = get(&r, &q)?;
                runs.push(Record {
                    method: method.name(),
                    parameter: Some(parameter),
                    quantity,
                    paths: r.paths,
                    mean: est.mean,
                    stderr: est.stderr,
                    exact,
                    error: est.mean - exact,
                    vov: est.vov,
                    seconds: r.seconds,
                });
            }
            bar.inc(1);
        }
    }
    bar.finish();
    Ok(runs)
}

/// The log–log panel titled `title`: σ as lines, |error| as dots, of the
/// records of `parameter`, and a `∝ 1/√N` line a factor 3 under the lowest
/// σ at the largest N.
pub(crate) fn panel(title: String, records: &[Record], parameter: &str) -> Panel {
    let rows: Vec<_> = records
        .iter()
        .filter(|r| r.parameter == Some(parameter))
        .map(|r| (r.method, r.paths, r.stderr, r.error))
        .collect();
    let mut series = Vec::new();
    for (k, method) in METHODS.into_iter().enumerate() {
        let rs: Vec<_> = rows.iter().filter(|r| r.0 == method.name()).collect();
        let sigma = rs.iter().map(|r| (r.1 as f64, r.2)).collect();
        // The dots side by side, not on top of each other.
        let error = rs
            .iter()
            .map(|r| {
                (
                    spread(r.1 as f64, k, METHODS.len(), true, 0.0),
                    r.3.abs(),
                    0.0,
                )
            })
            .collect();
        series.extend(sigma_and_error(method, &super::label(method), sigma, error));
    }
    // The reference slope, a factor 3 under the lowest σ at the largest N
    // so that it hides no curve.
    let ns = rows.iter().map(|r| r.1 as f64);
    let (lo, hi) = ns.fold((f64::INFINITY, 0.0f64), |(lo, hi), n| {
        (lo.min(n), hi.max(n))
    });
    let lowest = rows
        .iter()
        .filter(|r| r.1 as f64 == hi && r.2 > 0.0)
        .map(|r| r.2)
        .fold(f64::INFINITY, f64::min);
    if lowest.is_finite() {
        series.push(slope("∝ 1/√N", lowest / 3.0 * hi.sqrt(), (lo, hi)));
    }
    let mut panel = sigma_panel(title, "N (paths)", series);
    panel.legend = quiet_corner(
        &panel,
        &[Legend::LowerLeft, Legend::UpperRight],
        (0.45, 0.4),
    )
    .0;
    panel
}

/// `method`'s σ against `x` as a line labelled `label` (wide dashes for
/// transport: its σ often lies on rendering's, and [`layered`] draws it
/// first, so rendering's line runs on top through its dashes) and its
/// `(x, |mean − exact|, 0)` as dots.
pub(crate) fn sigma_and_error(
    method: Method,
    label: &str,
    sigma: Vec<(f64, f64)>,
    error: Vec<(f64, f64, f64)>,
) -> [Series; 2] {
    let line = if method == Method::Transport {
        Series::dashes
    } else {
        Series::line
    };
    [
        line(label, color(method), sigma),
        Series::points("", color(method), error),
    ]
}

/// `series` in a legend's order and a drawing order: first a key of every
/// labelled series (as given), then the data, unlabelled, the wide dashes
/// first so that a line lying on them is drawn on top and both show.
pub(crate) fn layered(series: Vec<Series>) -> Vec<Series> {
    let mut out: Vec<Series> = series
        .iter()
        .filter(|s| !s.label.is_empty())
        .map(Series::key)
        .collect();
    let (under, over): (Vec<Series>, Vec<Series>) = series
        .into_iter()
        .partition(|s| matches!(s.mark, Mark::Dashes(_)));
    out.extend(under.into_iter().chain(over).map(|mut s| {
        s.label.clear();
        s
    }));
    out
}

/// The dashed reference `c/√x` from `x = lo` to `hi`, labelled `label`:
/// the rate of an unbiased finite-variance estimator.
pub(crate) fn slope(label: &str, c: f64, (lo, hi): (f64, f64)) -> Series {
    Series::dashed(
        label,
        REFERENCE_COLOR,
        vec![(lo, c / lo.sqrt()), (hi, c / hi.sqrt())],
    )
}

/// The log–log panel titled `title` of σ (lines) and |mean − exact| (dots)
/// against `x_label`, drawing `series` ([`layered`]) after two legend
/// entries that say what lines and dots are (they draw nothing).
pub(crate) fn sigma_panel(title: String, x_label: &str, series: Vec<Series>) -> Panel {
    let mut all = vec![
        Series::line("σ (lines)", REFERENCE_COLOR, vec![]),
        Series::legend_dot("|mean − exact| (dots)", REFERENCE_COLOR),
    ];
    all.extend(layered(series));
    Panel {
        title,
        x_label: x_label.into(),
        y_label: "σ (lines), |mean − exact| (dots)".into(),
        x_log: true,
        y_log: true,
        series: all,
        ..Panel::default()
    }
}
