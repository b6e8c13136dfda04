//! Why finite differences of two Monte Carlo runs fail (the book's
//! "Introduction"): on the thick rod at `x = 1`, `ω = −1`, the central
//! difference `D_h = [I(π̃+h) − I(π̃−h)]/2h` of two intensity runs of `N`
//! paths each, for half steps `h` from 10⁻⁶ to 1, against the exact `s`:
//!
//! - with independent seeds, its standard error `√(σ₊² + σ₋²)/2h` grows like
//!   `1/h`;
//! - with common random numbers ([`CentralDifference`]: both rods sampled
//!   from one generator state, the standard error that of the per-path
//!   difference), a path pair differs only when a collision falls within `h`
//!   of the moving end, an event of probability `O(h)` with a weight
//!   difference `O(1)/h`: the standard error grows like `h^{-1/2}`, and for
//!   `N·h ≪ 1` no pair differs and the run reports `0 ± 0`;
//! - the bias of `D_h` itself, exact from [`exact::solve`], grows like `h²`.
//!
//! Dashed: the standard errors of rendering's and expectation's `s` with the
//! same `N`, unbiased at no step at all.
use super::{FigureOptions, thick};
use crate::error::Error;
use crate::estimator::{Estimator, Quantity};
use crate::fd::{CentralDifference, Pair};
use crate::plot::{Figure, Legend, Panel, Series};
use crate::rod::{Direction, Method, PARAMETER, Probe, Rod, exact};
use crate::runner::{RunConfig, run};
use crate::stats::Estimate;
use serde::Serialize;
use std::path::PathBuf;

/// Paths per run (times the effort).
pub const PATHS: u64 = 1_000_000;
/// The probe.
pub const PROBE: (f64, Direction) = (1.0, Direction::Left);
/// Half steps per decade of `h`.
const PER_DECADE: usize = 2;
/// `h` runs over `10^-6 … 10^0`.
const DECADES: (i32, i32) = (-6, 0);

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
    /// VOV of the per-path difference (common random numbers; for
    /// independent runs the larger of the two runs' VOVs).
    pub vov: f64,
}

/// The exact difference quotient at one step.
#[derive(Debug, Clone, Serialize)]
pub struct Bias {
    /// Half step `h`.
    pub h: f64,
    /// `[I(π̃+h) − I(π̃−h)]/2h − s`, exact.
    pub bias: f64,
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
    /// The Monte Carlo finite differences.
    pub points: Vec<Point>,
    /// The exact bias of `D_h`, where rounding leaves it meaningful.
    pub bias: Vec<Bias>,
}

/// The thick rod with length `π̃ + dl`.
fn stretched(dl: f64) -> Rod {
    let rod = thick();
    Rod {
        length: rod.length + dl,
        ..rod
    }
}

/// `method`'s estimator at the probe on `rod`.
fn estimator(method: Method, rod: Rod) -> Result<Box<dyn Estimator>, Error> {
    method.estimator((rod, Probe::new(&rod, PROBE.0, PROBE.1)?))
}

/// The exact bias of the central difference with half step `h`, or `None`
/// where it drowns in the rounding of `I(π̃+h) − I(π̃−h)`.
fn exact_bias(h: f64, s: f64) -> Option<Bias> {
    let i = |dl: f64| exact::solve(&stretched(dl), PROBE.0, PROBE.1).intensity;
    let bias = (i(h) - i(-h)) / (2.0 * h) - s;
    let rounding = 1e3 * f64::EPSILON * i(0.0) / h;
    (bias.abs() > rounding).then_some(Bias { h, bias })
}

/// The point of estimate `e` of `D_h` (`vov` as [`Point::vov`]).
fn point(kind: &'static str, h: f64, e: Estimate, s: f64) -> Point {
    Point {
        kind,
        h,
        estimate: e.mean,
        stderr: e.stderr,
        error: (e.mean - s).abs(),
        vov: e.vov,
    }
}

