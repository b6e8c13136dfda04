//! Convergence to the closed form: the standard error σ and the actual
//! error |mean − exact| against the number of paths N (10³ to 10⁶ in half
//! decades, a fresh seed per run), log–log, for every method on one
//! parameter of `polygon_occluder.toml` (the Γ's rotation), the intensity
//! estimator judged on `E`, the others on `∂E/∂π`. A dashed `∝ 1/√N` line
//! is the rate an unbiased finite-variance estimator shows. Every run has
//! its own seed. On this scene (black shapes, no medium, no bounce)
//! transport's Eulerian sources vanish (the radiance just in front of a
//! black surface has no gradient) and what is left are rendering's corner
//! terms: the two estimators are the same here (with one seed they agree
//! bit for bit), so their curves differ only by their seeds.
use super::{
    FigureOptions, METHODS, REFERENCE_COLOR, color, exact, load, only, parameter, run_method, save,
};
use crate::error::Error;
use crate::estimator::Quantity;
use crate::flat::Method;
use crate::plot::{Figure, Legend, Panel, Series, quiet_corner};
use crate::rod::figures::convergence::path_counts;
use serde::Serialize;
use std::path::PathBuf;
use std::sync::Arc;

/// The scene.
pub const SCENE: &str = "polygon_occluder";

/// The parameter judged.
pub const PARAMETER: &str = "gamma_rotate";

/// Base of the seed salts of this figure (distinct from the other figures').
const SALT: u64 = 50_000_000;

/// One run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Record {
    /// Method name.
    pub method: &'static str,
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
    /// Relative variance of the variance (tail diagnostic).
    pub vov: f64,
    /// Sampling wall time in seconds.
    pub seconds: f64,
}

/// The numbers behind `flat_convergence.{png,svg}`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Convergence {
    /// Scene file name.
    pub scene: &'static str,
    /// The parameter.
    pub parameter: &'static str,
    /// Every run.
    pub records: Vec<Record>,
}

/// Legend label of `method` here.
fn label(method: Method) -> String {
    match method {
        Method::Intensity => "intensity (E)".into(),
        m => format!("{} (∂E/∂π)", m.name()),
    }
}

/// The log–log panel: σ as lines, |error| as dots, the `∝ 1/√N` line
/// through the expectation method's σ at the largest N.
fn panel(c: &Convergence) -> Panel {
    let mut series = Vec::new();
    for method in METHODS {
        let rs: Vec<&Record> = c
            .records
            .iter()
            .filter(|r| r.method == method.name())
            .collect();
        let sigma = rs.iter().map(|r| (r.paths as f64, r.stderr)).collect();
        let error = rs
            .iter()
            .map(|r| (r.paths as f64, r.error.abs(), 0.0))
            .collect();
        series.push(Series::line(&label(method), color(method), sigma));
        series.push(Series::points("", color(method), error));
    }
    // The reference slope, a factor 3 under the lowest σ at the largest N
    // so that it hides no curve.
    let ns = c.records.iter().map(|r| r.paths as f64);
    let (lo, hi) = ns.fold((f64::INFINITY, 0.0f64), |(lo, hi), n| {
        (lo.min(n), hi.max(n))
    });
    let lowest = c
        .records
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
        title: format!("{}.toml, π = {}: error against paths", c.scene, c.parameter),
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

/// σ and |error| against N for every method on [`PARAMETER`] of [`SCENE`]
/// (a scene with that one parameter, so each run pays for one
/// sensitivity), 10³ to 10⁶ paths in half decades times the effort, on
/// `opts.threads`. Writes `flat_convergence.{png,svg}` and
/// `flat_convergence.json`.
pub fn convergence(opts: &FigureOptions) -> Result<Vec<PathBuf>, Error> {
    let base = load(SCENE)?;
    let j = parameter(&base, PARAMETER)?;
    let scene = Arc::new(only(&base, j)?);
    let (e, de) = exact(&scene, 0)?;
    let counts = path_counts(3, 6);
    let bar = opts.bar((METHODS.len() * counts.len()) as u64, "flat: convergence");
    let mut records = Vec::new();
    let mut salt = SALT;
    for method in METHODS {
        for &n in &counts {
            salt += 1;
            let r = run_method(opts, method, &scene, n, salt, opts.threads)?;
            let (q, quantity, exact) = match method {
                Method::Intensity => (Quantity::Intensity, "E", e),
                _ => (Quantity::sensitivity(PARAMETER), "dE/dπ", de),
            };
            let est = r
                .get(&q)
                .ok_or_else(|| Error::Output(format!("{} does not estimate {q}", method.name())))?;
            records.push(Record {
                method: method.name(),
                quantity,
                paths: r.paths,
                mean: est.mean,
                stderr: est.stderr,
                exact,
                error: est.mean - exact,
                vov: est.vov,
                seconds: r.seconds,
            });
            bar.inc(1);
        }
    }
    bar.finish();
    let c = Convergence {
        scene: SCENE,
        parameter: PARAMETER,
        records,
    };
    let mut figure = Figure::new(vec![panel(&c)], 1);
    figure.panel_size = (900, 620);
    save(opts, "convergence", &figure, &c)
}
