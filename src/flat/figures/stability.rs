//! Where the flatland methods fail (the book's "Where the methods fail"):
//! the per-path variance `σ² N` of `∂E/∂π` against the distance to a
//! singular configuration, log–log, one panel per failure, every derivative
//! method:
//!
//! 1. two warp knots meeting: a black segment's corner seen a gap `g` inside
//!    the lamp's end (expectation's variance grows like `1/g`);
//! 2. a sensor at distance `d` from the moving edge of the absorbing box it
//!    sits in (every method's variance grows like `1/d`; the exact
//!    derivative like `ln 1/d`);
//! 3. a thin dense scattering slab of thickness `t` and fixed optical
//!    thickness, translated (variance `∝ 1/t`, transport's `∝ 1/t²`).
//!
//! Finite differences are drawn too; where they are biased (their step
//! larger than `g` or `d`) the JSON's `z` says so. `tests/flat_failures.rs`
//! pins the first two.
use super::{DERIVATIVE_METHODS, FigureOptions, color, run_method, save};
use crate::error::Error;
use crate::estimator::Quantity;
use crate::flat::Scene;
use crate::flat::exact::Reference;
use crate::plot::{Figure, Legend, Panel, Series};
use serde::Serialize;
use std::path::PathBuf;
use std::sync::Arc;

/// Paths per run at effort 1.
const PATHS: u64 = 100_000;
/// Base of the seed salts of this figure.
const SALT: u64 = 60_000_000;

/// One run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Record {
    /// Which failure (`"knots"`, `"sensor"`, `"thin"`).
    pub case: &'static str,
    /// The distance to the singular configuration (`g`, `d` or `t`).
    pub distance: f64,
    /// Method name.
    pub method: &'static str,
    /// Estimate of `∂E/∂π`.
    pub mean: f64,
    /// Its standard error.
    pub stderr: f64,
    /// Paths.
    pub paths: u64,
    /// `σ² N`.
    pub variance: f64,
    /// Relative variance of the variance.
    pub vov: f64,
    /// The analytic `∂E/∂π` where one exists.
    pub exact: Option<f64>,
    /// `|mean − exact| / σ` where an exact value exists.
    pub z: Option<f64>,
}

pub use crate::flat::cases::{knots, sensor_near_edge, thin_slab};

/// The three cases: name, axis label, distances, scene builder.
type Case = (
    &'static str,
    &'static str,
    &'static [f64],
    fn(f64) -> Result<Scene, Error>,
);
const CASES: [Case; 3] = [
    (
        "knots",
        "gap g between two warp knots",
        &[0.1, 0.03, 0.01, 3e-3, 1e-3, 3e-4, 1e-4],
        knots,
    ),
    (
        "sensor",
        "distance d of the sensor to the moving edge",
        &[0.3, 0.1, 0.03, 0.01, 3e-3, 1e-3],
        sensor_near_edge,
    ),
    (
        "thin",
        "thickness t of the slab (optical thickness 0.3)",
        &[0.3, 0.1, 0.03, 0.01, 3e-3],
        thin_slab,
    ),
];

/// Runs the three cases and writes `flat_stability.{png,svg,json}`.
pub fn stability(opts: &FigureOptions) -> Result<Vec<PathBuf>, Error> {
    let total: usize = CASES.iter().map(|c| c.2.len()).sum();
    let bar = opts.bar((total * DERIVATIVE_METHODS.len()) as u64, "flat: stability");
    let mut records = Vec::new();
    let mut salt = SALT;
    for (case, _, distances, build) in CASES {
        for &distance in distances {
            let scene = Arc::new(build(distance)?);
            let exact = Reference::for_scene(&scene).ok().map(|r| r.derivative(0));
            for method in DERIVATIVE_METHODS {
                salt += 1;
                let r = run_method(opts, method, &scene, PATHS, salt, opts.threads)?;
                let e = r
                    .get(&Quantity::sensitivity("p"))
                    .ok_or_else(|| Error::Output("no sensitivity estimate".into()))?;
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
                    z: exact.map(|x| e.z_score(x)),
                });
                bar.inc(1);
            }
        }
    }
    bar.finish();
    let panels = CASES
        .iter()
        .map(|&(case, axis, _, _)| {
            let series = DERIVATIVE_METHODS
                .iter()
                .map(|&m| {
                    let pts: Vec<(f64, f64)> = records
                        .iter()
                        .filter(|r| r.case == case && r.method == m.name() && r.variance > 0.0)
                        .map(|r| (r.distance, r.variance))
                        .collect();
                    Series::line(m.name(), color(m), pts)
                })
                .collect();
            Panel {
                title: match case {
                    "knots" => "two warp knots meeting".into(),
                    "sensor" => "a sensor near a moving edge".into(),
                    _ => "a thin dense slab".into(),
                },
                x_label: axis.into(),
                y_label: "σ² N of ∂E/∂π".into(),
                x_log: true,
                y_log: true,
                series,
                legend: Legend::UpperRight,
                ..Panel::default()
            }
        })
        .collect();
    let mut figure = Figure::new(panels, 3);
    figure.panel_size = (620, 480);
    save(opts, "stability", &figure, &records)
}
