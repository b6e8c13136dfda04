//! Speed against accuracy (extends the paper's Fig. 6e from error per path
//! to error per second): the work-normalised variance `σ²·t` of every method
//! along the rod, and the error reached against wall time. `σ²·t` is the
//! variance one second of sampling leaves (σ² ∝ 1/N, t ∝ N), so it compares
//! methods whose paths cost differently; lower is better. The book discusses
//! it in the chapter "Comparing the approaches".
//!
//! Every timing run uses one thread, whatever `opts.threads`, so that the
//! wall times of different methods are comparable; `t` is the runner's
//! sampling wall time ([`RunResult::seconds`](crate::RunResult::seconds)),
//! the fastest of a few identical repeats for runs under [`MIN_SECONDS`].
//! Points with `σ = 0` (a probe where every path scores the same, e.g. at
//! `x = 0`, `ω = +1`) cannot be drawn on the log axis and are left out.
use super::convergence::{
    Case, NEAR_END, Record, error_panel, omega_label, path_counts, rod_title, rods, style,
};
use super::{FigureOptions, positions};
use crate::error::Error;
use crate::figures_common::convergence::layered;
use crate::plot::{Figure, Panel, Series};
use crate::rod::{Direction, Method};
use serde::Serialize;
use std::path::PathBuf;

/// Paths per point of the `σ²·t` panels (times the effort).
pub const PATHS: u64 = 1_000_000;

/// Evenly spaced positions along the rod in the `σ²·t` panels, ends
/// included; [`NEAR_END`] is added to them.
pub const POSITIONS: usize = 11;

/// The probe of the error-against-time panels.
pub const TIME_PROBE: (f64, Direction) = (1.0, Direction::Left);

/// Runs shorter than this (seconds) are repeated for a robust time.
pub const MIN_SECONDS: f64 = 0.1;

/// Most runs of one configuration when timing short runs.
pub const MAX_REPEATS: u32 = 5;

/// Base of the seed salts of this figure (distinct from the other figures').
const SALT: u64 = 20_000_000;

/// The numbers behind `efficiency.{png,svg}`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Efficiency {
    /// One run per method, rod, position and direction, `N = PATHS`.
    pub work: Vec<Record>,
    /// Runs at `TIME_PROBE` with 10³ to 10⁷ paths.
    pub error_vs_time: Vec<Record>,
}

/// A panel of `σ²·t` against `x` for every method in `records` (a line with
/// dots; zero-variance points, `σ = 0`, cannot be drawn on the log axis).
fn work_panel(title: String, records: &[Record]) -> Panel {
    let mut series = Vec::new();
    for method in Method::UNBIASED {
        let (label, color) = style(method);
        let xy: Vec<(f64, f64)> = records
            .iter()
            .filter(|r| r.method == method.name() && r.work > 0.0)
            .map(|r| (r.x, r.work))
            .collect();
        series.push(Series::points(
            "",
            color,
            xy.iter().map(|&(x, w)| (x, w, 0.0)).collect(),
        ));
        // Wide dashes under rendering's line, as in the error panels.
        series.push(if method == Method::Transport {
            Series::dashes(&label, color, xy)
        } else {
            Series::line(&label, color, xy)
        });
    }
    Panel {
        title,
        x_label: "x".into(),
        y_label: "σ²·t (t in seconds, 1 thread)".into(),
        y_log: true,
        series: layered(series),
        ..Panel::default()
    }
}

/// [`Record::measure`] with a robust time: a run shorter than
/// [`MIN_SECONDS`] is repeated (same seed, so the same estimate) until the
/// repeats add up to it or [`MAX_REPEATS`] are done, and the fastest time is
/// kept, which damps scheduler noise on short runs.
fn timed(
    opts: &FigureOptions,
    method: Method,
    case: Case,
    n: u64,
    salt: u64,
) -> Result<Record, Error> {
    let mut best = Record::measure(opts, method, case, n, salt)?;
    let (mut total, mut repeats) = (best.seconds, 1);
    while total < MIN_SECONDS && repeats < MAX_REPEATS {
        let again = Record::measure(opts, method, case, n, salt)?;
        total += again.seconds;
        repeats += 1;
        if again.seconds < best.seconds {
            best = again;
        }
    }
    Ok(best)
}

/// Speed against accuracy: `σ²·t` against `x` (11 positions and 1.95) for every
/// method, thin and thick rods (columns), `ω = −1` and `ω = +1` (rows), `N =
/// 10⁶` paths each; then |error| and σ against the sampling wall time at
/// `x = 1`, `ω = −1`, with 10³ to 10⁷ paths. All runs on **one thread**
/// whatever `opts.threads`. Writes `efficiency.{png,svg}` and
/// `efficiency.json`.
pub fn efficiency(opts: &FigureOptions) -> Result<Vec<PathBuf>, Error> {
    let timing = FigureOptions {
        threads: 1,
        ..opts.clone()
    };
    let counts = path_counts(3, 7);
    let directions = [Direction::Left, Direction::Right];
    let methods = Method::UNBIASED.len();
    let runs = methods * 2 * (directions.len() * (POSITIONS + 1) + counts.len());
    let bar = opts.bar(runs as u64, "efficiency");
    let mut salt = SALT;
    let mut measure = |method, case, n| {
        salt += 1;
        bar.inc(1);
        timed(&timing, method, case, n, salt)
    };
    let mut panels = Vec::new();
    let mut work = Vec::new();
    for omega in directions {
        for (rod_name, rod) in rods() {
            let mut xs = positions(&rod, POSITIONS);
            xs.push(NEAR_END);
            xs.sort_by(f64::total_cmp);
            let first = work.len();
            for method in Method::UNBIASED {
                for &x in &xs {
                    let case = Case {
                        rod_name,
                        rod,
                        x,
                        omega,
                    };
                    work.push(measure(method, case, PATHS)?);
                }
            }
            let title = format!(
                "{}, {}: σ²·t, N = {:.0e}",
                rod_title(rod_name, &rod),
                omega_label(omega),
                timing.paths(PATHS) as f64
            );
            panels.push(work_panel(title, &work[first..]));
        }
    }
    let mut error_vs_time = Vec::new();
    let (x, omega) = TIME_PROBE;
    for (rod_name, rod) in rods() {
        let case = Case {
            rod_name,
            rod,
            x,
            omega,
        };
        let first = error_vs_time.len();
        for method in Method::UNBIASED {
            for &n in &counts {
                error_vs_time.push(measure(method, case, n)?);
            }
        }
        let title = format!(
            "{}, x = {x}, {}: error against time",
            rod_title(rod_name, &rod),
            omega_label(omega)
        );
        panels.push(error_panel(
            title,
            "sampling wall time t (s, 1 thread)",
            "∝ 1/√t",
            &error_vs_time[first..],
            |r| r.seconds,
        ));
    }
    bar.finish();
    let json = opts.write_json(
        "efficiency",
        &Efficiency {
            work,
            error_vs_time,
        },
    )?;
    let mut figure = Figure::new(panels, 2).share_legend();
    // The lines are σ and the dots the errors only in the bottom row.
    for s in &mut figure.legend {
        if s.label.ends_with("(lines)") || s.label.ends_with("(dots)") {
            s.label.insert_str(s.label.len() - 1, ", bottom row");
        }
    }
    let mut written = figure.save(&opts.out, "efficiency")?;
    written.push(json);
    Ok(written)
}
