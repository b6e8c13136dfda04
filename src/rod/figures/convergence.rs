//! Convergence of every method to the exact solution (extends the paper's
//! Fig. 6e): the standard error σ and the actual error |mean − exact|
//! against the number of paths N, log–log, for the intensity estimator's
//! `I` and the expectation, rendering and transport estimators' `s = ∂I/∂π̃`,
//! on the thin and thick rods, at an interior probe (`x = 1`) and near the
//! moving end (`x = 1.95`), both directions. A dashed `∝ 1/√N` line is the
//! rate every unbiased finite-variance estimator must show. The book
//! discusses it in the chapter "Comparing the approaches".
//!
//! The run records and the error panel are shared with
//! [`efficiency`](super::efficiency).
use super::{FigureOptions, exact_value, thick, thin};
use crate::error::Error;
use crate::estimator::Quantity;
use crate::figures_common::color;
use crate::figures_common::convergence::{sigma_and_error, sigma_panel, slope};
use crate::plot::{Figure, Panel, spread};
use crate::rod::{Direction, Method, PARAMETER, Rod};
use serde::Serialize;
use std::path::PathBuf;

pub use crate::figures_common::convergence::path_counts;

/// The probe position near the moving end `π̃ = 2`.
pub const NEAR_END: f64 = 1.95;

/// The probes `(x, ω)` of the convergence figure, one row of panels each:
/// interior and near the moving end, `ω = −1` (where the sensitivity is
/// largest) first.
pub const PROBES: [(f64, Direction); 4] = [
    (1.0, Direction::Left),
    (NEAR_END, Direction::Left),
    (1.0, Direction::Right),
    (NEAR_END, Direction::Right),
];

/// Base of the seed salts of this figure (distinct from the other figures').
const SALT: u64 = 10_000_000;

/// What `method` is judged on: `I` for the intensity estimator, `s = ∂I/∂π̃`
/// for the three sensitivity estimators.
pub fn judged(method: Method) -> Quantity {
    match method {
        Method::Intensity => Quantity::Intensity,
        _ => Quantity::sensitivity(PARAMETER),
    }
}

/// Legend label and palette index of `method` in both figures.
pub(super) fn style(method: Method) -> (String, usize) {
    (
        format!("{} ({})", method.name(), judged(method)),
        color(method),
    )
}

/// One of the paper's rods at one probe.
#[derive(Debug, Clone, Copy)]
pub(super) struct Case {
    /// `"thin"` or `"thick"`.
    pub rod_name: &'static str,
    /// The rod.
    pub rod: Rod,
    /// Probe position.
    pub x: f64,
    /// Probe direction.
    pub omega: Direction,
}

/// `"thick rod (κs = 2.1, κe = 3)"`.
pub(super) fn rod_title(name: &str, rod: &Rod) -> String {
    format!("{name} rod (κs = {}, κe = {})", rod.ks, rod.ke)
}

/// The paper's thin and thick rods with their names.
pub(super) fn rods() -> [(&'static str, Rod); 2] {
    [("thin", thin()), ("thick", thick())]
}

/// `"ω = −1"` or `"ω = +1"`.
pub(super) fn omega_label(omega: Direction) -> &'static str {
    match omega {
        Direction::Right => "ω = +1",
        Direction::Left => "ω = −1",
    }
}

/// One run of one method at one probe, judged against the exact value: a
/// row of `convergence.json` and `efficiency.json`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Record {
    /// Method name.
    pub method: &'static str,
    /// The quantity judged (`I` or `∂I/∂length`).
    pub quantity: String,
    /// `"thin"` or `"thick"`.
    pub rod: &'static str,
    /// Probe position.
    pub x: f64,
    /// Probe direction, `+1` or `−1`.
    pub omega: f64,
    /// Paths sampled, `N`.
    pub paths: u64,
    /// The estimate.
    pub mean: f64,
    /// The exact value.
    pub exact: f64,
    /// Its standard error `σ`.
    pub stderr: f64,
    /// `mean − exact`.
    pub error: f64,
    /// Relative variance of the variance (tail diagnostic).
    pub vov: f64,
    /// Sampling wall time `t` in seconds.
    pub seconds: f64,
    /// Work-normalised variance `σ²·t`: independent of `N` once asymptotic.
    pub work: f64,
}

