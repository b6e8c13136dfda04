//! The methods compared by what an optimisation costs to reach the answer
//! (the book's chapter "Sensitivities at work"): every worked problem of [`PROBLEMS`], run by every
//! method of [`variants`] from several seeds; per run, the wall time and
//! the paths until the tail average's parameter error falls under
//! [`TOLERANCE`] *and stays there for the rest of the run*, and the final
//! error. `examples/optimize_compare.rs` writes the book's table and
//! figures from it; `geosens compare` prints a short version.
//!
//! A problem is one entry of [`PROBLEMS`]: its file, its true pose (or
//! `None` for a design problem, whose answer is found by [`scan`]) and its
//! budget. The error of parameter `j` is `|θ̄_j − θ*_j|` divided by the
//! scene's size for a translation ([`Model::translates`]) and in radians
//! (or the relative change of a scale) otherwise; a run's error is the
//! largest over its parameters.
use crate::error::Error;
use crate::method::Method;
use crate::method::model::Model;
use crate::optimize::{Optimizer, Product, Record, Sampling, Settings, Study, optimize};
use serde::Serialize;
use std::path::{Path, PathBuf};

/// The parameter error every problem is judged against: 10⁻³ of the
/// scene's size for a translation, 10⁻³ rad for a rotation.
pub const TOLERANCE: f64 = 1e-3;

/// Adam's first step (parameter units), every problem's.
pub const STEP: f64 = 0.02;

/// Independent batches of every evaluation.
pub const BATCHES: u32 = 8;

/// What a problem may spend per run.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Budget {
    /// Iterations of the optimiser.
    pub iterations: u32,
    /// Paths per measurement per iteration (a camera's: per pixel).
    pub paths: u64,
}

/// A worked problem.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Problem {
    /// Its scene file, relative to the crate's root (its points' number of
    /// coordinates says its dimension).
    pub file: &'static str,
    /// The true offsets of an inverse problem, in the parameters' order;
    /// `None` for a design problem, whose answer a [`scan`] finds.
    pub truth: Option<&'static [f64]>,
    /// Its budget per run.
    pub budget: Budget,
}

/// The worked problems, one line each.
pub const PROBLEMS: &[Problem] = &[
    // Flatland: an occluder's position and tilt from eight probes.
    Problem {
        file: "scenes/inverse_occluder.toml",
        truth: Some(&[0.12, 0.2]),
        budget: Budget {
            iterations: 400,
            paths: 8192,
        },
    },
    // Flatland design: aim a reflector at a hidden receiver (answer by scan).
    Problem {
        file: "scenes/design_reflector.toml",
        truth: None,
        budget: Budget {
            iterations: 300,
            paths: 16384,
        },
    },
    // 3D: an absorbing fog cube's position from radiance through it.
    Problem {
        file: crate::mesh::inverse::FOG.file,
        truth: Some(crate::mesh::inverse::FOG.truth),
        budget: Budget {
            iterations: 200,
            paths: 1024,
        },
    },
    // 3D: a triangle's shift and turn from a 12 × 12 image of it.
    Problem {
        file: crate::mesh::inverse::CAMERA.file,
        truth: Some(crate::mesh::inverse::CAMERA.truth),
        budget: Budget {
            iterations: 150,
            paths: 1024,
        },
    },
    // 3D: the same from nine ground irradiances (its turn is weakly seen).
    Problem {
        file: crate::mesh::inverse::TRIANGLE.file,
        truth: Some(crate::mesh::inverse::TRIANGLE.truth),
        budget: Budget {
            iterations: 300,
            paths: 1024,
        },
    },
];

/// A method and, for finite differences, its half step.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Variant {
    /// The method.
    #[serde(serialize_with = "method_name")]
    pub method: Method,
    /// `Method::Fd`'s half step (`None`: the default, 10⁻³).
    pub fd_step: Option<f64>,
}

fn method_name<S: serde::Serializer>(m: &Method, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_str(m.name())
}

impl Variant {
    /// The method with its defaults.
    pub const fn of(method: Method) -> Variant {
        Variant {
            method,
            fd_step: None,
        }
    }

    /// The table's name: the method's, with a finite difference's step if
    /// it is not the default.
    pub fn label(&self) -> String {
        match self.fd_step {
            Some(h) => format!("{} (step {h})", self.method.name()),
            None => self.method.name().into(),
        }
    }
}

