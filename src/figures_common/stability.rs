//! The runs of the flatland and 3D stability figures: every derivative
//! method ([`DERIVATIVE_METHODS`]) on a scene built at each distance to a
//! singular configuration, the sensitivity to its parameter `p` judged;
//! and the figure that shows them, one column per case: the per-path
//! variance with its error bar above, the bias below.
use super::{DERIVATIVE_METHODS, REFERENCE_COLOR, color};
use super::{FigureOptions, get, run_method, save, z};
use crate::error::Error;
use crate::estimator::Quantity;
use crate::method::Problem;
use crate::plot::{Figure, Panel, Series, spread};
use serde::Serialize;
use std::path::PathBuf;
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

/// One case: its name (in the records), its panels' title, the label of
/// its distance axis, its distances, its paths per run (times the effort),
/// and the scene (parameter `p`) at a distance with its exact `∂E/∂p` if
/// known.
pub(crate) type Case<S> = (
    &'static str,
    &'static str,
    &'static str,
    &'static [f64],
    u64,
    fn(f64) -> Result<(S, Option<f64>), Error>,
);

/// The seeds of the runs: `opts.seed` plus a salt.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Salt {
    /// One salt a run from this one on.
    Each(u64),
    /// This salt for every run (common random numbers across the runs, as
    /// a test that runs each with one seed).
    All(u64),
}

/// Runs every derivative method on `opts.threads` at every distance of
/// every case, seeds from `salt`. `what` names the progress bar.
fn measure<S>(
    opts: &FigureOptions,
    what: &str,
    cases: &[Case<S>],
    salt: Salt,
) -> Result<Vec<Record>, Error>
where
    Arc<S>: Problem,
{
    let total: usize = cases.iter().map(|c| c.3.len()).sum();
    let bar = opts.bar((total * DERIVATIVE_METHODS.len()) as u64, what);
    let mut records = Vec::new();
    let mut next = match salt {
        Salt::Each(s) | Salt::All(s) => s,
    };
    for &(case, _, _, distances, paths, build) in cases {
        for &distance in distances {
            let (scene, exact) = build(distance)?;
            let scene = Arc::new(scene);
            for method in DERIVATIVE_METHODS {
                if let Salt::Each(_) = salt {
                    next += 1;
                }
                let r = run_method(opts, method, &scene, paths, next, opts.threads)?;
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
                    z: exact.and_then(|x| z(e.mean, e.stderr, x)),
                });
                bar.inc(1);
            }
        }
    }
    bar.finish();
    Ok(records)
}

/// The case's per-path variance `σ²N` of `∂E/∂p` (named `derivative`, e.g.
/// `"∂E/∂π"`) against the distance, log–log, every derivative method as
/// points with error bars `±σ²N·√VOV` (the VOV is the relative variance of
/// the variance estimate), the methods side by side.
fn variance_panel(
    case: &str,
    title: &str,
    axis: &str,
    derivative: &str,
    records: &[Record],
) -> Panel {
    let n = DERIVATIVE_METHODS.len();
    let series = DERIVATIVE_METHODS
        .iter()
        .enumerate()
        .map(|(k, &m)| {
            let pts = records
                .iter()
                .filter(|r| {
                    r.case == case && r.method == m.name() && r.variance > 0.0 && r.distance > 0.0
                })
                .map(|r| {
                    (
                        spread(r.distance, k, n, true, 0.0),
                        r.variance,
                        r.variance * r.vov.max(0.0).sqrt(),
                    )
                })
                .collect();
            Series::points(m.name(), color(m), pts)
        })
        .collect();
    Panel {
        title: title.into(),
        x_label: axis.into(),
        y_label: format!("σ² N of {derivative} (bars: ±σ²N·√VOV)"),
        x_log: true,
        y_log: true,
        series,
        ..Panel::default()
    }
}

/// Where the bias panels clamp `(mean − exact)/σ`: a run beyond it is drawn
/// as a hollow triangle on the clamp line (its JSON keeps the value).
const CLAMP: f64 = 12.0;

/// Palette index of the clamp's legend entry (black).
const CLAMPED_COLOR: usize = REFERENCE_COLOR;