impl Record {
    /// Runs `method` at `case` with `paths` (effort-scaled) paths and seed
    /// `opts.seed + salt`, and judges it against the exact value.
    pub(super) fn measure(
        opts: &FigureOptions,
        method: Method,
        case: Case,
        paths: u64,
        salt: u64,
    ) -> Result<Record, Error> {
        let q = judged(method);
        let r = opts.run(method, case.rod, case.x, case.omega, paths, salt)?;
        let e = r
            .get(&q)
            .ok_or_else(|| Error::Output(format!("{} does not estimate {q}", method.name())))?;
        let exact = exact_value(&case.rod, case.x, case.omega, &q);
        Ok(Record {
            method: method.name(),
            quantity: q.to_string(),
            rod: case.rod_name,
            x: case.x,
            omega: case.omega.sign(),
            paths: r.paths,
            mean: e.mean,
            exact,
            stderr: e.stderr,
            error: e.mean - exact,
            vov: e.vov,
            seconds: r.seconds,
            work: e.stderr * e.stderr * r.seconds,
        })
    }
}

/// A log–log panel of every method in `records` against `x_of` (the path
/// count or the wall time): σ as a line, |error| as points, and a dashed
/// `∝ x^{−1/2}` reference (labelled `reference`) through the expectation
/// method's σ at its largest `x` (or the first method's, without it).
pub(super) fn error_panel(
    title: String,
    x_label: &str,
    reference: &str,
    records: &[Record],
    x_of: fn(&Record) -> f64,
) -> Panel {
    let mut series = Vec::new();
    let n = Method::UNBIASED.len();
    for (k, method) in Method::UNBIASED.into_iter().enumerate() {
        let mut rs: Vec<&Record> = records
            .iter()
            .filter(|r| r.method == method.name())
            .collect();
        if rs.is_empty() {
            continue;
        }
        rs.sort_by(|a, b| x_of(a).total_cmp(&x_of(b)));
        let sigma = rs.iter().map(|r| (x_of(r), r.stderr)).collect();
        // The dots side by side: methods that draw the same random numbers
        // give the same error.
        let error = rs
            .iter()
            .map(|r| (spread(x_of(r), k, n, true, 0.0), r.error.abs(), 0.0))
            .collect();
        series.extend(sigma_and_error(method, &style(method).0, sigma, error));
    }
    let xs = records.iter().map(x_of);
    let lo = xs.clone().fold(f64::INFINITY, f64::min);
    let hi = xs.fold(f64::NEG_INFINITY, f64::max);
    let expectation = Method::Expectation.name();
    let anchor_method = if records.iter().any(|r| r.method == expectation) {
        expectation
    } else {
        records.first().map_or(expectation, |r| r.method)
    };
    let anchor = records
        .iter()
        .filter(|r| r.method == anchor_method)
        .max_by(|a, b| x_of(a).total_cmp(&x_of(b)));
    if let Some(a) = anchor {
        series.push(slope(reference, a.stderr * x_of(a).sqrt(), (lo, hi)));
    }
    sigma_panel(title, x_label, series)
}

/// The convergence figure: σ and |error| against N (10² to 10⁷ paths in
/// half decades, times the effort; a fresh seed per run) for every method,
/// thin and thick rods (columns) at `x = 1` and `x = 1.95`, `ω = −1` then
/// `ω = +1` (rows). Runs on `opts.threads`. Writes `convergence.{png,svg}`
/// and the numbers to `convergence.json`.
pub fn convergence(opts: &FigureOptions) -> Result<Vec<PathBuf>, Error> {
    let counts = path_counts(2, 7);
    let runs = PROBES.len() * 2 * Method::UNBIASED.len() * counts.len();
    let bar = opts.bar(runs as u64, "convergence");
    let mut records = Vec::with_capacity(runs);
    let mut panels = Vec::new();
    let mut salt = SALT;
    for (x, omega) in PROBES {
        for (rod_name, rod) in rods() {
            let case = Case {
                rod_name,
                rod,
                x,
                omega,
            };
            let first = records.len();
            for method in Method::UNBIASED {
                for &n in &counts {
                    salt += 1;
                    records.push(Record::measure(opts, method, case, n, salt)?);
                    bar.inc(1);
                }
            }
            let title = format!(
                "{}, x = {x}, {}",
                rod_title(rod_name, &rod),
                omega_label(omega)
            );
            panels.push(error_panel(
                title,
                "N (paths)",
                "∝ 1/√N",
                &records[first..],
                |r| r.paths as f64,
            ));
        }
    }
    bar.finish();
    let json = opts.write_json("convergence", &records)?;
    let mut written = Figure::new(panels, 2)
        .share_legend()
        .save(&opts.out, "convergence")?;
    written.push(json);
    Ok(written)
}