/// A finite difference with a half step far above the default (0.2 of the
/// size for a translation, 0.2 rad for a rotation): a biased gradient,
/// which converges to its own fixed point, not the answer.
pub const BIASED_FD: Variant = Variant {
    method: Method::Fd,
    fd_step: Some(0.2),
};

/// The four gradient methods, then the biased finite difference.
pub fn variants() -> Vec<Variant> {
    vec![
        Variant::of(Method::Expectation),
        Variant::of(Method::Rendering),
        Variant::of(Method::Transport),
        Variant::of(Method::Fd),
        BIASED_FD,
    ]
}

/// A problem's study, flatland's or 3D's.
#[derive(Debug)]
pub enum Loaded {
    /// A flatland study.
    Flat(Box<Study<crate::flat::Scene>>),
    /// A 3D study.
    Mesh(Box<Study<crate::mesh::Scene>>),
}

/// Calls `$body` with `$s` bound to the study of either dimension.
macro_rules! with_study {
    ($loaded:expr, $s:ident => $body:expr) => {
        match $loaded {
            Loaded::Flat($s) => $body,
            Loaded::Mesh($s) => $body,
        }
    };
}

impl Loaded {
    /// Loads `path`: a 3D study if its points have three coordinates, else
    /// a flatland one ([`crate::scene::file::dimension`], as
    /// `geosens optimize` decides).
    pub fn load(path: &Path) -> Result<Loaded, Error> {
        match crate::scene::file::dimension(path)? {
            Some(3) => Ok(Loaded::Mesh(Box::new(crate::mesh::file::load_study(path)?))),
            _ => Ok(Loaded::Flat(Box::new(crate::flat::file::load_study(path)?))),
        }
    }

    /// A flatland study from the text of a TOML scene file.
    pub fn flat_toml(text: &str) -> Result<Loaded, Error> {
        let file: crate::flat::file::SceneFile =
            toml::from_str(text).map_err(|e| Error::Scene(e.to_string()))?;
        Ok(Loaded::Flat(Box::new(file.into_study()?)))
    }

    /// The parameters' names.
    pub fn names(&self) -> Vec<String> {
        with_study!(self, s => s.parameter_names())
    }

    /// What divides parameter `j`'s error: the scene's size for a
    /// translation, 1 otherwise (radians, a scale's relative change).
    pub fn scales(&self) -> Vec<f64> {
        with_study!(self, s => {
            let scene = s.scene();
            (0..s.parameter_names().len())
                .map(|j| if scene.translates(j) { scene.size() } else { 1.0 })
                .collect()
        })
    }

    /// Each parameter's bounds (offsets; ±∞ where none).
    pub fn bounds(&self) -> Vec<[f64; 2]> {
        with_study!(self, s => s.bounds())
    }

    /// The exact loss at `offsets`, where a closed form exists (flatland
    /// irradiance probes of least squares or a linear objective).
    pub fn exact_loss(&self, offsets: &[f64]) -> Option<f64> {
        let Loaded::Flat(s) = self else { return None };
        exact_flat_loss(s, offsets)
    }

    /// The loss estimated at `offsets` by `method` with `sampling`.
    pub fn estimated_loss(
        &self,
        offsets: &[f64],
        method: Method,
        sampling: &Sampling,
    ) -> Result<f64, Error> {
        with_study!(self, s => Ok(s.evaluate(offsets, method, sampling)?.loss.mean))
    }

    /// [`optimize`] on this study.
    pub fn optimize(
        &self,
        settings: &Settings,
        each: impl FnMut(&Record) -> bool,
    ) -> Result<Vec<Record>, Error> {
        with_study!(self, s => optimize(s, settings, each))
    }
}

/// The closed-form loss of a flatland study at `offsets` (`None` where a
/// measurement has no closed form).
fn exact_flat_loss(s: &Study<crate::flat::Scene>, offsets: &[f64]) -> Option<f64> {
    use crate::scene::objective::ObjectiveKind;
    let posed = s.posed(offsets).ok()?;
    let mut loss = 0.0;
    for m in s.measurements() {
        let r =
            crate::flat::exact::Reference::for_scene(&posed.with_sensor(m.sensor).ok()?).ok()?;
        let v = r.value();
        loss += match s.objective() {
            ObjectiveKind::LeastSquares => m.weight * (v - m.target.as_ref()?[0]).powi(2),
            ObjectiveKind::Maximize => -m.weight * v,
            ObjectiveKind::Minimize => m.weight * v,
        };
    }
    Some(loss)
}

