//! What the figures of every dimension share, written once: the options
//! every figure takes ([`FigureOptions`]), the methods the flatland and 3D
//! figures ([`crate::flat::figures`], [`crate::mesh::figures`]) show with
//! their colours and legend labels, running a method on a scene (or on the
//! rod at a probe), finding a parameter by name, the figure list runner,
//! saving a figure with its numbers; and the experiments whose logic is the
//! same on both kinds of scene (the sweeps against `π`, the convergence
//! panel, whose pieces the rod's figures draw too, the `σ²·t` per quantity,
//! the runs near singular configurations), parameterised by what differs.
//! Nothing here depends on a dimension's scene types: a scene is a
//! [`Model`] or a [`Problem`].
use crate::error::Error;
use crate::estimator::Quantity;
use crate::method::model::Model;
use crate::method::{Method, Problem};
use crate::runner::{RunConfig, RunResult, run};
use crate::stats::Estimate;
use indicatif::{ProgressBar, ProgressStyle};
use std::path::PathBuf;

pub(crate) mod convergence;
pub(crate) mod efficiency;
pub(crate) mod stability;
pub(crate) mod sweep;

/// What every figure function takes.
#[derive(Debug, Clone)]
pub struct FigureOptions {
    /// Folder the PNG and SVG files go to.
    pub out: PathBuf,
    /// Seed of every run (each run derives its own from it).
    pub seed: u64,
    /// Worker threads (0 = all cores).
    pub threads: usize,
    /// Multiplies every path count (1 for the book's figures; smaller for
    /// quick looks and tests).
    pub effort: f64,
    /// Show a progress bar.
    pub progress: bool,
    /// Print a line per picture written on stderr, its path and the
    /// seconds its figure took: where no progress bar is drawn (stderr not
    /// a terminal), a log shows how far the figures have got.
    pub log: bool,
}

impl FigureOptions {
    /// Options for the book's figures written to `out`.
    pub fn new(out: impl Into<PathBuf>) -> FigureOptions {
        FigureOptions {
            out: out.into(),
            seed: 1,
            threads: 0,
            effort: 1.0,
            progress: true,
            log: false,
        }
    }

    /// Options from an example's command line, `[OUT_DIR] [EFFORT]` (defaults
    /// `out/figures` and 1), and a runner that prints the files `figure`
    /// writes: what every `examples/fig_*.rs` does.
    pub fn run_example(figure: FigureFn) -> Result<(), Error> {
        let opts = FigureOptions::from_args()?;
        for path in figure(&opts)? {
            println!("wrote {}", path.display());
        }
        Ok(())
    }

    /// Options from an example's command line, `[OUT_DIR] [EFFORT]`
    /// (defaults `out/figures` and 1).
    pub fn from_args() -> Result<FigureOptions, Error> {
        let mut args = std::env::args().skip(1);
        let mut opts = FigureOptions::new(args.next().unwrap_or_else(|| "out/figures".into()));
        if let Some(e) = args.next() {
            opts.effort = e
                .parse()
                .ok()
                .filter(|v: &f64| v.is_finite() && *v > 0.0)
                .ok_or_else(|| Error::Output(format!("bad effort {e:?}: expected a number > 0")))?;
        }
        Ok(opts)
    }

    /// `paths` scaled by the effort, at least 2.
    pub fn paths(&self, paths: u64) -> u64 {
        ((paths as f64 * self.effort).round() as u64).max(2)
    }

    /// A progress bar over `len` steps (hidden unless `progress`).
    pub fn bar(&self, len: u64, what: &str) -> ProgressBar {
        if !self.progress {
            return ProgressBar::hidden();
        }
        let bar = ProgressBar::new(len).with_message(what.to_owned());
        if let Ok(style) =
            ProgressStyle::with_template("{msg:>28} [{bar:30}] {pos}/{len} {elapsed}")
        {
            bar.set_style(style.progress_chars("=> "));
        }
        bar
    }

    /// Writes `value` as pretty JSON to `out/name.json`: the numbers behind a
    /// figure, for the book's text and for readers.
    pub fn write_json<T: serde::Serialize>(&self, name: &str, value: &T) -> Result<PathBuf, Error> {
        let io = |e: std::io::Error| Error::Output(format!("cannot write {name}.json: {e}"));
        std::fs::create_dir_all(&self.out).map_err(io)?;
        let path = self.out.join(format!("{name}.json"));
        let text = serde_json::to_string_pretty(value).map_err(|e| Error::Output(e.to_string()))?;
        std::fs::write(&path, text).map_err(io)?;
        Ok(path)
    }
}