/// The legend entry of the runs drawn at the clamp.
fn clamped_key() -> Series {
    Series::triangles(
        &format!("|mean − exact|/σ > {CLAMP}: drawn at ±{CLAMP} (△ above, ▽ below)"),
        CLAMPED_COLOR,
        vec![],
    )
}

/// The case's bias against the distance: `(mean − exact)/σ` with a bar of
/// one, dashed lines at ±4, where every run has an exact value, a run
/// beyond ±[`CLAMP`] drawn as a hollow triangle on the clamp line; the
/// estimates themselves (`mean ± σ`) where not.
fn bias_panel(case: &str, axis: &str, derivative: &str, records: &[Record]) -> Panel {
    let mine: Vec<&Record> = records
        .iter()
        .filter(|r| r.case == case && r.distance > 0.0)
        .collect();
    let has_exact = mine.iter().all(|r| r.exact.is_some());
    let (lo, hi) = mine.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), r| {
        (lo.min(r.distance), hi.max(r.distance))
    });
    let n = DERIVATIVE_METHODS.len();
    let mut series = Vec::new();
    for (k, &m) in DERIVATIVE_METHODS.iter().enumerate() {
        let of_method = || mine.iter().filter(|r| r.method == m.name());
        let x = |r: &Record| spread(r.distance, k, n, true, 0.0);
        if !has_exact {
            let pts = of_method().map(|r| (x(r), r.mean, r.stderr)).collect();
            series.push(Series::points("", color(m), pts));
            continue;
        }
        // z with a bar of one (the error bar in units of σ); a wrong
        // estimate reporting σ = 0 is infinitely far.
        let z_of = |r: &Record| {
            r.z.or_else(|| Some((r.mean - r.exact?).signum() * f64::INFINITY))
        };
        let z = || of_method().filter_map(|r| Some((x(r), z_of(r)?)));
        let inside = z()
            .filter(|p| p.1.abs() <= CLAMP)
            .map(|(x, z)| (x, z, 1.0))
            .collect();
        series.push(Series::points("", color(m), inside));
        let beyond: Vec<_> = z()
            .filter(|p| p.1.abs() > CLAMP)
            .map(|(x, z)| (x, CLAMP.copysign(z), z > 0.0))
            .collect();
        if !beyond.is_empty() {
            series.push(Series::triangles("", color(m), beyond));
        }
    }
    if has_exact {
        for y in [-4.0, 4.0] {
            series.push(Series::dashed("", REFERENCE_COLOR, vec![(lo, y), (hi, y)]));
        }
    }
    Panel {
        title: if has_exact {
            format!("bias (mean − exact)/σ; dashed ±4; △▽ beyond ±{CLAMP}")
        } else {
            "no closed form: the estimates, mean ± σ".into()
        },
        x_label: axis.into(),
        y_label: if has_exact {
            "(mean − exact)/σ".into()
        } else {
            derivative.into()
        },
        x_log: true,
        series,
        ..Panel::default()
    }
}

/// Runs every case of `cases` (one column each: the variance above, the
/// bias below, `derivative` naming `∂E/∂p` on the axes), seeds from
/// `salt`, and writes `<prefix>_stability.{png,svg,json}` with panels of
/// `panel_size` pixels.
pub(crate) fn figure<S>(
    opts: &FigureOptions,
    prefix: &str,
    cases: &[Case<S>],
    salt: Salt,
    derivative: &str,
    panel_size: (u32, u32),
) -> Result<Vec<PathBuf>, Error>
where
    Arc<S>: Problem,
{
    let records = measure(opts, &format!("{prefix}: stability"), cases, salt)?;
    let mut panels: Vec<Panel> = cases
        .iter()
        .map(|&(case, title, axis, ..)| variance_panel(case, title, axis, derivative, &records))
        .collect();
    panels.extend(
        cases
            .iter()
            .map(|&(case, _, axis, ..)| bias_panel(case, axis, derivative, &records)),
    );
    let mut figure = Figure::new(panels, cases.len()).share_legend();
    // Every case keeps the entry, clamped runs or not: one legend for all.
    figure.legend.push(clamped_key());
    figure.panel_size = panel_size;
    save(opts, &format!("{prefix}_stability"), &figure, &records)
}
