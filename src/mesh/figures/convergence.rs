//! 3D convergence to the closed form: the standard error σ (lines) and the
//! actual error |mean − exact| (dots) against the number of paths N (10³
//! to 10⁶ in half decades times the effort, a fresh seed per run),
//! log–log, for every method on the nominal black triangle occluder
//! ([`TriangleOccluder::NOMINAL`]) with two parameters, its translation
//! along x and its rotation about the vertical (one panel each; one run of
//! a method gives both). The intensity estimator is judged on `E`, the
//! others on `∂E/∂π`. A dashed `∝ 1/√N` line is the rate an unbiased
//! finite-variance estimator shows.
use super::{FigureOptions, METHODS, REFERENCE_COLOR, color, get, label, run_method, save};
use crate::error::Error;
use crate::estimator::Quantity;
use crate::mesh::cases::TriangleOccluder;
use crate::method::Method;
use crate::plot::{Figure, Legend, Panel, Series, quiet_corner};
use crate::rod::figures::convergence::path_counts;
use serde::Serialize;
use std::path::PathBuf;
use std::sync::Arc;

/// The parameters judged (indices into [`TriangleOccluder::PARAMETERS`]).
pub const PARAMETERS: [usize; 2] = [0, 1];

/// Base of the seed salts of this figure (distinct from the other figures').
const SALT: u64 = 71_000_000;

/// One estimate of one run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Record {
    /// Method name.
    pub method: &'static str,
    /// The parameter of the panel.
    pub parameter: &'static str,
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

/// The log–log panel of one parameter.
fn panel(parameter: &str, records: &[Record]) -> Panel {
    let mine: Vec<&Record> = records
        .iter()
        .filter(|r| r.parameter == parameter)
        .collect();
    let mut series = Vec::new();
    for method in METHODS {
        let rs: Vec<&&Record> = mine.iter().filter(|r| r.method == method.name()).collect();
        let sigma = rs.iter().map(|r| (r.paths as f64, r.stderr)).collect();
        let error = rs
            .iter()
            .map(|r| (r.paths as f64, r.error.abs(), 0.0))
            .collect();
        series.push(Series::line(&label(method), color(method), sigma));
        series.push(Series::points("", color(method), error));
    }
    let ns = mine.iter().map(|r| r.paths as f64);
    let (lo, hi) = ns.fold((f64::INFINITY, 0.0f64), |(lo, hi), n| {
        (lo.min(n), hi.max(n))
    });
    let lowest = mine
        .iter()
        .filter(|r| r.paths as f64 == hi && r.stderr > 0.0)
        .map(|r| r.stderr)
        .fold(f64::INFINITY, f64::min);
    if lowest.is_finite() {
        let k = lowest / 3.0 * hi.sqrt();
        series.push(Series::dashed(
            "∝ 1/√N",
            REFERENCE_COLOR,
            vec![(lo, k / lo.sqrt()), (hi, k / hi.sqrt())],
        ));
    }
    let mut panel = Panel {
        title: format!("triangle occluder, π = {parameter}: error against paths"),
        x_label: "N (paths)".into(),
        y_label: "σ (lines), |mean − exact| (dots)".into(),
        x_log: true,
        y_log: true,
        series,
        ..Panel::default()
    };
    panel.legend = quiet_corner(
        &panel,
        &[Legend::LowerLeft, Legend::UpperRight],
        (0.45, 0.4),
    )
    .0;
    panel
}

/// σ and |mean − exact| against N for every method on the triangle
/// occluder's translation along x and rotation (one panel each), 10³ to
/// 10⁶ paths in half decades times the effort on `opts.threads`, against
/// the closed form. Writes `mesh_convergence.{png,svg,json}`:
///
/// ```text
/// cargo run --release --example fig_mesh_convergence -- [OUT_DIR] [EFFORT]
/// ```
pub fn convergence(opts: &FigureOptions) -> Result<Vec<PathBuf>, Error> {
    let t = TriangleOccluder::NOMINAL;
    let scene = Arc::new(t.scene(&PARAMETERS)?);
    let (e, de) = t.exact()?;
    let counts = path_counts(3, 6);
    let bar = opts.bar((METHODS.len() * counts.len()) as u64, "mesh: convergence");
    let mut records = Vec::new();
    let mut salt = SALT;
    for method in METHODS {
        for &n in &counts {
            salt += 1;
            let r = run_method(opts, method, &scene, n, salt, opts.threads)?;
            for k in PARAMETERS {
                let name = TriangleOccluder::PARAMETERS[k];
                let (q, quantity, exact) = match method {
                    Method::Intensity => (Quantity::Intensity, "E", e),
                    _ => (Quantity::sensitivity(name), "dE/dπ", de[k]),
                };
                let est = get(&r, &q)?;
                records.push(Record {
                    method: method.name(),
                    parameter: name,
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
    let panels = PARAMETERS
        .iter()
        .map(|&k| panel(TriangleOccluder::PARAMETERS[k], &records))
        .collect();
    let mut figure = Figure::new(panels, 2);
    figure.panel_size = (760, 560);
    save(opts, "convergence", &figure, &records)
}