/// A figure: runs its experiment and writes its files.
pub type FigureFn = fn(&FigureOptions) -> Result<Vec<PathBuf>, Error>;

/// The Monte Carlo methods in the figures' order.
pub const METHODS: [Method; 5] = [
    Method::Intensity,
    Method::Expectation,
    Method::Rendering,
    Method::Transport,
    Method::Fd,
];

/// The methods that estimate `∂E/∂π`.
pub const DERIVATIVE_METHODS: [Method; 4] = [
    Method::Expectation,
    Method::Rendering,
    Method::Transport,
    Method::Fd,
];

/// Palette index of `method` in every flatland and 3D figure.
pub fn color(method: Method) -> usize {
    match method {
        Method::Intensity => 0,
        Method::Expectation => 1,
        Method::Rendering => 2,
        Method::Transport => 3,
        Method::Fd => 4,
    }
}

/// Palette index of analytic curves and reference lines (black).
pub const REFERENCE_COLOR: usize = 6;

/// Runs every figure of `figures` in order; returns the files written.
pub(crate) fn all(opts: &FigureOptions, figures: &[FigureFn]) -> Result<Vec<PathBuf>, Error> {
    let mut written = Vec::new();
    for figure in figures {
        let start = crate::runner::Stopwatch::start();
        let files = figure(opts)?;
        if opts.log {
            let seconds = start.seconds();
            let pictures = files
                .iter()
                .filter(|f| f.extension() == Some("png".as_ref()));
            for picture in pictures {
                eprintln!("wrote {} ({seconds:.1} s)", picture.display());
            }
        }
        written.extend(files);
    }
    Ok(written)
}

/// Runs `method` on `problem` (a flatland or 3D scene, or the rod at a
/// probe) with `paths` (scaled by the effort) paths, seed `opts.seed +
/// salt`, on `threads` threads.
pub fn run_method<P: Problem>(
    opts: &FigureOptions,
    method: Method,
    problem: &P,
    paths: u64,
    salt: u64,
    threads: usize,
) -> Result<RunResult, Error> {
    let cfg = RunConfig::new(opts.paths(paths), opts.seed.wrapping_add(salt))?.threads(threads);
    run(problem.estimator(method, None)?.as_ref(), &cfg)
}

/// Index of the parameter called `name` in `scene`.
pub fn parameter<S: Model>(scene: &S, name: &str) -> Result<usize, Error> {
    scene
        .parameter_names()
        .position(|p| p == name)
        .ok_or_else(|| Error::Scene(format!("the scene has no parameter {name:?}")))
}

/// The estimate of `q` in `r`, or an error naming the method.
pub fn get(r: &RunResult, q: &Quantity) -> Result<Estimate, Error> {
    r.get(q)
        .ok_or_else(|| Error::Output(format!("{} does not estimate {q}", r.method)))
}

/// `(mean − exact)/stderr`; 0 when the estimate is exact, `None` when
/// `stderr = 0` but the estimate is not.
pub fn z(mean: f64, stderr: f64, exact: f64) -> Option<f64> {
    let diff = mean - exact;
    if diff == 0.0 {
        Some(0.0)
    } else {
        (stderr > 0.0).then(|| diff / stderr)
    }
}

/// Legend label of `method`: what it is judged on.
pub fn label(method: Method) -> String {
    match method {
        Method::Intensity => "intensity (E)".into(),
        m => format!("{} (∂E/∂π)", m.name()),
    }
}

/// Saves `figure` as `<name>.{png,svg}` with its numbers, `<name>.json`
/// (`name` with the dimension's prefix, as `flat_warp`); returns the files
/// written.
pub(crate) fn save<T: serde::Serialize>(
    opts: &FigureOptions,
    name: &str,
    figure: &crate::plot::Figure,
    numbers: &T,
) -> Result<Vec<PathBuf>, Error> {
    let mut written = figure.save(&opts.out, name)?;
    written.push(opts.write_json(name, numbers)?);
    Ok(written)
}

/// `n` evenly spaced values over `range`, ends included.
pub(crate) fn grid((lo, hi): (f64, f64), n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| lo + (hi - lo) * i as f64 / (n - 1) as f64)
        .collect()
}