/// Writes `finite_difference.{png,svg,json}`.
pub fn finite_difference(opts: &FigureOptions) -> Result<Vec<PathBuf>, Error> {
    let exact = exact::solve(&thick(), PROBE.0, PROBE.1).sensitivity;
    let paths = opts.paths(PATHS);
    let cfg = |salt: u64| -> Result<RunConfig, Error> {
        Ok(RunConfig::new(paths, opts.seed.wrapping_add(salt))?.threads(opts.threads))
    };
    let s = Quantity::sensitivity(PARAMETER);
    let stderr_of = |method: Method| -> Result<f64, Error> {
        let r = run(estimator(method, thick())?.as_ref(), &cfg(7)?)?;
        Ok(r.get(&s).map_or(f64::NAN, |e| e.stderr))
    };
    let steps = (DECADES.1 - DECADES.0) as usize * PER_DECADE;
    let hs: Vec<f64> = (0..=steps)
        .map(|i| 10f64.powf(DECADES.0 as f64 + i as f64 / PER_DECADE as f64))
        .collect();
    let bar = opts.bar(hs.len() as u64, "finite differences");
    let mut points = Vec::new();
    for (i, &h) in hs.iter().enumerate() {
        let (plus, minus) = (stretched(h), stretched(-h));
        // Independent: two runs, two seeds.
        let salt = 100 + 2 * i as u64;
        let a = run(estimator(Method::Intensity, plus)?.as_ref(), &cfg(salt)?)?.estimates[0].1;
        let b = run(
            estimator(Method::Intensity, minus)?.as_ref(),
            &cfg(salt + 1)?,
        )?
        .estimates[0]
            .1;
        let independent = Estimate {
            mean: (a.mean - b.mean) / (2.0 * h),
            stderr: a.stderr.hypot(b.stderr) / (2.0 * h),
            nonzero: a.nonzero.min(b.nonzero),
            n: a.n,
            vov: a.vov.max(b.vov),
            max_share: a.max_share.max(b.max_share),
            jumps: None,
        };
        points.push(point("independent", h, independent, exact));
        // Common random numbers: one run of the per-path difference.
        // No nominal run: the `+` run draws from the chunk's generator.
        let pair = Pair {
            parameter: PARAMETER.to_owned(),
            plus: estimator(Method::Intensity, plus)?,
            minus: estimator(Method::Intensity, minus)?,
            half_step: h,
        };
        let fd = CentralDifference::new(None, vec![pair])?;
        let common = run(&fd, &cfg(salt)?)?.estimates[0].1;
        points.push(point("common", h, common, exact));
        bar.inc(1);
    }
    bar.finish();
    let record = Record {
        exact,
        paths,
        rendering_stderr: stderr_of(Method::Rendering)?,
        expectation_stderr: stderr_of(Method::Expectation)?,
        points,
        bias: hs.iter().filter_map(|&h| exact_bias(h, exact)).collect(),
    };
    let mut fig = Figure::new(vec![panel(&record, &hs)], 1);
    fig.panel_size = (960, 600);
    let mut written = fig.save(&opts.out, "finite_difference")?;
    written.push(opts.write_json("finite_difference", &record)?);
    Ok(written)
}

/// The figure's one panel: σ and |error| of both kinds against `h`, the
/// exact bias, and the unbiased estimators' σ.
fn panel(record: &Record, hs: &[f64]) -> Panel {
    let mut series = Vec::new();
    for (color, (kind, label)) in [
        ("independent", "independent runs"),
        ("common", "common random numbers"),
    ]
    .into_iter()
    .enumerate()
    {
        let of_kind = || record.points.iter().filter(move |p| p.kind == kind);
        series.push(Series::line(
            &format!("σ, {label}"),
            color,
            of_kind().map(|p| (p.h, p.stderr)).collect(),
        ));
        let dots = |flagged: bool| -> Vec<(f64, f64, f64)> {
            of_kind()
                .filter(|p| (p.vov >= Estimate::VOV_LIMIT) == flagged)
                .map(|p| (p.h, p.error, 0.0))
                .collect()
        };
        series.push(Series::points(
            &format!("|D_h − s|, {label} (dots)"),
            color,
            dots(false),
        ));
        let flagged = dots(true);
        if !flagged.is_empty() {
            series.push(Series::points(
                &format!("|D_h − s|, {label}, flagged: VOV ≥ 0.1"),
                4,
                flagged,
            ));
        }
    }
    // Bias below a hundredth of rendering's σ only stretches the axis.
    let visible = 0.01 * record.rendering_stderr;
    series.push(Series::line(
        "|bias| of D_h (exact)",
        6,
        record
            .bias
            .iter()
            .filter(|b| b.bias.abs() >= visible)
            .map(|b| (b.h, b.bias.abs()))
            .collect(),
    ));
    let flat = |v: f64| vec![(hs[0], v), (hs[hs.len() - 1], v)];
    series.push(Series::dashed(
        "σ of rendering's s, same N",
        2,
        flat(record.rendering_stderr),
    ));
    series.push(Series::dashed(
        "σ of expectation's s, same N",
        3,
        flat(record.expectation_stderr),
    ));
    Panel {
        title: format!(
            "D_h = [I(length + h) − I(length − h)]/2h of two intensity runs: thick rod, x = 1, ω = −1, s = {:.5}",
            record.exact
        ),
        x_label: format!(
            "half step h (N = {:.0e} paths per run)",
            record.paths as f64
        ),
        y_label: "σ (lines), |D_h − exact s| (dots)".into(),
        x_log: true,
        y_log: true,
        series,
        legend: Legend::UpperRight,
        ..Panel::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exact_bias_is_second_order_until_rounding_hides_it() {
        let s = exact::solve(&thick(), PROBE.0, PROBE.1).sensitivity;
        let bias = |h: f64| exact_bias(h, s).map(|b| b.bias);
        let (b2, b3) = (bias(1e-2).unwrap(), bias(1e-3).unwrap());
        assert!((b2 / b3 - 100.0).abs() < 0.5, "{b2} / {b3}");
        assert!(bias(1e-7).is_none());
    }
}
