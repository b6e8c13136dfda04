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
use super::{DERIVATIVE_METHODS, FigureOptions, color, save};
use crate::error::Error;
use crate::figures_common::stability::{self, measure};
use crate::flat::Scene;
use crate::flat::exact::Reference;
use crate::plot::{Figure, Legend, Panel, Series};
use std::path::PathBuf;

/// Paths per run at effort 1.
const PATHS: u64 = 100_000;
/// Base of the seed salts of this figure.
const SALT: u64 = 60_000_000;

/// One run (`case`: `"knots"`, `"sensor"` or `"thin"`; `distance`: `g`, `d`
/// or `t`; `exact`: the analytic `∂E/∂π` where one exists; `z`:
/// `|mean − exact| / σ`).
pub use crate::figures_common::stability::Record;

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
    let builds: Vec<_> = CASES
        .iter()
        .map(|&(_, _, _, build)| {
            move |distance: f64| -> Result<(Scene, Option<f64>), Error> {
                let scene = build(distance)?;
                let exact = Reference::for_scene(&scene).ok().map(|r| r.derivative(0));
                Ok((scene, exact))
            }
        })
        .collect();
    let cases: Vec<stability::Case<'_, Scene>> = CASES
        .iter()
        .zip(&builds)
        .map(|(&(case, _, distances, _), build)| (case, distances, build as _))
        .collect();
    let records = measure(opts, "flat: stability", &cases, PATHS, SALT, |e, x| {
        Some(e.z_score(x))
    })?;
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
