//! The rod's figures (the book's chapters "The rod", one per approach, and
//! "Comparing the approaches"): each is one function that runs its
//! experiment, deterministic from the seed, draws it with [`crate::plot`]
//! and writes PNG and SVG under the output folder. The examples
//! `examples/fig_*.rs` each call one; `geosens compare --figures DIR` calls
//! them all.
use crate::error::Error;
use crate::estimator::Quantity;
use crate::rod::{Direction, Method, Probe, Rod, exact};
use crate::runner::{RunConfig, RunResult, run};
use indicatif::{ProgressBar, ProgressStyle};
use std::path::PathBuf;

pub mod along;
pub mod convergence;
pub mod efficiency;
pub mod finite_difference;
pub mod stability;

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

    /// Runs `method` at `(x, omega)` with `paths` (scaled) paths and seed
    /// `self.seed + salt`.
    pub fn run(
        &self,
        method: Method,
        rod: Rod,
        x: f64,
        omega: Direction,
        paths: u64,
        salt: u64,
    ) -> Result<RunResult, Error> {
        let probe = Probe::new(&rod, x, omega)?;
        let cfg =
            RunConfig::new(self.paths(paths), self.seed.wrapping_add(salt))?.threads(self.threads);
        run(method.estimator((rod, probe))?.as_ref(), &cfg)
    }
}

/// A figure: runs its experiment and writes its files.
pub type FigureFn = fn(&FigureOptions) -> Result<Vec<PathBuf>, Error>;

/// Every figure of the rod, in the book's order; returns the files written.
pub fn all(opts: &FigureOptions) -> Result<Vec<PathBuf>, Error> {
    crate::figures_common::all(
        opts,
        &[
            finite_difference::finite_difference,
            along::intensity_along_rod,
            along::sensitivity_along_rod,
            convergence::convergence,
            efficiency::efficiency,
            stability::stability,
        ],
    )
}

/// The paper's optically thin rod: κs = 0.07, κe = 0.1, length 2.
pub fn thin() -> Rod {
    Rod {
        ks: 0.07,
        ke: 0.1,
        length: 2.0,
        incoming: 1.0,
    }
}

/// The paper's optically thick rod: κs = 2.1, κe = 3, length 2.
pub fn thick() -> Rod {
    Rod {
        ks: 2.1,
        ke: 3.0,
        length: 2.0,
        incoming: 1.0,
    }
}

/// The exact value of `q` at `(x, omega)`.
pub fn exact_value(rod: &Rod, x: f64, omega: Direction, q: &Quantity) -> f64 {
    exact::solve(rod, x, omega).get(q)
}

/// `n` evenly spaced positions over `[0, length]`, ends included.
pub fn positions(rod: &Rod, n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| rod.length * i as f64 / (n - 1) as f64)
        .collect()
}
