//! Why finite differences of two Monte Carlo runs are a poor tool (the
//! book's introduction): on the thick rod at `x = 1`, `ω = −1`, the central
//! difference `[I(π̃+h) − I(π̃−h)]/2h` of two intensity runs of `N` paths,
//! with independent seeds and with common random numbers
//! ([`CentralDifference`]), against the exact `s`, for `h` from 10⁻⁶ to 0.32,
//! beside the standard errors of the rendering and expectation estimators
//! at the same `N`.
use super::{FigureOptions, thick};
use crate::error::Error;
use crate::estimator::Quantity;
use crate::fd::CentralDifference;
use crate::plot::{Figure, Legend, Panel, Series};
use crate::rod::{Direction, Method, PARAMETER, Probe, Rod, exact};
use crate::runner::{RunConfig, run};
use serde::Serialize;
use std::path::PathBuf;

/// Paths per run (times the effort).
pub const PATHS: u64 = 1_000_000;
/// The probe.
pub const PROBE: (f64, Direction) = (1.0, Direction::Left);

/// One finite-difference estimate.
#[derive(Debug, Clone, Serialize)]
pub struct Point {
    /// `"independent"` or `"common"` random numbers.
    pub kind: &'static str,
    /// Half step `h`.
    pub h: f64,
    /// The difference quotient.
    pub estimate: f64,
    /// Its standard error.
    pub stderr: f64,
    /// `|estimate − exact s|`.
    pub error: f64,
}

/// Everything the figure shows.
#[derive(Debug, Clone, Serialize)]
pub struct Record {
    /// Exact `s` at the probe.
    pub exact: f64,
    /// Paths per run.
    pub paths: u64,
    /// Standard error of rendering's `s` with the same paths.
    pub rendering_stderr: f64,
    /// Standard error of expectation's `s` with the same paths.
    pub expectation_stderr: f64,
    /// The finite differences.
    pub points: Vec<Point>,
}

fn intensity(rod: Rod) -> Result<Box<dyn crate::Estimator>, Error> {
    let probe = Probe::new(&rod, PROBE.0, PROBE.1)?;
    Ok(Method::Intensity.estimator(rod, probe))
}

/// Writes `finite_difference.{png,svg,json}`.
pub fn finite_difference(opts: &FigureOptions) -> Result<Vec<PathBuf>, Error> {
    let rod = thick();
    let exact = exact::solve(&rod, PROBE.0, PROBE.1).sensitivity;
    let paths = opts.paths(PATHS);
    let cfg = |salt: u64| {
        Ok::<_, Error>(RunConfig::new(paths, opts.seed.wrapping_add(salt))?.threads(opts.threads))
    };
    let s = Quantity::sensitivity(PARAMETER);
    let stderr_of = |method: Method| -> Result<f64, Error> {
        let probe = Probe::new(&rod, PROBE.0, PROBE.1)?;
        let r = run(method.estimator(rod, probe).as_ref(), &cfg(7)?)?;
        Ok(r.get(&s).map_or(f64::NAN, |e| e.stderr))
    };
    let hs: Vec<f64> = (0..=11)
        .map(|i| 10f64.powf(-6.0 + 0.5 * i as f64))
        .collect();
    let bar = opts.bar(hs.len() as u64, "finite differences");
    let mut points = Vec::new();
    for (i, &h) in hs.iter().enumerate() {
        let plus = Rod {
            length: rod.length + h,
            ..rod
        };
        let minus = Rod {
            length: rod.length - h,
            ..rod
        };
        // Independent: two runs, two seeds.
        let salt = 100 + 2 * i as u64;
        let a = run(intensity(plus)?.as_ref(), &cfg(salt)?)?.estimates[0].1;
        let b = run(intensity(minus)?.as_ref(), &cfg(salt + 1)?)?.estimates[0].1;
        let estimate = (a.mean - b.mean) / (2.0 * h);
        let stderr = a.stderr.hypot(b.stderr) / (2.0 * h);
        points.push(Point {
            kind: "independent",
            h,
            estimate,
            stderr,
            error: (estimate - exact).abs(),
        });
        // Common random numbers: one run of the per-path difference.
        let fd = CentralDifference::new(intensity(plus)?, intensity(minus)?, h)?;
        let e = run(&fd, &cfg(salt)?)?.estimates[0].1;
        points.push(Point {
            kind: "common",
            h,
            estimate: e.mean,
            stderr: e.stderr,
            error: (e.mean - exact).abs(),
        });
        bar.inc(1);
    }
    bar.finish();
    let record = Record {
        exact,
        paths,
        rendering_stderr: stderr_of(Method::Rendering)?,
        expectation_stderr: stderr_of(Method::Expectation)?,
        points,
    };
    let mut series = Vec::new();
    // Palette: the FD curves take colours no method uses elsewhere; the
    // methods keep theirs (rendering 2, expectation 1).
    for (color, kind, label) in [
        (5, "independent", "independent runs"),
        (6, "common", "common random numbers"),
    ] {
        let of = |f: fn(&Point) -> f64| {
            record
                .points
                .iter()
                .filter(|p| p.kind == kind)
                .map(|p| (p.h, f(p)))
                .collect()
        };
        series.push(Series::line(
            &format!("σ, {label}"),
            color,
            of(|p| p.stderr),
        ));
        series.push(Series::points(
            &format!("|error|, {label}"),
            color,
            record
                .points
                .iter()
                .filter(|p| p.kind == kind)
                .map(|p| (p.h, p.error, 0.0))
                .collect(),
        ));
    }
    let flat = |v: f64| vec![(hs[0], v), (hs[hs.len() - 1], v)];
    series.push(Series::dashed(
        "σ of rendering's s, same N",
        2,
        flat(record.rendering_stderr),
    ));
    series.push(Series::dashed(
        "σ of expectation's s, same N",
        1,
        flat(record.expectation_stderr),
    ));
    let panel = Panel {
        title: format!(
            "FD of two intensity runs, thick rod, x = 1, ω = −1, N = {paths} per run (exact s = {exact:.5})"
        ),
        x_label: "half step h".into(),
        y_label: "σ (lines), |FD − exact s| (dots)".into(),
        x_log: true,
        y_log: true,
        series,
        legend: Legend::UpperRight,
        ..Panel::default()
    };
    let mut fig = Figure::new(vec![panel], 1);
    fig.panel_size = (900, 560);
    let mut written = fig.save(&opts.out, "finite_difference")?;
    written.push(opts.write_json("finite_difference", &record)?);
    Ok(written)
}