/// The answer of a design problem: the minimum of the loss over the
/// parameters' bounds (at most two parameters, each bounded). Where the
/// loss has a closed form, a grid of 21 points a side zoomed five times
/// about its best point, each time to a quarter of its width. Otherwise the
/// intensity estimator with `paths` per measurement from one seed (common
/// random numbers, [`super::scan`]): a 21 × 21 grid over the bounds, then a
/// 21 × 21 grid of ±0.15 about its best point, and the stationary point of
/// the quadratic fitted to that finer grid (a noisy grid's best point
/// wanders by its spacing; the fit's peak does not).
pub fn scan(loaded: &Loaded, paths: u64) -> Result<Vec<f64>, Error> {
    let bounds = loaded.bounds();
    if bounds.len() > 2 || bounds.iter().flatten().any(|b| !b.is_finite()) {
        return Err(Error::Config(
            "a design problem's scan needs at most two parameters, each with bounds".into(),
        ));
    }
    if loaded.exact_loss(&vec![0.0; bounds.len()]).is_none() {
        return with_study!(loaded, s => estimated_peak(s, &bounds, paths));
    }
    const N: usize = 21;
    let mut box_: Vec<[f64; 2]> = bounds.clone();
    let mut best = vec![0.0; bounds.len()];
    for _ in 0..5 {
        let axes: Vec<Vec<f64>> = box_
            .iter()
            .map(|[lo, hi]| {
                (0..N)
                    .map(|i| lo + (hi - lo) * i as f64 / (N - 1) as f64)
                    .collect()
            })
            .collect();
        let mut best_loss = f64::INFINITY;
        let count = N.pow(axes.len() as u32);
        for k in 0..count {
            let x: Vec<f64> = (0..axes.len())
                .map(|d| axes[d][(k / N.pow(d as u32)) % N])
                .collect();
            // Points where the scene is invalid are skipped.
            if let Some(l) = loaded.exact_loss(&x)
                && l < best_loss
            {
                best_loss = l;
                best = x;
            }
        }
        for (d, b) in box_.iter_mut().enumerate() {
            let half = 0.125 * (b[1] - b[0]);
            *b = [
                (best[d] - half).max(bounds[d][0]),
                (best[d] + half).min(bounds[d][1]),
            ];
        }
    }
    Ok(best)
}

/// The estimated loss's minimum over two bounded parameters (see [`scan`]).
fn estimated_peak<S: Model>(
    s: &Study<S>,
    bounds: &[[f64; 2]],
    paths: u64,
) -> Result<Vec<f64>, Error> {
    use super::scan::{fit_quadratic, scan as grid};
    if bounds.len() != 2 {
        return Err(Error::Config(
            "an estimated design scan needs exactly two parameters".into(),
        ));
    }
    let sampling = Sampling {
        paths,
        batches: BATCHES,
        seed: 0x5ca9,
        threads: 0,
        fd_step: None,
        product: Product::Independent,
    };
    let axis = |lo: f64, hi: f64| -> Vec<f64> {
        (0..21)
            .map(|i| lo + (hi - lo) * f64::from(i) / 20.0)
            .collect()
    };
    let lowest = |points: &[super::scan::ScanPoint]| {
        points
            .iter()
            .min_by(|a, b| a.loss.total_cmp(&b.loss))
            .map(|p| p.offsets.clone())
            .ok_or_else(|| Error::Config("no valid scene on the scan's grid".into()))
    };
    let zero = [0.0, 0.0];
    let coarse = grid(
        s,
        &zero,
        (0, &axis(bounds[0][0], bounds[0][1])),
        (1, &axis(bounds[1][0], bounds[1][1])),
        &sampling,
    )?;
    let c = lowest(&coarse)?;
    let clip = |d: usize, x: f64| x.clamp(bounds[d][0], bounds[d][1]);
    let fine = grid(
        s,
        &zero,
        (0, &axis(clip(0, c[0] - 0.15), clip(0, c[0] + 0.15))),
        (1, &axis(clip(1, c[1] - 0.15), clip(1, c[1] + 0.15))),
        &sampling,
    )?;
    let points: Vec<([f64; 2], f64)> = fine
        .iter()
        .map(|p| ([p.offsets[0], p.offsets[1]], p.loss))
        .collect();
    let peak = fit_quadratic(&points)?.stationary();
    match peak {
        Some(p)
            if p.iter()
                .enumerate()
                .all(|(d, x)| (bounds[d][0]..=bounds[d][1]).contains(x)) =>
        {
            Ok(p.to_vec())
        }
        _ => lowest(&fine),
    }
}

/// One iteration of a run, as the comparison keeps it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Point {
    /// Iteration.
    pub iteration: u32,
    /// Wall time since the run's start, to the end of this iteration.
    pub seconds: f64,
    /// Paths sampled since the run's start, this iteration's included.
    pub paths: u64,
    /// The iterate.
    pub parameters: Vec<f64>,
    /// The tail average (the answer reported).
    pub average: Vec<f64>,
    /// The loss estimated at the iterate.
    pub loss: f64,
    /// The largest scaled error of the tail average.
    pub error: f64,
}

/// One run's outcome.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Run {
    /// The method.
    pub variant: Variant,
    /// The seed.
    pub seed: u64,
    /// Wall time until the error fell under the tolerance for good (to the
    /// end of the run); `None` if it did not.
    pub seconds_to_tolerance: Option<f64>,
    /// Paths until then.
    pub paths_to_tolerance: Option<u64>,
    /// Iteration from which on the error stayed under the tolerance.
    pub iteration_to_tolerance: Option<u32>,
    /// Wall time until the error first fell under the tolerance (it may
    /// have risen again).
    pub seconds_to_first_hit: Option<f64>,
    /// The tail average's error at the end.
    pub final_error: f64,
    /// The run's wall time.
    pub seconds: f64,
    /// The run's paths.
    pub paths: u64,
    /// Every iteration.
    #[serde(skip)]
    pub trace: Vec<Point>,
}

/// The largest scaled error of `x` from `answer`.
pub fn error(x: &[f64], answer: &[f64], scales: &[f64]) -> f64 {
    x.iter()
        .zip(answer)
        .zip(scales)
        .map(|((a, b), s)| (a - b).abs() / s)
        .fold(0.0, f64::max)
}

/// Runs `variant` on `loaded` from seed `seed` with `budget` (its paths
/// multiplied by `effort`), on `threads` threads; `each` is called after
/// every iteration.
pub fn run_one(
    loaded: &Loaded,
    answer: &[f64],
    variant: Variant,
    seed: u64,
    budget: Budget,
    threads: usize,
    mut each: impl FnMut(),
) -> Result<Run, Error> {
    let settings = Settings {
        method: variant.method,
        optimizer: Optimizer::Adam,
        iterations: budget.iterations,
        step: STEP,
        sampling: Sampling {
            paths: budget.paths.max(2 * u64::from(BATCHES)),
            batches: BATCHES,
            seed,
            threads,
            fd_step: variant.fd_step,
            product: Product::Independent,
        },
        tolerance: 0.0,
    };
    let names = loaded.names();
    let scales = loaded.scales();
    let (mut seconds, mut paths) = (0.0, 0u64);
    let mut trace = Vec::new();
    loaded.optimize(&settings, |r| {
        seconds += r.seconds;
        paths += r.paths;
        let parameters: Vec<f64> = names.iter().map(|n| r.parameters[n]).collect();
        let average: Vec<f64> = names.iter().map(|n| r.average[n]).collect();
        trace.push(Point {
            iteration: r.iteration,
            seconds,
            paths,
            error: error(&average, answer, &scales),
            parameters,
            average,
            loss: r.loss.mean,
        });
        each();
        true
    })?;
    Ok(outcome(variant, seed, trace))
}

/// A run's outcome from its trace.
fn outcome(variant: Variant, seed: u64, trace: Vec<Point>) -> Run {
    // The first iteration of the final stretch under the tolerance.
    let stays = trace
        .iter()
        .rposition(|p| p.error >= TOLERANCE)
        .map_or(Some(0), |i| (i + 1 < trace.len()).then_some(i + 1))
        .map(|i| &trace[i]);
    let first = trace.iter().find(|p| p.error < TOLERANCE);
    let last = trace.last();
    Run {
        variant,
        seed,
        seconds_to_tolerance: stays.map(|p| p.seconds),
        paths_to_tolerance: stays.map(|p| p.paths),
        iteration_to_tolerance: stays.map(|p| p.iteration),
        seconds_to_first_hit: first.map(|p| p.seconds),
        final_error: last.map_or(f64::NAN, |p| p.error),
        seconds: last.map_or(0.0, |p| p.seconds),
        paths: last.map_or(0, |p| p.paths),
        trace,
    }
}

/// One row of the table: a problem and a method over its seeds.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Row {
    /// The problem's file.
    pub problem: String,
    /// The method's label.
    pub method: String,
    /// Runs.
    pub runs: usize,
    /// Runs whose error fell under the tolerance and stayed there.
    pub reached: usize,
    /// Median, smallest and largest wall time to tolerance over the runs
    /// that reached it (seconds).
    pub seconds_to_tolerance: Option<[f64; 3]>,
    /// Median paths to tolerance over the runs that reached it.
    pub paths_to_tolerance: Option<f64>,
    /// Median wall time of a whole run.
    pub run_seconds: f64,
    /// Median, smallest and largest final error.
    pub final_error: [f64; 3],
}

/// The median of `v` (NaN if empty).
pub fn median(v: &[f64]) -> f64 {
    let mut v: Vec<f64> = v.iter().copied().filter(|x| !x.is_nan()).collect();
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

fn spread(v: &[f64]) -> [f64; 3] {
    [
        median(v),
        v.iter().copied().fold(f64::INFINITY, f64::min),
        v.iter().copied().fold(f64::NEG_INFINITY, f64::max),
    ]
}

/// The row of `runs` (one problem, one method).
pub fn row(problem: &str, runs: &[Run]) -> Row {
    let times: Vec<f64> = runs.iter().filter_map(|r| r.seconds_to_tolerance).collect();
    let paths: Vec<f64> = runs
        .iter()
        .filter_map(|r| r.paths_to_tolerance.map(|p| p as f64))
        .collect();
    let finals: Vec<f64> = runs.iter().map(|r| r.final_error).collect();
    let whole: Vec<f64> = runs.iter().map(|r| r.seconds).collect();
    Row {
        problem: problem.into(),
        method: runs.first().map_or(String::new(), |r| r.variant.label()),
        runs: runs.len(),
        reached: times.len(),
        seconds_to_tolerance: (!times.is_empty()).then(|| spread(&times)),
        paths_to_tolerance: (!paths.is_empty()).then(|| median(&paths)),
        run_seconds: median(&whole),
        final_error: spread(&finals),
    }
}

/// The problem's name in the table: its file name without the folder and
/// extension.
pub fn problem_name(file: &str) -> String {
    Path::new(file)
        .file_stem()
        .map_or(file.into(), |s| s.to_string_lossy().into_owned())
}

/// What the table's columns say.
pub const COLUMNS: [&str; 7] = [
    "problem",
    "method",
    "time to tol. [s] median (min–max)",
    "paths to tol. (median)",
    "reached",
    "final error median (min–max)",
    "run [s]",
];

impl Row {
    /// The row's cells, formatted.
    pub fn cells(&self) -> [String; 7] {
        let time = self.seconds_to_tolerance.map_or("—".into(), |[m, lo, hi]| {
            format!("{m:.2} ({lo:.2}–{hi:.2})")
        });
        let paths = self
            .paths_to_tolerance
            .map_or("—".into(), |p| format!("{p:.2e}"));
        let [m, lo, hi] = self.final_error;
        [
            problem_name(&self.problem),
            self.method.clone(),
            time,
            paths,
            format!("{}/{}", self.reached, self.runs),
            format!("{m:.1e} ({lo:.1e}–{hi:.1e})"),
            format!("{:.2}", self.run_seconds),
        ]
    }
}

/// `rows` as a plain-text table, columns padded.
pub fn text_table(rows: &[Row]) -> String {
    let cells: Vec<Vec<String>> = rows.iter().map(|r| r.cells().to_vec()).collect();
    padded(&COLUMNS, &cells)
}

/// `cells` under `header` as plain text: each column padded to its widest
/// cell, two spaces apart, no trailing spaces, the lines joined by
/// newlines.
pub fn padded(header: &[&str], cells: &[Vec<String>]) -> String {
    let widths: Vec<usize> = (0..header.len())
        .map(|c| {
            cells
                .iter()
                .map(|r| r[c].chars().count())
                .chain([header[c].chars().count()])
                .max()
                .unwrap_or(0)
        })
        .collect();
    let line = |r: &[&str]| {
        r.iter()
            .zip(&widths)
            .map(|(c, &w)| format!("{c:<w$}"))
            .collect::<Vec<_>>()
            .join("  ")
            .trim_end()
            .to_string()
    };
    let body = cells
        .iter()
        .map(|r| line(&r.iter().map(String::as_str).collect::<Vec<_>>()));
    std::iter::once(line(header))
        .chain(body)
        .collect::<Vec<_>>()
        .join("\n")
}

/// `rows` as a markdown table.
pub fn markdown_table(rows: &[Row]) -> String {
    let mut out = format!("| {} |\n", COLUMNS.join(" | "));
    out.push_str(&format!("|{}\n", "---|".repeat(COLUMNS.len())));
    for r in rows {
        out.push_str(&format!("| {} |\n", r.cells().join(" | ")));
    }
    out
}

/// `rows` as CSV (numbers unformatted; empty where none).
pub fn csv(rows: &[Row]) -> String {
    let mut out = String::from(
        "problem,method,runs,reached,seconds_to_tolerance_median,seconds_to_tolerance_min,\
         seconds_to_tolerance_max,paths_to_tolerance_median,run_seconds_median,\
         final_error_median,final_error_min,final_error_max\n",
    );
    for r in rows {
        let t = r
            .seconds_to_tolerance
            .map_or([String::new(), String::new(), String::new()], |t| {
                t.map(|v| v.to_string())
            });
        let p = r
            .paths_to_tolerance
            .map_or(String::new(), |p| p.to_string());
        let [m, lo, hi] = r.final_error;
        out.push_str(&format!(
            "{},{},{},{},{},{},{},{p},{},{m},{lo},{hi}\n",
            r.problem, r.method, r.runs, r.reached, t[0], t[1], t[2], r.run_seconds
        ));
    }
    out
}

/// `file` relative to the crate's root if it is not found as given.
pub fn resolve(file: &str) -> PathBuf {
    let here = PathBuf::from(file);
    if here.exists() {
        here
    } else {
        Path::new(env!("CARGO_MANIFEST_DIR")).join(file)
    }
}

/// The shipped flatland inverse problem's file text, for `geosens
/// compare`'s quick table (which must run wherever the binary is).
pub const INVERSE_OCCLUDER: &str = include_str!("../../scenes/inverse_occluder.toml");

#[cfg(test)]
mod tests {
    use super::*;

    /// Every worked problem loads, in the dimension its file's points give,
    /// with one truth per parameter.
    #[test]
    fn every_problem_loads_in_its_dimension() {
        for p in PROBLEMS {
            let loaded = Loaded::load(&resolve(p.file)).unwrap();
            let mesh = matches!(loaded, Loaded::Mesh(_));
            assert_eq!(mesh, p.file.starts_with("scenes/mesh/"), "{}", p.file);
            if let Some(t) = p.truth {
                assert_eq!(t.len(), loaded.names().len(), "{}", p.file);
            }
        }
    }

    fn point(error: f64) -> Point {
        Point {
            iteration: 0,
            seconds: 0.0,
            paths: 0,
            parameters: vec![],
            average: vec![],
            loss: 0.0,
            error,
        }
    }

    #[test]
    fn the_time_to_tolerance_is_from_the_last_crossing() {
        let trace = |e: &[f64]| {
            e.iter()
                .enumerate()
                .map(|(i, &e)| Point {
                    iteration: i as u32,
                    seconds: i as f64,
                    ..point(e)
                })
                .collect::<Vec<_>>()
        };
        let v = Variant::of(Method::Transport);
        let r = outcome(v, 1, trace(&[1.0, 1e-4, 2e-3, 5e-4, 4e-4]));
        assert_eq!(r.iteration_to_tolerance, Some(3));
        assert_eq!(r.seconds_to_first_hit, Some(1.0));
        let r = outcome(v, 1, trace(&[1.0, 1e-4, 2e-3]));
        assert_eq!(r.iteration_to_tolerance, None);
        assert_eq!(r.seconds_to_first_hit, Some(1.0));
        let r = outcome(v, 1, trace(&[1e-4, 1e-4]));
        assert_eq!(r.iteration_to_tolerance, Some(0));
    }

    #[test]
    fn the_flatland_problem_loads_with_its_scales_and_exact_loss() {
        let p = PROBLEMS[0];
        let loaded = Loaded::load(&resolve(p.file)).unwrap();
        let scales = loaded.scales();
        assert!(scales[0] > 1.0 && scales[1] == 1.0, "{scales:?}");
        let truth = p.truth.unwrap();
        assert!(loaded.exact_loss(truth).unwrap() < 1e-20);
        assert!(loaded.exact_loss(&[0.0, 0.0]).unwrap() > 1e-3);
        let embedded = Loaded::flat_toml(INVERSE_OCCLUDER).unwrap();
        assert_eq!(embedded.names(), loaded.names());
    }
}
